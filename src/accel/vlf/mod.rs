//! A visibility field (VLF-RT: Mortensen, Khanna, Yu, Slater, "A Visibility Field for Ray
//! Tracing", 2007): for each of a fixed set of directions
//! (lines), the scene seen along that direction through `n x n` parallel beams (a parallel
//! subfield), each beam listing the triangles it meets, partitioned along the beam by a 1-D tile
//! BSP. A query picks the nearest stored direction in constant time, walks the few tiles its
//! segment crosses and tests the triangles of the leaves between its ends, near to far.
//!
//! Trades memory and build time for traversal with no tree descent. Answers are exactly brute
//! force's: candidates are tested with [`crate::accel::intersect`] on the original world-space
//! triangles, and every bound is widened (by [`EPS`] of the ball radius) so the candidate set
//! is a superset.
//!
//! # Spaces
//! The scene is normalised into the unit ball: `p_ball = (p - centre) / radius` ([`UnitBall`]; the
//! ball's radius is the farthest vertex from the bounding-box centre). Direction `k`'s rotation
//! rows `a, b, w` ([`directions::Directions::rows`]) take it to canonical space, where the beams
//! run along `+z` and tile `(tx, ty)` of `n` covers `x_ball, y_ball` in
//! `[-1 + 2 tx / n, -1 + 2 (tx + 1) / n]` (and likewise y). A ray along `-w` uses `w`'s tiles
//! and walks its leaves in reverse.
//!
//! # Flat arrays
//! All u32/u16/f32/f64 `Vec`s, addressable with u32 indices:
//! - `directions.table` (u32, `side^2`), `directions.rows` (f64, 9 per direction; f32 on the GPU);
//! - per layer ([`layer::Layer`], layout in its module doc): the tile offsets (a u16 per tile
//!   under a u32 per row of tiles, or a u32 per tile where a row is too full), and `words`:
//!   each tile's entries (triangle id and its footprint box on a 16 x 16 sub-grid of the tile,
//!   so most candidates are dropped with four compares; one word each while ids fit 16 bits),
//!   a split tile's led by its split values and its leaves' bounds;
//! - the frame: `centre` (3), `radius`, and the settings `tiles`, `depth`, `split`.
//!
//! On the GPU (`gpu.rs`, `vlf.wgsl`) the same words are read, with one u32 offset per tile. Sizes
//! on the body (32K triangles, 513 directions, 128^2 tiles, leaf size 32) at depth 2: tile
//! offsets 17 MB, split headers 16 MB, entries 190 MB (223 MB; 333 MB in the first layout's
//! 6-byte entries and u32 offsets); the words are bound in chunks of whole directions under wgpu's
//! portable 128 MiB storage-binding size.
//!
//! The base layer indexes every triangle; a second, small layer holds objects inserted or moved
//! since the build ([`dynamic`]), and removed triangles' entries are marked removed in place.

pub mod bsp;
mod bundle;
pub mod directions;
pub mod dynamic;
mod gpu;
pub mod layer;
pub mod query;
pub mod raster;

pub use bsp::Split;
pub use gpu::GPU_BUFFERS;

/// Its WGSL: `accel_closest` and `accel_any` as one tile walk ([`gpu`] lays out the buffers).
pub const WGSL: &str = include_str!("vlf.wgsl");

use super::{Accelerator, BuildStats, GpuStructure, TriHit};
use crate::geometry::LocalFrame;
use crate::mesh::Triangles;
use directions::Directions;
use glam::DVec3;
use layer::Layer;
use std::time::{Duration, Instant};

/// Relative widening of every bound, in ball radii (tile squares, depth ranges, the ball).
/// Far above f64 rounding of scenes within ~1e6 radii of their origin, far below a tile.
pub const EPS: f64 = 1e-6;

/// Build parameters (paper Section 6 fixes 513 directions and 128 x 128 tiles; tile-BSP depth
/// 3-5 was best there). With the per-entry footprint boxes, depth 2 was faster still on the
/// body (0.93-1.05 against 0.84-0.92 Mrays/s AO any-hit, 370 MB against 445 MB in the first
/// layout; 223 MB against 318 MB in today's).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VlfSettings {
    /// Direction subdivision level `L`: `2 L^2 + 1` directions (16 gives the paper's 513).
    pub level: u32,
    /// Tiles per side of each parallel subfield.
    pub tiles: u32,
    /// Tile-BSP depth: `2^depth` leaves per split tile (0: no splits).
    pub depth: u32,
    /// Uniform slabs or median splits.
    pub split: Split,
    /// Tiles with at most this many triangles stay a plain list (no leaves stored).
    pub leaf_size: u32,
}

impl Default for VlfSettings {
    fn default() -> Self {
        VlfSettings {
            level: 16,
            tiles: 128,
            depth: 4,
            split: Split::Uniform,
            // Measured on the body (513 dirs, 128^2, depth 4, first layout): 32 gives 445 MB and 0.92 Mrays/s
            // AO any-hit where 8 gave 600 MB and 0.84 (fewer split tiles, fewer duplicates).
            leaf_size: 32,
        }
    }
}

impl crate::accel::settings::Params for VlfSettings {
    fn check(&self) -> Result<(), (&'static str, String)> {
        for (key, value, (lo, hi)) in [
            ("level", self.level, (1, 64)),
            ("tiles", self.tiles, (1, 1024)),
            ("depth", self.depth, (0, 6)),
        ] {
            if !(lo..=hi).contains(&value) {
                return Err((key, format!("must lie in {lo}..={hi}, got {value}")));
            }
        }
        Ok(())
    }

    /// Tile-BSP depths around the paper's best (3-5).
    fn tuning() -> toml::Table {
        toml::toml! {
            depth = [2, 3, 4, 5]
        }
    }
}

impl VlfSettings {
    /// The parameters in a few words.
    pub fn describe(&self) -> String {
        format!(
            "level {} ({} dirs), {}x{} tiles, depth {} {}, leaf size {}",
            self.level,
            2 * self.level * self.level + 1,
            self.tiles,
            self.tiles,
            self.depth,
            self.split.name(),
            self.leaf_size
        )
    }
}

/// The normalisation into the unit ball and the directions: what every layer shares.
#[derive(Clone, Debug)]
pub struct UnitBall {
    /// Ball centre in world space (the triangles' bounding-box centre).
    pub centre: DVec3,
    /// Ball radius in world units (farthest vertex from `centre`).
    pub radius: f64,
    /// 1 / radius.
    pub inv_radius: f64,
    /// Tiles per side / 2 (tile units per ball unit).
    pub half_tiles: f64,
    /// The stored directions and their lookup table.
    pub directions: Directions,
}

/// A built visibility field over a scene's triangles.
#[derive(Clone, Debug)]
pub struct VisibilityField {
    /// Parameters built with.
    pub settings: VlfSettings,
    /// Ball and directions.
    pub frame: UnitBall,
    /// Every triangle of the build.
    pub base: Layer,
    /// Triangles inserted or moved since ([`dynamic`]).
    pub overlay: Layer,
    /// World-space triangles (f64), in input order (moved objects updated in place).
    pub world: Vec<[DVec3; 3]>,
    /// `world` packed for the exact test ([`query::pack`]): 9 f64 per triangle.
    pub tri: Vec<f64>,
    /// Owner per triangle.
    pub object_of: Vec<u32>,
    /// Whether the base layer still indexes triangle i (false once its object moved or was
    /// removed).
    pub in_base: Vec<bool>,
    /// Triangles in the overlay.
    pub overlay_ids: Vec<u32>,
    /// Wall-clock time of the whole build.
    pub build_time: Duration,
}

/// The ball a field over `world` is built in: centred on the triangles' bounding box, out to
/// the farthest vertex. Dynamic updates must stay inside it.
pub fn ball(world: &[[DVec3; 3]]) -> (DVec3, f64) {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in world.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let centre = if lo.is_finite() { 0.5 * (lo + hi) } else { DVec3::ZERO };
    let radius = world
        .iter()
        .flatten()
        .map(|p| p.distance(centre))
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE.sqrt());
    (centre, radius)
}

/// A lower bound on the field's peak bytes while it is built over `triangles` triangles: its
/// build writes a 4-byte offset per tile of every direction (compacted to 2 bytes at the end)
/// and at least a 4-byte entry (id and footprint box) per triangle per direction, and holds
/// them twice (every direction's part, then the merged arrays); besides, the packed triangles.
pub fn min_bytes(triangles: usize, s: &VlfSettings) -> u64 {
    let directions = 2 * s.level as u64 * s.level as u64 + 1;
    let arrays = directions * (s.tiles as u64).pow(2) * 4 + triangles as u64 * directions * 4;
    2 * arrays + triangles as u64 * 72
}

impl VisibilityField {
    /// Builds the field over `triangles` (an empty list gives a field that never hits).
    pub fn build(triangles: &Triangles, settings: VlfSettings) -> anyhow::Result<VisibilityField> {
        let start = Instant::now();
        anyhow::ensure!(
            settings.tiles >= 1
                && (settings.tiles as u64).pow(2) * (2 * settings.level as u64 * settings.level as u64 + 1)
                    < u32::MAX as u64,
            "visibility field: {} directions x {}^2 tiles do not fit u32 tile offsets",
            2 * settings.level * settings.level + 1,
            settings.tiles
        );
        anyhow::ensure!(
            settings.depth <= 10,
            "visibility field: tile-BSP depth {} above 10",
            settings.depth
        );
        let world = triangles.positions.clone();
        anyhow::ensure!(
            world.len() < u32::MAX as usize,
            "visibility field: {} triangles do not fit u32 indices",
            world.len()
        );
        let (centre, radius) = ball(&world);
        let frame = UnitBall {
            centre,
            radius,
            inv_radius: 1.0 / radius,
            half_tiles: settings.tiles as f64 * 0.5,
            directions: Directions::new(settings.level),
        };
        let all: Vec<u32> = (0..world.len() as u32).collect();
        let base = Layer::build(&world, &all, &frame, &settings)?;
        Ok(VisibilityField {
            settings,
            frame,
            base,
            overlay: Layer::default(),
            in_base: vec![true; world.len()],
            tri: world.iter().flat_map(query::pack).collect(),
            world,
            object_of: triangles.object_of.clone(),
            overlay_ids: Vec::new(),
            build_time: start.elapsed(),
        })
    }

    /// Closest triangle other than `skip` hit with 0 < t < `tmax` along unit `dir`.
    pub fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        let ray = self.tile_ray(origin, dir, tmax)?;
        let mut best = (f64::INFINITY, u32::MAX);
        self.closest_in(&self.base, &ray, origin, dir, tmax, skip, &mut best);
        if !self.overlay_ids.is_empty() {
            self.closest_in(&self.overlay, &ray, origin, dir, tmax, skip, &mut best);
        }
        (best.1 != u32::MAX).then_some(TriHit {
            t: best.0,
            triangle: best.1,
        })
    }

    /// Whether any triangle other than `skip` is hit with 0 < t < `tmax`; stops at the first.
    pub fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        let Some(ray) = self.tile_ray(origin, dir, tmax) else {
            return false;
        };
        self.any_in(&self.base, &ray, origin, dir, tmax, skip)
            || (!self.overlay_ids.is_empty() && self.any_in(&self.overlay, &ray, origin, dir, tmax, skip))
    }

    /// Bytes of the structure's arrays (both layers, the table and rotations; not the
    /// triangles, which every structure needs).
    pub fn bytes(&self) -> usize {
        self.parts().iter().map(|p| p.1).sum()
    }

    /// [`VisibilityField::bytes`] by part: the base layer's tile offsets, split-tile headers
    /// and entries, the overlay layer, and the direction table with its rotations.
    pub fn parts(&self) -> [(&'static str, usize); 5] {
        let [offsets, headers, entries] = self.base.parts();
        [
            offsets,
            headers,
            entries,
            ("overlay", self.overlay.bytes()),
            (
                "directions",
                4 * self.frame.directions.table.len() + 8 * self.frame.directions.rows.len(),
            ),
        ]
    }
}

impl Accelerator for VisibilityField {
    fn name(&self) -> &'static str {
        "vlf"
    }

    fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        VisibilityField::closest(self, origin, dir, tmax, skip)
    }

    fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        VisibilityField::any_hit(self, origin, dir, tmax, skip)
    }

    fn any_hits(&self, queries: &[crate::accel::Query], hits: &mut [bool]) {
        VisibilityField::any_hits(self, queries, hits)
    }

    fn bundles(&self) -> bool {
        true
    }

    fn stats(&self) -> BuildStats {
        let bytes = self.bytes();
        let entries = self.base.entries();
        let parts: Vec<String> = self
            .parts()
            .iter()
            .map(|(part, b)| format!("{part} {:.1} MB", *b as f64 / 1e6))
            .collect();
        BuildStats {
            parameters: self.settings.describe(),
            build_time: self.build_time,
            gpu_bytes: gpu::bytes(self) as u64,
            memory_bytes: bytes as u64,
            triangles: self.world.len(),
            description: format!(
                "visibility field ({}): {} tile entries ({:.1} per triangle per direction), {} split tiles, built in {:.1} ms; {:.1} MB ({:.0} bytes per triangle: {})",
                self.settings.describe(),
                entries,
                entries as f64 / (self.world.len().max(1) * self.frame.directions.len()) as f64,
                self.base.split_tiles(),
                self.build_time.as_secs_f64() * 1e3,
                bytes as f64 / 1e6,
                bytes as f64 / self.world.len().max(1) as f64,
                parts.join(", ")
            ),
        }
    }

    fn gpu(&self, frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
        gpu::structure(self, frame)
    }

    /// The field moves its own copy of the object; the scene's moved triangles must be that
    /// copy, bit for bit, or the field would answer for triangles the scene no longer has.
    fn update(
        &mut self,
        method: crate::accel::UpdateMethod,
        moved: &Triangles,
        object: u32,
        step: DVec3,
    ) -> anyhow::Result<crate::accel::Updated> {
        if method != crate::accel::UpdateMethod::InPlace {
            return Err(crate::accel::unknown_update(self, method));
        }
        self.move_object(object, |p| p + step)?;
        anyhow::ensure!(
            moved.positions.len() == self.world.len()
                && moved
                    .object_of
                    .iter()
                    .zip(&moved.positions)
                    .zip(&self.world)
                    .all(|((&o, m), w)| o != object || m == w),
            "the visibility field's copy of object {object} moved by {step} differs from the scene's moved triangles"
        );
        Ok(crate::accel::Updated::InPlace)
    }
}
