// The cell's two lathes in headless Debian chromium (playwright-core): lathe1's panel offers a
// machine selector with both lathes, lathe1 chosen; choosing lathe2 opens lathe2's panel, which
// shows lathe2 chosen and its parts counting up while the robot tends it.
// Usage: node cell.cjs <lathe1 panel url> <lathe2 panel url>. Exits 1 with the reason on a failure.
"use strict";
const { fail, launch } = require("./browser.cjs");
const [first, second] = process.argv.slice(2);

async function machines(page) {
  return page.$$eval("#machine_select option", (os) => os.map((o) => `${o.textContent}${o.selected ? "*" : ""}`));
}

(async () => {
  const browser = await launch();
  const page = await browser.newPage();
  page.on("pageerror", (e) => fail(`page error: ${e.message}`));
  await page.goto(first);
  await page.waitForFunction(() => document.getElementById("link").textContent === "online", null, { timeout: 30000 });
  await page.waitForSelector("#machine_pick:not([hidden])", { timeout: 10000 });
  const one = (await machines(page)).join(",");
  if (one !== "lathe1*,lathe2") fail(`lathe1's selector: ${one}`);
  console.log(`ok   lathe1's panel: machines ${one}`);
  await Promise.all([page.waitForURL(second, { timeout: 20000 }), page.selectOption("#machine_select", { label: "lathe2" })]);
  await page.waitForFunction(() => document.getElementById("link").textContent === "online", null, { timeout: 30000 });
  const two = (await machines(page)).join(",");
  if (two !== "lathe1,lathe2*") fail(`lathe2's selector: ${two}`);
  console.log(`ok   lathe2's panel at ${page.url()}: machines ${two}`);
  const parts = Number(await page.textContent("#parts"));
  await page.waitForFunction((n) => Number(document.getElementById("parts").textContent) > n, parts, { timeout: 90000 });
  console.log(`ok   lathe2's parts ${parts} -> ${await page.textContent("#parts")}, state ${await page.textContent("#execution")}`);
  await browser.close();
})().catch((e) => fail(e.message));
