//! The verdict of a frame-time experiment, computed from its rows: the paper's claim, whether
//! every structure rendered the same frames, speed-ups as medians and quartiles of per-frame
//! ratios with a yes / no / not clearly answer, log-log scaling slopes, what updates cost, and
//! the memory and build time paid.

use super::runner::{FrameRow, FramesOutcome};
use super::spec::{FramesSpec, Generator, ShadingName};
use crate::metrics::stats::{median, quartiles};

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

/// Per frame (scene size, viewpoint, frame) of one shading, the ratio of `b`'s frame time to
/// `a`'s: above 1 where `a` is faster.
fn per_frame_ratios(rows: &[FrameRow], shading: ShadingName, triangles: Option<usize>, a: &str, b: &str) -> Vec<f64> {
    let pick = |l: &str| -> Vec<&FrameRow> {
        rows.iter()
            .filter(|r| r.shading == shading && triangles.is_none_or(|t| r.triangles == t) && label(r) == l)
            .collect()
    };
    let (xs, ys) = (pick(a), pick(b));
    xs.iter()
        .filter_map(|x| {
            let y = ys
                .iter()
                .find(|y| y.triangles == x.triangles && y.viewpoint == x.viewpoint && y.frame == x.frame)?;
            Some(y.seconds / x.seconds)
        })
        .collect()
}

/// "median M (q1-q3), faster on K of N frames" for ratios of `b` over `a`.
fn ratio_summary(r: &[f64]) -> String {
    let (q1, m, q3) = quartiles(r);
    format!(
        "median {m:.2}x (quartiles {q1:.2}-{q3:.2}x), faster on {} of {} frames",
        r.iter().filter(|&&x| x > 1.0).count(),
        r.len()
    )
}

/// A time ratio (theirs / ours) in words: "2.00x faster" or "3.00x slower".
fn faster(ratio: f64) -> String {
    if ratio >= 1.0 {
        format!("{ratio:.2}x faster")
    } else {
        format!("{:.2}x slower", 1.0 / ratio)
    }
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

/// Whether per-frame speed-ups `r` (theirs / VLF-RT's) answer "is VLF-RT faster" with yes (at
/// least three frames in four faster), no (at least three in four slower) or neither.
fn answer(r: &[f64]) -> &'static str {
    let (q1, _, q3) = quartiles(r);
    if q1 > 1.0 {
        "**yes**"
    } else if q3 < 1.0 {
        "**no**"
    } else {
        "**not clearly**"
    }
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
    let differing: Vec<String> = all
        .iter()
        .filter_map(|l| {
            let d: Vec<usize> = rows
                .iter()
                .filter(|r| label(r) == *l)
                .map(|r| r.differing_pixels)
                .collect();
            let (total, frames) = (d.iter().sum::<usize>(), d.iter().filter(|&&x| x > 0).count());
            (total > 0).then(|| {
                format!(
                    "{l}: {total} pixels on {frames} frames (at most {})",
                    d.iter().max().unwrap_or(&0)
                )
            })
        })
        .collect();
    out += &if differing.is_empty() {
        format!(
            "- **Exactness**: every structure's frame equals the first structure's pixel for pixel (object and radiance bits), on all {} frames rendered.\n",
            rows.len()
        )
    } else {
        format!(
            "- **Exactness FAILED**: frames differ from the first structure's ({}). Every structure is exact in f64, so this should be 0: some ray was decided differently.\n",
            differing.join("; ")
        )
    };
    let sizes: Vec<usize> = outcome.builds.iter().map(|b| b.triangles).fold(Vec::new(), |mut v, t| {
        if !v.contains(&t) {
            v.push(t);
        }
        v
    });
    let has = |l: &str| all.iter().any(|x| x == l);
    if spec.motion.is_none() {
        for &(shading, _) in &spec.shadings {
            for (baseline, what) in [
                ("kdtree", "the CRT-like kd-tree (the paper's baseline)"),
                ("bvh", "obvhs' BVH2 (very-slow build)"),
            ] {
                if !has(baseline) || !has("vlf") {
                    continue;
                }
                let r = per_frame_ratios(rows, shading, None, "vlf", baseline);
                out += &format!(
                    "- **Is VLF-RT faster than {what}, {} shading?** {}: speed-up per frame (its time / VLF-RT's) {}.",
                    shading.name(),
                    answer(&r),
                    ratio_summary(&r)
                );
                if sizes.len() > 1 {
                    let per: Vec<String> = sizes
                        .iter()
                        .map(|&t| {
                            let r = per_frame_ratios(rows, shading, Some(t), "vlf", baseline);
                            format!("{}K {:.2}x", t as f64 / 1e3, median(&r))
                        })
                        .collect();
                    out += &format!(" By size: {}.", per.join(", "));
                }
                out += "\n";
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
            if !has("vlf (update)") {
                continue;
            }
            let field = update("vlf (update)");
            for other in all.iter().filter(|l| !l.starts_with("vlf")) {
                let per_frame = |f: &dyn Fn(&FrameRow) -> f64| -> Vec<f64> {
                    let (a, b) = (of(other, f), of("vlf (update)", f));
                    a.iter().zip(&b).map(|(x, y)| x / y).collect()
                };
                let updates = per_frame(&|r| r.update_seconds.unwrap_or(f64::NAN));
                let totals = per_frame(&|r| r.seconds + r.update_seconds.unwrap_or(0.0));
                out += &format!(
                    "- **Is VLF-RT's update cheaper than {other}'s?** {}: {} to update (median of per-frame ratios {:.3}x); update + render: {} ({:.3}x).\n",
                    answer(&updates),
                    faster(median(&updates)),
                    median(&updates),
                    faster(median(&totals)),
                    median(&totals)
                );
            }
            if let Some(b) = outcome.builds.iter().find(|b| b.structure == "vlf") {
                out += &format!(
                    "- **VLF-RT's update vs building the field**: {:.4} s against {:.2} s ({}).\n",
                    field,
                    b.build_seconds,
                    faster(b.build_seconds / field)
                );
            }
        }
    }
    let cost: Vec<String> = outcome
        .builds
        .iter()
        .map(|b| {
            format!(
                "{} at {}K: {:.1} MB, {:.2} s",
                b.structure,
                b.triangles as f64 / 1e3,
                b.memory_bytes as f64 / 1e6,
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
