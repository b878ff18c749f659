//! report.md: what was run, the scene's acceleration structure, how far the ground truth is
//! from the exact answer, the verdict, what accuracy costs in time, and where the outputs are.

use super::summary::{find, swept_schemes, Summary};
use super::verdict::Verdict;
use crate::experiment::sweep::axes::{slices, Axis, Config, Slice};
use crate::experiment::sweep::runner::Outcome;
use crate::experiment::sweep::timing::{compare, ConfigTiming};
use crate::experiment::sweep::Spec;
use crate::output::numbers::or_na;
use crate::render::AdapterInfo;
use crate::sampling::{DiskScheme, Pattern};
use crate::timing::Decided;
use crate::timing::{Comparison, Looks, RULE};

fn opt(x: Option<f64>, f: impl Fn(f64) -> String) -> String {
    or_na(x.unwrap_or(f64::NAN), f)
}

/// The report's markdown.
pub fn report(spec: &Spec, outcome: &Outcome, summaries: &[Summary], adapter: &AdapterInfo, seconds: f64) -> String {
    let n = spec.figure_samples();
    let radius = spec.verdict_radius();
    let mut s = format!("# {}: soft-shadow sampling sweep\n\n", spec.name);
    s += &format!(
        "Experiment `{}`, scene `{}`; {} runs ({} failed) on **{}** ({}, {}, {}) in {:.0} s.\n\n",
        spec.path.display(),
        spec.scene_path.display(),
        outcome.records.len(),
        outcome.failures,
        adapter.name,
        adapter.backend,
        adapter.api,
        adapter.driver,
        seconds
    );
    s += "Render plan of a run at the figure ray count with every light on (derived from the scene):\n\n```\n";
    s += &outcome.plan.to_string();
    s += "```\n\n";
    if let Some(a) = &spec.scene.accel {
        let m: Vec<String> = spec
            .scene
            .meshes()
            .map(|m| {
                format!(
                    "`{}`: {} triangles ({} degenerate and {} non-finite skipped)",
                    m.source, m.triangles, m.skipped.degenerate, m.skipped.non_finite
                )
            })
            .collect();
        s += &format!("Meshes: {}. {}.\n\n", m.join("; "), a.stats().description);
    }
    s += "## Ground truth against the exact answer\n\n";
    s += &format!(
        "Ground truth: jittered sampling, {} shadow rays per pixel per light, {}x{} pixels. Exact: adaptive quadrature of the visible part of each disk (tolerance 1e-10), available for disk lights over spheres and planes; mesh scenes are judged against the ground truth alone.\n\n",
        spec.ground_truth.samples, spec.measure.width, spec.measure.height
    );
    s += "GT errors are over receiver pixels; RMSE and mean error over the exact image's penumbra. The exact image's own error is the quadrature's bound (its worst pixel), with the pixels where a panel reached the depth limit.\n\n";
    s += "| lights | light radius (m) | r_u closed form (m) | r_p closed form (m) | GT max abs error | GT RMSE (penumbra) | GT mean error (penumbra) | penumbra pixels | exact error bound | depth-limited pixels |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for r in &outcome.references {
        let o = r.on_axis.as_ref();
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.lights,
            r.light_radius,
            opt(o.map(|o| o.umbra_radius()), |x| if x < 0.0 {
                format!("{x:.5} (no umbra)")
            } else {
                format!("{x:.5}")
            }),
            opt(o.map(|o| o.penumbra_radius()), |x| format!("{x:.5}")),
            opt(r.gt_max_abs_all(), |x| format!("{x:.2e}")),
            opt(r.gt_vs_exact().map(|e| e.rmse), |x| format!("{x:.2e}")),
            opt(r.gt_vs_exact().map(|e| e.bias), |x| format!("{x:+.1e}")),
            r.mask.pixels.len(),
            opt(r.exact_quality.map(|q| q.max_error_bound), |x| format!("{x:.1e}")),
            r.exact_quality
                .map_or("n/a".into(), |q| q.depth_limited_pixels.to_string()),
        );
    }
    let pair = spec.verdict;
    let verdicts = verdicts(summaries, n, radius, pair);
    if outcome.references.iter().any(|r| r.on_axis.is_some()) {
        if pair == (DiskScheme::Paper, DiskScheme::Uniform) {
            s += "\n## Verdict\n\nThe claim (Vassilev 2012, Fig. 2): with eq. (2)+(3) the penumbra at 16 rays is wider than with eq. (1), at the same quality.\n\n";
        } else {
            s += &format!(
                "\n## Verdict\n\nThe experiment's comparison (`[verdict]`): `{}` against `{}` at {n} rays, asked as the 2012 paper asked of its pattern: a wider penumbra, and at what quality?\n\n",
                pair.0, pair.1
            );
        }
        if verdicts.is_empty() {
            s += &format!(
                "The sweep does not hold both `{}` and `{}` at this sample count and radius, so no verdict.\n\n",
                pair.1, pair.0
            );
        }
        for (label, v) in &verdicts {
            if !label.is_empty() {
                s += &format!("*{label}:*\n\n");
            }
            s += &v.markdown();
            s += "\n";
        }
    }
    if !outcome.timings.configs.is_empty() {
        s += &timing_section(outcome, spec.timing.warmup);
    }
    for slice in slices(summaries.iter().map(|x| &x.config), &COST_NAMES) {
        s += &super::schemes::scheme_section(summaries, &slice, n, radius, spec.verdict.0);
        s += &super::equal_time::section(outcome, summaries, &slice, n, radius);
        s += &cost_section(summaries, &slice, n, radius, outcome.timings.looks);
    }
    s += &super::structures::structure_section(spec, outcome, summaries);
    s += "\n## Outputs\n\n- `runs.csv`: one row per run, with the error's radial power spectrum (`error_power_NN`: rings of 1/32 cycles per pixel); `summary.csv`: means and 95 % CIs over seeds, with the per-pixel bias/variance split.\n";
    s += "- `ground_truth.csv`: per light configuration, the reference's checks above.\n- `plots/`: width vs samples (exact drawn), RMSE vs samples, RMSE vs frame time, radial profiles, width vs light radius (on-axis scenes); RMSE vs samples and vs frame time, the error's spectrum per scheme at the figure ray count (any scene). A plot over both patterns has one panel per pattern on shared axes; one file per value of each other swept axis, named `_AXIS-VALUE` (`rmse_vs_time_lights-1_accelerator-bvh.png`).\n";
    s += "- `images/`: every scheme and pattern of the measuring view at the figure ray count, the ground truth and the exact image, and the Fig. 2 pictures, each as `.exr` (the values) and `.png`; the grids `fig2_measure.png` and `fig2_picture.png`.\n- `index.html`: the comparison page (open it in a browser; no server needed).\n- `manifest.toml`: commit, adapter, experiment, seeds.\n";
    s
}

/// How times were taken, the rule that turns them into words, and the A/A control that checks
/// the rule on this machine: stated once per report.
fn timing_section(outcome: &Outcome, warmup: u32) -> String {
    let t = &outcome.timings;
    let some = t.configs.values().next();
    let mut s = format!(
        "
## Timing

Every configuration on the timing grid timed with its first seed, once per round, sequentially: the configurations a comparison holds (each scheme and uniform sampling, each structure and the first, at one pattern, ray count, light radius and light count) are visited back to back in seeded ABBA order, and after {first} rounds and every {every} after, up to {cap}, every open comparison is read by the rule; a decided one stops, and a configuration stops being timed when all of its have ({min}-{max} rounds here; `timings.csv` holds every round: replaying these looks on it gives the round each comparison stopped at and its word there, and the equal-time answers below recompute from it and `runs.csv`). Order seed {seed}; {warmup} warm-up frame(s) before each timed frame; clock: {clock}. {RULE}

",
        first = t.looks.first_look,
        every = t.looks.every,
        cap = t.looks.cap,
        min = t.configs.values().map(|c| c.frame_seconds.len()).min().unwrap_or(0),
        max = t.configs.values().map(|c| c.frame_seconds.len()).max().unwrap_or(0),
        seed = t.seed,
        warmup = warmup,
        clock = some.map_or("n/a", |c| c.clock.as_str()),
    );
    if let Some((config, twin)) = &t.noise {
        if let Some(first) = outcome
            .groups
            .iter()
            .find(|g| g.config == *config)
            .and_then(|g| t.configs.get(&g.key))
        {
            let Decided { ratio, word, rounds } = compare(twin, first, t.looks);
            s += &format!(
                "A/A control: one configuration ({} {}, {} rays, light radius {} m) visited twice per round, as if it were two, while its comparison was open; the time ratio of its two series is {}: **{}** after {rounds} rounds{}

",
                config.scheme,
                config.pattern,
                config.samples,
                config.light_radius,
                ratio.show_ratio(3),
                word.word(),
                match word {
                    Comparison::Equivalent => ", as it must be.",
                    Comparison::Undecided => ": the rounds could not show an unchanged workload equivalent on this machine (no direction either).",
                    _ => ". The rule called an unchanged workload different on this machine: read every time comparison below with that in mind.",
                }
            );
        }
    }
    s
}

/// How a configuration's frame time compares with uniform sampling's (time ratio with its
/// interval and the rule's word).
fn time_rank(x: Option<&ConfigTiming>, uniform: Option<&ConfigTiming>, looks: Looks) -> String {
    match (x, uniform) {
        (Some(a), Some(b)) => {
            let d = compare(a, b, looks);
            format!(
                "{}x uniform's time: {} ({} rounds)",
                d.ratio.show_ratio(2),
                d.word.word(),
                d.rounds
            )
        }
        _ => "untimed".into(),
    }
}

/// The axes the verdict names (at one light: the exact answer's case); it is read once per value
/// of the others.
const VERDICT_NAMES: [Axis; 5] = [
    Axis::Scheme,
    Axis::Pattern,
    Axis::Samples,
    Axis::LightRadius,
    Axis::Lights,
];

/// The verdict of each pattern at `n` rays and light radius `radius`, in each slice of the axes
/// it does not name, with the slice's label (empty when there is one slice).
fn verdicts(summaries: &[Summary], n: u32, radius: f64, pair: (DiskScheme, DiskScheme)) -> Vec<(String, Verdict)> {
    let mut out = Vec::new();
    for slice in slices(summaries.iter().map(|x| &x.config), &VERDICT_NAMES) {
        for pattern in [Pattern::PerPixel, Pattern::Shared] {
            let at = Config {
                pattern,
                samples: n,
                light_radius: radius,
                lights: 1,
                ..slice.config.clone()
            };
            out.extend(Verdict::new(summaries, &at, pair).map(|v| (slice.label(&[]), v)));
        }
    }
    out
}

/// The axes a cost section names; it is written once per value of the others.
const COST_NAMES: [Axis; 4] = [Axis::Scheme, Axis::Pattern, Axis::Samples, Axis::LightRadius];

/// What accuracy costs: error, frame time and work per scheme at the verdict's count, and each
/// scheme's frame time against uniform's at that count by the rule (with the rounds it took).
fn cost_section(summaries: &[Summary], slice: &Slice, n: u32, radius: f64, looks: Looks) -> String {
    let lights = slice.config.lights;
    let more = match slice.label(&[Axis::Lights]) {
        l if l.is_empty() => l,
        l => format!(", {l}"),
    };
    let mut s = format!(
        "\n## What accuracy costs ({lights} light(s){more})\n\nPer-pixel pattern, light radius {radius} m. RMSE against the ground truth over its penumbra (mean over seeds); FLIP of the Fig. 2 picture where rendered; `lost`: share of the true penumbra shown fully lit or fully dark; frame time: median [95 % interval] of the timed frames; rays, nodes visited and primitive tests of one frame (deterministic; nodes and tests where the backend counts them). `vs uniform@{n}`: the frame time against uniform's at the same count by the rule (see Timing; timed beside it, with the rounds it took). The time each scheme needs to reach uniform@{n}'s RMSE is read off its curve above.\n\n"
    );
    s += &format!("| scheme | RMSE @{n} | FLIP @{n} | lost @{n} | frame time @{n} | rays @{n} | nodes @{n} | tests @{n} | vs uniform@{n} |\n|---|---|---|---|---|---|---|---|---|\n");
    let base = Config {
        pattern: Pattern::PerPixel,
        samples: n,
        light_radius: radius,
        ..slice.config.clone()
    };
    let uniform = find(
        summaries,
        &Config {
            scheme: DiskScheme::Uniform,
            ..base.clone()
        },
    );
    for scheme in swept_schemes(summaries) {
        let Some(at) = find(summaries, &Config { scheme, ..base.clone() }) else {
            continue;
        };
        let matched = match uniform {
            None => "n/a".to_string(),
            Some(_) if scheme == DiskScheme::Uniform => "reference".to_string(),
            Some(u) => time_rank(at.timing.as_ref(), u.timing.as_ref(), looks),
        };
        let count = |v: Option<u64>| v.map_or("n/a".to_string(), |v| format!("{v:.3e}", v = v as f64));
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            scheme,
            or_na(at.metrics.rmse.mean, |x| format!("{x:.4}")),
            or_na(at.flip.mean, |x| format!("{x:.4}")),
            or_na(at.metrics.penumbra_lost_share.mean, |x| format!("{x:.3}")),
            at.frame.show_ms(),
            count(at.rays),
            count(at.work.map(|w| w.nodes)),
            count(at.work.map(|w| w.primitives)),
            matched
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(ms: &[f64]) -> ConfigTiming {
        ConfigTiming::wall_clock_ms(ms)
    }

    const L: Looks = Looks {
        first_look: 6,
        every: 3,
        cap: 6,
    };

    #[test]
    fn times_are_compared_by_the_rule() {
        let a = timing(&[99.0, 99.5, 100.0, 100.5, 101.0]);
        let b = timing(&[113.0, 113.5, 114.0, 114.5, 115.0]);
        let noisy = timing(&[80.0, 120.0, 100.0, 90.0, 110.0]);
        assert!(
            time_rank(Some(&a), Some(&b), L).ends_with(": faster (5 rounds)"),
            "{}",
            time_rank(Some(&a), Some(&b), L)
        );
        assert!(time_rank(Some(&b), Some(&a), L).ends_with(": slower (5 rounds)"));
        assert!(time_rank(Some(&a), Some(&noisy), L).ends_with(": undecided (5 rounds)"));
        assert_eq!(time_rank(None, Some(&b), L), "untimed");
    }
}
