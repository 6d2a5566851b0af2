//! Issue 47: the boundaries ARCHITECTURE.md states, enforced by Cargo. Each pure crate's
//! normal dependency tree (`cargo tree -e normal`, features resolved for that crate alone, as
//! `cargo build -p` resolves them) must not reach the transports, the runtime or the clock's
//! and threads' crates: then no code in it can use them, whatever its author meant.

use std::process::Command;

/// The crates of `package`'s normal dependency tree.
fn tree(package: &str) -> Vec<String> {
    let out = Command::new(env!("CARGO"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "tree",
            "-p",
            package,
            "-e",
            "normal",
            "--prefix",
            "none",
            "--offline",
        ])
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree -p {package}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(String::from)
        .collect()
}

const TRANSPORTS: [&str; 5] = ["ros2-client", "rustdds", "iceoryx2", "cnc_runtime", "smol"];

#[test]
fn the_pure_cores_cannot_reach_dds_iceoryx2_or_the_runtime() {
    for package in [
        "cnc_machine",
        "cnc_interpreter_core",
        "cnc_interpreter",
        "cnc_task_core",
        "cnc_motion_core",
        "cnc_plc_core",
        "cnc_sim_machine",
    ] {
        let crates = tree(package);
        assert!(crates.iter().any(|c| c == package), "{package}: {crates:?}");
        let reached: Vec<&String> = crates
            .iter()
            .filter(|c| TRANSPORTS.contains(&c.as_str()))
            .collect();
        assert!(reached.is_empty(), "{package} reaches {reached:?}");
    }
}

/// The machine's own crates, which the cell's programs must not reach. (`cnc_machine`, the
/// launch config's description of a machine, is public: the runtime reads launch files with it.)
const MACHINE_CRATES: [&str; 11] = [
    "cnc_interpreter_core",
    "cnc_interpreter",
    "cnc_task_core",
    "cnc_task",
    "cnc_motion_core",
    "cnc_motion",
    "cnc_plc_core",
    "cnc_plc",
    "cnc_sim_machine",
    "cnc_io",
    "cnc_hmi_bridge",
];

/// The supervisor and the robot are clients of the machines' public interface (DDS topics and
/// services) only, as a program nobody here wrote would be: their crate reaches no crate of
/// the machine, so it cannot call into one.
#[test]
fn the_cell_programs_reach_the_machines_through_their_public_interface_only() {
    let crates = tree("cnc_cell");
    assert!(crates.iter().any(|c| c == "cnc_cell"), "{crates:?}");
    assert!(crates.iter().any(|c| c == "cnc_msgs"), "{crates:?}");
    let reached: Vec<&String> = crates
        .iter()
        .filter(|c| MACHINE_CRATES.contains(&c.as_str()))
        .collect();
    assert!(reached.is_empty(), "cnc_cell reaches {reached:?}");
}

/// The functions of a Rust source longer than `limit` lines: name, first line, length. A
/// function runs from its `fn` line to the line its braces close (strings, characters and
/// comments are skipped when counting braces).
fn long_functions(text: &str, limit: usize) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut found = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some(at) = words.iter().position(|w| *w == "fn") else {
            continue;
        };
        if words[..at].iter().any(|w| {
            !matches!(
                *w,
                "pub" | "pub(crate)" | "pub(super)" | "async" | "const" | "unsafe"
            )
        }) {
            continue;
        }
        let name = words
            .get(at + 1)
            .map_or("", |w| w.split(['(', '<']).next().unwrap_or(""));
        let (mut depth, mut opened) = (0i64, false);
        for (j, l) in lines.iter().enumerate().skip(i) {
            let code = strip_literals(l);
            for c in code.chars() {
                match c {
                    '{' => {
                        depth += 1;
                        opened = true;
                    }
                    '}' => depth -= 1,
                    _ => {}
                }
            }
            if !opened && code.trim_end().ends_with(';') {
                break; // a declaration without a body
            }
            if opened && depth == 0 {
                if j - i + 1 > limit {
                    found.push((name.to_string(), i + 1, j - i + 1));
                }
                break;
            }
        }
    }
    found
}

/// A line without its string and character literals and its comment.
fn strip_literals(line: &str) -> String {
    let mut out = String::new();
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                while let Some(d) = chars.next() {
                    match d {
                        '\\' => {
                            chars.next();
                        }
                        '"' => break,
                        _ => {}
                    }
                }
            }
            '\'' => {
                // A character literal ('{', '\n') or a lifetime ('a): skip the literal only.
                let rest: String = chars.clone().take(3).collect();
                if let Some(escaped) = rest.strip_prefix('\\') {
                    let end = escaped.find('\'').map_or(0, |k| k + 2);
                    for _ in 0..end {
                        chars.next();
                    }
                } else if rest.chars().nth(1) == Some('\'') {
                    chars.next();
                    chars.next();
                }
            }
            '/' if chars.peek() == Some(&'/') => break,
            _ => out.push(c),
        }
    }
    out
}

fn rust_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("source folder") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Issue 47: a node shell is thin — no function in one is over 150 lines. The shells are the
/// crates that bind a core to the transports (task, motion, hmi_bridge, the cell's programs)
/// and the `node.rs` of
/// the nodes whose core shares their crate (plc, io, recorder).
#[test]
fn no_function_in_a_node_shell_is_over_150_lines() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for shell in [
        "nodes/task/src",
        "nodes/motion/src",
        "nodes/hmi_bridge/src",
        "cell/src",
    ] {
        rust_files(&root.join(shell), &mut files);
    }
    for node in ["plc", "io", "recorder"] {
        files.push(root.join(format!("nodes/{node}/src/node.rs")));
    }
    assert!(files.len() > 20, "{files:?}");
    let mut long = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).expect("source");
        for (name, line, length) in long_functions(&text, 150) {
            long.push(format!("{}:{line} {name}: {length} lines", f.display()));
        }
    }
    assert!(long.is_empty(), "{long:#?}");
    // The scanner finds what it should.
    let sample = format!(
        "fn short() {{\n}}\npub fn long() {{\n{}}}\n",
        "    let c = '{';\n".repeat(151)
    );
    assert_eq!(long_functions(&sample, 150), [("long".to_string(), 3, 153)]);
}
