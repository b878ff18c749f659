//! The sweep's plots: RMSE and extent widths against rays and frame time, the error's power
//! spectrum per scheme at the figure ray count, radial profiles at that count against the exact
//! profile, and extent width against light radius.

use super::results::Results;
use super::summary::{swept_schemes, Summary};
use crate::experiment::sweep::axes::{slices, Axis, Config, Slice};
use crate::experiment::sweep::record::{Aggregated, Status};
use crate::experiment::sweep::runner::{figure_samples, verdict_radius};
use crate::metrics::spectrum::BIN;
use crate::metrics::stats::{mean_ci, MeanCi};
use crate::output::plots::{line_plot, Axes, Reference as RefLine, Series};
use crate::sampling::Pattern;
use std::path::Path;

/// The axes the plots name; each plot is drawn once per value of the others.
const PLOT_NAMES: [Axis; 4] = [Axis::Scheme, Axis::Pattern, Axis::Samples, Axis::LightRadius];

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
    for (ci, scheme) in swept_schemes(summaries).iter().enumerate() {
        for pattern in Pattern::ALL {
            let mut pts: Vec<(f64, f64, f64)> = summaries
                .iter()
                .filter(|s| s.config.scheme == *scheme && s.config.pattern == pattern)
                .filter(|s| f.slice.holds(&s.config, &PLOT_NAMES))
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

/// Writes every plot into `dir`, one set per slice of the axes the plots do not name.
pub fn write_plots(r: &Results, summaries: &[Summary], dir: &Path) -> anyhow::Result<()> {
    for slice in slices(summaries.iter().map(|s| &s.config), &PLOT_NAMES) {
        let suffix: String = slice.varying.iter().map(|(a, v)| format!("_{v}{}", a.name())).collect();
        plots_for(r, summaries, dir, &slice, &suffix)?;
    }
    Ok(())
}

fn plots_for(r: &Results, summaries: &[Summary], dir: &Path, slice: &Slice, suffix: &str) -> anyhow::Result<()> {
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
        &Axes::new(
            &title("RMSE vs ground truth over the penumbra"),
            "shadow rays per pixel",
            "RMSE",
            true,
            true,
        ),
        &series(summaries, at_radius, samples, |m| m.rmse, 1.0),
        &[],
    )?;
    line_plot(
        &file("rmse_vs_time"),
        &Axes::new(
            &title("What accuracy costs: RMSE vs frame time"),
            "median frame time (ms)",
            "RMSE",
            true,
            true,
        ),
        &series(summaries, at_radius, |s| s.frame.median * 1e3, |m| m.rmse, 1.0),
        &[],
    )?;
    line_plot(
        &file("error_spectrum"),
        &Axes::new(
            &title(&format!(
                "Where the error goes at {n} rays, per-pixel (mean over seeds)"
            )),
            "frequency (cycles per pixel)",
            "error power per ring",
            false,
            true,
        ),
        &spectra(r, slice, n, radius),
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
    for (ci, scheme) in swept_schemes(summaries).iter().enumerate() {
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

/// The mean radial power spectrum of the error over seeds, per scheme with the per-pixel pattern
/// at `n` rays and light radius `radius`, each ring with its 95 % CI.
fn spectra(r: &Results, slice: &Slice, n: u32, radius: f64) -> Vec<(usize, Series)> {
    let mut out = Vec::new();
    for (ci, scheme) in r.spec.axes.schemes.iter().enumerate() {
        let config = Config {
            scheme: *scheme,
            pattern: Pattern::PerPixel,
            samples: n,
            light_radius: radius,
            ..slice.config.clone()
        };
        let rings: Vec<Vec<f64>> = r
            .outcome
            .records
            .iter()
            .filter(|x| x.status == Status::Ok && x.run.config() == config)
            .map(|x| x.spectrum.rings())
            .collect();
        let Some(first) = rings.first() else {
            continue;
        };
        let points = (0..first.len())
            .map(|k| {
                let m = mean_ci(&rings.iter().map(|x| x[k]).collect::<Vec<_>>());
                ((k as f64 + 0.5) * BIN, m.mean, m.ci95)
            })
            .filter(|p| p.1.is_finite())
            .collect();
        out.push((
            ci,
            Series {
                name: scheme.to_string(),
                points,
                dashed: false,
            },
        ));
    }
    out
}
