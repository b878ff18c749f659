//! Every committed time recomputes from the committed per-round times alone: a sweep's
//! `frame_s`, `frame_s_lo` and `frame_s_hi` in runs.csv are the median and order-statistic
//! interval of its configuration's rounds in timings.csv (every seed of a configuration carries
//! its one timing); an ao table's are those of rounds.csv; a realtime folder's timings.csv, of
//! its rounds.csv; an fps or frames table's, of its rounds.csv; a tuning.csv's, of its
//! tuning_rounds.csv, and which candidate it kept, with each candidate's word, follows from those
//! rounds by the tuning rule. The numbers are compared as the tables print them (to 12
//! significant digits).

use crate::common;
use penumbra::timing::median_interval;
use penumbra::timing::tuning::{considered_word, keep};
use std::collections::BTreeMap;
use std::path::Path;

type Row = BTreeMap<String, String>;

pub(crate) fn rows(path: &Path) -> Vec<Row> {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let headers = r.headers().unwrap().clone();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            headers
                .iter()
                .zip(rec.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

fn key(row: &Row, columns: &[&str]) -> String {
    columns
        .iter()
        .map(|c| row.get(*c).map_or("", String::as_str))
        .collect::<Vec<_>>()
        .join(";")
}

fn same(committed: &str, computed: f64) -> bool {
    match committed.parse::<f64>() {
        Ok(v) => v == computed || (v - computed).abs() <= 1e-12 * v.abs().max(computed.abs()),
        Err(_) => committed.is_empty() && computed.is_nan(),
    }
}

/// Where a table's times come from: its per-round file and column, and the table's columns
/// (median, low and high end of the interval).
struct Times<'a> {
    rounds: &'a str,
    column: &'a str,
    table: &'a str,
    columns: [&'a str; 3],
}

const FRAME: [&str; 3] = ["frame_s", "frame_s_lo", "frame_s_hi"];

impl<'a> Times<'a> {
    fn of(rounds: &'a str, table: &'a str) -> Times<'a> {
        Times {
            rounds,
            column: "frame_s",
            table,
            columns: FRAME,
        }
    }
}

/// Each series of per-round times in `rounds`, keyed by `id`, in file order.
fn series(folder: &Path, t: &Times, id: &[&str], control: Option<&str>) -> BTreeMap<String, Vec<f64>> {
    let mut series: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for r in rows(&folder.join(t.rounds)) {
        if control.is_some_and(|c| r.get(c).map(String::as_str) == Some("true")) {
            continue;
        }
        series
            .entry(key(&r, id))
            .or_default()
            .push(r[t.column].parse().unwrap());
    }
    series
}

/// Checks the time columns of `t.table` against the rounds of `t.rounds`, rows matched by `id`;
/// returns how many rows were checked and the problems.
fn check(folder: &Path, t: Times, id: &[&str], control: Option<&str>) -> (usize, Vec<String>) {
    let series = series(folder, &t, id, control);
    let table = t.table;
    let (mut checked, mut problems) = (0, Vec::new());
    for r in rows(&folder.join(table)) {
        let Some(s) = series.get(&key(&r, id)) else {
            // A row with a time must have the rounds it came from.
            if !r[t.columns[0]].is_empty() {
                problems.push(format!(
                    "{}/{table} {}: a time without rounds",
                    folder.display(),
                    key(&r, id)
                ));
            }
            continue;
        };
        let e = median_interval(s);
        for (column, value) in t.columns.into_iter().zip([e.median, e.lo, e.hi]) {
            if !same(&r[column], value) {
                problems.push(format!(
                    "{}/{table} {}: {column} = {} but its {} rounds give {value}",
                    folder.display(),
                    key(&r, id),
                    r[column],
                    s.len()
                ));
            }
        }
        checked += 1;
    }
    (checked, problems)
}

const SWEEP: &[&str] = &["scheme", "pattern", "samples", "light_radius", "lights", "accelerator"];

/// The kept candidate and each candidate's word in `folder`'s tuning.csv, recomputed from its
/// tuning_rounds.csv by the tuning rule; returns the structures checked and the problems.
fn check_tuning(folder: &Path, scene: &str) -> (usize, Vec<String>) {
    let t = Times {
        rounds: "tuning_rounds.csv",
        column: "time_s",
        table: "tuning.csv",
        columns: if scene == "mesh" {
            FRAME
        } else {
            ["tuning_s", "tuning_s_lo", "tuning_s_hi"]
        },
    };
    let rounds_id = [if scene == "mesh" { "mesh" } else { "scene" }, "structure", "candidate"];
    // The rounds file names its scene column `scene` whatever the kind calls it.
    let table_rows = rows(&folder.join("tuning.csv"));
    let by_round = series(folder, &t, &["scene", "structure", "candidate"], None);
    let (mut checked, mut problems) = (0, Vec::new());
    let mut tuned: BTreeMap<String, Vec<&Row>> = BTreeMap::new();
    // A setting taken from `--tuning` was not timed here: it has no rounds to check.
    for r in table_rows.iter().filter(|r| r["word"] != "reused") {
        tuned.entry(key(r, &rounds_id[..2])).or_default().push(r);
    }
    for (structure, candidates) in tuned {
        let times: Vec<Vec<f64>> = candidates
            .iter()
            .map(|r| by_round.get(&key(r, &rounds_id)).cloned().unwrap_or_default())
            .collect();
        if times.iter().any(Vec::is_empty) {
            problems.push(format!(
                "{}/tuning.csv {structure}: a candidate without rounds",
                folder.display()
            ));
            continue;
        }
        for (r, s) in candidates.iter().zip(&times) {
            let e = median_interval(s);
            for (column, value) in t.columns.into_iter().zip([e.median, e.lo, e.hi]) {
                if !same(&r[column], value) {
                    problems.push(format!(
                        "{}/tuning.csv {structure}: {column} = {} but its rounds give {value}",
                        folder.display(),
                        r[column]
                    ));
                }
            }
        }
        let kept = keep(&times);
        for (i, (r, c)) in candidates.iter().zip(&kept.considered).enumerate() {
            let (word, chosen) = (considered_word(c), (i == kept.index).to_string());
            if r["word"] != word
                || r["chosen"] != chosen
                || r["candidate"] != i.to_string()
                || r["against"] != c.against.to_string()
            {
                problems.push(format!(
                    "{}/tuning.csv {structure} candidate {i}: word {} chosen {} but its rounds give {word} {chosen}",
                    folder.display(),
                    r["word"],
                    r["chosen"]
                ));
            }
        }
        checked += 1;
    }
    (checked, problems)
}

#[test]
fn committed_times_recompute_from_their_rounds() {
    let mut checked = BTreeMap::new();
    let mut problems = Vec::new();
    for entry in std::fs::read_dir(common::repo("results")).unwrap() {
        let folder = entry.unwrap().path();
        let name = folder.file_name().unwrap().to_string_lossy().into_owned();
        let has = |f: &str| folder.join(f).exists();
        let (n, p) = if has("timings.csv") && has("runs.csv") && has("ground_truth.csv") {
            check(&folder, Times::of("timings.csv", "runs.csv"), SWEEP, Some("control"))
        } else if has("rounds.csv") && has("ao.csv") {
            check(
                &folder,
                Times::of("rounds.csv", "ao.csv"),
                &["mesh", "structure", "issue"],
                None,
            )
        } else if has("rounds.csv") && has("timings.csv") {
            check(
                &folder,
                Times::of("rounds.csv", "timings.csv"),
                &["what", "scheme", "rays", "filter"],
                None,
            )
        } else if has("rounds.csv") && has("fps.csv") {
            check(
                &folder,
                Times::of("rounds.csv", "fps.csv"),
                &["scene", "lights", "width", "height"],
                None,
            )
        } else if has("rounds.csv") && has("frames.csv") {
            let id = ["triangles", "structure", "update", "shading", "viewpoint", "frame"];
            check(&folder, Times::of("rounds.csv", "frames.csv"), &id, None)
        } else {
            continue;
        };
        checked.insert(name.clone(), n);
        problems.extend(p);
        if has("tuning_rounds.csv") {
            let (n, p) = check_tuning(&folder, if has("ao.csv") { "mesh" } else { "scene" });
            checked.insert(format!("{name}/tuning"), n);
            problems.extend(p);
        }
    }
    eprintln!("rows checked per folder: {checked:?}");
    for name in [
        "sphere",
        "body",
        "body-structures",
        "fps",
        "realtime",
        "ao",
        "ao/tuning",
        "ao-bundles",
        "ao-bundles/tuning",
        "ao-bundles-gpu",
        "ao-bundles-gpu/tuning",
        "walkthrough",
        "walkthrough/tuning",
        "scaling",
        "scaling/tuning",
        "dynamic",
    ] {
        assert!(
            checked.get(name).is_some_and(|&n| n > 0),
            "results/{name}: no timed row checked against its rounds"
        );
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
