//! What the tests of the Huaxing manual's example programs share: the fixture's text and the
//! turn-mill's setups.
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
