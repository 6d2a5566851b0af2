//! Issue 28, must-show 3: block search and restart, by fixture family (lathe cycles, threads,
//! subprograms and macros, mill cycles and cutter compensation). Each program runs once
//! uninterrupted; then it is restarted at several lines and several blocks, from a machine
//! standing elsewhere (the operator has moved it). For each restart:
//! - after the restart's preamble, the stream is the uninterrupted run's from the restart
//!   block on, command for command (so the final position is the same);
//! - a machine model fed only the preamble stands where the uninterrupted run stood before the
//!   block, with the same tool, spindle, speed, coolant and feed and path modes;
//! - the interpreter's program zero (work offset, shifts, tool offset) is the same;
//! - the approach moves the retract axis away from the work first, closes in on it only
//!   over the point, and arrives last; a mill's tool change happens with Z at the tool change
//!   position.
//!
//! The machine model here knows only what the M codes mean on the machine; it shares no code
//! with the search.

use std::path::{Path, PathBuf};

use cnc_interpreter::{Aux, Canon, Command, Dialect, Interpreter, Library, Setup};
use cnc_runtime::LaunchConfig;
use cnc_task::node::setup_from_config;
use cnc_task::search::{search, Approach, SearchTarget};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fixture's program: the listing after the header where the file has one.
fn fixture(dir: &str, name: &str) -> String {
    let path = root().join("../shared/fixtures").join(dir).join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    match text.split_once("(--- listing as printed ---)") {
        Some((_, listing)) => listing.to_string(),
        None => text,
    }
}

fn machine(config: &str, tools: Option<&Path>) -> Setup {
    let cfg =
        LaunchConfig::load_with_tool_table(&root().join("launch_configs").join(config), tools)
            .expect("config");
    setup_from_config(&cfg, &cfg.home())
}

/// What the machine is in, as its PLC and motion would show it.
#[derive(Debug, Clone, PartialEq, Default)]
struct Machine {
    at: Vec<f64>,
    /// Turret station or the tool put ready.
    selected: Option<i32>,
    /// The tool in a mill's spindle.
    in_spindle: Option<i32>,
    rpm: Option<f64>,
    turning: &'static str,
    coolant: &'static str,
    gear: Option<i32>,
    per_rev: bool,
    exact_stop: bool,
    /// Where the axes stood at each tool change.
    changed_at: Vec<Vec<f64>>,
}

impl Machine {
    fn at(p: &[f64]) -> Machine {
        Machine {
            at: p.to_vec(),
            turning: "stopped",
            coolant: "off",
            ..Machine::default()
        }
    }

    fn run(&mut self, cmds: &[Canon]) {
        for c in cmds {
            if let Some(e) = c.command.end() {
                self.at = e.to_vec();
            }
            match c.command {
                Command::FeedMode { per_rev } => self.per_rev = per_rev,
                Command::PathMode { exact_stop } => self.exact_stop = exact_stop,
                Command::Aux(Aux::T(t)) => self.selected = Some(t),
                Command::Aux(Aux::S(s)) => self.rpm = Some(s),
                Command::Aux(Aux::M(m)) => match m {
                    3 => self.turning = "clockwise",
                    4 => self.turning = "counter-clockwise",
                    5 => self.turning = "stopped",
                    19 => self.turning = "oriented",
                    7 => self.coolant = "mist",
                    8 => self.coolant = "flood",
                    9 => self.coolant = "off",
                    41..=44 => self.gear = Some(m),
                    6 => {
                        self.in_spindle = self.selected;
                        self.changed_at.push(self.at.clone());
                    }
                    _ => {}
                },
                _ => {}
            }
        }
    }
}

struct Program {
    name: String,
    dialect: Dialect,
    text: String,
    setup: Setup,
    library: Library,
}

impl Program {
    fn interpreter(&self) -> Interpreter {
        Interpreter::with_library(
            self.dialect,
            &self.text,
            self.setup.clone(),
            self.library.clone(),
        )
    }
}

/// `n` values spread evenly over `items` (all of them if there are fewer).
fn spread<T: Clone>(items: &[T], n: usize) -> Vec<T> {
    if items.len() <= n {
        return items.to_vec();
    }
    (0..n)
        .map(|k| items[k * (items.len() - 1) / (n - 1)].clone())
        .collect()
}

/// Restarts `p` at each of several lines and blocks from `here`; returns how many restarts
/// were checked.
fn check_restarts(p: &Program, here: &[f64]) -> usize {
    let mut full_run = p.interpreter();
    let mut full = Vec::new();
    while let Some(c) = full_run
        .next_command()
        .unwrap_or_else(|e| panic!("{}: {e}", p.name))
    {
        full.push(c);
    }
    let mut lines: Vec<u32> = full.iter().map(|c| c.main_line).collect();
    lines.sort_unstable();
    lines.dedup();
    let blocks: Vec<u64> = (1..=full.len() as u64).collect();
    let targets: Vec<SearchTarget> = spread(&lines, 6)
        .into_iter()
        .map(SearchTarget::Line)
        .chain(spread(&blocks, 6).into_iter().map(SearchTarget::Block))
        .collect();
    let approach = Approach::default_for(&p.setup);
    let r = approach.retract_axis;
    for target in &targets {
        let i = match target {
            SearchTarget::Line(l) => full.iter().position(|c| c.main_line >= *l).unwrap(),
            SearchTarget::Block(b) => *b as usize - 1,
            _ => unreachable!(),
        };
        let what = format!("{} restarted at {target:?} (command {i})", p.name);
        let mut interp = p.interpreter();
        let found = search(p.dialect, &mut interp, &p.text, target, here, &approach)
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(found.skipped as usize, i, "{what}");
        // The rest of the program is the uninterrupted run's.
        let mut rest = vec![found.first.clone()];
        let origin_at_restart = interp.program_origin();
        while let Some(c) = interp.next_command().unwrap() {
            rest.push(c);
        }
        assert_eq!(rest, full[i..], "{what}: the stream after the restart");
        // Offsets: the program zero at the restart block is the uninterrupted run's.
        let mut again = p.interpreter();
        for _ in 0..=i {
            again.next_command().unwrap();
        }
        assert_eq!(
            origin_at_restart,
            again.program_origin(),
            "{what}: program zero"
        );
        // The preamble leaves the machine as the uninterrupted run had it.
        let mut uninterrupted = Machine::at(&p.setup.start);
        uninterrupted.run(&full[..i]);
        let mut restarted = Machine::at(here);
        restarted.run(&found.preamble);
        let moved = full[..i].iter().any(|c| c.command.end().is_some());
        if !moved {
            // Nothing moved before the block: it starts from wherever the machine is.
            restarted.at.clone_from(&uninterrupted.at);
        }
        let tool_changes = restarted.changed_at.clone();
        restarted.changed_at.clear();
        uninterrupted.changed_at.clear();
        assert_eq!(restarted, uninterrupted, "{what}: the machine at the block");
        for at in tool_changes {
            assert_eq!(
                Some(at[r]),
                approach.tool_change_at,
                "{what}: tool change position"
            );
        }
        // The approach (the moves after any tool change): the retract axis away first, the
        // point reached last.
        let after_change = found
            .preamble
            .iter()
            .rposition(|c| c.command == Command::Aux(Aux::M(6)))
            .map_or(0, |k| k + 1);
        let mut start = here.to_vec();
        for c in &found.preamble[..after_change] {
            if let Some(e) = c.command.end() {
                start = e.to_vec();
            }
        }
        let moves: Vec<&[f64]> = found.preamble[after_change..]
            .iter()
            .filter_map(|c| c.command.end())
            .collect();
        if let (Some(first), Some(last), true) = (moves.first(), moves.last(), moved) {
            let target_point = &uninterrupted.at;
            assert_eq!(
                *last,
                &target_point[..],
                "{what}: approach ends at the block"
            );
            // Every move but the last stays out at the retract height, except the rapid down
            // to the clearance, which comes once the other axes are over the point.
            let away = start[r].max(target_point[r]);
            for m in &moves[..moves.len() - 1] {
                let over_point = (0..m.len()).all(|k| k == r || m[k] == target_point[k]);
                let floor = if over_point {
                    target_point[r] + approach.clearance.min(away - target_point[r])
                } else {
                    away
                };
                assert!(m[r] >= floor - 1e-9, "{what}: approach dips in: {moves:?}");
            }
            if first[r] != start[r] {
                let others_still = (0..start.len()).all(|k| k == r || first[k] == start[k]);
                assert!(others_still, "{what}: first approach move {first:?}");
            }
        }
    }
    targets.len()
}

fn lathe_family(dir: &str, dialect: Dialect, names: &[&str]) -> usize {
    let setup = machine("sim_lathe.yaml", None);
    let library_dir = root().join("../shared/fixtures").join(dir);
    let (library, _) = cnc_task::library::load_dir(&library_dir).expect("library");
    let here = [260.0, 150.0];
    names
        .iter()
        .map(|name| {
            let p = Program {
                name: format!("{dir}/{name}"),
                dialect,
                text: fixture(dir, name),
                setup: setup.clone(),
                library: library.clone(),
            };
            check_restarts(&p, &here)
        })
        .sum()
}

#[test]
fn lathe_cycles_restart_where_they_were_left() {
    let n = lathe_family(
        "000",
        Dialect::HuaxingLathe,
        &[
            "027_g90_axial_cycle_O0002.nc",
            "028_g94_radial_cycle_O0003.nc",
            "029_g71_type1_example1.nc",
            "030_g71_type2_example2.nc",
            "032_g71_g70_tnrc_example4.nc",
            "033_g72_radial_roughing_O0005.nc",
            "034_g73_pattern_repeat_O0006.nc",
            "036_g75_radial_grooving_O0008.nc",
            "058_ch20_ex4_tnrc_outer.nc",
        ],
    ) + lathe_family(
        "002",
        Dialect::Gtc2eLathe,
        &[
            "010_g24_taper_cycle_fig4_4.nc",
            "011_g77_cylinder_cycle_fig4_5.nc",
            "013_g75_grooving_cycle_fig4_7.nc",
            "023_part_fig4_8_taper_shaft_incremental.nc",
        ],
    );
    println!("{n} restarts checked");
}

#[test]
fn threads_restart_at_a_pass() {
    let n = lathe_family(
        "000",
        Dialect::HuaxingLathe,
        &[
            "037_g32_taper_thread_O0009.nc",
            "039_g92_thread_cycle_O0012.nc",
            "040_g76_multiple_thread_O0013.nc",
            "055_ch20_ex1_brass_bore_groove_thread.nc",
        ],
    ) + lathe_family(
        "002",
        Dialect::Gtc2eLathe,
        &[
            "005_g33_straight_thread.nc",
            "007_g33_inch_thread.nc",
            "008_g76_thread_cycle.nc",
        ],
    );
    println!("{n} restarts checked");
}

#[test]
fn subprograms_and_macros_restart_with_their_variables_and_levels() {
    let n = lathe_family(
        "000",
        Dialect::HuaxingLathe,
        &[
            "048_macro_if_goto.nc",
            "049_macro_if_execute.nc",
            "051_macro_sphere_main.nc",
        ],
    ) + lathe_family(
        "002",
        Dialect::Gtc2eLathe,
        &[
            "014_g22_g80_program_loop.nc",
            "022_m97_m98_m99_subroutine.nc",
        ],
    );
    println!("{n} restarts checked");
}

#[test]
fn mill_cycles_and_cutter_compensation_restart_in_the_compensated_path() {
    let dir = root().join("tests/oracle");
    let mut n = 0;
    for name in [
        "16_g73_g83_pecking.ngc",
        "21_length_comp_cycles.ngc",
        "35_cycle_data_modal.ngc",
        "41_cutter_comp_outside_profile.ngc",
        "43_cutter_comp_arcs.ngc",
        "48_while_spiral_with_comp.ngc",
        "49_locals_m98_and_g65.ngc",
        "52_helix_bore_g41.ngc",
        "54_helix_comp_g18_by_r.ngc",
        "62_tool_changes_at_g30.ngc",
        "70_inch_helix_comp.ngc",
    ] {
        let text = std::fs::read_to_string(dir.join(name)).expect("program");
        let table = text
            .lines()
            .find_map(|l| Some(l.split_once("(tools:")?.1.split_once(')')?.0.trim()))
            .unwrap_or("tools.tbl");
        let setup = machine("sim_mill.yaml", Some(&dir.join(table)));
        let here = [120.0, 80.0, -40.0];
        let p = Program {
            name: name.into(),
            dialect: Dialect::FanucMill,
            text,
            setup,
            library: Library::new(),
        };
        n += check_restarts(&p, &here);
    }
    println!("{n} restarts checked");
}
