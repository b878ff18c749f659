//! Sharded sweeps: the deal of groups to shards (deterministic, complete, balanced, ground truths
//! kept together where that pays), the CI experiment run as 3 shards and merged against the same
//! experiment unsharded, refused merges (missing, unfinished, duplicated, foreign shards) that
//! write nothing, a shard killed midway that resumes from its journal, and, where `sbatch` and a
//! running Slurm exist, the job-array script end to end.

use crate::common;
use penumbra::experiment::progress::Progress;

use penumbra::experiment::sweep::merge::{merge_shards, MergePlan};
use penumbra::experiment::sweep::run::{expand, Group};
use penumbra::experiment::sweep::shard::{assign, run_shard, share, Shard};
use penumbra::experiment::sweep::{run_sweep, Spec};
use penumbra::output::table::write_rows;
use penumbra::render::cpu::CpuBackend;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

fn sweep(args: &[&OsStr]) -> (i32, String) {
    common::sweep(args)
}

fn os(s: &str) -> &OsStr {
    OsStr::new(s)
}

fn ci() -> PathBuf {
    common::repo("experiments/ci.toml")
}

fn run_ok(args: &[&OsStr]) -> String {
    let (code, err) = sweep(args);
    assert_eq!(code, 0, "sweep {args:?} failed:\n{err}");
    err
}

#[test]
fn shard_texts_parse_and_bad_ones_are_refused() {
    assert_eq!("2/3".parse::<Shard>(), Ok(Shard { index: 2, count: 3 }));
    assert_eq!(Shard { index: 2, count: 3 }.to_string(), "2/3");
    for bad in ["0/3", "4/3", "3", "a/3", "1/0", "-1/2", "1/2/3", ""] {
        let e = bad.parse::<Shard>().unwrap_err();
        assert!(e.contains("1 <= K <= N"), "{bad}: {e}");
    }
    assert_eq!(
        Shard { index: 2, count: 3 }.dir(Path::new("results/ci")),
        Path::new("results/ci/shards/2-of-3")
    );
}

/// Expected rays of every group, as the deal counts them (frames x rays per frame, read from the
/// runs' configuration here rather than from the deal's code): pixels x (1 + lights x samples).
fn group_rays(spec: &Spec) -> Vec<f64> {
    let pixels = (spec.measure.width * spec.measure.height) as f64;
    expand(spec)
        .iter()
        .map(|g| g.runs.len() as f64 * pixels * (1.0 + (g.head().lights * g.head().samples) as f64))
        .collect()
}

#[test]
fn the_deal_covers_every_group_once_is_deterministic_and_balanced() {
    let spec = Spec::load(&ci()).unwrap();
    let groups = expand(&spec);
    let rays = group_rays(&spec);
    let total: f64 = rays.iter().sum();
    let biggest = rays.iter().cloned().fold(0.0, f64::max);
    for n in 1..=7u32 {
        let deal = assign(&spec, &groups, n);
        assert_eq!(deal.len(), groups.len());
        assert!(deal.iter().all(|&s| s < n));
        let mut load = vec![0.0; n as usize];
        for (s, r) in deal.iter().zip(&rays) {
            load[*s as usize] += r;
        }
        // Greedy list scheduling: every share renders the one ground truth of this single-radius
        // sweep (the deal gains nothing by leaving one idle), and no share's runs exceed their
        // mean by more than one group. One share holding everything fails this for n >= 2.
        let max = load.iter().cloned().fold(0.0, f64::max);
        assert!(
            max <= total / n as f64 + biggest,
            "n={n}: loads {load:?}, mean {}, biggest group {biggest}",
            total / n as f64
        );
        assert!(load.iter().all(|&l| l > 0.0), "n={n}: an idle share: {load:?}");
    }
    // Shares follow the groups' keys, not their order in the file: the same experiment with its
    // seeds listed in another order is dealt alike, group by group.
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (
        common::tiny_experiment(&dir.path().join("a"), |t| {
            t.replace("samples = [4, 16]", "samples = [4, 16, 64]")
        }),
        common::tiny_experiment(&dir.path().join("b"), |t| {
            t.replace("samples = [4, 16]", "samples = [64, 4, 16]")
        }),
    );
    let deal_of = |p: &Path| {
        let spec = Spec::load(p).unwrap();
        let groups = expand(&spec);
        let mut d: Vec<(String, u32)> = groups
            .iter()
            .map(|g| g.head().key_text())
            .zip(assign(&spec, &groups, 3))
            .collect();
        d.sort();
        d
    };
    assert_eq!(deal_of(&a), deal_of(&b));
}

/// The shares the groups of light radius `r` fell to.
fn shares_of_radius(groups: &[Group], deal: &[u32], r: f64) -> Vec<u32> {
    groups
        .iter()
        .zip(deal)
        .filter(|(g, _)| g.head().light_radius == r)
        .map(|(_, &s)| s)
        .collect()
}

#[test]
fn groups_sharing_a_costly_ground_truth_stay_together_and_cheap_ones_spread() {
    let dir = tempfile::tempdir().unwrap();
    // Four radii, each judged against a ground truth far costlier than its runs: two shards
    // should each take two radii whole rather than render all four ground truths.
    let costly = common::tiny_experiment(dir.path(), |t| {
        t.replace("light_radii = [0.02]", "light_radii = [0.01, 0.02, 0.03, 0.04]")
            .replace("samples = 256", "samples = 4096")
    });
    let spec = Spec::load(&costly).unwrap();
    let groups = expand(&spec);
    let deal = assign(&spec, &groups, 2);
    for &r in &spec.axes.light_radii {
        let shares = shares_of_radius(&groups, &deal, r);
        assert!(shares.windows(2).all(|w| w[0] == w[1]), "radius {r} split: {shares:?}");
    }
    assert!(deal.contains(&0) && deal.contains(&1), "{deal:?}");

    // Three radii with a ground truth far cheaper than a group: two shards balance only by
    // splitting a radius, and that pays.
    let cheap = common::tiny_experiment(&dir.path().join("cheap"), |t| {
        t.replace("light_radii = [0.02]", "light_radii = [0.01, 0.02, 0.03]")
            .replace("samples = 256", "samples = 1")
            .replace("samples = [4, 16]", "samples = [64, 256]")
    });
    let spec = Spec::load(&cheap).unwrap();
    let groups = expand(&spec);
    let deal = assign(&spec, &groups, 2);
    let split = spec.axes.light_radii.iter().any(|&r| {
        let shares = shares_of_radius(&groups, &deal, r);
        shares.contains(&0) && shares.contains(&1)
    });
    assert!(split, "no radius spread over both shares: {deal:?}");
    let rays = group_rays(&spec);
    let mut load = [0.0; 2];
    for (s, r) in deal.iter().zip(&rays) {
        load[*s as usize] += r;
    }
    let smallest = rays.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!((load[0] - load[1]).abs() <= smallest, "unbalanced: {load:?}");
}

/// Asserts each of `files` is byte for byte the same under `a` and `b`.
fn same_files(a: &Path, b: &Path, files: &[&str]) {
    for file in files {
        let (x, y) = (
            std::fs::read(a.join(file)).unwrap(),
            std::fs::read(b.join(file)).unwrap(),
        );
        assert!(x == y, "{file} differs");
    }
}

/// The CI experiment: unsharded into `dir/full`, as 3 shards merged into `dir/sharded`.
fn full_and_sharded(dir: &Path) -> (PathBuf, PathBuf) {
    let full = dir.join("full");
    let sharded = dir.join("sharded");
    run_ok(&[ci().as_os_str(), os("--out"), full.as_os_str()]);
    for k in 1..=3 {
        let s = format!("{k}/3");
        run_ok(&[
            ci().as_os_str(),
            os("--out"),
            sharded.as_os_str(),
            os("--shard"),
            os(&s),
        ]);
        assert!(!sharded.join("runs.csv").exists(), "a shard wrote the final outputs");
    }
    run_ok(&[
        ci().as_os_str(),
        os("--out"),
        sharded.as_os_str(),
        os("--merge"),
        os("3"),
    ]);
    (full, sharded)
}

#[test]
fn three_shards_merged_give_the_unsharded_tables_and_figures() {
    let _gpu = common::gpu();
    let dir = tempfile::tempdir().unwrap();
    let (full, sharded) = full_and_sharded(dir.path());
    for table in ["runs.csv", "summary.csv"] {
        let (a, b) = (
            common::without_clock(&full.join(table)),
            common::without_clock(&sharded.join(table)),
        );
        assert!(a.len() > 1);
        assert_eq!(a, b, "{table} differs");
    }
    // Every run was rendered by exactly one shard, each shard a real share.
    let mut shard_runs = 0;
    for k in 1..=3 {
        let n = common::without_clock(&sharded.join(format!("shards/{k}-of-3/records.csv"))).len() - 1;
        assert!(n > 0, "shard {k} ran nothing");
        shard_runs += n;
    }
    assert_eq!(shard_runs, common::without_clock(&full.join("runs.csv")).len() - 1);
    same_files(
        &full,
        &sharded,
        &[
            "ground_truth.csv",
            "images/fig2_measure.png",
            "images/ground_truth.exr",
            "plots/profiles.png",
            "plots/profiles.svg",
            "plots/rmse_vs_samples.png",
        ],
    );
    // The merge timed every configuration itself, in one phase.
    let timed = common::without_clock(&sharded.join("timings.csv")).len();
    assert!(timed > 1, "the merge timed nothing");
}

#[test]
fn a_sweep_over_two_radii_merged_from_two_shards_is_byte_identical_without_timing() {
    let _gpu = common::gpu();
    let dir = tempfile::tempdir().unwrap();
    // Radii listed largest first and a timing-free sweep: every byte of the tables must match,
    // rows in the unsharded order whichever shard rendered them.
    let exp = common::tiny_experiment(dir.path(), |t| {
        t.replace("light_radii = [0.02]", "light_radii = [0.03, 0.01]")
    });
    let (full, sharded) = (dir.path().join("full"), dir.path().join("sharded"));
    run_ok(&[exp.as_os_str(), os("--out"), full.as_os_str()]);
    for k in ["1/2", "2/2"] {
        run_ok(&[exp.as_os_str(), os("--out"), sharded.as_os_str(), os("--shard"), os(k)]);
    }
    run_ok(&[
        exp.as_os_str(),
        os("--out"),
        sharded.as_os_str(),
        os("--merge"),
        os("2"),
    ]);
    same_files(
        &full,
        &sharded,
        &[
            "runs.csv",
            "summary.csv",
            "ground_truth.csv",
            "plots/width_vs_radius.png",
        ],
    );
}

#[test]
fn merges_missing_unfinished_duplicated_or_foreign_shards_are_refused_and_write_nothing() {
    let _gpu = common::gpu();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    for k in [1, 3] {
        run_ok(&[
            ci().as_os_str(),
            os("--out"),
            out.as_os_str(),
            os("--shard"),
            os(&format!("{k}/3")),
        ]);
    }
    // Earlier results in the folder must survive every refused merge.
    common::earlier_results(&out, "sweep", "ci");
    let refused = |extra: &[&OsStr], expect: &[&str]| {
        let mut args = vec![
            ci().into_os_string(),
            "--out".into(),
            out.clone().into_os_string(),
            "--merge".into(),
        ];
        args.extend(extra.iter().map(|s| s.to_os_string()));
        let refs: Vec<&OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        let (code, err) = sweep(&refs);
        assert_eq!(code, 4, "{err}");
        for e in expect {
            assert!(err.contains(e), "missing `{e}` in:\n{err}");
        }
        assert_eq!(
            std::fs::read_to_string(out.join("runs.csv")).unwrap(),
            "earlier results\n"
        );
        assert!(!out.join("summary.csv").exists() && !out.join("report.md").exists());
    };
    let shard = |k: u32| out.join(format!("shards/{k}-of-3"));
    // Shard 2 never ran: its runs are listed with the command that reruns it.
    let spec = Spec::load(&ci()).unwrap();
    let runs: usize = share(&spec, Shard { index: 2, count: 3 })
        .iter()
        .map(|g| g.runs.len())
        .sum();
    let incomplete = format!("shard 2/3 is incomplete ({runs} runs missing)");
    refused(
        &[os("3")],
        &[
            "2-of-3: no such shard folder",
            &incomplete,
            "--shard 2/3",
            "seeds=[1, 2, 3, 4, 5, 6]",
        ],
    );
    // The same shard twice.
    refused(
        &[shard(1).as_os_str(), shard(1).as_os_str(), shard(3).as_os_str()],
        &["in more than one shard", "shard 2/3"],
    );
    // Shards of another split under the results folder.
    let five = out.join("shards/2-of-5");
    std::fs::create_dir_all(out.join("shards")).unwrap();
    run_ok(&[ci().as_os_str(), os("--out"), out.as_os_str(), os("--shard"), os("2/5")]);
    refused(
        &[shard(1).as_os_str(), five.as_os_str(), shard(3).as_os_str()],
        &["shards of different splits (merging 3): 1/3", "2/5"],
    );
    // No shard readable at all: the refusal still names the split asked for, not 1/1.
    refused(&[os("4")], &["shard 4/4 is incomplete", "--shard 1/4"]);
    // A shard that did not finish (no manifest).
    run_ok(&[ci().as_os_str(), os("--out"), out.as_os_str(), os("--shard"), os("2/3")]);
    std::fs::remove_file(shard(2).join("shard.toml")).unwrap();
    refused(
        &[os("3")],
        &["2-of-3: no shard.toml: the shard has not finished", "--shard 2/3"],
    );
    // A shard whose records were edited after it finished.
    run_ok(&[ci().as_os_str(), os("--out"), out.as_os_str(), os("--shard"), os("2/3")]);
    let records = shard(2).join("records.csv");
    let text = std::fs::read_to_string(&records).unwrap();
    std::fs::write(&records, text.replacen(",ok,", ",ok ,", 1)).unwrap();
    refused(
        &[os("3")],
        &["records.csv is not the file shard 2/3 wrote", "--shard 2/3"],
    );
    std::fs::write(&records, text).unwrap();
    // A shard run by another build of the binary (same code, one byte more).
    let other_build = dir.path().join("sweep-other");
    let mut exe = std::fs::read(env!("CARGO_BIN_EXE_sweep")).unwrap();
    exe.push(0);
    std::fs::write(&other_build, exe).unwrap();
    std::fs::set_permissions(&other_build, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let status = Command::new(&other_build)
        .args([ci().as_os_str(), os("--out"), out.as_os_str(), os("--shard"), os("2/3")])
        .output()
        .unwrap()
        .status;
    assert!(status.success());
    refused(
        &[os("3")],
        &["shard 2/3 ran under another build than this merge", "--shard 2/3"],
    );
    // A shard of another sweep (other seeds) under the right name.
    let other = common::tiny_experiment(&dir.path().join("other"), |t| {
        t.replace("seeds = [1, 2]", "seeds = [1, 3]")
    });
    let tiny = common::tiny_experiment(&dir.path().join("tiny"), |t| t);
    let tiny_out = dir.path().join("t");
    for (exp, k) in [(&tiny, "1/2"), (&other, "2/2")] {
        run_ok(&[exp.as_os_str(), os("--out"), tiny_out.as_os_str(), os("--shard"), os(k)]);
    }
    let (code, err) = sweep(&[
        tiny.as_os_str(),
        os("--out"),
        tiny_out.as_os_str(),
        os("--merge"),
        os("2"),
    ]);
    assert_eq!(code, 4, "{err}");
    assert!(err.contains("shard 2/2 ran another sweep"), "{err}");
    assert!(!tiny_out.join("runs.csv").exists());
    // With every shard of the right sweep the merge goes through.
    run_ok(&[
        tiny.as_os_str(),
        os("--out"),
        tiny_out.as_os_str(),
        os("--shard"),
        os("2/2"),
    ]);
    run_ok(&[
        tiny.as_os_str(),
        os("--out"),
        tiny_out.as_os_str(),
        os("--merge"),
        os("2"),
    ]);
    assert!(tiny_out.join("runs.csv").exists());
}

#[test]
fn failed_runs_reach_the_merge_as_an_unsharded_sweep_records_them() {
    let dir = tempfile::tempdir().unwrap();
    let spec = Spec::load(&common::tiny_experiment(dir.path(), |t| t)).unwrap();
    let full = run_sweep(
        &spec,
        &mut common::Flaky(CpuBackend::default()),
        &dir.path().join("j"),
        &dir.path().join("c"),
        true,
        &Progress::default(),
    )
    .unwrap();
    assert!(full.failures > 0);
    let results = dir.path().join("sharded");
    for index in 1..=2 {
        let done = run_shard(
            &spec,
            &mut common::Flaky(CpuBackend::default()),
            Shard { index, count: 2 },
            &results,
            false,
            &Progress::default(),
        )
        .unwrap();
        assert!(done.manifest.failed > 0 || done.manifest.runs == 0);
    }
    let dirs: Vec<PathBuf> = (1..=2).map(|index| Shard { index, count: 2 }.dir(&results)).collect();
    let plan = MergePlan {
        dirs: &dirs,
        split: Some(2),
        rerun: "sweep tiny.toml --shard",
        fresh: false,
    };
    let merged = merge_shards(
        &spec,
        &mut common::Flaky(CpuBackend::default()),
        &plan,
        &results,
        &Progress::default(),
    )
    .unwrap();
    assert_eq!(merged.failures, full.failures);
    let table = |records: &[penumbra::experiment::sweep::Record], name: &str| {
        let path = dir.path().join(name);
        write_rows(&path, records).unwrap();
        std::fs::read_to_string(path).unwrap()
    };
    let (a, b) = (table(&full.records, "a.csv"), table(&merged.records, "b.csv"));
    assert!(a.contains("simulated device loss"));
    assert_eq!(a, b);
    // Splits of one seed are NaN: compared as text.
    assert_eq!(format!("{:?}", full.groups), format!("{:?}", merged.groups));
}

#[test]
fn a_shard_killed_midway_resumes_from_its_journal() {
    let _gpu = common::gpu();
    let dir = tempfile::tempdir().unwrap();
    let (killed, clean) = (dir.path().join("killed"), dir.path().join("clean"));
    let args = |out: &Path| -> Vec<std::ffi::OsString> {
        vec![ci().into(), "--out".into(), out.into(), "--shard".into(), "2/3".into()]
    };
    let status = Command::new(env!("CARGO_BIN_EXE_sweep"))
        .args(args(&killed))
        .env("PENUMBRA_TEST_DIE_AFTER", "5")
        .output()
        .unwrap()
        .status;
    assert!(!status.success() && status.code().is_none(), "not killed: {status:?}");
    let shard = killed.join("shards/2-of-3");
    assert!(!shard.join("shard.toml").exists() && !shard.join("records.csv").exists());
    let journaled = std::fs::read_to_string(shard.join(".journal/groups.csv")).unwrap();
    assert_eq!(journaled.lines().count(), 1 + 5, "{journaled}");

    let resumed = Command::new(env!("CARGO_BIN_EXE_sweep"))
        .args(args(&killed))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&resumed.stderr);
    assert!(resumed.status.success(), "{err}");
    let manifest = std::fs::read_to_string(shard.join("shard.toml")).unwrap();
    assert!(manifest.contains("resumed = 5\n"), "{manifest}");
    let uninterrupted = Command::new(env!("CARGO_BIN_EXE_sweep"))
        .args(args(&clean))
        .output()
        .unwrap();
    assert!(uninterrupted.status.success());
    let clean_shard = clean.join("shards/2-of-3");
    for file in ["records.csv", "groups.csv"] {
        let (a, b) = (
            std::fs::read(shard.join(file)).unwrap(),
            std::fs::read(clean_shard.join(file)).unwrap(),
        );
        assert!(a == b, "{file}: the resumed shard differs from an uninterrupted one");
    }
    // Figures of resumed groups come from the journal, identical to rendered ones.
    let figures = |d: &Path| {
        let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(d.join(".journal/figures"))
            .unwrap()
            .map(|e| e.unwrap())
            .map(|e| {
                (
                    e.file_name().to_string_lossy().into_owned(),
                    std::fs::read(e.path()).unwrap(),
                )
            })
            .collect();
        v.sort();
        v
    };
    let f = figures(&shard);
    assert!(!f.is_empty());
    assert_eq!(f, figures(&clean_shard));
}

#[test]
fn a_slurm_job_array_of_four_shards_and_its_merge_give_the_unsharded_tables() {
    let cluster = Command::new("sinfo").arg("-h").output();
    if !matches!(&cluster, Ok(o) if o.status.success() && !o.stdout.is_empty()) {
        eprintln!("skipping: no running Slurm here (scripts/slurm/local-cluster.sh start makes one)");
        return;
    }
    let dir = tempfile::tempdir_in(common::repo("target")).unwrap();
    let out = dir.path().join("slurm");
    let submit = Command::new(common::repo("scripts/slurm/submit.sh"))
        .current_dir(common::repo(""))
        .env("PENUMBRA_SWEEP", env!("CARGO_BIN_EXE_sweep"))
        .env("PENUMBRA_SLURM_WAIT", "1")
        .args([ci().as_os_str(), os("4"), os("--out"), out.as_os_str()])
        .output()
        .unwrap();
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&submit.stdout),
        String::from_utf8_lossy(&submit.stderr)
    );
    assert!(submit.status.success(), "{log}");
    let full = dir.path().join("full");
    run_ok(&[ci().as_os_str(), os("--out"), full.as_os_str()]);
    for table in ["runs.csv", "summary.csv"] {
        assert_eq!(
            common::without_clock(&full.join(table)),
            common::without_clock(&out.join(table)),
            "{table} differs\n{log}"
        );
    }
    for k in 1..=4 {
        assert!(out.join(format!("shards/{k}-of-4/shard.toml")).exists());
    }
}
