//! index.html: a results folder as a page a person can look at offline. Any two images of one
//! size compared with a slider or a flip, zoomed and panned together with nearest-neighbour
//! magnification, under one exposure, with both pixel values read out under the cursor; error
//! views (signed difference, relative squared error, FLIP) with colour bars; the tables,
//! sortable, their rows linked to the images they describe; the plots; the report with its
//! verdict.
//!
//! The page opens from the file system with no server and no network: a browser refuses to let
//! a `file://` page read files or a canvas drawn from them, so the measured values travel in a
//! script beside the page (`page_data.js`, each image zlib-compressed and base64-encoded) and the
//! viewer draws them itself. The EXR beside each image holds the same values; the browser test
//! (tests/it/pages.rs) checks the page's readouts against it.

mod data;
mod markdown;
pub(crate) mod rebuild;

use crate::files::write_atomic;
use crate::metrics::flip::{flip_map, PIXELS_PER_DEGREE};
use crate::output::images::{grey, tonemap_with};
use anyhow::Context;
use serde::Serialize;
use std::path::Path;

pub use markdown::to_html as markdown_to_html;
pub use rebuild::rebuild;

/// How an image's values become a picture: the same mapping as its PNG.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Tone {
    /// Values in [0, 1] (visibility, ambient occlusion) shown as grey, value 1 white.
    Linear,
    /// Radiance tone-mapped like [`crate::output::images::tonemap_with`] with this exposure
    /// (the 99th percentile that maps to the knee). Radiance galleries are pictures to look at,
    /// not measurements: their EXRs and the page store them at half precision.
    Radiance {
        /// The exposure.
        p99: f64,
    },
}

impl Tone {
    /// Radiance as a picture gallery stores it: rounded to half precision, a finite value beyond
    /// the half range saturated to its largest (a highlight stays the brightest white, not
    /// infinity). A gallery's exposure is taken over these values, so that a page rebuilt from
    /// the EXRs finds the same exposure.
    pub fn radiance_stored(values: &[f32]) -> Vec<f32> {
        let most = half::f16::MAX.to_f32();
        values
            .iter()
            .map(|&v| {
                let v = if v.is_finite() { v.clamp(-most, most) } else { v };
                half::f16::from_f32(v).to_f32()
            })
            .collect()
    }

    /// The 8-bit picture of `values` (what the PNG shows and FLIP compares).
    pub fn picture(self, values: &[f32], width: u32, height: u32) -> crate::output::images::Rgb {
        match self {
            Tone::Linear => grey(values, width, height),
            Tone::Radiance { p99 } => tonemap_with(values, width, height, p99),
        }
    }
}

/// One measured image on the page.
#[derive(Clone, Debug)]
pub struct Shot {
    /// What it shows, e.g. "sobol (per-pixel), 16 rays".
    pub label: String,
    /// Its EXR, relative to the results folder (the page's readouts come from the same values).
    pub exr: String,
    /// Its PNG, relative to the results folder.
    pub png: String,
    /// The values, row-major from the top left.
    pub values: Vec<f32>,
    /// Column values that identify it in the page's tables (e.g. scheme = "sobol"): a table row
    /// whose same-named columns all hold these values links to it.
    pub key: Vec<(String, String)>,
}

/// Images of one size and meaning, compared with each other (one view of one scene).
#[derive(Clone, Debug)]
pub struct Gallery {
    /// Title, e.g. "measuring view, 16 rays, light radius 0.25".
    pub title: String,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// How values are shown.
    pub tone: Tone,
    /// The image the others are measured against (FLIP maps are computed against it); the page
    /// pins it as B when one of the others is A.
    pub reference: Option<usize>,
    /// A gallery of the same size whose i-th image is the counterpart of this one's i-th (the
    /// same frame under the other shading): B where this gallery has no reference.
    pub against: Option<usize>,
    /// The images.
    pub shots: Vec<Shot>,
}

impl Gallery {
    /// Whether its values are stored at half precision (see [`Tone::Radiance`]).
    pub fn half(&self) -> bool {
        matches!(self.tone, Tone::Radiance { .. })
    }

    /// A shot's values as stored (EXR and page alike): rounded to half precision in a half
    /// gallery, so that what the page reads out is what the file holds.
    pub fn stored(&self, shot: &Shot) -> Vec<f32> {
        stored_as(shot, self.half())
    }
}

/// A shot's values, rounded to half precision where `half` ([`Tone::radiance_stored`]).
fn stored_as(shot: &Shot, half: bool) -> Vec<f32> {
    if half {
        Tone::radiance_stored(&shot.values)
    } else {
        shot.values.clone()
    }
}

/// A results folder's page: what the report step knows besides the files it wrote.
#[derive(Clone, Debug, Default)]
pub struct Page {
    /// Title (the experiment's name and kind).
    pub title: String,
    /// The report in markdown (report.md), shown as the page's text with its verdict.
    pub report: String,
    /// The images.
    pub galleries: Vec<Gallery>,
}

/// Tables larger than this are linked, not shown (a page stays quick to open).
const TABLE_BYTES: u64 = 1 << 20;

/// Writes every shot's EXR and PNG into `dir`, each at its path (relative to `dir`).
pub fn write_shots(dir: &Path, gallery: &Gallery) -> anyhow::Result<()> {
    use crate::output::images::{write_exr, write_exr_half, write_png};
    let (w, h) = (gallery.width, gallery.height);
    for s in &gallery.shots {
        let values = gallery.stored(s);
        if gallery.half() {
            write_exr_half(&dir.join(&s.exr), &values, w, h)?;
        } else {
            write_exr(&dir.join(&s.exr), &values, w, h)?;
        }
        write_png(&dir.join(&s.png), &gallery.tone.picture(&values, w, h))?;
    }
    Ok(())
}

/// Writes index.html and page_data.js into `dir`, the results folder whose tables (*.csv, by
/// name; those over 1 MiB linked only), plots (plots/*.svg, else *.png) and pictures (images/*.png
/// with no EXR beside them) the page shows.
pub fn write(dir: &Path, page: &Page) -> anyhow::Result<()> {
    let half: Vec<bool> = page.galleries.iter().map(Gallery::half).collect();
    write_stored(dir, page, &half)
}

/// [`write`], each gallery's values stored at half precision where `half` says so (a rebuilt
/// folder's pictures keep the precision their EXRs have).
fn write_stored(dir: &Path, page: &Page, half: &[bool]) -> anyhow::Result<()> {
    check(&page.galleries)?;
    let mut galleries = Vec::new();
    for (g, &half) in page.galleries.iter().zip(half) {
        galleries.push(data::gallery(g, half, flip_maps(g, half)?)?);
    }
    let mut tables = Vec::new();
    for t in files_in(dir, "", ".csv")? {
        if std::fs::symlink_metadata(dir.join(&t))?.len() > TABLE_BYTES {
            tables.push(data::linked(&t));
            continue;
        }
        let text = crate::files::read_regular_text_at_most(&dir.join(&t), MAX_TEXT_BYTES)
            .with_context(|| format!("reading {t} for the page"))?;
        tables.push(data::table(&t, &text)?);
    }
    let plots = plots_in(dir)?;
    let script = data::script(&galleries, &tables)?;
    write_atomic(&dir.join("page_data.js"), script.as_bytes())?;
    let html = html(page, &plots, &pictures_in(dir)?);
    write_atomic(&dir.join("index.html"), html.as_bytes())
}

/// Per shot, its FLIP map against the gallery's reference (none for the reference itself or
/// where the gallery has none): FLIP compares what a person sees, the pictures the PNGs hold.
fn flip_maps(g: &Gallery, half: bool) -> anyhow::Result<Vec<Option<Vec<f32>>>> {
    let Some(r) = g.reference else {
        return Ok(vec![None; g.shots.len()]);
    };
    let reference = g.tone.picture(&stored_as(&g.shots[r], half), g.width, g.height);
    g.shots
        .iter()
        .enumerate()
        .map(|(i, s)| {
            if i == r {
                return Ok(None);
            }
            let test = g.tone.picture(&stored_as(s, half), g.width, g.height);
            flip_map(&reference.data, &test.data, g.width, g.height, PIXELS_PER_DEGREE).map(Some)
        })
        .collect()
}

/// Refuses galleries the page cannot show: one without images, a reference that is not one of
/// its images, a counterpart gallery that does not exist or whose images are of another size.
fn check(galleries: &[Gallery]) -> anyhow::Result<()> {
    for (i, g) in galleries.iter().enumerate() {
        anyhow::ensure!(!g.shots.is_empty(), "gallery {:?} has no images", g.title);
        if let Some(r) = g.reference {
            anyhow::ensure!(
                r < g.shots.len(),
                "gallery {:?}: reference {r} of {} images",
                g.title,
                g.shots.len()
            );
        }
        if let Some(o) = g.against {
            anyhow::ensure!(o != i, "gallery {:?} is set against itself", g.title);
            let other = galleries
                .get(o)
                .with_context(|| format!("gallery {:?} is set against gallery {o}, which is not there", g.title))?;
            anyhow::ensure!(
                (other.width, other.height) == (g.width, g.height),
                "gallery {:?} ({}x{}) is set against {:?} ({}x{})",
                g.title,
                g.width,
                g.height,
                other.title,
                other.width,
                other.height
            );
        }
    }
    Ok(())
}

/// The most bytes of one text (a CSV, an SVG plot, report.md) the page embeds: 40 times the
/// largest an experiment here writes (a sweep's runs.csv, 1.7 MB), so a planted or runaway file
/// is refused from its length instead of filling memory.
pub const MAX_TEXT_BYTES: u64 = 64 << 20;

/// The files of `dir`/`sub` whose names end in `suffix`, sorted, relative to `dir`; such a name
/// that is not a regular file (a link, pipe or folder), or that is not UTF-8, is refused with its
/// path.
fn files_in(dir: &Path, sub: &str, suffix: &str) -> anyhow::Result<Vec<String>> {
    crate::files::check_plain_folder(&dir.join(sub))?;
    let Ok(entries) = std::fs::read_dir(dir.join(sub)) else {
        return Ok(vec![]);
    };
    let mut names = Vec::new();
    for e in entries.filter_map(Result::ok) {
        let n = match e.file_name().into_string() {
            Ok(n) => n,
            Err(raw) => {
                use std::os::unix::ffi::OsStrExt;
                if raw.as_bytes().ends_with(suffix.as_bytes()) {
                    return Err(crate::files::Refused(format!(
                        "{}: a file name that is not UTF-8, which the page cannot name; rename or remove it",
                        e.path().display()
                    ))
                    .into());
                }
                continue;
            }
        };
        if !n.ends_with(suffix) {
            continue;
        }
        if !e.file_type().is_ok_and(|t| t.is_file()) {
            // Opening it says what it is, without following or blocking.
            crate::files::open_regular(&e.path())?;
        }
        names.push(if sub.is_empty() { n } else { format!("{sub}/{n}") });
    }
    names.sort();
    Ok(names)
}

/// The plots of a results folder, one file per plot (SVG where there is one).
fn plots_in(dir: &Path) -> anyhow::Result<Vec<String>> {
    let svg = files_in(dir, "plots", ".svg")?;
    let png = files_in(dir, "plots", ".png")?;
    let mut all: Vec<String> = png
        .into_iter()
        .filter(|p| !svg.contains(&p.replace(".png", ".svg")))
        .chain(svg.iter().cloned())
        .collect();
    all.sort();
    Ok(all)
}

/// The pictures under images/ that are not measured images (PNG with no EXR beside it: grids,
/// strips).
fn pictures_in(dir: &Path) -> anyhow::Result<Vec<String>> {
    let exr = files_in(dir, "images", ".exr")?;
    Ok(files_in(dir, "images", ".png")?
        .into_iter()
        .filter(|p| !exr.contains(&p.replace(".png", ".exr")))
        .collect())
}

const STYLE: &str = include_str!("page.css");
const SCRIPT: &str = include_str!("page.js");
const SELFTEST: &str = include_str!("selftest.js");

/// Text made safe inside HTML elements and double-quoted attributes.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

fn html(page: &Page, plots: &[String], pictures: &[String]) -> String {
    let title = escape(&page.title);
    // A page without images (the fps kind) has no comparison to link to.
    let compare = if page.galleries.is_empty() {
        ""
    } else {
        "<a href=\"#compare\">compare</a> "
    };
    let mut h = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{title}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n<header><h1>{title}</h1><nav>{compare}<a href=\"#tables\">tables</a> <a href=\"#plots\">plots</a> <a href=\"#report\">report</a></nav></header>\n"
    );
    if !page.galleries.is_empty() {
        h += COMPARE;
    }
    h += "<section id=\"tables\"><h2>Tables</h2><p class=\"hint\">Click a column to sort; a row with an image opens it in the comparison.</p><div id=\"table-list\"></div></section>\n";
    h += "<section id=\"plots\"><h2>Plots</h2>\n";
    h += "<p class=\"hint\">Click a figure to see it at full size.</p>\n";
    for p in plots.iter().chain(pictures) {
        let p = escape(p);
        h += &format!("<figure><div class=\"scroll\"><img src=\"{p}\" alt=\"{p}\" loading=\"eager\"></div><figcaption><a href=\"{p}\">{p}</a></figcaption></figure>\n");
    }
    h += "</section>\n<section id=\"report\"><h2>Report</h2>\n";
    h += &markdown::to_html(&page.report);
    h += "</section>\n<div id=\"lightbox\" hidden><img id=\"lightbox-img\" alt=\"the figure at full size\"></div>\n<pre id=\"selftest\" hidden></pre>\n<script src=\"page_data.js\"></script>\n<script>\n";
    h += SCRIPT;
    h += SELFTEST;
    h += "</script>\n</body>\n</html>\n";
    h
}

const COMPARE: &str = r#"<section id="compare"><h2>Compare</h2>
<div class="controls">
<label>A <select id="pick-a"></select></label>
<label>B <select id="pick-b"></select></label>
<label>mode <select id="mode"><option value="split">slider</option><option value="toggle">toggle</option></select></label>
<label id="split-label">split <input id="split" type="range" min="0" max="1" step="0.001" value="0.5"></label>
<button id="toggle" type="button" title="show A, then B, in one place (key T)">toggle A/B (T)</button>
<label>exposure <input id="exposure" type="range" min="-6" max="6" step="0.25" value="0"> <output id="exposure-value">0 EV</output></label>
<label>error view <select id="error-view"><option value="diff">signed difference A − B</option><option value="relse">relative squared error</option><option value="flip">FLIP of A against B</option></select></label>
<label>scale <select id="scale"><option value="auto">auto (99th percentile)</option><option value="fixed">fixed (the values' range)</option><option value="user">maximum:</option><option value="log">log (4 decades)</option></select> <input id="user-max" type="number" min="0" step="any" value="1" disabled></label>
<button id="fit" type="button">fit</button>
</div>
<table id="numbers" class="numbers" title="A against B over every pixel where both have a receiver (the tables' errors are over the penumbra only); pixels differing: values not bit for bit equal"><tr><th>MSE</th><th>relMSE</th><th>mean FLIP</th><th>max |A − B|</th><th>pixels differing</th><th>pixels compared</th></tr>
<tr><td id="num-mse"></td><td id="num-relmse"></td><td id="num-flip"></td><td id="num-max"></td><td><span id="num-differ"></span> of <span id="num-pixels"></span></td><td id="num-compared"></td></tr></table>
<div class="views">
<figure><canvas id="view-compare" width="640" height="480"></canvas><figcaption><span id="compare-caption" class="line"></span><span id="tone-caption" class="line"></span></figcaption></figure>
<figure><canvas id="view-error" width="640" height="480"></canvas><figcaption><span id="colour-scale" class="line"><canvas id="colour-bar" width="256" height="14"></canvas><span id="bar-lo"></span><span id="bar-hi"></span></span><span id="error-caption" class="line"></span></figcaption></figure>
</div>
<p id="readout" class="readout">Move the cursor over an image: pixel, A, B and the error view's value. Drag pans (the yellow divider moves the split); click the image or hold Ctrl and wheel to zoom; keys 1-9 step A through its gallery, T toggles.</p>
<p class="files" id="files"></p>
</section>
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_leaves_no_markup() {
        assert_eq!(
            escape(r#"<img src=x onerror="a('b')">&"#),
            "&lt;img src=x onerror=&quot;a(&#39;b&#39;)&quot;&gt;&amp;"
        );
    }
}
