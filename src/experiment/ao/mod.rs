//! Ambient-occlusion experiments (`kind = "ao"`): the visibility-field paper's Table 1 (513 AO
//! rays per camera hit, 256 x 256) timed for each acceleration structure at its best settings
//! on the same meshes, with the paper's numbers beside ours and a verdict on its claim that
//! VLF-RT beats a CRT kd-tree (by 1.45-2.51x), and on how it fares against a modern BVH.

pub mod report;
pub mod runner;
pub mod spec;

pub use runner::{run_ao, AoRow, TuningRow};
pub use spec::AoSpec;
