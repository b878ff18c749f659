//! The visibility field (`accel::vlf`) answers exactly what brute force over every triangle
//! answers (same triangle, same t, hit or miss), on seeded rays of every kind the renderer and
//! the AO experiments cast, and on the hard cases of its own construction: rays along a stored
//! direction and its opposite, rays on tile boundaries, rays starting or ending on a triangle,
//! grazing rays, triangles on tile boundaries, degenerate, spanning every tile or far smaller
//! than one, geometry touching the ball, an empty scene, one triangle, both split kinds and
//! several levels and tile counts; and after removing, inserting and moving objects.
//!
//! The ray generators (`common::rays`) take any `Triangles`; the shipped OFF meshes are checked
//! with them in `visibility_field_meshes.rs`.

use crate::common;

use crate::common::rays::*;
use glam::DVec3;
use penumbra::accel::brute::Brute;
use penumbra::accel::vlf::directions::Directions;
use penumbra::accel::vlf::{Split, VisibilityField, VlfSettings};
use penumbra::accel::{Accelerator, TriHit};
use penumbra::mesh::Triangles;

/// Compares the field with brute force on every ray: (closest mismatches, any-hit mismatches),
/// printing the first few.
fn mismatches(field: &VisibilityField, t: &Triangles, rays: &[Ray], label: &str) -> (usize, usize) {
    let brute = Brute::build(t);
    let (mut c, mut a) = (0, 0);
    for &(o, d, tmax, skip) in rays {
        let want: Option<TriHit> = brute.closest(o, d, tmax, skip);
        let got = field.closest(o, d, tmax, skip);
        if got != want {
            if c < 3 {
                eprintln!("{label}: closest o={o:?} d={d:?} tmax={tmax} skip={skip}: got {got:?}, want {want:?}");
            }
            c += 1;
        }
        if field.any_hit(o, d, tmax, skip) != want.is_some() {
            if a < 3 {
                eprintln!(
                    "{label}: any o={o:?} d={d:?} tmax={tmax} skip={skip}: want {}",
                    want.is_some()
                );
            }
            a += 1;
        }
    }
    (c, a)
}

fn check(field: &VisibilityField, t: &Triangles, rays: &[Ray], label: &str) {
    let (c, a) = mismatches(field, t, rays, label);
    assert_eq!(
        (c, a),
        (0, 0),
        "{label}: {c} closest and {a} any-hit answers differ from brute force"
    );
}

fn check_all(t: &Triangles, settings: VlfSettings, n: usize, seed: u32, label: &str) -> VisibilityField {
    let field = VisibilityField::build(t, settings).unwrap();
    for (kind, rays) in all_rays(t, &field.frame.directions, n, seed) {
        check(&field, t, &rays, &format!("{label} {kind} ({})", settings.describe()));
    }
    field
}

/// A grid of triangles whose corners lie on tile boundaries of the `+z` direction (whose tiles
/// are aligned with world x, y) for tile counts dividing 8, two triangles touching the unit
/// ball at the poles (fixing the ball: centre 0, radius 1), and one spanning every tile.
fn boundary_scene() -> Triangles {
    let mut out = vec![
        [v(0., 0., 1.), v(0.01, 0., 0.9), v(0., 0.01, 0.9)],
        [v(0., 0., -1.), v(0.01, 0., -0.9), v(0., 0.01, -0.9)],
    ];
    let g = |i: i32| i as f64 * 0.25;
    for i in -2..2 {
        for j in -2..2 {
            let z = 0.1 * (i * 3 + j) as f64;
            out.push([v(g(i), g(j), z), v(g(i + 1), g(j), z), v(g(i + 1), g(j + 1), z + 0.05)]);
            out.push([v(g(i), g(j), z), v(g(i + 1), g(j + 1), z + 0.05), v(g(i), g(j + 1), z)]);
            // Edge-on to +z: a wall on a tile boundary.
            out.push([v(g(i), g(j), -0.5), v(g(i), g(j + 1), -0.5), v(g(i), g(j), -0.3)]);
        }
    }
    // Spans the ball's whole cross-section in every direction it is not edge-on to.
    let s = 0.999;
    out.push([
        v(-s, -0.0, 0.02),
        v(s * 0.5, -s * 0.866, 0.02),
        v(s * 0.5, s * 0.866, 0.02),
    ]);
    tris(out)
}

/// Rays along tile boundaries of the `+z` direction: along `+-z` on edges and corners, and
/// perpendicular to the beam lying in a boundary plane.
fn boundary_rays(r: &mut Rng) -> Vec<Ray> {
    let mut out = Vec::new();
    for i in -4..=4 {
        for j in -4..=4 {
            let (x, y) = (i as f64 * 0.125, j as f64 * 0.125);
            out.push((v(x, y, -2.0), DVec3::Z, f64::INFINITY, u32::MAX));
            out.push((v(x, y, 2.0), DVec3::NEG_Z, f64::INFINITY, u32::MAX));
            out.push((v(x, y, r.range(-1., 1.)), DVec3::Z, r.range(0.1, 2.), u32::MAX));
            out.push((v(x, -2.0, r.range(-0.6, 0.6)), DVec3::Y, f64::INFINITY, u32::MAX));
            out.push((v(-2.0, y, r.range(-0.6, 0.6)), DVec3::X, f64::INFINITY, u32::MAX));
            let d = v(r.range(-1., 1.), r.range(-1., 1.), r.range(-1., 1.)).normalize();
            out.push((v(x, y, r.range(-0.5, 0.5)) - 3.0 * d, d, f64::INFINITY, u32::MAX));
        }
    }
    out
}

/// The direction set has the paper's 513 lines at level 16, and the table's choice is never
/// more than a documented angle worse than the exact nearest over 1e6 seeded directions.
#[test]
fn direction_table_is_near_nearest() {
    for (level, count, samples) in [(16u32, 513usize, 1_000_000usize), (4, 33, 200_000), (1, 3, 10_000)] {
        let dirs = Directions::new(level);
        assert_eq!(dirs.len(), count);
        for k in 0..count as u32 {
            let [a, b, w] = dirs.rotation(k);
            assert!((a.dot(b)).abs() < 1e-12 && (a.dot(w)).abs() < 1e-12 && (a.cross(b) - w).length() < 1e-12);
        }
        let mut r = Rng(level * 77);
        let (mut worst, mut worst_nearest, mut worst_excess) = (0f64, 0f64, 0f64);
        for _ in 0..samples {
            let d = r.unit();
            let (got, best) = (dirs.lookup(d), dirs.nearest_exhaustive(d));
            let (a, b) = (dirs.angle(d, got), dirs.angle(d, best));
            worst = worst.max(a);
            worst_nearest = worst_nearest.max(b);
            worst_excess = worst_excess.max(a - b);
            // Lines: the opposite direction gets the same one.
            assert_eq!(dirs.lookup(-d), got);
        }
        eprintln!(
            "level {level}: worst angle to the table's direction {:.3} deg, to the nearest {:.3} deg, worst excess {:.4} deg",
            worst.to_degrees(),
            worst_nearest.to_degrees(),
            worst_excess.to_degrees()
        );
        // Documented bound (accel::vlf::directions): at level 16 the table's line is at most
        // 1.3 degrees farther than the exact nearest line, and at most 5.7 degrees off (measured:
        // 1.23 and 5.60; the exact nearest is at most 5.00 off).
        if level == 16 {
            assert!(worst_excess.to_degrees() < 1.3, "excess {}", worst_excess.to_degrees());
            assert!(worst.to_degrees() < 5.7, "worst {}", worst.to_degrees());
            assert!((worst_nearest.to_degrees() - 5.0).abs() < 0.05);
        }
        // Every stored direction maps to itself.
        for k in 0..count as u32 {
            assert_eq!(dirs.lookup(dirs.direction(k)), k, "level {level} direction {k}");
        }
    }
}

/// Random soup (mixed sizes, slivers, degenerate triangles, far from the origin), every ray
/// kind, both split kinds, several levels and tile counts.
#[test]
fn soup_matches_brute_force() {
    let t = soup(600, 3);
    for (i, (level, tiles, depth, split)) in [
        (16, 128, 4, Split::Uniform),
        (16, 128, 4, Split::Median),
        (4, 32, 3, Split::Uniform),
        (2, 7, 5, Split::Median),
        (1, 1, 0, Split::Uniform),
        (8, 64, 2, Split::Median),
    ]
    .into_iter()
    .enumerate()
    {
        let settings = VlfSettings {
            level,
            tiles,
            depth,
            split,
            leaf_size: 2,
        };
        check_all(&t, settings, 1500, 100 + i as u32, "soup");
    }
}

/// Corners on tile boundaries, walls edge-on to the beam on boundaries, geometry touching the
/// ball, a triangle spanning every tile; rays along boundaries, edges and corners.
#[test]
fn tile_boundaries_match_brute_force() {
    let t = boundary_scene();
    let mut r = Rng(9);
    let rays = boundary_rays(&mut r);
    for (tiles, split) in [
        (8, Split::Uniform),
        (8, Split::Median),
        (16, Split::Uniform),
        (128, Split::Median),
    ] {
        let settings = VlfSettings {
            tiles,
            split,
            leaf_size: 1,
            ..VlfSettings::default()
        };
        let field = check_all(&t, settings, 800, tiles, "boundary");
        check(&field, &t, &rays, &format!("boundary rays {}", settings.describe()));
    }
}

/// No triangles: never a hit. One triangle: hits exactly where brute force hits.
#[test]
fn empty_and_single_triangle() {
    let empty = Triangles::default();
    let field = VisibilityField::build(&empty, VlfSettings::default()).unwrap();
    assert!(field.closest(DVec3::ZERO, DVec3::Z, f64::INFINITY, u32::MAX).is_none());
    assert!(!field.any_hit(v(1., 2., 3.), DVec3::X, 5.0, u32::MAX));
    let one = tris(vec![[v(0.1, 0.2, 0.3), v(1.1, 0.2, 0.4), v(0.1, 1.3, 0.2)]]);
    for split in [Split::Uniform, Split::Median] {
        let settings = VlfSettings {
            split,
            leaf_size: 0,
            ..VlfSettings::default()
        };
        check_all(&one, settings, 500, 5, "single");
    }
}

/// The body mesh (32K triangles): every ray kind against brute force.
#[test]
fn body_mesh_matches_brute_force() {
    let body = penumbra::scene::Scene::load(&common::repo("experiments/scenes/body.toml")).unwrap();
    let settings = VlfSettings {
        level: 8,
        tiles: 64,
        ..VlfSettings::default()
    };
    let field = check_all(&body.triangles, settings, 300, 21, "body");
    eprintln!("{}", field.stats().description);
}

/// A field whose tile lists lost entries is caught: dropping every id of the tiles in one
/// direction makes rays along it miss.
#[test]
fn a_broken_field_is_caught() {
    let t = soup(300, 8);
    let mut field = VisibilityField::build(&t, VlfSettings::default()).unwrap();
    let rays: Vec<Ray> = all_rays(&t, &field.frame.directions, 3000, 4)
        .into_iter()
        .flat_map(|(_, r)| r)
        .collect();
    assert_eq!(mismatches(&field, &t, &rays, "intact"), (0, 0));
    // Break: every direction loses the first id of each non-split tile.
    for k in 0..field.base.offsets.tiles() {
        let (start, end, split) = field.base.offsets.block(k);
        if !split && end > start {
            field.base.kill_at(start);
        }
    }
    let (c, a) = mismatches(&field, &t, &rays, "broken");
    assert!(c > 0 && a > 0, "a broken field went unnoticed ({c}, {a})");
}

/// Remove, insert and move objects without a rebuild: the answers follow the changed scene.
#[test]
fn dynamic_updates_match_brute_force() {
    let mut t = soup(400, 11);
    for split in [Split::Uniform, Split::Median] {
        let settings = VlfSettings {
            level: 8,
            tiles: 64,
            split,
            ..VlfSettings::default()
        };
        let mut field = VisibilityField::build(&t, settings).unwrap();
        let mut current = t.clone();
        // Remove object 1: in the reference its triangles shrink to a point (never hit).
        common::updates::remove(&mut field, &mut current, 1);
        let dirs = field.frame.directions.clone();
        for (kind, rays) in all_rays(&current, &dirs, 800, 1) {
            check(&field, &current, &rays, &format!("after remove: {kind}"));
        }
        // Move object 2 (inside the ball), insert object 9.
        common::updates::move_and_insert(&mut field, &mut current);
        for (kind, rays) in all_rays(&current, &dirs, 800, 2) {
            check(&field, &current, &rays, &format!("after move and insert: {kind}"));
        }
        // Outside the ball: refused, nothing changed.
        assert!(field.move_object(3, |p| p + v(100.0, 0.0, 0.0)).is_err());
        t = soup(400, 11);
    }
}
