//! Nothing lost: identical inputs give byte-identical runs.csv, an interrupted sweep resumes
//! from its journal to the same bytes, `--fresh` redoes everything, and a failing run is
//! recorded as failed while the sweep goes on (and measured again on resume), and a
//! configuration the device cannot time is left untimed while the others are timed.

use crate::common;
use penumbra::experiment::progress::Progress;

use penumbra::experiment::sweep::record::Status;
use penumbra::experiment::sweep::{run_sweep, Spec};
use penumbra::render::cpu::CpuBackend;
use penumbra::sampling::DiskScheme;
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
    let mut backend = common::Refusing::seed_2();
    let out = run_sweep(&spec, &mut backend, dir.path(), true, &Progress::default()).unwrap();
    assert_eq!(out.records.len(), 16);
    assert_eq!(out.failures, 8);
    for r in &out.records {
        let failed = r.run.seed == 2;
        assert_eq!(r.status, if failed { Status::Failed } else { Status::Ok });
        assert_eq!(r.error.contains("simulated device loss"), failed);
        assert_eq!(r.metrics.rmse.is_nan(), failed);
    }
    // A unit with a failed run is measured again on resume: on a working device nothing fails.
    let mut good = CpuBackend::default();
    let again = run_sweep(&spec, &mut good, dir.path(), false, &Progress::default()).unwrap();
    assert_eq!(again.failures, 0);
    assert!(again.records.iter().all(|r| r.status == Status::Ok));
    // Units measured whole are taken from the journal: the flaky device renders nothing again.
    let resumed = run_sweep(&spec, &mut backend, dir.path(), false, &Progress::default()).unwrap();
    assert_eq!(resumed.failures, 0, "a journaled unit was measured again");
    let images = |o: &penumbra::experiment::sweep::Outcome| -> Vec<String> {
        o.records.iter().map(|r| r.image_fnv1a.clone()).collect()
    };
    assert_eq!(images(&resumed), images(&again));
}

#[test]
fn a_configuration_that_cannot_be_timed_is_left_untimed_and_the_rest_are_timed() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t.replace("repeats = 0", "repeats = 6"));
    let spec = Spec::load(&exp).unwrap();
    assert_eq!(spec.timing.repeats, 6, "the tiny experiment's timing was not edited");
    let mut backend = common::Refusing {
        cpu: CpuBackend::default(),
        refuses: |s| s.scheme == DiskScheme::Paper,
        timing_too: true,
    };
    let out = run_sweep(&spec, &mut backend, dir.path(), true, &Progress::default()).unwrap();
    assert_eq!(out.failures, 8, "every paper run fails, every uniform run renders");
    for r in &out.records {
        let paper = r.run.scheme == DiskScheme::Paper;
        assert_eq!(r.status == Status::Ok, !paper);
        assert_eq!(r.time.frame_s.is_nan(), paper, "{:?}", r.run);
    }
}
