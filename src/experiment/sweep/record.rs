//! Records: one row of runs.csv per run, in tidy form. A record is typed data that the csv crate
//! writes and reads back (the journal resumes from it, and a resumed sweep reproduces earlier
//! rows byte for byte); each metric is defined in `metrics` or README.md.

use super::axes::Run;
use crate::accel::settings::ParameterColumns;
use crate::metrics::stats::{mean_ci, MeanCi};
use crate::output::table::{float, Float};
use crate::render::AdapterInfo;
use serde::ser::SerializeStruct;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Whether a run rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Rendered and measured.
    Ok,
    /// Failed; the record's `error` says why.
    Failed,
}

/// One row of runs.csv. Its columns are its fields' in order, each part's fields in turn: the
/// key and status, the run's axes ([`Run`], so a new axis is a new column by itself), then what
/// was measured. Values not measured (a failed run, a scene without an exact on-axis answer, an
/// untimed sweep) are NaN or `None`, empty in the table.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Hash of everything that determines the run ([`Run::key`]).
    pub run_key: String,
    /// Whether it rendered.
    pub status: Status,
    /// Its axes.
    pub run: Run,
    /// The measuring image and its radial reading.
    pub radial: Radial,
    /// The metrics summary.csv aggregates over seeds.
    pub metrics: Metrics,
    /// The radial power spectrum of its error image.
    pub spectrum: SpectrumColumns,
    /// Rays traced.
    pub rays: WorkCounts,
    /// Its configuration's frame time, from the timing phase.
    pub time: FrameTime,
    /// The scene's acceleration structure, on mesh scenes.
    pub structure: StructureColumns,
    /// Its parameters, one column each (empty without meshes).
    pub parameters: ParameterColumns,
    /// The device that rendered it.
    pub device: Device,
    /// FNV-1a of the shadow image's f32 bits: runs that differ only in the acceleration
    /// structure must give the same hash (empty when it did not render).
    pub image_fnv1a: String,
    /// Why it failed; empty when it rendered.
    pub error: String,
}

/// The columns before the run's axes.
#[derive(Serialize, Deserialize)]
struct Head {
    run_key: String,
    status: Status,
}

/// The columns after the device's.
#[derive(Serialize, Deserialize)]
struct Tail {
    image_fnv1a: String,
    error: String,
}

type Parts = (
    Head,
    Run,
    Radial,
    Metrics,
    SpectrumColumns,
    WorkCounts,
    FrameTime,
    StructureColumns,
    ParameterColumns,
    Device,
    Tail,
);

impl Serialize for Record {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let head = Head {
            run_key: self.run_key.clone(),
            status: self.status,
        };
        let tail = Tail {
            image_fnv1a: self.image_fnv1a.clone(),
            error: self.error.clone(),
        };
        (
            head,
            &self.run,
            &self.radial,
            &self.metrics,
            &self.spectrum,
            &self.rays,
            &self.time,
            &self.structure,
            &self.parameters,
            &self.device,
            tail,
        )
            .serialize(s)
    }
}

impl<'de> Deserialize<'de> for Record {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Record, D::Error> {
        let (head, run, radial, metrics, spectrum, rays, time, structure, parameters, device, tail) =
            Parts::deserialize(d)?;
        Ok(Record {
            run_key: head.run_key,
            status: head.status,
            run,
            radial,
            metrics,
            spectrum,
            rays,
            time,
            structure,
            parameters,
            device,
            image_fnv1a: tail.image_fnv1a,
            error: tail.error,
        })
    }
}

/// The measuring image's size and its radial reading: the closed-form radii, the exact image's
/// extent and 10-90 % width (read like the runs'), and the run's own extent.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Radial {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Closed-form umbra radius r_u (negative: no umbra).
    #[serde(with = "float")]
    pub exact_umbra_radius: f64,
    /// Closed-form penumbra radius r_p.
    #[serde(with = "float")]
    pub exact_penumbra_radius: f64,
    /// The exact image's visible extent, outer - inner.
    #[serde(with = "float")]
    pub exact_extent_width: f64,
    /// The exact image's 10-90 % width.
    #[serde(with = "float")]
    pub exact_width_10_90: f64,
    /// Inner edge of the run's visible extent.
    #[serde(with = "float")]
    pub extent_inner: f64,
    /// Outer edge of the run's visible extent.
    #[serde(with = "float")]
    pub extent_outer: f64,
}

impl Radial {
    /// A `width` x `height` image with no radial reading.
    pub fn unmeasured(width: u32, height: u32) -> Radial {
        Radial {
            width,
            height,
            exact_umbra_radius: f64::NAN,
            exact_penumbra_radius: f64::NAN,
            exact_extent_width: f64::NAN,
            exact_width_10_90: f64::NAN,
            extent_inner: f64::NAN,
            extent_outer: f64::NAN,
        }
    }
}

/// Declares the metrics summary.csv aggregates over seeds, once: a run's [`Metrics`] (runs.csv's
/// columns) and their [`Aggregated`] means and 95 % CI half-widths (summary.csv's `NAME_mean`
/// and `NAME_ci95` columns).
macro_rules! aggregated_metrics {
    ($($(#[$doc:meta])* $m:ident,)*) => {
        /// The metrics of a run that summary.csv aggregates over seeds.
        #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
        pub struct Metrics {
            $($(#[$doc])* #[serde(with = "float")] pub $m: f64,)*
        }

        impl Metrics {
            /// Nothing measured.
            pub const NONE: Metrics = Metrics { $($m: f64::NAN,)* };

            /// Each metric's mean and 95 % CI half-width over `runs`.
            pub fn aggregate(runs: &[&Metrics]) -> Aggregated {
                Aggregated { $($m: mean_ci(&runs.iter().map(|r| r.$m).collect::<Vec<_>>()),)* }
            }
        }

        /// Each metric of [`Metrics`] over the seeds of a configuration.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Aggregated {
            $($(#[$doc])* pub $m: MeanCi,)*
        }

        impl Serialize for Aggregated {
            fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                let mut row = s.serialize_struct("Aggregated", 2 * [$(stringify!($m)),*].len())?;
                $(
                    row.serialize_field(concat!(stringify!($m), "_mean"), &Float(self.$m.mean))?;
                    row.serialize_field(concat!(stringify!($m), "_ci95"), &Float(self.$m.ci95))?;
                )*
                row.end()
            }
        }
    };
}

aggregated_metrics! {
    /// Visible extent of the penumbra, outer - inner (m).
    extent_width,
    /// 10-90 % width of the mean radial profile (m).
    width_10_90,
    /// Mean signed profile - exact profile inside the exact extent.
    profile_bias,
    /// Mean |profile - exact profile| inside the exact extent.
    profile_abs_bias,
    /// RMSE against the ground truth over its penumbra.
    rmse,
    /// Relative MSE against the ground truth over its penumbra.
    relmse,
    /// Mean signed error against the ground truth over its penumbra.
    bias,
    /// RMSE against the exact image over the ground truth's penumbra.
    rmse_exact,
    /// The run's penumbra area over the ground truth's.
    penumbra_area_ratio,
    /// Share of the true penumbra shown fully lit or fully dark.
    penumbra_lost_share,
    /// Share of the error's power below [`crate::metrics::spectrum::LOW_CUTOFF`] cycles per
    /// pixel (white noise: 1/16).
    lowfreq_share,
    /// RMSE over the penumbra of the error after a Gaussian blur of
    /// [`crate::metrics::spectrum::BLUR_SIGMA`] pixels (what a simple denoiser leaves).
    rmse_blurred,
}

/// Declares the rings of the error's radial power spectrum as runs.csv columns, one per ring of
/// [`crate::metrics::spectrum::BIN`] cycles per pixel, so that the table stays flat.
macro_rules! spectrum_columns {
    ($($ring:ident),*) => {
        /// The mean power of the run's error image per ring of frequencies: column
        /// `error_power_NN` covers [NN, NN + 1) / 32 cycles per pixel
        /// ([`crate::metrics::spectrum::error_spectrum`]).
        #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
        pub struct SpectrumColumns {
            $(#[allow(missing_docs)] #[serde(with = "float")] pub $ring: f64,)*
        }

        impl SpectrumColumns {
            /// Not measured.
            pub const NONE: SpectrumColumns = SpectrumColumns { $($ring: f64::NAN,)* };

            /// Rings of the spectrum.
            pub const RINGS: usize = [$(stringify!($ring)),*].len();

            /// The columns of a radial spectrum of [`SpectrumColumns::RINGS`] rings.
            pub fn of(radial: &[f64]) -> SpectrumColumns {
                let mut rings = radial.iter().copied();
                SpectrumColumns { $($ring: rings.next().unwrap_or(f64::NAN),)* }
            }

            /// The ring powers, lowest frequency first.
            pub fn rings(&self) -> Vec<f64> {
                vec![$(self.$ring),*]
            }
        }
    };
}

spectrum_columns!(
    error_power_00,
    error_power_01,
    error_power_02,
    error_power_03,
    error_power_04,
    error_power_05,
    error_power_06,
    error_power_07,
    error_power_08,
    error_power_09,
    error_power_10,
    error_power_11,
    error_power_12,
    error_power_13,
    error_power_14,
    error_power_15
);

/// Rays one frame of the run traced, and what their queries cost where the backend counts it
/// (the CPU; empty on the GPU): deterministic work that does not move between runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WorkCounts {
    /// Camera rays.
    pub primary_rays: Option<u64>,
    /// Shadow rays, all lights.
    pub shadow_rays: Option<u64>,
    /// Queries asked of the scene.
    pub queries: Option<u64>,
    /// Traversal steps (nodes, tiles) of the structure.
    pub nodes_visited: Option<u64>,
    /// Primitive intersection tests (triangles and analytic shapes).
    pub primitive_tests: Option<u64>,
}

/// The frame time of the run's configuration (timed once, with its first seed).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameTime {
    /// Median frame time (s).
    #[serde(with = "float")]
    pub frame_s: f64,
    /// Lower end of its 95 % interval (s).
    #[serde(with = "float")]
    pub frame_s_lo: f64,
    /// Upper end of its 95 % interval (s).
    #[serde(with = "float")]
    pub frame_s_hi: f64,
    /// Frames timed.
    pub timed_frames: Option<usize>,
    /// All rays per second at the median frame time.
    #[serde(with = "float")]
    pub rays_per_s: f64,
    /// Camera rays per second of the primary pass.
    #[serde(with = "float")]
    pub primary_rays_per_s: f64,
    /// Shadow rays per second of the shadow passes.
    #[serde(with = "float")]
    pub shadow_rays_per_s: f64,
    /// How frames were timed (`gpu-timestamp` or `wall-clock`).
    pub clock: Option<String>,
}

impl FrameTime {
    /// Not timed.
    pub const UNTIMED: FrameTime = FrameTime {
        frame_s: f64::NAN,
        frame_s_lo: f64::NAN,
        frame_s_hi: f64::NAN,
        timed_frames: None,
        rays_per_s: f64::NAN,
        primary_rays_per_s: f64::NAN,
        shadow_rays_per_s: f64::NAN,
        clock: None,
    };
}

/// The scene's acceleration structure: its build time and GPU memory per triangle (its
/// parameters follow, [`ParameterColumns`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StructureColumns {
    /// Build time (s).
    #[serde(with = "float")]
    pub build_s: f64,
    /// GPU bytes per triangle (nodes and triangles).
    #[serde(with = "float")]
    pub gpu_bytes_per_triangle: f64,
}

impl StructureColumns {
    /// No structure (no meshes).
    pub const NONE: StructureColumns = StructureColumns {
        build_s: f64::NAN,
        gpu_bytes_per_triangle: f64::NAN,
    };
}

/// The device a run rendered on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Device {
    /// `gpu` or `cpu`.
    pub backend: String,
    /// Adapter name.
    pub adapter: String,
    /// Driver name and version.
    pub driver: String,
    /// Graphics API, or the CPU thread count.
    pub api: String,
}

impl Device {
    /// The device `a` describes.
    pub fn of(a: &AdapterInfo) -> Device {
        Device {
            backend: a.backend.clone(),
            adapter: a.name.clone(),
            driver: a.driver.clone(),
            api: a.api.clone(),
        }
    }
}
