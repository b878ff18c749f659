//! Every kind on the experiment core: the CI twins of the sweep, ao, frames, realtime and fps run
//! whole, as two shards merged, and killed after their first journaled unit then resumed, give the same tables but for
//! the clock's columns; a merge missing a shard is refused with the command that reruns it and
//! writes nothing; filters keep only the units and values named and refuse what a kind does not
//! have.

use crate::common;
use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
use std::process::Command;

fn run(args: &[&OsStr]) -> (i32, String) {
    common::sweep(args)
}

fn run_ok(args: &[&OsStr]) -> String {
    let (code, err) = run(args);
    assert_eq!(code, 0, "sweep {args:?} failed:\n{err}");
    err
}

/// `experiment` with `edit` applied, written into `dir` (mesh and scene paths made absolute).
fn variant(dir: &Path, experiment: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(common::repo(experiment)).unwrap();
    let assets = common::repo("assets").display().to_string();
    let scenes = common::repo("experiments/scenes").display().to_string();
    let text = text
        .replace("\"../assets", &format!("\"{assets}"))
        .replace("\"scenes/", &format!("\"{scenes}/"));
    let path = dir.join(Path::new(experiment).file_name().unwrap());
    let edited = edit(text.clone());
    assert_ne!(edited, text, "{experiment}: the edit changed nothing");
    std::fs::write(&path, edited).unwrap();
    path
}

/// Runs `experiment` whole, as two concurrent shards merged (after a refused merge missing one's
/// manifest, and that shard's rerun from its journal), and killed
/// after one unit then resumed; every run's `tables` must equal the whole run's but for the clock,
/// and the first table must have rows.
fn whole_sharded_and_resumed_agree(experiment: &Path, tables: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let exp = experiment.as_os_str();
    let at = |name: &str| dir.path().join(name);
    let (full, sharded, killed) = (at("full"), at("sharded"), at("killed"));
    let out = |p: &Path| -> [OsString; 2] { ["--out".into(), p.into()] };
    let [o, f] = out(&full);
    run_ok(&[exp, &o, &f]);

    // Both shards at once into one results folder, as parallel.sh runs them on one node.
    let [o, s] = out(&sharded);
    let shard = |k: &str| {
        Command::new(env!("CARGO_BIN_EXE_sweep"))
            .args([exp, &o, &s, OsStr::new("--shard"), OsStr::new(k)])
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let running = [shard("1/2"), shard("2/2")];
    for child in running {
        let done = child.wait_with_output().unwrap();
        assert!(done.status.success(), "{}", String::from_utf8_lossy(&done.stderr));
    }
    // A shard without its manifest is unfinished: the merge refuses it, naming the rerun.
    std::fs::remove_file(sharded.join("shards/2-of-2/shard.toml")).unwrap();
    let (code, err) = run(&[exp, &o, &s, OsStr::new("--merge"), OsStr::new("2")]);
    assert_eq!(code, 4, "{err}");
    assert!(
        err.contains("shard 2/2 is incomplete") && err.contains("rerun it: sweep") && err.contains("--shard 2/2"),
        "{err}"
    );
    assert!(!sharded.join("manifest.toml").exists(), "a refused merge wrote results");
    let err = run_ok(&[exp, &o, &s, OsStr::new("--shard"), OsStr::new("2/2")]);
    assert!(
        err.contains(" resumed)") && !err.contains("(0 resumed)"),
        "the rerun shard measured again:\n{err}"
    );
    run_ok(&[exp, &o, &s, OsStr::new("--merge"), OsStr::new("2")]);

    let [o, k] = out(&killed);
    let status = Command::new(env!("CARGO_BIN_EXE_sweep"))
        .args([exp, &o, &k])
        .env("PENUMBRA_TEST_DIE_AFTER", "1")
        .output()
        .unwrap()
        .status;
    assert!(!status.success() && status.code().is_none(), "not killed: {status:?}");
    assert!(!killed.join("manifest.toml").exists());
    // A journaled unit changed after it was written (one digit, or cut short) is refused, not
    // taken as measured; restored, it resumes.
    let journaled: Vec<PathBuf> = std::fs::read_dir(killed.join(".journal"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(journaled.len(), 1, "{journaled:?}");
    let original = std::fs::read_to_string(&journaled[0]).unwrap();
    let digit = original.rfind(|c: char| c.is_ascii_digit() && c != '7').unwrap();
    let mut edited = original.clone();
    edited.replace_range(digit..digit + 1, "7");
    for damaged in [edited, original[..original.len() * 2 / 3].to_string()] {
        std::fs::write(&journaled[0], damaged).unwrap();
        let (code, err) = run(&[exp, &o, &k]);
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains("has changed since it was written") && err.contains("--fresh"),
            "{err}"
        );
        assert!(!killed.join("manifest.toml").exists());
    }
    std::fs::write(&journaled[0], &original).unwrap();
    let err = run_ok(&[exp, &o, &k]);
    assert!(
        err.contains("1 of") && err.contains("units taken from the journal"),
        "{err}"
    );
    let from_journal = |home: &Path| common::manifest_count(home, "units_from_journal");
    assert_eq!(from_journal(&killed), 1, "the manifest counts the unit resumed");
    assert_eq!(from_journal(&full), 0);

    for (i, table) in tables.iter().enumerate() {
        let whole = common::without_clock(&full.join(table));
        assert!(i > 0 || whole.len() > 1, "{table}: no rows");
        for other in [&sharded, &killed] {
            assert!(
                whole == common::without_clock(&other.join(table)),
                "{table}: {} differs from the whole run",
                other.display()
            );
        }
    }
}

#[test]
fn sweep_sharded_merged_and_resumed_gives_the_whole_runs_tables() {
    whole_sharded_and_resumed_agree(
        &common::repo("experiments/ci.toml"),
        &["runs.csv", "summary.csv", "ground_truth.csv", "timings.csv"],
    );
}

#[test]
fn ao_sharded_merged_and_resumed_gives_the_whole_runs_tables() {
    let dir = tempfile::tempdir().unwrap();
    // One candidate per structure: tuning picks by time, so it would make the settings (and the
    // work they cost) depend on the clock.
    let exp = variant(dir.path(), "experiments/ao-ci.toml", |t| {
        t.replace("max_depth = [8, 22]", "max_depth = 22")
            .replace("depth = [2, 4]", "depth = 3")
    });
    whole_sharded_and_resumed_agree(&exp, &["ao.csv", "rounds.csv"]);
}

#[test]
fn frames_in_blocks_sharded_merged_and_resumed_give_the_whole_runs_tables() {
    let dir = tempfile::tempdir().unwrap();
    let exp = variant(dir.path(), "experiments/frames-ci.toml", |t| {
        t.replace("[path]\nframes = 3", "[path]\nframes = 3\nblock = 2")
    });
    whole_sharded_and_resumed_agree(&exp, &["frames.csv", "builds.csv", "summary.csv"]);
}

#[test]
fn realtime_sharded_merged_and_resumed_gives_the_whole_runs_tables() {
    whole_sharded_and_resumed_agree(
        &common::repo("experiments/realtime-ci.toml"),
        &["runs.csv", "summary.csv", "timings.csv"],
    );
}

#[test]
fn fps_sharded_merged_and_resumed_gives_the_whole_runs_table() {
    whole_sharded_and_resumed_agree(&common::repo("experiments/fps-ci.toml"), &["fps.csv"]);
}

#[test]
fn filters_keep_the_units_and_values_named_and_refuse_what_a_kind_lacks() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::repo("experiments/ao-ci.toml");
    let dry = |filters: &[&str]| {
        let mut args: Vec<&OsStr> = vec![exp.as_os_str(), OsStr::new("--dry-run")];
        for f in filters {
            args.extend([OsStr::new("--filter"), OsStr::new(f)]);
        }
        run(&args)
    };
    let (code, err) = dry(&["colour=red"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("unknown axis `colour`") && err.contains("mesh, structure, issue"),
        "{err}"
    );
    let (code, err) = dry(&["structure=octree"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("kdtree, kdtree-sah, vlf, bvh, cwbvh, brute"), "{err}");

    let out = dir.path().join("cow");
    run_ok(&[
        exp.as_os_str(),
        OsStr::new("--out"),
        out.as_os_str(),
        OsStr::new("--filter"),
        OsStr::new("mesh=cow"),
        OsStr::new("--filter"),
        OsStr::new("structure=bvh"),
        OsStr::new("--filter"),
        OsStr::new("structure=brute"),
    ]);
    let rows = common::without_clock(&out.join("ao.csv"));
    let (mesh, structure) = (rows[0].iter().position(|h| h == "mesh").unwrap(), 2);
    assert_eq!(rows[0][structure], "structure");
    let kept: Vec<(&str, &str)> = rows[1..]
        .iter()
        .map(|r| (r[mesh].as_str(), r[structure].as_str()))
        .collect();
    assert_eq!(kept, [("cow", "bvh"), ("cow", "brute")]);
}

/// Filters on two axes where the first thins the second's values: fps' sphere keeps only one
/// light, so its light counts are [2] once `scene=body` is kept, and `lights=2` must still mean
/// two lights (it indexed the list before the scene filter, out of bounds).
#[test]
fn a_filter_keeps_its_value_after_another_axis_thins_the_list() {
    let dir = tempfile::tempdir().unwrap();
    let exp = variant(dir.path(), "experiments/fps-ci.toml", |t| {
        t.replacen(
            "lights = [1, 2]\npaper_fps = [15.95, 9.39]",
            "lights = [1]\npaper_fps = [15.95]",
            1,
        )
        .replacen(
            "lights = [1, 2]\npaper_fps = [8.36, 6.13]",
            "lights = [2]\npaper_fps = [6.13]",
            1,
        )
    });
    // It panicked (exit 101) indexing the thinned list.
    run_ok(&[
        exp.as_os_str(),
        OsStr::new("--dry-run"),
        OsStr::new("--filter"),
        OsStr::new("scene=body"),
        OsStr::new("--filter"),
        OsStr::new("lights=2"),
    ]);
}

/// `path`'s tuning.csv with `chosen` moved, on the rows of `scene` and `structure`, from the kept
/// candidate to another, written to `to`: a choice the timing did not make, which only
/// `--tuning` can bring about. Returns the parameter column and value now kept.
fn choose_another(
    path: &Path,
    to: &Path,
    (scene_column, scene, structure): (&str, &str, &str),
    column: &str,
) -> String {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let headers = reader.headers().unwrap().clone();
    let at = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let mut rows: Vec<Vec<String>> = reader
        .records()
        .map(|r| r.unwrap().iter().map(str::to_string).collect())
        .collect();
    let mine: Vec<usize> = (0..rows.len())
        .filter(|&i| rows[i][at(scene_column)] == scene && rows[i][at("structure")] == structure)
        .collect();
    assert!(mine.len() >= 2, "{structure} on {scene}: no candidates to move to");
    let kept = *mine.iter().find(|&&i| rows[i][at("chosen")] == "true").unwrap();
    let other = *mine.iter().find(|&&i| i != kept).unwrap();
    rows[kept][at("chosen")] = "false".into();
    rows[other][at("chosen")] = "true".into();
    let mut w = csv::Writer::from_path(to).unwrap();
    w.write_record(&headers).unwrap();
    for r in &rows {
        w.write_record(r).unwrap();
    }
    w.flush().unwrap();
    rows[other][at(column)].clone()
}

/// The rows of a table whose `column` equals `value`, by another `column2` value.
fn column_values(path: &Path, filter: (&str, &str), column: &str) -> Vec<String> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let headers = reader.headers().unwrap().clone();
    let at = |name: &str| headers.iter().position(|h| h == name).unwrap();
    reader
        .records()
        .map(Result::unwrap)
        .filter(|r| &r[at(filter.0)] == filter.1)
        .map(|r| r[at(column)].to_string())
        .collect()
}

/// `--tuning` builds what the file kept: given the whole run's tuning.csv (copied out of its
/// folder), two shards and their merge equal the whole run in every column but the clock's; given
/// a copy with one choice moved to a candidate the timing did not keep, shards and merge build
/// that one (so the file, not a second timing, decides). The reused settings carry the word
/// `reused` and nothing timed. `experiment` is a variant whose `scene`-column `scene` tunes
/// `structure` over `column`; `table` is its table of rows with parameters.
fn tuning_file_decides_what_shards_build(
    experiment: &Path,
    (scene_column, scene, structure, column): (&str, &str, &str, &str),
    table: &str,
) {
    let dir = tempfile::tempdir().unwrap();
    let exp = experiment.as_os_str();
    let at = |name: &str| dir.path().join(name);
    let out = |p: &Path| -> [OsString; 2] { ["--out".into(), p.into()] };
    let [o, f] = out(&at("full"));
    run_ok(&[exp, &o, &f]);
    let rounds = std::fs::read_to_string(at("full/tuning_rounds.csv")).unwrap();
    assert!(rounds.lines().count() > 1, "no tuning rounds:\n{rounds}");
    let same = at("kept.csv");
    std::fs::copy(at("full/tuning.csv"), &same).unwrap();
    let moved = at("moved.csv");
    let value = choose_another(&same, &moved, (scene_column, scene, structure), column);
    let sharded = |name: &str, tuning: &Path| -> PathBuf {
        let [o, s] = out(&at(name));
        for extra in [["--shard", "1/2"], ["--shard", "2/2"], ["--merge", "2"]] {
            let args: Vec<&OsStr> = vec![
                exp,
                &o,
                &s,
                OsStr::new("--tuning"),
                tuning.as_os_str(),
                OsStr::new(extra[0]),
                OsStr::new(extra[1]),
            ];
            run_ok(&args);
        }
        at(name)
    };
    let kept = sharded("same", &same);
    assert!(
        common::without_clock(&at("full").join(table)) == common::without_clock(&kept.join(table)),
        "{table} of the shards given the whole run's tuning differs from the whole run's"
    );
    let tuning = std::fs::read_to_string(kept.join("tuning.csv")).unwrap();
    assert!(tuning.lines().skip(1).all(|l| l.contains(",reused,")), "{tuning}");
    assert!(!kept.join("tuning_rounds.csv").exists(), "nothing was timed for tuning");
    let other = sharded("moved", &moved);
    let built = column_values(&other.join(table), (scene_column, scene), column);
    let mine: Vec<&String> = built.iter().filter(|v| !v.is_empty()).collect();
    assert!(
        !mine.is_empty() && mine.iter().all(|v| **v == value),
        "{column}: {built:?}, the file keeps {value}"
    );
    let whole = column_values(&at("full").join(table), (scene_column, scene), column);
    assert_ne!(whole, built, "the moved choice built what the whole run built");
}

#[test]
fn ao_shards_given_a_tuning_file_build_what_it_kept() {
    let dir = tempfile::tempdir().unwrap();
    let exp = variant(dir.path(), "experiments/ao-ci.toml", |t| {
        t.replace("name = \"ao-ci\"", "name = \"ao-ci-tuned\"")
    });
    tuning_file_decides_what_shards_build(&exp, ("mesh", "cow", "vlf", "vlf_depth"), "ao.csv");
}

#[test]
fn frames_shards_given_a_tuning_file_build_what_it_kept() {
    let dir = tempfile::tempdir().unwrap();
    let exp = variant(dir.path(), "experiments/frames-ci.toml", |t| {
        t.replace(
            "generator = \"classroom\"",
            "generator = \"random-triangles\"\ntriangles = [300, 2400]\nseed = 5",
        )
        .replace("frames = 3", "frames = 2\nviewpoints = [\"outside\", \"inside\"]")
        .replace("shadings = [\"opengl\", \"whitted\"]", "shadings = [\"opengl\"]")
        .replace("tiles = 32\ndepth = 3", "tiles = 32\ndepth = [2, 3]")
            + "\n[tuning]\ncameras = 1\nrepeats = 6\n"
    });
    tuning_file_decides_what_shards_build(&exp, ("triangles", "2400", "vlf", "vlf_depth"), "builds.csv");
}

/// Refusals of `--tuning`, exit 2 before anything is measured: a kind that tunes nothing, a file
/// kept for another candidate grid, a file inside the results folder the run replaces, a missing
/// file.
#[test]
fn bad_tuning_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let exp = variant(dir.path(), "experiments/ao-ci.toml", |t| {
        t.replace("name = \"ao-ci\"", "name = \"ao-ci-tuned\"")
    });
    let full = dir.path().join("full");
    run_ok(&[exp.as_os_str(), OsStr::new("--out"), full.as_os_str()]);
    let tuning = dir.path().join("kept.csv");
    std::fs::copy(full.join("tuning.csv"), &tuning).unwrap();
    let bad = dir.path().join("bad");
    let refused = |experiment: &Path, file: &Path, out: &Path, says: &str| {
        let (code, err) = run(&[
            experiment.as_os_str(),
            OsStr::new("--out"),
            out.as_os_str(),
            OsStr::new("--tuning"),
            file.as_os_str(),
        ]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(says), "{err}");
    };
    refused(
        &common::repo("experiments/fps-ci.toml"),
        &tuning,
        &bad,
        "tune no structure",
    );
    let other = dir.path().join("other");
    std::fs::create_dir(&other).unwrap();
    let regrid = variant(&other, "experiments/ao-ci.toml", |t| {
        t.replace("depth = [2, 4]", "depth = [1, 3]")
    });
    refused(&regrid, &tuning, &bad, "not among the experiment's candidates");
    refused(
        &exp,
        &full.join("tuning.csv"),
        &full,
        "lies in the results folder this run replaces",
    );
    refused(&exp, &dir.path().join("none.csv"), &bad, "cannot read");
    assert!(
        full.join("tuning_rounds.csv").exists(),
        "a refused run left the earlier results"
    );
}
