//! A new user's first hour: the `cnc` binary, copied out of the build as `cargo install` does,
//! run from folders that know nothing of the repository, with `HOME` in a temporary folder.
//! It checks and simulates programs on its built-in machines, runs a program on the built-in
//! lathe and keeps its files in the data folder the README names, and starts the demo cell
//! without a warning from a dependency.

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

const REPO: &str = env!("CARGO_MANIFEST_DIR");

/// The cells these tests start serve the web panel on the default 127.0.0.1:8080: one at a time.
static CELL: Mutex<()> = Mutex::new(());

/// A temporary user: a home folder, a working folder, and `cnc` installed under `root/bin`.
struct User {
    home: PathBuf,
    work: PathBuf,
    cnc: PathBuf,
}

impl User {
    fn new(name: &str) -> User {
        let base =
            std::env::temp_dir().join(format!("cnc_first_hour_{}_{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        let (home, work, bin) = (base.join("home"), base.join("work"), base.join("root/bin"));
        for d in [&home, &work, &bin] {
            std::fs::create_dir_all(d).unwrap();
        }
        let cnc = bin.join("cnc");
        // A hard link opens no file for writing: a copy's open descriptor, inherited by a
        // child another test forks meanwhile, would make the binary "text file busy".
        if std::fs::hard_link(env!("CARGO_BIN_EXE_cnc"), &cnc).is_err() {
            std::fs::copy(env!("CARGO_BIN_EXE_cnc"), &cnc).unwrap();
        }
        User { home, work, cnc }
    }

    /// `cnc ARGS` in the working folder, with this user's home and no XDG_DATA_HOME.
    fn command(&self, args: &[&str]) -> Command {
        let mut c = Command::new(&self.cnc);
        c.current_dir(&self.work)
            .args(args)
            .env("HOME", &self.home)
            .env_remove("XDG_DATA_HOME")
            .env_remove("RUST_LOG");
        c
    }

    fn run(&self, args: &[&str]) -> Output {
        busy_retry(|| self.command(args).output())
    }

    /// The data folder of the built-in lathe, as the README says.
    fn data(&self) -> PathBuf {
        self.home.join(".local/share/cnc/sim_lathe")
    }
}

/// Runs `f` again while the binary is "text file busy" (a copied binary, see [`User::new`]).
fn busy_retry<T>(mut f: impl FnMut() -> std::io::Result<T>) -> T {
    for _ in 0..100 {
        match f() {
            Err(e) if e.raw_os_error() == Some(libc::ETXTBSY) => {
                std::thread::sleep(Duration::from_millis(20))
            }
            other => return other.unwrap(),
        }
    }
    panic!("the binary stayed busy")
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

#[test]
fn check_and_simulate_work_from_any_folder() {
    let user = User::new("check");
    let demo = format!("{REPO}/examples/lathe/demo_shaft.nc");
    let out = user.run(&["check", &demo]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        text(&out).contains("no alarm (huaxing-lathe)"),
        "{}",
        text(&out)
    );

    let out = user.run(&["simulate", &demo]);
    assert!(out.status.success(), "{}", text(&out));
    let seconds: f64 = String::from_utf8_lossy(&out.stdout)
        .lines()
        .find_map(|l| {
            l.strip_prefix("cycle time: ")?
                .strip_suffix(" s")?
                .parse()
                .ok()
        })
        .unwrap_or_else(|| panic!("no cycle time: {}", text(&out)));
    assert!(seconds > 1.0, "{seconds}");

    // The built-in mill, by name, with a program of the LinuxCNC oracle.
    let mill = format!("{REPO}/tests/oracle/04_full_circle_and_helix.ngc");
    let out = user.run(&["check", "--config", "sim_mill", &mill, "--trace"]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        text(&out).contains("no alarm (fanuc-mill)"),
        "{}",
        text(&out)
    );
    assert!(text(&out).contains("ARC"), "{}", text(&out));

    // The built-in 802D mill, by name, simulates the manual's compensated contour as printed.
    let contour = format!("{REPO}/../shared/fixtures/001/061_trc_complete_example.mpf");
    let out = user.run(&["simulate", "--config", "sim_mill_802d", &contour]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(text(&out).contains("cycle time: "), "{}", text(&out));

    // A config that is neither a file nor a built-in machine is named, with the choices.
    let out = user.run(&["check", "--config", "sim_lathe.yaml", &demo]);
    assert!(!out.status.success());
    assert!(
        text(&out).contains("sim_lathe.yaml: no such launch config file, nor a built-in machine (sim_lathe, sim_mill, sim_mill_802d, sim_turnmill)"),
        "{}",
        text(&out)
    );
    // Nothing was written: checking is reading.
    assert_eq!(std::fs::read_dir(&user.work).unwrap().count(), 0);
    assert!(!user.data().exists());
}

#[test]
fn help_and_dialect_choices_name_every_dialect_of_the_interpreter() {
    let user = User::new("help");
    let out = user.run(&["check", "--help"]);
    let help = text(&out);
    for d in cnc_runtime::config::DIALECTS {
        assert!(help.contains(d), "{d} missing from check --help:\n{help}");
    }
    let demo = format!("{REPO}/examples/lathe/demo_shaft.nc");
    let out = user.run(&["check", "--dialect", "heidenhain", &demo]);
    assert!(!out.status.success());
    assert!(
        text(&out).contains(
            "possible values: huaxing-lathe, gtc2e-lathe, iso-lathe, fanuc-mill, sinumerik-802d"
        ),
        "{}",
        text(&out)
    );
    // `sinumerik` names the 802D: the lathe program is read in its dialect, whose syntax
    // alarm 12080 refuses the FANUC-style comment in its first line.
    let out = user.run(&["check", "--dialect", "sinumerik", &demo]);
    assert!(
        text(&out).contains("alarm 12080 at line 1"),
        "{}",
        text(&out)
    );
    assert!(!text(&out).contains("invalid value"), "{}", text(&out));
}

#[test]
fn an_installed_cnc_runs_a_program_and_keeps_its_files_in_its_data_folder() {
    let _one = CELL.lock().unwrap_or_else(|e| e.into_inner());
    let user = User::new("run");
    // #200-#289 are kept (Huaxing); the memory file holds them after the run.
    std::fs::write(
        user.work.join("part.nc"),
        "#200=12.5\nG00 X100 Z20\nS500 M03\nG01 Z10 F3000\nM05\nM30\n",
    )
    .unwrap();
    let mut child = busy_retry(|| {
        user.command(&["run", "--program", "part.nc", "--cycles", "1"])
            .env("ROS_DOMAIN_ID", "61")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
    });
    let lines = read_lines(&mut child, usize::MAX, Duration::from_secs(120));
    let status = finish(&mut child, &lines);
    let all = lines.join("\n");
    assert!(status.success() && all.contains("cycles done 1"), "{all}");
    let data = user.data();
    assert!(
        all.contains(&format!(
            "built-in sim_lathe, files under {}",
            data.display()
        )),
        "{all}"
    );

    let memory = std::fs::read_to_string(data.join("state/lathe1_memory.yaml"))
        .unwrap_or_else(|e| panic!("memory file: {e}\n{all}"));
    assert!(
        memory.contains("200") && memory.contains("12.5"),
        "{memory}"
    );
    assert!(data.join("state/lathe1_plc_memory.yaml").is_file(), "{all}");
    let bags: Vec<PathBuf> = std::fs::read_dir(data.join("records"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(bags.len(), 1, "{bags:?}");
    assert!(bags[0].join("metadata.yaml").is_file(), "{:?}", bags[0]);
    // Only the program is in the working folder.
    let here: Vec<_> = std::fs::read_dir(&user.work).unwrap().collect();
    assert_eq!(here.len(), 1, "{here:?}");

    // The auditor's tool reads the recording from anywhere.
    let out = user.run(&["audit", "verify", bags[0].to_str().unwrap()]);
    assert!(
        out.status.success() && text(&out).contains("intact"),
        "{}",
        text(&out)
    );
}

#[test]
fn the_demo_cell_starts_without_a_warning_from_a_dependency() {
    let _one = CELL.lock().unwrap_or_else(|e| e.into_inner());
    let user = User::new("demo");
    let mut child = busy_retry(|| {
        user.command(&[])
            .env("ROS_DOMAIN_ID", "62")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
    });
    // 20 lines: the banner, where files go, and the demo part's progress.
    let lines = read_lines(&mut child, 20, Duration::from_secs(120));
    // SAFETY: a signal to our own child process.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
    let first = lines.join("\n");
    let status = finish(&mut child, &lines);
    assert!(lines.len() >= 20, "{first}");
    assert!(
        lines[0].starts_with("cell 'lathe1' running (built-in sim_lathe"),
        "{first}"
    );
    assert!(first.contains("demo_shaft.nc line"), "{first}");
    for l in &lines {
        let lower = l.to_ascii_lowercase();
        assert!(
            !(l.contains("[W]") || l.contains("WARN") || lower.contains("warning")),
            "a warning in the first 20 lines: {l}\n{first}"
        );
    }
    assert!(
        status.success(),
        "Ctrl-C ends the demo with exit 0\n{first}"
    );
}

/// Lines from the child's stdout and stderr as they come, until `count` lines, the end of both,
/// or `limit`.
fn read_lines(child: &mut std::process::Child, count: usize, limit: Duration) -> Vec<String> {
    let (tx, rx) = std::sync::mpsc::channel();
    let out = child.stdout.take().unwrap();
    let err = child.stderr.take().unwrap();
    let t = tx.clone();
    std::thread::spawn(move || forward(out, t));
    std::thread::spawn(move || forward(err, tx));
    let deadline = Instant::now() + limit;
    let mut lines = Vec::new();
    while lines.len() < count {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(l) => lines.push(l),
            Err(_) => break, // both ended, or the limit
        }
    }
    lines
}

/// Sends the lines read from `from`; reads on to the end when nobody listens any more, so the
/// child never blocks on a full pipe.
fn forward(from: impl std::io::Read, to: std::sync::mpsc::Sender<String>) {
    for line in BufReader::new(from).lines().map_while(Result::ok) {
        let _ = to.send(line);
    }
}

/// The child's exit status; one still running after 60 s is killed and the test fails.
fn finish(child: &mut std::process::Child, lines: &[String]) -> std::process::ExitStatus {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("cnc did not end:\n{}", lines.join("\n"));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// A failed install names its step, the command and apt's own reason, and stops the script.
/// Run with a PATH that has no `ip` and no Python and an `apt-get` that refuses, so nothing on
/// this machine is touched.
#[test]
fn a_failed_install_step_says_which_and_why() {
    let base = std::env::temp_dir().join(format!("cnc_setup_{}", std::process::id()));
    let bin = base.join("bin");
    let _ = std::fs::remove_dir_all(&base);
    std::fs::create_dir_all(&bin).unwrap();
    let apt = "#!/bin/sh\n[ \"$1\" = update ] && exit 0\n\
               for p; do last=$p; done\n\
               echo \"E: Unable to locate package $last\" >&2\nexit 100\n";
    std::fs::write(bin.join("apt-get"), apt).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(bin.join("apt-get"), std::fs::Permissions::from_mode(0o755)).unwrap();
    for tool in ["dirname", "mktemp", "rm", "tail", "sed", "cat"] {
        let real = ["/usr/bin", "/bin"]
            .iter()
            .map(|d| PathBuf::from(d).join(tool))
            .find(|p| p.exists())
            .unwrap_or_else(|| panic!("{tool} not found"));
        std::os::unix::fs::symlink(real, bin.join(tool)).unwrap();
    }
    let out = Command::new("/bin/bash")
        .arg(format!("{REPO}/scripts/setup.sh"))
        .env_clear()
        .env("PATH", &bin)
        .output()
        .unwrap();
    let all = text(&out);
    assert_eq!(out.status.code(), Some(1), "{all}");
    assert!(
        all.contains(
            "setup: system: missing ip python3-venv: apt-get install iproute2 python3-venv"
        ),
        "{all}"
    );
    assert!(
        all.contains("setup: step 'system' FAILED: `apt-get install -y --no-install-recommends iproute2 python3-venv` exited 100"),
        "{all}"
    );
    assert!(
        all.contains("E: Unable to locate package python3-venv"),
        "{all}"
    );
    // Nothing after the failed step ran.
    assert!(!all.contains("setup: chromium"), "{all}");
}
