//! The f32 ray obvhs' CWBVH traversal is given, and the one thing about it obvhs 0.4.0 gets wrong.
//!
//! # A -0.0 direction component misses every child box
//! `CwBvhNode::intersect_ray` (both its SSE and its scalar form) picks each child's near and far
//! planes on an axis by `ray.direction.x < 0.0`, which is false for -0.0, but scales them by
//! `ray.inv_direction`, which `Ray::new` makes with `safe_inverse`: `x.signum() / f32::EPSILON`
//! for |x| <= EPSILON, negative for -0.0 (`signum(-0.0) = -1`). On that axis the near plane is then
//! mapped to the larger distance and the far one to the smaller: a ray whose origin lies between
//! them gets an entry distance above its exit and misses the child. Rays along the visibility
//! field's grid directions are such rays: the octahedral grid puts a quarter of its directions in
//! coordinate planes, and orienting one into a normal's hemisphere by negation turns its 0.0 into
//! -0.0. [`direction`] hands obvhs +0.0 instead, the same direction, on which both tests agree.

use glam::{DVec3, Vec3A};
use obvhs::ray::Ray;

/// `d` in f32 with every zero component +0.0: the direction obvhs' CWBVH node test reads
/// consistently (see the module doc). A component f32 rounds to zero counts as zero.
pub fn direction(d: DVec3) -> Vec3A {
    let d = Vec3A::from(d.as_vec3());
    Vec3A::select(d.cmpeq(Vec3A::ZERO), Vec3A::ZERO, d)
}

/// obvhs' CWBVH node test floors every entry distance at 1e-4 (`cwbvh::node::EPSILON`, a constant
/// in world units): a ray must start at least this far before the first box it may hit.
const OBVHS_TMIN: f64 = 1e-4;

/// The f32 ray that walks the tree for the f64 segment `origin + t dir`, `0 < t < tmax`, over a
/// root box `(lo, hi)` in world coordinates whose tree lies in coordinates relative to `centre`,
/// and its parameter shift `s` (walk distance = t - s); `None` where the segment misses the box.
///
/// An origin well outside the box moves to a margin before the box's entry point, so that its
/// f32 rounding is by ulps of the scene's size (which the tree's widened boxes cover) and not of
/// its distance. Any other origin moves back a little along the ray: obvhs floors entry distances
/// at 1e-4, and every point of the true segment must lie beyond twice that along the walk (and
/// beyond the f32 rounding of a point of the scene). Hits before t = 0 that the walk then meets
/// are refused by the caller's f64 test.
pub fn shifted(lo: DVec3, hi: DVec3, centre: DVec3, origin: DVec3, dir: DVec3, tmax: f64) -> Option<(Ray, f64)> {
    let (a, b) = ((lo - origin) / dir, (hi - origin) / dir);
    let enter = a.min(b).max_element();
    let exit = a.max(b).min_element();
    let size = (hi - lo).max_element();
    let lead = 2.0 * OBVHS_TMIN + size * 1e-6;
    let margin = size * 1e-3 + lead;
    // An origin on a slab plane of a ray parallel to it gives NaN: walk from behind the origin.
    let defined = !(enter.is_nan() || exit.is_nan());
    if defined && (exit < 0.0 || enter > exit + margin || enter > tmax + margin) {
        return None;
    }
    let s = if defined && enter.is_finite() && enter > margin {
        enter - margin
    } else {
        -lead
    };
    let far = ((tmax - s) * (1.0 + 1e-6) + margin) as f32;
    let ray = Ray::new(
        Vec3A::from((origin + dir * s - centre).as_vec3()),
        direction(dir),
        0.0,
        far,
    );
    Some((ray, s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_components_become_positive_and_others_stay() {
        let d = direction(DVec3::new(-0.0, 0.6, -0.8));
        assert_eq!(d.x.to_bits(), 0.0f32.to_bits());
        assert_eq!((d.y, d.z), (0.6, -0.8));
        // Too small for f32: a zero, made positive.
        let d = direction(DVec3::new(-1e-60, 1.0, 0.0));
        assert_eq!(d.x.to_bits(), 0.0f32.to_bits());
    }

    #[test]
    fn the_walk_starts_before_the_box_or_just_behind_the_origin() {
        let (lo, hi) = (DVec3::splat(-1.0), DVec3::splat(1.0));
        // From outside: starts just before the entry at t = 4.
        let (ray, s) = shifted(lo, hi, DVec3::ZERO, DVec3::new(0.0, 0.0, -5.0), DVec3::Z, 100.0).unwrap();
        assert!(s < 4.0 && s > 3.99, "{s}");
        assert!((ray.origin.z as f64 - (-5.0 + s)).abs() < 1e-6);
        // From inside, or just outside: starts behind the origin by more than twice obvhs'
        // floor, not further.
        for z in [0.0, -1.0005] {
            let (_, s) = shifted(lo, hi, DVec3::ZERO, DVec3::new(0.0, 0.0, z), DVec3::Z, 100.0).unwrap();
            assert!(s < -2.0 * OBVHS_TMIN && s > -3.0 * OBVHS_TMIN, "{s}");
        }
        // Pointing away, or ending before the box: no walk.
        assert!(shifted(lo, hi, DVec3::ZERO, DVec3::new(0.0, 0.0, -5.0), -DVec3::Z, 100.0).is_none());
        assert!(shifted(lo, hi, DVec3::ZERO, DVec3::new(0.0, 0.0, -5.0), DVec3::Z, 3.0).is_none());
    }
}
