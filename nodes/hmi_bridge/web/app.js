// The operator panel: everything arrives over one WebSocket, and every button sends a request
// that the bridge carries out through the same path as the ROS 2 services.
"use strict";
const $ = (id) => document.getElementById(id);
let ws = null;
let nextId = 1;
let path = [];
let listingName = null;
let ladder = null;
let signals = null;
let lastLine = -1;
let parameters = [];

const STEPS = [0, 10, 15, 20, 25, 30, 35, 40, 50, 60, 70, 80, 90, 100, 125, 150];
for (const id of ["feed_ov", "spindle_ov"]) {
  for (const s of STEPS) {
    const o = document.createElement("option");
    o.textContent = s;
    if (s === 100) o.selected = true;
    $(id).appendChild(o);
  }
}

function send(request) {
  if (!ws || ws.readyState !== WebSocket.OPEN) return;
  request.id = nextId++;
  ws.send(JSON.stringify(request));
}

function connect() {
  ws = new WebSocket(`ws://${location.host}/ws`);
  ws.onopen = () => {
    $("link").textContent = "online";
    $("link").className = "on";
    send({ op: "list" });
    send({ op: "parameters" });
  };
  ws.onclose = () => {
    $("link").textContent = "offline";
    $("link").className = "off";
    // A closed panel on the network may mean an expired session: ask again before retrying.
    jogStop();
    setTimeout(start, 1000);
  };
  ws.onmessage = (e) => {
    let m;
    try { m = JSON.parse(e.data); } catch (_) { return; }
    (handlers[m.type] || (() => {}))(m);
  };
}

const fmt = (v) => (typeof v === "number" ? v.toFixed(3) : "-");
// Seconds as minutes:seconds with tenths (the program's run time).
const clock = (s) => {
  const t = Math.round(s * 10) / 10;
  return `${Math.floor(t / 60)}:${(t % 60).toFixed(1).padStart(4, "0")}`;
};

const handlers = {
  welcome(m) {
    path = m.path || [];
    $("history").innerHTML = "";
    for (const h of m.history || []) handlers.history({ entry: h });
    $("commands").innerHTML = "";
    for (const c of m.commands || []) handlers.command({ entry: c });
    draw();
  },
  state(m) {
    const s = m.machine;
    if (s) {
      $("mode").textContent = s.mode;
      $("execution").textContent = s.execution;
      $("program").textContent = s.program || "-";
      $("line").textContent = s.line;
      $("estop").hidden = !s.emergency_stop;
      // The program's message to the operator (MSG), as the control's message line shows it.
      $("program-message").textContent = s.message || "";
      $("program-message").hidden = !s.message;
      if (s.program && s.program !== listingName) {
        listingName = s.program;
        send({ op: "read", name: s.program });
      }
      if (s.line !== lastLine) {
        lastLine = s.line;
        markLine(s.line);
      }
    }
    if (m.axes && m.axes.length) jogKeys(m.axes.map((a) => a.name));
    $("axes").innerHTML = (m.axes || [])
      .map((a) => `<tr><th>${a.name}</th><td>${fmt(a.machine)}</td><td>${fmt(a.work)}</td><td>${fmt(a.to_go)}</td></tr>`)
      .join("");
    $("feed").textContent = Math.round(m.feed || 0);
    if (m.spindle) {
      $("rpm").textContent = Math.round(m.spindle.actual_rpm);
      $("rpm_cmd").textContent = Math.round(m.spindle.commanded_rpm);
    }
    if (m.overrides) {
      $("ov_feed").textContent = m.overrides.feed;
      $("ov_spindle").textContent = m.overrides.spindle;
      $("ov_rapid").textContent = m.overrides.rapid;
    }
    $("parts").textContent = m.parts ? m.parts.count : 0;
    if (m.timers) $("cycle_time").textContent = clock(m.timers.cycle);
    $("alarms").innerHTML = (m.alarms || [])
      .map((a) => `<li class="${a.acknowledged ? "seen" : "unseen"}">${a.number} ${escape(a.text)}${a.line ? ` (line ${a.line})` : ""} [${a.source}]${a.acknowledged ? " (seen)" : ""}</li>`)
      .join("");
    for (const h of m.history || []) handlers.history({ entry: h });
    for (const c of m.commands || []) handlers.command({ entry: c });
    if (m.path_reset) path = [];
    path.push(...(m.path || []));
    if (m.plot) $("toolpath").dataset.axes = m.plot.join(",");
    draw();
  },
  history(m) {
    const h = m.entry;
    const li = document.createElement("li");
    li.textContent = `${h.raised ? "raised" : "cleared"} ${h.number} ${h.text} [${h.source}]`;
    $("history").prepend(li);
  },
  command(m) {
    const c = m.entry;
    const li = document.createElement("li");
    li.textContent = `${c.accepted ? "✓" : "✗"} ${c.command} ${c.detail} — ${c.client}: ${c.message}`;
    $("commands").prepend(li);
  },
  reply(m) {
    // Reads answer with their data; the message line is for commands.
    if (m.accepted && ["read_program", "list_programs", "get_offsets", "get_parameters"].includes(m.op)) return;
    if (m.accepted && m.op === "set_parameter") send({ op: "parameters" });
    $("message").textContent = `${m.op || "request"}: ${m.message}`;
    $("message").className = m.accepted ? "accepted" : "refused";
    if (m.accepted && ["load_program", "delete_program"].includes(m.op)) send({ op: "list" });
  },
  program(m) {
    listingName = m.name;
    $("listing_name").textContent = m.name;
    $("listing").innerHTML = m.text.split("\n").map((l) => `<li>${escape(l) || "&nbsp;"}</li>`).join("");
    markLine(lastLine);
  },
  programs(m) {
    $("programs").innerHTML = m.programs.map((p) => `<option value="${escape(p.name)}">${escape(p.name)} (${p.size} B)</option>`).join("");
  },
  offsets(m) {
    const mm = (v) => `<td>${escape(Number(v).toFixed(3))}</td>`;
    $("tools").innerHTML = m.tools.map((t) =>
      `<tr><td>${escape(String(t.number))}</td>${[t.x, t.z, t.wear_x, t.wear_z, t.radius].map(mm).join("")}<td>${escape(String(t.tip))}</td></tr>`).join("");
    $("works").innerHTML = m.work.map((w) =>
      `<tr><th>${escape(w.code)}</th>${w.axes.map((a, i) => `<td>${escape(`${a}=${Number(w.values[i]).toFixed(3)}`)}</td>`).join("")}</tr>`).join("");
  },
  parameters(m) {
    parameters = m.rows || [];
    showParameters();
  },
  ladder(m) {
    ladder = m;
    $("ladder_source").textContent = m.source;
    drawLadder();
  },
  signals(m) {
    signals = m;
    $("scan").textContent = m.scan;
    drawLadder();
  },
};

// The parameter table, filtered; a row's click puts its name in the write line.
function showParameters() {
  const filter = $("param_filter").value.trim();
  $("parameters").innerHTML = parameters
    .filter(([name]) => !filter || name.includes(filter))
    .map(([name, value, pending]) => `<tr data-name="${escape(name)}"><td>${escape(name)}</td><td>${escape(value)}</td><td>${escape(pending)}</td></tr>`)
    .join("");
  for (const row of $("parameters").children) {
    row.onclick = () => { $("param_name").value = row.dataset.name; };
  }
}

function escape(s) {
  return String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);
}

function markLine(line) {
  const items = $("listing").children;
  for (const li of items) li.classList.remove("current");
  const li = items[line - 1];
  if (li) {
    li.classList.add("current");
    li.scrollIntoView({ block: "nearest" });
  }
}

function draw() {
  const c = $("toolpath");
  const g = c.getContext("2d");
  g.clearRect(0, 0, c.width, c.height);
  if (path.length < 2) return;
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  for (const [x, y] of path) {
    x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
  }
  const k = Math.min((c.width - 20) / Math.max(x1 - x0, 1e-3), (c.height - 20) / Math.max(y1 - y0, 1e-3));
  const px = (x) => 10 + (x - x0) * k;
  const py = (y) => c.height - 10 - (y - y0) * k;
  g.strokeStyle = "#1565c0";
  g.beginPath();
  g.moveTo(px(path[0][0]), py(path[0][1]));
  for (const [x, y] of path) g.lineTo(px(x), py(y));
  g.stroke();
  const [tx, ty] = path[path.length - 1];
  g.fillStyle = "#d84315";
  g.beginPath();
  g.arc(px(tx), py(ty), 4, 0, 2 * Math.PI);
  g.fill();
  g.fillStyle = "#37474f";
  g.fillText(c.dataset.axes || "", 4, 12);
}

// An address's bit in the last snapshot: R9000+ follows R0-R999 in the R table.
function bit(space, byte, b) {
  if (!signals || !signals[space]) return null;
  let i = byte;
  if (space === "R" && byte >= 9000) i = 1000 + byte - 9000;
  const v = signals[space][i];
  return v === undefined ? null : (v >> b) & 1;
}

function drawLadder() {
  if (!ladder) return;
  const filter = $("ladder_filter").value.trim().toUpperCase();
  const html = [];
  ladder.rungs.forEach((rung, i) => {
    if (filter && !rung.toUpperCase().includes(filter)) return;
    const text = escape(rung).replace(/\b([XYFGRAK])(\d+)\.([0-7])\b/g, (all, s, n, b) => {
      const v = bit(s, Number(n), Number(b));
      return v === null ? all : `<span class="sig ${v ? "on" : "off"}">${all}</span>`;
    });
    html.push(`<div class="rung" data-line="${ladder.lines[i]}">${text}</div>`);
  });
  $("ladder").innerHTML = html.join("");
}

$("cycle_start").onclick = () => {
  const stored = $("programs").value;
  const execution = $("execution").textContent;
  // In feed hold cycle start resumes; otherwise it starts the program shown or selected.
  const name = execution === "FEED_HOLD" ? "" : listingName || stored || "";
  // A start in mid-program (block search) applies to this cycle start only.
  const at = execution === "FEED_HOLD" ? "" : $("start_at").value.trim();
  $("start_at").value = "";
  send({ op: "start", name, at });
};
// Jog keys, one pair per axis once the axes are known. A continuous jog is held by repeating
// the request every 50 ms while the key is down; released, or the connection lost, the
// machine stops the axis by itself within 200 ms (dead man, decisions D69).
let jogTimer = null;
function jogStop() {
  if (jogTimer === null) return;
  clearInterval(jogTimer.interval);
  send({ op: "jog", axis: jogTimer.axis, direction: 0 });
  jogTimer = null;
}
function jogKeys(names) {
  const box = $("jog_keys");
  if (box.dataset.axes === names.join()) return;
  box.dataset.axes = names.join();
  box.innerHTML = "";
  for (const axis of names) {
    for (const [label, direction] of [["-", -1], ["+", 1]]) {
      const b = document.createElement("button");
      b.id = `jog_${axis}${label === "+" ? "plus" : "minus"}`;
      b.textContent = `${label}${axis}`;
      b.onpointerdown = () => {
        const feed = Number($("jog_feed").value) || 0;
        const increment = Number($("jog_step").value) || 0;
        const ask = () => send({ op: "jog", axis, direction, feed, increment });
        ask();
        if (increment === 0) {
          jogStop();
          jogTimer = { axis, interval: setInterval(ask, 50) };
        }
      };
      b.onpointerup = jogStop;
      b.onpointerleave = jogStop;
      box.appendChild(b);
    }
  }
}
window.addEventListener("blur", jogStop);
$("feed_hold").onclick = () => send({ op: "feed_hold" });
$("reset").onclick = () => send({ op: "reset" });
$("mode_set").onclick = () => send({ op: "mode", mode: $("mode_select").value });
$("mdi_run").onclick = () => send({ op: "mdi", text: $("mdi").value });
$("ov_set").onclick = () =>
  send({ op: "overrides", feed: Number($("feed_ov").value), spindle: Number($("spindle_ov").value), rapid: Number($("rapid_ov").value) });
// A program goes as a binary message (JSON header, zero byte, the text as it is): escaped in
// JSON, a program near the 4 MiB limit would not fit in one message.
$("load").onclick = () => {
  if (!ws || ws.readyState !== WebSocket.OPEN) return;
  const utf8 = new TextEncoder();
  const head = utf8.encode(JSON.stringify({ id: nextId++, op: "load", name: $("load_name").value }));
  const body = utf8.encode($("load_text").value);
  const message = new Uint8Array(head.length + 1 + body.length);
  message.set(head, 0);
  message.set(body, head.length + 1);
  ws.send(message);
};
$("select").onclick = () => { if ($("programs").value) send({ op: "read", name: $("programs").value }); };
$("delete").onclick = () => { if ($("programs").value) send({ op: "delete", name: $("programs").value }); };
$("refresh").onclick = () => send({ op: "list" });
$("offsets_read").onclick = () => send({ op: "offsets" });
$("tool_set").onclick = () => send({ op: "set_tool_offset", number: $("tool_no").value, values: $("tool_values").value });
$("work_set").onclick = () => send({ op: "set_work_offset", code: $("work_code").value, values: $("work_values").value });
$("ladder_filter").oninput = drawLadder;
$("acknowledge").onclick = () => send({ op: "acknowledge" });
$("param_set").onclick = () => send({ op: "set_parameter", name: $("param_name").value, value: $("param_value").value });
$("param_filter").oninput = showParameters;

// A machine of a cell offers the other machines' panels: choosing one opens it.
function showCell(cell) {
  const panels = (cell && cell.panels) || [];
  $("machine_pick").hidden = panels.length === 0;
  const select = $("machine_select");
  select.replaceChildren(...panels.map((p) => {
    const o = document.createElement("option");
    o.value = p.url;
    o.textContent = p.name;
    o.selected = p.name === cell.machine;
    return o;
  }));
  select.onchange = () => { window.location.href = select.value; };
}

// On the network the panel needs a login (the server says so at /session); on the machine's
// own screen (loopback) it does not.
async function start() {
  let session = { required: false, operator: null };
  try { session = await (await fetch("/session")).json(); } catch (_) { setTimeout(start, 1000); return; }
  $("operator").hidden = !session.operator;
  $("operator_name").textContent = session.operator || "";
  showCell(session.cell);
  if (session.required && !session.operator) {
    document.querySelector("main").hidden = true;
    $("login").hidden = false;
    return;
  }
  $("login").hidden = true;
  document.querySelector("main").hidden = false;
  connect();
}
$("login").onsubmit = async (e) => {
  e.preventDefault();
  const r = await fetch("/login", {
    method: "POST",
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify({ name: $("login_name").value, password: $("login_password").value }),
  });
  $("login_password").value = "";
  if (r.ok) start();
  else $("login_message").textContent = `refused: ${await r.text()}`;
};
$("logout").onclick = async () => {
  await fetch("/logout", { method: "POST" });
  if (ws) ws.close();
};
start();
