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
use std::time::Duration;

mod run_verb;

use clap::{Parser, Subcommand};
use cnc::machines;
use cnc_runtime::LaunchConfig;

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

pub(crate) static STOP: AtomicBool = AtomicBool::new(false);

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
            .and_then(|p| run_verb::run(config_file.or(config).as_deref(), p, cycles, drive_trace)),
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
            run_verb::run(None, Some((name.into(), text.into())), 0, None)
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

pub(crate) fn install_signal_handlers() {
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
pub(crate) type NamedProgram = (String, String);

fn read_named_program(path: &Path) -> Result<NamedProgram, String> {
    Ok((program_name(path), read_program(path)?))
}

/// The drive trace named on the command line, which needs the drives' queue.
pub(crate) fn with_drive_trace(
    cfg: &mut LaunchConfig,
    trace: Option<PathBuf>,
) -> Result<(), String> {
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
