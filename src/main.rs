//! `cnc`: run a cell on the simulated machine, or check a part program.
//!
//! `cnc run [CONFIG]` runs until Ctrl-C; with `--program FILE --cycles N` it loads and runs the
//! program N times through the cell's own ROS 2 services and exits 0 when done, 1 on any alarm.
//! With no arguments it runs the built-in simulated lathe with the demo part, looping.
//! `cnc run <cell launch file>` runs a whole cell: its machines, robot and supervisor. Where no
//! config is named, the built-in lathe is used ([`cnc::machines`]).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand};
use cnc::cell::Cell;
use cnc::machines;
use cnc_cell::client::CellClient;
use cnc_msgs::msg::MachineState;
use cnc_runtime::LaunchConfig;
use ros2_client::ServiceMapping;

#[derive(Parser)]
#[command(name = "cnc", about = "Soft CNC for robot-tended machine cells")]
struct Cli {
    #[command(subcommand)]
    command: Option<Verb>,
}

#[derive(Subcommand)]
enum Verb {
    /// Start every node of the cell in this process.
    Run {
        /// The launch config: a file, or a built-in machine (sim_lathe, sim_mill, sim_mill_802d, sim_turnmill); default:
        /// the built-in sim_lathe. A cell launch file (`launch_configs/cell_two_lathes.yaml`)
        /// runs all its machines, the robot and the cell supervisor until its order is done.
        #[arg(value_name = "CONFIG")]
        config_file: Option<PathBuf>,
        /// The same as CONFIG.
        #[arg(long, conflicts_with = "config_file")]
        config: Option<PathBuf>,
        /// Load and run this program, then exit.
        #[arg(long)]
        program: Option<PathBuf>,
        /// Cycles to run (with --program). 0 = until Ctrl-C.
        #[arg(long, default_value_t = 1)]
        cycles: u32,
        /// Write the drive trace (every drive tick's setpoints, positions, following errors
        /// and queue depth) to this CSV file; needs `servo.drive_queue_ms` in the config.
        #[arg(long, value_name = "FILE")]
        drive_trace: Option<PathBuf>,
    },
    /// Run one node of the cell in this process (the others run in their own processes or on
    /// other hosts), until Ctrl-C or SIGTERM.
    Node {
        node: NodeName,
        /// The launch config: a file, or a built-in machine (sim_lathe, sim_mill, sim_mill_802d, sim_turnmill); default:
        /// the built-in sim_lathe.
        #[arg(value_name = "CONFIG")]
        config_file: Option<PathBuf>,
        /// The same as CONFIG.
        #[arg(long, conflicts_with = "config_file")]
        config: Option<PathBuf>,
        /// The io node: write the drive trace to this CSV file (as `cnc run --drive-trace`).
        #[arg(long, value_name = "FILE")]
        drive_trace: Option<PathBuf>,
    },
    /// Interpret a program without running it; report every error with line and alarm number.
    Check {
        #[command(flatten)]
        program: ProgramArgs,
        /// Print the canonical block stream, one command per line.
        #[arg(long)]
        trace: bool,
        /// The trace's text: `text` (our golden-file format) or `linuxcnc` (the canonical
        /// calls as LinuxCNC 2.9's `rs274` prints them).
        #[arg(long, default_value = "text", value_parser = ["text", "linuxcnc"])]
        format: String,
    },
    /// Run a program through the interpreter and the planner on a simulated clock: prints
    /// `cycle time: <seconds> s` and can draw the tool path over the turned part.
    Simulate {
        #[command(flatten)]
        program: ProgramArgs,
        /// Write the tool path over the finished 2-D profile as an SVG file (lathes).
        #[arg(long)]
        svg: Option<PathBuf>,
        /// Velocity profile (trapezoidal, s-curve); default: the config's servo.profile.
        #[arg(long)]
        profile: Option<ProfileArg>,
        /// Also print motion's CPU time per servo tick (p50, p99, max).
        #[arg(long)]
        timing: bool,
    },
    /// Check a PLC ladder program (mnemonic text): prints its size, or the first error with
    /// its line and reason; `--rungs` lists the program rung by rung.
    PlcCheck {
        file: PathBuf,
        #[arg(long)]
        rungs: bool,
    },
    /// Recordings (bags) of the machine's topics.
    Record {
        #[command(subcommand)]
        action: RecordVerb,
    },
    /// Operators who may log in to the web panel (`hmi.operators_file`, default
    /// `operators.yaml` beside the launch config).
    Operator {
        #[command(subcommand)]
        action: OperatorVerb,
        /// The launch config: a file, or a built-in machine (sim_lathe, sim_mill, sim_mill_802d, sim_turnmill); default:
        /// the built-in sim_lathe.
        #[arg(long, global = true)]
        config: Option<PathBuf>,
    },
    /// DDS Security for a cell.
    Security {
        #[command(subcommand)]
        action: SecurityVerb,
    },
    /// Tamper evidence of recordings.
    Audit {
        #[command(subcommand)]
        action: AuditVerb,
    },
    /// Publish a recording on DDS again with its original timing, under
    /// `/<namespace>_replay/...` unless `--namespace` names another.
    Replay {
        bag: PathBuf,
        /// The launch config whose network section (domain, interfaces) is used: a file, or a
        /// built-in machine (sim_lathe, sim_mill, sim_mill_802d, sim_turnmill); default: the built-in sim_lathe.
        #[arg(long)]
        config: Option<PathBuf>,
        #[arg(long)]
        namespace: Option<String>,
        /// 2 = twice as fast.
        #[arg(long, default_value_t = 1.0)]
        speed: f64,
        /// Start once this topic (e.g. `axes`) has a reader (up to 10 s).
        #[arg(long)]
        wait_for: Option<String>,
    },
}

#[derive(Subcommand)]
enum RecordVerb {
    /// Repair a bag (or one .mcap file) cut off by a crash: keeps everything up to the last
    /// flushed chunk, adds the index and rewrites metadata.yaml.
    Recover { bag: PathBuf },
}

#[derive(Subcommand)]
enum OperatorVerb {
    /// Add an operator or change their password: the password is read from the first line of
    /// standard input; only its salted hash is stored.
    Set { name: String },
    /// Remove an operator.
    Remove { name: String },
    /// List the operators.
    List,
}

#[derive(Subcommand)]
enum SecurityVerb {
    /// Make the cell's keystore (SROS2 layout): one authority, and an enclave for each
    /// machine (`/<machine>`), `/cell/supervisor`, `/cell/robot` and `/cell/observer`, each with
    /// its certificate, key and signed permissions. Refused if the folder exists.
    Init {
        keystore: PathBuf,
        /// A machine's namespace (`lathe1`); repeat for each machine of the cell.
        #[arg(long = "machine", required = true)]
        machines: Vec<String>,
        /// `encrypt` (the default): every message authenticated, the samples, submessages and
        /// discovery encrypted; `sign`: every message authenticated, nothing encrypted.
        #[arg(long, default_value = "encrypt", value_parser = cnc::keystore::Protection::parse)]
        protection: cnc::keystore::Protection,
    },
}

#[derive(Subcommand)]
enum AuditVerb {
    /// Check a bag's audit chain; exits 1 and names the first altered or missing chunk.
    Verify { bag: PathBuf },
}

/// A part program and what it is read with.
#[derive(clap::Args)]
struct ProgramArgs {
    program: PathBuf,
    /// The launch config that describes the machine: a file, or a built-in machine
    /// (sim_lathe, sim_mill, sim_mill_802d, sim_turnmill); default: the built-in sim_lathe.
    #[arg(long, visible_alias = "launch")]
    config: Option<PathBuf>,
    /// The program's dialect; default: the config's (`sinumerik` is `sinumerik-802d`).
    #[arg(long, value_parser = dialect_names())]
    dialect: Option<String>,
    /// Folder of subprograms (O number on the first line or file name O1234.nc);
    /// default: the program's folder.
    #[arg(long)]
    library: Option<PathBuf>,
    /// Mill tool table (`number length_mm diameter_mm` per line) instead of the config's
    /// `machine.tool_table`: H<n> is the length, D<n> the radius of entry n.
    #[arg(long)]
    tools: Option<PathBuf>,
    /// The tool in the spindle when the program starts, as the machine would hold it
    /// (default: the config's `machine.tool_in_spindle`, else none).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=32000))]
    tool_in_spindle: Option<u32>,
}

/// The dialects `--dialect` takes, with `sinumerik` for the 802D.
fn dialect_names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(cnc_runtime::config::DIALECTS.map(|d| {
        let v = clap::builder::PossibleValue::new(d);
        if d == "sinumerik-802d" {
            v.alias("sinumerik")
        } else {
            v
        }
    }))
}

/// A program ready to interpret: the launch config, its text, the dialect (the command
/// line's, else the config's) and the subprogram library (the folder given, else the
/// program's own).
struct LoadedProgram {
    cfg: LaunchConfig,
    text: String,
    dialect: cnc_interpreter::Dialect,
    library: cnc_interpreter::Library,
}

impl ProgramArgs {
    fn load(&self) -> Result<LoadedProgram, String> {
        use cnc_interpreter::Dialect;
        let (mut cfg, _) = machines::load(self.config.as_deref(), self.tools.as_deref())?;
        if let Some(t) = self.tool_in_spindle {
            cfg.machine.tool_in_spindle = t;
        }
        let text = read_program(&self.program)?;
        let name = self.dialect.as_deref().unwrap_or(&cfg.machine.dialect);
        let dialect = Dialect::from_name(name).ok_or_else(|| {
            let known: Vec<&str> = Dialect::ALL.iter().map(|d| d.name()).collect();
            format!("unknown dialect {name:?}; known: {}", known.join(", "))
        })?;
        let dir = match &self.library {
            Some(d) => d.clone(),
            None => self
                .program
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .unwrap_or(Path::new("."))
                .to_path_buf(),
        };
        // Files that are not programs or repeat a number are left out of the library.
        let (library, _skipped) = cnc_task::library::load_dir(&dir)
            .map_err(|e| format!("library {}: {e}", dir.display()))?;
        Ok(LoadedProgram {
            cfg,
            text,
            dialect,
            library,
        })
    }
}

static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    STOP.store(true, Ordering::SeqCst);
}

fn main() -> ExitCode {
    cnc_runtime::heap::return_large_blocks();
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("warn,rustdds=off,ros2_client=error"),
    )
    .init();
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Verb::Run {
            config_file,
            config,
            program,
            cycles,
            drive_trace,
        }) => program
            .as_deref()
            .map(read_named_program)
            .transpose()
            .and_then(|p| run(config_file.or(config).as_deref(), p, cycles, drive_trace)),
        Some(Verb::Check {
            program,
            trace,
            format,
        }) => check(&program, trace.then_some(format.as_str())),
        Some(Verb::Node {
            node,
            config_file,
            config,
            drive_trace,
        }) => run_node(node, config_file.or(config).as_deref(), drive_trace),
        Some(Verb::Simulate {
            program,
            svg,
            profile,
            timing,
        }) => simulate(
            &program,
            svg.as_deref(),
            cnc::simulate::Options {
                profile: profile.map(ProfileArg::shape),
                timing,
            },
        ),
        Some(Verb::PlcCheck { file, rungs }) => plc_check(&file, rungs),
        Some(Verb::Record {
            action: RecordVerb::Recover { bag },
        }) => cnc_recorder::recover::recover(&bag).map(|lines| {
            for l in lines {
                println!("{l}");
            }
        }),
        Some(Verb::Audit {
            action: AuditVerb::Verify { bag },
        }) => audit_verify(&bag),
        Some(Verb::Operator { action, config }) => operator(action, config.as_deref()),
        Some(Verb::Security {
            action:
                SecurityVerb::Init {
                    keystore,
                    machines,
                    protection,
                },
        }) => cnc::keystore::cell_enclaves(&machines)
            .and_then(|enclaves| cnc::keystore::init(&keystore, &enclaves, protection))
            .map(|folders| {
                println!(
                    "keystore {}: {} enclaves",
                    keystore.display(),
                    folders.len()
                );
                for f in folders {
                    println!("  {}", f.display());
                }
            }),
        Some(Verb::Replay {
            bag,
            config,
            namespace,
            speed,
            wait_for,
        }) => replay(
            &bag,
            config.as_deref(),
            cnc_recorder::replay::ReplayOptions {
                namespace,
                speed,
                wait_for,
            },
        ),
        None => {
            let (name, text) = machines::DEMO_PROGRAM;
            run(None, Some((name.into(), text.into())), 0, None)
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cnc: {e}");
            ExitCode::FAILURE
        }
    }
}

fn audit_verify(bag: &Path) -> Result<(), String> {
    use cnc_recorder::audit::{verify, Verdict};
    match verify(bag)? {
        Verdict::Intact {
            files,
            chunks,
            last,
        } => {
            println!(
                "{}: intact ({chunks} chunks in {files} files), last hash {}",
                bag.display(),
                cnc_recorder::chain::hex(&last)
            );
            Ok(())
        }
        Verdict::Altered(why) => Err(format!("ALTERED: {why}")),
    }
}

fn replay(
    bag: &Path,
    config: Option<&Path>,
    options: cnc_recorder::replay::ReplayOptions,
) -> Result<(), String> {
    let (cfg, _) = machines::load(config, None)?;
    install_signal_handlers();
    let r =
        cnc_recorder::replay::replay(bag, &cfg.network, &options, &|| STOP.load(Ordering::SeqCst))?;
    println!(
        "replayed {} messages under /{} in {:.1} s ({} skipped)",
        r.sent, r.namespace, r.seconds, r.skipped
    );
    Ok(())
}

fn install_signal_handlers() {
    // SAFETY: installing a handler that only stores to an atomic.
    unsafe {
        libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
    }
}

fn plc_check(file: &Path, rungs: bool) -> Result<(), String> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let program =
        cnc_plc::Program::parse(&text).map_err(|e| format!("{}: refused: {e}", file.display()))?;
    let all = program.rungs();
    println!(
        "{}: {} steps, {} rungs (level 1: {} steps, level 2: {} steps), {} subroutines",
        file.display(),
        program.steps.len(),
        all.len(),
        program.level1().len(),
        program.level2().len(),
        program.subroutines.len()
    );
    if rungs {
        for (k, r) in all.iter().enumerate() {
            let steps = &program.steps[r.clone()];
            let line = steps.first().map_or(0, |s| s.line);
            let text: Vec<&str> = steps.iter().map(|s| s.text.as_str()).collect();
            println!("{k:4} (line {line}): {}", text.join(" | "));
        }
    }
    Ok(())
}

/// `trace`: print the canonical stream in that format (`text` or `linuxcnc`).
fn check(args: &ProgramArgs, trace: Option<&str>) -> Result<(), String> {
    use cnc_interpreter::diagnose;
    let LoadedProgram {
        cfg,
        text,
        dialect,
        library: lib,
    } = args.load()?;
    let program = args.program.as_path();
    let letters = cfg.axis_letters();
    let setup = cnc_task::node::setup_from_config(&cfg, &cfg.home());
    let errors = diagnose(dialect, &text, setup.clone(), lib.clone());
    if let Some(format) = trace {
        use std::io::Write;
        let setup_axes = setup.axes.clone();
        let mut interp = cnc_interpreter::Interpreter::with_library(dialect, &text, setup, lib);
        let diameter: Vec<bool> = cfg.machine.axes.iter().map(|a| a.diameter).collect();
        let plane = cfg
            .machine
            .arc_plane
            .clone()
            .map(|p| p.chars().next().unwrap_or('X'));
        let mut linuxcnc = cnc_interpreter::trace::LinuxCnc::new(&letters, &diameter, plane);
        let mut out = std::io::BufWriter::new(std::io::stdout().lock());
        let mut count = 0;
        let mut calls = String::new();
        while let Ok(Some(c)) = interp.next_command() {
            count += 1;
            if count > cnc_interpreter::interpreter::MAX_CHECK_COMMANDS {
                break; // the diagnosis above reports the endless program
            }
            let written = if format == "linuxcnc" {
                calls.clear();
                linuxcnc.write(&c, &mut calls);
                out.write_all(calls.as_bytes())
            } else {
                // The program's axes: a turn-mill's C and live tool too (D141, D142).
                writeln!(out, "{}", cnc_interpreter::trace::line(&setup_axes, &c))
            };
            written.map_err(|e| format!("stdout: {e}"))?;
        }
        out.flush().map_err(|e| format!("stdout: {e}"))?;
    }
    if errors.is_empty() {
        eprintln!("{}: no alarm ({})", program.display(), dialect.name());
        return Ok(());
    }
    for e in &errors {
        eprintln!("{}: {e}", program.display());
    }
    Err(format!("{} alarm(s)", errors.len()))
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum ProfileArg {
    Trapezoidal,
    SCurve,
}

impl ProfileArg {
    fn shape(self) -> cnc_runtime::config::ProfileShape {
        match self {
            ProfileArg::Trapezoidal => cnc_runtime::config::ProfileShape::Trapezoidal,
            ProfileArg::SCurve => cnc_runtime::config::ProfileShape::SCurve,
        }
    }
}

fn simulate(
    args: &ProgramArgs,
    svg: Option<&Path>,
    options: cnc::simulate::Options,
) -> Result<(), String> {
    let p = args.load()?;
    let sim = cnc::simulate::simulate(&p.cfg, p.dialect, &p.text, p.library, options)
        .map_err(|e| format!("{}: {e}", args.program.display()))?;
    print!("{}", cnc::simulate::report(&sim));
    if let Some(path) = svg {
        if sim.path.is_empty() {
            return Err("--svg draws turned parts: the machine needs X and Z axes".into());
        }
        std::fs::write(path, cnc::simulate::svg(&sim))
            .map_err(|e| format!("{}: {e}", path.display()))?;
        eprintln!("tool path and part drawn in {}", path.display());
    }
    Ok(())
}

fn read_program(path: &Path) -> Result<String, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    String::from_utf8(bytes).map_err(|_| format!("{}: not UTF-8 text", path.display()))
}

fn program_name(path: &Path) -> String {
    path.file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("program")
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || "._-".contains(*c))
        .collect()
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum NodeName {
    Io,
    Plc,
    Motion,
    Interpreter,
    HmiBridge,
    Recorder,
}

impl NodeName {
    /// The node's name in its instance lock, as the in-process cell names it.
    fn lock_name(&self) -> &'static str {
        match self {
            NodeName::Io => "io",
            NodeName::Plc => "plc",
            NodeName::Motion => "motion",
            NodeName::Interpreter => "interpreter",
            NodeName::HmiBridge => "hmi_bridge",
            NodeName::Recorder => "recorder",
        }
    }
}

fn run_node(
    node: NodeName,
    config: Option<&Path>,
    drive_trace: Option<PathBuf>,
) -> Result<(), String> {
    let (mut cfg, _) = machines::load(config, None)?;
    with_drive_trace(&mut cfg, drive_trace)?;
    install_signal_handlers();
    let inst =
        cnc_runtime::shm::instance(&cfg.machine.namespace, cfg.network.effective_domain_id()?);
    // Held until this process ends: a second copy of this node of this machine is refused.
    let _lock = cnc_runtime::instance_lock::acquire(&inst, node.lock_name())?;
    cnc::cell::clean_dead_nodes();
    let shutdown = cnc_runtime::Shutdown::default();
    let s = shutdown.clone();
    let worker = std::thread::spawn(move || match node {
        NodeName::Io => cnc_io::node::run(cfg, inst, s),
        NodeName::Plc => cnc_plc::node::run(cfg, inst, s).map(|_| String::new()),
        NodeName::Motion => cnc_motion::node::run(cfg, inst, s),
        NodeName::Interpreter => cnc_task::node::run(cfg, inst, s).map(|_| String::new()),
        NodeName::HmiBridge => cnc_hmi_bridge::node::run(cfg, s).map(|_| String::new()),
        NodeName::Recorder => {
            cnc_recorder::node::run(cfg, s).map(|dir| format!("recorded into {}", dir.display()))
        }
    });
    while !STOP.load(Ordering::SeqCst) && !worker.is_finished() {
        std::thread::sleep(Duration::from_millis(50));
    }
    shutdown.request();
    let summary = worker.join().map_err(|_| "node panicked".to_string())??;
    if !summary.is_empty() {
        println!("{summary}");
    }
    Ok(())
}

/// A program to run: its name in program memory and its text.
type NamedProgram = (String, String);

fn read_named_program(path: &Path) -> Result<NamedProgram, String> {
    Ok((program_name(path), read_program(path)?))
}

/// The drive trace named on the command line, which needs the drives' queue.
fn with_drive_trace(cfg: &mut LaunchConfig, trace: Option<PathBuf>) -> Result<(), String> {
    if let Some(path) = trace {
        if cfg.servo.drive_queue_ms <= 0.0 {
            return Err(
                "--drive-trace: the drives run lock-step in this config; set servo.drive_queue_ms"
                    .into(),
            );
        }
        cfg.servo.drive_trace = Some(path);
    }
    Ok(())
}

fn run(
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
    println!(
        "{:<17} {} line {:>4} | {} | spindle {:>6.0} rpm (cmd {:.0}) | parts {} | cycles done {}",
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

/// `cnc operator …`: edits the operators file of the config's web panel.
fn operator(action: OperatorVerb, config: Option<&Path>) -> Result<(), String> {
    use cnc_hmi_bridge::web::login::{self, OperatorsFile};
    let (cfg, _) = machines::load(config, None)?;
    let path = cfg
        .hmi
        .operators_file
        .clone()
        .ok_or("the launch config names no hmi.operators_file")?;
    let mut file = match path.exists() {
        true => OperatorsFile::load(&path)?,
        false => OperatorsFile::default(),
    };
    match action {
        OperatorVerb::List => {
            for name in file.operators.keys() {
                println!("{name}");
            }
            return Ok(());
        }
        OperatorVerb::Remove { name } => {
            if file.operators.remove(&name).is_none() {
                return Err(format!("no operator {name:?} in {}", path.display()));
            }
        }
        OperatorVerb::Set { name } => {
            if !OperatorsFile::valid_name(&name) {
                return Err(format!(
                    "operator name {name:?}: 1 to 32 letters, digits, '_', '-' or '.'"
                ));
            }
            let mut password = String::new();
            std::io::stdin()
                .read_line(&mut password)
                .map_err(|e| format!("password from standard input: {e}"))?;
            let password = password.trim_end_matches(['\r', '\n']);
            if password.chars().count() < 8 {
                return Err("the password needs at least 8 characters".into());
            }
            let salt = login::random(16)?;
            let hash = login::hash_password(password, &salt, login::ITERATIONS);
            file.operators.insert(name, hash);
        }
    }
    let text = serde_yaml::to_string(&file).map_err(|e| e.to_string())?;
    cnc_runtime::persist::write_atomic(&path, &text)?;
    // Hashes are not secrets, but nobody else needs to read them.
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600))
        .map_err(|e| format!("{}: {e}", path.display()))?;
    println!("operators in {}: {}", path.display(), file.operators.len());
    Ok(())
}
