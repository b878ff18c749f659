//! The sweep's plots: RMSE and extent widths against rays and frame time, the error's power
//! spectrum per scheme at the figure ray count, radial profiles at that count against the exact
//! profile, and extent width against light radius. A plot over both patterns is drawn as two
//! panels side by side on shared axes, one per pattern, so that no panel holds more than one
//! line per scheme; a scheme has one look (colour, marker, dashes) in every plot.

use super::results::Results;
use super::summary::{swept_schemes, Summary};
use crate::experiment::sweep::axes::{slices, Axis, Config, Slice};
use crate::experiment::sweep::record::{Aggregated, Status};
use crate::metrics::spectrum::BIN;
use crate::metrics::stats::{mean_ci, MeanCi};
pub use crate::output::plots::scheme_look;
use crate::output::plots::{line_panels, line_plot, Axes, Panel, Point, Reference as RefLine, Series};
use crate::sampling::{DiskScheme, Pattern};
use std::path::Path;

/// The axes the plots name; each plot is drawn once per value of the others.
const PLOT_NAMES: [Axis; 4] = [Axis::Scheme, Axis::Pattern, Axis::Samples, Axis::LightRadius];

/// Which summaries a plot shows: its slice's, at one radius or at one ray count.
#[derive(Clone, Copy)]
struct Filter<'a> {
    radius: Option<f64>,
    samples: Option<u32>,
    slice: &'a Slice,
    /// The experiment's schemes, which give each its look ([`scheme_look`]).
    schemes: &'a [DiskScheme],
}

/// One panel per pattern swept (its series: one per scheme) of one metric against a per-summary
/// x.
fn panels(
    summaries: &[Summary],
    f: Filter,
    x: impl Fn(&Summary) -> f64,
    metric: fn(&Aggregated) -> MeanCi,
    scale: f64,
) -> Vec<Panel> {
    let mut out = Vec::new();
    for pattern in Pattern::ALL {
        let mut series = Vec::new();
        for scheme in &swept_schemes(summaries) {
            let mut pts: Vec<Point> = summaries
                .iter()
                .filter(|s| s.config.scheme == *scheme && s.config.pattern == pattern)
                .filter(|s| f.slice.holds(&s.config, &PLOT_NAMES))
                .filter(|s| {
                    f.radius.is_none_or(|r| s.config.light_radius == r)
                        && f.samples.is_none_or(|n| s.config.samples == n)
                })
                .map(|s| {
                    let m = metric(&s.metrics);
                    Point::ci(x(s), m.mean * scale, m.ci95 * scale)
                })
                .filter(|p| p.y.is_finite())
                .collect();
            pts.sort_by(|a, b| a.x.total_cmp(&b.x));
            if !pts.is_empty() {
                series.push(Series {
                    name: scheme.to_string(),
                    look: scheme_look(*scheme, f.schemes),
                    points: pts,
                });
            }
        }
        if !series.is_empty() {
            out.push(Panel {
                title: format!("{pattern} pattern"),
                series,
            });
        }
    }
    out
}

/// The file name suffix of a slice: `_AXIS-VALUE` per axis that tells the slices apart, in axis
/// order (`_lights-1_accelerator-bvh`), any character of a value outside letters, digits, `.`
/// and `-` written `-`.
fn suffix(slice: &Slice) -> String {
    slice
        .varying
        .iter()
        .map(|(a, v)| {
            let v: String = v
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                        c
                    } else {
                        '-'
                    }
                })
                .collect();
            format!("_{}-{v}", a.name())
        })
        .collect()
}

/// Writes every plot into `dir`, one set per slice of the axes the plots do not name.
pub fn write_plots(r: &Results, summaries: &[Summary], dir: &Path) -> anyhow::Result<()> {
    for slice in slices(summaries.iter().map(|s| &s.config), &PLOT_NAMES) {
        plots_for(r, summaries, dir, &slice, &suffix(&slice))?;
    }
    Ok(())
}

fn plots_for(r: &Results, summaries: &[Summary], dir: &Path, slice: &Slice, suffix: &str) -> anyhow::Result<()> {
    let spec = r.spec;
    let radius = spec.verdict_radius();
    let n = spec.figure_samples();
    let lights = slice.config.lights;
    let schemes = &spec.axes.schemes;
    let at_radius = Filter {
        radius: Some(radius),
        samples: None,
        slice,
        schemes,
    };
    let samples = |s: &Summary| s.config.samples as f64;
    let file = |name: &str| dir.join(format!("{name}{suffix}.png"));
    let others = match slice.label(&[Axis::Lights]) {
        l if l.is_empty() => l,
        l => format!(", {l}"),
    };
    let title = |what: &str| format!("{what}, light radius {radius} m, {lights} light(s){others}");
    line_panels(
        &file("rmse_vs_samples"),
        &Axes::new(
            &title("RMSE vs ground truth over the penumbra"),
            "shadow rays per pixel",
            "RMSE",
            true,
            true,
        ),
        &panels(summaries, at_radius, samples, |m| m.rmse, 1.0),
        &[],
    )?;
    line_panels(
        &file("rmse_vs_time"),
        &Axes::new(
            &title("What accuracy costs: RMSE vs frame time"),
            "median frame time (ms)",
            "RMSE",
            true,
            true,
        ),
        &panels(summaries, at_radius, |s| s.frame.median * 1e3, |m| m.rmse, 1.0),
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
    line_panels(
        &file("width_vs_samples"),
        &Axes::new(
            &title("Visible penumbra extent"),
            "shadow rays per pixel",
            "extent width (mm)",
            true,
            false,
        ),
        &panels(summaries, at_radius, samples, |m| m.extent_width, 1e3),
        &flat("exact extent", b - a),
    )?;
    line_panels(
        &file("width_10_90_vs_samples"),
        &Axes::new(
            &title("10-90 % width of the mean radial profile"),
            "shadow rays per pixel",
            "10-90 % width (mm)",
            true,
            false,
        ),
        &panels(summaries, at_radius, samples, |m| m.width_10_90, 1e3),
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
    line_panels(
        &file("width_vs_radius"),
        &Axes::new(
            &format!("Visible penumbra extent at {n} rays, {lights} light(s){others}"),
            "light radius (mm)",
            "extent width (mm)",
            false,
            false,
        ),
        &panels(
            summaries,
            Filter {
                radius: None,
                samples: Some(n),
                slice,
                schemes,
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
    for pattern in Pattern::ALL {
        let mut series = Vec::new();
        for scheme in &swept_schemes(summaries) {
            let config = Config {
                scheme: *scheme,
                pattern,
                samples: n,
                light_radius: radius,
                ..slice.config.clone()
            };
            if let Some((_, p)) = r.outcome.profiles.iter().find(|(c, _)| *c == config) {
                series.push(Series {
                    name: scheme.to_string(),
                    look: scheme_look(*scheme, schemes),
                    points: p
                        .radius
                        .iter()
                        .zip(&p.mean)
                        .map(|(x, y)| Point::bare(x * 1e3, *y))
                        .collect(),
                });
            }
        }
        if !series.is_empty() {
            profiles.push(Panel {
                title: format!("{pattern} pattern"),
                series,
            });
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
    line_panels(
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
fn spectra(r: &Results, slice: &Slice, n: u32, radius: f64) -> Vec<Series> {
    let mut out = Vec::new();
    let schemes = &r.spec.axes.schemes;
    for scheme in schemes {
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
                Point::ci((k as f64 + 0.5) * BIN, m.mean, m.ci95)
            })
            .filter(|p| p.y.is_finite())
            .collect();
        out.push(Series {
            name: scheme.to_string(),
            look: scheme_look(*scheme, schemes),
            points,
        });
    }
    out
}
