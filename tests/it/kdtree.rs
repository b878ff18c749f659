//! The CRT-like kd-tree (`accel::kdtree`): answers equal brute force's bit for bit (same
//! triangle, same t, ties to the lower index) on the shipped OFF meshes and a triangle soup for
//! every ray kind, and on the cases a kd-tree gets wrong first: rays and triangles lying in split
//! planes, axis-parallel rays, origins on planes, far origins, `tmax` exactly at a hit, `skip`,
//! coincident triangles, depth 0 and the deepest tree. Every leaf holds every triangle whose
//! box meets it, and a tree that lost one triangle reference fails the comparison.

use crate::common;

use crate::common::rays::*;
use glam::DVec3;
use penumbra::accel::kdtree::{KdSettings, KdTree, MAX_DEPTH};
use penumbra::accel::vlf::directions::Directions;
use penumbra::accel::{intersect, Accelerator, TriHit};
use penumbra::mesh::Triangles;
use rayon::prelude::*;

/// Brute force's closest hit with the walk's rules: 0 < t < tmax, not `skip`, ties to the lower
/// index.
pub(crate) fn brute(t: &Triangles, (o, d, tmax, skip): Ray) -> Option<TriHit> {
    let mut best: Option<TriHit> = None;
    for (i, tri) in t.positions.iter().enumerate() {
        let i = i as u32;
        match intersect(o, d, tri) {
            Some(h) if i != skip && h > 0.0 && h < tmax && best.is_none_or(|b| h < b.t) => {
                best = Some(TriHit { t: h, triangle: i })
            }
            _ => {}
        }
    }
    best
}

/// Rays the tree answers differently from brute force (closest or any-hit), with a few named.
pub(crate) fn wrong(tree: &KdTree, t: &Triangles, rays: &[Ray]) -> (usize, Vec<String>) {
    let bad: Vec<String> = rays
        .par_iter()
        .filter_map(|&ray| {
            let want = brute(t, ray);
            let got = tree.closest(ray.0, ray.1, ray.2, ray.3);
            let any = tree.any_hit(ray.0, ray.1, ray.2, ray.3);
            (got != want || any != want.is_some()).then(|| format!("{ray:?}: got {got:?} any {any}, want {want:?}"))
        })
        .collect();
    (bad.len(), bad.into_iter().take(3).collect())
}

#[test]
fn every_ray_kind_on_every_mesh_matches_brute_force() {
    let dirs = Directions::new(16);
    let mut scenes: Vec<(String, Triangles)> = ["cow", "mech-holes-shark", "bull", "camel", "man"]
        .iter()
        .map(|m| (m.to_string(), common::off_mesh(m)))
        .collect();
    scenes.push(("soup".into(), soup(3000, 5)));
    for (name, t) in &scenes {
        for settings in [
            KdSettings::default(),
            KdSettings {
                max_depth: 8,
                leaf_size: 16,
                ..KdSettings::default()
            },
        ] {
            let tree = KdTree::build(t, settings);
            let mut hits = 0;
            for (kind, rays) in all_rays(t, &dirs, 1500, 17) {
                hits += rays.iter().filter(|r| brute(t, **r).is_some()).count();
                let (n, examples) = wrong(&tree, t, &rays);
                assert_eq!(
                    n,
                    0,
                    "{name} {kind} {settings:?}: {n} of {} wrong: {examples:#?}",
                    rays.len()
                );
            }
            assert!(hits > 1000, "{name}: the rays must meet the mesh ({hits} hits)");
        }
    }
}

/// An axis-aligned box of side 2 at `c`, its faces as 12 triangles, every face in a plane a
/// spatial-median split can choose; plus a second, coincident copy of one face.
pub(crate) fn boxes(c: DVec3) -> Triangles {
    let mut out = Vec::new();
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |a: f64, b: f64| {
                let mut p = DVec3::ZERO;
                p[axis] = side;
                p[u] = a;
                p[w] = b;
                c + p
            };
            out.push([corner(-1., -1.), corner(1., -1.), corner(1., 1.)]);
            out.push([corner(-1., -1.), corner(1., 1.), corner(-1., 1.)]);
        }
    }
    // Inner walls on the box's median planes, and a face duplicated (a tie on every hit).
    out.push([c + v(0., -1., -1.), c + v(0., 1., -1.), c + v(0., 1., 1.)]);
    out.push([c + v(-1., 0., -1.), c + v(1., 0., -1.), c + v(1., 0., 1.)]);
    out.push(out[0]);
    tris(out)
}

/// Rays along the axes and diagonals from points on the box's faces and median planes, from
/// inside and outside, with and without `tmax` and `skip`.
pub(crate) fn plane_rays(c: DVec3, r: &mut Rng) -> Vec<Ray> {
    let mut dirs: Vec<DVec3> = Vec::new();
    for a in 0..3 {
        for s in [-1.0, 1.0] {
            let mut d = DVec3::ZERO;
            d[a] = s;
            dirs.push(d);
        }
    }
    dirs.extend([v(1., 1., 0.), v(1., 0., -1.), v(0., -1., 1.), v(1., 1., 1.)].map(|d| d.normalize()));
    let grid = [-1.0, -0.5, 0.0, 0.5, 1.0, 1.5, -3.0];
    let mut out = Vec::new();
    for &x in &grid {
        for &y in &grid {
            for &z in &grid {
                let o = c + v(x, y, z);
                for &d in &dirs {
                    out.push((o, d, f64::INFINITY, u32::MAX));
                    out.push((o, d, 1.0, u32::MAX));
                    out.push((o, d, f64::INFINITY, r.index(15) as u32));
                }
            }
        }
    }
    out
}

#[test]
fn rays_and_triangles_in_split_planes_match_brute_force() {
    let mut r = Rng(3);
    for c in [DVec3::ZERO, v(1e6, -1e6, 3e5), v(0.25, 0.5, -0.75)] {
        let t = boxes(c);
        let rays = plane_rays(c, &mut r);
        for settings in [
            KdSettings::default(),
            KdSettings {
                max_depth: 0,
                leaf_size: 4,
                ..KdSettings::default()
            },
            KdSettings {
                max_depth: MAX_DEPTH,
                leaf_size: 0,
                ..KdSettings::default()
            },
        ] {
            let tree = KdTree::build(&t, settings);
            let (n, examples) = wrong(&tree, &t, &rays);
            assert_eq!(
                n,
                0,
                "box at {c}, {settings:?}: {n} of {} wrong: {examples:#?}",
                rays.len()
            );
        }
    }
}

#[test]
fn tmax_at_a_hit_and_ties_follow_brute_force() {
    let t = boxes(DVec3::ZERO);
    let tree = KdTree::build(&t, KdSettings::default());
    let (o, d) = (v(-3.0, 0.3, 0.2), DVec3::X);
    let first = tree.closest(o, d, f64::INFINITY, u32::MAX).unwrap();
    // Face 0 (x = -1) and its copy (the last triangle) tie: the lower index wins.
    assert_eq!(Some(first), brute(&t, (o, d, f64::INFINITY, u32::MAX)));
    assert_eq!(first.triangle, 0);
    assert!((first.t - 2.0).abs() < 1e-12);
    // tmax exactly at the hit excludes it (0 < t < tmax), as brute force does.
    let at = (o, d, first.t, u32::MAX);
    assert_eq!(tree.closest(at.0, at.1, at.2, at.3), brute(&t, at));
    assert!(brute(&t, at).is_none_or(|h| h.t < first.t));
    assert!(!tree.any_hit(o, d, first.t, u32::MAX));
    // Skipping the winner gives its copy, at the same distance.
    let copy = tree.closest(o, d, f64::INFINITY, 0).unwrap();
    assert_eq!((copy.triangle, copy.t), (t.positions.len() as u32 - 1, first.t));
}

/// Every triangle whose bounding box meets a leaf's box is in the leaf.
#[test]
fn leaves_hold_every_triangle_that_meets_them() {
    let t = soup(2000, 9);
    let tree = KdTree::build(&t, KdSettings::default());
    let mut leaves = 0;
    let mut stack = vec![(0usize, tree.bounds)];
    while let Some((n, (lo, hi))) = stack.pop() {
        match tree.split(n) {
            Some((axis, split, left)) => {
                let (mut a, mut b) = ((lo, hi), (lo, hi));
                a.1[axis] = split;
                b.0[axis] = split;
                stack.push((left, a));
                stack.push((left + 1, b));
            }
            None => {
                leaves += 1;
                let (first, count) = tree.nodes[n].items();
                let held = &tree.items[first..first + count];
                for (i, tri) in t.positions.iter().enumerate() {
                    let (a, b) = (tri[0].min(tri[1]).min(tri[2]), tri[0].max(tri[1]).max(tri[2]));
                    if a.cmple(hi).all() && b.cmpge(lo).all() {
                        assert!(held.contains(&(i as u32)), "triangle {i} missing from leaf {n}");
                    }
                }
            }
        }
    }
    assert!(leaves > 100, "{leaves} leaves");
    assert!(tree.depth <= KdSettings::default().max_depth);
}

#[test]
fn a_tree_that_lost_a_triangle_reference_is_caught() {
    let t = common::off_mesh("cow");
    let mut tree = KdTree::build(&t, KdSettings::default());
    let dirs = Directions::new(16);
    let rays = ao_grid(&t, &dirs, 4000, &mut Rng(21));
    assert_eq!(wrong(&tree, &t, &rays).0, 0);
    // Point every reference to triangle 100 elsewhere: rays that hit it first must now differ.
    let lost = 100u32;
    tree.items
        .iter_mut()
        .filter(|i| **i == lost)
        .for_each(|i| *i = lost + 1);
    let aimed: Vec<Ray> = (0..200)
        .map(|k| {
            let p = point_on(&t.positions[lost as usize], &mut Rng(k));
            let n = normal(&t.positions[lost as usize]);
            (p + n * 0.01, -n, f64::INFINITY, u32::MAX)
        })
        .collect();
    let (n, _) = wrong(&tree, &t, &aimed);
    assert!(n > 100, "only {n} of 200 rays aimed at the lost triangle noticed");
}

/// Splits are stored from the root box's corner, not from the origin: a mesh far from the origin
/// gets the tree it gets at home (an absolute f32 split there would round the planes away and
/// leave a near brute-force tree), and still answers as brute force does.
#[test]
fn a_mesh_far_from_the_origin_keeps_its_tree() {
    let home = common::off_mesh("cow");
    let nodes_at_home = KdTree::build(&home, KdSettings::default()).nodes.len();
    for offset in [1e6, 1e7] {
        let far = tris(
            home.positions
                .iter()
                .map(|t| t.map(|p| p + DVec3::splat(offset)))
                .collect(),
        );
        let tree = KdTree::build(&far, KdSettings::default());
        assert!(
            tree.nodes.len() * 2 > nodes_at_home,
            "offset {offset}: {} nodes, {nodes_at_home} at home",
            tree.nodes.len()
        );
        let rays = ao_random(&far, 2000, &mut Rng(31));
        let (n, examples) = wrong(&tree, &far, &rays);
        assert_eq!(n, 0, "offset {offset}: {examples:#?}");
    }
}

/// Slivers crossing one another straddle every plane, so each leaf of a deep tree holds nearly
/// all of them: a build over a budget of leaf entries stops and says so (instead of taking
/// 2^depth copies of the triangles), and a build within its budget is the unbudgeted tree.
#[test]
fn a_tree_whose_leaves_outgrow_their_budget_is_refused() {
    // Near-diameters of a circle of 1024 points, one from each point: every plane across the
    // disc cuts most of them.
    let n = 1024;
    let at = |k: usize| {
        let a = std::f64::consts::TAU * (k % n) as f64 / n as f64;
        DVec3::new(a.cos(), a.sin(), 0.0)
    };
    let mut slivers: Vec<[DVec3; 3]> = (0..n).map(|k| [at(k), at(k + n / 2 - 1), at(k + n / 2)]).collect();
    // One small triangle off to the side moves the median planes off the centre.
    let off = DVec3::new(1.6, 1.3, 0.0);
    slivers.push([off, off + DVec3::X * 0.01, off + DVec3::Y * 0.01]);
    let crossing = tris(slivers);
    let deep = KdSettings {
        max_depth: 20,
        ..KdSettings::default()
    };
    let Err(e) = KdTree::within(&crossing, deep, 1_000_000) else {
        panic!("a tree over crossing slivers within a million entries");
    };
    assert!(
        e.contains("more than 1000000 triangle entries") && e.contains("max_depth"),
        "{e}"
    );
    let mesh = common::off_mesh("cow");
    let settings = KdSettings::default();
    let unbounded = KdTree::build(&mesh, settings);
    let within = KdTree::within(&mesh, settings, 10 * mesh.positions.len() * 64).unwrap();
    let rays = random_segments(&mesh, 2000, &mut Rng(5));
    for &ray in &rays {
        let (o, d, tmax, skip) = ray;
        assert_eq!(unbounded.closest(o, d, tmax, skip), within.closest(o, d, tmax, skip));
    }
    assert_eq!(unbounded.stats().memory_bytes, within.stats().memory_bytes);
}
