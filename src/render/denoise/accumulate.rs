//! Temporal accumulation of one pixel's values over frames, with the first and second moments a
//! variance-guided filter reads (SVGF's temporal integration, Schied et al. 2017, sec. 4.1)
//! ([`Accumulator`]), and, apart from it, of the blocker distances a light's shadow rays met,
//! which the penumbra filter sizes its kernel by ([`BlockerHistory`]).
//! The camera is fixed, so a pixel's history is its own (no reprojection); a moving occluder
//! leaves behind the ghost that the lag metric measures.

use crate::render::NO_RECEIVER;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// How frames are combined: an axis value of real-time experiments.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Accumulation {
    /// The running mean of every frame so far: converges on a static scene, never forgets.
    Mean,
    /// Exponential moving average with weight `alpha` on the newest frame, and 1/k while the
    /// history holds k < 1/alpha frames (as SVGF does), so the first frames are not
    /// underweighted.
    Ema(f64),
}

impl Accumulation {
    /// The name in tables: `mean` or `ema`.
    pub fn name(self) -> &'static str {
        match self {
            Accumulation::Mean => "mean",
            Accumulation::Ema(_) => "ema",
        }
    }

    /// The newest frame's weight when the history holds `k` frames, itself included.
    pub fn weight(self, k: u32) -> f64 {
        let mean = 1.0 / k.max(1) as f64;
        match self {
            Accumulation::Mean => mean,
            Accumulation::Ema(alpha) => alpha.max(mean),
        }
    }
}

impl fmt::Display for Accumulation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Accumulation {
    type Err = String;

    /// `mean`, or `ema` (its alpha is set separately).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "mean" => Ok(Accumulation::Mean),
            "ema" => Ok(Accumulation::Ema(f64::NAN)),
            _ => Err(format!("unknown accumulation `{s}`; one of mean, ema")),
        }
    }
}

/// One view's accumulated image history: per pixel the moments of its frames' values.
#[derive(Clone, Debug)]
pub struct Accumulator {
    mode: Accumulation,
    frames: u32,
    /// Frames in each pixel's history: a pixel that had no receiver starts afresh when it gets one.
    history: Vec<u32>,
    m1: Vec<f64>,
    m2: Vec<f64>,
}

impl Accumulator {
    /// An empty history of `pixels` pixels.
    pub fn new(mode: Accumulation, pixels: usize) -> Accumulator {
        Accumulator {
            mode,
            frames: 0,
            history: vec![0; pixels],
            m1: vec![0.0; pixels],
            m2: vec![0.0; pixels],
        }
    }

    /// Frames added so far.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// Adds one frame: its shadow image (`NO_RECEIVER` where none).
    pub fn add(&mut self, image: &[f32]) {
        self.frames += 1;
        for (i, &v) in image.iter().enumerate() {
            if v == NO_RECEIVER {
                self.m1[i] = NO_RECEIVER as f64;
                self.history[i] = 0;
                continue;
            }
            self.history[i] += 1;
            let w = self.mode.weight(self.history[i]);
            let v = v as f64;
            self.m1[i] += w * (v - self.m1[i]);
            self.m2[i] += w * (v * v - self.m2[i]);
        }
    }

    /// The accumulated image.
    pub fn image(&self) -> Vec<f32> {
        self.m1.iter().map(|&v| v as f32).collect()
    }

    /// Per pixel, the variance of one frame's value from the temporal moments (m2 - m1^2).
    pub fn variance(&self) -> Vec<f32> {
        self.m1
            .iter()
            .zip(&self.m2)
            .map(|(&m1, &m2)| if m1 < 0.0 { 0.0 } else { (m2 - m1 * m1).max(0.0) as f32 })
            .collect()
    }

    /// The variance the a-trous filter is guided by: the temporal one where a pixel's history
    /// holds four frames (SVGF, sec. 4.2), before that the spatial variance of the accumulated
    /// image over the receiver pixels of a 5 x 5 window.
    pub fn variance_or_spatial(&self, width: u32, height: u32) -> Vec<f32> {
        let temporal = self.variance();
        let (w, h) = (width as i64, height as i64);
        (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if self.m1[i as usize] < 0.0 {
                    return 0.0;
                }
                if self.history[i as usize] >= 4 {
                    return temporal[i as usize];
                }
                let (mut s1, mut s2, mut n) = (0.0, 0.0, 0.0);
                for qy in (y - 2).max(0)..=(y + 2).min(h - 1) {
                    for qx in (x - 2).max(0)..=(x + 2).min(w - 1) {
                        let v = self.m1[(qy * w + qx) as usize];
                        if v >= 0.0 {
                            (s1, s2, n) = (s1 + v, s2 + v * v, n + 1.0);
                        }
                    }
                }
                (s2 / n - (s1 / n) * (s1 / n)).max(0.0) as f32
            })
            .collect()
    }
}

/// One light's accumulated blocker distances, combined over frames as the image is
/// ([`Accumulation`]) but counting, per pixel, only the frames where some shadow ray met a
/// blocker; kept apart from the image's history, which it never changes.
#[derive(Clone, Debug)]
pub struct BlockerHistory {
    mode: Accumulation,
    blocker: Vec<f64>,
    blocked_frames: Vec<u32>,
}

impl BlockerHistory {
    /// An empty history of `pixels` pixels.
    pub fn new(mode: Accumulation, pixels: usize) -> BlockerHistory {
        BlockerHistory {
            mode,
            blocker: vec![f64::NAN; pixels],
            blocked_frames: vec![0; pixels],
        }
    }

    /// Adds one frame: per pixel, the mean distance to the blockers its shadow rays met (NaN
    /// where none met one), at the pixels with a receiver in its shadow image (`NO_RECEIVER`
    /// where none: those keep their history).
    pub fn add(&mut self, image: &[f32], blocker: &[f64]) {
        for (i, &v) in image.iter().enumerate() {
            if v == NO_RECEIVER || !blocker[i].is_finite() {
                continue;
            }
            self.blocked_frames[i] += 1;
            let w = self.mode.weight(self.blocked_frames[i]);
            let old = if self.blocker[i].is_nan() {
                blocker[i]
            } else {
                self.blocker[i]
            };
            self.blocker[i] = old + w * (blocker[i] - old);
        }
    }

    /// Per pixel, the accumulated blocker distance (NaN where no shadow ray met a blocker).
    pub fn blocker(&self) -> &[f64] {
        &self.blocker
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mean_is_the_mean_and_the_ema_forgets_geometrically() {
        let frames = [0.0f32, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 0.0];
        let mut mean = Accumulator::new(Accumulation::Mean, 1);
        let mut ema = Accumulator::new(Accumulation::Ema(0.25), 1);
        let mut reference = 0.0;
        for (k, &v) in frames.iter().enumerate() {
            mean.add(&[v]);
            ema.add(&[v]);
            // Direct: alpha = max(0.25, 1/k).
            let w = (1.0 / (k + 1) as f64).max(0.25);
            reference = (1.0 - w) * reference + w * v as f64;
        }
        let exact_mean = frames.iter().map(|&v| v as f64).sum::<f64>() / frames.len() as f64;
        assert!((mean.image()[0] as f64 - exact_mean).abs() < 1e-7);
        assert!((ema.image()[0] as f64 - reference).abs() < 1e-7);
        // Bernoulli frames: the temporal variance of the mean history is p (1 - p).
        assert!((mean.variance()[0] as f64 - exact_mean * (1.0 - exact_mean)).abs() < 1e-7);
    }

    #[test]
    fn a_pixel_that_gains_a_receiver_starts_its_history_afresh() {
        let mut a = Accumulator::new(Accumulation::Mean, 1);
        a.add(&[NO_RECEIVER]);
        a.add(&[0.25]);
        a.add(&[0.75]);
        assert_eq!(a.image(), vec![0.5]);
    }

    #[test]
    fn pixels_without_a_receiver_stay_without() {
        let mut a = Accumulator::new(Accumulation::Ema(0.1), 2);
        let mut b = BlockerHistory::new(Accumulation::Ema(0.1), 2);
        for (image, blocker) in [([NO_RECEIVER, 0.5], [1.0, 2.0]), ([NO_RECEIVER, 0.5], [1.0, 4.0])] {
            a.add(&image);
            b.add(&image, &blocker);
        }
        assert_eq!(a.image(), vec![NO_RECEIVER, 0.5]);
        assert_eq!(a.variance()[0], 0.0);
        assert!(b.blocker()[0].is_nan());
        assert!((b.blocker()[1] - 3.0).abs() < 1e-12);
    }

    #[test]
    fn blocker_distances_average_over_the_frames_that_met_a_blocker() {
        let mut b = BlockerHistory::new(Accumulation::Mean, 1);
        for blocker in [2.0, f64::NAN, 4.0] {
            b.add(&[0.5], &[blocker]);
        }
        assert!((b.blocker()[0] - 3.0).abs() < 1e-12);
    }
}
