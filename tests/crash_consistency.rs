//! Issue 26: what the machine keeps survives kill -9 at any moment, consistently. The cell runs
//! as its own process (`cnc run`) with its state in a temporary folder; this test is its
//! supervisor. 50 times it writes a tool offset, a parameter and a new program, starts a part
//! (whose last block counts it in kept variable #200 before M30), and kills the cell with
//! SIGKILL at a random moment: during the writes, or around the end of the part. After each
//! restart it compares:
//! - the part count with the parts the supervisor saw counted (the count is published only
//!   once on disk: never lower; one higher only when the kill fell between the write and the
//!   publication);
//! - #200 less the part count never falls (a counted part's increment is never lost) and
//!   rises by at most one per kill (a part killed between its last block and its count);
//! - the tool offset and the parameter: the last acknowledged value, or the one in flight;
//! - every acknowledged program, byte for byte, in program memory and on disk;
//! - the kept program position: whole, naming the part, at one of its lines (how often it was
//!   at or past the line the supervisor last saw is printed: the position is written behind
//!   the machine, never ahead of what it reached).
//!
//! The random moments come from a seed printed at the start (`CNC_CRASH_SEED` repeats a run).

use std::collections::BTreeMap;
use std::path::Path;
use std::time::{Duration, Instant};

mod common;

use cnc_cell::client::CellClient;
use cnc_msgs::msg::ToolOffset;
use cnc_msgs::srv::{
    GetOffsets, GetOffsetsRequest, GetParameters, GetParametersRequest, SetParameter,
    SetParameterRequest, SetToolOffset, SetToolOffsetRequest,
};
use cnc_runtime::LaunchConfig;
use cnc_task::position::ProgramPosition;
use ros2_client::ServiceMapping;

const DOMAIN: u16 = 71;
const KILLS: usize = 50;
/// The part's last move (`G00 X60`, line 6): after it come #200, M05 and M30, then the count.
const LAST_MOVE_LINE: u32 = 6;
/// End-of-part kills fall this long after the last move shows, at random.
const END_WINDOW_S: f64 = 0.8;
const PART: &str =
    "O0001\nG00 X60 Z5\nS600 M03\nG01 X50 F3000\nZ-5\nG00 X60\n#200=#200+1\nM05\nM30\n";

/// A small random generator (xorshift), so a failing run can be repeated from its seed.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// What the restarted machine reports and keeps.
struct Kept {
    count: u32,
    kept_200: f64,
    wear_x: f64,
    lookahead: String,
    programs: BTreeMap<String, u64>,
}

fn read_back(client: &mut CellClient, memory_file: &Path) -> Kept {
    let t0 = Instant::now();
    while client.part_count.is_none() {
        client.poll();
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "no part count after restart"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    let memory: serde_yaml::Value = std::fs::read_to_string(memory_file)
        .ok()
        .and_then(|t| serde_yaml::from_str(&t).ok())
        .unwrap_or(serde_yaml::Value::Null);
    let kept_200 = memory["kept"][200].as_f64().unwrap_or(0.0);
    let offsets = client
        .service::<GetOffsets>("get_offsets")
        .and_then(|s| s.query(GetOffsetsRequest::default()))
        .expect("get_offsets");
    let wear_x = offsets
        .tools
        .iter()
        .find(|t| t.number == 1)
        .map_or(f64::NAN, |t| t.wear_x);
    let params = client
        .service::<GetParameters>("get_parameters")
        .and_then(|s| {
            s.query(GetParametersRequest {
                prefix: "servo.lookahead".into(),
            })
        })
        .expect("get_parameters");
    // A written parameter is pending until the next start; after a restart it is the value.
    let lookahead = params.values.first().cloned().unwrap_or_default();
    let list = client.list_programs().expect("list_programs");
    Kept {
        count: client.part_count.as_ref().map_or(0, |p| p.count),
        kept_200,
        wear_x,
        lookahead,
        programs: list.names.into_iter().zip(list.sizes).collect(),
    }
}

/// Offsets are kept to the micrometre.
fn same(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-6
}

fn offset(wear_x: f64) -> SetToolOffsetRequest {
    SetToolOffsetRequest {
        offset: ToolOffset {
            number: 1,
            wear_x,
            radius: 0.4,
            tip: 3,
            ..Default::default()
        },
    }
}

#[test]
fn kill_9_at_fifty_random_moments_loses_nothing_the_supervisor_was_told() {
    let seed = std::env::var("CNC_CRASH_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| cnc_runtime::clock::wall_ns() | 1);
    println!("CNC_CRASH_SEED={seed}");
    let mut rng = Rng(seed);
    let dir = std::env::temp_dir().join(format!("cnc_crash_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let config = common::sim_lathe_file(&dir, "crash_lathe.yaml", DOMAIN, |_| {});
    let cfg = LaunchConfig::load(&config).expect("config");
    let memory_file = cfg.machine.memory_file.clone().expect("memory file");
    let program_dir = cfg
        .machine
        .program_directory
        .clone()
        .expect("program folder");
    let log = dir.join("cell.log");
    let position_file = cfg.machine.position_file.clone().expect("position file");

    // What the supervisor was told, and what was in flight at the kill.
    let mut seen_count = 0u32;
    let mut drift = 0.0; // #200 less the part count
    let mut wear = (0.0, None::<f64>); // acknowledged, in flight
    let mut lookahead = (cfg.servo.lookahead.to_string(), None::<String>);
    let mut programs: BTreeMap<String, String> = BTreeMap::new();
    let mut in_flight_program: Option<(String, String)> = None;
    let mut extra_counts = 0;
    let mut kill_moments = Vec::new();
    // The part's line the supervisor saw last before the kill, and how often the kept
    // position was at or past it.
    let mut line_seen = 0u32;
    let mut position_caught_up = 0;

    for round in 0..=KILLS {
        let t_start = Instant::now();
        // Killed if the test fails before the round's own kill: no cell outlives the test.
        let mut cell = common::KillOnDrop(common::cnc_run(&config, &log));
        let mut client = CellClient::new(
            &cfg.network,
            "lathe1",
            "supervisor",
            ServiceMapping::Enhanced,
        )
        .expect("client")
        .with_timeout(Duration::from_secs(5));
        client
            .wait_ready(Duration::from_secs(60))
            .unwrap_or_else(|e| panic!("round {round}: {e}"));
        let t_ready = t_start.elapsed().as_secs_f64();
        let kept = read_back(&mut client, &memory_file);
        println!(
            "round {round}: ready after {t_ready:.1} s, read back after {:.1} s: count {}, #200 {}",
            t_start.elapsed().as_secs_f64(),
            kept.count,
            kept.kept_200
        );

        // Compare with what the supervisor was told before the kill.
        if round > 0 {
            assert!(
                kept.count >= seen_count && kept.count <= seen_count + 1,
                "round {round}: part count {} after restart, the supervisor saw {seen_count}",
                kept.count
            );
            extra_counts += (kept.count > seen_count) as u32;
            let d = kept.kept_200 - f64::from(kept.count);
            assert!(
                d >= drift && d <= drift + 1.0,
                "round {round}: #200 {} and part count {}: a counted part's increment was lost \
                 or two parts were counted once (drift {drift} before)",
                kept.kept_200,
                kept.count
            );
            drift = d;
            assert!(
                same(kept.wear_x, wear.0) || wear.1.is_some_and(|w| same(kept.wear_x, w)),
                "round {round}: wear {} after restart; acknowledged {}, in flight {:?}",
                kept.wear_x,
                wear.0,
                wear.1
            );
            wear = (kept.wear_x, None);
            assert!(
                kept.lookahead == lookahead.0 || Some(&kept.lookahead) == lookahead.1.as_ref(),
                "round {round}: servo.lookahead {} after restart; acknowledged {}, in flight {:?}",
                kept.lookahead,
                lookahead.0,
                lookahead.1
            );
            lookahead = (kept.lookahead.clone(), None);
            if let Some((name, text)) = in_flight_program.take() {
                if kept.programs.contains_key(&name) {
                    programs.insert(name, text);
                }
            }
            for (name, text) in &programs {
                assert_eq!(
                    kept.programs.get(name),
                    Some(&(text.len() as u64)),
                    "round {round}: program {name} not kept whole"
                );
                let on_disk = std::fs::read_to_string(program_dir.join(name)).unwrap_or_default();
                assert!(on_disk == *text, "round {round}: {name} on disk differs");
            }
            assert_eq!(
                kept.programs.len(),
                programs.len(),
                "round {round}: {:?}",
                kept.programs
            );
            let text = std::fs::read_to_string(&position_file).expect("a kept position");
            let position = ProgramPosition::from_yaml(&text)
                .unwrap_or_else(|e| panic!("round {round}: {e}: {text:?}"));
            assert!(
                position.program == "part.nc" && (1..=9).contains(&position.line),
                "round {round}: kept position {position:?}"
            );
            position_caught_up += (position.line >= line_seen) as u32;
        }
        seen_count = kept.count;
        if round == KILLS {
            let _ = cell.0.kill();
            let _ = cell.0.wait();
            break;
        }

        // The round: writes, then a part; the kill comes at a random moment.
        let t0 = Instant::now();
        // Odd rounds: during the writes, by the clock. Even rounds (but the first, which runs
        // its part to the end): around the end of the part, from when its last move shows.
        let kill_at = (round % 2 == 1).then(|| Duration::from_secs_f64(rng.next() * 0.3));
        let end_delay = (round > 0 && round % 2 == 0)
            .then(|| Duration::from_secs_f64(rng.next() * END_WINDOW_S));
        let mut end_kill: Option<Instant> = None;
        let killed = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let killer = kill_at.map(|at| {
            let pid = cell.0.id();
            let killed = killed.clone();
            std::thread::spawn(move || {
                std::thread::sleep(at);
                // SAFETY: kill(2) with a pid this test spawned and has not yet waited for.
                unsafe { libc::kill(pid as i32, libc::SIGKILL) };
                killed.store(true, std::sync::atomic::Ordering::SeqCst);
            })
        });
        // After the kill nothing more is asked (a call would only wait for its timeout).
        let alive = || !killed.load(std::sync::atomic::Ordering::SeqCst);
        let new_wear = (round as f64 + 1.0) / 1000.0;
        wear.1 = Some(new_wear);
        if !alive() {
        } else if let Ok(Ok(r)) = client
            .service::<SetToolOffset>("set_tool_offset")
            .map(|s| s.call(offset(new_wear)))
        {
            if r.accepted {
                wear = (new_wear, None);
            }
        }
        let value = (8 + round % 40).to_string();
        lookahead.1 = Some(value.clone());
        if !alive() {
        } else if let Ok(Ok(r)) = client.service::<SetParameter>("set_parameter").map(|s| {
            s.call(SetParameterRequest {
                name: "servo.lookahead".into(),
                value: value.clone(),
            })
        }) {
            if r.accepted {
                lookahead = (value, None);
            }
        }
        let name = format!("jobs/P{round:03}.nc");
        let text = format!("O{:04}\nG00 X{}\nM30\n", round + 100, 50 + round);
        in_flight_program = Some((name.clone(), text.clone()));
        if alive() && client.load_program(&name, &text).is_ok_and(|r| r.accepted) {
            programs.insert(name, text);
            in_flight_program = None;
        }
        if round == 0 {
            assert!(client.load_program("part.nc", PART).unwrap().accepted);
            programs.insert("part.nc".into(), PART.into());
        }
        if alive() {
            let _ = client.reset();
        }
        if alive() {
            line_seen = 0;
            let _ = client.start_program("part.nc");
        }
        // Follow the part count until the kill (or, in round 0, the part's end).
        loop {
            client.poll();
            if let Some(p) = &client.part_count {
                seen_count = seen_count.max(p.count);
            }
            if let Some(s) = client.state.as_ref().filter(|s| s.program == "part.nc") {
                if s.line > 0 {
                    line_seen = s.line;
                }
            }
            if let Some(delay) = end_delay {
                let at_end = client
                    .state
                    .as_ref()
                    .is_some_and(|s| s.program == "part.nc" && s.line >= LAST_MOVE_LINE);
                if end_kill.is_none() && (at_end || t0.elapsed() > Duration::from_secs(30)) {
                    end_kill = Some(Instant::now() + delay);
                }
                if end_kill.is_some_and(|t| Instant::now() >= t) && alive() {
                    // SAFETY: kill(2) with a pid this test spawned and has not yet waited for.
                    unsafe { libc::kill(cell.0.id() as i32, libc::SIGKILL) };
                    killed.store(true, std::sync::atomic::Ordering::SeqCst);
                }
            }
            if round == 0 && seen_count > kept.count {
                break;
            }
            if let Ok(Some(_)) = cell.0.try_wait() {
                break;
            }
            assert!(
                t0.elapsed() < Duration::from_secs(60),
                "round {round}: stuck"
            );
            std::thread::sleep(Duration::from_millis(2));
        }
        if round == 0 {
            let _ = cell.0.kill();
        }
        let _ = cell.0.wait();
        if let Some(k) = killer {
            let _ = k.join();
        }
        kill_moments.push(t0.elapsed().as_secs_f64());
        drop(client);
    }
    println!(
        "{KILLS} kills; rounds ended {:.2}..{:.2} s after their writes began; parts counted {seen_count}; \
         counted before the supervisor heard of it {extra_counts} times; #200 ahead of the count by {drift}; \
         kept position at or past the line the supervisor saw {position_caught_up} times",
        kill_moments.iter().cloned().fold(f64::INFINITY, f64::min),
        kill_moments.iter().cloned().fold(0.0, f64::max)
    );
    assert!(
        seen_count >= 5,
        "too few parts finished to test the end of parts: {seen_count}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
