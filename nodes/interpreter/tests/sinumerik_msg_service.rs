//! The MSG service (`001` §8.4.4, fixture 003, decisions D120): `MSG("V24: …")` and
//! `MSG("File: …")` send their text through the message service's output, not to the
//! display; the same text goes out again only after an empty text for that output.

#[path = "support/sinumerik.rs"]
mod support;

use cnc_interpreter_core::ServiceOutput;
use support::*;

fn sent(r: &mut Run) -> Vec<(ServiceOutput, String)> {
    std::mem::take(&mut r.front.core.service_messages)
        .into_iter()
        .map(|(_, output, text)| (output, text))
        .collect()
}

/// Fixture 003 with its interface made `File` and its placeholders moves: each of the three
/// identical texts goes out, since an empty text follows each.
#[test]
fn f003_each_repeated_text_goes_out_after_its_empty_text() {
    let text = fixture("003").replace("<接口>", "File");
    let holes = text.lines().filter(|l| placeholder(l)).count();
    let fills: Vec<String> = (0..holes).map(|k| format!("G1 F100 X{k}")).collect();
    let fills: Vec<&str> = fills.iter().map(String::as_str).collect();
    let program = {
        let mut t = String::new();
        let mut f = fills.iter();
        for line in text.lines() {
            t.push_str(if placeholder(line) {
                f.next().unwrap()
            } else {
                line
            });
            t.push('\n');
        }
        t + "M30\n"
    };
    let mut r = run(&program).ok();
    let out = sent(&mut r);
    assert_eq!(
        out,
        vec![(ServiceOutput::File, "示例文本".to_string()); 3],
        "{out:?}"
    );
    // Nothing of it on the display.
    assert_eq!(r.front.message(), "");
    // Without the empty texts the same text goes out once.
    let once = program.replace("MSG(\"File:\")\n", "");
    let mut r = run(&once).ok();
    assert_eq!(sent(&mut r).len(), 1);
}

#[test]
fn the_interface_is_named_before_the_text_and_the_rest_is_the_display_s() {
    let mut r = run("MSG(\"V24:轮廓粗加工\")\nMSG(\"FILE: 轮廓粗加工\")\nR1=5\n\
                     MSG(\"File: X\"<<R1)\nMSG(\"轮廓粗加工\")\nM30\n")
    .ok();
    assert_eq!(
        sent(&mut r),
        vec![
            (ServiceOutput::Serial, "轮廓粗加工".to_string()),
            (ServiceOutput::File, "轮廓粗加工".to_string()),
            (ServiceOutput::File, "X5".to_string()),
        ]
    );
    assert_eq!(r.front.message(), "轮廓粗加工");
}
