//! `cnc run`: one machine's cell, or a whole cell from its launch file, run from the terminal
//! and watched there — the programmed cycles of `--program` through the cell's own services,
//! the supervisor's view of a whole cell, a line of progress and the alarms as they come.

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use cnc::cell::Cell;
use cnc::machines;
use cnc_cell::client::CellClient;
use cnc_msgs::msg::MachineState;
use cnc_runtime::LaunchConfig;
use ros2_client::ServiceMapping;

use crate::{install_signal_handlers, with_drive_trace, NamedProgram, STOP};

pub(crate) fn run(
    config: Option<&Path>,
    program: Option<NamedProgram>,
    cycles: u32,
    drive_trace: Option<PathBuf>,
) -> Result<(), String> {
    if let Some(path) = config.filter(|p| cnc_cell::launch::is_cell_file(p)) {
        if program.is_some() {
            return Err("a cell launch file runs its work order: no --program".into());
        }
        return run_cell(path);
    }
    let (mut cfg, described) = machines::load(config, None)?;
    with_drive_trace(&mut cfg, drive_trace)?;
    install_signal_handlers();
    let domain = cfg.network.effective_domain_id()?;
    let ns = cfg.machine.namespace.clone();
    let cell = Cell::start(&cfg)?;
    println!(
        "cell '{ns}' running ({described}): DDS domain {domain} on {:?}; services /{ns}/load_program, /{ns}/start_program, /{ns}/stop, /{ns}/reset; topics /{ns}/machine_state, /{ns}/spindle, /{ns}/axes, /{ns}/part_count, /{ns}/alarms, /{ns}/alarm_events",
        cfg.network.interfaces
    );
    for (what, path) in cfg.written_files() {
        println!("{what}: {}", path.display());
    }
    let outcome = supervise(&cfg, &cell, program, cycles);
    let (summary, errors) = cell.stop();
    if !summary.is_empty() {
        println!("{summary}");
    }
    for e in &errors {
        eprintln!("cnc: {e}");
    }
    outcome?;
    if errors.is_empty() {
        Ok(())
    } else {
        Err("a node failed".into())
    }
}

/// Runs a whole cell from its launch file: every machine, the cell supervisor and the robot
/// in this process, until the work order is complete (exit 0), Ctrl-C, or a node fails. The
/// terminal shows the supervisor's view whenever it changes.
fn run_cell(path: &Path) -> Result<(), String> {
    use cnc_cell::robot_node::CellWatch;
    let launch = cnc_cell::launch::load(path)?;
    for cfg in &launch.machines {
        if cfg.network.effective_security()?.is_some() {
            return Err(format!(
                "{}: DDS Security is on: run each machine in its own process \
                 (`cnc run <machine config>`); the one-process demo cell does not work under \
                 security (docs/decisions.md, D113)",
                cfg.machine.namespace
            ));
        }
    }
    install_signal_handlers();
    let mut cells = Vec::new();
    for cfg in &launch.machines {
        match Cell::start(cfg) {
            Ok(c) => cells.push(c),
            Err(e) => {
                for c in cells {
                    c.stop();
                }
                return Err(format!("{}: {e}", cfg.machine.namespace));
            }
        }
        let web = match cfg.hmi.web_address.as_str() {
            "" => "no web panel".to_string(),
            a => format!("web panel http://{a}/"),
        };
        println!(
            "machine '{}' running: DDS domain {} on {:?}, {web}",
            cfg.machine.namespace,
            cfg.network.effective_domain_id()?,
            cfg.network.interfaces
        );
    }
    let net = launch.machines[0].network.clone();
    let names: Vec<String> = launch
        .order
        .lines
        .iter()
        .map(|l| l.machine.clone())
        .collect();
    let (order, options) = (launch.order, launch.supervisor);
    println!(
        "work order '{}': {} parts of {} on each of {}",
        order.name,
        order.lines[0].parts,
        order.lines[0].program,
        names.join(", ")
    );
    // The supervisor starts each machine's first part; the robot loads the others.
    let parts: Vec<u32> = order
        .lines
        .iter()
        .map(|l| l.parts.saturating_sub(1))
        .collect();
    let supervisor = {
        let net = net.clone();
        std::thread::spawn(move || {
            cnc_cell::supervisor_node::supervise(&net, order, &options, &STOP)
        })
    };
    let robot_net = net.clone();
    let swap = launch.swap_seconds;
    let robot_names = names.clone();
    std::thread::spawn(move || {
        let forever = Instant::now() + Duration::from_secs(365 * 24 * 3600);
        let served =
            cnc_cell::robot_node::serve_cell(&robot_net, &robot_names, &parts, swap, forever);
        if let Err(e) = served {
            eprintln!("cnc: robot: {e}");
        }
    });
    // The terminal's view of the cell only reads: under DDS Security, the observer.
    let mut watch = CellWatch::new(&net.with_default_enclave("/cell/observer")?, "cnc_cli")?;
    let mut shown = String::new();
    let outcome = loop {
        if STOP.load(Ordering::SeqCst) {
            break Ok(());
        }
        if let Some(node) = cells.iter().find_map(|c| c.failed_node()) {
            break Err(format!("node {node} stopped"));
        }
        watch.poll();
        if let Some(s) = &watch.last {
            let line = cell_line(s);
            if line != shown {
                println!("{line}");
                shown = line;
            }
            if s.complete {
                println!("work order '{}' complete", s.order);
                break Ok(());
            }
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    STOP.store(true, Ordering::SeqCst);
    let finished = supervisor
        .join()
        .map_err(|_| "the supervisor panicked".to_string())
        .and_then(|r| r);
    if let Ok((_, Some(bag))) = &finished {
        println!("supervisor's audit bag: {}", bag.display());
    }
    let mut errors = Vec::new();
    for c in cells {
        errors.extend(c.stop().1);
    }
    for e in &errors {
        eprintln!("cnc: {e}");
    }
    outcome?;
    finished?;
    if errors.is_empty() {
        Ok(())
    } else {
        Err("a node failed".into())
    }
}

/// One line of the supervisor's view: each machine's status, parts and last cycle time.
fn cell_line(s: &cnc_msgs::msg::CellState) -> String {
    s.machines
        .iter()
        .map(|m| {
            let last = m
                .cycle_times
                .last()
                .map_or(String::new(), |t| format!(", last cycle {t:.2} s"));
            let why = match m.status {
                cnc_msgs::msg::CellMachine::PAUSED | cnc_msgs::msg::CellMachine::UNREACHABLE => {
                    format!(" ({})", m.reason)
                }
                _ => String::new(),
            };
            format!(
                "{} {}{why}: {}/{} parts{last}",
                m.name,
                cnc_cell::supervisor::status_name(m.status),
                m.count,
                m.target
            )
        })
        .collect::<Vec<_>>()
        .join(" | ")
}

/// Loads and runs the program for the requested cycles, printing progress; or just waits.
fn supervise(
    cfg: &LaunchConfig,
    cell: &Cell,
    program: Option<NamedProgram>,
    cycles: u32,
) -> Result<(), String> {
    // The launcher starts programs as the cell's supervisor would (its DDS Security identity).
    let mut client = CellClient::new(
        &cfg.network.with_default_enclave("/cell/supervisor")?,
        &cfg.machine.namespace,
        "cnc_cli",
        ServiceMapping::Enhanced,
    )?;
    let name = program.as_ref().map(|(name, _)| name.clone());
    if let Some((name, text)) = &program {
        client.wait_ready(Duration::from_secs(30))?;
        let r = client.load_program(name, text)?;
        if !r.accepted {
            return Err(format!("load refused: {}", r.message));
        }
    }
    let mut done = 0u32;
    // A cycle is complete when PROGRAM_COMPLETED follows the ACTIVE of this start.
    let mut seen_active = false;
    let mut cycle_running = false;
    // The part count when the cycle started.
    let mut parts_before = 0;
    let mut last_print = Instant::now();
    while !STOP.load(Ordering::SeqCst) {
        if let Some(node) = cell.failed_node() {
            return Err(format!("node {node} stopped"));
        }
        if let Some(name) = &name {
            if !cycle_running {
                if cycles != 0 && done >= cycles {
                    return Ok(());
                }
                parts_before = client.part_count.as_ref().map_or(0, |p| p.count);
                let r = client.start_program(name)?;
                if !r.accepted {
                    return Err(format!("start refused: {}", r.message));
                }
                (cycle_running, seen_active) = (true, false);
            }
            for s in client.poll() {
                match s.execution {
                    MachineState::ACTIVE => seen_active = true,
                    MachineState::PROGRAM_COMPLETED if seen_active => {
                        done += 1;
                        cycle_running = false;
                        // The part count comes from the PLC once it is kept on disk, a little
                        // after the state: the line shows it (a program that counts no part
                        // waits the two seconds).
                        let counted = |c: &CellClient| {
                            c.part_count
                                .as_ref()
                                .is_some_and(|p| p.count > parts_before)
                        };
                        client.wait_until(Duration::from_secs(2), counted);
                        print_progress(&client, done);
                    }
                    MachineState::STOPPED if seen_active => {
                        return Err(format!(
                            "cycle {} stopped: {}",
                            done + 1,
                            alarm_list(&client)
                        ))
                    }
                    _ => {}
                }
            }
        } else {
            client.poll();
        }
        if last_print.elapsed() > Duration::from_millis(500) {
            last_print = Instant::now();
            print_progress(&client, done);
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    Ok(())
}

fn alarm_list(c: &CellClient) -> String {
    let alarms = c
        .alarms
        .as_ref()
        .map(|a| a.alarms.as_slice())
        .unwrap_or_default();
    alarms
        .iter()
        .map(|a| {
            format!(
                "alarm {} ({}): {} [{} line {}]",
                a.number, a.source, a.text, a.program, a.line
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

fn print_progress(c: &CellClient, done: u32) {
    let s = c.state.as_ref();
    let sp = c.spindle.as_ref();
    let pos = c
        .axes
        .as_ref()
        .map(|a| {
            a.axes
                .iter()
                .map(|x| format!("{}{:.3}", x.name, x.actual_position))
                .collect::<Vec<_>>()
                .join(" ")
        })
        .unwrap_or_default();
    // A turn-mill's live tool (D143), where the machine has one.
    let live = c
        .live_tool
        .as_ref()
        .map(|t| format!(" | live tool {:>5.0} rpm", t.actual_rpm))
        .unwrap_or_default();
    println!(
        "{:<17} {} line {:>4} | {} | spindle {:>6.0} rpm (cmd {:.0}){live} | parts {} | cycles done {}",
        s.map(|s| s.execution_name.as_str()).unwrap_or("-"),
        s.map(|s| s.program.as_str()).unwrap_or(""),
        s.map(|s| s.line).unwrap_or(0),
        pos,
        sp.map(|s| s.actual_rpm).unwrap_or(0.0),
        sp.map(|s| s.commanded_rpm).unwrap_or(0.0),
        c.part_count.as_ref().map(|p| p.count).unwrap_or(0),
        done
    );
}
