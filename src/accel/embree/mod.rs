//! Intel Embree 3 (Wald et al. 2014, "Embree: A Kernel Framework for Efficient CPU Ray
//! Tracing") as an acceleration structure: the system library's BVH build and its SIMD
//! traversal and triangle tests, called one ray at a time (`rtcIntersect1`, `rtcOccluded1`)
//! from the CPU backend's threads, so a researcher can set the visibility field, the kd-trees
//! and obvhs' BVHs against the kernel production CPU renderers use.
//!
//! Embree answers in f32 where every other structure here tests triangles in f64: its triangle
//! is chosen by its own f32 test (rays that graze an edge or start within f32 rounding of a
//! surface can be decided otherwise than by the f64 reference), and the distance of that
//! triangle is then recomputed by the f64 test where it hits in f64 as well, so a hit point
//! is as precise as the other structures' whichever triangle was chosen. The structure is
//! therefore registered as not exact ([`super::Registered::exact`]): experiments count where its
//! images differ instead of failing on it. Triangles are stored relative to their bounding
//! box's centre, as the BVHs store theirs, so f32 keeps the scene's detail wherever it sits.
//!
//! Embree exposes no traversal counters in its release builds (only builds configured with
//! `EMBREE_STAT_COUNTERS` keep them), so its rows count queries but leave nodes and primitive
//! tests empty ([`super::Registered::counts_work`]). Its memory is what its device allocated
//! (a memory-monitor callback), less the vertex and index buffers this module hands it. CPU
//! only: Embree has no WGSL form.

mod ffi;

use super::{intersect, Accelerator, BuildStats, GpuStructure, TriHit};
use crate::geometry::LocalFrame;
use crate::mesh::Triangles;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::ffi::{c_void, CString};
use std::sync::atomic::{AtomicI64, Ordering};
use std::time::{Duration, Instant};

/// Embree's build quality (`RTCBuildQuality`): `low` builds a Morton-code BVH, `medium` a
/// binned-SAH BVH (Embree's default), `high` adds spatial splits. The registered structure
/// builds at `high`, as renderers build static scenes; the others are for tests and benches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Quality {
    /// `RTC_BUILD_QUALITY_LOW`.
    Low,
    /// `RTC_BUILD_QUALITY_MEDIUM`.
    Medium,
    /// `RTC_BUILD_QUALITY_HIGH`.
    #[default]
    High,
}

impl Quality {
    fn code(self) -> u32 {
        match self {
            Quality::Low => 0,
            Quality::Medium => 1,
            Quality::High => 2,
        }
    }

    /// `low`, `medium`, `high`.
    pub fn name(self) -> &'static str {
        match self {
            Quality::Low => "low",
            Quality::Medium => "medium",
            Quality::High => "high",
        }
    }
}

/// Embree has no parameters in scene and experiment files (`[accel.embree]` is empty): it
/// builds at [`Quality::High`] without the robust flag. (Each parameter of a registered
/// structure is a column of every table that lists build parameters.)
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EmbreeSettings {}

impl super::settings::Params for EmbreeSettings {
    fn check(&self) -> Result<(), (&'static str, String)> {
        Ok(())
    }
}

/// Bytes Embree's device holds, as its memory monitor reports them.
struct Monitor {
    bytes: AtomicI64,
}

unsafe extern "C" fn monitor(user: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: `user` is the structure's boxed Monitor, which outlives its device.
    let m = unsafe { &*(user as *const Monitor) };
    m.bytes.fetch_add(bytes as i64, Ordering::Relaxed);
    true
}

/// A query's context: Embree's followed by the triangle to ignore, which the filter reads.
#[repr(C)]
struct SkipContext {
    base: ffi::IntersectContext,
    skip: u32,
}

/// Drops every candidate hit on the context's `skip` triangle (the receiver a ray leaves).
unsafe extern "C" fn skip_filter(args: *const ffi::FilterArguments) {
    // SAFETY: Embree passes N valid flags and an SoA hit block of N lanes; the context is the
    // SkipContext the query was issued with (its first field is Embree's context).
    unsafe {
        let args = &*args;
        let skip = (*(args.context as *const SkipContext)).skip;
        let n = args.n as usize;
        let prim = (args.hit as *const u32).add(5 * n);
        for i in 0..n {
            if *args.valid.add(i) != 0 && *prim.add(i) == skip {
                *args.valid.add(i) = 0;
            }
        }
    }
}

/// An Embree scene over a scene's triangles.
pub struct Embree {
    device: ffi::Handle,
    scene: ffi::Handle,
    /// Keeps the monitor's counter alive while the device may call it.
    monitor: Box<Monitor>,
    /// Triangles in f64 world space, in input order (the distance of the chosen triangle).
    world: Vec<[DVec3; 3]>,
    /// Origin of Embree's coordinates.
    centre: DVec3,
    quality: Quality,
    build_time: Duration,
    /// Device bytes after the build, less the vertex and index buffers.
    bytes: u64,
}

// SAFETY: a committed Embree scene answers queries from any number of threads at once (Embree's
// API guarantees rtcIntersect1/rtcOccluded1 are thread-safe after rtcCommitScene), and it is
// changed only through `&mut self`.
unsafe impl Send for Embree {}
unsafe impl Sync for Embree {}

/// Bytes of the vertex (three f32 corners a triangle) and index buffers handed to Embree.
const BUFFER_BYTES_PER_TRIANGLE: u64 = 36 + 12;

impl Embree {
    /// Builds an Embree scene over `triangles` at `quality`, on one thread (queries then come
    /// from as many threads as the CPU backend runs).
    pub fn build(triangles: &Triangles, quality: Quality) -> anyhow::Result<Embree> {
        let api = ffi::api().map_err(anyhow::Error::msg)?;
        // One build thread: Embree's parallel builders may order a leaf's triangles otherwise
        // from run to run, and a tie (two triangles at one t) would then be broken otherwise.
        let config = CString::new("threads=1,verbose=0").expect("no NUL");
        let device = api.device(&config).map_err(anyhow::Error::msg)?;
        // The build is timed from here: a renderer makes its device once (the process's first
        // takes 0.6 s here, starting Embree's task scheduler; later ones milliseconds).
        let start = Instant::now();
        let monitor = Box::new(Monitor {
            bytes: AtomicI64::new(0),
        });
        // SAFETY: the device is live; the monitor box outlives it (released in Drop first).
        unsafe {
            (api.set_device_memory_monitor)(device, Some(self::monitor), &*monitor as *const Monitor as *mut c_void)
        };
        let centre = super::bvh::centre(&triangles.positions);
        let mut embree = Embree {
            device,
            scene: std::ptr::null_mut(),
            monitor,
            world: triangles.positions.clone(),
            centre,
            quality,
            build_time: Duration::ZERO,
            bytes: 0,
        };
        embree.commit(api).map_err(anyhow::Error::msg)?;
        embree.build_time = start.elapsed();
        let held = embree.monitor.bytes.load(Ordering::Relaxed).max(0) as u64;
        embree.bytes = held.saturating_sub(BUFFER_BYTES_PER_TRIANGLE * embree.world.len() as u64);
        Ok(embree)
    }

    /// A new scene over `world`: one triangle geometry, committed.
    fn commit(&mut self, api: &ffi::Api) -> Result<(), String> {
        let n = self.world.len();
        // SAFETY: the device is live; every buffer Embree returns holds the items asked for.
        unsafe {
            let scene = (api.new_scene)(self.device);
            api.check(self.device, "creating a scene")?;
            self.scene = scene;
            (api.set_scene_flags)(scene, ffi::SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
            (api.set_scene_build_quality)(scene, self.quality.code());
            let geometry = (api.new_geometry)(self.device, ffi::GEOMETRY_TYPE_TRIANGLE);
            api.check(self.device, "creating a triangle geometry")?;
            (api.set_geometry_build_quality)(geometry, self.quality.code());
            let vertices =
                (api.set_new_geometry_buffer)(geometry, ffi::BUFFER_TYPE_VERTEX, 0, ffi::FORMAT_FLOAT3, 12, 3 * n)
                    as *mut [f32; 3];
            let indices = (api.set_new_geometry_buffer)(geometry, ffi::BUFFER_TYPE_INDEX, 0, ffi::FORMAT_UINT3, 12, n)
                as *mut [u32; 3];
            if let Err(e) = api.check(self.device, &format!("allocating buffers for {n} triangles")) {
                (api.release_geometry)(geometry);
                return Err(e);
            }
            for (i, tri) in self.world.iter().enumerate() {
                for (k, corner) in tri.iter().enumerate() {
                    *vertices.add(3 * i + k) = (*corner - self.centre).as_vec3().to_array();
                }
                let first = 3 * i as u32;
                *indices.add(i) = [first, first + 1, first + 2];
            }
            (api.commit_geometry)(geometry);
            (api.attach_geometry)(scene, geometry);
            (api.release_geometry)(geometry);
            (api.commit_scene)(scene);
            api.check(self.device, &format!("building over {n} triangles"))
        }
    }

    /// Embree's ray for `origin + t dir`, 0 < t < `tmax`, in its coordinates; None where the
    /// segment is empty or not finite in f32 (Embree's release builds do not check rays, and a
    /// NaN would walk its tree as it pleases), which no triangle can be hit on.
    fn ray(&self, origin: DVec3, dir: DVec3, tmax: f64) -> Option<ffi::Ray> {
        let (org, dir) = ((origin - self.centre).as_vec3(), dir.as_vec3());
        let positive = tmax > 0.0; // false for NaN
        if self.world.is_empty() || !positive || !org.is_finite() || !dir.is_finite() {
            return None;
        }
        Some(ffi::Ray {
            org: org.to_array(),
            tnear: 0.0,
            dir: dir.to_array(),
            time: 0.0,
            // Embree keeps hits at t <= tfar; the segment ends before tmax.
            tfar: below(tmax),
            mask: u32::MAX,
            id: 0,
            flags: 0,
        })
    }

    fn context(skip: u32) -> SkipContext {
        SkipContext {
            base: ffi::IntersectContext::new((skip != u32::MAX).then_some(skip_filter as ffi::FilterFunction)),
            skip,
        }
    }
}

/// The largest f32 below `t` (infinity stays infinite).
fn below(t: f64) -> f32 {
    let f = t as f32;
    if f as f64 >= t && f.is_finite() && f > 0.0 {
        f32::from_bits(f.to_bits() - 1)
    } else {
        f
    }
}

/// Why Embree has no GPU form, as both GPU refusals say it.
const NO_GPU: &str = "`embree` has no GPU form (Embree is a CPU library)";

impl Accelerator for Embree {
    fn name(&self) -> &'static str {
        "embree"
    }

    fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        let ray = self.ray(origin, dir, tmax)?;
        let api = ffi::api().expect("opened when built");
        let mut rayhit = ffi::RayHit {
            ray,
            hit: ffi::Hit {
                ng: [0.0; 3],
                u: 0.0,
                v: 0.0,
                prim_id: ffi::INVALID_ID,
                geom_id: ffi::INVALID_ID,
                inst_id: [ffi::INVALID_ID],
            },
        };
        let mut context = Self::context(skip);
        // SAFETY: the scene is committed; the context pointer is the whole SkipContext's, as
        // the filter reads it.
        unsafe { (api.intersect1)(self.scene, (&raw mut context).cast(), &mut rayhit) };
        if rayhit.hit.geom_id == ffi::INVALID_ID {
            return None;
        }
        let triangle = rayhit.hit.prim_id;
        // The chosen triangle's distance in f64 where its f64 test hits it inside the segment;
        // else (an edge graze decided otherwise in f32) Embree's own.
        let t = intersect(origin, dir, &self.world[triangle as usize])
            .filter(|t| *t > 0.0 && *t < tmax)
            .unwrap_or(rayhit.ray.tfar as f64);
        Some(TriHit { t, triangle })
    }

    fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        let Some(mut ray) = self.ray(origin, dir, tmax) else {
            return false;
        };
        let api = ffi::api().expect("opened when built");
        let mut context = Self::context(skip);
        // SAFETY: as in `closest`; an occluded ray comes back with tfar = -inf.
        unsafe { (api.occluded1)(self.scene, (&raw mut context).cast(), &mut ray) };
        ray.tfar == f32::NEG_INFINITY
    }

    fn stats(&self) -> BuildStats {
        let n = self.world.len();
        BuildStats {
            parameters: format!("quality={}", self.quality.name()),
            build_time: self.build_time,
            gpu_bytes: 0,
            memory_bytes: self.bytes,
            triangles: n,
            description: format!(
                "Embree 3 (system library, build quality `{}` on one thread; f32 traversal and \
                 triangle tests, the chosen triangle's distance in f64; CPU only): {:.1} bytes per \
                 triangle allocated by Embree beyond its vertex and index buffers (its allocator's \
                 blocks, leaf triangle copies included; not the f64 copy every structure keeps), \
                 built in {:.1} ms; no traversal counters",
                self.quality.name(),
                self.bytes as f64 / n.max(1) as f64,
                self.build_time.as_secs_f64() * 1e3
            ),
        }
    }

    fn gpu(&self, _frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
        anyhow::bail!("{NO_GPU}; choose bvh, cwbvh, kdtree or vlf for the GPU backend")
    }

    fn gpu_refusal(&self) -> Option<String> {
        Some(NO_GPU.into())
    }

    fn update(
        &mut self,
        method: super::UpdateMethod,
        moved: &Triangles,
        _object: u32,
        _step: DVec3,
    ) -> anyhow::Result<super::Updated> {
        match method {
            super::UpdateMethod::Rebuild => *self = Embree::build(moved, self.quality)?,
            m => return Err(super::unknown_update(self, m)),
        }
        Ok(super::Updated::Rebuilt)
    }
}

impl Drop for Embree {
    fn drop(&mut self) {
        if let Ok(api) = ffi::api() {
            // SAFETY: the handles are live and released once; the scene before its device.
            unsafe {
                if !self.scene.is_null() {
                    (api.release_scene)(self.scene);
                }
                (api.release_device)(self.device);
            }
        }
    }
}

impl std::fmt::Debug for Embree {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Embree({} triangles, quality {})",
            self.world.len(),
            self.quality.name()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::brute_force;
    use rayon::prelude::*;

    fn random(seed: u32) -> impl FnMut() -> f64 {
        let mut rng = seed;
        move || {
            rng = crate::sampling::rng::pcg(rng);
            crate::sampling::rng::to_unit(rng)
        }
    }

    /// 3000 seeded triangles of about 5 cm in the unit cube, placed 1000 m from the origin (so
    /// f32 keeps their detail only through the structure's centring).
    fn soup() -> Triangles {
        let mut next = random(1);
        let far = DVec3::new(1000.0, -1000.0, 500.0);
        let positions: Vec<[DVec3; 3]> = (0..3000)
            .map(|_| {
                let c = far + DVec3::new(next(), next(), next());
                [0, 1, 2].map(|_| c + 0.05 * DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5))
            })
            .collect();
        let n = positions.len();
        Triangles {
            positions,
            object_of: vec![0; n],
        }
    }

    /// How far inside `tri` (barycentric, negative outside) the line `o + t d` crosses its plane.
    fn margin(o: DVec3, d: DVec3, tri: &[DVec3; 3]) -> f64 {
        let (e1, e2) = (tri[1] - tri[0], tri[2] - tri[0]);
        let p = d.cross(e2);
        let inv = 1.0 / e1.dot(p);
        let s = o - tri[0];
        let u = s.dot(p) * inv;
        let v = d.dot(s.cross(e1)) * inv;
        u.min(v).min(1.0 - u - v)
    }

    /// Against brute force in f64 on seeded rays: the same triangle and, for it, the f64
    /// distance to the bit, except on rays that cross an edge of one of the two triangles
    /// within f32 rounding (a barycentric margin under 1e-4); those must be rare.
    #[test]
    fn agrees_with_f64_brute_force_but_within_f32_rounding_of_edges() {
        let tris = soup();
        for quality in [Quality::High, Quality::Medium, Quality::Low] {
            let e = Embree::build(&tris, quality).unwrap();
            let mut next = random(2);
            let centre = DVec3::new(1000.5, -999.5, 500.5);
            let (mut hits, mut grazes) = (0, 0);
            for k in 0..20_000 {
                let target = centre + DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
                let d = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
                let o = target - d * 2.0;
                let (got, want) = (e.closest(o, d, f64::INFINITY, u32::MAX), brute_force(&tris, o, d));
                hits += want.is_some() as u32;
                if got.map(|h| h.triangle) != want.map(|h| h.triangle) {
                    let near = [got, want]
                        .iter()
                        .flatten()
                        .any(|h| margin(o, d, &tris.positions[h.triangle as usize]).abs() < 1e-4);
                    assert!(near, "{quality:?} ray {k}: {got:?} against {want:?}, far from any edge");
                    grazes += 1;
                    continue;
                }
                if let (Some(g), Some(w)) = (got, want) {
                    assert_eq!(g.t, w.t, "{quality:?} ray {k}");
                }
                assert_eq!(
                    e.any_hit(o, d, f64::INFINITY, u32::MAX),
                    want.is_some(),
                    "{quality:?} ray {k}"
                );
            }
            assert!(hits > 5000, "the rays must meet the triangles ({hits})");
            assert!(grazes < 20, "{quality:?}: {grazes} of 20000 rays decided otherwise");
        }
    }

    /// Rays aimed exactly at triangle corners, where f32 and f64 each decide by rounding: every
    /// answer that differs from brute force's is a ray within 1e-4 (barycentric) of an edge.
    #[test]
    fn corner_aimed_rays_differ_only_at_edges() {
        let tris = soup();
        let e = Embree::build(&tris, Quality::High).unwrap();
        let mut next = random(3);
        let mut differ = 0;
        for (k, tri) in tris.positions.iter().enumerate() {
            let d = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
            let o = tri[k % 3] - d * 2.0;
            let (got, want) = (e.closest(o, d, f64::INFINITY, u32::MAX), brute_force(&tris, o, d));
            if got.map(|h| h.triangle) != want.map(|h| h.triangle) {
                differ += 1;
                let near = [got, want]
                    .iter()
                    .flatten()
                    .any(|h| margin(o, d, &tris.positions[h.triangle as usize]).abs() < 1e-4);
                assert!(near, "ray {k}: {got:?} against {want:?}, far from any edge");
            }
        }
        // Rounding decides about half of them each way: the case is met, not avoided.
        assert!(differ > 100, "{differ} of 3000 corner rays differ");
    }

    /// A ray leaving a triangle with it skipped does not meet it again, with it not skipped it
    /// may; the far end is exclusive as the f64 structures' is.
    #[test]
    fn skip_and_tmax_are_honoured() {
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let positions = vec![
            [c(0., 0., 0.), c(1., 0., 0.), c(0., 1., 0.)],
            [c(0., 0., 1.), c(1., 0., 1.), c(0., 1., 1.)],
            [c(0., 0., 2.), c(1., 0., 2.), c(0., 1., 2.)],
        ];
        let tris = Triangles {
            object_of: vec![0; 3],
            positions,
        };
        let e = Embree::build(&tris, Quality::High).unwrap();
        let (o, d) = (c(0.25, 0.25, -1.0), DVec3::Z);
        let first = e.closest(o, d, f64::INFINITY, u32::MAX).unwrap();
        assert_eq!((first.triangle, first.t), (0, 1.0));
        let second = e.closest(o, d, f64::INFINITY, 0).unwrap();
        assert_eq!((second.triangle, second.t), (1, 2.0));
        assert!(!e.any_hit(o, d, 0.999, u32::MAX));
        assert!(e.any_hit(o, d, 1.001, u32::MAX));
        // From triangle 1's surface upwards: only triangle 2 is ahead; skipping 2 leaves none.
        let up = c(0.25, 0.25, 1.0);
        assert_eq!(e.closest(up, d, f64::INFINITY, 1).map(|h| h.triangle), Some(2));
        assert!(
            !e.any_hit(up, d, f64::INFINITY, 2),
            "triangle 1 at t = 0 is not ahead (t > 0)"
        );
        assert!(!e.any_hit(c(0.25, 0.25, 1.5), d, f64::INFINITY, 2));
        assert!(e.any_hit(c(0.25, 0.25, 1.5), d, 0.50001, u32::MAX));
        assert!(!e.any_hit(c(0.25, 0.25, 1.5), d, 0.5, u32::MAX), "t = tmax is outside");
    }

    /// Answers do not depend on how many threads ask at once (one device, queries from the
    /// pool's threads).
    #[test]
    fn concurrent_queries_answer_as_serial_ones() {
        let tris = soup();
        let e = Embree::build(&tris, Quality::High).unwrap();
        let mut next = random(2);
        let rays: Vec<(DVec3, DVec3)> = (0..4000)
            .map(|_| {
                let d = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
                (DVec3::new(1000.5, -999.5, 500.5) - 2.0 * d, d)
            })
            .collect();
        let serial: Vec<_> = rays
            .iter()
            .map(|&(o, d)| e.closest(o, d, f64::INFINITY, u32::MAX))
            .collect();
        let parallel: Vec<_> = rays
            .par_iter()
            .map(|&(o, d)| e.closest(o, d, f64::INFINITY, u32::MAX))
            .collect();
        assert_eq!(serial, parallel);
        assert!(serial.iter().filter(|h| h.is_some()).count() > 1000);
    }

    /// Its memory is what Embree allocated for the tree (more than nothing, less than a
    /// kilobyte a triangle); `[accel.embree]` takes no keys.
    #[test]
    fn stats_and_settings() {
        let tris = soup();
        let e = Embree::build(&tris, Quality::High).unwrap();
        let s = e.stats();
        assert!(
            s.memory_bytes > 3000 * 8 && s.memory_bytes < 3000 * 1000,
            "{}",
            s.memory_bytes
        );
        assert_eq!((s.triangles, s.gpu_bytes), (3000, 0));
        assert!(e.gpu_refusal().is_some());
        assert_eq!(s.parameters, "quality=high");
        assert!(toml::from_str::<EmbreeSettings>("").is_ok());
        assert!(
            toml::from_str::<EmbreeSettings>("quality = \"low\"").is_err(),
            "no keys"
        );
    }
}
