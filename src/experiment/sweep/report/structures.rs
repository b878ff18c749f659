//! "What the structure costs": with an `accelerators` axis, each configuration rendered by
//! every structure other than the first is set beside the first structure's: whether every
//! seed's shadow image is the same bit for bit (equal accuracy by construction, not by
//! metric), and how their frame times compare (ranked only beyond timing noise).

use super::summary::{find, Summary};
use crate::experiment::sweep::axes::Config;
use crate::experiment::sweep::runner::Outcome;
use crate::experiment::sweep::timing::faster;
use crate::experiment::sweep::Spec;
use crate::metrics::stats::median;
use crate::output::numbers::or_na;

/// The seeds of `config` whose images `a` and `b` render identically, and the seeds both have.
fn same_images(outcome: &Outcome, a: &Config, b: &Config) -> (usize, usize) {
    let of = |c: &Config| {
        outcome
            .records
            .iter()
            .filter(|r| r.run.config() == *c && !r.image_fnv1a.is_empty())
            .map(|r| (r.run.seed, r.image_fnv1a.as_str()))
            .collect::<Vec<_>>()
    };
    let (xs, ys) = (of(a), of(b));
    let both: Vec<_> = xs
        .iter()
        .filter_map(|(seed, h)| ys.iter().find(|(s, _)| s == seed).map(|(_, g)| h == g))
        .collect();
    (both.iter().filter(|&&same| same).count(), both.len())
}

/// The section, or nothing when the sweep has one structure.
pub fn structure_section(spec: &Spec, outcome: &Outcome, summaries: &[Summary]) -> String {
    let names = &spec.axes.accelerators;
    if names.len() < 2 {
        return String::new();
    }
    let base = &names[0];
    let noise = outcome.timings.noise.as_ref().map(|(_, t)| t);
    let mut s = format!(
        "\n## What the acceleration structure costs\n\nEvery configuration rendered with each structure beside `{base}`: seeds whose shadow images are identical bit for bit, and the frame times (median ms [quartiles]); a structure is called faster or slower only beyond timing noise, as above.\n\n| lights | scheme | pattern | rays | radius (m) | structure | same images | frame ms | `{base}` ms | time / `{base}`'s | ranked |\n|---|---|---|---|---|---|---|---|---|---|---|\n"
    );
    let (mut identical, mut compared, mut ratios) = (0, 0, Vec::new());
    for other in summaries.iter().filter(|x| x.config.accelerator != *base) {
        let reference = Config {
            accelerator: base.clone(),
            ..other.config.clone()
        };
        let Some(first) = find(summaries, &reference) else {
            continue;
        };
        let (same, both) = same_images(outcome, &other.config, &reference);
        identical += same;
        compared += both;
        let (o, f) = (other.frame_ms(), first.frame_ms());
        let ratio = o.1 / f.1;
        if ratio.is_finite() {
            ratios.push(ratio);
        }
        let ranked = match (&other.timing, &first.timing) {
            (Some(a), Some(b)) => match faster(a, b, noise) {
                Some(true) => "faster",
                Some(false) => "slower",
                None => "equal within noise",
            },
            _ => "untimed",
        };
        let c = &other.config;
        let ms = |(q1, m, q3): (f64, f64, f64)| or_na(m, |m| format!("{m:.2} [{q1:.2}, {q3:.2}]"));
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {same}/{both} | {} | {} | {} | {ranked} |\n",
            c.lights,
            c.scheme,
            c.pattern,
            c.samples,
            c.light_radius,
            c.accelerator,
            ms(o),
            ms(f),
            or_na(ratio, |r| format!("{r:.2}x"))
        );
    }
    s += &format!(
        "\nIdentical shadow images in {identical} of {compared} runs compared{}. Frame time relative to `{base}`: median {}, range {}.\n",
        if identical == compared { "" } else { " (a differing image means the structures decided some ray differently: see runs.csv's image_fnv1a)" },
        if ratios.is_empty() { "n/a".to_string() } else { format!("{:.2}x", median(&ratios)) },
        if ratios.is_empty() {
            "n/a".to_string()
        } else {
            format!(
                "{:.2}-{:.2}x",
                ratios.iter().cloned().fold(f64::INFINITY, f64::min),
                ratios.iter().cloned().fold(0.0, f64::max)
            )
        }
    );
    s
}
