//! Every ratio a report states, with its interval and word, recomputes from the folder's CSVs
//! alone (not from the run that wrote them), for a sample of each kind of comparison:
//! - a sweep's `vs uniform@16` cells and its A/A control line: the stopping rule replayed on the
//!   per-round times of timings.csv ([`decide`] at the looks of the manifest's cap) gives the
//!   ratio, the word and the rounds it took;
//! - an ao folder's claim lines and open-question table: the paired per-round ratio of
//!   rounds.csv, as a speed-up, with the rule's word;
//! - a frames folder without motion (the walkthrough, scaling): the median of per-frame
//!   speed-ups of frames.csv with its order-statistic interval and the count of frames faster.
//!
//! Each expected text is built from the CSVs with the library's rule and printing and must
//! appear in report.md as written; a report cell of a kind checked here that no recomputed text
//! matches fails too, so a report that drifts from its CSVs, or CSVs that cannot give back what
//! the report says, are caught. Sweep cells are matched to the configuration their section
//! names (lights, structure, radius, count), so a cell moved between tables fails.
//!
//! Beyond that sample, every interval any report prints with a word beside it (equal-time
//! budgets, time to reach a target, realtime budgets, speed-ups) must carry the rule's word for
//! that printed interval.

use crate::common;
use crate::round_times::rows;
use penumbra::experiment::frames::verdict::Speedup;
use penumbra::experiment::frames::FramesSpec;
use penumbra::timing::sequential::{decide, Looks};
use penumbra::timing::{paired_ratio, Comparison};
use std::collections::BTreeMap;
use std::path::Path;

fn report(folder: &Path) -> String {
    std::fs::read_to_string(folder.join("report.md")).unwrap()
}

/// The sequential design's cap, as the manifest records the run's `[timing] repeats`.
fn cap(folder: &Path) -> u32 {
    let text = std::fs::read_to_string(folder.join("manifest.toml")).unwrap();
    let manifest: toml::Table = text.parse().unwrap();
    manifest["timing"]["repeats"].as_integer().unwrap() as u32
}

/// The text a sweep report prints for a ratio of two series under the stopping rule.
fn decided_text(a: &[f64], b: &[f64], looks: Looks) -> (String, String) {
    let d = decide(a, b, looks);
    (
        d.ratio.show_ratio(2),
        format!("{} ({} rounds)", d.word.word(), d.rounds),
    )
}

/// Per-round frame times keyed by the configuration's columns.
type Series = BTreeMap<Vec<String>, Vec<f64>>;

/// Checks a sweep folder; returns the cells matched and the problems.
fn sweep(folder: &Path) -> (usize, Vec<String>) {
    const CONFIG: [&str; 6] = ["scheme", "pattern", "samples", "light_radius", "lights", "accelerator"];
    let looks = Looks::up_to(cap(folder));
    let mut series: Series = BTreeMap::new();
    let mut control: Series = BTreeMap::new();
    for r in rows(&folder.join("timings.csv")) {
        let id: Vec<String> = CONFIG.iter().map(|c| r[*c].clone()).collect();
        let into = if r["control"] == "true" {
            &mut control
        } else {
            &mut series
        };
        into.entry(id).or_default().push(r["frame_s"].parse().unwrap());
    }
    // Every scheme against uniform sampling at its own count, pattern, radius, lights, structure.
    let mut expected: BTreeMap<Vec<String>, String> = BTreeMap::new();
    for (id, s) in series.iter().filter(|(id, _)| id[0] != "uniform") {
        let mut base = id.clone();
        base[0] = "uniform".into();
        if let Some(u) = series.get(&base) {
            let (ratio, word) = decided_text(s, u, looks);
            expected.insert(id.clone(), format!("{ratio}x uniform's time: {word}"));
        }
    }
    let text = report(folder);
    let (mut matched, mut problems) = (0, Vec::new());
    // The section a cell lies in names the rest of its configuration: lights (and the
    // structure, where several are swept) in its heading, the radius in its first paragraph,
    // the count in its table's header.
    let (mut lights, mut accelerator, mut radius, mut samples) = (None, None, None, None);
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("## ") {
            let inside = rest
                .split_once('(')
                .map_or("", |(_, r)| r.strip_suffix(')').unwrap_or(r));
            lights = inside.split_once(" light(s)").map(|(l, _)| l.to_string());
            accelerator = inside.split_once("accelerator=").map(|(_, a)| a.to_string());
            (radius, samples) = (None, None);
        }
        if let Some((_, r)) = line.split_once("light radius ") {
            radius = r.split_once(" m").and_then(|(r, _)| r.parse::<f64>().ok());
        }
        if let Some((_, n)) = line.split_once("| vs uniform@") {
            samples = n.split_once(' ').map(|(n, _)| n.to_string());
        }
        if !line.contains("x uniform's time: ") {
            continue;
        }
        let scheme = line.trim_start_matches("| ").split(" |").next().unwrap_or("");
        let cell = line
            .split(" | ")
            .find(|c| c.contains("x uniform's time: "))
            .unwrap()
            .trim_end_matches(" |");
        let here = |id: &Vec<String>| {
            id[0] == scheme
                && id[1] == "per-pixel"
                && Some(&id[2]) == samples.as_ref()
                && id[3].parse::<f64>().ok() == radius
                && Some(&id[4]) == lights.as_ref()
                && accelerator.as_ref().is_none_or(|a| &id[5] == a)
        };
        let want: Vec<&String> = expected.iter().filter(|(id, _)| here(id)).map(|(_, t)| t).collect();
        if want.len() == 1 && want[0] == cell {
            matched += 1;
        } else {
            problems.push(format!(
                "{}: `{scheme}`'s `{cell}` (lights {lights:?}, {accelerator:?}, radius {radius:?}, \
                 {samples:?} rays) is not what timings.csv gives: {want:?}",
                folder.display()
            ));
        }
    }
    // The A/A control: the twin's series over the first's.
    for (id, twin) in &control {
        let d = decide(twin, &series[id], looks);
        let (ratio, word) = (
            d.ratio.show_ratio(3),
            format!("**{}** after {} rounds", d.word.word(), d.rounds),
        );
        let want = format!("the time ratio of its two series is {ratio}: {word}");
        if text.contains(&want) {
            matched += 1;
        } else {
            problems.push(format!("{}: no A/A line `{want}`", folder.display()));
        }
    }
    (matched, problems)
}

/// Checks an ao folder; returns the comparisons matched and the problems.
fn ao(folder: &Path) -> (usize, Vec<String>) {
    // (mesh, structure, issue) -> seconds per round, in round order.
    let mut series: BTreeMap<(String, String, String), Vec<f64>> = BTreeMap::new();
    let mut meshes: Vec<String> = Vec::new();
    for r in rows(&folder.join("rounds.csv")) {
        if !meshes.contains(&r["mesh"]) {
            meshes.push(r["mesh"].clone());
        }
        series
            .entry((r["mesh"].clone(), r["structure"].clone(), r["issue"].clone()))
            .or_default()
            .push(r["frame_s"].parse().unwrap());
    }
    // The other's time over the subject's, as a speed-up with the subject's word.
    let speedup = |mesh: &str, subject: (&str, &str), other: (&str, &str)| -> Option<(String, &'static str)> {
        let a = series.get(&(mesh.into(), subject.0.into(), subject.1.into()))?;
        let b = series.get(&(mesh.into(), other.0.into(), other.1.into()))?;
        let ratio = paired_ratio(a, b);
        Some((ratio.recip().show_speedup(2), Comparison::of(&ratio).word()))
    };
    let text = report(folder);
    let (mut matched, mut problems) = (0, Vec::new());
    // The claim lines: "- **`vlf` vs `kdtree`** ...: cow 2.04 [1.98, 2.17]x (faster), ...".
    for line in text.lines().filter(|l| l.starts_with("- **`") && l.contains("` vs `")) {
        let names: Vec<&str> = line.split('`').collect();
        let (subject, other) = (names[1], names[3]);
        for mesh in &meshes {
            let Some((s, word)) = speedup(mesh, (subject, "single"), (other, "single")) else {
                continue;
            };
            let want = format!("{mesh} {s}x ({word})");
            if line.contains(&want) {
                matched += 1;
            } else {
                problems.push(format!("{}: `{subject}` vs `{other}` lacks `{want}`", folder.display()));
            }
        }
    }
    // The open question's rows: "| `kdtree` single / `vlf` single | cell per mesh |".
    for line in text.lines().filter(|l| l.starts_with("| `")) {
        let label = line[2..].split(" |").next().unwrap();
        let Some((first, second)) = label.split_once(" / ") else {
            continue;
        };
        let parse = |s: &str| -> Option<(String, String)> {
            let (name, issue) = s.rsplit_once(' ')?;
            Some((name.trim_matches('`').to_string(), issue.to_string()))
        };
        let (Some(other), Some(subject)) = (
            parse(first),
            parse(second).or_else(|| {
                // "`vlf` single / bundled": the same structure.
                let (name, _) = parse(first)?;
                Some((name, second.to_string()))
            }),
        ) else {
            continue;
        };
        let cells: Vec<String> = meshes
            .iter()
            .map(|m| {
                speedup(m, (&subject.0, &subject.1), (&other.0, &other.1))
                    .map_or("n/a".to_string(), |(s, w)| format!("{s}x {w}"))
            })
            .collect();
        let want = format!("| {label} | {} |", cells.join(" | "));
        if line == want {
            matched += 1;
        } else {
            problems.push(format!("{}: `{line}` but rounds.csv gives `{want}`", folder.display()));
        }
    }
    (matched, problems)
}

/// Checks a frames folder without motion; returns the comparisons matched and the problems.
fn frames(folder: &Path, name: &str) -> (usize, Vec<String>) {
    let spec = FramesSpec::load(&common::repo(&format!("experiments/{name}.toml"))).unwrap();
    if spec.motion.is_some() {
        return (0, Vec::new());
    }
    let subject = spec.claim.subject.as_str();
    // (shading, triangles, viewpoint) -> structure -> frame -> seconds.
    type Cells = BTreeMap<(String, String, String), BTreeMap<String, BTreeMap<u32, f64>>>;
    let mut cells = Cells::new();
    for r in rows(&folder.join("frames.csv")) {
        cells
            .entry((r["shading"].clone(), r["triangles"].clone(), r["viewpoint"].clone()))
            .or_default()
            .entry(r["structure"].clone())
            .or_default()
            .insert(r["frame"].parse().unwrap(), r["frame_s"].parse().unwrap());
    }
    let text = report(folder);
    let (mut matched, mut problems) = (0, Vec::new());
    for ((shading, triangles, viewpoint), by) in &cells {
        let ours = &by[subject];
        for (other, theirs) in by.iter().filter(|(s, _)| s.as_str() != subject) {
            let ratios: Vec<f64> = ours.iter().map(|(f, s)| theirs[f] / s).collect();
            let sp = Speedup::of(&ratios, spec.cameras);
            let faster = ratios.iter().filter(|&&x| x > 1.0).count();
            let shown = sp.estimate.show_speedup(2);
            let answer = sp.comparison().answer();
            // One cell: "...**yes**: speed-up per frame (...) 1.18 [..]x (...), faster on 60 of
            // 60 frames"; several: "1K outside **no** 0.81 [..]x (2 of 32 frames faster)".
            let single = format!("**{answer}**: speed-up per frame (its time / `{subject}`'s) {shown}x");
            let tail = format!("faster on {faster} of {} frames", ratios.len());
            let thousands = triangles.parse::<f64>().unwrap() / 1e3;
            let cell = format!(
                "{thousands}K {viewpoint} **{answer}** {shown}x ({faster} of {} frames faster)",
                ratios.len()
            );
            let question = format!("- **Is `{subject}` faster than `{other}`");
            let asked = text
                .lines()
                .find(|l| l.starts_with(&question) && l.contains(&format!(", {shading} shading?**")));
            match asked {
                Some(l) if (l.contains(&single) && l.contains(&tail)) || l.contains(&cell) => matched += 1,
                Some(l) => problems.push(format!(
                    "{}: `{l}` lacks `{single} ... {tail}` or `{cell}`",
                    folder.display()
                )),
                None => problems.push(format!(
                    "{}: no question for `{other}`, {shading} shading",
                    folder.display()
                )),
            }
        }
    }
    (matched, problems)
}

#[test]
fn every_ratio_a_report_states_recomputes_from_its_csvs() {
    let mut matched = BTreeMap::new();
    let mut problems = Vec::new();
    for entry in std::fs::read_dir(common::repo("results")).unwrap() {
        let folder = entry.unwrap().path();
        if !folder.is_dir() {
            continue;
        }
        let name = folder.file_name().unwrap().to_string_lossy().into_owned();
        let has = |f: &str| folder.join(f).exists();
        let (n, p) = if has("timings.csv") && has("ground_truth.csv") {
            sweep(&folder)
        } else if has("ao.csv") {
            ao(&folder)
        } else if has("frames.csv") {
            frames(&folder, &name)
        } else {
            continue;
        };
        matched.insert(name, n);
        problems.extend(p);
    }
    eprintln!("report ratios recomputed per folder: {matched:?}");
    for name in [
        "sphere",
        "body",
        "body-structures",
        "ao",
        "ao-bundles",
        "ao-bundles-gpu",
        "walkthrough",
        "scaling",
    ] {
        assert!(
            matched.get(name).is_some_and(|&n| n > 0),
            "results/{name}: no ratio of its report recomputed"
        );
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The word a report gives an interval, where a word follows it in the same phrase: the
/// interval's bounds, the word, and the text between them.
fn worded_intervals(text: &str) -> Vec<(f64, f64, &'static str, String)> {
    const WORDS: [&str; 6] = ["faster", "slower", "better", "worse", "equivalent", "undecided"];
    let mut out = Vec::new();
    for (at, _) in text.match_indices(" [") {
        let rest = &text[at + 2..];
        let ratio_before = text[..at].rsplit([' ', '(', '*']).next().unwrap_or("");
        let Some((inside, after)) = rest.split_once(']') else {
            continue;
        };
        let Some((lo, hi)) = inside.split_once(", ") else {
            continue;
        };
        let (Ok(lo), Ok(hi), Ok(_)) = (lo.parse::<f64>(), hi.parse::<f64>(), ratio_before.parse::<f64>()) else {
            continue;
        };
        // The phrase ends at the next cell, clause or interval.
        let mut end = after.find(['|', ';', '[', '\n']).unwrap_or(after.len()).min(40);
        while !after.is_char_boundary(end) {
            end -= 1;
        }
        let phrase = &after[..end];
        let word = phrase
            .split(|c: char| !c.is_ascii_alphabetic())
            .enumerate()
            .find(|&(i, w)| WORDS.contains(&w) && !(i > 0 && phrase.contains(&format!("frames {w}"))))
            .map(|(_, w)| WORDS.into_iter().find(|x| *x == w).unwrap());
        if let Some(word) = word {
            out.push((lo, hi, word, phrase.to_string()));
        }
    }
    out
}

/// Whatever the comparison, a word must be the rule's for the interval printed beside it
/// (intervals are printed with the digits that decide them): a direction only for an interval
/// wholly beyond the margin, *equivalent* only wholly inside it, *undecided* otherwise; an
/// error is *better* below 1 and *worse* above.
#[test]
fn every_word_in_every_report_is_the_rules_for_its_printed_interval() {
    let (lo_band, hi_band) = penumbra::timing::rule::band();
    let (mut seen, mut problems) = (0, Vec::new());
    for entry in std::fs::read_dir(common::repo("results")).unwrap() {
        let report = entry.unwrap().path().join("report.md");
        let Ok(text) = std::fs::read_to_string(&report) else {
            continue;
        };
        for (lo, hi, word, phrase) in worded_intervals(&text) {
            seen += 1;
            let (outside, inside) = (hi < lo_band || lo > hi_band, lo >= lo_band && hi <= hi_band);
            let fits = match word {
                "equivalent" => inside,
                "undecided" => !outside && !inside,
                "better" => hi < lo_band,
                "worse" => lo > hi_band,
                _ => outside,
            };
            if !fits {
                problems.push(format!("{}: [{lo}, {hi}]{phrase}", report.display()));
            }
        }
    }
    assert!(seen > 300, "only {seen} worded intervals found in the reports");
    assert!(
        problems.is_empty(),
        "words the rule does not give:\n{}",
        problems.join("\n")
    );
}
