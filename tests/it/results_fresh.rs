//! The committed results belong to the code in front of the reader: every folder under
//! `results/` has a manifest naming a clean commit of this history (HEAD or an ancestor; that
//! its numbers are still what the current code computes is tests/it/reproduction.rs's part),
//! made from `experiments/FOLDER.toml`, and every input file it lists (experiment, scenes, meshes, points
//! files) still hashes as it did when the results were made. Any edit to an experiment, scene or
//! mesh therefore fails the test command until the results are regenerated
//! (`scripts/regenerate.sh`, from a clean checkout, results committed alone on top).

use crate::common;
use penumbra::experiment::manifest::{staleness, Manifest, Problem};

#[test]
fn every_committed_results_folder_is_fresh() {
    let repo = common::repo("");
    let problems = staleness(&repo.join("results"), &repo);
    let list: Vec<String> = problems.iter().map(|p| format!("  {p}")).collect();
    assert!(
        problems.is_empty(),
        "{} problem(s) with the committed results (each folder must name a clean commit of this history and inputs that match the repository's files):\n{}",
        problems.len(),
        list.join("\n")
    );
}

/// A folder the binary writes, run from the root of a small repository as scripts/regenerate.sh
/// runs it, lists every file it read (experiment, scene, mesh, points file) by a path the check
/// resolves, and passes it; editing any of them is caught. (Whether the build was clean depends
/// on the checkout the test binary was built in: that problem alone is allowed here.)
#[test]
fn a_fresh_run_passes_and_an_edited_input_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    let write = |relative: &str, text: &str| {
        let p = root.join(relative);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    };
    let scene = std::fs::read_to_string(common::repo("experiments/scenes/sphere.toml")).unwrap();
    write(
        "experiments/scenes/tiny.toml",
        &format!("{scene}\n[[meshes]]\npath = \"../../assets/tri.obj\"\n"),
    );
    // One triangle under the light, beside the sphere.
    write(
        "assets/tri.obj",
        "v 0.3 -0.1 0.3\nv 0.5 -0.1 0.3\nv 0.4 0.1 0.3\nf 1 2 3\n",
    );
    write(
        "experiments/patterns/fib.csv",
        &std::fs::read_to_string(common::repo("experiments/patterns/fibonacci16.csv")).unwrap(),
    );
    write(
        "experiments/tiny.toml",
        r#"kind = "sweep"
name = "tiny"
scene = "scenes/tiny.toml"
backend = "cpu"

[measure]
camera = "measure"
width = 16
height = 16

[sweep]
schemes = ["uniform", "points:fib"]
patterns = ["per-pixel"]
samples = [16]
light_radii = [0.02]
seeds = [1, 2]

[points.fib]
path = "patterns/fib.csv"

[ground_truth]
samples = 64

[timing]
repeats = 0
"#,
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_sweep"))
        .arg("experiments/tiny.toml")
        .current_dir(root)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(root.join("results/tiny/manifest.toml")).unwrap();
    let manifest: Manifest = toml::from_str(&text).unwrap();
    let paths: Vec<&str> = manifest.inputs.iter().map(|i| i.path.as_str()).collect();
    assert_eq!(
        paths,
        [
            "experiments/tiny.toml",
            "experiments/scenes/tiny.toml",
            "assets/tri.obj",
            "experiments/patterns/fib.csv"
        ]
    );
    let found = |p: &[Problem]| -> Vec<String> {
        p.iter()
            .filter(|p| !p.what.starts_with("built from a dirty tree"))
            .map(|p| p.to_string())
            .collect()
    };
    assert_eq!(found(&staleness(&root.join("results"), root)), Vec::<String>::new());
    for path in &paths {
        let file = root.join(path);
        let before = std::fs::read(&file).unwrap();
        let mut edited = before.clone();
        edited.extend_from_slice(b"\n");
        std::fs::write(&file, &edited).unwrap();
        let problems = found(&staleness(&root.join("results"), root));
        assert_eq!(problems.len(), 1, "{path}: {problems:#?}");
        assert!(
            problems[0].starts_with("results/tiny: ")
                && problems[0].contains(&format!("input `{path}` changed since the run"))
                && problems[0].contains("scripts/regenerate.sh"),
            "{}",
            problems[0]
        );
        std::fs::write(&file, &before).unwrap();
    }
}
