//! Ray bundles (`Accelerator::any_hits`): every structure's bundled answers equal brute force
//! and its own single queries, hit for hit, on every kind of ray and on the hard cases (zero and
//! -0.0 direction components, rays that miss the bounds, mixed octants, empty and one-ray
//! bundles); the field's bundle walk does exactly the single walks' work, the kd-tree's packets
//! the same triangle tests (and at most 1 % more) in fewer node visits; and an AO frame issued
//! direction-major is the single-ray frame to the bit. The packets' f32 walk is also tested
//! plane by plane in `accel::kdtree::packet`.

use crate::common;
use crate::common::rays::*;
use glam::DVec3;
use penumbra::accel::vlf::directions::Directions;
use penumbra::accel::{intersect, registered, work, AccelSettings, Issue, Query, REGISTRY};
use penumbra::mesh::Triangles;
use penumbra::render::cpu::CpuBackend;
use penumbra::render::{Backend, Sampling, View};
use penumbra::scene::ambient::{AmbientOcclusion, AoDirections, Weighting};
use rayon::prelude::*;

fn queries(rays: &[Ray]) -> Vec<Query> {
    rays.iter()
        .map(|&(origin, dir, tmax, skip)| Query {
            origin,
            dir,
            tmax,
            skip,
        })
        .collect()
}

/// Brute force's any-hit: some triangle other than `skip` with 0 < t < tmax.
fn brute_any(t: &Triangles, q: &Query) -> bool {
    t.positions
        .iter()
        .enumerate()
        .any(|(i, tri)| i as u32 != q.skip && intersect(q.origin, q.dir, tri).is_some_and(|h| h > 0.0 && h < q.tmax))
}

/// Every CPU structure's bundled answers against brute force and its single answers.
fn check_all(name: &str, t: &Triangles, qs: &[Query]) {
    check(name, t, qs, |_| true)
}

/// [`check_all`] for the structures `only` names.
fn check(name: &str, t: &Triangles, qs: &[Query], only: impl Fn(&str) -> bool) {
    let want: Vec<bool> = qs.par_iter().map(|q| brute_any(t, q)).collect();
    for r in REGISTRY.iter().filter(|r| r.exact && only(r.name)) {
        let s = penumbra::accel::build(t, &AccelSettings::default_for(r))
            .unwrap()
            .unwrap();
        let mut hits = vec![true; qs.len()];
        s.any_hits(qs, &mut hits);
        let single: Vec<bool> = qs.iter().map(|q| s.any_hit(q.origin, q.dir, q.tmax, q.skip)).collect();
        let wrong: Vec<usize> = (0..qs.len()).filter(|&i| hits[i] != want[i]).collect();
        assert!(
            wrong.is_empty(),
            "{name}, {}: {} of {} bundled answers differ from brute force, e.g. {:?}",
            r.name,
            wrong.len(),
            qs.len(),
            wrong.iter().take(3).map(|&i| (qs[i], want[i])).collect::<Vec<_>>()
        );
        assert_eq!(hits, single, "{name}, {}: bundled differs from single", r.name);
    }
}

#[test]
fn bundled_answers_equal_brute_force_on_every_kind_of_ray() {
    let cow = penumbra::experiment::ao::spec::into_unit_ball(common::off_mesh("cow").positions);
    let dirs = Directions::new(16);
    for (kind, rays) in all_rays(&cow, &dirs, 1500, 41) {
        let qs = queries(&rays);
        check_all(&format!("cow {kind}"), &cow, &qs);
        // The same rays one direction at a time: how the AO pass bundles them.
        let mut sorted = qs.clone();
        sorted.sort_by(|a, b| a.dir.to_array().partial_cmp(&b.dir.to_array()).unwrap());
        check_all(&format!("cow {kind} by direction"), &cow, &sorted);
    }
    let s = soup(600, 7);
    for (kind, rays) in all_rays(&s, &dirs, 600, 8) {
        check_all(&format!("soup {kind}"), &s, &queries(&rays));
    }
}

/// A closed box `[-1, 1]^3` with an inner wall on x = 0 and one on y = 0, scaled by `scale`.
fn walled_box(scale: f64) -> Triangles {
    let mut out = Vec::new();
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |a: f64, b: f64| {
                let mut p = DVec3::ZERO;
                p[axis] = side;
                p[u] = a;
                p[w] = b;
                p
            };
            out.push([corner(-1., -1.), corner(1., -1.), corner(1., 1.)]);
            out.push([corner(-1., -1.), corner(1., 1.), corner(-1., 1.)]);
        }
    }
    out.push([v(0., -1., -1.), v(0., 1., -1.), v(0., 1., 1.)]);
    out.push([v(-1., 0., -1.), v(1., 0., -1.), v(1., 0., 1.)]);
    tris(out.into_iter().map(|t| t.map(|p| p * scale)).collect())
}

/// Rays in `dirs` from a grid of points on and off `walled_box(scale)`'s walls and outside it,
/// each unbounded, with a short tmax and with a skipped triangle.
fn box_rays(scale: f64, dirs: &[DVec3]) -> Vec<Query> {
    let grid = [-1.0, -0.5, 0.0, 0.5, 1.0, 1.5, -3.0];
    let mut rays = Vec::new();
    let mut r = Rng(5);
    for &x in &grid {
        for &y in &grid {
            for &z in &grid {
                for &d in dirs {
                    let o = v(x, y, z) * scale;
                    rays.push((o, d, f64::INFINITY, u32::MAX));
                    rays.push((o, d, 0.5 * scale, u32::MAX));
                    rays.push((o, d, f64::INFINITY, r.index(14) as u32));
                }
            }
        }
    }
    queries(&rays)
}

/// A closed box with inner walls, rays along the axes with +0.0 and -0.0 components from on and
/// off the planes, outside the bounds, with a short tmax and a skipped triangle, mixed in one
/// bundle; and the empty and one-ray bundles.
#[test]
fn hard_bundles_match_brute_force() {
    let t = walled_box(1.0);
    let mut dirs = Vec::new();
    for a in 0..3 {
        let mut d = DVec3::ZERO;
        d[a] = 1.0;
        dirs.extend([d, -d]);
    }
    dirs.extend([v(1., 1., 0.), v(-1., -1., -0.), v(-0., -1., 1.), v(0.3, -0.2, 0.9)].map(|d| d.normalize()));
    let qs = box_rays(1.0, &dirs);
    assert!(
        qs.iter()
            .filter(|q| q.dir.to_array().iter().any(|c| *c == 0.0 && c.is_sign_negative()))
            .count()
            > 500
    );
    check_all("box", &t, &qs);
    check_all("box, one ray", &t, &qs[..1]);
    check_all("box, no ray", &t, &[]);
}

/// The kd-tree packets' f32 walk at its edges: rays tilted off a wall or an axis by components
/// from 1e-30 (walked as parallel) to 1e-6 (f32 rounds the plane distance hard), on boxes from
/// 1e-30 to 1e25 across (outside the f32 walk's range the packet is traced ray by ray) and one
/// far from the origin. Every answer is brute force's and the single walk's.
#[test]
fn kdtree_packets_hold_at_the_edges_of_f32() {
    let mut dirs = Vec::new();
    for tilt in [1e-30, 1e-19, 1e-17, 1e-12, 1e-9, 1e-6] {
        for a in 0..3 {
            let (mut d, mut e) = (DVec3::ZERO, DVec3::ZERO);
            d[a] = 1.0;
            d[(a + 1) % 3] = tilt;
            e[a] = -1.0;
            e[(a + 2) % 3] = -tilt;
            e[(a + 1) % 3] = tilt;
            dirs.extend([d.normalize(), e.normalize()]);
        }
    }
    for scale in [1e-30, 1e-17, 1.0, 1e17, 1e25] {
        let qs = box_rays(scale, &dirs);
        check(&format!("box x {scale:e}"), &walled_box(scale), &qs, kd_trees);
    }
    // Far from the origin: the packets walk from the box's corner, the single walk in absolute
    // coordinates with planes 1e-9 of 2e6 thick.
    let far = DVec3::new(1e6, -3e6, 2e6);
    let moved = tris(walled_box(1.0).positions.iter().map(|t| t.map(|p| p + far)).collect());
    let qs: Vec<Query> = box_rays(1.0, &dirs)
        .into_iter()
        .map(|q| Query {
            origin: q.origin + far,
            ..q
        })
        .collect();
    check("box at (1e6, -3e6, 2e6)", &moved, &qs, kd_trees);
}

/// Walls that do not straddle the tree's planes, so a lane that enters the wrong child misses
/// them: rays parallel to the planes up to a component of +-1e-20 (walked as flat) or +-1e-18
/// (the first not), in both directions; and small triangles far from the origin, hit from their
/// own corners (on the split planes).
#[test]
fn kdtree_packets_find_walls_they_cannot_enter_by_mistake() {
    let mut out = Vec::new();
    for k in 0..16 {
        let z0 = k as f64;
        out.push([v(2.0, -1.0, z0), v(2.0, 1.0, z0), v(2.0, 0.0, z0 + 0.5)]);
        out.push([v(-2.0, -1.0, z0), v(-2.0, 1.0, z0), v(-2.0, 0.0, z0 + 0.5)]);
    }
    let mut rays = Vec::new();
    for k in 0..16 {
        for (x, tilt) in [1.0, -1.0]
            .into_iter()
            .flat_map(|x| [-1e-20, 1e-20, -1e-18, 1e-18].map(|t| (x, t)))
        {
            rays.push((v(0.0, 0.1, k as f64 + 0.25), v(x, 0.0, tilt), f64::INFINITY, u32::MAX));
        }
    }
    check(
        "stacked walls, dz = +-1e-20, +-1e-18",
        &tris(out),
        &queries(&rays),
        kd_trees,
    );
    let far = DVec3::new(1e6, 1e6, -1e6);
    let small = tris(
        soup(600, 7)
            .positions
            .iter()
            .map(|t| t.map(|p| p * 1e-3 + far))
            .collect(),
    );
    let dirs = Directions::new(16);
    for (kind, rays) in all_rays(&small, &dirs, 600, 8) {
        check(&format!("small soup at 1e6 {kind}"), &small, &queries(&rays), kd_trees);
    }
}

/// Seeded soups of large, small and axis-aligned triangles, at the origin and far from their
/// own size from it, hit from triangle corners (on split planes) and from around them, towards
/// other corners or anywhere, with zero, -0.0 and tiny components of either sign, tmax from 0
/// to 1e300 and skipped triangles: every packet answer is brute force's and the single walk's.
#[test]
fn kdtree_packets_agree_on_corner_rays() {
    for (seed, offset, size) in [(1, 0.0, 1.0), (2, 1e6, 1e-3), (3, 1e12, 1.0), (4, 1e-5, 1e-10)] {
        let mut r = Rng(seed);
        let far = v(offset, -0.7 * offset, 0.3 * offset);
        let around = |r: &mut Rng, k: f64| v(r.range(-k, k), r.range(-k, k), r.range(-k, k));
        let t = tris(
            (0..400)
                .map(|_| {
                    let c = around(&mut r, size) + far;
                    let s = size * [0.3, 0.03, 0.003][r.index(3)];
                    let (mut a, mut b) = (around(&mut r, s), around(&mut r, s));
                    if r.f() < 0.3 {
                        let axis = r.index(3);
                        (a[axis], b[axis]) = (0.0, 0.0);
                    }
                    [c, c + a, c + b]
                })
                .collect(),
        );
        let corner = |r: &mut Rng| t.positions[r.index(400)][r.index(3)];
        let mut rays = Vec::new();
        while rays.len() < 60_000 {
            let o = match r.index(3) {
                0 => corner(&mut r),
                1 => far + around(&mut r, 1.5 * size),
                _ => far + around(&mut r, 4.0 * size),
            };
            let target = corner(&mut r);
            let mut d = if r.f() < 0.5 { target - o } else { around(&mut r, 1.0) };
            for a in 0..3 {
                let x = r.f();
                if x < 0.25 {
                    d[a] = if x < 0.15 { 0.0 } else { -0.0 };
                } else if x < 0.4 {
                    let tiny = [1e-30, 1e-19, 1e-18, 1e-17, 1e-12, 1e-9, 1e-6, 1e-4][r.index(8)];
                    d[a] = if r.f() < 0.5 { tiny } else { -tiny };
                }
            }
            let Some(d) = d.try_normalize() else { continue };
            let tmax = [f64::INFINITY, 0.0, (target - o).length(), size * r.f(), 1e300][r.index(5)];
            let skip = if r.f() < 0.2 { r.index(400) as u32 } else { u32::MAX };
            rays.push((o, d, tmax, skip));
        }
        check(
            &format!("corner rays, {size:e} at {offset:e}"),
            &t,
            &queries(&rays),
            kd_trees,
        );
    }
}

fn kd_trees(name: &str) -> bool {
    name.starts_with("kdtree")
}

/// The field's bundle walk reorders memory traffic only: its work equals the single walks'. The
/// kd-tree's packets test the single walks' triangles and, where an f32 lane's thicker plane
/// reaches a neighbouring leaf, a few more (each lane meets its own leaves in its own order and
/// stops at its first hit), and fetch each node once per packet: fewer node visits on coherent AO
/// rays.
#[test]
fn bundles_do_the_work_the_design_says() {
    let cow = penumbra::experiment::ao::spec::into_unit_ball(common::off_mesh("cow").positions);
    let dirs = Directions::new(16);
    // Eight neighbouring receivers on each of 500 triangles, one stored direction each: the
    // coherence of neighbouring pixels' rays along one grid line.
    let mut r = Rng(9);
    let mut rays = Vec::new();
    for _ in 0..500 {
        let i = r.index(cow.positions.len());
        let w = dirs.direction(r.index(dirs.len()) as u32);
        let w = if w.dot(normal(&cow.positions[i])) < 0.0 { -w } else { w };
        for _ in 0..8 {
            rays.push((point_on(&cow.positions[i], &mut r), w, 4.0, i as u32));
        }
    }
    let qs = queries(&rays);
    let counted = |name: &str| {
        let s = penumbra::accel::build(&cow, &AccelSettings::named(name).unwrap())
            .unwrap()
            .unwrap();
        let (_, single) = work::counted(|| qs.iter().filter(|q| s.any_hit(q.origin, q.dir, q.tmax, q.skip)).count());
        let mut hits = vec![false; qs.len()];
        let (_, bundled) = work::counted(|| s.any_hits(&qs, &mut hits));
        (single, bundled)
    };
    let (single, bundled) = counted("vlf");
    assert_eq!(single, bundled, "the field's bundle does the single walks' work");
    for name in ["kdtree", "kdtree-sah"] {
        let (single, bundled) = counted(name);
        // The f32 walk's thicker planes may add a neighbouring leaf, never drop one.
        assert!(
            bundled.primitives >= single.primitives && bundled.primitives as f64 <= 1.01 * single.primitives as f64,
            "{name}: the single walks' triangle tests and at most 1 % more: {} against {}",
            bundled.primitives,
            single.primitives
        );
        assert!(
            (bundled.nodes as f64) < 0.6 * single.nodes as f64,
            "{name}: packets of 8 parallel rays share node visits: {} against {}",
            bundled.nodes,
            single.nodes
        );
    }
}

/// An AO frame with its rays issued direction-major equals the single-ray frame to the bit, for
/// grid and disk directions, plain and cosine weights, on the field and the kd-tree.
#[test]
fn a_bundled_ao_frame_is_the_single_frame() {
    let cow = penumbra::experiment::ao::spec::into_unit_ball(common::off_mesh("cow").positions);
    let camera = penumbra::experiment::ao::runner::camera();
    let mut backend = CpuBackend::default();
    let sampling = Sampling {
        scheme: penumbra::sampling::DiskScheme::Uniform,
        pattern: penumbra::sampling::Pattern::PerPixel,
        seed: 3,
        frame: 0,
    };
    for name in ["vlf", "kdtree", "bvh"] {
        for (directions, rays) in [
            (AoDirections::grid(4), 33),
            (AoDirections::Disk(penumbra::sampling::DiskScheme::Uniform), 24),
        ] {
            for weighting in [Weighting::Plain, Weighting::Cosine] {
                let mut frame = |issue: Issue| {
                    let ao = AmbientOcclusion {
                        directions: directions.clone(),
                        rays,
                        weighting,
                        max_distance: 4.0,
                        issue,
                    };
                    let scene = common::triangles_scene(&cow, registered(name).unwrap().name)
                        .with_cameras([("ao".to_string(), camera.clone())].into())
                        .with_ambient(Some(ao));
                    let view = View {
                        camera: &scene.cameras["ao"],
                        width: 72,
                        height: 64,
                    };
                    let f = backend.render(&scene, view, sampling).unwrap();
                    (f.ambient.unwrap(), f.rays.ambient, f.work)
                };
                let (single, bundled) = (frame(Issue::Single), frame(Issue::Bundled));
                assert!(single.0.iter().filter(|&&v| (0.0..1.0).contains(&v)).count() > 300);
                assert_eq!(single.0, bundled.0, "{name} {rays} {weighting:?}: images differ");
                assert_eq!(single.1, bundled.1, "{name}: ray counts differ");
                assert_eq!(single.2.queries, bundled.2.queries, "{name}: queries differ");
            }
        }
    }
}

/// Rays no renderer casts but a caller may: NaN and infinite components, zero and subnormal
/// directions, zero, negative and NaN `tmax`, origins far outside (1e300) and exactly on the
/// box's planes with a zero component along them. Every structure's bundle answers as its single
/// queries do, and as brute force where the ray is finite.
#[test]
fn degenerate_bundles_answer_as_single_queries() {
    let s = soup(300, 12);
    let (lo, hi) = bounds(&s);
    let mid = (lo + hi) * 0.5;
    let mut r = Rng(77);
    let specials = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
        -0.0,
        f64::MIN_POSITIVE / 4.0,
        -1e-300,
        1.0,
        -1.0,
    ];
    let mut rays: Vec<Ray> = Vec::new();
    for _ in 0..3000 {
        let mut origin = match r.index(4) {
            0 => mid + r.unit() * 1.5,
            1 => point_on(&s.positions[r.index(s.positions.len())], &mut r),
            2 => DVec3::splat(1e300) * r.unit(),
            _ => mid,
        };
        let mut dir = r.unit();
        for a in 0..3 {
            match r.index(6) {
                0 => dir[a] = specials[r.index(specials.len())],
                1 => origin[a] = [lo[a], hi[a], mid[a], f64::NAN][r.index(4)],
                2 => dir[a] = 0.0,
                _ => {}
            }
        }
        let tmax = [f64::INFINITY, 0.0, -1.0, f64::NAN, 0.3, 5.0][r.index(6)];
        let skip = [u32::MAX, r.index(s.positions.len()) as u32][r.index(2)];
        rays.push((origin, dir, tmax, skip));
    }
    let qs = queries(&rays);
    let finite = |q: &Query| {
        q.origin.is_finite() && q.dir.is_finite() && q.tmax.is_finite() && q.origin.abs().max_element() < 1e10
    };
    let want: Vec<bool> = qs.iter().map(|q| brute_any(&s, q)).collect();
    assert!(want.iter().filter(|&&w| w).count() > 100, "some of them hit");
    for reg in REGISTRY {
        let a = penumbra::accel::build(&s, &AccelSettings::default_for(reg))
            .unwrap()
            .unwrap();
        let single: Vec<bool> = qs.iter().map(|q| a.any_hit(q.origin, q.dir, q.tmax, q.skip)).collect();
        let mut hits = vec![true; qs.len()];
        a.any_hits(&qs, &mut hits);
        let differ: Vec<&Query> = (0..qs.len())
            .filter(|&i| hits[i] != single[i])
            .map(|i| &qs[i])
            .collect();
        assert!(
            differ.is_empty(),
            "{}: {} bundled answers differ from single, e.g. {:?}",
            reg.name,
            differ.len(),
            &differ[..differ.len().min(3)]
        );
        if a.bundles() {
            let wrong: Vec<&Query> = (0..qs.len())
                .filter(|&i| finite(&qs[i]) && hits[i] != want[i])
                .map(|i| &qs[i])
                .collect();
            assert!(
                wrong.is_empty(),
                "{}: {} answers differ from brute force, e.g. {:?}",
                reg.name,
                wrong.len(),
                &wrong[..wrong.len().min(3)]
            );
        }
    }
}

/// The field's bundle walk reads the overlay layer and skips the ids a move overwrote with
/// DEAD, as its single walk does: after moving one object, inserting one and removing one,
/// bundled answers equal single ones and brute force over the current triangles.
#[test]
fn a_field_bundle_after_updates_answers_as_brute_force() {
    use penumbra::accel::vlf::{VisibilityField, VlfSettings};
    use penumbra::accel::Accelerator;
    let mut s = soup(400, 21);
    let mut field = VisibilityField::build(
        &s,
        VlfSettings {
            level: 4,
            tiles: 16,
            depth: 2,
            ..VlfSettings::default()
        },
    )
    .unwrap();
    let step = v(0.05, -0.03, 0.02);
    field.move_object(1, |p| p + step).unwrap();
    for (t, &o) in s.positions.iter_mut().zip(&s.object_of) {
        if o == 1 {
            *t = t.map(|p| p + step);
        }
    }
    field.remove_object(2).unwrap();
    let mut r = Rng(4);
    let added: Vec<[DVec3; 3]> = (0..40)
        .map(|_| {
            let c = v(3.0, -2.0, 1.5) + v(r.range(-0.8, 0.8), r.range(-0.8, 0.8), r.range(-0.4, 0.4));
            [c, c + r.unit() * 0.2, c + r.unit() * 0.2]
        })
        .collect();
    field.insert_object(9, &added).unwrap();
    // The current scene: object 2 gone (a point no ray hits keeps the indices), 9 added.
    let gone = [DVec3::splat(1e3); 3];
    let mut now: Vec<[DVec3; 3]> = s
        .positions
        .iter()
        .zip(&s.object_of)
        .map(|(t, &o)| if o == 2 { gone } else { *t })
        .collect();
    now.extend(added);
    let now = Triangles {
        object_of: vec![0; now.len()],
        positions: now,
    };
    let mut rays = random_segments(&now, 1500, &mut r);
    rays.extend(shadow_rays(&now, 1500, &mut r));
    rays.extend(ao_random(&now, 1500, &mut r));
    let qs = queries(&rays);
    let want: Vec<bool> = qs.iter().map(|q| brute_any(&now, q)).collect();
    let single: Vec<bool> = qs
        .iter()
        .map(|q| field.any_hit(q.origin, q.dir, q.tmax, q.skip))
        .collect();
    let mut hits = vec![true; qs.len()];
    Accelerator::any_hits(&field, &qs, &mut hits);
    assert_eq!(single, want, "the updated field's single answers");
    assert_eq!(hits, want, "the updated field's bundled answers");
    assert!(want.iter().filter(|&&w| w).count() > 500 && want.iter().filter(|&&w| !w).count() > 500);
}

/// The bundled AO pass tests the scene's spheres and planes before it asks the structure (a
/// ray a shape blocks is not in the bundle) and serves receivers on them (no triangle to skip):
/// with a sphere and a plane beside the cow, per-pixel and shared disk points, the image, rays
/// and queries equal the single pass's, and the shapes change the image.
#[test]
fn a_bundled_ao_frame_with_spheres_and_planes_is_the_single_frame() {
    use penumbra::scene::shape::{Plane, Sphere};
    let cow = penumbra::experiment::ao::spec::into_unit_ball(common::off_mesh("cow").positions);
    let camera = penumbra::experiment::ao::runner::camera();
    let mut backend = CpuBackend::default();
    let mesh = penumbra::scene::Mesh {
        source: "test".into(),
        file_fnv1a: 0,
        albedo: 0.5,
        mirror: 0.0,
        triangles: cow.positions.len(),
        skipped: Default::default(),
    };
    let scene = |name: &'static str, shapes: bool, ao: AmbientOcclusion| {
        let (spheres, planes) = if shapes {
            (
                vec![Sphere {
                    center: v(0.45, -0.5, 0.35),
                    radius: 0.3,
                    albedo: 0.5,
                }],
                vec![Plane {
                    point: v(0.0, 0.0, -0.45),
                    normal: v(0.0, 0.0, 1.0),
                    albedo: 0.5,
                }],
            )
        } else {
            (vec![], vec![])
        };
        penumbra::scene::Scene::analytic(spheres, planes, vec![])
            .with_meshes(
                vec![mesh.clone()],
                Triangles {
                    positions: cow.positions.clone(),
                    object_of: vec![0; cow.positions.len()],
                },
                AccelSettings::named(name).unwrap(),
            )
            .with_cameras([("ao".to_string(), camera.clone())].into())
            .with_ambient(Some(ao))
    };
    for pattern in [
        penumbra::sampling::Pattern::PerPixel,
        penumbra::sampling::Pattern::Shared,
    ] {
        let sampling = Sampling {
            scheme: penumbra::sampling::DiskScheme::Uniform,
            pattern,
            seed: 5,
            frame: 0,
        };
        for name in ["vlf", "kdtree-sah"] {
            for (directions, rays) in [
                (AoDirections::grid(3), 19),
                (AoDirections::Disk(penumbra::sampling::DiskScheme::Uniform), 16),
            ] {
                let mut frame = |issue: Issue, shapes: bool| {
                    let ao = AmbientOcclusion {
                        directions: directions.clone(),
                        rays,
                        weighting: Weighting::Cosine,
                        max_distance: 3.0,
                        issue,
                    };
                    let scene = scene(name, shapes, ao);
                    let view = View {
                        camera: &scene.cameras["ao"],
                        width: 80,
                        height: 60,
                    };
                    let f = backend.render(&scene, view, sampling).unwrap();
                    (f.ambient.unwrap(), f.rays.ambient, f.work.queries)
                };
                let (single, bundled) = (frame(Issue::Single, true), frame(Issue::Bundled, true));
                let what = format!("{name} {pattern:?} {rays} rays");
                assert_eq!(single.0, bundled.0, "{what}: images differ");
                assert_eq!(
                    (single.1, single.2),
                    (bundled.1, bundled.2),
                    "{what}: rays or queries differ"
                );
                let plain = frame(Issue::Bundled, false).0;
                let changed = (0..plain.len()).filter(|&i| plain[i] != single.0[i]).count();
                assert!(changed > 1000, "{what}: the shapes change {changed} pixels");
            }
        }
    }
}
