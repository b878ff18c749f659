//! Frame-rate experiments (`kind = "fps"`): the soft-shadow paper's Table 1 (frames per second
//! over 100 frames, 16 shadow rays per pixel, sphere and dressed body, one and two lights) on
//! today's adapter, with the paper's numbers beside ours.

pub mod report;
pub mod runner;
pub mod spec;

pub use runner::{run_fps, FpsRow};
pub use spec::{timed_scene, FpsScene, FpsSpec};
