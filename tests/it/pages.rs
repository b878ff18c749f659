//! Results pages in a real browser: the CI sweep's fresh page and every committed results
//! folder's page pass their self-test (no console error, every image decodes, the slider, the flip
//! and the exposure change what is shown, every readout equals the EXR, what is drawn under the
//! cursor is the PNG's pixel and the error view's colour of A - B); and the check fails on a page
//! broken in each of those ways. The ao and frames kinds' pages are checked where their CI
//! experiments run (ao_experiment.rs, frames_experiment.rs).

use crate::common::{self, browser};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The CI sweep written through the binary once per test binary.
fn ci_page() -> &'static Path {
    static DIR: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &DIR.get_or_init(|| {
        let _gpu = common::gpu();
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("ci");
        let exp = common::repo("experiments/ci.toml");
        let (code, err) = common::sweep(&[exp.as_os_str(), OsStr::new("--out"), out.as_os_str()]);
        assert_eq!(code, 0, "{err}");
        (dir, out)
    })
    .1
}

#[test]
fn the_ci_sweeps_page_passes_in_the_browser() {
    let dir = ci_page();
    for file in [
        "index.html",
        "page_data.js",
        "images/ground_truth.exr",
        "images/exact.png",
    ] {
        assert!(dir.join(file).exists(), "{file} missing");
    }
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    // Offline: nothing is fetched from a network.
    for remote in ["http://", "https://", "//cdn"] {
        assert!(!html.contains(&format!("src=\"{remote}")), "{remote} in the page");
    }
    browser::check_page(dir);
    // Its tables (journal included) under the one unit convention, one value per column.
    assert!(common::assert_tidy_tables(dir).len() >= 4);
}

#[test]
fn every_committed_results_folder_has_a_page_that_passes() {
    let results = common::repo("results");
    let mut folders: Vec<PathBuf> = std::fs::read_dir(&results)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("manifest.toml").exists())
        .collect();
    folders.sort();
    assert!(!folders.is_empty());
    for dir in &folders {
        assert!(
            dir.join("index.html").exists(),
            "{} has no index.html: rerun its experiment (`cargo run --release --bin sweep experiments/{}.toml`)",
            dir.display(),
            dir.file_name().unwrap().to_string_lossy()
        );
        browser::check_page(dir);
    }
}

/// A copy of the CI page with `edit` applied to one of its files.
fn broken(edit: impl FnOnce(&Path)) -> tempfile::TempDir {
    let copy = tempfile::tempdir().unwrap();
    let src = ci_page();
    for sub in ["", "images", "plots"] {
        std::fs::create_dir_all(copy.path().join(sub)).unwrap();
        for e in std::fs::read_dir(src.join(sub)).unwrap() {
            let e = e.unwrap();
            if e.file_type().unwrap().is_file() {
                std::fs::copy(e.path(), copy.path().join(sub).join(e.file_name())).unwrap();
            }
        }
    }
    edit(copy.path());
    copy
}

fn replace_in(path: &Path, from: &str, to: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains(from), "{from:?} not in {}", path.display());
    std::fs::write(path, text.replacen(from, to, 1)).unwrap();
}

/// Each way a page can be broken is caught, with a message that says which.
#[test]
fn the_browser_check_fails_on_a_broken_page() {
    let Some(chromium) = browser::chromium() else {
        return;
    };
    type Edit = Box<dyn FnOnce(&Path)>;
    let cases: [(&str, Edit); 10] = [
        (
            "console error",
            Box::new(|d| {
                replace_in(
                    &d.join("index.html"),
                    "'use strict';",
                    "'use strict';\nconsole.error('planted');",
                )
            }),
        ),
        (
            "image does not decode",
            Box::new(|d| std::fs::write(d.join("images/fig2_measure.png"), b"\x89PNG\r\n\x1a\nbroken").unwrap()),
        ),
        (
            "the slider does not change",
            Box::new(|d| {
                replace_in(
                    &d.join("index.html"),
                    "state.split = Number(e.target.value);",
                    "state.split = state.split;",
                )
            }),
        ),
        (
            "the page reads",
            Box::new(|d| {
                // The EXR of the ground truth no longer holds what the page shows.
                let p = d.join("images/ground_truth.exr");
                let img = exr::prelude::read_first_flat_layer_from_file(&p).unwrap();
                let w = img.layer_data.size.width() as u32;
                let h = img.layer_data.size.height() as u32;
                let values: Vec<f32> = img.layer_data.channel_data.list[0]
                    .sample_data
                    .values_as_f32()
                    .map(|v| if v == -1.0 { v } else { v * 0.5 + 0.25 })
                    .collect();
                penumbra::output::images::write_exr(&p, &values, w, h).unwrap();
            }),
        ),
        (
            "reads out pixel",
            Box::new(|d| {
                // An off-by-one in the cursor's pixel.
                replace_in(
                    &d.join("index.html"),
                    "return [Math.floor((cx - state.panX) / state.zoom),",
                    "return [1 + Math.floor((cx - state.panX) / state.zoom),",
                )
            }),
        ),
        (
            "under the cursor where the PNG holds",
            Box::new(|d| {
                // The picture drawn upside down: every readout still matches the EXR.
                replace_in(
                    &d.join("index.html"),
                    "px.set([...rgb, 255], 4 * i);",
                    "px.set([...rgb, 255], 4 * ((shot.height - 1 - Math.floor(i / shot.width)) * shot.width + (i % shot.width)));",
                )
            }),
        ),
        (
            "at +1 EV the page draws",
            Box::new(|d| {
                // An exposure control that is not in stops.
                replace_in(
                    &d.join("index.html"),
                    "const gain = Math.pow(2, state.ev);",
                    "const gain = Math.pow(2, state.ev / 2);",
                )
            }),
        ),
        (
            "the error view draws",
            Box::new(|d| {
                // Positive differences drawn blue: the readout still reads the right number.
                replace_in(
                    &d.join("index.html"),
                    "colour: (v, s) => diverging(v / s)",
                    "colour: (v, s) => diverging(-v / s)",
                )
            }),
        ),
        (
            "no table row opens",
            Box::new(|d| {
                // A key the tables do not write the same way (the radius as 0.020).
                replace_in(
                    &d.join("page_data.js"),
                    "\"light_radius\":\"0.02\"",
                    "\"light_radius\":\"0.020\"",
                )
            }),
        ),
        (
            "the exposure does not change",
            Box::new(|d| {
                replace_in(
                    &d.join("index.html"),
                    "state.ev = Number(e.target.value);",
                    "state.ev = state.ev;",
                )
            }),
        ),
    ];
    for (expected, edit) in cases {
        let dir = broken(edit);
        let p = browser::problems(&chromium, dir.path());
        assert!(
            p.iter().any(|m| m.contains(expected)),
            "breaking the page for {expected:?} gave: {p:#?}"
        );
    }
    let intact = broken(|_| {});
    assert_eq!(browser::problems(&chromium, intact.path()), Vec::<String>::new());
}
