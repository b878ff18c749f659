//! Bad input: a clear error naming file, line and key, a non-zero exit, and earlier results
//! left exactly as they were.

use crate::common;

use std::ffi::OsStr;
use std::path::Path;

/// Runs the sweep on an edited tiny experiment over a results folder holding earlier results,
/// and returns stderr after checking the exit code and that nothing was touched.
fn rejects(edit: impl Fn(String) -> String) -> String {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), edit);
    let out = dir.path().join("results");
    common::earlier_results(&out, "sweep", "tiny");
    let (code, stderr) = common::sweep(&[exp.as_os_str(), OsStr::new("--out"), out.as_os_str()]);
    assert_eq!(code, 2, "bad input must exit with status 2; stderr:\n{stderr}");
    assert_eq!(
        std::fs::read_to_string(out.join("runs.csv")).unwrap(),
        "earlier results\n"
    );
    let entries: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(entries.len(), 2, "the failed run wrote {entries:?}");
    stderr
}

fn assert_located(stderr: &str, file: &str, line: usize, key: &str) {
    let want = format!("{file}:{line}:");
    assert!(stderr.contains(&want), "expected `{want}` in:\n{stderr}");
    assert!(stderr.contains(key), "expected key `{key}` in:\n{stderr}");
}

#[test]
fn malformed_toml() {
    let e = rejects(|t| t.replace("width = 24", "width = = 24"));
    assert_located(&e, "tiny.toml", 6, "key `width`");
}

#[test]
fn unknown_key() {
    let e = rejects(|t| t.replace("seeds = [1, 2]", "seeds = [1, 2]\nseed_count = 3"));
    assert_located(&e, "tiny.toml", 15, "seed_count");
}

#[test]
fn negative_light_radius() {
    let e = rejects(|t| t.replace("light_radii = [0.02]", "light_radii = [0.02, -0.01]"));
    assert_located(&e, "tiny.toml", 13, "sweep.light_radii[1]");
    assert!(e.contains("positive"), "{e}");
}

#[test]
fn zero_samples() {
    let e = rejects(|t| t.replace("samples = [4, 16]", "samples = [0, 16]"));
    assert_located(&e, "tiny.toml", 12, "sweep.samples[0]");
}

#[test]
fn unknown_scheme() {
    let e = rejects(|t| t.replace(r#"["uniform", "paper"]"#, r#"["uniform", "halton"]"#));
    assert_located(&e, "tiny.toml", 10, "sweep.schemes");
    assert!(e.contains("halton") && e.contains("paper-literal"), "{e}");
}

#[test]
fn bad_scene_value_is_located_in_the_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t);
    let scene = dir.path().join("scenes/sphere.toml");
    let text = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("radius = 0.25", "radius = 0.0");
    std::fs::write(&scene, text).unwrap();
    let (code, e) = common::sweep(&[exp.as_os_str(), OsStr::new("--out"), dir.path().join("r").as_os_str()]);
    assert_eq!(code, 2);
    assert!(e.contains("sphere.toml:") && e.contains("spheres[0].radius"), "{e}");
    assert!(!Path::new(&dir.path().join("r/runs.csv")).exists());
}

#[test]
fn missing_experiment_file() {
    let (code, e) = common::sweep(&[OsStr::new("/nonexistent/exp.toml")]);
    assert_eq!(code, 2);
    assert!(e.contains("/nonexistent/exp.toml") && e.contains("cannot read"), "{e}");
}

/// No GPU adapter: `--backend gpu` fails naming what to install; `auto` warns and falls back to
/// the CPU backend, whose name then stands in the results.
#[test]
fn no_gpu_adapter() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t);
    let run = |backend: &str, out: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_sweep"))
            .args([
                exp.as_os_str(),
                OsStr::new("--backend"),
                OsStr::new(backend),
                OsStr::new("--out"),
                dir.path().join(out).as_os_str(),
            ])
            .env("WGPU_BACKEND", "vulkan")
            .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
            .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
            .output()
            .unwrap()
    };
    let gpu = run("gpu", "g");
    let err = String::from_utf8_lossy(&gpu.stderr);
    assert!(
        gpu.status.code() == Some(1) && err.contains("no GPU adapter") && err.contains("mesa-vulkan-drivers"),
        "{err}"
    );
    assert!(!dir.path().join("g/runs.csv").exists());
    let auto = run("auto", "a");
    let err = String::from_utf8_lossy(&auto.stderr);
    assert!(
        auto.status.success() && err.contains("falling back to the f64 CPU backend"),
        "{err}"
    );
    let runs = std::fs::read_to_string(dir.path().join("a/runs.csv")).unwrap();
    assert!(
        runs.lines().skip(1).all(|l| l.contains(",cpu,penumbra f64 reference,")),
        "{runs}"
    );
}

#[test]
fn frame_rate_experiment_errors_are_located() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("scenes")).unwrap();
    std::fs::copy(
        common::repo("experiments/scenes/sphere.toml"),
        dir.path().join("scenes/sphere.toml"),
    )
    .unwrap();
    let text = std::fs::read_to_string(common::repo("experiments/fps.toml")).unwrap();
    let one_scene = &text[..text.find("[[scenes]]\nname = \"body\"").unwrap()];
    let text = one_scene.replace("scenes/sphere-two-lights.toml", "scenes/sphere.toml");
    std::fs::write(dir.path().join("fps.toml"), &text).unwrap();
    let (code, e) = common::sweep(&[
        dir.path().join("fps.toml").as_os_str(),
        OsStr::new("--out"),
        dir.path().join("r").as_os_str(),
    ]);
    assert_eq!(code, 2);
    assert!(
        e.contains("fps.toml:") && e.contains("scenes[0].lights") && e.contains("1..=1"),
        "{e}"
    );
    assert!(!dir.path().join("r").exists());
}

#[test]
fn unknown_kind() {
    let e = rejects(|t| format!("kind = \"sweeps\"\n{t}"));
    assert_located(&e, "tiny.toml", 1, "key `kind`");
    assert!(
        e.contains("sweeps") && e.contains("`sweep`") && e.contains("`fps`"),
        "{e}"
    );
}

#[test]
fn another_kinds_file_is_read_by_its_kind() {
    // A frame rate cannot go untimed: the fps kind's own rule.
    let e = rejects(|t| format!("kind = \"fps\"\n{t}"));
    assert!(e.contains("tiny.toml:") && e.contains("key `timing.repeats`"), "{e}");
    let e = rejects(|t| format!("kind = \"fps\"\n{}", t.replace("repeats = 0", "repeats = 6")));
    assert!(
        e.contains("tiny.toml:") && e.contains("unknown field") && e.contains("`samples`"),
        "{e}"
    );
}

/// No `kind` means a sweep: the tiny experiment has none. A frame-rate file that lost its
/// `kind` is read as a sweep, and the error says how the file was read.
#[test]
fn a_file_without_kind_is_a_sweep() {
    use penumbra::experiment::kind::Kind;
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t);
    assert!(!std::fs::read_to_string(&exp).unwrap().contains("kind"));
    assert_eq!(penumbra::experiment::load(&exp).unwrap().header().kind, Kind::Sweep);
    let text = std::fs::read_to_string(common::repo("experiments/fps.toml"))
        .unwrap()
        .replace("kind = \"fps\"\n", "");
    let fps = dir.path().join("fps.toml");
    std::fs::write(&fps, &text).unwrap();
    let (code, e) = common::sweep(&[fps.as_os_str(), OsStr::new("--dry-run")]);
    assert_eq!(code, 2, "{e}");
    // Whichever of the frame-rate keys the sweep meets first is blamed, on its own line.
    let key = e
        .split("key `")
        .nth(1)
        .and_then(|r| r.split('`').next())
        .expect("a key named");
    let line = 1 + text
        .lines()
        .position(|l| l.starts_with(&format!("{key} ")))
        .expect("the key's line");
    assert_located(&e, "fps.toml", line, &format!("key `{key}`"));
    assert!(e.contains("a file without `kind` is read as kind = \"sweep\""), "{e}");
}

/// `[timed] samples` names swept counts only, each once, and at least one; the error points at
/// the entry (line 24 of the tiny file holds the list).
#[test]
fn a_timing_grid_names_swept_counts() {
    let with = |list: &'static str| move |t: String| format!("{t}\n[timed]\nsamples = {list}\n");
    let e = rejects(with("[4, 8]"));
    assert_located(&e, "tiny.toml", 24, "key `timed.samples[1]`");
    assert!(e.contains("8 is not in sweep.samples [4, 16]"), "{e}");
    let e = rejects(with("[16, 16]"));
    assert!(
        e.contains("key `timed.samples[1]`") && e.contains("listed twice"),
        "{e}"
    );
    let e = rejects(with("[]"));
    assert!(e.contains("key `timed.samples`") && e.contains("at least one"), "{e}");
}
