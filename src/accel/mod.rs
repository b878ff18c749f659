//! Acceleration structures for ray queries against triangle meshes. [`bvh`] wraps obvhs' BVH2
//! (PLOC build) for the CPU and lays it out for the WGSL traversal in
//! `render/gpu/shaders/bvh.wgsl`.

pub mod bvh;

pub use bvh::{Bvh, Preset};
