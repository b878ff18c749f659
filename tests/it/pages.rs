//! Results pages in a real browser: the CI sweep's fresh page, a page written straight through the
//! page module (a gallery with a reference and two bit-identical images, two picture galleries
//! at different exposures set against each other), and every committed results folder's page
//! pass their self-test (common/browser.rs: the opening pair, readouts, the pair's numbers, one
//! tone map, a still layout, keys, wheel, divider, URL, plots at full size); and the check fails
//! on a page broken in each of those ways. The ao and frames kinds' pages are checked where their
//! CI experiments run (ao_experiment.rs, frames_experiment.rs).

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

/// A page written through `penumbra::output::page` alone, 48x32: "measured" (values in [0, 1],
/// its reference first, two noisy images bit-identical, one with pixels without a receiver) and
/// two picture galleries of radiance at exposures 1 and 3 set against each other (each one's
/// first frame with a half-precision subnormal and a value past the half range in its corners).
fn synthetic_page() -> &'static Path {
    use penumbra::output::page::{write, write_shots, Gallery, Page, Shot, Tone};
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("images")).unwrap();
        let (w, h) = (48u32, 32u32);
        let mut state = 12345u32;
        let mut noise = move || {
            state = state.wrapping_mul(1664525).wrapping_add(1013904223);
            (state >> 8) as f32 / (1u32 << 24) as f32 - 0.5
        };
        let smooth: Vec<f32> = (0..w * h).map(|i| (i % w) as f32 / (w - 1) as f32).collect();
        let noisy: Vec<f32> = smooth.iter().map(|v| (v + 0.2 * noise()).clamp(0.0, 1.0)).collect();
        let holes: Vec<f32> = noisy
            .iter()
            .enumerate()
            .map(|(i, &v)| if i % 7 == 0 { -1.0 } else { (v + 0.05).min(1.0) })
            .collect();
        let shot = |name: &str, label: &str, values: Vec<f32>| Shot {
            label: label.into(),
            exr: format!("images/{name}.exr"),
            png: format!("images/{name}.png"),
            values,
            key: vec![],
        };
        let measured = Gallery {
            title: "measured".into(),
            width: w,
            height: h,
            tone: Tone::Linear,
            reference: Some(0),
            against: None,
            shots: vec![
                shot("exact", "exact", smooth.clone()),
                shot("noisy", "noisy", noisy.clone()),
                shot("noisy_again", "noisy again (the same values)", noisy.clone()),
                shot("holes", "noisy, brighter, with pixels that have no receiver, and a label long enough to run past the width of its view on any screen", holes),
            ],
        };
        let mut pictures = |name: &str, scale: f32| Gallery {
            title: format!("{name} pictures"),
            width: w,
            height: h,
            tone: Tone::Radiance {
                p99: penumbra::output::images::exposure(&smooth.iter().map(|v| v * scale).collect::<Vec<_>>()),
            },
            reference: None,
            against: None,
            shots: (0..3)
                .map(|k| {
                    let mut values: Vec<f32> =
                        smooth.iter().map(|v| scale * v * (1.0 + 0.1 * k as f32) + 0.01 * noise()).collect();
                    if k == 0 {
                        // Half precision's edges, where the self-test reads: a subnormal, and a
                        // value past its range (stored as its largest).
                        values[0] = 3.0e-6;
                        *values.last_mut().unwrap() = 1.0e5;
                    }
                    shot(&format!("strip_{name}_{k}"), &format!("{name} frame {k}"), values)
                })
                .collect(),
        };
        let mut galleries = vec![measured, pictures("dim", 1.0), pictures("bright", 3.0)];
        galleries[1].against = Some(2);
        galleries[2].against = Some(1);
        for g in &galleries {
            write_shots(dir.path(), g).unwrap();
        }
        write(
            dir.path(),
            &Page {
                title: "synthetic".into(),
                report: "# A page for the browser test\n".into(),
                galleries,
            },
        )
        .unwrap();
        dir
    })
    .path()
}

#[test]
fn a_page_written_through_the_page_module_passes_in_the_browser() {
    browser::check_page(synthetic_page());
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
    broken_copy(ci_page(), edit)
}

/// A copy of the page in `src` with `edit` applied to one of its files.
fn broken_copy(src: &Path, edit: impl FnOnce(&Path)) -> tempfile::TempDir {
    let copy = tempfile::tempdir().unwrap();
    for sub in ["", "images", "plots"] {
        std::fs::create_dir_all(copy.path().join(sub)).unwrap();
        let Ok(entries) = std::fs::read_dir(src.join(sub)) else {
            continue;
        };
        for e in entries {
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
    let cases: [(&str, Edit); 16] = [
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
                    "const at = 4 * i;",
                    "const at = 4 * ((shot.height - 1 - Math.floor(i / shot.width)) * shot.width + (i % shot.width));",
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
                    "colour: (t) => diverging(t)",
                    "colour: (t) => diverging(-t)",
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
            "a plot does not open at full size",
            Box::new(|d| {
                replace_in(
                    &d.join("index.html"),
                    "#lightbox img { display: block; margin: 1em auto; max-width: none;",
                    "#lightbox img { display: block; margin: 1em auto; max-width: 50%;",
                )
            }),
        ),
        (
            "the wheel zooms",
            Box::new(|d| {
                replace_in(
                    &d.join("index.html"),
                    "if (!(armed || e.ctrlKey",
                    "if (false && !(armed || e.ctrlKey",
                )
            }),
        ),
        (
            "zoom is unbounded",
            Box::new(|d| {
                replace_in(
                    &d.join("index.html"),
                    "const zoom = Math.min(Math.max(state.zoom * factor, least), most);",
                    "const zoom = state.zoom * factor;",
                )
            }),
        ),
        (
            "dragging the divider",
            Box::new(|d| {
                replace_in(
                    &d.join("index.html"),
                    "const onDivider = ",
                    "const onDivider = false && ",
                )
            }),
        ),
        (
            "does not reopen the same view",
            Box::new(|d| {
                replace_in(
                    &d.join("index.html"),
                    "state.mode = p.get('mode') === 'toggle' ? 'toggle' : 'split';",
                    "state.mode = 'split';",
                )
            }),
        ),
        (
            "T does not toggle",
            Box::new(|d| {
                replace_in(
                    &d.join("index.html"),
                    "if (t.tagName === 'INPUT' && (t.type",
                    "if (t.tagName === 'INPUT' || (t.type",
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

/// What only a page with references, bit-identical images and galleries at different exposures
/// shows is caught on the page written through the page module.
#[test]
fn the_browser_check_fails_on_a_broken_comparison() {
    let Some(chromium) = browser::chromium() else {
        return;
    };
    type Edit = Box<dyn FnOnce(&Path)>;
    let html = |from: &'static str, to: &'static str| -> Edit {
        Box::new(move |d: &Path| replace_in(&d.join("index.html"), from, to))
    };
    let cases: [(&str, Edit); 9] = [
        (
            "opens comparing an image with itself",
            html(
                "state.a = a;\n          choose(a);",
                "state.a = a;\n          choose(a, a);",
            ),
        ),
        (
            "leaves B on",
            // A picked in its select, B kept where it was (on the other gallery's image).
            html(
                "choose(Number(e.target.value));\n      e.target.blur();",
                "choose(Number(e.target.value), state.b);\n      e.target.blur();",
            ),
        ),
        (
            "the pair's tone map",
            // A drawn with its own gallery's exposure, B with B's.
            html(
                "const t = tone();\n    return layer(shot",
                "const t = galleries[shot.gallery].tone;\n    return layer(shot",
            ),
        ),
        (
            "bit-identical but the error view says",
            html("'A and B are bit-identical: no error to show'", "'A − B'"),
        ),
        (
            "the page's mse",
            html("mse: compared ? se / compared", "mse: compared ? se / a.values.length"),
        ),
        (
            "the layout moves",
            html(
                ".views figure { margin: 0; width: 640px; max-width: 100%; }",
                ".views figure { margin: 0; }",
            ),
        ),
        (
            "a number key does not move A",
            html(
                "if (k < g.count) choose(g.first + k, state.b);",
                "if (k < g.count) choose(g.first + k);",
            ),
        ),
        (
            "the FLIP view",
            html("flip.disabled = !flipShown();", "flip.disabled = false;"),
        ),
        (
            "the page reads",
            // Half-precision subnormals decoded with the normal numbers' exponent.
            html(
                "if (exponent === 0) return sign * fraction * Math.pow(2, -24);",
                "if (exponent === 0) return sign * fraction * Math.pow(2, -10);",
            ),
        ),
    ];
    for (expected, edit) in cases {
        let dir = broken_copy(synthetic_page(), edit);
        let p = browser::problems(&chromium, dir.path());
        assert!(
            p.iter().any(|m| m.contains(expected)),
            "breaking the page for {expected:?} gave: {p:#?}"
        );
    }
}
