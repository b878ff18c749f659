//! The visibility field's WGSL walk (and the kd-tree's) against the BVH's WGSL walk on the same
//! GPU, over the shipped meshes: all test the same f32 triangles with the same `triangle_t`, so
//! any ray on which they disagree (hit or miss, triangle, t) is a candidate a walk dropped. Ray kinds:
//! random segments, AO rays along the field's own grid directions and in random directions,
//! shadow rays to a 4 cm disk light, camera rays; 100K of each on every shipped mesh and on the
//! body. About 80 s on lavapipe (2 cores), the fields' builds included.

#![cfg(feature = "test-hooks")]

use crate::common;

use glam::DVec3;
use penumbra::accel::vlf::directions::Directions;
use penumbra::accel::vlf::VlfSettings;
use penumbra::mesh::Triangles;
use penumbra::render::gpu::ProbeHit;
use penumbra::sampling::Stream;
use penumbra::scene::Scene;

/// Rays per kind per mesh.
const RAYS: u32 = 100_000;

/// Seeded rays of the five kinds over `t`: (kind, origin, unit direction, tmax).
fn rays(t: &Triangles) -> Vec<(&'static str, DVec3, DVec3, f64)> {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in t.positions.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let (centre, size) = (0.5 * (lo + hi), (hi - lo).length());
    let s = Stream::new(2026, 12, None);
    let grid = Directions::new(VlfSettings::default().level);
    let mut out = Vec::new();
    let unit = |k: u32, i: u32| s.unit(16 * k + i);
    let sphere = |k: u32, i: u32| {
        let z = 2.0 * unit(k, i) - 1.0;
        let phi = std::f64::consts::TAU * unit(k, i + 1);
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    // A point on a triangle, lifted off it along its normal, and that normal.
    let surface = |k: u32| {
        let tri = &t.positions[(unit(k, 0) * t.positions.len() as f64) as usize % t.positions.len()];
        let (a, b) = (unit(k, 1), unit(k, 2));
        let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
        let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
        (
            tri[0] + (tri[1] - tri[0]) * a + (tri[2] - tri[0]) * b + n * 1e-5 * size,
            n,
        )
    };
    let light = centre + DVec3::new(0.3, -0.2, 1.0) * size;
    for k in 0..RAYS {
        let a = lo + (hi - lo) * DVec3::new(unit(k, 3), unit(k, 4), unit(k, 5)) * 1.2 - (hi - lo) * 0.1;
        let b = lo + (hi - lo) * DVec3::new(unit(k, 6), unit(k, 7), unit(k, 8)) * 1.2 - (hi - lo) * 0.1;
        out.push(("segment", a, (b - a).normalize(), (b - a).length()));
        let (p, n) = surface(k);
        let g = grid.direction((unit(k, 9) * grid.len() as f64) as u32 % grid.len() as u32);
        out.push(("ao-grid", p, if g.dot(n) < 0.0 { -g } else { g }, 0.5 * size));
        let r = sphere(k, 10);
        out.push(("ao-random", p, if r.dot(n) < 0.0 { -r } else { r }, 0.5 * size));
        let (rho, phi) = (0.02 * unit(k, 12).sqrt(), std::f64::consts::TAU * unit(k, 13));
        let q = light + DVec3::new(rho * phi.cos(), rho * phi.sin(), 0.0);
        out.push(("shadow", p, (q - p).normalize(), (q - p).length()));
        let eye = centre - DVec3::new(0.2, 1.0, -0.3).normalize() * 2.0 * size;
        out.push(("camera", eye, (a - eye).normalize(), f64::INFINITY));
    }
    out
}

fn check(name: &str, t: &Triangles) {
    let Some(mut gpu) = common::gpu() else { return };
    let rays = rays(t);
    let probes: Vec<_> = rays.iter().map(|&(_, o, d, tmax)| (o, d, tmax)).collect();
    let bvh: Vec<ProbeHit> = gpu.probe(&common::triangles_scene(t, "bvh"), &probes).unwrap();
    let mut hits = std::collections::BTreeMap::<&str, (u32, u32)>::new();
    // The field, and the kd-tree (whose WGSL walk is checked here on whole meshes).
    for structure in ["vlf", "kdtree"] {
        let other: Vec<ProbeHit> = gpu.probe(&common::triangles_scene(t, structure), &probes).unwrap();
        for ((kind, ..), (b, v)) in rays.iter().zip(bvh.iter().zip(&other)) {
            let entry = hits.entry(kind).or_default();
            entry.0 += b.any as u32;
            entry.1 += 1;
            assert_eq!(v.any, b.any, "{name} {structure} {kind}: any-hit differs");
            match (v.closest, b.closest) {
                // Equal t on two triangles (a shared edge): the field and the kd-tree take the
                // lower index, the BVH the first it meets.
                (Some((tv, iv)), Some((tb, ib))) => assert!(
                    tv == tb && iv <= ib,
                    "{name} {structure} {kind}: closest ({tv}, {iv}) vs BVH ({tb}, {ib})"
                ),
                (None, None) => {}
                (v, b) => panic!("{name} {structure} {kind}: closest {v:?} vs BVH {b:?}"),
            }
        }
    }
    for (kind, (hit, n)) in hits {
        assert!(
            hit > n / 50 && hit < n,
            "{name} {kind}: {hit} of {n} rays hit; the rays must test something"
        );
    }
}

#[test]
fn off_meshes_on_the_gpu_match_the_bvh() {
    for name in ["cow", "mech-holes-shark", "bull", "camel", "man"] {
        check(name, &common::off_mesh(name));
    }
}

#[test]
fn body_on_the_gpu_matches_the_bvh() {
    let body = Scene::load(&common::repo("experiments/scenes/body.toml")).unwrap();
    check("body", &body.triangles);
}

/// An octahedron of unit corners: its corners are its farthest points, so the field's ball
/// passes through them.
fn octahedron() -> Triangles {
    let c = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y];
    let mut positions = Vec::new();
    for i in 0..4 {
        positions.push([c[i], c[(i + 1) % 4], DVec3::Z]);
        positions.push([c[(i + 1) % 4], c[i], -DVec3::Z]);
    }
    Triangles {
        object_of: vec![0; positions.len()],
        positions,
    }
}

/// The WGSL answers of `field`, a scene of triangles `t` indexed by a visibility field, on
/// `probes` equal brute force's WGSL answers over `t` (any-hit, closest triangle and t);
/// returns how many rays hit.
fn assert_matches_brute_force(t: &Triangles, field: &Scene, probes: &[(DVec3, DVec3, f64)]) -> usize {
    let Some(mut gpu) = common::gpu() else {
        return usize::MAX;
    };
    let brute = gpu.probe(&common::triangles_scene(t, "brute"), probes).unwrap();
    let vlf = gpu.probe(field, probes).unwrap();
    let bad: Vec<_> = brute
        .iter()
        .zip(&vlf)
        .enumerate()
        .filter(|(_, (b, v))| b.any != v.any || b.closest != v.closest)
        .collect();
    assert!(
        bad.is_empty(),
        "{} of {} rays differ, first: {:?} at {:?}",
        bad.len(),
        probes.len(),
        bad[0],
        probes[bad[0].0]
    );
    brute.iter().filter(|h| h.any).count()
}

/// Geometry touching the ball: an octahedron's corners are its farthest points, so the ball
/// passes through them; rays aimed at corners and edge midpoints from every side (and along
/// the grid's own directions) hit there, at the ball's rim. The reference is brute force's WGSL
/// (every triangle tested): at shared corners f32 rounding lets a hit fall just outside a
/// triangle's bounds, which the BVH's boxes do not allow for (a finding of this test: on ray
/// 1235 the BVH reports triangle 3 at t = 2.9999974 where triangle 4 is hit at 2.9999962).
#[test]
fn corners_on_the_ball_on_the_gpu_match_brute_force() {
    let t = octahedron();
    let targets: Vec<DVec3> = [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y, -DVec3::Z]
        .into_iter()
        .chain(t.positions.iter().map(|p| 0.5 * (p[0] + p[1])))
        .collect();
    let grid = Directions::new(VlfSettings::default().level);
    let s = Stream::new(7, 0, None);
    let mut probes = Vec::new();
    for (k, target) in targets.iter().enumerate() {
        for j in 0..400u32 {
            let i = (k as u32) * 400 + j;
            let d = if j % 2 == 0 {
                grid.direction((s.unit(3 * i) * grid.len() as f64) as u32 % grid.len() as u32)
            } else {
                DVec3::new(s.unit(3 * i) - 0.5, s.unit(3 * i + 1) - 0.5, s.unit(3 * i + 2) - 0.5).normalize()
            };
            let d = if d.dot(*target) > 0.0 { -d } else { d };
            probes.push((*target - d * 3.0, d, f64::INFINITY));
        }
    }
    let hits = assert_matches_brute_force(&t, &common::triangles_scene(&t, "vlf"), &probes);
    assert!(hits > probes.len() / 2, "{hits} of {} rays hit", probes.len());
}

/// A triangle exactly at the end of a segment is not hit (0 < t < tmax), as brute force's WGSL
/// and the CPU answer: rays down the z axis ending on the lower of two stacked triangles.
#[test]
fn a_hit_at_tmax_is_not_a_hit_on_the_gpu() {
    let corners = |z: f64| {
        [
            DVec3::new(-1.0, -1.0, z),
            DVec3::new(1.0, -1.0, z),
            DVec3::new(0.0, 1.0, z),
        ]
    };
    let t = Triangles {
        positions: vec![corners(0.0), corners(0.5)],
        object_of: vec![0, 0],
    };
    let probes: Vec<_> = (0..64)
        .map(|i| {
            let (x, y) = ((i % 8) as f64 / 32.0 - 0.1, (i / 8) as f64 / 32.0 - 0.1);
            // Ends exactly on the lower triangle; passes the upper one only for i odd.
            let z = if i % 2 == 0 { 0.25 } else { 1.0 };
            (DVec3::new(x, y, z), DVec3::NEG_Z, z)
        })
        .collect();
    let hits = assert_matches_brute_force(&t, &common::triangles_scene(&t, "vlf"), &probes);
    assert!(hits == 32 || hits == usize::MAX, "{hits} rays hit the upper triangle");
}

/// Geometry touching the ball seen from 30 to 3000 radii away: f32 rounding of the ray's
/// segment inside the ball must not drop its ends.
#[test]
fn far_origins_on_the_gpu_match_brute_force() {
    let t = octahedron();
    let s = Stream::new(11, 0, None);
    let mut probes = Vec::new();
    for (j, dist) in [30.0, 300.0, 3000.0].into_iter().enumerate() {
        for i in 0..2000u32 {
            let i = i + 2000 * j as u32;
            let u = |k: u32| s.unit(4 * i + k);
            let d = DVec3::new(u(0) - 0.5, u(1) - 0.5, u(2) - 0.5).normalize();
            let corner = [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y, -DVec3::Z][i as usize % 6];
            probes.push((corner * (0.99 + 0.01 * u(3)) - d * dist, d, f64::INFINITY));
        }
    }
    let hits = assert_matches_brute_force(&t, &common::triangles_scene(&t, "vlf"), &probes);
    assert!(hits > probes.len() / 2, "{hits} of {} rays hit", probes.len());
}

/// After dynamic updates (an object removed, one moved, one inserted) the field's WGSL walk
/// reads the base layer with the removed ids and the overlay layer of moved and inserted
/// triangles, and answers as brute force's WGSL over the updated triangles.
#[test]
fn dynamic_updates_on_the_gpu_match_brute_force() {
    use crate::common::rays::{all_rays, soup};
    use penumbra::accel::vlf::VisibilityField;
    let t = soup(400, 11);
    let settings = VlfSettings {
        level: 8,
        tiles: 64,
        ..VlfSettings::default()
    };
    let mut field = VisibilityField::build(&t, settings).unwrap();
    let mut current = t.clone();
    common::updates::remove(&mut field, &mut current, 1);
    common::updates::move_and_insert(&mut field, &mut current);
    assert_eq!(field.world.len(), current.positions.len());

    let probes: Vec<_> = all_rays(&current, &field.frame.directions.clone(), 2000, 3)
        .into_iter()
        .flat_map(|(_, rays)| rays)
        .map(|(o, d, tmax, _)| (o, d, tmax))
        .collect();
    let mut updated = common::triangles_scene(&current, "vlf");
    updated.accel = Some(std::sync::Arc::new(field));
    let hits = assert_matches_brute_force(&current, &updated, &probes);
    assert!(hits > probes.len() / 10, "{hits} of {} rays hit", probes.len());
}

/// The field's WGSL walk at the 16-bit id boundary: 0xffff triangles (one-word entries, the
/// last id 0xfffe) and 0x10000 (two words), answering as the BVH's WGSL when built, after the
/// object with the last indices is removed, after a move (a narrow overlay, under a wide base
/// for 0x10000) and after an insert past 0xffff (a wide overlay over a narrow base). The BVH,
/// not brute force, is the reference: brute force's two loops over 65K triangles pass lavapipe's
/// 65535-iteration loop cap (`render::gpu::loop_cap`) and its any-hit comes back cut short.
#[test]
fn ids_at_the_16_bit_boundary_on_the_gpu_match_the_bvh() {
    use crate::visibility_field_lean::{boundary_scene, boundary_settings, boundary_updates, lean_rays};
    use penumbra::accel::vlf::{Split, VisibilityField};
    let on_gpu = |field: &VisibilityField, t: &Triangles, label: &str| {
        let Some(mut gpu) = common::gpu() else { return };
        let probes: Vec<_> = lean_rays(t, field, 300, 5)
            .into_iter()
            .map(|(o, d, tmax, _)| (o, d, tmax))
            .collect();
        // The field's WGSL is chosen by its name; "brute" only keeps the scene's own build cheap.
        let mut scene = common::triangles_scene(t, "brute");
        scene.accel = Some(std::sync::Arc::new(field.clone()));
        let vlf = gpu.probe(&scene, &probes).unwrap();
        let bvh = gpu.probe(&common::triangles_scene(t, "bvh"), &probes).unwrap();
        let mut hits = 0;
        for (i, (v, b)) in vlf.iter().zip(&bvh).enumerate() {
            assert_eq!(v.any, b.any, "{label}: any-hit differs on ray {i} {:?}", probes[i]);
            hits += b.any as usize;
            match (v.closest, b.closest) {
                // Equal t on two triangles: the field takes the lower index, the BVH the first
                // it meets.
                (Some((tv, iv)), Some((tb, ib))) => assert!(
                    tv == tb && iv <= ib,
                    "{label}: closest ({tv}, {iv}) vs BVH ({tb}, {ib}) on ray {i} {:?}",
                    probes[i]
                ),
                (None, None) => {}
                (v, b) => panic!("{label}: closest {v:?} vs BVH {b:?} on ray {i} {:?}", probes[i]),
            }
        }
        assert!(hits > probes.len() / 10, "{label}: {hits} of {} rays hit", probes.len());
    };
    for (n, split) in [(0xffff, Split::Uniform), (0x10000, Split::Median)] {
        let t = boundary_scene(n, 7);
        let mut field = VisibilityField::build(&t, boundary_settings(split)).unwrap();
        assert_eq!(field.base.wide, n > 0xffff);
        on_gpu(&field, &t, &format!("{n}: built"));
        let mut current = t.clone();
        boundary_updates(&mut field, &mut current, |f, c, label| {
            on_gpu(f, c, &format!("{n}: {label}"))
        });
    }
}
