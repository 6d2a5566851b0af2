//! What a ladder monitor shows: the running program as rungs of source text, with every symbol
//! followed by its address (`ESP_N(X8.4)`), so a monitor colours contacts from the signal tables
//! alone, without knowing the program's symbol table.

use crate::address::Address;
use crate::Program;

/// The program as rungs (each rung's steps, one per line) and each rung's first source line.
pub fn rungs(program: &Program) -> (Vec<String>, Vec<u32>) {
    let mut texts = Vec::new();
    let mut lines = Vec::new();
    for range in program.rungs() {
        let steps = &program.steps[range];
        lines.push(steps.first().map_or(0, |s| s.line));
        let text: Vec<String> = steps.iter().map(|s| resolve(program, &s.text)).collect();
        texts.push(text.join("\n"));
    }
    (texts, lines)
}

/// Appends each symbol's address to it; quoted message texts stay as written.
fn resolve(program: &Program, text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 16);
    let mut word = String::new();
    let mut quoted = false;
    let flush = |word: &mut String, out: &mut String| {
        out.push_str(word);
        if let Some(a) = program.symbols.get(&word.to_ascii_uppercase()) {
            match a {
                Address::Bit(b) => out.push_str(&format!("({b})")),
                Address::Byte(b) => out.push_str(&format!("({b})")),
            }
        }
        word.clear();
    };
    for c in text.chars() {
        if c == '"' {
            flush(&mut word, &mut out);
            quoted = !quoted;
            out.push(c);
        } else if !quoted && (c.is_ascii_alphanumeric() || c == '_' || c == '.') {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            out.push(c);
        }
    }
    flush(&mut word, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symbols_are_followed_by_their_addresses_and_rungs_start_with_rd() {
        let p = Program::parse(
            "SYM START X4.0\nSYM LAMP Y2.1\nRD START\nOR R10.0\nWRT LAMP\nRD.NOT X0.1\nWRT R10.0\nEND1\nEND2\n",
        )
        .expect("program");
        let (rungs, lines) = rungs(&p);
        assert_eq!(rungs[0], "RD START(X4.0)\nOR R10.0\nWRT LAMP(Y2.1)");
        assert_eq!(rungs[1], "RD.NOT X0.1\nWRT R10.0");
        assert_eq!(lines[..2], [3, 6]);
    }
}
