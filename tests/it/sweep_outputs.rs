//! Nothing lost: identical inputs give byte-identical runs.csv, an interrupted sweep resumes
//! from its journal to the same bytes, `--fresh` redoes everything, and a failing run is
//! recorded as failed while the sweep goes on.

use crate::common;
use penumbra::experiment::progress::Progress;

use penumbra::experiment::sweep::record::Status;
use penumbra::experiment::sweep::{run_sweep, Spec};
use penumbra::render::cpu::CpuBackend;
use std::ffi::OsStr;
use std::path::Path;

fn sweep_into(exp: &Path, out: &Path, extra: &[&str]) -> String {
    let mut args = vec![exp.as_os_str(), OsStr::new("--out"), out.as_os_str()];
    args.extend(extra.iter().map(OsStr::new));
    let (code, stderr) = common::sweep(&args);
    assert_eq!(code, 0, "{stderr}");
    stderr
}

#[test]
fn identical_inputs_give_identical_runs_csv_and_resume_reproduces_it() {
    let _gpu = common::gpu();
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t);
    let (a, b, c) = (dir.path().join("a"), dir.path().join("b"), dir.path().join("c"));
    sweep_into(&exp, &a, &[]);
    sweep_into(&exp, &b, &["--fresh"]);
    let runs_a = std::fs::read(a.join("runs.csv")).unwrap();
    assert_eq!(
        runs_a,
        std::fs::read(b.join("runs.csv")).unwrap(),
        "runs.csv differs between identical sweeps"
    );
    assert_eq!(
        std::fs::read(a.join("summary.csv")).unwrap(),
        std::fs::read(b.join("summary.csv")).unwrap()
    );
    assert!(std::fs::read_to_string(a.join("runs.csv")).unwrap().lines().count() == 1 + 2 * 2 * 2 * 2);

    // Interrupt: killed after its first journaled group (the core writes each unit whole), with
    // no outputs.
    let killed = std::process::Command::new(env!("CARGO_BIN_EXE_sweep"))
        .args([exp.as_os_str(), OsStr::new("--out"), c.as_os_str()])
        .env("PENUMBRA_TEST_DIE_AFTER", "1")
        .output()
        .unwrap();
    assert!(killed.status.code().is_none(), "not killed: {:?}", killed.status);
    assert!(!c.join("runs.csv").exists());
    let log = sweep_into(&exp, &c, &[]);
    assert!(log.contains("1 of 8 units taken from the journal"), "{log}");
    assert_eq!(
        std::fs::read(c.join("runs.csv")).unwrap(),
        runs_a,
        "resumed runs.csv differs"
    );

    let log = sweep_into(&exp, &c, &["--fresh"]);
    assert!(!log.contains("taken from the journal"), "{log}");
    let manifest = std::fs::read_to_string(c.join("manifest.toml")).unwrap();
    for key in [
        "schema = 3",
        "kind = \"sweep\"",
        "[build]",
        "commit = ",
        "[[inputs]]",
        "scenes/sphere.toml",
        "seeds = [1, 2]",
        "[adapter]",
        "name =",
    ] {
        assert!(manifest.contains(key), "manifest lacks {key}:\n{manifest}");
    }
}

#[test]
fn failed_runs_are_recorded_and_the_sweep_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let spec = Spec::load(&common::tiny_experiment(dir.path(), |t| t)).unwrap();
    let mut backend = common::Flaky(CpuBackend::default());
    let out = run_sweep(&spec, &mut backend, dir.path(), true, &Progress::default()).unwrap();
    assert_eq!(out.records.len(), 16);
    assert_eq!(out.failures, 8);
    for r in &out.records {
        let failed = r.run.seed == 2;
        assert_eq!(r.status, if failed { Status::Failed } else { Status::Ok });
        assert_eq!(r.error.contains("simulated device loss"), failed);
        assert_eq!(r.metrics.rmse.is_nan(), failed);
    }
    // Groups with a failure are not journaled: a later sweep retries them.
    let journaled = std::fs::read_to_string(dir.path().join("j/groups.csv")).unwrap_or_default();
    assert!(journaled.lines().count() <= 1, "{journaled}");
}
