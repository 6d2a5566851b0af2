//! What the tests of the Huaxing manual's example programs share: the fixture's text, the
//! turn-mill's setups, reading a program and checking the alarms of a list of programs.
#![allow(dead_code)]

/// The listing of fixture `name` of `../shared/fixtures/000`, below its header.
pub fn fixture(name: &str) -> String {
    let path = format!(
        "{}/../../../shared/fixtures/000/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    text.split("(--- listing as printed ---)")
        .nth(1)
        .expect("listing marker")
        .to_string()
}

/// A turn-mill lathe at X200 Z100 (diameter), its spindle the C axis.
pub fn turn_mill() -> cnc_interpreter::Setup {
    cnc_interpreter::Setup::lathe([200.0, 100.0]).with_spindle_c_axis()
}

/// The turn-mill with its live tool as axis A (G14.4), up to 2500 r/min.
pub fn with_live_tool() -> cnc_interpreter::Setup {
    turn_mill().with_live_tool('A', 4, 2500.0)
}

/// `text` read by the Huaxing front end on `setup`.
pub fn hx(
    text: &str,
    setup: cnc_interpreter::Setup,
) -> Result<Vec<cnc_interpreter::Canon>, cnc_interpreter::ProgramError> {
    cnc_interpreter::check(cnc_interpreter::Dialect::HuaxingLathe, text, setup)
}

/// Each program of `cases` ends in the alarm `number` at `line`.
pub fn assert_alarms(
    cases: impl IntoIterator<Item = (&'static str, cnc_interpreter::Setup, u32, u32)>,
) {
    for (text, setup, number, line) in cases {
        let e = hx(text, setup).unwrap_err();
        assert_eq!((e.number, e.line), (number, line), "{text}: {e}");
    }
}
