//! Real-time reconstruction of a shadow image from few rays: temporal accumulation
//! ([`accumulate`]), the guides a filter reads ([`GBuffer`], the blocker estimate in
//! [`penumbra`]), and the spatial filters ([`Filter`]) that every [`crate::render::Backend`] runs,
//! the CPU in f64 ([`cpu`]) and the GPU in WGSL compute (`gpu/shaders/denoise.wgsl`).
//!
//! A filter reads one accumulated shadow image, its per-sample temporal variance, the G-buffer
//! and a per-pixel kernel width; it writes one image. Pixels without a receiver
//! ([`crate::render::NO_RECEIVER`]) are neither read nor written.

pub mod accumulate;
pub mod cpu;
pub mod gbuffer;
pub mod penumbra;

pub use accumulate::{Accumulation, Accumulator, BlockerHistory};
pub use gbuffer::GBuffer;

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// A reconstruction filter: an axis value of real-time experiments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Filter {
    /// The accumulated image as it is.
    None,
    /// A Gaussian of fixed standard deviation ([`FilterSettings::gaussian_sigma`]) over receiver
    /// pixels, blind to depth and normals: the naive filter.
    Gaussian,
    /// Edge-avoiding a-trous wavelet filter guided by depth, normal and the temporal variance
    /// (Schied et al. 2017, SVGF, eqs. 1-5): 5 x 5 B3-spline taps at steps 1, 2, 4, ...
    Atrous,
    /// An oriented Gaussian whose size follows the penumbra's estimated width from the shadow
    /// rays' blocker distances (Boksansky, Wimmer & Bittner 2019, "Ray Traced Shadows:
    /// Maintaining Real-Time Frame Rates", Ray Tracing Gems ch. 13), depth- and normal-aware:
    /// wide along the shadow's edge, where visibility does not change, and narrow across it, so
    /// that it averages noise without widening the penumbra ([`penumbra`]).
    Penumbra,
}

impl Filter {
    /// Every filter, in report order.
    pub const ALL: [Filter; 4] = [Filter::None, Filter::Gaussian, Filter::Atrous, Filter::Penumbra];

    /// The name in experiment files and tables.
    pub fn name(self) -> &'static str {
        match self {
            Filter::None => "none",
            Filter::Gaussian => "gaussian",
            Filter::Atrous => "atrous",
            Filter::Penumbra => "penumbra",
        }
    }
}

impl fmt::Display for Filter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Filter {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Filter::ALL.into_iter().find(|f| f.name() == s).ok_or_else(|| {
            let names: Vec<&str> = Filter::ALL.iter().map(|f| f.name()).collect();
            format!("unknown filter `{s}`; one of {}", names.join(", "))
        })
    }
}

/// The filters' parameters, read from an experiment's `[filters]` table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FilterSettings {
    /// Standard deviation of the fixed Gaussian, pixels.
    pub gaussian_sigma: f64,
    /// A-trous iterations (steps 1, 2, ..., 2^(n-1); SVGF uses 5).
    pub atrous_iterations: u32,
    /// SVGF's sigma_l: how many local standard deviations a value difference may span.
    pub atrous_sigma_luminance: f64,
    /// SVGF's sigma_z: depth differences allowed, in units of the local depth change per pixel.
    pub atrous_sigma_depth: f64,
    /// SVGF's sigma_n: the exponent of the normals' cosine.
    pub atrous_sigma_normal: f64,
    /// The penumbra filter's standard deviation along the edge, as a share of the estimated
    /// penumbra width.
    pub penumbra_scale: f64,
    /// Largest standard deviation the penumbra filter uses, pixels.
    pub penumbra_max_sigma: f64,
}

impl Default for FilterSettings {
    fn default() -> Self {
        FilterSettings {
            gaussian_sigma: 1.5,
            atrous_iterations: 4,
            atrous_sigma_luminance: 4.0,
            atrous_sigma_depth: 1.0,
            atrous_sigma_normal: 128.0,
            penumbra_scale: 0.5,
            penumbra_max_sigma: 8.0,
        }
    }
}

impl FilterSettings {
    /// What is wrong with the settings, as (key, message).
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        let positive = |key: &'static str, v: f64, max: f64| {
            if v.is_finite() && v > 0.0 && v <= max {
                Ok(())
            } else {
                Err((key, format!("must be positive and at most {max}, got {v}")))
            }
        };
        positive("gaussian_sigma", self.gaussian_sigma, MAX_SIGMA)?;
        positive("atrous_sigma_luminance", self.atrous_sigma_luminance, 1e6)?;
        positive("atrous_sigma_depth", self.atrous_sigma_depth, 1e6)?;
        positive("atrous_sigma_normal", self.atrous_sigma_normal, 1e4)?;
        positive("penumbra_scale", self.penumbra_scale, 1e3)?;
        positive("penumbra_max_sigma", self.penumbra_max_sigma, MAX_SIGMA)?;
        if !(1..=8).contains(&self.atrous_iterations) {
            return Err((
                "atrous_iterations",
                format!("must be in 1..=8, got {}", self.atrous_iterations),
            ));
        }
        Ok(())
    }
}

/// Largest Gaussian standard deviation any filter takes, pixels (its window is 3 sigma wide).
pub const MAX_SIGMA: f64 = 16.0;

/// Half-width of a Gaussian window of standard deviation `sigma` pixels: 3 sigma, rounded up, in
/// f32 as the WGSL kernels round it (an f64 3 sigma can land just above a whole number that the
/// f32 one equals, and the windows would differ by a ring).
pub fn gaussian_radius(sigma: f64) -> i32 {
    (3.0f32 * sigma as f32).ceil() as i32
}

/// Below this standard deviation (pixels) along the edge the penumbra filter leaves a pixel as
/// it is: a Gaussian that narrow puts over 99 % of its weight on the pixel itself.
pub const MIN_SIGMA: f64 = 0.25;

/// Standard deviation (pixels) of the window the penumbra filter reads the edge's direction
/// from: wide enough that a few rays a pixel give a direction even across a 2-pixel penumbra,
/// narrow enough that a curved edge's direction is its local one (13 x 13 taps).
pub const DIRECTION_SIGMA: f64 = 2.0;

/// Below this length of the penumbra filter's regression vector, sum w (I_q - mean) (q - p) over
/// its [`DIRECTION_SIGMA`] window, over the window's weight, a neighbourhood has no edge
/// direction: a slope of about 1e-6 / sigma^2
/// per pixel. It catches flat and exactly symmetric neighbourhoods only; under noise the
/// direction is whatever the noise leaves.
pub const DIRECTIONLESS: f64 = 1e-6;

/// What a filter reads: one accumulated image and its guides, all row-major over one view.
#[derive(Clone, Copy, Debug)]
pub struct Input<'a> {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The accumulated shadow image, [`crate::render::NO_RECEIVER`] where no receiver.
    pub image: &'a [f32],
    /// Per-pixel variance of one frame's value (SVGF's luminance variance), the a-trous guide.
    pub variance: &'a [f32],
    /// Depth, normal and pixel footprint of the surface each pixel sees.
    pub gbuffer: &'a GBuffer,
    /// Per-pixel standard deviation (pixels) of the penumbra filter's Gaussian along the edge,
    /// from the blocker estimate ([`penumbra::kernel_sigma`]); 0 where no blocker was seen
    /// nearby.
    pub sigma: &'a [f32],
    /// The filters' parameters.
    pub settings: FilterSettings,
}

impl Input<'_> {
    /// Pixel count.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Whether pixel `i` has a receiver.
    pub fn receives(&self, i: usize) -> bool {
        self.image[i] != crate::render::NO_RECEIVER
    }

    /// The taps `filter` reads: window entries visited over every receiver pixel, the work that
    /// explains its time (the same loops on both backends).
    pub fn taps(&self, filter: Filter) -> u64 {
        let receivers = (0..self.pixels()).filter(|&i| self.receives(i)).count() as u64;
        let window = |r: i32| ((2 * r + 1) * (2 * r + 1)) as u64;
        match filter {
            Filter::None => 0,
            Filter::Gaussian => receivers * window(gaussian_radius(self.settings.gaussian_sigma)),
            Filter::Atrous => receivers * 25 * self.settings.atrous_iterations as u64,
            // The direction's window, then four pixels per step of the line (an upper bound: a
            // pixel whose window shows no direction stops after the window).
            Filter::Penumbra => (0..self.pixels())
                .filter(|&i| self.receives(i) && self.sigma[i] as f64 >= MIN_SIGMA)
                .map(|i| {
                    let along = self.sigma[i] as f64;
                    window(gaussian_radius(DIRECTION_SIGMA)) + 4 * (2 * gaussian_radius(along) as u64 + 1)
                })
                .sum(),
        }
    }
}

/// A filter's result.
#[derive(Clone, Debug)]
pub struct Output {
    /// The filtered image.
    pub image: Vec<f32>,
    /// Taps read ([`Input::taps`]).
    pub taps: u64,
}

/// The B3-spline weights of one a-trous axis (SVGF's 5 x 5 kernel is their outer product).
pub const B3: [f64; 5] = [1.0 / 16.0, 1.0 / 4.0, 3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0];

/// Added to the a-trous luminance weight's denominator so zero variance stops every difference
/// larger than about this much (SVGF's epsilon).
pub const LUMINANCE_EPSILON: f64 = 1e-3;
