//! What the tests of the Huaxing manual's example programs share: the fixture's text.
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
