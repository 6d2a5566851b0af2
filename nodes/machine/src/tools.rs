//! The offset page's entry numbers, as each control counts them (D47, D80).

/// Largest offset number (`003` table 7.1: H, D 1–200).
pub const MAX_TOOL_NUMBER: u32 = 200;
/// Largest entry of the 802D's offset page: tools T1–T32000, each with cutting edges D1–D9,
/// entry T×10+D (`001` §9.6, decision D80).
pub const MAX_EDGE_ENTRY: u32 = 320_009;

/// Whether `n` is an entry of `dialect`'s offset page: T×10+D with D 1–9 on the 802D,
/// 1–[`MAX_TOOL_NUMBER`] on the others; the error says which entries there are.
pub fn check_entry(dialect: &str, n: u32) -> Result<(), String> {
    match dialect {
        "sinumerik-802d" if !(11..=MAX_EDGE_ENTRY).contains(&n) || n.is_multiple_of(10) => Err(
            format!("offset entry {n}: the 802D's entries are T×10+D, T 1–32000 and D 1–9"),
        ),
        "sinumerik-802d" => Ok(()),
        _ if !(1..=MAX_TOOL_NUMBER).contains(&n) => {
            Err(format!("offset entry {n}: entries are 1–{MAX_TOOL_NUMBER}"))
        }
        _ => Ok(()),
    }
}
