//! The visibility field's WGSL walk at the end of a segment: a triangle exactly at t = tmax is
//! not hit (0 < t < tmax), as brute force's WGSL and the CPU answer.

#![cfg(feature = "test-hooks")]

mod common;

use glam::DVec3;
use penumbra::mesh::Triangles;

#[test]
fn a_hit_at_tmax_is_not_a_hit_on_the_gpu() {
    let Some(mut gpu) = common::gpu() else { return };
    let positions = vec![
        [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ],
        [
            DVec3::new(-1.0, -1.0, 0.5),
            DVec3::new(1.0, -1.0, 0.5),
            DVec3::new(0.0, 1.0, 0.5),
        ],
    ];
    let t = Triangles {
        object_of: vec![0; positions.len()],
        positions,
    };
    let mut probes = Vec::new();
    for i in 0..64 {
        let x = (i % 8) as f64 / 32.0 - 0.1;
        let y = (i / 8) as f64 / 32.0 - 0.1;
        // Ends exactly on the lower triangle; passes the upper one only for i odd.
        let z = if i % 2 == 0 { 0.25 } else { 1.0 };
        probes.push((DVec3::new(x, y, z), DVec3::NEG_Z, z));
    }
    let brute = gpu.probe(&common::triangles_scene(&t, "brute"), &probes).unwrap();
    let vlf = gpu.probe(&common::triangles_scene(&t, "vlf"), &probes).unwrap();
    let mut bad = 0;
    for (i, (b, v)) in brute.iter().zip(&vlf).enumerate() {
        if b.any != v.any || b.closest != v.closest {
            if bad < 3 {
                eprintln!("ray {i} {:?}: brute {b:?}, vlf {v:?}", probes[i]);
            }
            bad += 1;
        }
    }
    assert_eq!(bad, 0, "{bad} of {} rays differ", probes.len());
}

/// Geometry touching the ball (an octahedron's corners lie on it), seen from a few hundred
/// radii away: f32 rounding of the ray's segment inside the ball must not drop its ends.
#[test]
fn far_origins_on_the_gpu_match_brute_force() {
    let Some(mut gpu) = common::gpu() else { return };
    let c = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y];
    let mut positions = Vec::new();
    for i in 0..4 {
        positions.push([c[i], c[(i + 1) % 4], DVec3::Z]);
        positions.push([c[(i + 1) % 4], c[i], -DVec3::Z]);
    }
    let t = Triangles {
        object_of: vec![0; positions.len()],
        positions,
    };
    let s = penumbra::sampling::Stream::new(11, 0, None);
    let mut probes = Vec::new();
    for (j, dist) in [30.0, 300.0, 3000.0].into_iter().enumerate() {
        for i in 0..2000u32 {
            let i = i + 2000 * j as u32;
            let d = DVec3::new(s.unit(4 * i) - 0.5, s.unit(4 * i + 1) - 0.5, s.unit(4 * i + 2) - 0.5).normalize();
            let corner = [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y, -DVec3::Z][i as usize % 6];
            let target = corner * (0.99 + 0.01 * s.unit(4 * i + 3));
            probes.push((target - d * dist, d, f64::INFINITY));
        }
    }
    let brute = gpu.probe(&common::triangles_scene(&t, "brute"), &probes).unwrap();
    let vlf = gpu.probe(&common::triangles_scene(&t, "vlf"), &probes).unwrap();
    let mut bad = 0;
    for (i, (b, v)) in brute.iter().zip(&vlf).enumerate() {
        if b.any != v.any || b.closest != v.closest {
            if bad < 3 {
                eprintln!("ray {i} {:?}: brute {b:?}, vlf {v:?}", probes[i]);
            }
            bad += 1;
        }
    }
    let hits = brute.iter().filter(|h| h.any).count();
    eprintln!("{hits} of {} rays hit", probes.len());
    assert_eq!(bad, 0, "{bad} of {} rays differ", probes.len());
}
