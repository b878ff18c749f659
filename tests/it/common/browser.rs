//! A results page opened in a real browser (Debian's headless `chromium`): the page's self-test
//! (`index.html#selftest`) hovers every image, moves the slider and the divider, toggles, changes
//! the exposure, the error view and its scale, presses keys, turns the wheel, reopens its view
//! from the URL, opens a plot, and checks that every <img> decoded; this module reads what it
//! wrote and checks it against the files: the pair the page opens on and the B that follows each
//! A picked in its select against the galleries in page_data.js, each readout against the EXR
//! beside the image, the error view's readout against the two EXRs' difference, the pair's
//! numbers (MSE, relMSE, max, pixels differing) against the crate's error metrics of the EXRs
//! and the mean FLIP against the crate's FLIP of the two PNGs, the colour drawn under the cursor
//! against the crate's tone mapping under the pair's one tone (the PNG's pixel where the image's
//! own tone is that one), and that no frame of the page moves while the controls change.

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
            "--window-size=1600,1200",
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
pub fn exr(path: &Path) -> Result<(Vec<f32>, usize), String> {
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

/// The colour the page should draw for `value` under the tone `tone` (JSON as the page has it)
/// at `ev` stops, computed with the crate's own mapping: the value times 2^ev, except a pixel
/// with no receiver, which keeps its colour.
fn drawn(tone: &Value, value: f32, ev: i32) -> Option<[u8; 3]> {
    use penumbra::output::images::{grey, tonemap_with};
    let gain = 2f32.powi(ev);
    let scaled = if value == -1.0 { value } else { gain * value };
    let img = match tone["kind"].as_str()? {
        "linear" => grey(&[scaled], 1, 1),
        "radiance" => tonemap_with(&[gain * value], 1, 1, tone["p99"].as_f64()?),
        _ => return None,
    };
    img.data.try_into().ok()
}

/// The pair's numbers from the two EXRs: pixels compared (both with a receiver), pixels whose
/// bits differ, and the crate's error metrics of A against B over the compared pixels (the
/// tables take them over the penumbra only): MSE (RMSE squared), relMSE (÷ (B² + 0.01)), max
/// |A − B|.
fn pair_numbers(a: &[f32], b: &[f32]) -> [f64; 5] {
    use penumbra::metrics::error::{ErrorMetrics, PenumbraMask};
    let differing = a.iter().zip(b).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
    let mask = PenumbraMask {
        pixels: (0..a.len()).filter(|&i| a[i] != -1.0 && b[i] != -1.0).collect(),
    };
    let m = ErrorMetrics::measure(a, b, &mask);
    [
        mask.pixels.len() as f64,
        differing as f64,
        m.rmse * m.rmse,
        m.relmse,
        m.max_abs,
    ]
}

/// Whether the page's text shows `value` to the six significant digits its numbers have.
fn shows_six(text: &str, value: f64) -> bool {
    let Ok(shown) = text.parse::<f64>() else {
        return false;
    };
    (shown - value).abs() <= 6e-6 * value.abs() + 1e-300
}

/// The pair the page should open on, from the galleries in page_data.js: the first gallery's
/// first image that is not its reference, against its partner, or the gallery's next image.
fn expected_opening(data: &Value) -> Option<(String, String)> {
    let galleries = data["galleries"].as_array()?;
    let g = galleries.first()?;
    let shots = g["shots"].as_array()?;
    let reference = g["reference"].as_u64().map(|r| r as usize);
    let a = (0..shots.len()).find(|&k| Some(k) != reference).unwrap_or(0);
    let exr = |k: usize| g["shots"][k]["exr"].as_str().map(str::to_string);
    let b = match expected_partner(data, &exr(a)?) {
        Some(b) => b,
        None => exr((a + 1) % shots.len())?,
    };
    Some((exr(a)?, b))
}

/// The image B must follow A to, from the galleries in page_data.js: its gallery's reference
/// (where A is not it), else the same image of the gallery it is set against (where that gallery
/// has one, of its size); `None` where B is free.
fn expected_partner(data: &Value, a: &str) -> Option<String> {
    let galleries = data["galleries"].as_array()?;
    let (g, k) = galleries.iter().enumerate().find_map(|(g, gallery)| {
        let k = gallery["shots"].as_array()?.iter().position(|s| s["exr"] == a)?;
        Some((g, k))
    })?;
    let gallery = &galleries[g];
    let exr = |g: &Value, k: usize| g["shots"][k]["exr"].as_str().map(str::to_string);
    if let Some(r) = gallery["reference"].as_u64().filter(|&r| r as usize != k) {
        return exr(gallery, r as usize);
    }
    let other = &galleries[gallery["against"].as_u64()? as usize];
    let same_size = other["width"] == gallery["width"] && other["height"] == gallery["height"];
    (same_size && k < other["shots"].as_array()?.len()).then(|| exr(other, k))?
}

/// The gallery of page_data.js that holds the image `exr`.
fn gallery_of<'a>(data: &'a Value, exr: &str) -> Option<&'a Value> {
    data["galleries"]
        .as_array()?
        .iter()
        .find(|g| g["shots"].as_array().is_some_and(|s| s.iter().any(|s| s["exr"] == exr)))
}

/// page_data.js as JSON.
pub fn page_data(dir: &Path) -> Result<Value, String> {
    let text = std::fs::read_to_string(dir.join("page_data.js")).map_err(|e| format!("page_data.js: {e}"))?;
    let json = text
        .strip_prefix("window.PENUMBRA = ")
        .and_then(|t| t.trim_end().strip_suffix(';'))
        .ok_or("page_data.js is not `window.PENUMBRA = {...};`")?;
    serde_json::from_str(json).map_err(|e| format!("page_data.js: {e}"))
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
    let data = page_data(dir);
    match &data {
        Ok(data) => {
            // Picking A in its select, B follows to A's reference or counterpart.
            for r in &readouts {
                let (Some(a), Some(followed)) = (r["a"].as_str(), r["followed"].as_str()) else {
                    continue;
                };
                if let Some(want) = expected_partner(data, a).filter(|w| w != followed) {
                    out.push(format!(
                        "picking A = {a} leaves B on {followed}, not on {want} (its reference or counterpart)"
                    ));
                }
            }
            if let Some((a, b)) = expected_opening(data) {
                let opened = (report["opened"]["a"].as_str(), report["opened"]["b"].as_str());
                if opened.0 == opened.1 && a != b {
                    out.push(format!(
                        "the page opens comparing an image with itself ({:?})",
                        opened.0
                    ));
                } else if opened != (Some(a.as_str()), Some(b.as_str())) {
                    out.push(format!(
                        "the page opens on {opened:?}, not on {a} against {b} (its reference or counterpart)"
                    ));
                }
            }
        }
        Err(e) => out.push(e.clone()),
    }
    for r in &readouts {
        check_readout(r, data.as_ref().ok(), dir, &mut read, &mut pngs, &mut out);
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
    // Two different images of one size: the slider and the toggle must change what is shown.
    let differing = exrs.iter().enumerate().any(|(i, p)| {
        exrs[i + 1..].iter().any(|q| match (read(p), read(q)) {
            (Ok(a), Ok(b)) => a.1 == b.1 && a.0.len() == b.0.len() && a.0 != b.0,
            _ => false,
        })
    });
    if differing {
        for control in ["slider", "toggle", "exposure"] {
            if report[control]["changed"] != Value::Bool(true) {
                out.push(format!(
                    "the {control} does not change what is shown: {}",
                    report[control]
                ));
            }
        }
    }
    if !exrs.is_empty() {
        controls(&report, &mut out);
    }
    if let Some(plot) = report["plot"].as_object() {
        if plot["open"] != Value::Bool(true) || plot["natural"] != plot["shown"] || plot["natural"] == 0 {
            out.push(format!(
                "a plot does not open at full size on click: {}",
                report["plot"]
            ));
        }
    }
    out
}

/// The controls' own checks: the layout holds still, keys, wheel, divider, FLIP's offer, URL.
fn controls(report: &Value, out: &mut Vec<String>) {
    for m in report["layout"].as_array().into_iter().flatten() {
        out.push(format!("the layout moves: {}", m.as_str().unwrap_or("")));
    }
    if report["keys"]["jump"] == Value::Bool(false) {
        out.push("a number key does not move A through its gallery against the pinned B".into());
    }
    if report["keys"]["after_slider"] != Value::Bool(true) {
        out.push("T does not toggle A/B once the slider has had the focus".into());
    }
    let wheel = &report["wheel"];
    if wheel["plain_ignored"] != Value::Bool(true) {
        out.push("the wheel zooms (and stops the page scrolling) without a click or a modifier".into());
    }
    if wheel["modifier_zooms"] != Value::Bool(true) {
        out.push("the wheel with Ctrl does not zoom".into());
    }
    let (most, least, fit) = (
        wheel["most"].as_f64().unwrap_or(f64::INFINITY),
        wheel["least"].as_f64().unwrap_or(0.0),
        wheel["fit"].as_f64().unwrap_or(1.0),
    );
    // Turned all the way each way, the wheel stops at half the fit and at 64x (twice the fit,
    // for an image that small).
    let (want_least, want_most) = (fit / 2.0, 64f64.max(2.0 * fit));
    let near = |x: f64, y: f64| (x - y).abs() <= 1e-9 * y;
    if !near(least, want_least) || !near(most, want_most) {
        out.push(format!(
            "zoom is unbounded or wrongly bounded: {least} .. {most} for a fit of {fit} (bounds {want_least} .. {want_most})"
        ));
    }
    if (report["divider"]["split"].as_f64().unwrap_or(0.5) - 0.75).abs() > 0.01 {
        out.push(format!(
            "dragging the divider a quarter of the view to the right gives split {}, not 0.75",
            report["divider"]["split"]
        ));
    }
    for f in report["flip_offered"].as_array().into_iter().flatten() {
        out.push(format!("the FLIP view: {}", f.as_str().unwrap_or("")));
    }
    if report["hash"]["ok"] != Value::Bool(true) {
        out.push(format!(
            "the view in the URL does not reopen the same view: {}",
            report["hash"]
        ));
    }
}

type Exrs<'a> = dyn FnMut(&str) -> Result<(Vec<f32>, usize), String> + 'a;

/// One readout (an image A against B at one pixel) against the files and the galleries of
/// page_data.js (`data`): which image is A's reference, and each gallery's tone.
fn check_readout(
    r: &Value,
    data: Option<&Value>,
    dir: &Path,
    read: &mut Exrs,
    pngs: &mut std::collections::BTreeMap<String, image::RgbImage>,
    out: &mut Vec<String>,
) {
    let (a, b) = (r["a"].as_str().unwrap_or(""), r["b"].as_str().unwrap_or(""));
    let (x, y) = (
        r["x"].as_u64().unwrap_or(0) as usize,
        r["y"].as_u64().unwrap_or(0) as usize,
    );
    let shown = &r["shown"];
    let (Ok((av, w)), Ok((bv, _))) = (read(a), read(b)) else {
        out.push(format!("readout names an unreadable EXR: {a} or {b}"));
        return;
    };
    let (Some(gallery_a), Some(gallery_b)) = (data.and_then(|d| gallery_of(d, a)), data.and_then(|d| gallery_of(d, b)))
    else {
        out.push(format!("readout names an image page_data.js does not hold: {a} or {b}"));
        return;
    };
    let reference = gallery_a["reference"]
        .as_u64()
        .and_then(|k| gallery_a["shots"][k as usize]["exr"].as_str());
    if shown["x"] != Value::String(x.to_string()) || shown["y"] != Value::String(y.to_string()) {
        out.push(format!(
            "{a}: hovering pixel ({x}, {y}) reads out pixel ({}, {})",
            shown["x"], shown["y"]
        ));
        return;
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
    // The pair's numbers, from the EXRs; bit-identical images are said to be so.
    let identical = av.iter().zip(&bv).all(|(p, q)| p.to_bits() == q.to_bits());
    let says_identical = r["error_caption"].as_str().unwrap_or("").contains("bit-identical");
    if identical != says_identical {
        out.push(format!(
            "{a} against {b}: the images are {}bit-identical but the error view says {:?}",
            if identical { "" } else { "not " },
            r["error_caption"]
        ));
    }
    let [compared, differing, mse, relmse, max] = pair_numbers(&av, &bv);
    let numbers = &r["numbers"];
    let number = |k: &str| numbers[k].as_str().unwrap_or("").to_string();
    for (k, want) in [
        ("compared", compared),
        ("differ", differing),
        ("pixels", av.len() as f64),
    ] {
        if number(k).parse::<f64>().ok() != Some(want) {
            out.push(format!(
                "{a} against {b}: the page's {k} is {} where the EXRs give {want}",
                number(k)
            ));
        }
    }
    for (k, want) in [("mse", mse), ("relmse", relmse), ("max", max)] {
        let ok = if compared == 0.0 {
            number(k) == "—"
        } else if want == 0.0 {
            number(k) == "0"
        } else {
            shows_six(&number(k), want)
        };
        if !ok {
            out.push(format!(
                "{a} against {b}: the page's {k} is {} where the EXRs give {want}",
                number(k)
            ));
        }
    }
    // Mean FLIP: A's map is against its gallery's reference, which B is here (where B is not,
    // the page shows none).
    if reference == Some(b) && a != b {
        let flip = (|| -> Result<f64, String> {
            let reference = pixels(pngs, dir, r["png_b"].as_str().unwrap_or(""))?.clone();
            let test = pixels(pngs, dir, r["png_a"].as_str().unwrap_or(""))?;
            penumbra::metrics::flip::flip_mean(
                reference.as_raw(),
                test.as_raw(),
                reference.width(),
                reference.height(),
                penumbra::metrics::flip::PIXELS_PER_DEGREE,
            )
            .map_err(|e| e.to_string())
        })();
        match flip {
            Ok(want) if !shows_six(&number("flip"), want) => out.push(format!(
                "{a} against {b}: the page's mean FLIP is {} where the crate's FLIP of the PNGs is {want}",
                number("flip")
            )),
            Ok(_) => {}
            Err(e) => out.push(e),
        }
    } else if number("flip") != "—" {
        out.push(format!(
            "{a} against {b}: a mean FLIP ({}) where B is not A's reference",
            number("flip")
        ));
    }
    // What is drawn under the cursor: A and B each under the pair's one tone (B's gallery's, as
    // page_data.js gives it), which is the PNG's pixel where the image's own tone is that one, and
    // A at +1 EV.
    if r.get("png_a").is_none() {
        out.push(format!(
            "{a} ({x}, {y}): no colour read back (a page from an older viewer: `page DIR` rebuilds it)"
        ));
        return;
    }
    let tone = &gallery_b["tone"];
    for (value, png, own, key) in [
        (va, &r["png_a"], &gallery_a["tone"], "rgb_a"),
        (vb, &r["png_b"], &gallery_b["tone"], "rgb_b"),
    ] {
        match drawn(tone, value as f32, 0) {
            Some(want) if !close(&shown[key], &want) => out.push(format!(
                "{} ({x}, {y}): the page draws {} under the cursor where the pair's tone map {tone} gives {want:?} for {value}",
                png.as_str().unwrap_or(""),
                shown[key]
            )),
            Some(_) => {}
            None => out.push(format!("{a}: the readout names no tone mapping: {tone}")),
        }
        if own != tone {
            continue;
        }
        let png = png.as_str().unwrap_or("");
        match pixels(pngs, dir, png) {
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
    if !identical {
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
    }
    match drawn(tone, va as f32, 1) {
        Some(want) if !close(&shown["rgb_a_ev1"], &want) => out.push(format!(
            "{a} ({x}, {y}): at +1 EV the page draws {} where the value {va} doubled is {want:?}",
            shown["rgb_a_ev1"]
        )),
        _ => {}
    }
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
