//! The axis list (experiment/sweep/axes.rs) is the one place the tables take their identity
//! from: runs.csv's identity columns are the axes in their declared order, summary.csv's and
//! timings.csv's the same without the seed, and rows come in the list's expansion order.

use crate::common;

use penumbra::experiment::sweep::axes::Axis;
use penumbra::experiment::sweep::run::expand;
use penumbra::experiment::sweep::Spec;
use std::ffi::OsStr;

fn table(path: &std::path::Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|x| x.unwrap().iter().map(String::from).collect())
        .collect();
    (header, rows)
}

#[test]
fn identity_columns_and_row_order_come_from_the_axis_list() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| {
        t.replace("light_radii = [0.02]", "light_radii = [0.02, 0.03]")
            .replace("repeats = 0", "repeats = 6")
    });
    let out = dir.path().join("out");
    let (code, e) = common::sweep(&[
        exp.as_os_str(),
        OsStr::new("--backend"),
        OsStr::new("cpu"),
        OsStr::new("--out"),
        out.as_os_str(),
    ]);
    assert_eq!(code, 0, "{e}");
    let axes: Vec<String> = Axis::ALL.iter().map(|a| a.name().to_string()).collect();
    let n = axes.len();
    assert_eq!(axes.last().map(String::as_str), Some("seed"));

    let (header, rows) = table(&out.join("runs.csv"));
    assert_eq!(header[..2], ["run_key", "status"]);
    assert_eq!(header[2..2 + n], axes[..]);
    let spec = Spec::load(&exp).unwrap();
    let expected: Vec<Vec<String>> = expand(&spec)
        .iter()
        .flat_map(|g| g.runs.iter())
        .map(|r| {
            let mut v: Vec<String> = r.config().values().into_iter().map(|(_, v)| v).collect();
            v.push(r.seed.to_string());
            v
        })
        .collect();
    let got: Vec<Vec<String>> = rows.iter().map(|r| r[2..2 + n].to_vec()).collect();
    assert_eq!(got, expected, "runs.csv rows in expansion order");
    // Light radius nests outside the scheme: the first half of the rows has the first radius.
    assert!(got[..got.len() / 2].iter().all(|r| r[3] == "0.02"), "{got:?}");

    for (file, next) in [("summary.csv", "seeds"), ("timings.csv", "control")] {
        let (header, _) = table(&out.join(file));
        assert_eq!(header[..n - 1], axes[..n - 1], "{file}");
        assert_eq!(header[n - 1], next, "{file}");
    }
}

/// Plots and report sections that do not name an axis are drawn once per value of it: with two
/// light counts, one set of plots and one cost section each, and the verdict (one light) once.
#[test]
fn reports_hold_an_axis_they_do_not_name_at_each_value() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| {
        t.replace("seeds = [1, 2]", "seeds = [1, 2]\nlight_counts = [1, 2]")
    });
    std::fs::copy(
        common::repo("experiments/scenes/sphere-two-lights.toml"),
        dir.path().join("scenes/sphere.toml"),
    )
    .unwrap();
    let out = dir.path().join("out");
    let (code, e) = common::sweep(&[
        exp.as_os_str(),
        OsStr::new("--backend"),
        OsStr::new("cpu"),
        OsStr::new("--out"),
        out.as_os_str(),
    ]);
    assert_eq!(code, 0, "{e}");
    for lights in [1, 2] {
        assert!(out.join(format!("plots/rmse_vs_samples_lights-{lights}.png")).is_file());
    }
    assert!(!out.join("plots/rmse_vs_samples.png").exists());
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for lights in [1, 2] {
        let heading = format!("## What accuracy costs ({lights} light(s))");
        assert_eq!(report.matches(&heading).count(), 1, "{report}");
    }
    assert_eq!(report.matches("pattern, 2 seeds.**").count(), 2, "{report}");
}
