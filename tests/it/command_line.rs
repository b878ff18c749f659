//! The command line: `--backend` is checked before any work, `--dry-run` lists the runs and the
//! render plan without rendering, `--filter` runs a subset into its own folder, and the exit
//! status tells bad input (2) from other failures.

use crate::common;

use std::ffi::OsStr;
use std::process::{Command, Output};

fn sweep(args: &[&OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sweep")).args(args).output().unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn an_unknown_backend_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t);
    let out = dir.path().join("r");
    let o = sweep(&[
        exp.as_os_str(),
        "--backend".as_ref(),
        "vulkan".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = text(&o.stderr);
    assert!(
        e.contains("--backend") && e.contains("auto") && e.contains("gpu") && e.contains("cpu"),
        "{e}"
    );
    assert!(!out.exists());
}

#[test]
fn a_dry_run_lists_every_run_and_the_plan_and_renders_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t);
    let out = dir.path().join("r");
    let o = sweep(&[exp.as_os_str(), "--dry-run".as_ref(), "--out".as_ref(), out.as_os_str()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let s = text(&o.stdout);
    // 2 schemes x 2 patterns x 2 ray counts, 2 seeds each.
    assert!(
        s.contains("tiny: 16 runs in 8 configurations, each over seeds [1, 2]"),
        "{s}"
    );
    assert!(s.contains("8 units:"), "{s}");
    assert_eq!(s.lines().filter(|l| l.starts_with("  scheme=")).count(), 8, "{s}");
    assert!(
        s.contains("scheme=paper pattern=shared samples=16 light_radius=0.02 lights=1"),
        "{s}"
    );
    assert!(s.contains("render plan") && s.contains("shadow"), "{s}");
    assert!(!out.exists(), "a dry run wrote results");
}

#[test]
fn a_filter_runs_a_subset_into_its_own_folder() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t);
    let dry = |filters: &[&str]| {
        let mut args: Vec<&OsStr> = vec![exp.as_os_str(), "--dry-run".as_ref()];
        for f in filters {
            args.push("--filter".as_ref());
            args.push(f.as_ref());
        }
        sweep(&args)
    };
    let o = dry(&["scheme=paper", "samples=16"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let s = text(&o.stdout);
    assert!(s.contains("tiny: 4 runs in 2 configurations"), "{s}");
    assert!(!s.contains("scheme=uniform"), "{s}");
    for (bad, why) in [
        (
            "scheme=halton",
            "not among the experiment's scheme values: uniform, paper",
        ),
        ("samples=64", "not among the experiment's samples values: 4, 16"),
        ("colour=red", "unknown axis"),
    ] {
        let o = dry(&[bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        assert!(text(&o.stderr).contains(why), "{bad}: {}", text(&o.stderr));
    }
    // A real filtered run, without --out, lands beside (not over) the whole sweep's results.
    let o = Command::new(env!("CARGO_BIN_EXE_sweep"))
        .current_dir(dir.path())
        .args([
            exp.as_os_str(),
            "--filter".as_ref(),
            "samples=4".as_ref(),
            "--backend".as_ref(),
            "cpu".as_ref(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let runs = std::fs::read_to_string(dir.path().join("results/tiny--samples=4/runs.csv")).unwrap();
    assert_eq!(runs.lines().count(), 1 + 8, "{runs}");
    assert!(!dir.path().join("results/tiny").exists());
}

/// `--version` names the commit and the cleanliness every manifest records (scripts/regenerate.sh
/// compares them with HEAD before it runs anything).
#[test]
fn version_names_the_build_the_manifests_record() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_sweep"))
        .arg("--version")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    let want = format!("({}, clean = {})", env!("PENUMBRA_COMMIT"), env!("PENUMBRA_CLEAN"));
    assert!(text.contains(&want), "{text} lacks {want}");
}
