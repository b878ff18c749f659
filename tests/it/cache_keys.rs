//! Cached and resumed work is keyed by every input: editing an OBJ the scene reads invalidates the
//! journal and the ground-truth cache, and one backend never resumes rows another wrote.

use crate::common;

use std::ffi::OsStr;
use std::path::Path;

const EXPERIMENT: &str = r#"
name = "keys"
scene = "scene.toml"

[measure]
camera = "measure"
width = 16
height = 16

[sweep]
schemes = ["uniform"]
patterns = ["per-pixel"]
samples = [4, 16]
light_radii = [0.05]
seeds = [1, 2]

[ground_truth]
samples = 64

[timing]
warmup = 0
repeats = 0
"#;

/// A 0.2 m square occluder at height `z`, as two triangles.
fn square(z: f64) -> String {
    format!("v -0.1 -0.1 {z}\nv 0.1 -0.1 {z}\nv 0.1 0.1 {z}\nv -0.1 0.1 {z}\nf 1 2 3\nf 1 3 4\n")
}

/// Runs the sweep with `backend`; returns how many groups it resumed from the journal.
fn resumed(dir: &Path, backend: &str) -> usize {
    let args = [
        dir.join("keys.toml").into_os_string(),
        "--out".into(),
        dir.join("out").into_os_string(),
        "--backend".into(),
        backend.into(),
    ];
    let args: Vec<&OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let (code, stderr) = common::sweep(&args);
    assert_eq!(code, 0, "{stderr}");
    let Some(at) = stderr.find(" units taken from the journal") else {
        return 0;
    };
    let line = stderr[..at].rsplit('\n').next().unwrap_or_default();
    let of = line.rfind(" of ").expect("N of M units");
    let digits: String = line[..of].chars().rev().take_while(|c| c.is_ascii_digit()).collect();
    digits.chars().rev().collect::<String>().parse().unwrap()
}

fn cached_ground_truths(dir: &Path) -> usize {
    std::fs::read_dir(dir.join("out/cache")).map_or(0, |d| d.count())
}

/// The scene (a square occluder from square.obj), the experiment and the OBJ, in a new folder.
fn experiment_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("scene.toml"), common::mesh_over_plane("square.obj", 0.05)).unwrap();
    std::fs::write(d.join("keys.toml"), EXPERIMENT).unwrap();
    std::fs::write(d.join("square.obj"), square(0.5)).unwrap();
    dir
}

#[test]
fn editing_an_obj_invalidates_the_journal_and_the_ground_truth_cache() {
    let dir = experiment_dir();
    let d = dir.path();
    // Both groups resume, the one at the figures' ray count (16) with its journaled figure.
    assert_eq!(resumed(d, "cpu"), 0);
    assert_eq!(resumed(d, "cpu"), 2);
    assert_eq!(cached_ground_truths(d), 1);
    // Same scene file, same OBJ name, different geometry.
    std::fs::write(d.join("square.obj"), square(0.6)).unwrap();
    assert_eq!(resumed(d, "cpu"), 0, "an edited OBJ must not reuse journaled rows");
    assert_eq!(
        cached_ground_truths(d),
        2,
        "an edited OBJ must not reuse the cached ground truth"
    );
    assert_eq!(resumed(d, "cpu"), 2);
}

#[test]
fn one_backend_never_resumes_another_backends_rows() {
    if common::gpu().is_none() {
        return;
    }
    let dir = experiment_dir();
    let d = dir.path();
    assert_eq!(resumed(d, "gpu"), 0);
    assert_eq!(resumed(d, "cpu"), 0, "the CPU backend resumed rows the GPU wrote");
    let runs = std::fs::read_to_string(d.join("out/runs.csv")).unwrap();
    assert!(runs.lines().skip(1).all(|l| l.contains(",cpu,")), "{runs}");
    // Both backends' rows stay journaled side by side.
    assert_eq!(resumed(d, "gpu"), 2);
    assert_eq!(resumed(d, "cpu"), 2);
}

/// Another seed list gives another bias/variance split: a group journaled with seeds [1, 2] is
/// not taken for [1, 2, 3] (its first run's key is the same), nor is the shorter one afterwards.
#[test]
fn another_seed_list_renders_the_group_again() {
    let dir = experiment_dir();
    let d = dir.path();
    assert_eq!(resumed(d, "cpu"), 0);
    let three = EXPERIMENT.replace("seeds = [1, 2]", "seeds = [1, 2, 3]");
    std::fs::write(d.join("keys.toml"), three).unwrap();
    assert_eq!(resumed(d, "cpu"), 0, "seeds [1, 2, 3] resumed the [1, 2] group");
    let summary = std::fs::read_to_string(d.join("out/summary.csv")).unwrap();
    let mut rows = csv::Reader::from_reader(summary.as_bytes());
    let seeds = rows.headers().unwrap().iter().position(|h| h == "seeds").unwrap();
    for row in rows.records() {
        assert_eq!(&row.unwrap()[seeds], "3");
    }
    assert_eq!(resumed(d, "cpu"), 2);
    std::fs::write(d.join("keys.toml"), EXPERIMENT).unwrap();
    assert_eq!(resumed(d, "cpu"), 2, "both seed lists stay journaled");
}
