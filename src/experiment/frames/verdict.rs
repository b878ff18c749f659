//! The verdict of a frame-time experiment, computed from its rows: the paper's claim, whether
//! every structure rendered the same frames, speed-ups as the median of per-frame ratios with a
//! 95 % moving-block interval over frames (consecutive frames are correlated) and the one rule's
//! yes / no / undecided, the work behind each time, log-log scaling slopes, what updates cost,
//! and the memory and build time paid.

use super::runner::{FrameRow, FramesOutcome};
use super::spec::{Cameras, FramesSpec, Generator, ShadingName};
use crate::metrics::stats::median;
use crate::timing::{median_interval, series_median, Comparison, Estimate};

/// A structure and the way it follows motion, as rows and plots label it.
pub fn label(r: &FrameRow) -> String {
    match r.update {
        "none" => r.structure.to_string(),
        u => format!("{} ({u})", r.structure),
    }
}

/// The distinct labels of `rows`, in first-seen order.
pub fn labels(rows: &[FrameRow]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for r in rows {
        let l = label(r);
        if !out.contains(&l) {
            out.push(l);
        }
    }
    out
}

/// A scene size and viewpoint: where frame times are comparable, so a claim is asked of each
/// apart (times trend with size and differ between viewpoints).
pub type Cell<'a> = (usize, &'a str);

/// Per frame (scene size, viewpoint, frame, in path order) of one shading, within `cell` where
/// one is given, the ratio `value(b) / value(a)`: above 1 where `a` is faster.
pub fn per_frame_ratios(
    rows: &[FrameRow],
    shading: ShadingName,
    cell: Option<Cell>,
    (a, b): (&str, &str),
    value: &dyn Fn(&FrameRow) -> f64,
) -> Vec<f64> {
    let pick = |l: &str| -> Vec<&FrameRow> {
        rows.iter()
            .filter(|r| {
                r.shading == shading && cell.is_none_or(|(t, v)| r.triangles == t && r.viewpoint == v) && label(r) == l
            })
            .collect()
    };
    let (xs, ys) = (pick(a), pick(b));
    xs.iter()
        .filter_map(|x| {
            let y = ys
                .iter()
                .find(|y| y.triangles == x.triangles && y.viewpoint == x.viewpoint && y.frame == x.frame)?;
            Some(value(y) / value(x))
        })
        .collect()
}

/// The median of per-frame values with its 95 % interval, and the block length behind it: over
/// independent random cameras the exact order-statistic interval (blocks of one frame); along a
/// path, where consecutive frames are correlated, the moving-block interval of
/// [`series_median`].
pub fn over_frames(values: &[f64], cameras: Cameras) -> (Estimate, usize) {
    match cameras {
        // Below six values the order statistics' widest interval covers less than 95 %.
        Cameras::Random { .. } if values.len() < 6 => (
            Estimate {
                median: median(values),
                ..Estimate::NAN
            },
            1,
        ),
        Cameras::Random { .. } => (median_interval(values), 1),
        Cameras::Path => series_median(values),
    }
}

/// A speed-up over frames: the median of per-frame ratios (theirs / ours) with its 95 %
/// interval ([`over_frames`]), and the rule's word for "ours is faster".
pub struct Speedup {
    /// The median ratio and its interval.
    pub estimate: Estimate,
    block: usize,
    faster_frames: usize,
    frames: usize,
}

impl Speedup {
    /// The speed-up of per-frame `ratios` drawn as `cameras` draws frames.
    pub fn of(ratios: &[f64], cameras: Cameras) -> Speedup {
        let (estimate, block) = over_frames(ratios, cameras);
        Speedup {
            estimate,
            block,
            faster_frames: ratios.iter().filter(|&&x| x > 1.0).count(),
            frames: ratios.len(),
        }
    }

    /// The rule's word for "ours is faster".
    pub fn comparison(&self) -> Comparison {
        Comparison::of_speedup(&self.estimate)
    }

    /// "1.14x [1.07, 1.23] (95 % interval over frames in blocks of 8), faster on 384 of 420
    /// frames".
    fn summary(&self) -> String {
        let over = if self.block == 1 {
            "95 % interval over independent frames".to_string()
        } else {
            format!("95 % interval over frames in blocks of {}", self.block)
        };
        format!(
            "{}x ({over}), faster on {} of {} frames",
            self.estimate.show_speedup(2),
            self.faster_frames,
            self.frames
        )
    }
}

/// A claim answered in each scene size and viewpoint apart: "**yes** in 8 and **undecided** in
/// 2 of 10 sizes and viewpoints ...: 1K outside **no** 0.81x [0.75, 0.88] (2 of 12 frames
/// faster); ...".
fn by_cell(per: &[(Cell, Speedup)]) -> String {
    let count = |c: Comparison| per.iter().filter(|(_, s)| s.comparison() == c).count();
    let mut tally: Vec<String> = Comparison::ALL
        .into_iter()
        .filter(|&c| count(c) > 0)
        .map(|c| format!("**{}** in {}", c.answer(), count(c)))
        .collect();
    let last = tally.pop().unwrap_or_default();
    let tally = if tally.is_empty() {
        last
    } else {
        format!("{} and {last}", tally.join(", "))
    };
    let listed: Vec<String> = per
        .iter()
        .map(|((t, v), s)| {
            format!(
                "{}K {v} **{}** {}x ({} of {} frames faster)",
                *t as f64 / 1e3,
                s.comparison().answer(),
                s.estimate.show_speedup(2),
                s.faster_frames,
                s.frames
            )
        })
        .collect();
    let over = match per.first() {
        Some((_, s)) if s.block > 1 => format!("95 % intervals over frames in blocks of {}", s.block),
        _ => "95 % intervals over independent frames".to_string(),
    };
    format!(
        "{tally} of {} sizes and viewpoints, each asked apart (speed-up per frame, its time / ours, {over}): {}",
        per.len(),
        listed.join("; ")
    )
}

/// Least-squares slope of log y against log x: the exponent a of y ~ x^a; None with fewer than
/// two points or any non-positive value (no logarithm: a structure that stores nothing).
pub fn log_log_slope(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 2 || points.iter().any(|&(x, y)| !(x > 0.0 && y > 0.0)) {
        return None;
    }
    let n = points.len() as f64;
    let (xs, ys): (Vec<f64>, Vec<f64>) = points.iter().map(|(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Median frame seconds of `label` at `triangles` under `shading`, over every frame and viewpoint.
pub fn median_at(rows: &[FrameRow], shading: ShadingName, l: &str, triangles: usize) -> Option<f64> {
    let v: Vec<f64> = rows
        .iter()
        .filter(|r| r.shading == shading && r.triangles == triangles && label(r) == l)
        .map(|r| r.seconds)
        .collect();
    (!v.is_empty()).then(|| median(&v))
}

/// What the paper claims for this experiment's set-up (its Fig. 5 and 6 survive as curves only).
fn paper_claim(spec: &FramesSpec) -> &'static str {
    match (&spec.generator, &spec.motion) {
        (_, Some(_)) => "The paper (Section 8) describes the field's update (remove the object's ids from every subfield, move it, insert it again) and times none; the question here is what it costs against rebuilding or refitting a BVH.",
        (Generator::Classroom, None) => "The paper (Fig. 6, curves only, no numbers in the text): VLF-RT walks through its 51K-polygon classroom faster than CRT, with OpenGL-like and with Whitted shading.",
        (Generator::RandomTriangles { .. }, None) => "The paper (Fig. 5, curves only, no numbers in the text): on uniformly distributed random triangles VLF-RT's frame time grows with scene size and stays below CRT's.",
    }
}

/// The verdict on the paper's frame-time claims, from the rows.
pub fn verdict(spec: &FramesSpec, outcome: &FramesOutcome) -> String {
    let rows = &outcome.frames;
    let mut out = format!("{}\n\n", paper_claim(spec));
    let all = labels(rows);
    // Per structure label: (exact, "LABEL: N pixels on F frames (at most M)") where any differ.
    let differing: Vec<(bool, String)> = all
        .iter()
        .filter_map(|l| {
            let mine: Vec<&FrameRow> = rows.iter().filter(|r| label(r) == *l).collect();
            let d: Vec<usize> = mine.iter().map(|r| r.differing_pixels).collect();
            let (total, frames) = (d.iter().sum::<usize>(), d.iter().filter(|&&x| x > 0).count());
            let exact = crate::accel::is_exact(mine[0].structure);
            (total > 0).then(|| {
                (
                    exact,
                    format!(
                        "{l}: {total} pixels on {frames} frames (at most {})",
                        d.iter().max().unwrap_or(&0)
                    ),
                )
            })
        })
        .collect();
    let (failed, inexact): (Vec<_>, Vec<_>) = differing.into_iter().partition(|(exact, _)| *exact);
    // "exact" qualifies the words only where an inexact structure is among the rows.
    let exact = if rows.iter().any(|r| !crate::accel::is_exact(r.structure)) {
        "exact "
    } else {
        ""
    };
    let listed = |v: Vec<(bool, String)>| v.into_iter().map(|(_, s)| s).collect::<Vec<_>>().join("; ");
    out += &if failed.is_empty() {
        format!(
            "- **Exactness**: every {exact}structure's frame equals the first {exact}structure's pixel for pixel (object and radiance bits), on all {} frames rendered.\n",
            rows.len()
        )
    } else {
        format!(
            "- **Exactness FAILED**: frames differ from the first {exact}structure's ({}). Every {exact}structure runs one exact triangle test (in f64 on the CPU, the same f32 test on the GPU), so this should be 0: some ray was decided differently.\n",
            listed(failed)
        )
    };
    if !inexact.is_empty() {
        out += &format!(
            "- **Inexact structures** (their own f32 triangle tests: a ray that grazes an edge, or leaves a surface within f32 rounding of a neighbouring triangle, may be decided otherwise): frames differ from the first exact structure's ({}).\n",
            listed(inexact)
        );
    }
    let sizes: Vec<usize> = outcome.builds.iter().map(|b| b.triangles).fold(Vec::new(), |mut v, t| {
        if !v.contains(&t) {
            v.push(t);
        }
        v
    });
    let cells: Vec<Cell> = sizes
        .iter()
        .flat_map(|&t| spec.viewpoints.iter().map(move |v| (t, v.as_str())))
        .filter(|&(t, v)| rows.iter().any(|r| r.triangles == t && r.viewpoint == v))
        .collect();
    let subject = spec.claim.subject.as_str();
    let work = |l: &str, shading: ShadingName| {
        let counted = rows
            .iter()
            .find(|r| label(r) == l)
            .is_none_or(|r| crate::accel::counts_work(r.structure));
        if !counted {
            return "no work counters".to_string();
        }
        let of = |f: fn(&FrameRow) -> u64| {
            median(
                &rows
                    .iter()
                    .filter(|r| r.shading == shading && label(r) == l)
                    .map(|r| f(r) as f64)
                    .collect::<Vec<_>>(),
            )
        };
        format!(
            "{:.3e} nodes, {:.3e} tests per frame",
            of(|r| r.work.nodes),
            of(|r| r.work.primitives)
        )
    };
    if spec.motion.is_none() {
        for &(shading, _) in &spec.shadings {
            for other in all.iter().filter(|l| l.as_str() != subject) {
                let r = per_frame_ratios(rows, shading, None, (subject, other), &|r| r.seconds);
                if r.is_empty() {
                    continue;
                }
                let role = if *other == spec.claim.baseline {
                    " (the paper's baseline)"
                } else {
                    ""
                };
                let answer = if cells.len() > 1 {
                    // Frame times trend with size and differ between viewpoints: each cell is
                    // asked apart, never pooled.
                    let per: Vec<(Cell, Speedup)> = cells
                        .iter()
                        .map(|&c| {
                            let r = per_frame_ratios(rows, shading, Some(c), (subject, other), &|r| r.seconds);
                            (c, Speedup::of(&r, spec.cameras))
                        })
                        .collect();
                    by_cell(&per)
                } else {
                    let sp = Speedup::of(&r, spec.cameras);
                    format!(
                        "**{}**: speed-up per frame (its time / `{subject}`'s) {}",
                        sp.comparison().answer(),
                        sp.summary()
                    )
                };
                out += &format!(
                    "- **Is `{subject}` faster than `{other}`{role}, {} shading?** {answer}. Work: `{subject}` {}; `{other}` {}.\n",
                    shading.name(),
                    work(subject, shading),
                    work(other, shading),
                );
            }
            if sizes.len() > 1 {
                let slopes: Vec<String> = all
                    .iter()
                    .filter_map(|l| {
                        let pts: Vec<(f64, f64)> = sizes
                            .iter()
                            .filter_map(|&t| Some((t as f64, median_at(rows, shading, l, t)?)))
                            .collect();
                        Some(format!("{l} N^{:.2}", log_log_slope(&pts)?))
                    })
                    .collect();
                out += &format!(
                    "- **Scaling, {} shading**: median frame time grows as {} (least-squares log-log slope over {} sizes, {}K-{}K triangles).\n",
                    shading.name(),
                    slopes.join(", "),
                    sizes.len(),
                    sizes[0] as f64 / 1e3,
                    sizes[sizes.len() - 1] as f64 / 1e3
                );
            }
        }
    } else {
        // The subject's own update: the first way it offers.
        let own = all.iter().find(|l| l.starts_with(subject)).cloned();
        for &(shading, _) in &spec.shadings {
            let of = |l: &str, f: &dyn Fn(&FrameRow) -> f64| -> Vec<f64> {
                rows.iter()
                    .filter(|r| r.shading == shading && label(r) == l)
                    .map(f)
                    .collect()
            };
            let update = |l: &str| median(&of(l, &|r| r.update_seconds.unwrap_or(f64::NAN)));
            let total = |l: &str| median(&of(l, &|r| r.seconds + r.update_seconds.unwrap_or(0.0)));
            let listed: Vec<String> = all
                .iter()
                .map(|l| format!("{l} {:.4} s update, {:.4} s update + render", update(l), total(l)))
                .collect();
            out += &format!(
                "- **Per moving frame, {} shading (medians)**: {}.\n",
                shading.name(),
                listed.join("; ")
            );
            let Some(own) = &own else { continue };
            let field = update(own);
            for other in all.iter().filter(|l| *l != own) {
                let updates = Speedup::of(
                    &per_frame_ratios(rows, shading, None, (own, other), &|r| {
                        r.update_seconds.unwrap_or(f64::NAN)
                    }),
                    spec.cameras,
                );
                let totals = Speedup::of(
                    &per_frame_ratios(rows, shading, None, (own, other), &|r| {
                        r.seconds + r.update_seconds.unwrap_or(0.0)
                    }),
                    spec.cameras,
                );
                out += &format!(
                    "- **Is `{own}` cheaper than `{other}`?** To update: **{}**, speed-up per frame (its time / `{own}`'s) {}. Update + render: **{}**, {}.\n",
                    updates.comparison().answer(),
                    updates.summary(),
                    totals.comparison().answer(),
                    totals.summary(),
                );
            }
            if let Some(b) = outcome.builds.iter().find(|b| b.structure == subject) {
                out += &format!(
                    "- **`{own}` vs building `{subject}` again**: a median {:.4} s per update against one {:.2} s build (a ratio of {:.1}; the build is timed once).\n",
                    field,
                    b.build_seconds,
                    b.build_seconds / field
                );
            }
        }
    }
    let cost: Vec<String> = outcome
        .builds
        .iter()
        .map(|b| {
            format!(
                "{} at {}K: {:.1} MB ({} B per triangle), {:.2} s",
                b.structure,
                b.triangles as f64 / 1e3,
                b.memory_bytes as f64 / 1e6,
                crate::output::numbers::per_triangle(b.memory_bytes, b.triangles),
                b.build_seconds
            )
        })
        .collect();
    if !cost.is_empty() {
        out += &format!("- **Memory and build time**: {}.\n", cost.join("; "));
    }
    if sizes.len() > 1 {
        let slopes: Vec<String> = spec
            .structures
            .iter()
            .filter_map(|s| {
                let pts: Vec<(f64, f64)> = outcome
                    .builds
                    .iter()
                    .filter(|b| b.structure == s.name)
                    .map(|b| (b.triangles as f64, b.memory_bytes as f64))
                    .collect();
                Some(format!("{} N^{:.2}", s.name, log_log_slope(&pts)?))
            })
            .collect();
        out += &format!("- **Memory grows as** {}.\n", slopes.join(", "));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_log_slope_recovers_a_power_law() {
        let pts: Vec<(f64, f64)> = [1e3, 4e3, 16e3, 256e3]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(0.37)))
            .collect();
        assert!((log_log_slope(&pts).unwrap() - 0.37).abs() < 1e-12);
        assert_eq!(log_log_slope(&pts[..1]), None);
        assert_eq!(log_log_slope(&[(2.0, 1.0), (2.0, 5.0)]), None);
        assert_eq!(
            log_log_slope(&[(1e3, 0.0), (1e4, 0.0)]),
            None,
            "brute force stores nothing"
        );
    }
}
