//! Acceleration structures: the one seam for "does this segment hit a triangle, and which one
//! first" over the triangles of every mesh in a scene (pbrt-v4's `Intersect`/`IntersectP`,
//! obvhs' traversal closures).
//!
//! A structure is a Rust type implementing [`Accelerator`] for the CPU, plus a WGSL module for
//! the GPU that defines
//!
//! ```text
//! fn accel_closest(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> AccelHit
//! fn accel_any(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> bool
//! ```
//!
//! over the storage buffers it declares at `@group(2)` ([`GpuStructure`]), with `AccelHit
//! { t, triangle }` (`triangle` in input order, `NO_HIT` on a miss; `skip` is a triangle to
//! ignore) and the flag `cut_short` set where a loop ended early; it adds each node (or tile) it
//! visits to `work_nodes` and each primitive test to `work_prims`, as its CPU walk counts them
//! ([`work`]). Every structure's module may
//! use the shared triangle struct `AccelTri` and ray-triangle test `triangle_t`
//! ([`TRIANGLE_WGSL`], prepended to it). The GPU
//! backend compiles each structure's module into its own pipelines, chosen by name. Adding a
//! structure is its module, its WGSL and one line in [`REGISTRY`]. A structure may be CPU only
//! ([`Registered::gpu`] false): its [`Accelerator::gpu`] then refuses by name, and the GPU
//! backend reports that error rather than render with another structure.

pub mod brute;
pub mod bundle;
pub mod bvh;
pub mod cwbvh;
pub mod embree;
pub mod kdtree;
pub mod memory;
pub mod settings;
pub mod vlf;
pub mod work;

pub use bundle::{Issue, Query};
pub use bvh::{Bvh, Preset};
pub use settings::AccelSettings;

use crate::geometry::LocalFrame;
use crate::mesh::Triangles;
use glam::DVec3;
use serde::Deserialize;
use std::sync::Arc;
use std::time::Duration;

/// The WGSL every structure's module shares: `struct AccelTri` (the twin of [`GpuTri`]) and
/// `triangle_t(o, d, v0, e1, e2) -> f32`, the twin of [`intersect`] (-1 on a miss).
pub const TRIANGLE_WGSL: &str = include_str!("triangle.wgsl");

/// A triangle as the GPU reads it: corner 0 and the two edges from it in full f32 (the form
/// `triangle_t` takes), with its input index; 48 bytes, read in WGSL as `AccelTri`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Debug)]
pub struct GpuTri {
    /// Corner 0.
    pub v0: [f32; 3],
    _p0: u32,
    /// Corner 1 - corner 0.
    pub e1: [f32; 3],
    /// Index in input order.
    pub index: u32,
    /// Corner 2 - corner 0.
    pub e2: [f32; 3],
    _p1: u32,
}

const _: () = assert!(std::mem::size_of::<GpuTri>() == 48);

impl GpuTri {
    /// Triangle `index` (`world`, f64) in `frame`'s local coordinates: corners converted in f64,
    /// edges taken before rounding to f32.
    pub fn new(world: &[DVec3; 3], index: u32, frame: &LocalFrame) -> GpuTri {
        let p = world.map(|c| frame.point_f64(c));
        GpuTri {
            v0: p[0].as_vec3().to_array(),
            _p0: 0,
            e1: (p[1] - p[0]).as_vec3().to_array(),
            index,
            e2: (p[2] - p[0]).as_vec3().to_array(),
            _p1: 0,
        }
    }
}

/// A closest hit: distance along the (unit) ray and the triangle's index in input order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriHit {
    /// Distance.
    pub t: f64,
    /// Triangle index (input order).
    pub triangle: u32,
}

/// Möller-Trumbore ray-triangle intersection in f64; the distance, or None. Both sides hit.
pub fn intersect(origin: DVec3, dir: DVec3, tri: &[DVec3; 3]) -> Option<f64> {
    intersect_edges(origin, dir, tri[0], (tri[1] - tri[0], tri[2] - tri[0]))
}

/// [`intersect`] with the triangle's edges from corner 0 already taken (the same operations,
/// so the same t to the bit): a packet sets a triangle up once for all its rays.
#[inline]
pub fn intersect_edges(origin: DVec3, dir: DVec3, v0: DVec3, (e1, e2): (DVec3, DVec3)) -> Option<f64> {
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(e2.dot(q) * inv)
}

/// Closest hit with t > 0 by testing every triangle: the reference every structure is tested
/// against.
pub fn brute_force(triangles: &Triangles, origin: DVec3, dir: DVec3) -> Option<TriHit> {
    triangles
        .positions
        .iter()
        .enumerate()
        .filter_map(|(i, t)| {
            intersect(origin, dir, t)
                .filter(|t| *t > 0.0)
                .map(|t| TriHit { t, triangle: i as u32 })
        })
        .min_by(|a, b| a.t.total_cmp(&b.t))
}

/// Ray queries over a fixed set of triangles, in f64 on the CPU.
pub trait Accelerator: Send + Sync + std::fmt::Debug {
    /// The name it is registered under (scene files and sweeps choose by it).
    fn name(&self) -> &'static str;

    /// Closest triangle other than `skip` hit with 0 < t < `tmax` along unit `dir`.
    fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit>;

    /// Whether any triangle other than `skip` is hit with 0 < t < `tmax`; may stop at the first.
    fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool;

    /// [`Accelerator::any_hit`] for each of `queries`, issued as one bundle: `hits[i]` answers
    /// `queries[i]`. A structure that can share work across coherent rays overrides it (the
    /// field walks a direction's tiles in tile order, the kd-tree traverses packets); the
    /// answers are always the single queries'.
    fn any_hits(&self, queries: &[Query], hits: &mut [bool]) {
        for (q, h) in queries.iter().zip(hits) {
            *h = self.any_hit(q.origin, q.dir, q.tmax, q.skip);
        }
    }

    /// Whether [`Accelerator::any_hits`] is its own (not the one-at-a-time default): only then
    /// is timing its bundles a different measurement.
    fn bundles(&self) -> bool {
        false
    }

    /// What the structure cost to build and what it occupies.
    fn stats(&self) -> BuildStats;

    /// The GPU form in `frame`'s local coordinates, or an error naming the limit it exceeds.
    fn gpu(&self, frame: &LocalFrame) -> anyhow::Result<GpuStructure>;

    /// Why [`Accelerator::gpu`] would fail, where that is known without packing anything (no
    /// GPU traversal; a tree deeper than the GPU's stack): a run checks it before it chooses a
    /// backend.
    fn gpu_refusal(&self) -> Option<String> {
        None
    }

    /// Brings it up to date after the triangles of `object` moved by `step` (the scene's
    /// triangles are now `moved`, same count and order), by `method`, one of
    /// [`Accelerator::updates`]; says what it did.
    fn update(&mut self, method: UpdateMethod, moved: &Triangles, object: u32, step: DVec3) -> anyhow::Result<Updated>;
}

/// A way a structure follows triangles that moved ([`Accelerator::updates`] lists a
/// structure's); its name is the `update` column of the frames kind's tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpdateMethod {
    /// The structure's own change in place (the visibility field's, paper Section 8).
    InPlace,
    /// New bounds over the same topology (a BVH's refit).
    Refit,
    /// Built again with its own parameters.
    Rebuild,
    /// Built again with obvhs' fastest preset: what an engine would do every frame.
    RebuildFastest,
}

impl UpdateMethod {
    /// Every way, in the order structures list theirs.
    pub const ALL: [UpdateMethod; 4] = [
        UpdateMethod::InPlace,
        UpdateMethod::Refit,
        UpdateMethod::Rebuild,
        UpdateMethod::RebuildFastest,
    ];

    /// `update`, `refit`, `rebuild`, `rebuild-fastest`.
    pub fn name(self) -> &'static str {
        match self {
            UpdateMethod::InPlace => "update",
            UpdateMethod::Refit => "refit",
            UpdateMethod::Rebuild => "rebuild",
            UpdateMethod::RebuildFastest => "rebuild-fastest",
        }
    }
}

/// What an update of moved triangles did to a structure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Updated {
    /// Kept its topology and refitted its bounds (a BVH refit).
    Refit,
    /// Changed in place where the object was and is (the field's Section 8 update).
    InPlace,
    /// Was built again from the moved triangles.
    Rebuilt,
}

impl Updated {
    /// `refit`, `in-place`, `rebuild`.
    pub fn name(self) -> &'static str {
        match self {
            Updated::Refit => "refit",
            Updated::InPlace => "in-place",
            Updated::Rebuilt => "rebuild",
        }
    }
}

/// Refuses an update method a structure does not offer.
pub(crate) fn unknown_update(structure: &dyn Accelerator, method: UpdateMethod) -> anyhow::Error {
    let offered: Vec<&str> = registered(structure.name())
        .map_or(&[][..], |r| r.updates)
        .iter()
        .map(|m| m.name())
        .collect();
    anyhow::anyhow!(
        "{} cannot update by `{}`; it offers {}",
        structure.name(),
        method.name(),
        offered.join(", ")
    )
}

/// Build cost and size, for records and reports.
#[derive(Debug, Clone, PartialEq)]
pub struct BuildStats {
    /// The build parameters in a few words (a BVH's preset name).
    pub parameters: String,
    /// Wall-clock build time, everything included.
    pub build_time: Duration,
    /// Bytes the GPU form occupies.
    pub gpu_bytes: u64,
    /// Bytes the structure's CPU form occupies beyond the triangles every structure keeps (its
    /// memory cost in comparisons).
    pub memory_bytes: u64,
    /// Triangles indexed.
    pub triangles: usize,
    /// One sentence for the report: kind, size, build time, memory.
    pub description: String,
}

/// A structure's GPU buffers: bound read-only at `@group(2)`, binding i for `buffers[i]`.
pub struct GpuStructure {
    /// (label, bytes) per buffer, in binding order.
    pub buffers: Vec<(&'static str, Vec<u8>)>,
    /// Loop iterations budgeted for one any-hit query on adapters that cap loops (a query that
    /// runs over is caught as cut short, and the frame redone with fewer samples per dispatch).
    pub walk_iterations: u32,
}

/// One registered structure.
pub struct Registered {
    /// Name in scene files and sweeps.
    pub name: &'static str,
    /// Its WGSL module (see the module doc for the interface); empty where it has none.
    pub wgsl: &'static str,
    /// Whether it has a GPU form. A structure without one (`wgsl` empty) is refused by its
    /// [`Accelerator::gpu`] with an error naming it, which the GPU backend meets before compiling
    /// anything: it never falls back to another structure.
    pub gpu: bool,
    /// Storage buffers its WGSL declares at `@group(2)`.
    pub gpu_buffers: u32,
    /// Its parameters from its table, validated and completed with defaults, or the key that
    /// is wrong and why ([`settings::validate`] over its typed [`settings::Params`]).
    pub params: fn(&toml::Table) -> Result<toml::Table, (String, String)>,
    /// The grid it is tuned over where an experiment lists none ([`settings::Params::tuning`]).
    pub tuning: fn() -> toml::Table,
    /// Builds it over `triangles`, or says which limit the scene exceeds.
    pub build: fn(&Triangles, &AccelSettings) -> anyhow::Result<Arc<dyn Accelerator>>,
    /// A lower bound on the bytes it takes over this many triangles with these settings
    /// ([`memory::check`] refuses a build that cannot fit).
    pub memory: fn(usize, &AccelSettings) -> u64,
    /// The ball (centre, radius) a structure built over these triangles can follow moved
    /// triangles within, where it has one (the field's directions are fixed to its ball).
    pub follows_within: Option<Region>,
    /// The ways it can follow triangles that moved, its own first (a field's update in place,
    /// paper Section 8; a BVH's refit; a rebuild): what [`Accelerator::update`] takes, and how
    /// many copies of it a moving scene times.
    pub updates: &'static [UpdateMethod],
    /// Whether its answers are the f64 reference's (every structure whose leaves run the
    /// project's f64 triangle test): experiments require an exact structure's images to equal
    /// the others' bit for bit, and count where an inexact one's (Embree's f32 tests) differ.
    pub exact: bool,
    /// Whether its CPU walk counts nodes and primitive tests ([`work`]); where not (Embree
    /// exposes no counters), tables leave those columns empty rather than write zeros.
    pub counts_work: bool,
}

/// The ball (centre, radius) a structure built over some triangles can follow them within.
pub type Region = fn(&[[DVec3; 3]]) -> (DVec3, f64);

/// Every acceleration structure, the default first.
pub const REGISTRY: &[Registered] = &[
    Registered {
        name: "bvh",
        wgsl: bvh::WGSL,
        gpu: true,
        gpu_buffers: 2,
        params: settings::validate::<bvh::BvhSettings>,
        tuning: <bvh::BvhSettings as settings::Params>::tuning,
        build: |t, s| Ok(Arc::new(Bvh::build(t, s.typed::<bvh::BvhSettings>().preset))),
        // Two 32-byte nodes and an index per triangle, f32 and f64 copies of the triangles.
        memory: |n, _| n as u64 * (64 + 4 + 48 + 72),
        follows_within: None,
        // A refit keeps the tree's topology (cheap; the tree decays as things move); a rebuild
        // with its own preset; a rebuild with obvhs' fastest preset, what an engine would do per
        // frame (the fastest tree to build, slower to walk).
        updates: &[UpdateMethod::Refit, UpdateMethod::Rebuild, UpdateMethod::RebuildFastest],
        exact: true,
        counts_work: true,
    },
    Registered {
        name: "brute",
        wgsl: brute::WGSL,
        gpu: true,
        gpu_buffers: 1,
        params: settings::validate::<brute::BruteSettings>,
        tuning: <brute::BruteSettings as settings::Params>::tuning,
        build: |t, _| Ok(Arc::new(brute::Brute::build(t))),
        memory: |n, _| n as u64 * 72,
        follows_within: None,
        updates: &[UpdateMethod::Rebuild],
        exact: true,
        counts_work: true,
    },
    Registered {
        name: "vlf",
        wgsl: vlf::WGSL,
        gpu: true,
        gpu_buffers: vlf::GPU_BUFFERS,
        params: settings::validate::<vlf::VlfSettings>,
        tuning: <vlf::VlfSettings as settings::Params>::tuning,
        build: |t, s| Ok(Arc::new(vlf::VisibilityField::build(t, s.typed())?)),
        memory: |n, s| vlf::min_bytes(n, &s.typed()),
        follows_within: Some(vlf::ball),
        // The object's ids removed from every tile it covered and inserted again where it now
        // is (paper Section 8).
        updates: &[UpdateMethod::InPlace],
        exact: true,
        counts_work: true,
    },
    Registered {
        name: "kdtree",
        wgsl: kdtree::WGSL,
        gpu: true,
        gpu_buffers: kdtree::GPU_BUFFERS,
        params: settings::validate::<kdtree::KdSettings>,
        tuning: <kdtree::KdSettings as settings::Params>::tuning,
        build: |t, s| {
            Ok(Arc::new(
                kdtree::KdTree::within(t, s.typed(), kdtree_entries()).map_err(anyhow::Error::msg)?,
            ))
        },
        // A leaf entry per triangle at least, and the f64 copy.
        memory: |n, _| n as u64 * (4 + 72),
        follows_within: None,
        updates: &[UpdateMethod::Rebuild],
        exact: true,
        counts_work: true,
    },
    Registered {
        name: "kdtree-sah",
        wgsl: kdtree::WGSL,
        gpu: true,
        gpu_buffers: kdtree::GPU_BUFFERS,
        params: kdtree::sah_params,
        tuning: kdtree::sah_tuning,
        build: |t, s| {
            Ok(Arc::new(
                kdtree::KdTree::within(t, s.typed(), kdtree_entries())
                    .map_err(anyhow::Error::msg)?
                    .named("kdtree-sah"),
            ))
        },
        memory: |n, _| n as u64 * (4 + 72),
        follows_within: None,
        updates: &[UpdateMethod::Rebuild],
        exact: true,
        counts_work: true,
    },
    Registered {
        name: "cwbvh",
        wgsl: cwbvh::WGSL,
        gpu: true,
        gpu_buffers: 2,
        params: settings::validate::<cwbvh::CwbvhSettings>,
        tuning: <cwbvh::CwbvhSettings as settings::Params>::tuning,
        build: |t, s| {
            Ok(Arc::new(cwbvh::Cwbvh::build(
                t,
                s.typed::<cwbvh::CwbvhSettings>().preset,
            )))
        },
        // A primitive slot per triangle at least, and the f64 copy.
        memory: |n, _| n as u64 * (4 + 72),
        follows_within: None,
        updates: &[UpdateMethod::Rebuild],
        exact: true,
        counts_work: true,
    },
    Registered {
        name: "embree",
        wgsl: "",
        gpu: false,
        gpu_buffers: 0,
        params: settings::validate::<embree::EmbreeSettings>,
        tuning: <embree::EmbreeSettings as settings::Params>::tuning,
        build: |t, _| Ok(Arc::new(embree::Embree::build(t, embree::Quality::High)?)),
        // Its vertex and index buffers (48 bytes a triangle), the f64 copy, and at least a
        // leaf reference per triangle.
        memory: |n, _| n as u64 * (48 + 72 + 4),
        follows_within: None,
        updates: &[UpdateMethod::Rebuild],
        exact: false,
        counts_work: false,
    },
];

/// The registered structure called `name`.
pub fn registered(name: &str) -> Option<&'static Registered> {
    REGISTRY.iter().find(|r| r.name == name)
}

/// Whether structure `name` answers as the f64 reference does ([`Registered::exact`]); a name
/// outside the registry is taken as exact, so nothing is excused from the bit-for-bit check.
pub fn is_exact(name: &str) -> bool {
    registered(name).is_none_or(|r| r.exact)
}

/// Whether structure `name` counts its walk's nodes and tests ([`Registered::counts_work`]); a
/// name outside the registry is taken as counting.
pub fn counts_work(name: &str) -> bool {
    registered(name).is_none_or(|r| r.counts_work)
}

/// Registered names, for messages.
pub fn names() -> Vec<&'static str> {
    REGISTRY.iter().map(|r| r.name).collect()
}

/// Builds the structure `settings` names over `triangles`; `None` for no triangles. A
/// structure that cannot fit in the memory available is refused before it is built.
pub fn build(triangles: &Triangles, settings: &AccelSettings) -> anyhow::Result<Option<Arc<dyn Accelerator>>> {
    let r = registered(settings.name).expect("settings hold a registered name");
    if triangles.positions.is_empty() {
        return Ok(None);
    }
    let n = triangles.positions.len();
    memory::check(settings, n, memory::available()).map_err(anyhow::Error::msg)?;
    if n < LARGE_BUILD {
        return (r.build)(triangles, settings).map(Some);
    }
    // A build is one call that reports nothing until it returns: say that it started, that it
    // is still going every PROGRESS_SECONDS, and what it took.
    tracing::info!("building {} over {n} triangles", r.name);
    let started = std::time::Instant::now();
    let (done, waiting) = std::sync::mpsc::channel::<()>();
    let name = r.name;
    let watch = std::thread::spawn(move || {
        while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) =
            waiting.recv_timeout(std::time::Duration::from_secs(PROGRESS_SECONDS))
        {
            tracing::info!(
                "still building {name} over {n} triangles ({:.0} s so far)",
                started.elapsed().as_secs_f64()
            );
        }
    });
    let built = (r.build)(triangles, settings);
    drop(done);
    let _ = watch.join();
    tracing::info!("built {} in {:.1} s", r.name, started.elapsed().as_secs_f64());
    built.map(Some)
}

/// Leaf entries a kd-tree build may make: a quarter of the memory budget at 4 bytes each (the
/// build holds its triangle lists besides), where a budget is known.
pub(crate) fn kdtree_entries() -> usize {
    memory::available().map_or(kdtree::MAX_ENTRIES, |b| (b.bytes / 16) as usize)
}

/// Triangle count from which a build says when it starts, how it goes and what it took.
pub const LARGE_BUILD: usize = 200_000;

/// Seconds between a large build's progress lines.
const PROGRESS_SECONDS: u64 = 15;

/// An accelerator name as written in a scene file.
#[derive(Debug, Clone, Deserialize, PartialEq, Eq)]
#[serde(transparent)]
pub struct AccelName(pub String);

impl Default for AccelName {
    fn default() -> Self {
        AccelName(REGISTRY[0].name.to_string())
    }
}
