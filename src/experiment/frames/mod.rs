//! Frame-time experiments (`kind = "frames"`): the visibility-field paper's scaling (Fig. 5),
//! walkthrough (Fig. 6) and dynamic-scene claims, measured per acceleration structure.

pub mod report;
pub mod runner;
pub mod spec;
pub mod verdict;

pub use runner::run_frames;
pub use spec::FramesSpec;
