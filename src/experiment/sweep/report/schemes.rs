//! Which scheme to use at few rays: every swept scheme ranked at the figure ray count by the error a viewer sees (FLIP), the error a simple denoiser leaves (blurred
//! RMSE), where the error sits in frequency (low-frequency share) and plain RMSE, with each
//! scheme's penumbra width against the exact one.
//!
//! A scheme is named best by a metric when its mean is the lowest; it is "clearly" best when its
//! 95 % interval over seeds lies below every other scheme's, and otherwise the schemes whose
//! intervals overlap its are named with it.

use super::summary::{find, swept_schemes, Summary};
use crate::experiment::sweep::axes::{Config, Slice};
use crate::metrics::stats::MeanCi;
use crate::output::numbers::with_ci;
use crate::sampling::{DiskScheme, Pattern};

/// A metric the schemes are ranked by (lower is better).
struct Metric {
    /// What it is called in the report.
    label: &'static str,
    /// Its value for a configuration.
    value: fn(&Summary) -> MeanCi,
    /// Its number format.
    show: fn(f64) -> String,
}

const METRICS: [Metric; 4] = [
    Metric {
        label: "perceptual error (FLIP of the Fig. 2 picture)",
        value: |s| s.flip,
        show: |x| format!("{x:.4}"),
    },
    Metric {
        label: "error left after a 1-pixel Gaussian blur (RMSE over the penumbra)",
        value: |s| s.metrics.rmse_blurred,
        show: |x| format!("{x:.4}"),
    },
    Metric {
        label: "low-frequency share of the error's power (below 0.125 cycles per pixel; white noise 0.0625)",
        value: |s| s.metrics.lowfreq_share,
        show: |x| format!("{x:.3}"),
    },
    Metric {
        label: "RMSE over the penumbra",
        value: |s| s.metrics.rmse,
        show: |x| format!("{x:.4}"),
    },
];

/// The schemes ranked by one metric: (scheme, value), lowest mean first, measured ones only.
fn ranked(rows: &[(DiskScheme, &Summary)], value: fn(&Summary) -> MeanCi) -> Vec<(DiskScheme, MeanCi)> {
    let mut out: Vec<(DiskScheme, MeanCi)> = rows
        .iter()
        .map(|(s, x)| (*s, value(x)))
        .filter(|(_, m)| m.mean.is_finite())
        .collect();
    out.sort_by(|a, b| a.1.mean.total_cmp(&b.1.mean));
    out
}

/// Whether `a`'s interval lies wholly below `b`'s.
fn clearly_below(a: MeanCi, b: MeanCi) -> bool {
    a.ci95.is_finite() && b.ci95.is_finite() && a.mean + a.ci95 < b.mean - b.ci95
}

/// "n-th of m": an ordinal.
fn ordinal(k: usize) -> String {
    let suffix = match (k % 10, k % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{k}{suffix}")
}

/// One sentence per metric ([`sentence`]).
fn rank_sentences(rows: &[(DiskScheme, &Summary)], subject: DiskScheme) -> String {
    METRICS
        .iter()
        .map(|m| sentence(m, &ranked(rows, m.value), subject))
        .collect()
}

/// The best scheme by `m` in `r` (ranked, lowest first) with its interval, the schemes tied
/// with it, and the rank of `subject` (the verdict's: the paper's pattern by default).
fn sentence(m: &Metric, r: &[(DiskScheme, MeanCi)], subject: DiskScheme) -> String {
    let Some(&(best, b)) = r.first() else {
        return format!("- *Least {}:* not measured here.\n", m.label);
    };
    let tied: Vec<String> = r[1..]
        .iter()
        .filter(|(_, x)| !clearly_below(b, *x))
        .map(|(name, _)| name.to_string())
        .collect();
    let call = if r.len() < 2 {
        "the only scheme measured by it here, so none is called best".to_string()
    } else if !b.ci95.is_finite() {
        "no interval (fewer than four seeds), so no scheme is called best".to_string()
    } else if tied.is_empty() {
        "below every other scheme, 95 % intervals disjoint".to_string()
    } else {
        format!("tied within the intervals with {}", tied.join(", "))
    };
    let rank = match r.iter().position(|(name, _)| *name == subject) {
        Some(k) => {
            let p = r[k].1;
            let better = r.iter().filter(|(_, x)| clearly_below(*x, p)).count();
            let who = match subject {
                DiskScheme::Paper => "The paper's pattern".to_string(),
                s => format!("`{s}`"),
            };
            format!(
                " {who} ranks {} of {} ({}, {better} scheme(s) clearly below it).",
                ordinal(k + 1),
                r.len(),
                with_ci(p.mean, p.ci95, m.show)
            )
        }
        None => String::new(),
    };
    format!(
        "- *Least {}:* **{best}**, {}; {call}.{rank}\n",
        m.label,
        with_ci(b.mean, b.ci95, m.show)
    )
}

/// A width against the exact one, as a signed percentage with its interval.
fn against_exact(x: MeanCi, exact: f64) -> String {
    with_ci(100.0 * (x.mean / exact - 1.0), 100.0 * x.ci95 / exact, |d| {
        format!("{d:+.1} %")
    })
}

/// The per-pixel configuration of `scheme` at `samples` rays in the slice.
fn config(slice: &Slice, scheme: DiskScheme, samples: u32, radius: f64) -> Config {
    Config {
        scheme,
        pattern: Pattern::PerPixel,
        samples,
        light_radius: radius,
        ..slice.config.clone()
    }
}

/// The section: every scheme at `n` rays (equal time is [`super::equal_time`]'s).
pub fn scheme_section(summaries: &[Summary], slice: &Slice, n: u32, radius: f64, subject: DiskScheme) -> String {
    let at_n: Vec<(DiskScheme, &Summary)> = swept_schemes(summaries)
        .iter()
        .filter_map(|&s| find(summaries, &config(slice, s, n, radius)).map(|x| (s, x)))
        .collect();
    if at_n.len() < 2 {
        return String::new();
    }
    let label = match slice.label(&[]) {
        l if l.is_empty() => l,
        l => format!(" ({l})"),
    };
    let mut s = format!(
        "\n## Which scheme at {n} rays{label}\n\nPer-pixel pattern, light radius {radius} m, means over seeds with 95 % intervals. Blurred error: the error against the ground truth blurred by a Gaussian of 1 pixel (what a denoiser that averages neighbours leaves), RMSE over the penumbra. Low-frequency share: the power of the error's spectrum below 0.125 cycles per pixel over all of it up to 0.5 (receiver pixels, Hann window, its mean removed): white noise puts 1/16 there, blue noise less, a pattern shared by neighbours (banding, bias) more. Widths against the exact image's.\n\n"
    );
    if at_n.iter().any(|(scheme, _)| {
        matches!(
            scheme,
            DiskScheme::BluenoiseCp | DiskScheme::SobolBluenoise | DiskScheme::SobolBluenoiseT
        )
    }) {
        s += &format!("Blue-noise tables: {}.\n\n", crate::sampling::bluenoise::settings());
    }
    if at_n.iter().any(|(scheme, _)| *scheme == DiskScheme::StbnCp) {
        s += &format!("STBN masks: {}.\n\n", crate::sampling::stbn::settings());
    }
    s += &rank_sentences(&at_n, subject);
    let exact = at_n
        .iter()
        .find_map(|(_, x)| (x.exact_width_10_90.is_finite()).then_some((x.exact_width_10_90, x.exact_extent_width)));
    s += "\n| scheme | source | RMSE | FLIP | blurred RMSE | low-freq share | 10-90 width vs exact | extent vs exact | frame time |\n|---|---|---|---|---|---|---|---|---|\n";
    for (scheme, x) in &at_n {
        let four = |v: f64| format!("{v:.4}");
        let m = &x.metrics;
        let (w, e) = exact.map_or(("n/a".into(), "n/a".into()), |(w, e)| {
            (against_exact(m.width_10_90, w), against_exact(m.extent_width, e))
        });
        s += &format!(
            "| {scheme} | {} | {} | {} | {} | {} | {w} | {e} | {} |\n",
            scheme.source(),
            with_ci(m.rmse.mean, m.rmse.ci95, four),
            with_ci(x.flip.mean, x.flip.ci95, four),
            with_ci(m.rmse_blurred.mean, m.rmse_blurred.ci95, four),
            with_ci(m.lowfreq_share.mean, m.lowfreq_share.ci95, |v| format!("{v:.3}")),
            x.frame.show_ms(),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mci(mean: f64, ci95: f64) -> MeanCi {
        MeanCi { mean, ci95 }
    }

    #[test]
    fn only_disjoint_intervals_are_clearly_below() {
        assert!(clearly_below(mci(1.0, 0.1), mci(1.5, 0.1)));
        assert!(!clearly_below(mci(1.0, 0.3), mci(1.5, 0.3)));
        assert!(!clearly_below(mci(1.0, f64::NAN), mci(5.0, 0.1)));
        assert!(!clearly_below(mci(1.5, 0.1), mci(1.0, 0.1)));
    }

    #[test]
    fn the_best_is_named_with_those_its_interval_overlaps_and_the_paper_is_ranked() {
        let m = &METRICS[3];
        let clear = [
            (DiskScheme::Sobol, mci(0.030, 0.001)),
            (DiskScheme::Paper, mci(0.050, 0.002)),
            (DiskScheme::Uniform, mci(0.096, 0.004)),
        ];
        let s = sentence(m, &clear, DiskScheme::Paper);
        assert!(
            s.contains("**sobol**, 0.0300 ± 0.0010; below every other scheme"),
            "{s}"
        );
        assert!(
            s.contains("ranks 2nd of 3 (0.0500 ± 0.0020, 1 scheme(s) clearly below it)"),
            "{s}"
        );
        let tie = [
            (DiskScheme::Sobol, mci(0.030, 0.005)),
            (DiskScheme::Pmj02, mci(0.033, 0.005)),
            (DiskScheme::Paper, mci(0.050, 0.002)),
        ];
        let s = sentence(m, &tie, DiskScheme::Paper);
        assert!(s.contains("tied within the intervals with pmj02."), "{s}");
        assert!(s.contains("ranks 3rd of 3 (0.0500 ± 0.0020, 2 scheme(s)"), "{s}");
        let single = [
            (DiskScheme::Sobol, mci(0.03, f64::NAN)),
            (DiskScheme::Uniform, mci(0.09, f64::NAN)),
        ];
        assert!(sentence(m, &single, DiskScheme::Paper).contains("no scheme is called best"));
        assert!(
            !sentence(m, &single, DiskScheme::Paper).contains("ranks"),
            "no paper, no rank"
        );
        assert!(sentence(m, &[], DiskScheme::Paper).contains("not measured here"));
        let own = sentence(m, &tie, DiskScheme::Pmj02);
        assert!(
            own.contains("`pmj02` ranks 2nd of 3") && !own.contains("paper's pattern ranks"),
            "{own}"
        );
        let alone = sentence(m, &[(DiskScheme::Uniform, mci(0.09, 0.01))], DiskScheme::Paper);
        assert!(
            alone.contains("the only scheme measured") && !alone.contains("below every"),
            "{alone}"
        );
    }

    #[test]
    fn ordinals_read_as_english() {
        let words: Vec<String> = [1, 2, 3, 4, 11, 12, 13, 21, 22].map(ordinal).to_vec();
        assert_eq!(
            words,
            ["1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd"]
        );
    }
}
