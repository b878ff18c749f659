//! Measurements of a rendered visibility image. Each formula is documented once, here or in
//! the submodule that computes it; the runner combines them into one record per run.

pub mod edge;
pub mod error;
pub mod extent;
pub mod flip;
pub mod profile;
pub mod seeds;
pub mod spectrum;
pub mod stats;
pub mod throughput;

pub use error::{penumbra_coverage, ErrorMetrics, PenumbraMask};
pub use profile::{RadialProfile, Receivers};
pub use seeds::BiasVariance;
