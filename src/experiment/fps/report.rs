//! Outputs of a frame-rate experiment: fps.csv, a plot with the paper's Table 1 beside our
//! numbers, report.md and the page (index.html).

use super::{FpsRow, FpsSpec};
use crate::files::write_atomic;
use crate::output::page::{self, Page};
use crate::output::plots::{line_plot, Axes, Point, Reference, Series};
use crate::output::table::{float, write_rows};
use crate::render::AdapterInfo;
use crate::timing::{EstimateColumns, FRAME_S, RULE};
use serde::Serialize;
use std::path::Path;

/// A row of rounds.csv: one configuration's timed frame in one round, so every median and
/// interval of fps.csv recomputes from committed numbers.
#[derive(Serialize)]
struct RoundCsv<'a> {
    scene: &'a str,
    lights: u32,
    width: u32,
    height: u32,
    round: usize,
    #[serde(with = "float")]
    frame_s: f64,
}

/// Writes fps.csv, rounds.csv, plots/fps.png, report.md and index.html under `out`.
pub fn write_fps(
    spec: &FpsSpec,
    rows: &[FpsRow],
    adapter: &AdapterInfo,
    seconds: f64,
    out: &Path,
) -> anyhow::Result<()> {
    write_rows(&out.join("fps.csv"), rows.iter().map(|r| csv_row(spec, r, adapter)))?;
    write_rows(
        &out.join("rounds.csv"),
        rows.iter().flat_map(|r| {
            r.frame_seconds
                .iter()
                .enumerate()
                .map(move |(round, &frame_s)| RoundCsv {
                    scene: &r.scene,
                    lights: r.lights,
                    width: r.width,
                    height: r.height,
                    round,
                    frame_s,
                })
        }),
    )?;
    let mut series = Vec::new();
    let mut refs = Vec::new();
    let pixels: Vec<f64> = spec.resolutions.iter().map(|r| (r[0] * r[1]) as f64 / 1e6).collect();
    let (lo, hi) = (
        pixels.iter().copied().fold(f64::INFINITY, f64::min),
        pixels.iter().copied().fold(0.0, f64::max),
    );
    let mut keys: Vec<(String, u32)> = rows.iter().map(|r| (r.scene.clone(), r.lights)).collect();
    keys.dedup();
    for (i, (scene, lights)) in keys.iter().enumerate() {
        let of: Vec<&FpsRow> = rows
            .iter()
            .filter(|r| &r.scene == scene && r.lights == *lights)
            .collect();
        // Each frame rate with the interval of its timed frames, as fps.csv and the table give it.
        let points = of
            .iter()
            .map(|r| {
                let fps = r.fps();
                Point::between((r.width * r.height) as f64 / 1e6, fps.median, fps.lo, fps.hi)
            })
            .collect();
        series.push(Series {
            name: format!("{scene}, {lights} light(s): ours"),
            look: i,
            points,
        });
        if let Some(r) = of.first() {
            refs.push(Reference {
                name: format!("{scene}, {lights} light(s): paper"),
                points: vec![(lo, r.paper_fps), (hi, r.paper_fps)],
                colour: Some(i),
            });
        }
    }
    let title = format!(
        "Table 1 on {} (paper: GTX 560M): {} shadow rays per pixel per light",
        adapter.name, spec.samples
    );
    line_plot(
        &out.join("plots/fps.png"),
        &Axes {
            interval: "95 % interval over the timed frames",
            ..Axes::new(&title, "megapixels", "frames per second (median)", true, true)
        },
        &series,
        &refs,
    )?;
    let mut md = format!("# {}: the soft-shadow paper's Table 1, measured\n\n", spec.name);
    md += &format!(
        "Experiment `{}` on **{}** ({}, {}, {}), {:.0} s. Each configuration renders {} shadow rays per pixel per light with the `{}` scheme ({} pattern) on 4 cm disk lights; every configuration is timed once per round in {} interleaved rounds ({} untimed frames before each timed one; clock: {}). {RULE}\n\n",
        spec.path.display(),
        adapter.name,
        adapter.backend,
        adapter.api,
        adapter.driver,
        seconds,
        spec.samples,
        spec.sampling.scheme,
        spec.sampling.pattern,
        spec.header.schedule.repeats,
        spec.header.schedule.warmup,
        rows.first().map_or("-", |r| r.clock.name())
    );
    md += "The paper (Vassilev 2012, Table 1) timed 100 frames with OptiX on a GTX 560M laptop GPU at an unstated resolution: sphere 15.95 / 9.39 fps, dressed body 8.36 / 6.13 fps with one / two lights.\n\n";
    md += "| scene | lights | resolution | frame ms [95 %] | fps (ours) [95 %] | fps (paper) | rays per frame | nodes per frame | tests per frame | shadow rays/s |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for r in rows {
        let count = |f: fn(&crate::accel::work::Work) -> u64| {
            r.work.as_ref().map_or("n/a".into(), |w| format!("{:.3e}", f(w) as f64))
        };
        md += &format!(
            "| {} | {} | {}x{} | {} | {} | {} | {:.3e} | {} | {} | {:.3e} |\n",
            r.scene,
            r.lights,
            r.width,
            r.height,
            r.frame.scaled(1e3).show(1),
            r.fps().show(3),
            r.paper_fps,
            (r.primary_rays + r.shadow_rays) as f64,
            count(|w| w.nodes),
            count(|w| w.primitives),
            r.shadow_rays_per_s()
        );
    }
    md += "\nOutputs: `fps.csv` (one row per configuration, with the adapter), `rounds.csv` (every timed frame, in round order: each median and interval recomputes from it), `plots/fps.png`, `index.html` (the page); nodes and tests are counted on the CPU backend only (n/a on the GPU).\n";
    write_atomic(&out.join("report.md"), md.as_bytes())?;
    page::write(
        out,
        &Page {
            title: format!("{}: frame rates", spec.name),
            report: md,
            galleries: vec![],
        },
    )
}

/// A row of fps.csv: one timed configuration, its frame time with its interval ([`FRAME_S`]), its
/// rates and work, with the device.
type CsvRow<'a> = (Configuration<'a>, EstimateColumns, Rates<'a>);

/// The columns before the frame time in fps.csv.
#[derive(Serialize)]
struct Configuration<'a> {
    scene: &'a str,
    lights: u32,
    width: u32,
    height: u32,
    samples: u32,
    timed_frames: usize,
}

/// The columns after the frame time in fps.csv.
#[derive(Serialize)]
struct Rates<'a> {
    #[serde(with = "float")]
    frames_per_s: f64,
    #[serde(with = "float")]
    paper_frames_per_s: f64,
    primary_rays: u64,
    shadow_rays: u64,
    queries: Option<u64>,
    nodes_visited: Option<u64>,
    primitive_tests: Option<u64>,
    #[serde(with = "float")]
    shadow_rays_per_s: f64,
    clock: &'a str,
    adapter: &'a str,
    driver: &'a str,
    api: &'a str,
}

/// The row of `r`, timed on `a`.
fn csv_row<'a>(spec: &FpsSpec, r: &'a FpsRow, a: &'a AdapterInfo) -> CsvRow<'a> {
    (
        Configuration {
            scene: &r.scene,
            lights: r.lights,
            width: r.width,
            height: r.height,
            samples: spec.samples,
            timed_frames: r.frame_seconds.len(),
        },
        r.frame.columns(FRAME_S),
        Rates {
            frames_per_s: r.fps().median,
            paper_frames_per_s: r.paper_fps,
            primary_rays: r.primary_rays,
            shadow_rays: r.shadow_rays,
            queries: r.work.map(|w| w.queries),
            nodes_visited: r.work.map(|w| w.nodes),
            primitive_tests: r.work.map(|w| w.primitives),
            shadow_rays_per_s: r.shadow_rays_per_s(),
            clock: r.clock.name(),
            adapter: &a.name,
            driver: &a.driver,
            api: &a.api,
        },
    )
}
