//! The visibility field (`accel::vlf`, default settings) side by side with obvhs on cow, bull,
//! man (assets/meshes) and the dressed body (experiments/scenes/body.toml), each scaled into the
//! unit ball (the VLF's normalisation: bounding-box centre, farthest vertex at radius 1):
//!
//! - `vlf`: the visibility field's f64 queries;
//! - `bvh`: the project's `accel::Bvh` (obvhs BVH2, `very-slow` preset, its best tree), its f64
//!   exact-test queries;
//! - `bvh2-obvhs`: the same BVH2 traversed by obvhs itself with its f32 triangle test;
//! - `cwbvh-obvhs`: obvhs' CWBVH (`very_slow_build`) traversed by obvhs with its f32 test, its
//!   rays' -0.0 direction components made +0.0 (`accel::cwbvh::ray::direction`: obvhs 0.4.0's
//!   node test misses every child box along a -0.0 component);
//! - `kdtree`: the paper's baseline, a CRT-like kd-tree (`accel::kdtree`: spatial-median
//!   splits, explicit-stack front-to-back walk, f64 exact tests) at its default depth and leaf
//!   size; `-- --tune-kdtree` times it on `ao-grid` over a grid of depths and leaf sizes, as the
//!   paper tuned its CRT;
//! - `kdtree-sah`: the same nodes and walk with SAH planes (Wald & Havran 2006) at the best of
//!   `-- --tune-kdtree --split sah` ([`SAH`]);
//! - `cwbvh`: `accel::cwbvh`, the registry's CWBVH: obvhs' very-slow CWBVH over widened boxes,
//!   obvhs' traversal, f64 exact tests;
//! - `embree`: `accel::embree`, the system Embree 3 library at its high build quality, its own
//!   f32 traversal and triangle tests (set it beside `cwbvh-obvhs` for f32 against f32); no
//!   work counters (`-`).
//!
//! Ray kinds (64 seeded points on the mesh, 513 rays each, 32832 per kind): `ao-grid` (every
//! stored direction oriented into the point's normal hemisphere, length 4, the start triangle
//! skipped: the paper's Section 7 set-up), `ao-grid-by-direction` (the same rays ordered one
//! stored direction at a time, so consecutive rays share a parallel subfield), `ao-frame` (the AO
//! experiment's own frame: every camera hit of its 256 x 256 image, origins lifted as the renderer
//! lifts them, with every 8th stored direction, 65 per receiver, receiver by receiver; and as
//! `STRUCTURE bundled` rows the same rays direction-major in bundles of 4096 receivers, answered by
//! `Accelerator::any_hits`: the field's tile-ordered walk, the kd-trees' packets of 8, the
//! others one ray at a time in bundle order), `ao-random` (513
//! uniform hemisphere directions per point), `shadow` (to a uniform point of a disk of radius
//! 0.02 above the scene) any-hit, and `camera` (a 181 x 181 pinhole image framing the ball)
//! closest-hit. Single thread (`1t`) and
//! rayon over all cores (`mt`).
//!
//! The obvhs columns are not exact (f32 tests), but agree with the f64 structures to a few hits
//! in 10^5. Without the -0.0 workaround obvhs' CWBVH reported fewer hits on `ao-grid` (cow 19.8 %
//! against 22.4 %): about a quarter of the 513 stored directions lie in coordinate planes, and
//! orienting one into a hemisphere by negation gives a -0.0 component.
//!
//! `cargo bench --bench vlf_compare`: criterion, small samples (about 5 minutes on 2 cores).
//! `cargo bench --bench vlf_compare -- --table`: one table of medians (Mrays/s, with the 95 %
//! interval of the median of 7 runs single-threaded), build times, memory (structure bytes: the
//! VLF's arrays, the BVHs' nodes and index lists; not the triangles every structure keeps) and
//! the work counters per ray (`accel::work`: nodes visited, primitives tested; `-` for obvhs'
//! own walks, which count nothing; a packet's node is counted once for its rays). `--meshes
//! cow,man`, `--structures kdtree,kdtree-sah` and `--kinds ao-frame` narrow it.
//! `-- --resolution`: the `ao-frame` rays at 64, 128, 256 and 512 square, single and bundled, one
//! thread, with the work per ray beside each rate (does the field's advantage move with the image
//! size because the work does, or because the memory traffic does?). `-- --counters`: the VLF's work per any-hit ray (tiles,
//! leaves, entries scanned, exact tests) beside the CWBVH's triangle tests.
//! `VLF_PROFILE_SECS=20 perf record ... vlf_compare-*`: loops the VLF's single-thread any-hit on
//! the cow's grid-direction AO rays, for a profile.

use criterion::{Criterion, SamplingMode, Throughput};
use glam::{DVec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::BvhBuildParams;
use penumbra::accel::cwbvh::{ray as cw_ray, Cwbvh};
use penumbra::accel::embree::{Embree, Quality};
use penumbra::accel::kdtree::{KdSettings, KdTree, Split};
use penumbra::accel::vlf::{VisibilityField, VlfSettings};
use penumbra::accel::work;
use penumbra::accel::{Accelerator, Bvh, Preset, Query};
use penumbra::mesh::Triangles;
use penumbra::sampling::rng::Seeded as Rng;
use penumbra::timing::median_interval;
use rayon::prelude::*;
use std::path::Path;
use std::time::{Duration, Instant};

/// A query: origin, unit direction, tmax, skip.
type Q = (DVec3, DVec3, f64, u32);

const KINDS: [&str; 6] = [
    "ao-grid",
    "ao-grid-by-direction",
    "ao-frame",
    "ao-random",
    "shadow",
    "camera",
];
const STRUCTURES: [&str; 8] = [
    "vlf",
    "bvh",
    "bvh2-obvhs",
    "cwbvh-obvhs",
    "kdtree",
    "kdtree-sah",
    "cwbvh",
    "embree",
];

/// The SAH kd-tree the table times: the best of `-- --tune-kdtree --split sah` summed over the
/// cow, the man and the body (depth 24, leaf 2, Wald & Havran's constants; depths 20-30 and K_T
/// 1-15 lie within the timing noise of it on a loaded two-core machine, depth 16 and below or
/// K_T 60 clearly slower).
const SAH: KdSettings = KdSettings {
    split: Split::Sah,
    max_depth: 24,
    leaf_size: 2,
    traversal_cost: None,
    intersection_cost: None,
    empty_factor: None,
};
const POINTS: u32 = 64;
/// `ao-frame`: the AO experiment's image size ...
const FRAME: u32 = 256;
/// ... with every 8th of the 513 stored directions (65 per receiver).
const STRIDE: usize = 8;
/// Receivers per bundle, as the renderer's direction-major AO pass takes them.
const BUNDLE: usize = 4096;

struct Mesh {
    tris: Triangles,
    vlf: VisibilityField,
    bvh: Bvh,
    cw: CwBvh,
    cw_time: Duration,
    kd: KdTree,
    kd_sah: KdTree,
    cwbvh: Cwbvh,
    embree: Embree,
}

fn repo(p: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// The mesh's triangles scaled into the unit ball.
fn load(name: &str) -> Triangles {
    let positions: Vec<[DVec3; 3]> = if name == "body" {
        penumbra::scene::Scene::load(&repo("experiments/scenes/body.toml"))
            .expect("body scene")
            .triangles
            .positions
    } else {
        let file = penumbra::mesh::load(&repo(&format!("assets/meshes/{name}.off"))).expect("mesh");
        penumbra::mesh::clean(file.triangles, &glam::DMat4::IDENTITY).0
    };
    penumbra::experiment::ao::spec::into_unit_ball(positions)
}

fn build(name: &'static str) -> Mesh {
    let tris = load(name);
    let vlf = VisibilityField::build(&tris, VlfSettings::default()).unwrap();
    let bvh = Bvh::build(&tris, Preset::VerySlow);
    let start = Instant::now();
    let mut core = Duration::ZERO;
    let cw = build_cwbvh_from_tris(&bvh.local, BvhBuildParams::very_slow_build(), &mut core);
    let cw_time = start.elapsed();
    let kd = KdTree::build(&tris, KdSettings::default());
    let kd_sah = KdTree::build(&tris, SAH);
    let cwbvh = Cwbvh::build(&tris, Preset::VerySlow);
    let embree = Embree::build(&tris, Quality::High).expect("the system Embree 3 library");
    Mesh {
        tris,
        vlf,
        bvh,
        cw,
        cw_time,
        kd,
        kd_sah,
        cwbvh,
        embree,
    }
}

/// A seeded point on the mesh: (point, normal, triangle).
fn point(t: &Triangles, r: &mut Rng) -> (DVec3, DVec3, u32) {
    let i = r.index(t.positions.len());
    let p = &t.positions[i];
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    (r.point_on(p), n, i as u32)
}

/// A receiver of the AO experiment's frame: lifted origin, normal facing the camera, triangle.
type Receiver = (DVec3, DVec3, u32);

/// Every camera hit of the AO experiment's frame at `size` x `size` (its camera, closest hits
/// found exactly), in raster order, lifted off the surface as the renderer lifts them.
fn receivers(m: &Mesh, size: u32) -> Vec<Receiver> {
    let camera = penumbra::experiment::ao::runner::camera();
    let mut out = Vec::new();
    for y in 0..size {
        for x in 0..size {
            let r = camera.ray(x, y, size, size);
            let Some(hit) = m.bvh.closest(r.origin, r.direction, f64::INFINITY, u32::MAX) else {
                continue;
            };
            let p = &m.tris.positions[hit.triangle as usize];
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            let n = if n.dot(r.direction) > 0.0 { -n } else { n };
            let at = r.origin + r.direction * hit.t;
            out.push((penumbra::geometry::offset_origin(at, n), n, hit.triangle));
        }
    }
    out
}

/// Every [`STRIDE`]-th stored direction oriented into receiver `r`'s hemisphere: its AO rays.
fn ao_rays<'a>(m: &'a Mesh, &(o, n, tri): &Receiver) -> impl Iterator<Item = Q> + 'a {
    let dirs = &m.vlf.frame.directions;
    (0..dirs.len() as u32).step_by(STRIDE).map(move |k| {
        let w = dirs.direction(k);
        (o, if w.dot(n) < 0.0 { -w } else { w }, 4.0, tri)
    })
}

/// The frame's AO rays direction-major, as the renderer bundles them: per [`BUNDLE`]
/// receivers, one bundle per direction.
fn bundles(m: &Mesh, receivers: &[Receiver]) -> Vec<Vec<Query>> {
    let mut out = Vec::new();
    for chunk in receivers.chunks(BUNDLE) {
        let per: Vec<Vec<Q>> = chunk.iter().map(|r| ao_rays(m, r).collect()).collect();
        for k in 0..per[0].len() {
            out.push(
                per.iter()
                    .map(|rays| {
                        let (origin, dir, tmax, skip) = rays[k];
                        Query {
                            origin,
                            dir,
                            tmax,
                            skip,
                        }
                    })
                    .collect(),
            );
        }
    }
    out
}

/// The structures behind the `Accelerator` seam, by slot (obvhs' own walks have none).
fn accelerator(m: &Mesh, s: usize) -> Option<&dyn Accelerator> {
    match s {
        0 => Some(&m.vlf),
        1 => Some(&m.bvh),
        4 => Some(&m.kd),
        5 => Some(&m.kd_sah),
        6 => Some(&m.cwbvh),
        7 => Some(&m.embree),
        _ => None,
    }
}

/// Any-hit over `bundles`, each answered by the structure's [`Accelerator::any_hits`] (obvhs'
/// own walks: ray by ray in bundle order); returns the hits.
fn run_bundled(m: &Mesh, s: usize, bundles: &[Vec<Query>], parallel: bool) -> usize {
    let one = |b: &Vec<Query>| -> usize {
        match accelerator(m, s) {
            Some(a) => {
                let mut hits = vec![false; b.len()];
                a.any_hits(b, &mut hits);
                hits.iter().filter(|&&h| h).count()
            }
            None => b
                .iter()
                .filter(|q| trace(m, s, false, &(q.origin, q.dir, q.tmax, q.skip)))
                .count(),
        }
    };
    if parallel {
        bundles.par_iter().map(one).sum()
    } else {
        bundles.iter().map(one).sum()
    }
}

fn rays(m: &Mesh, kind: &str) -> Vec<Q> {
    if kind == "ao-frame" {
        return receivers(m, FRAME).iter().flat_map(|r| ao_rays(m, r)).collect();
    }
    if kind == "ao-grid-by-direction" {
        // Direction-major: consecutive rays read the same subfield's arrays.
        let point_major = rays(m, "ao-grid");
        let n = m.vlf.frame.directions.len();
        let points = point_major.len() / n;
        return (0..point_major.len())
            .map(|k| point_major[(k % points) * n + k / points])
            .collect();
    }
    let mut r = Rng(0x5eed ^ (kind.len() as u32 * 7717));
    let dirs = &m.vlf.frame.directions;
    let n = dirs.len();
    let mut out = Vec::with_capacity(POINTS as usize * n);
    if kind == "camera" {
        let side = ((POINTS as f64 * n as f64).sqrt()) as usize;
        let eye = DVec3::new(0.3, -2.0, 0.8).normalize() * 3.0;
        let w = -eye.normalize();
        let u = w.cross(DVec3::Z).normalize();
        let v = u.cross(w);
        let half = 0.36;
        for y in 0..side {
            for x in 0..side {
                let (sx, sy) = (
                    (2.0 * (x as f64 + 0.5) / side as f64 - 1.0) * half,
                    (2.0 * (y as f64 + 0.5) / side as f64 - 1.0) * half,
                );
                out.push((eye, (w + u * sx + v * sy).normalize(), f64::INFINITY, u32::MAX));
            }
        }
        return out;
    }
    let light = DVec3::new(0.3, 0.0, 1.5);
    for _ in 0..POINTS {
        let (p, nrm, i) = point(&m.tris, &mut r);
        for j in 0..n {
            let d = match kind {
                "ao-grid" => dirs.direction(j as u32),
                "ao-random" => r.unit(),
                _ => {
                    let (rad, ang) = (0.02 * r.f().sqrt(), r.f() * std::f64::consts::TAU);
                    let q = light + DVec3::new(rad * ang.cos(), rad * ang.sin(), 0.0);
                    out.push((p, (q - p).normalize(), (q - p).length(), i));
                    continue;
                }
            };
            out.push((p, if d.dot(nrm) >= 0.0 { d } else { -d }, 4.0, i));
        }
    }
    out
}

/// One query with structure `s`; closest-hit for camera rays, any-hit otherwise. Returns hit.
#[inline]
fn trace(m: &Mesh, s: usize, closest: bool, &(o, d, tmax, skip): &Q) -> bool {
    match s {
        0 if closest => m.vlf.closest(o, d, tmax, skip).is_some(),
        0 => m.vlf.any_hit(o, d, tmax, skip),
        1 if closest => m.bvh.closest(o, d, tmax, skip).is_some(),
        1 => m.bvh.any_hit(o, d, tmax, skip),
        4 if closest => penumbra::accel::Accelerator::closest(&m.kd, o, d, tmax, skip).is_some(),
        4 => penumbra::accel::Accelerator::any_hit(&m.kd, o, d, tmax, skip),
        5 if closest => penumbra::accel::Accelerator::closest(&m.kd_sah, o, d, tmax, skip).is_some(),
        5 => penumbra::accel::Accelerator::any_hit(&m.kd_sah, o, d, tmax, skip),
        6 if closest => m.cwbvh.closest(o, d, tmax, skip).is_some(),
        6 => m.cwbvh.any_hit(o, d, tmax, skip),
        7 if closest => m.embree.closest(o, d, tmax, skip).is_some(),
        7 => m.embree.any_hit(o, d, tmax, skip),
        _ => {
            let ray = Ray::new(
                Vec3A::from((o - m.bvh.centre).as_vec3()),
                cw_ray::direction(d),
                0.0,
                tmax as f32,
            );
            let (indices, local) = (
                if s == 2 {
                    &m.bvh.tree.primitive_indices
                } else {
                    &m.cw.primitive_indices
                },
                &m.bvh.local,
            );
            let test = |r: &Ray, id: usize| {
                let tri = indices[id];
                if tri == skip {
                    f32::INFINITY
                } else {
                    local[tri as usize].intersect(r)
                }
            };
            match (s, closest) {
                (2, false) => !m.bvh.tree.ray_traverse_miss(ray, test),
                (2, true) => m.bvh.tree.ray_traverse(ray, &mut RayHit::none(), test),
                (_, false) => !m.cw.ray_traverse_miss(ray, test),
                (_, true) => m.cw.ray_traverse(ray, &mut RayHit::none(), test),
            }
        }
    }
}

fn run(m: &Mesh, s: usize, closest: bool, rays: &[Q], parallel: bool) -> usize {
    if parallel {
        rays.par_chunks(256)
            .map(|c| c.iter().filter(|r| trace(m, s, closest, r)).count())
            .sum()
    } else {
        rays.iter().filter(|r| trace(m, s, closest, r)).count()
    }
}

/// Structure bytes (no triangles) of each structure.
fn bytes(m: &Mesh) -> [usize; 8] {
    let bvh2 = std::mem::size_of_val(m.bvh.tree.nodes.as_slice()) + 4 * m.bvh.tree.primitive_indices.len();
    let cw = std::mem::size_of_val(m.cw.nodes.as_slice()) + 4 * m.cw.primitive_indices.len();
    [
        m.vlf.bytes(),
        bvh2,
        bvh2,
        cw,
        m.kd.bytes(),
        m.kd_sah.bytes(),
        m.cwbvh.bytes(),
        Accelerator::stats(&m.embree).memory_bytes as usize,
    ]
}

const MESHES: [&str; 4] = ["cow", "bull", "man", "body"];

/// The values of `--flag a,b,c`, or `all` where the flag is absent.
fn listed<'a>(flag: &str, all: &[&'a str]) -> Vec<&'a str> {
    let args: Vec<String> = std::env::args().collect();
    let Some(i) = args.iter().position(|a| a == flag) else {
        return all.to_vec();
    };
    let wanted: Vec<&str> = args.get(i + 1).map_or(vec![], |v| v.split(',').collect());
    let out: Vec<&str> = all.iter().copied().filter(|a| wanted.contains(a)).collect();
    assert!(!out.is_empty(), "{flag} names none of {all:?}");
    out
}

fn table() {
    let threads = rayon::current_num_threads();
    println!(
        "vlf_compare: {} logical CPUs, rayon {threads} threads; Mrays/s, median of 7 runs of each kind's \
         rays ({} per kind; ao-frame: every camera hit of a {FRAME}^2 frame x 65 directions) (1t: with \
         its 95 % interval, the runs' range); work per ray from one single-threaded run",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        POINTS * 513
    );
    println!();
    println!("| mesh | tris | structure | build s | MB | B/tri | kind | nodes/ray | prims/ray | 1t Mrays/s | mt Mrays/s | hit % |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let structures = listed("--structures", &STRUCTURES);
    for name in listed("--meshes", &MESHES) {
        let t0 = Instant::now();
        let m = build(name);
        eprintln!("{name}: built in {:.1} s", t0.elapsed().as_secs_f64());
        let parts: Vec<String> = m
            .vlf
            .parts()
            .iter()
            .map(|(part, b)| format!("{part} {:.1} MB", *b as f64 / 1e6))
            .collect();
        eprintln!("{name}: vlf bytes by part: {}", parts.join(", "));
        let b = bytes(&m);
        let builds = [
            m.vlf.build_time.as_secs_f64(),
            m.bvh.total_time.as_secs_f64(),
            m.bvh.total_time.as_secs_f64(),
            m.cw_time.as_secs_f64(),
            penumbra::accel::Accelerator::stats(&m.kd).build_time.as_secs_f64(),
            penumbra::accel::Accelerator::stats(&m.kd_sah).build_time.as_secs_f64(),
            m.cwbvh.build_time.as_secs_f64(),
            Accelerator::stats(&m.embree).build_time.as_secs_f64(),
        ];
        let n = m.tris.positions.len();
        for kind in listed("--kinds", &KINDS) {
            let rays = rays(&m, kind);
            let closest = kind == "camera";
            // The frame's rays also as the renderer bundles them (`STRUCTURE bundled` rows).
            let bundled = (kind == "ao-frame").then(|| bundles(&m, &receivers(&m, FRAME)));
            for (s, label) in STRUCTURES.iter().enumerate() {
                if !structures.contains(label) {
                    continue;
                }
                let mut issues: Vec<(String, &dyn Fn(bool) -> usize)> = Vec::new();
                let single = |p: bool| run(&m, s, closest, &rays, p);
                issues.push((label.to_string(), &single));
                let bundle = |p: bool| run_bundled(&m, s, bundled.as_deref().unwrap_or_default(), p);
                if bundled.is_some() {
                    issues.push((format!("{label} bundled"), &bundle));
                }
                for (label, go) in issues {
                    let (hits, w) = work::counted(|| go(false));
                    let per_ray = |x: u64| {
                        if w.nodes + w.primitives == 0 {
                            "-".to_string()
                        } else {
                            format!("{:.1}", x as f64 / rays.len() as f64)
                        }
                    };
                    let rates = [false, true].map(|p| {
                        let rate: Vec<f64> = (0..7)
                            .map(|_| {
                                let t = Instant::now();
                                std::hint::black_box(go(p));
                                rays.len() as f64 / t.elapsed().as_secs_f64() / 1e6
                            })
                            .collect();
                        median_interval(&rate)
                    });
                    println!(
                        "| {name} | {n} | {label} | {:.3} | {:.1} | {:.0} | {kind} | {} | {} | {} | {:.2} | {:.2} |",
                        builds[s],
                        b[s] as f64 / 1e6,
                        b[s] as f64 / n as f64,
                        per_ray(w.nodes),
                        per_ray(w.primitives),
                        rates[0].show(2),
                        rates[1].median,
                        100.0 * hits as f64 / rays.len() as f64
                    );
                }
            }
        }
        eprintln!("{name}: {}", penumbra::accel::Accelerator::stats(&m.vlf).description);
        eprintln!("{name}: {}", penumbra::accel::Accelerator::stats(&m.kd).description);
        eprintln!("{name}: {}", penumbra::accel::Accelerator::stats(&m.kd_sah).description);
        eprintln!("{name}: {}", penumbra::accel::Accelerator::stats(&m.cwbvh).description);
        eprintln!("{name}: {}", penumbra::accel::Accelerator::stats(&m.embree).description);
    }
}

/// Work per any-hit ray of each mesh (`--counters`).
fn count_table() {
    println!(
        "Work per any-hit ray: VLF tiles visited, leaves visited, entries scanned, exact tests; CWBVH triangle tests"
    );
    println!();
    println!("| mesh | kind | VLF tiles | VLF leaves | VLF entries | VLF exact tests | CWBVH tri tests |");
    println!("|---|---|---|---|---|---|---|");
    for name in MESHES {
        let m = build(name);
        for kind in ["ao-grid", "ao-random", "shadow"] {
            let [tiles, leaves, entries, exact, cw] = counters(&m, &rays(&m, kind));
            println!("| {name} | {kind} | {tiles:.1} | {leaves:.1} | {entries:.1} | {exact:.1} | {cw:.1} |");
        }
    }
}

/// The VLF's any-hit walk (`VisibilityField::any_hit` on the base layer, rebuilt from its public
/// pieces) with counters, and the CWBVH's triangle tests: per ray (tiles, leaves, entries
/// scanned, exact tests, CWBVH triangle tests). Checks the hits agree with `any_hit`.
fn counters(m: &Mesh, rays: &[Q]) -> [f64; 5] {
    use penumbra::accel::vlf::query::exact_t;
    let f = &m.vlf;
    let mut c = [0usize; 5];
    for &(o, d, tmax, skip) in rays {
        let hit = f.tile_ray(o, d, tmax).is_some_and(|ray| {
            f.walk(
                &ray,
                || f64::INFINITY,
                |tile, ta, tb| {
                    c[0] += 1;
                    f.leaves(&f.base, &ray, tile, ta, tb, |leaf| {
                        c[1] += 1;
                        c[2] += leaf.entries();
                        leaf.each(|id| {
                            if id == skip {
                                return false;
                            }
                            c[3] += 1;
                            let t = exact_t(o, d, &f.tri[9 * id as usize..9 * id as usize + 9]);
                            t > 0.0 && t < tmax
                        })
                    })
                },
            )
        });
        assert_eq!(hit, f.any_hit(o, d, tmax, skip));
        let ray = Ray::new(
            Vec3A::from((o - m.bvh.centre).as_vec3()),
            cw_ray::direction(d),
            0.0,
            tmax as f32,
        );
        m.cw.ray_traverse_miss(ray, |r, id| {
            c[4] += 1;
            let tri = m.cw.primitive_indices[id];
            if tri == skip {
                f32::INFINITY
            } else {
                m.bvh.local[tri as usize].intersect(r)
            }
        });
    }
    c.map(|x| x as f64 / rays.len() as f64)
}

fn criterion_benches(c: &mut Criterion) {
    for name in MESHES {
        let m = build(name);
        for kind in KINDS {
            let rays = rays(&m, kind);
            let closest = kind == "camera";
            let mut g = c.benchmark_group(format!("{name}/{kind}"));
            g.sample_size(10)
                .sampling_mode(SamplingMode::Flat)
                .warm_up_time(Duration::from_millis(300))
                .measurement_time(Duration::from_millis(700))
                .throughput(Throughput::Elements(rays.len() as u64));
            for (s, label) in STRUCTURES.iter().enumerate() {
                for (p, mode) in ["1t", "mt"].iter().enumerate() {
                    g.bench_function(format!("{label}_{mode}"), |b| {
                        b.iter(|| run(&m, s, closest, &rays, p == 1))
                    });
                }
            }
            g.finish();
        }
    }
    let m = load("cow");
    let mut g = c.benchmark_group("cow/build");
    g.sample_size(10).sampling_mode(SamplingMode::Flat);
    g.bench_function("vlf", |b| {
        b.iter(|| VisibilityField::build(&m, VlfSettings::default()).unwrap())
    });
    g.bench_function("bvh", |b| b.iter(|| Bvh::build(&m, Preset::VerySlow)));
    let local = Bvh::build(&m, Preset::VerySlow).local;
    g.bench_function("cwbvh-obvhs", |b| {
        b.iter(|| build_cwbvh_from_tris(&local, BvhBuildParams::very_slow_build(), &mut Duration::default()))
    });
    g.finish();
}

/// The kd-tree on `ao-grid` rays over depths and leaf sizes (`--tune-kdtree`), one thread, as the
/// paper tuned its CRT baseline: median of 5 runs each, with memory, build time and the work per
/// ray. With `--split sah`, the SAH tree over depths, leaf sizes and traversal costs K_T
/// (K_I = 20, Wald & Havran's 15 among them).
fn tune_kdtree() {
    let sah = std::env::args().any(|a| a == "sah");
    println!(
        "{} kd-tree on ao-grid any-hit rays, one thread, median of 5 runs of {} rays",
        if sah { "SAH" } else { "Spatial-median" },
        POINTS * 513
    );
    println!();
    println!("| mesh | depth | leaf | K_T | build ms | MB | nodes/ray | prims/ray | Mrays/s |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let grid: Vec<(u32, u32, Option<f64>)> = if sah {
        let mut g = Vec::new();
        for d in [12, 16, 20, 24, 30] {
            for l in [1, 2, 4, 8] {
                for k in [1.0, 2.5, 5.0, 10.0, 15.0, 30.0, 60.0] {
                    g.push((d, l, Some(k)));
                }
            }
        }
        g
    } else {
        let mut g = Vec::new();
        for d in [16, 18, 20, 22, 24, 26, 28, 30] {
            for l in [2, 4, 8, 16, 32] {
                g.push((d, l, None));
            }
        }
        g
    };
    let (slot, split) = if sah { (5, Split::Sah) } else { (4, Split::Median) };
    for name in listed("--meshes", &MESHES) {
        let mut m = build(name);
        let rays = rays(&m, "ao-grid");
        let mut best = (0.0, 0, 0, None);
        for &(max_depth, leaf_size, traversal_cost) in &grid {
            let tree = KdTree::build(
                &m.tris,
                KdSettings {
                    split,
                    max_depth,
                    leaf_size,
                    traversal_cost,
                    ..KdSettings::default()
                },
            );
            if sah {
                m.kd_sah = tree;
            } else {
                m.kd = tree;
            }
            let (_, w) = work::counted(|| run(&m, slot, false, &rays, false));
            let times: Vec<f64> = (0..5)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(run(&m, slot, false, &rays, false));
                    t.elapsed().as_secs_f64()
                })
                .collect();
            let rate = rays.len() as f64 / penumbra::metrics::stats::median(&times) / 1e6;
            let tree = if sah { &m.kd_sah } else { &m.kd };
            let stats = penumbra::accel::Accelerator::stats(tree);
            println!(
                "| {name} | {max_depth} | {leaf_size} | {} | {:.0} | {:.1} | {:.1} | {:.1} | {rate:.2} |",
                traversal_cost.map_or("-".into(), |k| k.to_string()),
                stats.build_time.as_secs_f64() * 1e3,
                tree.bytes() as f64 / 1e6,
                w.nodes as f64 / rays.len() as f64,
                w.primitives as f64 / rays.len() as f64,
            );
            if rate > best.0 {
                best = (rate, max_depth, leaf_size, traversal_cost);
            }
        }
        eprintln!(
            "{name}: best depth {} leaf {} K_T {:?} at {:.2} Mrays/s",
            best.1, best.2, best.3, best.0
        );
    }
}

/// Each structure on the AO experiment's frame at 64, 128, 256 and 512 square (`--resolution`),
/// one thread, single and bundled: the rate (median of 5 runs) beside the work per ray, so a
/// ratio that moves with the image size can be told apart from work that moves with it.
fn resolution() {
    println!(
        "AO frame rays (every {STRIDE}th stored direction per camera hit), one thread, median of 5 runs, Mrays/s [95 % interval]"
    );
    println!();
    println!("| mesh | size | receivers | structure | issue | nodes/ray | prims/ray | Mrays/s |");
    println!("|---|---|---|---|---|---|---|---|");
    let structures = listed("--structures", &["kdtree", "kdtree-sah", "vlf", "bvh", "cwbvh"]);
    for name in listed("--meshes", &["cow", "man", "body"]) {
        let m = build(name);
        for size in [64, 128, 256, 512] {
            let receivers = receivers(&m, size);
            let rays: Vec<Q> = receivers.iter().flat_map(|r| ao_rays(&m, r)).collect();
            let bundled = bundles(&m, &receivers);
            for (s, label) in STRUCTURES.iter().enumerate() {
                if !structures.contains(label) {
                    continue;
                }
                let single = || run(&m, s, false, &rays, false);
                let bundle = || run_bundled(&m, s, &bundled, false);
                for (issue, go) in [("single", &single as &dyn Fn() -> usize), ("bundled", &bundle)] {
                    let (_, w) = work::counted(go);
                    let rate: Vec<f64> = (0..5)
                        .map(|_| {
                            let t = Instant::now();
                            std::hint::black_box(go());
                            rays.len() as f64 / t.elapsed().as_secs_f64() / 1e6
                        })
                        .collect();
                    println!(
                        "| {name} | {size} | {} | {label} | {issue} | {:.1} | {:.1} | {} |",
                        receivers.len(),
                        w.nodes as f64 / rays.len() as f64,
                        w.primitives as f64 / rays.len() as f64,
                        median_interval(&rate).show(2)
                    );
                }
            }
        }
    }
}

fn main() {
    if std::env::args().any(|a| a == "--resolution") {
        resolution();
        return;
    }
    if std::env::args().any(|a| a == "--tune-kdtree") {
        tune_kdtree();
        return;
    }
    if std::env::args().any(|a| a == "--table") {
        table();
        return;
    }
    if std::env::args().any(|a| a == "--counters") {
        count_table();
        return;
    }
    if let Some(secs) = std::env::var("VLF_PROFILE_SECS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
    {
        // For `perf record`: the VLF's any-hit on the cow's grid-direction AO rays, one thread.
        let m = build("cow");
        let rays = rays(&m, "ao-grid");
        let t = Instant::now();
        while t.elapsed().as_secs_f64() < secs {
            std::hint::black_box(run(&m, 0, false, &rays, false));
        }
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    criterion_benches(&mut c);
    c.final_summary();
}
