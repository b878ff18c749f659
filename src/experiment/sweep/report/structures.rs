//! "What the structure costs": with an `accelerators` axis, each configuration rendered by
//! every structure other than the first is set beside the first structure's: whether every
//! seed's shadow image is the same bit for bit (equal accuracy by construction, not by
//! metric), how their frame times compare (by the one timing rule), and the work each did.

use super::summary::{find, Summary};
use crate::experiment::sweep::axes::Config;
use crate::experiment::sweep::runner::Outcome;
use crate::experiment::sweep::timing::compare;
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
    let mut s = format!(
        "\n## What the acceleration structure costs\n\nEvery configuration rendered with each structure beside `{base}`: seeds whose shadow images are identical bit for bit, the frame times (median ms [95 % interval]), the time ratio with its interval, the rule's word (see Timing) and the rounds it took, and the nodes visited and primitives tested in one frame where the backend counts them.\n\n| lights | scheme | pattern | rays | radius (m) | structure | same images | frame ms | `{base}` ms | time / `{base}`'s | word | rounds | nodes | `{base}` nodes | tests | `{base}` tests |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n"
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
        let (ratio, word, rounds) = match (&other.timing, &first.timing) {
            (Some(a), Some(b)) => {
                let d = compare(a, b, outcome.timings.looks);
                (d.ratio, d.word.word(), d.rounds.to_string())
            }
            _ => (crate::timing::Estimate::NAN, "untimed", "n/a".to_string()),
        };
        if ratio.median.is_finite() {
            ratios.push(ratio.median);
        }
        let c = &other.config;
        let ms = |e: &crate::timing::Estimate| or_na(e.median, |_| e.scaled(1e3).show(2));
        let count = |w: Option<crate::accel::work::Work>, f: fn(crate::accel::work::Work) -> u64| {
            w.map_or("n/a".to_string(), |w| format!("{:.3e}", f(w) as f64))
        };
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {same}/{both} | {} | {} | {} | {word} | {rounds} | {} | {} | {} | {} |\n",
            c.lights,
            c.scheme,
            c.pattern,
            c.samples,
            c.light_radius,
            c.accelerator,
            ms(&other.frame),
            ms(&first.frame),
            or_na(ratio.median, |_| format!("{}x", ratio.show_ratio(2))),
            count(other.work, |w| w.nodes),
            count(first.work, |w| w.nodes),
            count(other.work, |w| w.primitives),
            count(first.work, |w| w.primitives),
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
