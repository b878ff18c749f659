//! Edge cases of the visibility field against brute force: build parameters at their limits
//! (deep tile BSPs, more triangles than a 16-bit id holds), ray origins far from the scene, and the
//! memory the field reports for its GPU form.

use crate::common::rays::*;
use glam::DVec3;
use penumbra::accel::brute::Brute;
use penumbra::accel::vlf::{Split, VisibilityField, VlfSettings};
use penumbra::accel::Accelerator;

fn mismatches(field: &VisibilityField, t: &penumbra::mesh::Triangles, rays: &[Ray]) -> usize {
    let brute = Brute::build(t);
    let mut bad = 0;
    for &(o, d, tmax, skip) in rays {
        let want = brute.closest(o, d, tmax, skip);
        let got = field.closest(o, d, tmax, skip);
        let any = field.any_hit(o, d, tmax, skip);
        if got != want || any != want.is_some() {
            if bad < 3 {
                eprintln!("o={o:?} d={d:?} tmax={tmax}: got {got:?} (any {any}), want {want:?}");
            }
            bad += 1;
        }
    }
    bad
}

/// Small triangles in a slab, each split tile deep (1024 leaves): every answer is exact. (Tiles
/// whose leaves would overflow the 16-bit leaf bounds: `visibility_field_lean`.)
#[test]
fn deep_tile_bsp_with_many_triangles_is_exact() {
    let mut r = Rng(5);
    let t = tris(small_triangles(5000, &mut r));
    for split in [Split::Uniform, Split::Median] {
        let settings = VlfSettings {
            level: 1,
            tiles: 4,
            depth: 10,
            split,
            leaf_size: 1,
        };
        let field = VisibilityField::build(&t, settings).unwrap();
        assert!(field.base.split_tiles() > 0, "{split:?}: no tile was split");
        let rays = random_segments(&t, 2000, &mut r);
        let bad = mismatches(&field, &t, &rays);
        assert_eq!(
            bad,
            0,
            "{split:?}: {bad} of {} rays differ from brute force",
            rays.len()
        );
    }
}

fn small_triangles(n: usize, r: &mut Rng) -> Vec<[DVec3; 3]> {
    (0..n)
        .map(|_| {
            let c = v(r.range(-1., 1.), r.range(-1., 1.), r.range(-1., 1.));
            [c, c + r.unit() * 0.05, c + r.unit() * 0.05]
        })
        .collect()
}

/// More triangles than a 16-bit id holds, in rows of tiles too full for 15-bit offsets: the
/// layer falls back to two-word entries and one u32 offset per tile, answers exactly, and
/// removing an object marks its wide entries removed (checked against brute force over the
/// scene with that object's triangles collapsed to points, indices unchanged).
#[test]
fn wide_entries_and_flat_offsets_are_exact() {
    use penumbra::accel::vlf::layer::Offsets;
    let mut r = Rng(17);
    let mut t = tris(small_triangles(70_000, &mut r));
    for split in [Split::Uniform, Split::Median] {
        let settings = VlfSettings {
            level: 1,
            tiles: 4,
            depth: 2,
            split,
            leaf_size: 8,
        };
        let mut field = VisibilityField::build(&t, settings).unwrap();
        assert!(field.base.wide, "70K triangles need two-word entries");
        assert!(
            matches!(field.base.offsets, Offsets::Flat(_)),
            "rows this full need u32 offsets"
        );
        assert!(field.base.split_tiles() > 0);
        assert_six_bytes_per_entry(&field);
        let rays = random_segments(&t, 300, &mut r);
        assert_eq!(mismatches(&field, &t, &rays), 0, "{split:?}: intact");
        field.remove_object(1).unwrap();
        let mut gone = t.clone();
        for (p, &o) in gone.positions.iter_mut().zip(&t.object_of) {
            if o == 1 {
                *p = [p[0]; 3];
            }
        }
        assert_eq!(mismatches(&field, &gone, &rays), 0, "{split:?}: object 1 removed");
    }
    // A narrow layer for contrast: the same generator at 5000 triangles packs one word each.
    t.positions.truncate(5000);
    t.object_of.truncate(5000);
    let field = VisibilityField::build(
        &t,
        VlfSettings {
            level: 1,
            tiles: 16,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(!field.base.wide && matches!(field.base.offsets, Offsets::Rows { .. }));
}

/// A wide layer's entries take six bytes each: every split tile's entry words, counted against
/// the entries its leaf bounds list (independent of how entries are encoded), are three per
/// pair, an odd count padded (two-word entries would take four per pair).
fn assert_six_bytes_per_entry(field: &VisibilityField) {
    use penumbra::accel::vlf::bsp::{header_len, LeafBounds};
    let layer = &field.base;
    let leaves = 1usize << field.settings.depth;
    let stride = field.settings.split.stride(leaves);
    let header = header_len(field.settings.split, leaves);
    let mut checked = 0;
    for k in 0..layer.offsets.tiles() {
        let (start, end, split) = layer.offsets.block(k);
        if split {
            let entries = LeafBounds::read(&layer.words[start + stride..start + header], leaves - 1).end;
            assert_eq!(
                end - start - header,
                3 * entries.div_ceil(2),
                "tile {k}: {entries} entries"
            );
            checked += 1;
        }
    }
    assert!(checked > 0, "no split tile to check");
}

/// Geometry touching the ball (an octahedron's corners lie on it), seen from far away: the ray's
/// segment inside the ball must not lose its ends to rounding.
#[test]
fn far_origins_match_brute_force() {
    let c = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y];
    let mut positions = Vec::new();
    for i in 0..4 {
        positions.push([c[i], c[(i + 1) % 4], DVec3::Z]);
        positions.push([c[(i + 1) % 4], c[i], -DVec3::Z]);
    }
    let t = tris(positions);
    let field = VisibilityField::build(&t, VlfSettings::default()).unwrap();
    let mut r = Rng(9);
    for dist in [1e3, 1e5, 1e6, 1e7] {
        let mut rays = Vec::new();
        for _ in 0..2000 {
            let d = r.unit();
            // Aim at points near the corners (on the ball) and edges.
            let k = r.index(6);
            let corner = [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y, -DVec3::Z][k];
            let target = corner * r.range(0.999, 1.0) + r.unit() * 1e-3;
            rays.push((target - d * dist, d, f64::INFINITY, u32::MAX));
        }
        let bad = mismatches(&field, &t, &rays);
        assert_eq!(bad, 0, "origins {dist} away: {bad} of {} rays differ", rays.len());
    }
}

/// What the field reports as its GPU size is what its GPU form uploads.
#[test]
fn gpu_bytes_are_the_uploaded_buffers() {
    let mut r = Rng(3);
    let mut out = Vec::new();
    for _ in 0..500 {
        let c = v(r.range(-1., 1.), r.range(-1., 1.), r.range(-1., 1.));
        out.push([c, c + r.unit() * 0.1, c + r.unit() * 0.1]);
    }
    let t = tris(out);
    let field = VisibilityField::build(
        &t,
        VlfSettings {
            level: 4,
            tiles: 16,
            ..Default::default()
        },
    )
    .unwrap();
    let frame = penumbra::geometry::LocalFrame {
        origin: DVec3::ZERO,
        scale: 1.0,
    };
    let uploaded: usize = field.gpu(&frame).unwrap().buffers.iter().map(|(_, b)| b.len()).sum();
    let reported = field.stats().gpu_bytes as usize;
    eprintln!("reported {reported}, uploaded {uploaded}");
    assert!(
        (reported as f64 - uploaded as f64).abs() < 0.01 * uploaded as f64,
        "reported {reported} bytes, uploads {uploaded}"
    );
}
