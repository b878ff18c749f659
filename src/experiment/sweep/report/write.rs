//! Writes a finished sweep: tables, plots, images, report and manifest, each file atomically,
//! the manifest last.

use super::markdown::{report, verdict_radius};
use super::pictures::{picture_flip, write_fig2_picture};
use super::summary::{self, Summary};
use crate::experiment::sweep::axes::{slices, Axis, Config, Slice};
use crate::experiment::sweep::pictures::Pictures;
use crate::experiment::sweep::record::Aggregated;
use crate::experiment::sweep::runner::{figure_samples, Outcome};
use crate::experiment::sweep::timing::ConfigTiming;
use crate::experiment::sweep::Spec;
use crate::files::write_atomic;
use crate::metrics::stats::MeanCi;
use crate::output::images::{diverging, grey, write_exr, Rgb};
use crate::output::plots::{image_grid, line_plot, Axes, Reference as RefLine, Series};
use crate::output::table::{float, write_rows};
use crate::render::AdapterInfo;
use crate::sampling::{DiskScheme, Pattern};
use serde::Serialize;
use std::path::Path;

/// Everything a sweep produced, ready to write.
pub struct Results<'a> {
    /// The experiment.
    pub spec: &'a Spec,
    /// The sweep's outcome.
    pub outcome: &'a Outcome,
    /// Fig. 2-style pictures, when the experiment has `[figures]`.
    pub pictures: Option<&'a Pictures>,
    /// The device.
    pub adapter: &'a AdapterInfo,
    /// Wall-clock seconds of the sweep.
    pub seconds: f64,
    /// Peak resident memory of the process, if known (bytes).
    pub peak_rss: Option<u64>,
}

/// Writes every output under `out`.
pub fn write_all(r: &Results, out: &Path) -> anyhow::Result<()> {
    let flip = match r.pictures {
        Some(p) => picture_flip(p)?,
        None => Default::default(),
    };
    let summaries = summary::summarise(r.outcome, &flip);
    write_rows(&out.join("runs.csv"), &r.outcome.records)?;
    write_rows(&out.join("summary.csv"), &summaries)?;
    write_ground_truth(r, out)?;
    write_timings(r, out)?;
    write_plots(r, &summaries, &out.join("plots"))?;
    write_images(r, &out.join("images"))?;
    write_atomic(
        &out.join("report.md"),
        report(r.spec, r.outcome, &summaries, r.adapter, r.seconds).as_bytes(),
    )?;
    write_atomic(&out.join("manifest.toml"), manifest(r).as_bytes())
}

/// A row of ground_truth.csv: one reference (lights on, light radius) and its checks.
#[derive(Serialize)]
struct GroundTruthRow {
    lights: u32,
    #[serde(with = "float")]
    light_radius: f64,
    ground_truth_samples: u32,
    #[serde(with = "float")]
    exact_umbra_radius: f64,
    #[serde(with = "float")]
    exact_penumbra_radius: f64,
    #[serde(with = "float")]
    exact_extent_inner: f64,
    #[serde(with = "float")]
    exact_extent_outer: f64,
    #[serde(with = "float")]
    exact_width_10_90: f64,
    #[serde(with = "float")]
    gt_extent_inner: f64,
    #[serde(with = "float")]
    gt_extent_outer: f64,
    #[serde(with = "float")]
    gt_width_10_90: f64,
    #[serde(with = "float")]
    gt_max_abs_error: f64,
    #[serde(with = "float")]
    gt_rmse_penumbra: f64,
    #[serde(with = "float")]
    gt_bias_penumbra: f64,
    penumbra_pixels: usize,
    #[serde(with = "float")]
    exact_max_error_bound: f64,
    exact_depth_limited_pixels: Option<usize>,
}

fn write_ground_truth(r: &Results, out: &Path) -> anyhow::Result<()> {
    let nan2 = (f64::NAN, f64::NAN);
    let rows = r.outcome.references.iter().map(|x| {
        let (ru, rp) = x
            .on_axis
            .as_ref()
            .map_or(nan2, |o| (o.umbra_radius(), o.penumbra_radius()));
        let (ei, eo) = x.exact_profile.as_ref().map_or(nan2, |p| p.extent());
        let (gi, go) = x.gt_profile().map_or(nan2, |p| p.extent());
        GroundTruthRow {
            lights: x.lights,
            light_radius: x.light_radius,
            ground_truth_samples: r.spec.ground_truth.samples,
            exact_umbra_radius: ru,
            exact_penumbra_radius: rp,
            exact_extent_inner: ei,
            exact_extent_outer: eo,
            exact_width_10_90: x.exact_profile.as_ref().map_or(f64::NAN, |p| p.width_10_90()),
            gt_extent_inner: gi,
            gt_extent_outer: go,
            gt_width_10_90: x.gt_profile().map_or(f64::NAN, |p| p.width_10_90()),
            gt_max_abs_error: x.gt_max_abs_all().unwrap_or(f64::NAN),
            gt_rmse_penumbra: x.gt_vs_exact().map_or(f64::NAN, |e| e.rmse),
            gt_bias_penumbra: x.gt_vs_exact().map_or(f64::NAN, |e| e.bias),
            penumbra_pixels: x.mask.pixels.len(),
            exact_max_error_bound: x.exact_quality.map_or(f64::NAN, |q| q.max_error_bound),
            exact_depth_limited_pixels: x.exact_quality.map(|q| q.depth_limited_pixels),
        }
    });
    write_rows(&out.join("ground_truth.csv"), rows)
}

/// A row of timings.csv after its configuration's columns: one timed frame.
#[derive(Serialize)]
struct TimedFrame {
    noise_probe: bool,
    frame: usize,
    #[serde(with = "float")]
    frame_ms: f64,
    #[serde(with = "float")]
    primary_ms: f64,
    clock: String,
}

/// timings.csv: every timed frame, one row each, so the spread behind each median can be seen.
fn write_timings(r: &Results, out: &Path) -> anyhow::Result<()> {
    let t = &r.outcome.timings;
    if t.configs.is_empty() {
        return Ok(());
    }
    let frames = |config: &Config, noise_probe: bool, c: &ConfigTiming| {
        c.frame_seconds
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let frame = TimedFrame {
                    noise_probe,
                    frame: i,
                    frame_ms: s * 1e3,
                    primary_ms: c.primary_seconds.get(i).map_or(f64::NAN, |p| p * 1e3),
                    clock: c.clock.clone(),
                };
                (config.clone(), frame)
            })
            .collect::<Vec<_>>()
    };
    let mut all = Vec::new();
    for g in &r.outcome.groups {
        if let Some(c) = t.configs.get(&g.key) {
            all.extend(frames(&g.config, false, c));
        }
    }
    if let Some((config, c)) = &t.noise {
        all.extend(frames(config, true, c));
    }
    write_rows(&out.join("timings.csv"), all)
}

/// The axes the plots name; each plot is drawn once per value of the others.
const PLOTS_SHOW: [Axis; 4] = [Axis::Scheme, Axis::Pattern, Axis::Samples, Axis::LightRadius];

/// Which summaries a plot shows: its slice's, at one radius or at one ray count.
#[derive(Clone, Copy)]
struct Filter<'a> {
    radius: Option<f64>,
    samples: Option<u32>,
    slice: &'a Slice,
}

/// Series of one metric against a per-summary x, per scheme (per-pixel solid, shared dashed).
fn series(
    summaries: &[Summary],
    f: Filter,
    x: impl Fn(&Summary) -> f64,
    metric: fn(&Aggregated) -> MeanCi,
    scale: f64,
) -> Vec<(usize, Series)> {
    let mut out = Vec::new();
    for (ci, scheme) in DiskScheme::ALL.iter().enumerate() {
        for pattern in Pattern::ALL {
            let mut pts: Vec<(f64, f64, f64)> = summaries
                .iter()
                .filter(|s| s.config.scheme == *scheme && s.config.pattern == pattern)
                .filter(|s| f.slice.holds(&s.config, &PLOTS_SHOW))
                .filter(|s| {
                    f.radius.is_none_or(|r| s.config.light_radius == r)
                        && f.samples.is_none_or(|n| s.config.samples == n)
                })
                .map(|s| {
                    let m = metric(&s.metrics);
                    (x(s), m.mean * scale, m.ci95 * scale)
                })
                .filter(|p| p.1.is_finite())
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            if !pts.is_empty() {
                out.push((
                    ci,
                    Series {
                        name: format!("{scheme} ({pattern})"),
                        points: pts,
                        dashed: pattern == Pattern::Shared,
                    },
                ));
            }
        }
    }
    out
}

fn write_plots(r: &Results, summaries: &[Summary], dir: &Path) -> anyhow::Result<()> {
    for slice in slices(summaries.iter().map(|s| &s.config), &PLOTS_SHOW) {
        let suffix: String = slice.varying.iter().map(|(a, v)| format!("_{v}{}", a.name())).collect();
        plots_for(r, summaries, dir, &slice, &suffix)?;
    }
    Ok(())
}

fn plots_for(r: &Results, summaries: &[Summary], dir: &Path, slice: &Slice, suffix: &str) -> anyhow::Result<()> {
    use plotters::chart::SeriesLabelPosition::{LowerLeft, LowerRight};
    let spec = r.spec;
    let radius = verdict_radius(spec);
    let n = figure_samples(spec);
    let lights = slice.config.lights;
    let at_radius = Filter {
        radius: Some(radius),
        samples: None,
        slice,
    };
    let samples = |s: &Summary| s.config.samples as f64;
    let file = |name: &str| dir.join(format!("{name}{suffix}.png"));
    let title = |what: &str| format!("{what}, light radius {radius} m, {lights} light(s)");
    line_plot(
        &file("rmse_vs_samples"),
        &Axes {
            legend: LowerLeft,
            ..Axes::new(
                &title("RMSE vs ground truth over the penumbra"),
                "shadow rays per pixel",
                "RMSE",
                true,
                true,
            )
        },
        &series(summaries, at_radius, samples, |m| m.rmse, 1.0),
        &[],
    )?;
    line_plot(
        &file("rmse_vs_time"),
        &Axes {
            legend: LowerLeft,
            ..Axes::new(
                &title("What accuracy costs: RMSE vs frame time"),
                "median frame time (ms)",
                "RMSE",
                true,
                true,
            )
        },
        &series(summaries, at_radius, |s| s.frame_ms().1, |m| m.rmse, 1.0),
        &[],
    )?;
    let Some(reference) = r
        .outcome
        .references
        .iter()
        .find(|x| x.light_radius == radius && x.lights == lights)
    else {
        return Ok(());
    };
    let Some(exact) = &reference.exact_profile else {
        return Ok(());
    };
    let (lo, hi) = (
        *spec.axes.samples.iter().min().unwrap_or(&1) as f64,
        *spec.axes.samples.iter().max().unwrap_or(&1) as f64,
    );
    let flat = |name: &str, y: f64| {
        vec![RefLine {
            name: name.into(),
            points: vec![(lo, y * 1e3), (hi, y * 1e3)],
            colour: None,
        }]
    };
    let (a, b) = exact.extent();
    line_plot(
        &file("width_vs_samples"),
        &Axes::new(
            &title("Visible penumbra extent"),
            "shadow rays per pixel",
            "extent width (mm)",
            true,
            false,
        ),
        &series(summaries, at_radius, samples, |m| m.extent_width, 1e3),
        &flat("exact extent", b - a),
    )?;
    line_plot(
        &file("width_10_90_vs_samples"),
        &Axes::new(
            &title("10-90 % width of the mean radial profile"),
            "shadow rays per pixel",
            "10-90 % width (mm)",
            true,
            false,
        ),
        &series(summaries, at_radius, samples, |m| m.width_10_90, 1e3),
        &flat("exact 10-90 %", exact.width_10_90()),
    )?;
    let mut exact_vs_radius: Vec<(f64, f64)> = r
        .outcome
        .references
        .iter()
        .filter(|x| x.lights == lights)
        .filter_map(|x| {
            x.exact_profile
                .as_ref()
                .map(|p| (x.light_radius * 1e3, (p.extent().1 - p.extent().0) * 1e3))
        })
        .collect();
    exact_vs_radius.sort_by(|a, b| a.0.total_cmp(&b.0));
    line_plot(
        &file("width_vs_radius"),
        &Axes::new(
            &format!("Visible penumbra extent at {n} rays"),
            "light radius (mm)",
            "extent width (mm)",
            false,
            false,
        ),
        &series(
            summaries,
            Filter {
                radius: None,
                samples: Some(n),
                slice,
            },
            |s| s.config.light_radius * 1e3,
            |m| m.extent_width,
            1e3,
        ),
        &[RefLine {
            name: "exact".into(),
            points: exact_vs_radius,
            colour: None,
        }],
    )?;
    let mut profiles = Vec::new();
    for (ci, scheme) in DiskScheme::ALL.iter().enumerate() {
        for pattern in Pattern::ALL {
            let config = Config {
                scheme: *scheme,
                pattern,
                samples: n,
                light_radius: radius,
                ..slice.config.clone()
            };
            if let Some((_, p)) = r.outcome.profiles.iter().find(|(c, _)| *c == config) {
                let points = p
                    .radius
                    .iter()
                    .zip(&p.mean)
                    .map(|(x, y)| (x * 1e3, *y, f64::NAN))
                    .collect();
                profiles.push((
                    ci,
                    Series {
                        name: format!("{scheme} ({pattern})"),
                        points,
                        dashed: pattern == Pattern::Shared,
                    },
                ));
            }
        }
    }
    let exact_line = RefLine {
        name: "exact".into(),
        points: exact
            .radius
            .iter()
            .zip(&exact.mean)
            .map(|(x, y)| (x * 1e3, *y))
            .filter(|p| p.1.is_finite())
            .collect(),
        colour: None,
    };
    let x_range = reference.on_axis.as_ref().map(|o| {
        let (ru, rp) = (o.umbra_radius().max(0.0) * 1e3, o.penumbra_radius() * 1e3);
        (ru - 0.4 * (rp - ru), rp + 0.4 * (rp - ru))
    });
    line_plot(
        &file("profiles"),
        &Axes {
            x_range,
            legend: LowerRight,
            ..Axes::new(
                &title(&format!("Radial profile at {n} rays (mean over seeds)")),
                "distance from shadow centre (mm)",
                "visibility",
                false,
                false,
            )
        },
        &profiles,
        &[exact_line],
    )
}

fn write_images(r: &Results, dir: &Path) -> anyhow::Result<()> {
    let spec = r.spec;
    let radius = verdict_radius(spec);
    let n = figure_samples(spec);
    let (w, h) = (spec.measure.width, spec.measure.height);
    let lights = *spec.axes.light_counts.iter().max().expect("validated non-empty");
    if let Some(reference) = r
        .outcome
        .references
        .iter()
        .find(|x| x.light_radius == radius && x.lights == lights)
    {
        let gt = &reference.ground_truth;
        write_exr(&dir.join("ground_truth.exr"), gt, w, h)?;
        let mut tiles: Vec<(String, Rgb)> = Vec::new();
        let mut errors: Vec<(String, Rgb)> = Vec::new();
        for (scheme, pattern) in [
            (DiskScheme::Uniform, Pattern::PerPixel),
            (DiskScheme::Paper, Pattern::PerPixel),
            (DiskScheme::Paper, Pattern::Shared),
            (DiskScheme::Sobol, Pattern::PerPixel),
        ] {
            let kept = r.outcome.keep.iter().find(|(c, _)| {
                c.scheme == scheme && c.pattern == pattern && c.light_radius == radius && c.lights == lights
            });
            if let Some((_, img)) = kept {
                write_exr(&dir.join(format!("{scheme}_{pattern}_{n}.exr")), img, w, h)?;
                tiles.push((format!("{scheme} ({pattern}), {n} rays"), grey(img, w, h)));
                errors.push((
                    format!("{scheme} ({pattern}) - ground truth"),
                    diverging(img, gt, 0.5, w, h),
                ));
            }
        }
        tiles.push((
            format!("ground truth, {} rays", spec.ground_truth.samples),
            grey(gt, w, h),
        ));
        if let Some(exact) = &reference.exact {
            write_exr(&dir.join("exact.exr"), exact, w, h)?;
            tiles.push(("exact".into(), grey(exact, w, h)));
            errors.push(("ground truth - exact (x100)".into(), diverging(gt, exact, 0.005, w, h)));
        }
        let columns = tiles.len().max(errors.len());
        let all: Vec<(String, &Rgb)> = tiles.iter().chain(&errors).map(|(l, i)| (l.clone(), i)).collect();
        image_grid(&dir.join("fig2_measure.png"), &all, columns)?;
    }
    if let Some(p) = r.pictures {
        write_fig2_picture(p, spec.axes.seeds[0], &dir.join("fig2_picture.png"))?;
    }
    Ok(())
}

fn manifest(r: &Results) -> String {
    let s = r.spec;
    let a = r.adapter;
    let hash = |t: &str| format!("{:016x}", crate::fingerprint::fnv1a(t.as_bytes()));
    let experiment_text = std::fs::read_to_string(&s.path).unwrap_or_default();
    let q = |t: &str| format!("{t:?}");
    let list = |v: Vec<String>| format!("[{}]", v.join(", "));
    let mut m = String::from("# Provenance of the results in this folder.\n");
    m += &format!("git_commit = {}\n", q(&crate::output::git_commit()));
    m += &format!(
        "experiment = {}\nexperiment_fnv1a = {}\n",
        q(&s.path.display().to_string()),
        q(&hash(&experiment_text))
    );
    m += &format!(
        "scene = {}\nscene_fnv1a = {}\n",
        q(&s.scene_path.display().to_string()),
        q(&hash(&s.scene_text))
    );
    m += &format!(
        "runs = {}\nfailed_runs = {}\nresumed_groups = {}\nsweep_seconds = {:.1}\n",
        r.outcome.records.len(),
        r.outcome.failures,
        r.outcome.resumed,
        r.seconds
    );
    if let Some(rss) = r.peak_rss {
        m += &format!("peak_rss_bytes = {rss}\n");
    }
    m += &format!(
        "seeds = {}\n",
        list(s.axes.seeds.iter().map(|x| x.to_string()).collect())
    );
    m += &format!(
        "timing_warmup = {}\ntiming_repeats = {}\ntiming_order_seed = {}\n",
        s.timing.warmup,
        s.timing.repeats,
        crate::experiment::sweep::timing::ORDER_SEED
    );
    m += &format!(
        "ground_truth_samples = {}\nground_truth_seed = {}\n",
        s.ground_truth.samples,
        crate::experiment::sweep::reference::GROUND_TRUTH_SEED
    );
    m += &format!(
        "[adapter]\nbackend = {}\nname = {}\ndriver = {}\napi = {}\n",
        q(&a.backend),
        q(&a.name),
        q(&a.driver),
        q(&a.api)
    );
    if let Some(cap) = a.loop_cap {
        m += &format!("loop_iteration_cap = {cap}\n");
    }
    m += &format!("[plan]\nfirst_run = {}\n", q(r.outcome.plan.to_string().trim()));
    m
}
