//! Sharded sweeps on the experiment core: the deal of a sweep's groups to shards
//! (deterministic, complete, balanced, ground truths kept together where that pays), refused
//! merges (missing, unfinished, duplicated, foreign, edited or other-build shards) that write
//! nothing, and, where `sbatch` and a running Slurm exist, the job-array script end to end. That a
//! sharded, merged or killed-and-resumed sweep gives the whole run's tables is tested with every
//! other kind's in `kinds_on_the_core.rs`.

use crate::common;
use penumbra::experiment::core::shard::{deal, Shard};
use penumbra::experiment::core::Declaration;
use penumbra::experiment::sweep::run::{expand, Group};
use penumbra::experiment::sweep::{Spec, Sweep};
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

/// The share of each group of `spec` among `count`, as the core deals the sweep's units (an
/// experiment that times nothing and draws no pictures has only groups).
fn assign(spec: &Spec, groups: &[Group], count: u32) -> Vec<u32> {
    let units = Sweep::new(spec.clone()).units();
    assert_eq!(units.len(), groups.len(), "units other than groups");
    let costs: Vec<_> = units.iter().map(|u| u.cost.clone()).collect();
    deal(&costs, count).0
}

/// The CI experiment untimed (its timing unit, twice all its groups' rays, would hold a share
/// alone).
fn ci_untimed(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(ci()).unwrap();
    let scenes = common::repo("experiments/scenes").display().to_string();
    let path = dir.join("ci-untimed.toml");
    let text = text
        .replace("repeats = 6 ", "repeats = 0 ")
        .replace("\"scenes/", &format!("\"{scenes}/"));
    assert!(text.contains("repeats = 0"));
    std::fs::write(&path, text).unwrap();
    path
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
    let dir = tempfile::tempdir().unwrap();
    let spec = Spec::load(&ci_untimed(dir.path())).unwrap();
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
    // ray counts listed in another order is dealt alike, group by group.
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
    // Shard 2 never ran: its units are listed with the command that reruns it.
    refused(
        &[os("3")],
        &[
            "2-of-3: no such shard folder",
            "shard 2/3 is incomplete (",
            "units missing); rerun it: sweep",
            "--shard 2/3",
            "scheme=",
        ],
    );
    // The same shard twice.
    refused(
        &[shard(1).as_os_str(), shard(1).as_os_str(), shard(3).as_os_str()],
        &["units are in more than one shard", "shard 2/3"],
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
    refused(&[os("4")], &["shard 2/4 is incomplete", "--shard 1/4"]);
    // A shard that did not finish (no manifest).
    run_ok(&[ci().as_os_str(), os("--out"), out.as_os_str(), os("--shard"), os("2/3")]);
    std::fs::remove_file(shard(2).join("shard.toml")).unwrap();
    refused(
        &[os("3")],
        &["2-of-3: no shard.toml: the shard has not finished", "--shard 2/3"],
    );
    // A shard whose journaled unit was edited after it finished.
    run_ok(&[ci().as_os_str(), os("--out"), out.as_os_str(), os("--shard"), os("2/3")]);
    let unit = std::fs::read_dir(shard(2).join(".journal"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| std::fs::read_to_string(p).unwrap().contains(",ok,"))
        .expect("a journaled group");
    let text = std::fs::read_to_string(&unit).unwrap();
    std::fs::write(&unit, text.replacen(",ok,", ",ok ,", 1)).unwrap();
    refused(&[os("3")], &["is not the file shard 2/3 wrote", "--shard 2/3"]);
    std::fs::write(&unit, text).unwrap();
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
    assert!(err.contains("shard 2/2 ran under another inputs, axes"), "{err}");
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
