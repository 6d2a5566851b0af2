//! Issue 23, must-show 3: the 802D's programmable frames (`001` §9.2.6–§9.2.10; decision
//! D79) against transforms the test computes itself. Each case sets TRANS/ROT/SCALE/MIRROR
//! and their additive forms in some order and plane, runs one contour of lines, arcs (centre
//! and `CR=` forms, more and less than a semicircle, a full circle) and, where asked, the same
//! contour under G41 radius compensation; every move the front end emits must be the test's
//! matrix applied to the contour's program points: ends, arc centres (so radii), the arc's
//! direction (turned by a mirror) and its plane.
//!
//! The test's frame is its own 3×3 matrix and translation: an absolute instruction replaces
//! it, an additive one composes on the program side (`F := F ∘ op`), which is the manual's
//! "in the coordinates the frame already defines".

use cnc_interpreter::sinumerik::Sinumerik;
use cnc_interpreter::{Command, Library, Setup};
use cnc_interpreter_core::{next_command, ToolOffset};

const LETTERS: [char; 3] = ['X', 'Y', 'Z'];
/// Each axis's circle-centre word (X: I, Y: J, Z: K).
const CENTRE: [char; 3] = ['I', 'J', 'K'];
const TOL: f64 = 1e-6;

/// A frame as the test computes it: machine = `m` · program + `t`.
#[derive(Clone, Copy, Debug)]
struct Affine {
    m: [[f64; 3]; 3],
    t: [f64; 3],
}

impl Affine {
    fn identity() -> Affine {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        Affine { m, t: [0.0; 3] }
    }
    fn translation(v: [f64; 3]) -> Affine {
        Affine {
            t: v,
            ..Affine::identity()
        }
    }
    /// Counter-clockwise from axis `h` toward axis `v` (G17 X→Y, G18 Z→X, G19 Y→Z).
    fn rotation(h: usize, v: usize, degrees: f64) -> Affine {
        let (s, c) = degrees.to_radians().sin_cos();
        let mut a = Affine::identity();
        a.m[h][h] = c;
        a.m[h][v] = -s;
        a.m[v][h] = s;
        a.m[v][v] = c;
        a
    }
    fn diagonal(f: [f64; 3]) -> Affine {
        let mut a = Affine::identity();
        for (i, row) in a.m.iter_mut().enumerate() {
            row[i] = f[i];
        }
        a
    }
    /// `self ∘ inner`: first `inner`, then `self`.
    fn then_inner(&self, inner: &Affine) -> Affine {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                *cell = (0..3).map(|k| self.m[i][k] * inner.m[k][j]).sum();
            }
        }
        Affine {
            m,
            t: self.apply(inner.t),
        }
    }
    fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let mut q = self.t;
        for (i, qi) in q.iter_mut().enumerate() {
            *qi += (0..3).map(|k| self.m[i][k] * p[k]).sum::<f64>();
        }
        q
    }
    /// Whether the frame turns circles in the plane (h, v) the other way.
    fn mirrors(&self, h: usize, v: usize) -> bool {
        self.m[h][h] * self.m[v][v] - self.m[h][v] * self.m[v][h] < 0.0
    }
}

/// One frame instruction: its 802D text and the test's own transform of it.
struct Instr {
    text: String,
    absolute: bool,
    op: Affine,
}

/// The plane's axes as (first, second, normal) indices and its G code.
fn plane(g: u32) -> (usize, usize, usize) {
    match g {
        17 => (0, 1, 2),
        18 => (2, 0, 1),
        _ => (1, 2, 0),
    }
}

fn words(values: &[(usize, f64)]) -> String {
    values
        .iter()
        .map(|&(i, v)| format!("{}{v}", LETTERS[i]))
        .collect::<Vec<_>>()
        .join(" ")
}

fn trans(values: &[(usize, f64)], additive: bool) -> Instr {
    let mut v = [0.0; 3];
    for &(i, x) in values {
        v[i] = x;
    }
    Instr {
        text: format!("{}TRANS {}", if additive { "A" } else { "" }, words(values)),
        absolute: !additive,
        op: Affine::translation(v),
    }
}

fn rot(g: u32, degrees: f64, additive: bool) -> Instr {
    let (h, v, _) = plane(g);
    Instr {
        text: format!("{}ROT RPL={degrees}", if additive { "A" } else { "" }),
        absolute: !additive,
        op: Affine::rotation(h, v, degrees),
    }
}

fn scale(values: &[(usize, f64)], additive: bool) -> Instr {
    let mut f = [1.0; 3];
    for &(i, x) in values {
        f[i] = x;
    }
    Instr {
        text: format!("{}SCALE {}", if additive { "A" } else { "" }, words(values)),
        absolute: !additive,
        op: Affine::diagonal(f),
    }
}

fn mirror(axes: &[usize], additive: bool) -> Instr {
    let mut f = [1.0; 3];
    for &i in axes {
        f[i] = -1.0;
    }
    let named: Vec<(usize, f64)> = axes.iter().map(|&i| (i, 0.0)).collect();
    Instr {
        text: format!(
            "{}MIRROR {}",
            if additive { "A" } else { "" },
            words(&named)
        ),
        absolute: !additive,
        op: Affine::diagonal(f),
    }
}

/// The frame the instructions leave, computed by the test.
fn expected_frame(instrs: &[Instr]) -> Affine {
    instrs.iter().fold(Affine::identity(), |frame, i| {
        if i.absolute {
            i.op
        } else {
            frame.then_inner(&i.op)
        }
    })
}

/// A move of the contour in program coordinates: its end, and for an arc its centre and
/// whether it turns clockwise.
#[derive(Clone, Copy, Debug)]
struct Element {
    end: [f64; 3],
    arc: Option<([f64; 3], bool)>,
}

/// A point in the plane (first, second) at depth `n` along the normal.
fn at(g: u32, a: f64, b: f64, n: f64) -> [f64; 3] {
    let (h, v, w) = plane(g);
    let mut p = [0.0; 3];
    p[h] = a;
    p[v] = b;
    p[w] = n;
    p
}

/// The uncompensated contour: its program text and the points the test expects (in program
/// coordinates, before the frame).
fn contour(g: u32) -> (String, Vec<Element>) {
    let (h, v, w) = plane(g);
    let (hl, vl, wl) = (LETTERS[h], LETTERS[v], LETTERS[w]);
    let (hc, vc) = (CENTRE[h], CENTRE[v]);
    let text = format!(
        "G0 {hl}0 {vl}0 {wl}5\n\
         G1 {wl}-2 F300\n\
         {hl}40\n\
         G2 {hl}60 {vl}20 CR=20\n\
         G3 {hl}80 {vl}40 {hc}20 {vc}0\n\
         G2 {hl}80 {vl}40 {hc}0 {vc}=-10\n\
         G3 {hl}30 {vl}40 CR=-30\n\
         G1 {hl}0 {vl}40\n\
         G0 {wl}5\n"
    );
    let line = |a, b, n| Element {
        end: at(g, a, b, n),
        arc: None,
    };
    let arc = |a, b, ca, cb, cw| Element {
        end: at(g, a, b, -2.0),
        arc: Some((at(g, ca, cb, -2.0), cw)),
    };
    let elements = vec![
        line(0.0, 0.0, 5.0),
        line(0.0, 0.0, -2.0),
        line(40.0, 0.0, -2.0),
        // CR=20 from (40,0) to (60,20) clockwise: the quarter about (60,0).
        arc(60.0, 20.0, 60.0, 0.0, true),
        // Centre 20 to the right of the start: three quarters about (80,20).
        arc(80.0, 40.0, 80.0, 20.0, false),
        // End = start: the full circle about (80,30).
        arc(80.0, 40.0, 80.0, 30.0, true),
        // CR=-30 from (80,40) to (30,40): the larger arc, so its centre lies right of the
        // chord as it runs (counter-clockwise), √(30²−25²) from its middle.
        arc(30.0, 40.0, 55.0, 40.0 + 275f64.sqrt(), false),
        line(0.0, 40.0, -2.0),
        line(0.0, 40.0, 5.0),
    ];
    (text, elements)
}

/// The contour under G41 with a tool radius of `r` program units (a pocket side, all
/// corners inside, so each compensated corner is the intersection of the offset elements):
/// the start-up move goes to the offset point of the next element's start, G40 leaves from
/// the offset point of the last element's end (`001` §9.6).
fn compensated(g: u32, r: f64) -> (String, Vec<Element>) {
    let (h, v, w) = plane(g);
    let (hl, vl, wl) = (LETTERS[h], LETTERS[v], LETTERS[w]);
    let text = format!(
        "G0 {hl}-20 {vl}-20 {wl}5\n\
         G1 {wl}-2 F300\n\
         G41 G1 {hl}0 {vl}0\n\
         {hl}80\n\
         G3 {hl}80 {vl}60 CR=30\n\
         G1 {hl}0\n\
         {vl}0\n\
         G40 G1 {hl}-20 {vl}-20\n\
         G0 {wl}5\n"
    );
    let line = |a, b, n| Element {
        end: at(g, a, b, n),
        arc: None,
    };
    let elements = vec![
        line(-20.0, -20.0, 5.0),
        line(-20.0, -20.0, -2.0),
        line(0.0, r, -2.0),
        line(80.0, r, -2.0),
        Element {
            end: at(g, 80.0, 60.0 - r, -2.0),
            arc: Some((at(g, 80.0, 30.0, -2.0), false)),
        },
        line(r, 60.0 - r, -2.0),
        line(r, 0.0, -2.0),
        line(-20.0, -20.0, -2.0),
        line(-20.0, -20.0, 5.0),
    ];
    (text, elements)
}

fn run(text: &str, setup: Setup) -> Vec<Command> {
    let mut front = Sinumerik::new(text, setup, Library::new());
    let mut out = Vec::new();
    loop {
        match next_command(&mut front) {
            Ok(Some(c)) => out.push(c.command),
            Ok(None) => break,
            Err(e) => panic!("{e}\n{text}"),
        }
        assert!(out.len() < 10_000, "runaway program");
    }
    out
}

fn mill(tool_radius: f64) -> Setup {
    let mut s = Setup::new(&['X', 'Y', 'Z'], &[false; 3], &[0.0; 3]);
    // T1 D1: a radius and no length, so only the frame moves the points.
    s.offsets.tools.insert(
        11,
        ToolOffset {
            radius: tool_radius,
            ..ToolOffset::default()
        },
    );
    s
}

fn near(a: &[f64], b: &[f64; 3]) -> bool {
    a.len() == 3 && a.iter().zip(b).all(|(x, y)| (x - y).abs() < TOL)
}

/// Runs `instrs` then the contour in plane `g` and compares every move with the test's frame
/// applied to the contour's points.
fn check(name: &str, g: u32, instrs: &[Instr], contour: (String, Vec<Element>), setup: Setup) {
    let (h, v, _) = plane(g);
    let frame = expected_frame(instrs);
    let mut text = format!("G{g} G90\nT1 D1\n");
    for i in instrs {
        text.push_str(&i.text);
        text.push('\n');
    }
    text.push_str(&contour.0);
    text.push_str("M30\n");
    let moves: Vec<Command> = run(&text, setup)
        .into_iter()
        .filter(|c| c.end().is_some())
        .collect();
    let expected = &contour.1;
    assert_eq!(
        moves.len(),
        expected.len(),
        "{name}: moves {moves:?}\n{text}"
    );
    for (k, (got, want)) in moves.iter().zip(expected).enumerate() {
        let end = frame.apply(want.end);
        let at = format!("{name}, move {k}: got {got:?}, want end {end:?}\n{text}");
        assert!(near(got.end().unwrap_or_default(), &end), "{at}");
        match (got, want.arc) {
            (
                Command::Arc {
                    center,
                    clockwise,
                    plane,
                    ..
                },
                Some((c, cw)),
            ) => {
                let c = frame.apply(c);
                assert!(near(center, &c), "{at}: centre {c:?}");
                assert_eq!(*clockwise, cw != frame.mirrors(h, v), "{at}: direction");
                assert_eq!(*plane, Some([h as u8, v as u8]), "{at}: plane");
            }
            (Command::Linear { .. } | Command::Rapid { .. }, None) => {}
            _ => panic!("{at}: kind"),
        }
    }
}

/// The frame cases: every instruction and its additive form, several orders, all planes.
fn cases(g: u32) -> Vec<(&'static str, Vec<Instr>)> {
    let (h, v, w) = plane(g);
    vec![
        ("none", vec![]),
        (
            "TRANS",
            vec![trans(&[(h, 10.0), (v, -5.0), (w, 3.0)], false)],
        ),
        ("ROT", vec![rot(g, 30.0, false)]),
        ("SCALE", vec![scale(&[(h, 1.5), (v, 1.5)], false)]),
        ("MIRROR", vec![mirror(&[h], false)]),
        (
            "TRANS AROT ASCALE AMIRROR",
            vec![
                trans(&[(h, 10.0), (v, 5.0)], false),
                rot(g, 30.0, true),
                scale(&[(h, 2.0), (v, 2.0)], true),
                mirror(&[v], true),
            ],
        ),
        (
            "ROT then ATRANS: the shift turns with the frame",
            vec![rot(g, 45.0, false), trans(&[(h, 20.0)], true)],
        ),
        (
            "ATRANS then AROT: the turn about the shifted origin",
            vec![trans(&[(h, 20.0)], true), rot(g, 45.0, true)],
        ),
        (
            "SCALE then ATRANS: the shift is scaled",
            vec![
                scale(&[(h, 0.5), (v, 0.5)], false),
                trans(&[(h, 40.0), (v, 10.0)], true),
            ],
        ),
        (
            "MIRROR then AROT: the turn is mirrored",
            vec![
                mirror(&[h], false),
                rot(g, -20.0, true),
                trans(&[(v, 7.0)], true),
            ],
        ),
        (
            "two mirrors cancel in direction",
            vec![mirror(&[h], false), mirror(&[v], true), rot(g, 60.0, true)],
        ),
        (
            "AMIRROR twice on one axis is none",
            vec![
                mirror(&[h], false),
                mirror(&[h], true),
                trans(&[(h, 3.0)], true),
            ],
        ),
        (
            "an absolute ROT clears TRANS and SCALE before it",
            vec![
                trans(&[(h, 50.0)], false),
                scale(&[(h, 3.0), (v, 3.0)], true),
                rot(g, 15.0, false),
                trans(&[(v, -4.0)], true),
            ],
        ),
        (
            "an absolute TRANS clears ROT and MIRROR",
            vec![
                rot(g, 30.0, false),
                mirror(&[v], true),
                trans(&[(h, 1.0), (v, 2.0)], false),
            ],
        ),
        (
            "AROT adds angles",
            vec![rot(g, 10.0, false), rot(g, 25.0, true), rot(g, -5.0, true)],
        ),
        (
            "ASCALE multiplies",
            vec![
                scale(&[(h, 2.0), (v, 2.0)], false),
                trans(&[(h, 5.0)], true),
                scale(&[(h, 0.25), (v, 0.25)], true),
            ],
        ),
    ]
}

#[test]
fn frames_move_lines_and_arcs_as_the_test_matrices_do_in_g17_g18_g19() {
    let mut n = 0;
    for g in [17, 18, 19] {
        for (name, instrs) in cases(g) {
            check(&format!("G{g} {name}"), g, &instrs, contour(g), mill(5.0));
            n += 1;
        }
    }
    println!("{n} frame cases, each a contour of lines, four arc forms and a full circle");
}

/// The compensated contour under each frame: the tool runs on the offset path (computed here
/// from the geometry in program units, the radius divided by a frame's scale, so the machine
/// sees the tool's own radius), and the frame carries that path. A mirror turns G41 into a
/// cut on the machine's right, the mirror image of the unmirrored cut (the manual's "MIRROR
/// reverses G41/G42").
#[test]
fn frames_carry_compensated_contours_in_every_plane() {
    const RADIUS: f64 = 5.0;
    let mut n = 0;
    for g in [17, 18, 19] {
        let (h, v, _) = plane(g);
        let frames: Vec<(&str, Vec<Instr>, f64)> = vec![
            ("none", vec![], 1.0),
            ("TRANS", vec![trans(&[(h, 10.0), (v, -5.0)], false)], 1.0),
            (
                "ROT ATRANS",
                vec![rot(g, 30.0, false), trans(&[(h, 12.0)], true)],
                1.0,
            ),
            ("MIRROR", vec![mirror(&[h], false)], 1.0),
            (
                "MIRROR AROT",
                vec![mirror(&[v], false), rot(g, 45.0, true)],
                1.0,
            ),
            ("SCALE 2", vec![scale(&[(h, 2.0), (v, 2.0)], false)], 2.0),
            (
                "TRANS AROT ASCALE 0.5",
                vec![
                    trans(&[(h, -30.0), (v, 20.0)], false),
                    rot(g, -60.0, true),
                    scale(&[(h, 0.5), (v, 0.5)], true),
                ],
                0.5,
            ),
        ];
        for (name, instrs, factor) in frames {
            check(
                &format!("G{g} G41 under {name}"),
                g,
                &instrs,
                compensated(g, RADIUS / factor),
                mill(RADIUS),
            );
            n += 1;
        }
    }
    println!("{n} compensated contours under frames");
}

/// A circle under unequal plane scale factors is no circle: the manual's rule ("circles need
/// equal scale factors in the plane") is an alarm at the arc, lines run.
#[test]
fn unequal_plane_scale_factors_refuse_a_circle_and_scale_lines() {
    let text = "G17 G90\nSCALE X2 Y3\nG0 X10 Y10 Z5\nG1 X20 F300\nG2 X30 Y10 CR=5\nM30\n";
    let mut front = Sinumerik::new(text, mill(0.0), Library::new());
    let mut moves = Vec::new();
    let error = loop {
        match next_command(&mut front) {
            Ok(Some(c)) => moves.extend(c.command.end().map(<[f64]>::to_vec)),
            Ok(None) => break None,
            Err(e) => break Some(e),
        }
    };
    let frame = expected_frame(&[scale(&[(0, 2.0), (1, 3.0)], false)]);
    assert!(near(&moves[0], &frame.apply([10.0, 10.0, 5.0])));
    assert!(near(&moves[1], &frame.apply([20.0, 10.0, 5.0])));
    let e = error.expect("the arc is refused");
    assert_eq!((e.number, e.line), (14040, 5), "{e}");
    assert!(e.text.contains("same scale factor"), "{e}");
}

/// The map the interpreter sends with each block for the operator's work position
/// (`Core::work_frame`): under G54, TRANS, AROT, ASCALE and AMIRROR, a machine point less the
/// origin taken through it is the work point the program wrote; without a frame it is empty.
#[test]
fn the_work_frame_sent_for_the_display_takes_machine_points_back_to_the_programs() {
    let mut s = Setup::new(&LETTERS, &[false; 3], &[0.0; 3]);
    let g54 = s.offsets.work.entry(0).or_default();
    g54.insert('X', 100.0);
    g54.insert('Y', -40.0);
    let text = "G54 G17 G0 X1 Y2 Z3\nTRANS X5 Y7\nAROT RPL=30\nASCALE X2 Y2\nAMIRROR X0\n\
                G1 X10 Y-4 Z6 F100\nM30\n";
    let mut front = Sinumerik::new(text, s, Library::new());
    assert!(front.core.work_frame().is_empty(), "no frame yet");
    let mut ends = Vec::new();
    let mut maps = Vec::new();
    while let Some(c) = next_command(&mut front).unwrap() {
        if let Some(end) = c.command.end() {
            ends.push(end.to_vec());
            maps.push((front.core.program_origin(), front.core.work_frame()));
        }
    }
    let (end, (origin, frame)) = (&ends[1], &maps[1]);
    assert_eq!(frame.len(), 12, "3 rows of 3 and a constant");
    let work: Vec<f64> = (0..3)
        .map(|i| {
            let row = &frame[i * 4..i * 4 + 4];
            (0..3).map(|j| row[j] * (end[j] - origin[j])).sum::<f64>() + row[3]
        })
        .collect();
    for (w, p) in work.iter().zip([10.0, -4.0, 6.0]) {
        assert!((w - p).abs() < TOL, "{work:?} from the machine's {end:?}");
    }
    // The frame really turns: the machine point is not the work point shifted.
    assert!((end[0] - origin[0] - 10.0).abs() > 1.0, "{end:?}");
}
