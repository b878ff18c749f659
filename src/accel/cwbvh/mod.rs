//! obvhs' compressed wide BVH (CWBVH: eight children per node, child boxes quantised to 8 bits;
//! Ylitie, Karras & Laine 2017, "Efficient Incoherent Ray Traversal on GPUs Through Compressed
//! Wide BVHs"), built by obvhs as its own `build_cwbvh_from_tris` builds it and walked by obvhs'
//! traversal (its `traverse!` loop and SIMD node test), with the project's f64 triangle test at
//! the leaves as [`super::Bvh`] has: the modern BVH the visibility field is set against.
//!
//! Two things stand between obvhs' traversal and exact answers, both handled where the ray is
//! made ([`ray`]): the node test's treatment of -0.0 direction components (an obvhs bug: such rays
//! miss every child box), and its floor of 1e-4 on entry distances. The tree's boxes are widened
//! by a few f32 ulps of the scene's size before quantisation, as the BVH2's are, so the f32 walk
//! never culls a hit the f64 test finds.
//!
//! On the GPU the same nodes are walked by `cwbvh.wgsl` ([`gpu`]): a stack walk that tests a
//! node's eight children at once and visits inner children near to far, with f32 triangle
//! tests.

mod gpu;
pub mod ray;

/// The CWBVH's WGSL: `accel_closest` and `accel_any` over its node and triangle buffers.
pub const WGSL: &str = include_str!("cwbvh.wgsl");

use super::bvh::{centre, relative, widened, Preset};
use super::{intersect, work, Accelerator, BuildStats, GpuStructure, TriHit};
use crate::geometry::LocalFrame;
use crate::mesh::Triangles;
use glam::{DVec3, UVec2, Vec3};
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ploc::PlocBuilder;
use obvhs::splits::split_aabbs_preset;
use obvhs::triangle::Triangle;
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};

/// The CWBVH's parameters (`[accel.cwbvh]`): obvhs' build preset.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CwbvhSettings {
    /// Build preset (`slow` and `very-slow` pre-split large triangles).
    pub preset: Preset,
}

impl super::settings::Params for CwbvhSettings {
    fn check(&self) -> Result<(), (&'static str, String)> {
        Ok(())
    }

    /// Every obvhs preset, fastest build to best tree.
    fn tuning() -> toml::Table {
        toml::toml! {
            preset = ["fastest", "very-fast", "fast", "medium", "slow", "very-slow"]
        }
    }
}

/// A CWBVH over a scene's triangles.
#[derive(Clone)]
pub struct Cwbvh {
    /// The obvhs tree, in coordinates relative to `centre`, its boxes widened.
    pub tree: CwBvh,
    /// Triangles in f64 world space, in input order.
    pub world: Vec<[DVec3; 3]>,
    /// Origin of the tree's coordinates.
    pub centre: DVec3,
    /// The root box in world coordinates.
    bounds: (DVec3, DVec3),
    /// The preset used.
    pub preset: Preset,
    /// Wall-clock build time, conversion to f32 included.
    pub build_time: Duration,
}

/// obvhs' BVH2 before conversion, built as `build_cwbvh_from_tris` builds it (PLOC over the
/// triangles' boxes, or their pre-split pieces, then reinsertion; no leaf collapse).
fn bvh2(local: &[Triangle], preset: Preset) -> Bvh2 {
    let config = preset.params();
    let mut bvh2 = if config.pre_split {
        let mut aabbs: Vec<Aabb> = local.iter().map(|t| t.aabb()).collect();
        let largest = aabbs.iter().map(Aabb::half_area).fold(0.0f32, f32::max);
        let average = aabbs.iter().map(Aabb::half_area).sum::<f32>() / aabbs.len() as f32;
        let mut indices: Vec<u32> = (0..local.len() as u32).collect();
        split_aabbs_preset(&mut aabbs, &mut indices, local, average, largest);
        PlocBuilder::with_capacity(aabbs.len()).build(
            config.ploc_search_distance,
            &aabbs,
            indices,
            config.sort_precision,
            config.search_depth_threshold,
        )
    } else {
        PlocBuilder::with_capacity(local.len()).build(
            config.ploc_search_distance,
            local,
            (0..local.len() as u32).collect(),
            config.sort_precision,
            config.search_depth_threshold,
        )
    };
    bvh2.uses_spatial_splits = config.pre_split;
    ReinsertionOptimizer::default().run(&mut bvh2, config.reinsertion_batch_ratio, None);
    bvh2
}

impl Cwbvh {
    /// Builds the tree over `triangles` with `preset`.
    pub fn build(triangles: &Triangles, preset: Preset) -> Cwbvh {
        let start = Instant::now();
        let centre = centre(&triangles.positions);
        let local = relative(&triangles.positions, centre);
        let tree = if local.is_empty() {
            CwBvh::default()
        } else {
            let wide = widened(&bvh2(&local, preset));
            bvh2_to_cwbvh(&wide, preset.params().max_prims_per_leaf.clamp(1, 3), true, false)
        };
        let root = tree.total_aabb;
        let bounds = (
            Vec3::from(root.min).as_dvec3() + centre,
            Vec3::from(root.max).as_dvec3() + centre,
        );
        Cwbvh {
            tree,
            world: triangles.positions.clone(),
            centre,
            bounds,
            preset,
            build_time: start.elapsed(),
        }
    }

    /// Walks the tree with obvhs' traversal along the walk ray of `origin + t dir`, calling
    /// `test(slot)` for each primitive slot it reaches: `Some(t)` shortens the walk to `t` (its
    /// parameter), `Some(NEG_INFINITY)` ends it. Counts nodes whose children it tests and
    /// primitive tests ([`crate::accel::work`]).
    #[inline]
    fn walk(&self, origin: DVec3, dir: DVec3, tmax: f64, mut test: impl FnMut(usize, f64) -> Option<f32>) {
        if self.world.is_empty() {
            return;
        }
        let Some((mut ray, s)) = ray::shifted(self.bounds.0, self.bounds.1, self.centre, origin, dir, tmax) else {
            return;
        };
        let (mut nodes, mut prims) = (0u64, 0u64);
        let mut state = self.tree.new_traversal(ray.direction);
        let mut node;
        'walk: {
            obvhs::traverse!(
                self.tree,
                node,
                state,
                {
                    nodes += 1;
                    node.intersect_ray(&ray, state.oct_inv4)
                },
                {
                    prims += 1;
                    match test(state.primitive_id as usize, s) {
                        Some(t) if t == f32::NEG_INFINITY => break 'walk,
                        Some(t) => ray.tmax = ray.tmax.min(t),
                        None => {}
                    }
                }
            );
        }
        work::add(nodes, prims);
    }

    /// Closest triangle other than `skip` hit with 0 < t < `tmax` along unit `dir`, ties to the
    /// lower index.
    pub fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        let mut best: Option<TriHit> = None;
        self.walk(origin, dir, tmax, |slot, s| {
            let tri = self.tree.primitive_indices[slot];
            match intersect(origin, dir, &self.world[tri as usize]) {
                Some(t)
                    if tri != skip
                        && t > 0.0
                        && t < tmax
                        && best.is_none_or(|b| t < b.t || (t == b.t && tri < b.triangle)) =>
                {
                    best = Some(TriHit { t, triangle: tri });
                    // The walk's new far end, in its parameter, rounded outwards (a tie is
                    // still tested).
                    Some(((t - s) + (t - s).abs() * 1e-6 + 1e-30) as f32)
                }
                _ => None,
            }
        });
        best
    }

    /// Whether any triangle other than `skip` is hit with 0 < t < `tmax`; stops at the first.
    pub fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        let mut hit = false;
        self.walk(origin, dir, tmax, |slot, _| {
            let tri = self.tree.primitive_indices[slot];
            match intersect(origin, dir, &self.world[tri as usize]) {
                Some(t) if tri != skip && t > 0.0 && t < tmax => {
                    hit = true;
                    Some(f32::NEG_INFINITY)
                }
                _ => None,
            }
        });
        hit
    }

    /// Bytes of nodes (80 each) and primitive slots.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.tree.nodes.as_slice()) + 4 * self.tree.primitive_indices.len()
    }
}

impl Accelerator for Cwbvh {
    fn name(&self) -> &'static str {
        "cwbvh"
    }

    fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        Cwbvh::closest(self, origin, dir, tmax, skip)
    }

    fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        Cwbvh::any_hit(self, origin, dir, tmax, skip)
    }

    fn stats(&self) -> BuildStats {
        let n = self.world.len();
        BuildStats {
            parameters: self.preset.name().to_string(),
            build_time: self.build_time,
            gpu_bytes: gpu::bytes(self),
            memory_bytes: self.bytes() as u64,
            triangles: n,
            description: format!(
                "CWBVH (obvhs, preset `{}`, obvhs' traversal, f64 triangle tests; a stack walk of \
                 the same nodes on the GPU): {} nodes of 8 children, {:.2} primitive slots per \
                 triangle, {:.1} bytes per triangle, built in {:.1} ms",
                self.preset.name(),
                self.tree.nodes.len(),
                self.tree.primitive_indices.len() as f64 / n.max(1) as f64,
                self.bytes() as f64 / n.max(1) as f64,
                self.build_time.as_secs_f64() * 1e3
            ),
        }
    }

    fn gpu(&self, frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
        gpu::structure(self, frame)
    }

    fn gpu_refusal(&self) -> Option<String> {
        gpu::too_deep(gpu::depth(&self.tree))
    }

    fn update(
        &mut self,
        method: super::UpdateMethod,
        moved: &Triangles,
        _object: u32,
        _step: DVec3,
    ) -> anyhow::Result<super::Updated> {
        match method {
            super::UpdateMethod::Rebuild => *self = Cwbvh::build(moved, self.preset),
            m => return Err(super::unknown_update(self, m)),
        }
        Ok(super::Updated::Rebuilt)
    }
}

impl std::fmt::Debug for Cwbvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Cwbvh({} triangles, {} nodes, {})",
            self.world.len(),
            self.tree.nodes.len(),
            self.preset.name()
        )
    }
}
