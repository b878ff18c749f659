//! Every committed time recomputes from the committed per-round times alone: a sweep's
//! `frame_s`, `frame_s_lo` and `frame_s_hi` in runs.csv are the median and order-statistic
//! interval of its configuration's rounds in timings.csv (every seed of a configuration carries
//! its one timing); an ao table's are those of rounds.csv; a realtime folder's timings.csv, of
//! its rounds.csv. The numbers are compared as the tables print them (to 12 significant digits).

use crate::common;
use penumbra::timing::median_interval;
use std::collections::BTreeMap;
use std::path::Path;

type Row = BTreeMap<String, String>;

fn rows(path: &Path) -> Vec<Row> {
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

/// Checks `table`'s time columns against the rounds of `rounds`, rows matched by `id`; returns
/// how many rows were checked and the problems.
fn check(folder: &Path, rounds: &str, table: &str, id: &[&str], control: Option<&str>) -> (usize, Vec<String>) {
    let mut series: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for r in rows(&folder.join(rounds)) {
        if control.is_some_and(|c| r.get(c).map(String::as_str) == Some("true")) {
            continue;
        }
        series
            .entry(key(&r, id))
            .or_default()
            .push(r["frame_s"].parse().unwrap());
    }
    let (mut checked, mut problems) = (0, Vec::new());
    for r in rows(&folder.join(table)) {
        let Some(s) = series.get(&key(&r, id)) else {
            continue;
        };
        let e = median_interval(s);
        for (column, value) in [("frame_s", e.median), ("frame_s_lo", e.lo), ("frame_s_hi", e.hi)] {
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

#[test]
fn committed_times_recompute_from_their_rounds() {
    let mut checked = BTreeMap::new();
    let mut problems = Vec::new();
    for entry in std::fs::read_dir(common::repo("results")).unwrap() {
        let folder = entry.unwrap().path();
        let has = |f: &str| folder.join(f).exists();
        let (n, p) = if has("timings.csv") && has("runs.csv") && has("ground_truth.csv") {
            check(&folder, "timings.csv", "runs.csv", SWEEP, Some("control"))
        } else if has("rounds.csv") && has("ao.csv") {
            check(&folder, "rounds.csv", "ao.csv", &["mesh", "structure", "issue"], None)
        } else if has("rounds.csv") && has("timings.csv") {
            check(
                &folder,
                "rounds.csv",
                "timings.csv",
                &["what", "scheme", "rays", "filter"],
                None,
            )
        } else {
            continue;
        };
        checked.insert(folder.file_name().unwrap().to_string_lossy().into_owned(), n);
        problems.extend(p);
    }
    eprintln!("rows checked per folder: {checked:?}");
    for name in [
        "sphere",
        "body",
        "body-structures",
        "ao",
        "ao-bundles",
        "ao-bundles-gpu",
    ] {
        assert!(
            checked.get(name).is_some_and(|&n| n > 0),
            "results/{name}: no timed row checked against its rounds"
        );
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
