//! README's figures come from the reports: every committed answer in README sits between a line
//! `<!-- answer: results/NAME/report.md -->` and a line `<!-- /answer -->`, and every figure
//! written there must appear among the numbers of the report it names, so a regeneration that
//! moves a figure fails the test command until README says what the report says. Each
//! committed results folder has at least one such block, and each block quotes at least one
//! measured (decimal) figure.

use crate::common;
use std::collections::BTreeSet;

/// The numbers in `text`: digit runs with their decimal point, digit grouping (`51,224` and
/// `51\u{2009}224` read as 51224; a sentence's full stop is not a decimal point) and sign (a
/// `+` or `-` not preceded by a digit: `1.66-2.51` is a range, `-0.5 %` a sign).
fn numbers(text: &str) -> Vec<String> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        if !chars[i].is_ascii_digit() {
            i += 1;
            continue;
        }
        let signed = i > 0 && matches!(chars[i - 1], '+' | '-') && !(i > 1 && chars[i - 2].is_ascii_digit());
        let mut n = if signed {
            chars[i - 1].to_string()
        } else {
            String::new()
        };
        while i < chars.len() {
            let c = chars[i];
            let next_digit = chars.get(i + 1).is_some_and(|d| d.is_ascii_digit());
            if c.is_ascii_digit() {
                n.push(c);
            } else if c == '.' && next_digit {
                n.push('.');
            } else if (c == ',' || c == '\u{2009}' || c == '\u{202f}') && next_digit {
                // Grouping only when three digits follow (a list "1,2" is two numbers).
                let group = chars[i + 1..].iter().take_while(|d| d.is_ascii_digit()).count();
                if group != 3 {
                    break;
                }
            } else {
                break;
            }
            i += 1;
        }
        out.push(n);
    }
    out
}

/// Integers of one or two digits (counts, ranks, seeds: "6th of 9", "4 seeds") appear in any
/// report; the figures checked are the rest.
fn is_count(n: &str) -> bool {
    let digits = n.trim_start_matches(['+', '-']);
    !digits.contains('.') && digits.len() <= 2
}

/// (report path, block text) for every answer block of `readme`: a marker is a line of its own
/// (README's prose may quote one in backticks).
fn blocks(readme: &str) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    let mut open: Option<(String, String)> = None;
    for line in readme.lines() {
        let t = line.trim();
        if let Some(report) = t.strip_prefix("<!-- answer:").and_then(|r| r.strip_suffix("-->")) {
            assert!(open.is_none(), "an answer block opens inside another: {t}");
            open = Some((report.trim().to_string(), String::new()));
        } else if t == "<!-- /answer -->" {
            out.push(open.take().expect("<!-- /answer --> without an opening marker"));
        } else if let Some((_, text)) = open.as_mut() {
            text.push_str(line);
            text.push('\n');
        }
    }
    assert!(open.is_none(), "an answer block is never closed");
    out
}

#[test]
fn every_number_in_a_readme_answer_is_in_its_report() {
    let readme = std::fs::read_to_string(common::repo("README.md")).unwrap();
    let mut missing = Vec::new();
    let mut covered = BTreeSet::new();
    for (report, text) in blocks(&readme) {
        let body =
            std::fs::read_to_string(common::repo(&report)).unwrap_or_else(|e| panic!("README names {report}: {e}"));
        let known: BTreeSet<String> = numbers(&body).into_iter().collect();
        let figures: Vec<String> = numbers(&text).into_iter().filter(|n| !is_count(n)).collect();
        assert!(
            figures.iter().any(|n| n.contains('.')),
            "the answer block for {report} quotes no measured figure"
        );
        for n in figures {
            if !known.contains(&n) {
                missing.push(format!("{report}: README says {n}, the report never does"));
            }
        }
        if let Some(folder) = report.strip_prefix("results/").and_then(|r| r.split('/').next()) {
            covered.insert(folder.to_string());
        }
    }
    assert!(
        missing.is_empty(),
        "README figures not in the reports they name:\n{}",
        missing.join("\n")
    );
    // Results folders; a plain file beside them (a stability table) is not one.
    for entry in std::fs::read_dir(common::repo("results")).unwrap() {
        let entry = entry.unwrap();
        if !entry.path().is_dir() {
            continue;
        }
        let name = entry.file_name().to_string_lossy().into_owned();
        assert!(covered.contains(&name), "results/{name} has no answer block in README");
    }
}

/// The number reader keeps decimals, digit groups and signs, drops full stops and list commas;
/// block markers count only on lines of their own.
#[test]
fn numbers_and_blocks_read_as_written() {
    assert_eq!(
        numbers("1.78x (1.66-2.51x), 51,224 triangles."),
        ["1.78", "1.66", "2.51", "51224"]
    );
    assert_eq!(numbers("at 4,8 and 16. Then 0.5"), ["4", "8", "16", "0.5"]);
    assert_eq!(numbers("a 12\u{2009}345 B"), ["12345"]);
    assert_eq!(numbers("+6.8 % and -0.5 %, 3-4"), ["+6.8", "-0.5", "3", "4"]);
    let readme = "quoted `<!-- answer: x.md -->` stays prose\n  <!-- answer: a.md -->\n  1.5x\n  <!-- /answer -->\n";
    assert_eq!(blocks(readme), [("a.md".to_string(), "  1.5x\n".to_string())]);
}
