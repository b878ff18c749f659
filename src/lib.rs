//! # penumbra
//!
//! A measurement harness for ray-traced soft shadows. An experiment file names a scene and the
//! axes to sweep (sampling scheme x pattern x shadow-ray count x light radius x seed); the
//! harness renders every combination on the GPU (wgpu compute) or the f64 CPU reference,
//! measures penumbra width and noise against a high-sample ground truth that is itself checked
//! against an exact answer, and writes CSV, plots and a report.
//!
//! ```
//! use penumbra::sampling::{DiskScheme, Site};
//! // The soft-shadow paper's 16 "pseudo-random" targets (eq. 2 + 3): the centre first.
//! let pts = DiskScheme::Paper.points(16, Site::pixel(1, 0, [0, 0], 0, 0));
//! assert_eq!(pts[0], glam::DVec2::ZERO);
//! assert!(pts[1..].iter().all(|p| p.length() >= 0.3 - 1e-12 && p.length() <= 1.0));
//! ```

pub mod accel;
pub mod config;
pub mod experiment;
pub mod files;
pub mod fingerprint;
pub mod geometry;
pub mod mesh;
pub mod metrics;
pub mod output;
pub mod peers;
pub mod reference;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod timing;
