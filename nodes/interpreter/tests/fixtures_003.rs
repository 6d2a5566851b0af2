//! The FANUC-style milling manual's example programs (`../shared/fixtures/003/`), with the
//! machine coordinates each header states (where the header flags a misprint, the value the
//! manual's own arithmetic gives).

use cnc_interpreter::{Canon, Command, Dialect, ProgramError, Setup};

fn fixture(name: &str) -> String {
    let path = format!(
        "{}/../../../shared/fixtures/003/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn mill(axes: &[char], start: &[f64]) -> Setup {
    Setup::new(axes, &vec![false; axes.len()], start)
}

fn run(text: &str, setup: Setup) -> Result<Vec<Canon>, ProgramError> {
    cnc_interpreter::check(Dialect::FanucMill, text, setup)
}

fn ends(cmds: &[Canon]) -> Vec<Vec<f64>> {
    cmds.iter()
        .filter_map(|c| c.command.end().map(<[f64]>::to_vec))
        .collect()
}

fn assert_close(got: &[Vec<f64>], want: &[&[f64]]) {
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            g.iter().zip(*w).all(|(a, b)| (a - b).abs() < 1e-9),
            "{got:?} vs {want:?}"
        );
    }
}

const XYZ: [char; 3] = ['X', 'Y', 'Z'];

#[test]
fn fixture_001_g00_goes_to_x150_y25() {
    let cmds = run(
        &fixture("001_g00_independent_axes_single_block.nc"),
        mill(&XYZ, &[-50.0, -75.0, 0.0]),
    )
    .unwrap();
    // One rapid; each axis at its own rate is the motion planner's dog-leg (issue 4).
    assert!(matches!(&cmds[0].command, Command::Rapid { end } if end == &[150.0, 25.0, 0.0]));
}

#[test]
fn fixture_002_g01_and_f_are_modal() {
    let cmds = run(
        &fixture("002_g01_modal_feed.nc"),
        mill(&XYZ, &[-50.0, -75.0, 0.0]),
    )
    .unwrap();
    let feeds: Vec<(Vec<f64>, f64)> = cmds
        .iter()
        .filter_map(|c| match &c.command {
            Command::Linear { end, feed } => Some((end.clone(), *feed)),
            _ => None,
        })
        .collect();
    assert_eq!(
        feeds,
        [
            (vec![150.0, 25.0, 0.0], 100.0),
            (vec![50.0, 75.0, 0.0], 100.0)
        ]
    );
}

#[test]
fn fixture_003_g28_goes_through_the_intermediate_point() {
    let mut setup = mill(&XYZ, &[0.0, 0.0, 0.0]);
    setup.reference = vec![300.0, 200.0, 100.0];
    let cmds = run(&fixture("003_g28_intermediate_point_memory.nc"), setup).unwrap();
    // N1 at rapid (power-on G00); N2: (-40, -25), then X and Y to the reference point;
    // N3: Z31, then Z to its reference point. Axes not named stay.
    assert_close(
        &ends(&cmds),
        &[
            &[20.0, 54.0, 0.0],
            &[-40.0, -25.0, 0.0],
            &[300.0, 200.0, 0.0],
            &[300.0, 200.0, 31.0],
            &[300.0, 200.0, 100.0],
        ],
    );
    assert!(cmds
        .iter()
        .all(|c| !matches!(c.command, Command::Linear { .. })));
}

fn work_offsets(setup: &mut Setup) {
    for (index, values) in [
        (0u8, [-150.0, -210.0, -90.0]),
        (3, [-430.0, -330.0, -120.0]),
    ] {
        for (a, v) in XYZ.iter().zip(values) {
            setup.offsets.work.entry(index).or_default().insert(*a, v);
        }
    }
}

#[test]
fn fixture_004_work_offsets_and_g53() {
    let text = fixture("004_g54_g57_g53_work_offsets.nc");
    // With a 4th axis A the whole table runs. N3 and N11 as the arithmetic gives them:
    // Z-162.5 (-90 - 72.5) and X-392.6 (-430 + 37.4); the manual prints -160.5 and 392.6.
    let mut setup = mill(&['X', 'Y', 'Z', 'A'], &[0.0; 4]);
    work_offsets(&mut setup);
    let cmds = run(&text, setup).unwrap();
    let got: Vec<Vec<f64>> = ends(&cmds).iter().map(|e| e[..3].to_vec()).collect();
    assert_close(
        &got,
        &[
            &[-100.0, -160.0, 0.0],
            &[-100.0, -160.0, -160.0],
            &[-100.0, -160.0, -162.5],
            &[-112.6, -160.0, -162.5],
            &[-112.6, -160.0, -90.0],
            &[-150.0, -210.0, -90.0],
            &[0.0, 0.0, 0.0],
            &[-380.0, -280.0, 0.0],
            &[-380.0, -280.0, -190.0],
            &[-380.0, -280.0, -192.5],
            &[-392.6, -280.0, -192.5],
            &[-392.6, -280.0, -120.0],
            &[-430.0, -330.0, -120.0],
        ],
    );
    // On the 3-axis mill (launch_configs/sim_mill.yaml) the A word of N6 is P/S 009, an
    // address the machine does not have.
    let mut setup = mill(&XYZ, &[0.0; 3]);
    work_offsets(&mut setup);
    let e = run(&text, setup).unwrap_err();
    let n6 = text.lines().position(|l| l.starts_with("N6 ")).expect("N6") as u32 + 1;
    assert_eq!((e.number, e.line), (9, n6), "{e}");
}

#[test]
fn fixture_005_g92_shifts_every_work_system() {
    let mut setup = mill(&XYZ, &[0.0; 3]);
    work_offsets(&mut setup);
    let cmds = run(&fixture("005_g92_shift_applies_to_all_wcs.nc"), setup).unwrap();
    // N2 moves nothing; N3 to the new origin; N4 to G57's shifted origin; N5 to the original.
    assert_close(
        &ends(&cmds),
        &[
            &[-150.0, -210.0, -90.0],
            &[-220.0, -310.0, -140.0],
            &[-500.0, -430.0, -170.0],
            &[-430.0, -330.0, -120.0],
        ],
    );
}

#[test]
fn g04_dwell_p_is_milliseconds_x_is_seconds() {
    // FANUC 0-M: G04 P in ms (no decimal point), X in seconds; LinuxCNC's P is seconds, so the
    // oracle programs leave G04 out and this test holds the FANUC reading.
    let cmds = run("G04 P1500\nG04 X2.5\n", mill(&XYZ, &[0.0; 3])).unwrap();
    let dwells: Vec<f64> = cmds
        .iter()
        .filter_map(|c| match c.command {
            Command::Dwell { seconds } => Some(seconds),
            _ => None,
        })
        .collect();
    assert_eq!(dwells, [1.5, 2.5]);
}
