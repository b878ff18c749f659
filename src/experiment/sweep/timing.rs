//! Frame times you can rank by, timed the one way every kind times ([`crate::timing`]).
//! Every configuration of a sweep (all axes but the seed) is timed with its first seed's sampling,
//! once per interleaved round; each visit renders `warmup` untimed frames, then one timed frame
//! over resources already resident on the device. An A/A control, one configuration visited a
//! second time per round as if it were another, checks the rule on this machine: the two must
//! read "equal within noise".

use super::axes::Config;
use super::run::{Group, Run};
use super::spec::Spec;
use crate::render::{Backend, Sampling, View};
use crate::timing::{median_interval, paired_ratio, Comparison, Estimate};
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
/// its interval, and the word the rule gives it; NaN and "equal" where either is untimed or
/// they were not timed in the same rounds.
pub fn compare(a: &ConfigTiming, b: &ConfigTiming) -> (Estimate, Comparison) {
    if a.frame_seconds.is_empty() || a.frame_seconds.len() != b.frame_seconds.len() {
        return (Estimate::NAN, Comparison::Equal);
    }
    let ratio = paired_ratio(&a.frame_seconds, &b.frame_seconds);
    (ratio, Comparison::of(&ratio))
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

/// Times `groups` (each by its first run) and, if `noise` is given, the A/A control, in the
/// schedule's interleaved rounds. A configuration whose frame fails to render is logged, left
/// untimed (the report reads "n/a") and not visited again: its runs' rows say why it failed, and
/// one configuration the device cannot render never keeps the others from being timed.
pub fn time_groups(
    spec: &Spec,
    backend: &mut dyn Backend,
    groups: &[Group],
    noise: Option<&Group>,
    on_frame: &dyn Fn(),
) -> anyhow::Result<(Vec<ConfigTiming>, Option<ConfigTiming>)> {
    let t = &spec.timing;
    let mut entries: Vec<(usize, &Run)> = groups.iter().enumerate().map(|(i, g)| (i, g.head())).collect();
    if let Some(g) = noise {
        entries.extend((0..NOISE_VISITS).map(|_| (groups.len(), g.head())));
    }
    let mut out = vec![ConfigTiming::empty(); groups.len() + 1];
    let mut failed = vec![false; groups.len() + 1];
    t.run(entries.len(), |k| -> anyhow::Result<f64> {
        let (slot, run) = entries[k];
        if failed[slot] {
            on_frame();
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
        let timing = match backend.time(&scene, view, sampling, t.warmup, 1) {
            Ok(timing) => timing,
            Err(e) => {
                tracing::error!("timing {} failed; left untimed: {e:#}", run.config());
                failed[slot] = true;
                out[slot] = ConfigTiming::empty();
                on_frame();
                return Ok(f64::NAN);
            }
        };
        let c = &mut out[slot];
        c.frame_seconds.extend(&timing.seconds);
        c.primary_seconds.extend(&timing.primary_seconds);
        c.clock = timing.clock.name().to_string();
        on_frame();
        Ok(timing.seconds.first().copied().unwrap_or(f64::NAN))
    })?;
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
    fn comparisons_pair_by_round_and_follow_the_rule() {
        let a = timing(&[10.0, 11.0, 12.0, 13.0, 14.0]);
        let b = timing(&[15.0, 16.0, 17.0, 18.0, 19.0]);
        assert_eq!(compare(&a, &b).1, Comparison::Faster);
        assert_eq!(compare(&b, &a).1, Comparison::Slower);
        let drifting = timing(&[10.0, 20.0, 12.0, 13.0, 14.0]);
        let same = timing(&[10.5, 19.0, 12.5, 12.5, 14.5]);
        assert_eq!(compare(&drifting, &same).1, Comparison::Equal);
        assert_eq!(compare(&a, &timing(&[])).1, Comparison::Equal);
        assert!(
            compare(&a, &timing(&[1.0, 2.0])).0.median.is_nan(),
            "not timed in the same rounds"
        );
        let f = a.frame();
        assert!((f.median - 0.012).abs() < 1e-12 && f.lo <= f.median && f.hi >= f.median);
        assert!(a.primary_median().is_nan());
    }
}
