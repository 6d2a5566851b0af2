//! The 802D's transfer format (`001` §12.1): a listing read in over RS232 names each program
//! in a header line `%_N_<NAME>_MPF` or `%_N_<NAME>_SPF`, and the control stores each under
//! its name. A listing that holds a main program and its subprograms (the manual's CYCLE72
//! example 1, §10.6.3) therefore runs as printed: the main program is the text up to the
//! next header, and every later section is a program of its own (decision D95).

/// One program after a header of the listing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Section<'a> {
    /// The name it is called by (`EX72CONTOUR`).
    pub name: String,
    /// Its file name (`EX72CONTOUR.SPF`), what errors call it.
    pub file: String,
    /// Its lines, numbered from 1 as the control numbers the stored program's.
    pub text: &'a str,
}

/// `line`'s program name and file name, if it is a transfer header.
fn header(line: &str) -> Option<(String, String)> {
    let line = line.trim_start();
    // Most lines are blocks: one look at their first character.
    if !line.starts_with('%') {
        return None;
    }
    let word = line.trim_end().split([' ', '\t', ';']).next()?;
    let rest = word
        .get(..4)
        .filter(|p| p.eq_ignore_ascii_case("%_N_"))
        .map(|_| &word[4..])?;
    let (name, kind) = rest.rsplit_once('_')?;
    let kind = kind.to_ascii_uppercase();
    (!name.is_empty() && (kind == "MPF" || kind == "SPF"))
        .then(|| (name.to_ascii_uppercase(), format!("{name}.{kind}")))
}

/// The main program of `text` and the programs that follow it. A header before the main
/// program's first block names the main program itself and stays in its text.
pub fn split(text: &str) -> (&str, Vec<Section<'_>>) {
    let mut starts = Vec::new(); // (offset of the header line, name, file)
    let mut offset = 0;
    let mut seen_block = false;
    for line in text.split_inclusive('\n') {
        if let Some((name, file)) = header(line) {
            if seen_block || !starts.is_empty() {
                starts.push((offset, name, file));
            } else {
                seen_block = true; // the main program's own header
            }
        } else if !seen_block && !line.trim().is_empty() && !line.trim_start().starts_with(';') {
            seen_block = true;
        }
        offset += line.len();
    }
    let Some(&(first, _, _)) = starts.first() else {
        return (text, Vec::new());
    };
    let mut sections = Vec::new();
    for (i, (at, name, file)) in starts.iter().enumerate() {
        let end = starts.get(i + 1).map_or(text.len(), |s| s.0);
        // The section starts on the line after its header.
        let body = &text[*at..end];
        let body = body.split_once('\n').map_or("", |(_, b)| b);
        sections.push(Section {
            name: name.clone(),
            file: file.clone(),
            text: body,
        });
    }
    (&text[..first], sections)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_listing_splits_at_each_header_after_the_main_program() {
        let text = "%_N_PART_MPF\nN10 G0 X0\nN20 EX\nN30 M2\n%_N_EX_SPF ; the contour\n\
                    N100 G1 X1\nN110 M17\n%_n_two_spf\nN5 M17\n";
        let (main, sections) = split(text);
        assert_eq!(main, "%_N_PART_MPF\nN10 G0 X0\nN20 EX\nN30 M2\n");
        assert_eq!(sections.len(), 2);
        assert_eq!(sections[0].name, "EX");
        assert_eq!(sections[0].file, "EX.SPF");
        assert_eq!(sections[0].text, "N100 G1 X1\nN110 M17\n");
        assert_eq!(sections[1].name, "TWO");
        assert_eq!(sections[1].file, "two.SPF");
        assert_eq!(sections[1].text, "N5 M17\n");
    }

    #[test]
    fn a_program_without_headers_or_with_its_own_only_is_one_program() {
        for text in ["N10 G0 X0\nM2\n", "; a comment\n%_N_A_MPF\nG0 X0\nM2\n", ""] {
            assert_eq!(split(text), (text, Vec::new()));
        }
        // Not headers: a percent sign alone, a missing kind.
        let text = "G0 X0\n%\n%_N_A\nM2\n";
        assert_eq!(split(text), (text, Vec::new()));
    }
}
