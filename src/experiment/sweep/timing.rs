//! Frame times you can rank by. Every configuration of a sweep (all axes but the seed) is timed
//! once, with its first seed's sampling, over `repeats` rounds. Each round visits the
//! configurations in a fresh seeded random order, so slow drift of the machine (clocks, other
//! load) spreads over all of them instead of favouring whichever ran first; each visit renders
//! `warmup` untimed frames and then one timed frame over resources already resident on the
//! device. A noise probe, one configuration visited [`NOISE_VISITS`] extra times per round at
//! random places in the order, measures the noise floor: the spread of one unchanging workload
//! across the whole timing phase.

use super::axes::Config;
use super::run::{Group, Run};
use super::spec::{Spec, TimingSpec};
use crate::fingerprint::fnv1a;
use crate::metrics::stats::{median, quartiles};
use crate::render::{Backend, Sampling, View};
use crate::sampling::rng::pcg;
use std::collections::BTreeMap;

/// Seed of the visiting order (recorded in the manifest).
pub const ORDER_SEED: u32 = 0x510e_527f;
/// Extra visits of the noise probe per round.
pub const NOISE_VISITS: u32 = 3;

/// The timed frames of one configuration.
#[derive(Clone, Debug, PartialEq)]
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

    /// First quartile, median and third quartile of the frame time, in milliseconds.
    pub fn frame_ms(&self) -> (f64, f64, f64) {
        let (a, b, c) = quartiles(&self.frame_seconds);
        (a * 1e3, b * 1e3, c * 1e3)
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
        median(&self.primary_seconds)
    }
}

/// Whether two timings can be ranked: their interquartile ranges are disjoint, and their medians
/// differ by more than the noise probe's interquartile range (relative to the larger median),
/// when there is a probe. With five frames each, disjoint ranges alone rank one pair of identical
/// configurations in five; with the probe's fifteen frames as the floor, one in fifteen (the
/// simulation in this module's tests).
/// `Some(true)` when `a` is faster, `Some(false)` when slower, `None` when equal within timing
/// noise (or untimed).
pub fn faster(a: &ConfigTiming, b: &ConfigTiming, noise: Option<&ConfigTiming>) -> Option<bool> {
    let ((a1, am, a3), (b1, bm, b3)) = (a.frame_ms(), b.frame_ms());
    if am.is_nan() || bm.is_nan() {
        return None;
    }
    let floor = noise.map_or(0.0, |n| {
        let (q1, m, q3) = n.frame_ms();
        if m > 0.0 {
            (q3 - q1) / m * am.max(bm)
        } else {
            0.0
        }
    });
    if (am - bm).abs() <= floor {
        None
    } else if a3 < b1 {
        Some(true)
    } else if b3 < a1 {
        Some(false)
    } else {
        None
    }
}

/// The timing phase's result.
#[derive(Clone, Debug, Default)]
pub struct Timings {
    /// Per configuration, keyed by its group key.
    pub configs: BTreeMap<String, ConfigTiming>,
    /// The noise probe's configuration and its frames.
    pub noise: Option<(Config, ConfigTiming)>,
}

/// Key of the timing settings: journaled timings are reused only under the same settings.
pub fn settings_key(t: &TimingSpec) -> String {
    let text = format!(
        "warmup={};repeats={};order={ORDER_SEED:08x};noise={NOISE_VISITS}",
        t.warmup, t.repeats
    );
    format!("{:016x}", fnv1a(text.as_bytes()))
}

/// Journal key of the noise probe's frames.
pub fn noise_key(group_key: &str) -> String {
    format!("noise-{group_key}")
}

/// The configuration whose repeated frames give the noise floor: uniform sampling, per-pixel, at
/// the figure ray count and the verdict's radius where swept, else the first configuration.
pub fn noise_probe<'a>(groups: &'a [&'a Group], samples: u32, radius: f64) -> Option<&'a Group> {
    groups
        .iter()
        .find(|g| {
            let h = g.head();
            h.scheme == crate::sampling::DiskScheme::Uniform
                && h.pattern == crate::sampling::Pattern::PerPixel
                && h.samples == samples
                && h.light_radius == radius
        })
        .or(groups.first())
        .copied()
}

/// A visiting order of `n` entries for `round`: Fisher-Yates over a counter-based stream.
pub fn order(n: usize, round: u32) -> Vec<usize> {
    let mut v: Vec<usize> = (0..n).collect();
    let stream = pcg(ORDER_SEED ^ pcg(round));
    for i in (1..n).rev() {
        let j = pcg(stream ^ pcg(i as u32)) as usize % (i + 1);
        v.swap(i, j);
    }
    v
}

/// Times `groups` (each by its first run) and, if `noise` is given, the noise probe, in
/// interleaved rounds. `keys` are the journal keys of the entries (group keys, then the noise key).
pub fn time_groups(
    spec: &Spec,
    backend: &mut dyn Backend,
    groups: &[&Group],
    noise: Option<&Group>,
    on_frame: &dyn Fn(),
) -> anyhow::Result<(Vec<ConfigTiming>, Option<ConfigTiming>)> {
    let t = &spec.timing;
    let mut entries: Vec<(usize, &Run)> = groups.iter().enumerate().map(|(i, g)| (i, g.head())).collect();
    if let Some(g) = noise {
        entries.extend((0..NOISE_VISITS).map(|_| (groups.len(), g.head())));
    }
    let mut out = vec![ConfigTiming::empty(); groups.len() + 1];
    for round in 0..t.repeats {
        for k in order(entries.len(), round) {
            let (slot, run) = entries[k];
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
            };
            let timing = backend.time(&scene, view, sampling, t.warmup, 1)?;
            let c = &mut out[slot];
            c.frame_seconds.extend(&timing.seconds);
            c.primary_seconds.extend(&timing.primary_seconds);
            c.clock = timing.clock.name().to_string();
            on_frame();
        }
    }
    let noise_timing = out.pop().filter(|_| noise.is_some());
    Ok((out, noise_timing))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(ms: &[f64]) -> ConfigTiming {
        ConfigTiming::wall_clock_ms(ms)
    }

    #[test]
    fn ranks_only_disjoint_interquartile_ranges() {
        let a = timing(&[10.0, 11.0, 12.0, 13.0, 14.0]);
        let b = timing(&[15.0, 16.0, 17.0, 18.0, 19.0]);
        let overlapping = timing(&[12.5, 13.0, 14.0, 15.0, 30.0]);
        assert_eq!(faster(&a, &b, None), Some(true));
        assert_eq!(faster(&b, &a, None), Some(false));
        assert_eq!(faster(&a, &overlapping, None), None);
        assert_eq!(faster(&a, &timing(&[]), None), None);
        // Medians 5 ms apart: ranked under a 20 % noise floor, not under a 40 % one.
        let probe = |rel: f64| timing(&[-1.0, -0.5, 0.0, 0.5, 1.0].map(|k| 100.0 * (1.0 + k * rel)));
        assert_eq!(faster(&a, &b, Some(&probe(0.2))), Some(true));
        assert_eq!(faster(&a, &b, Some(&probe(0.4))), None);
        let (q1, med, q3) = a.frame_ms();
        assert!((q1 - 11.0).abs() < 1e-9 && (med - 12.0).abs() < 1e-9 && (q3 - 13.0).abs() < 1e-9);
        assert!(a.primary_median().is_nan());
    }

    /// Identical configurations (five frames each from one seeded noise distribution) against a
    /// probe of fifteen: the noise floor cuts the false rankings that disjoint ranges alone make.
    #[test]
    fn identical_configurations_are_rarely_ranked() {
        let mut draw = {
            let stream = crate::sampling::Stream::new(11, 0, None);
            let mut i = 0u32;
            move || {
                // Roughly normal (sum of four uniforms) around 50 ms, sd ~ 2.9 ms.
                let u: f64 = (0..4)
                    .map(|_| {
                        i += 1;
                        stream.unit(i)
                    })
                    .sum();
                50.0 + 5.0 * (u - 2.0)
            }
        };
        let mut frames = |n: usize| timing(&(0..n).map(|_| draw()).collect::<Vec<_>>());
        let trials = 2000;
        let (mut alone, mut gated) = (0, 0);
        for _ in 0..trials {
            let (a, b, probe) = (frames(5), frames(5), frames(15));
            alone += faster(&a, &b, None).is_some() as usize;
            gated += faster(&a, &b, Some(&probe)).is_some() as usize;
        }
        let (alone, gated) = (alone as f64 / trials as f64, gated as f64 / trials as f64);
        eprintln!("identical pairs ranked: {alone} by disjoint ranges alone, {gated} with the floor");
        assert!(alone > 0.1, "disjoint ranges alone ranked {alone}");
        assert!(
            gated < 0.08 && gated < alone / 2.0,
            "with the noise floor {gated} were ranked"
        );
    }

    #[test]
    fn orders_are_permutations_that_differ_between_rounds() {
        let rounds: Vec<Vec<usize>> = (0..5).map(|r| order(50, r)).collect();
        for o in &rounds {
            let mut sorted = o.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..50).collect::<Vec<_>>());
        }
        assert!(rounds.windows(2).all(|w| w[0] != w[1]));
        assert_eq!(order(50, 3), rounds[3], "seeded: the same round gives the same order");
        // Interleaved: the first entry is not always first.
        assert!(rounds.iter().any(|o| o[0] != 0));
    }
}
