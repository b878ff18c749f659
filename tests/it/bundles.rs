//! Ray bundles (`Accelerator::any_hits`): every structure's bundled answers equal brute force
//! and its own single queries, hit for hit, on every kind of ray and on the hard cases (zero and
//! -0.0 direction components, rays that miss the bounds, mixed octants, empty and one-ray
//! bundles); the field's bundle walk does exactly the single walks' work, the kd-tree's packets
//! the same triangle tests in fewer node visits; and an AO frame issued direction-major is the
//! single-ray frame to the bit.

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
    let want: Vec<bool> = qs.par_iter().map(|q| brute_any(t, q)).collect();
    for r in REGISTRY {
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

/// A closed box with inner walls, rays along the axes with +0.0 and -0.0 components from on and
/// off the planes, outside the bounds, with a short tmax and a skipped triangle, mixed in one
/// bundle; and the empty and one-ray bundles.
#[test]
fn hard_bundles_match_brute_force() {
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
    let t = tris(out);
    let mut dirs = Vec::new();
    for a in 0..3 {
        let mut d = DVec3::ZERO;
        d[a] = 1.0;
        dirs.extend([d, -d]);
    }
    dirs.extend([v(1., 1., 0.), v(-1., -1., -0.), v(-0., -1., 1.), v(0.3, -0.2, 0.9)].map(|d| d.normalize()));
    let grid = [-1.0, -0.5, 0.0, 0.5, 1.0, 1.5, -3.0];
    let mut rays = Vec::new();
    let mut r = Rng(5);
    for &x in &grid {
        for &y in &grid {
            for &z in &grid {
                for &d in &dirs {
                    rays.push((v(x, y, z), d, f64::INFINITY, u32::MAX));
                    rays.push((v(x, y, z), d, 0.5, u32::MAX));
                    rays.push((v(x, y, z), d, f64::INFINITY, r.index(14) as u32));
                }
            }
        }
    }
    let qs = queries(&rays);
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

/// The field's bundle walk reorders memory traffic only: its work equals the single walks'. The
/// kd-tree's packets test the same triangles (each lane meets its own leaves in its own order and
/// stops at its first hit) and fetch each node once per packet: fewer node visits on coherent AO
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
        assert_eq!(single.primitives, bundled.primitives, "{name}: the same triangle tests");
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
