//! A results page opened in a real browser (Debian's headless `chromium`): the page's self-test
//! (`index.html#selftest`) hovers every image, moves the slider, flips, changes the exposure, and
//! checks that every <img> decoded; this module reads what it wrote and checks it against the
//! files: each readout against the EXR beside the image, the error view's readout against the two
//! EXRs' difference, the colour drawn under the cursor against the PNG (and at +1 EV against the
//! crate's tone mapping of the value doubled).

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The browser, or `None` with a note when it is not installed. Where the environment sets
/// `PENUMBRA_REQUIRE_BROWSER=1` (CI installs chromium and does), a missing browser fails.
pub fn chromium() -> Option<PathBuf> {
    let found = std::env::var_os("PENUMBRA_CHROMIUM").map(PathBuf::from).or_else(|| {
        std::env::split_paths(&std::env::var_os("PATH")?)
            .flat_map(|d| ["chromium", "chromium-browser"].map(|n| d.join(n)))
            .find(|p| p.is_file())
    });
    if found.is_none() {
        assert!(
            std::env::var("PENUMBRA_REQUIRE_BROWSER").as_deref() != Ok("1"),
            "PENUMBRA_REQUIRE_BROWSER=1 but no chromium on PATH (nor PENUMBRA_CHROMIUM)"
        );
        eprintln!("skipping browser checks: no chromium on PATH");
    }
    found
}

/// What the page's self-test wrote, as JSON, with the browser's log of the page's console
/// (`console`).
pub fn self_test(browser: &Path, page: &Path) -> Result<Value, String> {
    let profile = tempfile::tempdir().map_err(|e| e.to_string())?;
    let url = format!(
        "file://{}#selftest",
        page.canonicalize().map_err(|e| e.to_string())?.display()
    );
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--virtual-time-budget=60000",
            "--enable-logging=stderr",
            "--v=0",
            "--dump-dom",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(&url)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("starting {}: {e}", browser.display()))?;
    // Drain the page's DOM while waiting (it is larger than a pipe holds).
    let mut stdout = child.stdout.take().expect("piped");
    let reader = std::thread::spawn(move || {
        let mut dom = String::new();
        std::io::Read::read_to_string(&mut stdout, &mut dom).map(|_| dom)
    });
    let mut stderr = child.stderr.take().expect("piped");
    let log = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = std::io::Read::read_to_string(&mut stderr, &mut text);
        text
    });
    let start = Instant::now();
    while child.try_wait().map_err(|e| e.to_string())?.is_none() {
        if start.elapsed() > Duration::from_secs(180) {
            let _ = child.kill();
            return Err(format!("{url}: the browser did not finish in 180 s"));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let dom = reader.join().expect("reader").map_err(|e| e.to_string())?;
    // The browser logs every console message of the page (the page itself writes none), even
    // one written before the page's own error capture starts.
    let console: Vec<String> = log
        .join()
        .expect("log reader")
        .lines()
        .filter(|l| l.contains(":CONSOLE"))
        .map(str::to_string)
        .collect();
    let open = "<pre id=\"selftest\">";
    let start = dom
        .find(open)
        .ok_or_else(|| format!("{url}: the self-test wrote nothing (page did not run?)"))?
        + open.len();
    let end = dom[start..].find("</pre>").ok_or("unterminated self-test output")? + start;
    let text = dom[start..end]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&nbsp;", "\u{a0}")
        .replace("&amp;", "&");
    let mut report: Value =
        serde_json::from_str(&text).map_err(|e| format!("{url}: self-test output is not JSON ({e}): {text}"))?;
    report["console"] = console.into();
    Ok(report)
}

/// A one-channel EXR's values and width.
fn exr(path: &Path) -> Result<(Vec<f32>, usize), String> {
    let img = exr::prelude::read_first_flat_layer_from_file(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let width = img.layer_data.size.width();
    let ch = &img.layer_data.channel_data.list[0];
    Ok((ch.sample_data.values_as_f32().collect(), width))
}

/// Whether the page's text for a pixel shows `value` (`no receiver` for -1).
fn shows(text: &str, value: f64) -> bool {
    if value == -1.0 {
        return text == "no receiver";
    }
    shows_number(text, value)
}

/// Whether the page's text shows `value` to the seven significant digits it prints.
fn shows_number(text: &str, value: f64) -> bool {
    let Ok(shown) = text.parse::<f64>() else {
        return false;
    };
    let digit = if value == 0.0 {
        1e-7
    } else {
        10f64.powf(value.abs().log10().floor() - 6.0)
    };
    (shown - value).abs() <= 0.5 * digit * (1.0 + 1e-9)
}

/// The PNG `name` (relative to `dir`), read once.
fn pixels<'a>(
    cache: &'a mut std::collections::BTreeMap<String, image::RgbImage>,
    dir: &Path,
    name: &str,
) -> Result<&'a image::RgbImage, String> {
    if !cache.contains_key(name) {
        let img = image::open(dir.join(name)).map_err(|e| format!("{name}: {e}"))?;
        cache.insert(name.to_string(), img.to_rgb8());
    }
    Ok(&cache[name])
}

/// Whether the page's colour (JSON [r, g, b]) is `want`, each channel within one step (the
/// page's floating point may round a value on a step's edge the other way).
fn close(shown: &Value, want: &[u8; 3]) -> bool {
    let Some(rgb) = shown.as_array().filter(|a| a.len() == 3) else {
        return false;
    };
    rgb.iter()
        .zip(want)
        .all(|(s, &w)| s.as_u64().is_some_and(|s| s.abs_diff(w as u64) <= 1))
}

/// The scale of the signed-difference view of `a` against `b`: the 99th percentile of |a - b|
/// over the pixels where both have a receiver (1 where that is 0).
fn difference_scale(a: &[f32], b: &[f32]) -> f64 {
    let mut m: Vec<f64> = a
        .iter()
        .zip(b)
        .filter(|(x, y)| **x != -1.0 && **y != -1.0)
        .map(|(&x, &y)| (x as f64 - y as f64).abs())
        .collect();
    m.sort_by(f64::total_cmp);
    // The page's index, floor(0.99 n), computed as it computes it.
    let k = ((0.99 * m.len() as f64).floor() as usize).min(m.len().saturating_sub(1));
    let s = m.get(k).copied().unwrap_or(0.0);
    if s > 0.0 {
        s
    } else {
        1.0
    }
}

/// The colour the page should draw for `value` at +1 EV under the gallery's tone mapping (JSON
/// as the page has it), computed with the crate's own mapping: the value doubled, except a pixel
/// with no receiver, which keeps its colour.
fn brighter(tone: &Value, value: f32) -> Option<[u8; 3]> {
    use penumbra::output::images::{grey, tonemap_with};
    let doubled = if value == -1.0 { value } else { 2.0 * value };
    let img = match tone["kind"].as_str()? {
        "linear" => grey(&[doubled], 1, 1),
        "radiance" => tonemap_with(&[2.0 * value], 1, 1, tone["p99"].as_f64()?),
        _ => return None,
    };
    img.data.try_into().ok()
}

/// Every problem the page at `dir`/index.html shows in the browser (none: it passes).
pub fn problems(browser: &Path, dir: &Path) -> Vec<String> {
    let report = match self_test(browser, &dir.join("index.html")) {
        Ok(r) => r,
        Err(e) => return vec![e],
    };
    let mut out = Vec::new();
    for e in report["errors"].as_array().into_iter().flatten() {
        out.push(format!("console error: {e}"));
    }
    for e in report["console"].as_array().into_iter().flatten() {
        out.push(format!("console error (browser log): {e}"));
    }
    for exr in report["unlinked"].as_array().into_iter().flatten() {
        out.push(format!("no table row opens {exr}, though it names its rows"));
    }
    for img in report["images"].as_array().into_iter().flatten() {
        if img["ok"] != Value::Bool(true) {
            out.push(format!("image does not decode: {}", img["src"]));
        }
    }
    let readouts = report["readouts"].as_array().cloned().unwrap_or_default();
    let mut pngs = std::collections::BTreeMap::new();
    let mut files = std::collections::BTreeMap::new();
    let mut read = |name: &str| -> Result<(Vec<f32>, usize), String> {
        if !files.contains_key(name) {
            files.insert(name.to_string(), exr(&dir.join(name))?);
        }
        Ok(files[name].clone())
    };
    for r in &readouts {
        let (a, b) = (r["a"].as_str().unwrap_or(""), r["b"].as_str().unwrap_or(""));
        let (x, y) = (
            r["x"].as_u64().unwrap_or(0) as usize,
            r["y"].as_u64().unwrap_or(0) as usize,
        );
        let shown = &r["shown"];
        let (Ok((av, w)), Ok((bv, _))) = (read(a), read(b)) else {
            out.push(format!("readout names an unreadable EXR: {a} or {b}"));
            continue;
        };
        if shown["x"] != Value::String(x.to_string()) || shown["y"] != Value::String(y.to_string()) {
            out.push(format!(
                "{a}: hovering pixel ({x}, {y}) reads out pixel ({}, {})",
                shown["x"], shown["y"]
            ));
            continue;
        }
        let (va, vb) = (av[y * w + x] as f64, bv[y * w + x] as f64);
        let text = |k: &str| shown[k].as_str().unwrap_or("").to_string();
        if !shows(&text("a"), va) {
            out.push(format!(
                "{a} ({x}, {y}): the page reads {} where the EXR holds {va}",
                text("a")
            ));
        }
        if !shows(&text("b"), vb) {
            out.push(format!(
                "{b} ({x}, {y}): the page reads {} where the EXR holds {vb}",
                text("b")
            ));
        }
        // An error view has no value where either pixel has no receiver; elsewhere every
        // difference is a number, -1 (black against white) too.
        if va == -1.0 || vb == -1.0 {
            if text("e") != "—" {
                out.push(format!(
                    "{a} - {b} ({x}, {y}): the error view reads {} where a pixel has no receiver",
                    text("e")
                ));
            }
        } else if !shows_number(&text("e"), va - vb) {
            out.push(format!(
                "{a} - {b} ({x}, {y}): the error view reads {} where the EXRs differ by {}",
                text("e"),
                va - vb
            ));
        }
        // What is drawn under the cursor is the PNG's pixel there (at 0 EV), and at +1 EV the
        // picture of the EXR's value doubled.
        if r.get("png_a").is_none() {
            out.push(format!(
                "{a} ({x}, {y}): no colour read back (a page from an older viewer: `page DIR` rebuilds it)"
            ));
            continue;
        }
        for (png, key) in [(&r["png_a"], "rgb_a"), (&r["png_b"], "rgb_b")] {
            let png = png.as_str().unwrap_or("");
            match pixels(&mut pngs, dir, png) {
                Ok(img) => {
                    let want = img.get_pixel(x as u32, y as u32).0;
                    if !close(&shown[key], &want) {
                        out.push(format!(
                            "{png} ({x}, {y}): the page draws {} under the cursor where the PNG holds {want:?}",
                            shown[key]
                        ));
                    }
                }
                Err(e) => out.push(e),
            }
        }
        // The signed-difference view (the one the self-test reads) draws A - B on the diverging
        // scale at the 99th percentile of |A - B|, grey where a pixel has no receiver.
        let want = if va == -1.0 || vb == -1.0 {
            [96, 96, 96]
        } else {
            penumbra::output::images::diverging_colour((va - vb) / difference_scale(&av, &bv))
        };
        if !close(&shown["rgb_e"], &want) {
            out.push(format!(
                "{a} - {b} ({x}, {y}): the error view draws {} under the cursor where A - B = {} is {want:?}",
                shown["rgb_e"],
                va - vb
            ));
        }
        match brighter(&r["tone"], va as f32) {
            Some(want) if !close(&shown["rgb_a_ev1"], &want) => out.push(format!(
                "{a} ({x}, {y}): at +1 EV the page draws {} where the value {va} doubled is {want:?}",
                shown["rgb_a_ev1"]
            )),
            Some(_) => {}
            None => out.push(format!("{a}: the readout names no tone mapping: {}", r["tone"])),
        }
    }
    // Every image of the page (an EXR under images/ is one) is read out.
    let exrs: Vec<String> = std::fs::read_dir(dir.join("images"))
        .into_iter()
        .flatten()
        .filter_map(Result::ok)
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n.ends_with(".exr"))
        .map(|n| format!("images/{n}"))
        .collect();
    for e in &exrs {
        if !readouts.iter().any(|r| r["a"] == Value::String(e.clone())) {
            out.push(format!("{e} is not on the page (no readout of it)"));
        }
    }
    // Two different images of one size: the slider and the flip must change what is shown.
    let differing = exrs.iter().enumerate().any(|(i, p)| {
        exrs[i + 1..].iter().any(|q| match (read(p), read(q)) {
            (Ok(a), Ok(b)) => a.1 == b.1 && a.0.len() == b.0.len() && a.0 != b.0,
            _ => false,
        })
    });
    if differing {
        for control in ["slider", "flip", "exposure"] {
            if report[control]["changed"] != Value::Bool(true) {
                out.push(format!(
                    "the {control} does not change what is shown: {}",
                    report[control]
                ));
            }
        }
    }
    out
}

/// Asserts the page in `dir` passes in the browser (when one is installed).
pub fn check_page(dir: &Path) {
    if let Some(browser) = chromium() {
        let p = problems(&browser, dir);
        assert!(
            p.is_empty(),
            "{}/index.html in {}:\n{}",
            dir.display(),
            browser.display(),
            p.join("\n")
        );
    }
}
