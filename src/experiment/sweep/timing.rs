//! Frame times you can rank by, timed the one way every kind times ([`crate::timing`]), and
//! sequentially ([`crate::timing::sequential`]).
//! Every configuration of a sweep (all axes but the seed) at a timed ray count (`[timed]`) is
//! timed with its first seed's sampling; each visit renders `warmup` untimed frames, then one timed frame over resources
//! already resident on the device. The configurations a report compares share a block, visited
//! back to back: those of one pattern, ray count, light radius and light count, so each scheme
//! is timed beside uniform sampling and each structure beside the first. Rounds go on while a
//! comparison (scheme / uniform, structure / the first, the A/A control) is undecided, up to
//! the file's `repeats`. An A/A control, one configuration visited a second time per round as
//! if it were another, checks the rule on this machine: the two must never read faster or
//! slower.

use super::axes::Config;
use super::run::{Group, Run};
use super::spec::Spec;
use crate::render::limit::DeviceLimit;
use crate::render::{Backend, Sampling, View};
use crate::timing::{decide, median_interval, Comparison, Decided, Estimate, Looks, Pair, RoundDone};
use std::collections::BTreeMap;

/// Extra visits of the A/A control per round.
pub const NOISE_VISITS: u32 = 1;

/// The timed frames of one configuration, one per round in round order.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConfigTiming {
    /// Seconds per timed frame, in the order they were taken.
    pub frame_seconds: Vec<f64>,
    /// Seconds of the primary pass of each timed frame, where the clock splits passes.
    pub primary_seconds: Vec<f64>,
    /// How the times were taken (`gpu-timestamp` or `wall-clock`).
    pub clock: String,
}

impl ConfigTiming {
    /// No frames yet.
    pub fn empty() -> ConfigTiming {
        ConfigTiming {
            frame_seconds: vec![],
            primary_seconds: vec![],
            clock: String::new(),
        }
    }

    /// Median frame time with its 95 % interval, seconds.
    pub fn frame(&self) -> Estimate {
        median_interval(&self.frame_seconds)
    }

    /// Wall-clock frames of the given milliseconds: hand-made timings for tests.
    #[cfg(test)]
    pub(crate) fn wall_clock_ms(ms: &[f64]) -> ConfigTiming {
        ConfigTiming {
            frame_seconds: ms.iter().map(|x| x * 1e-3).collect(),
            primary_seconds: vec![],
            clock: "wall-clock".into(),
        }
    }

    /// Median seconds of the primary pass; NaN where the clock cannot split passes.
    pub fn primary_median(&self) -> f64 {
        crate::metrics::stats::median(&self.primary_seconds)
    }
}

/// The time ratio `a / b` of two configurations timed in the same rounds (paired by round) with
/// its interval, the word the stopping rule gave it and the rounds it took (replayed on the
/// series, [`decide`]); NaN, "undecided" and no rounds where either is untimed.
pub fn compare(a: &ConfigTiming, b: &ConfigTiming, looks: Looks) -> Decided {
    if a.frame_seconds.is_empty() || b.frame_seconds.is_empty() {
        return Decided {
            ratio: Estimate::NAN,
            word: Comparison::Undecided,
            rounds: 0,
        };
    }
    decide(&a.frame_seconds, &b.frame_seconds, looks)
}

/// The timing phase's result.
#[derive(Clone, Debug, Default)]
pub struct Timings {
    /// Per configuration, keyed by its group key.
    pub configs: BTreeMap<String, ConfigTiming>,
    /// The A/A control's configuration and its second series of frames.
    pub noise: Option<(Config, ConfigTiming)>,
    /// Seed of the visiting order and of every bootstrap interval.
    pub seed: u32,
    /// When the rounds were looked at and the most of them.
    pub looks: Looks,
}

/// The configuration timed twice as the A/A control: uniform sampling, per-pixel, at the figure
/// ray count and the verdict's radius where swept, else the first configuration.
pub fn noise_probe(groups: &[Group], samples: u32, radius: f64) -> Option<usize> {
    let probe = groups.iter().position(|g| {
        let h = g.head();
        h.scheme == crate::sampling::DiskScheme::Uniform
            && h.pattern == crate::sampling::Pattern::PerPixel
            && h.samples == samples
            && h.light_radius == radius
    });
    probe.or((!groups.is_empty()).then_some(0))
}

/// The blocks of units visited back to back (units: `groups`, then the A/A control's second
/// visit of group `noise` if given) and the comparisons the report states: each scheme against
/// uniform sampling, each structure against the first swept, the control against its group.
pub fn blocks_and_pairs(groups: &[Group], noise: Option<usize>) -> (Vec<Vec<usize>>, Vec<Pair>) {
    let configs: Vec<Config> = groups.iter().map(Group::config).collect();
    let block_of = |c: &Config| (c.pattern, c.samples, c.light_radius.to_bits(), c.lights);
    let mut keys = Vec::new();
    let mut blocks: Vec<Vec<usize>> = Vec::new();
    for (i, c) in configs.iter().enumerate() {
        match keys.iter().position(|k| *k == block_of(c)) {
            Some(b) => blocks[b].push(i),
            None => {
                keys.push(block_of(c));
                blocks.push(vec![i]);
            }
        }
    }
    let first_structure = configs.first().map(|c| c.accelerator.clone());
    let mut pairs = Vec::new();
    for (a, c) in configs.iter().enumerate() {
        let against = |other: &Config| configs.iter().position(|x| x == other);
        if c.scheme != crate::sampling::DiskScheme::Uniform {
            let uniform = Config {
                scheme: crate::sampling::DiskScheme::Uniform,
                ..c.clone()
            };
            pairs.extend(against(&uniform).map(|b| Pair { a, b }));
        }
        if let Some(first) = first_structure.as_ref().filter(|f| **f != c.accelerator) {
            let base = Config {
                accelerator: first.clone(),
                ..c.clone()
            };
            pairs.extend(against(&base).map(|b| Pair { a, b }));
        }
    }
    if let Some(g) = noise {
        let twin = groups.len();
        let b = blocks
            .iter()
            .position(|b| b.contains(&g))
            .expect("every group in a block");
        blocks[b].push(twin);
        pairs.push(Pair { a: twin, b: g });
    }
    (blocks, pairs)
}

/// Times `groups` (each by its first run) and, if `noise` is given, the A/A control, in the
/// schedule's blocked rounds until every comparison of [`blocks_and_pairs`] is decided or the
/// file's `repeats` are run ([`crate::timing::Schedule::run_sequential`]). A configuration
/// whose frame fails to render is logged, left untimed (the report reads "n/a") and not visited
/// again: its runs' rows say why it failed, and one configuration the device cannot render
/// never keeps the others from being timed.
pub fn time_groups(
    spec: &Spec,
    backend: &mut dyn Backend,
    groups: &[Group],
    noise: Option<usize>,
    on_round: &dyn Fn(RoundDone),
) -> anyhow::Result<(Vec<ConfigTiming>, Option<ConfigTiming>)> {
    let t = &spec.timing;
    let (blocks, pairs) = blocks_and_pairs(groups, noise);
    let mut entries: Vec<&Run> = groups.iter().map(Group::head).collect();
    entries.extend(noise.map(|g| groups[g].head()));
    let mut out = vec![ConfigTiming::empty(); entries.len()];
    let mut failed = vec![false; entries.len()];
    let times = t.run_sequential(
        Looks::up_to(t.repeats),
        &blocks,
        &pairs,
        |slot| -> anyhow::Result<f64> {
            let run = entries[slot];
            if failed[slot] {
                return Ok(f64::NAN);
            }
            let scene = spec.scene_with(run.lights, run.light_radius, run.samples, &run.accelerator);
            let view = View {
                camera: &scene.cameras[&spec.measure.camera],
                width: spec.measure.width,
                height: spec.measure.height,
            };
            let sampling = Sampling {
                scheme: run.scheme,
                pattern: run.pattern,
                seed: run.seed,
                frame: 0,
            };
            match backend.time(&scene, view, sampling, t.warmup, 1) {
                Ok(timing) if timing.seconds.first().is_some_and(|s| s.is_finite()) => {
                    let c = &mut out[slot];
                    c.primary_seconds.extend(&timing.primary_seconds);
                    c.clock = timing.clock.name().to_string();
                    Ok(timing.seconds[0])
                }
                Ok(_) => {
                    tracing::error!("timing {} gave no finite time; left untimed", run.config());
                    failed[slot] = true;
                    Ok(f64::NAN)
                }
                Err(e) if DeviceLimit::part_of(&e).is_some() => Err(e),
                Err(e) => {
                    tracing::error!("timing {} failed; left untimed: {e:#}", run.config());
                    failed[slot] = true;
                    Ok(f64::NAN)
                }
            }
        },
        on_round,
    )?;
    for ((c, seconds), failed) in out.iter_mut().zip(times.seconds).zip(failed) {
        c.frame_seconds = if failed { vec![] } else { seconds };
        if failed {
            c.primary_seconds.clear();
        }
    }
    let noise_timing = noise.and_then(|_| out.pop());
    Ok((out, noise_timing))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(ms: &[f64]) -> ConfigTiming {
        ConfigTiming::wall_clock_ms(ms)
    }

    #[test]
    fn comparisons_pair_by_round_and_follow_the_rule() {
        let a = timing(&[10.0, 11.0, 12.0, 13.0, 14.0]);
        let b = timing(&[15.0, 16.0, 17.0, 18.0, 19.0]);
        let looks = Looks::up_to(6);
        assert_eq!(compare(&a, &b, looks).word, Comparison::Faster);
        assert_eq!(compare(&b, &a, looks).word, Comparison::Slower);
        let drifting = timing(&[10.0, 20.0, 12.0, 13.0, 14.0]);
        let same = timing(&[10.5, 19.0, 12.5, 12.5, 14.5]);
        assert_eq!(compare(&drifting, &same, looks).word, Comparison::Undecided);
        assert_eq!(compare(&a, &timing(&[]), looks).word, Comparison::Undecided);
        let r = compare(&a, &timing(&[20.0, 22.0]), looks).ratio;
        assert!(
            (r.median - 0.5).abs() < 1e-12,
            "paired over the rounds both were timed in: {r:?}"
        );
        let f = a.frame();
        assert!((f.median - 0.012).abs() < 1e-12 && f.lo <= f.median && f.hi >= f.median);
        assert!(a.primary_median().is_nan());
    }
}
