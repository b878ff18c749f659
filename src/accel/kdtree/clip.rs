//! A triangle clipped to a box, for the SAH's "perfect splits" (Wald & Havran 2006): the
//! bounds of the part of a triangle inside a node, whose faces are the planes worth
//! trying. Sutherland-Hodgman against the six faces, in f64.

use glam::DVec3;

/// Room for the corners of a triangle clipped by six planes (3 + 6 for a convex polygon; more
/// only where rounding bends it, when the unclipped bounds are returned instead).
const MAX_CORNERS: usize = 16;

/// The bounds of the part of `tri` inside `bounds` grown by `pad` on every side, or `None` where
/// nothing is left. Growing the box keeps the answer conservative: a triangle that meets the box,
/// however thinly, gets bounds (rounding moves a clipped corner by ulps, far less than `pad`). A
/// coordinate all corners share (a triangle lying in an axis plane) comes out exactly, since an
/// interpolation between equal values returns that value.
pub fn clipped_bounds(tri: &[DVec3; 3], bounds: (DVec3, DVec3), pad: f64) -> Option<(DVec3, DVec3)> {
    let mut poly = [DVec3::ZERO; MAX_CORNERS];
    poly[..3].copy_from_slice(tri);
    let mut n = 3;
    let mut next = [DVec3::ZERO; MAX_CORNERS];
    for axis in 0..3 {
        for (plane, keep_below) in [(bounds.0[axis] - pad, false), (bounds.1[axis] + pad, true)] {
            let inside = |p: DVec3| if keep_below { p[axis] <= plane } else { p[axis] >= plane };
            let mut m = 0;
            for i in 0..n {
                if m + 2 > MAX_CORNERS {
                    return Some(unclipped(tri, bounds, pad));
                }
                let (a, b) = (poly[i], poly[(i + 1) % n]);
                if inside(a) {
                    next[m] = a;
                    m += 1;
                }
                if inside(a) != inside(b) {
                    let t = (plane - a[axis]) / (b[axis] - a[axis]);
                    let mut p = a + (b - a) * t;
                    // On the plane exactly, whatever the rounding of the other coordinates.
                    p[axis] = plane;
                    next[m] = p;
                    m += 1;
                }
            }
            n = m;
            if n == 0 {
                return None;
            }
            poly[..n].copy_from_slice(&next[..n]);
        }
    }
    let lo = poly[..n].iter().fold(DVec3::INFINITY, |a, p| a.min(*p));
    let hi = poly[..n].iter().fold(DVec3::NEG_INFINITY, |a, p| a.max(*p));
    Some((lo, hi))
}

/// The triangle's bounding box within the grown box: a box holding the clipped part whatever it is.
fn unclipped(tri: &[DVec3; 3], bounds: (DVec3, DVec3), pad: f64) -> (DVec3, DVec3) {
    let (lo, hi) = super::bounds_of(tri);
    (
        lo.max(bounds.0 - DVec3::splat(pad)),
        hi.min(bounds.1 + DVec3::splat(pad)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn a_triangle_inside_keeps_its_bounds() {
        let t = [v(0.1, 0.2, 0.3), v(0.9, 0.2, 0.3), v(0.5, 0.8, 0.6)];
        let b = clipped_bounds(&t, (DVec3::ZERO, DVec3::ONE), 0.0).unwrap();
        assert_eq!(b, (v(0.1, 0.2, 0.3), v(0.9, 0.8, 0.6)));
    }

    #[test]
    fn a_cut_triangle_gets_the_bounds_of_its_inside_part() {
        // The right triangle x + y <= 2 at z = 0.5, cut by the unit box: the part inside is the
        // whole unit square's lower-left triangle x + y <= 2 within [0, 1]^2, i.e. the square.
        let t = [v(0.0, 0.0, 0.5), v(2.0, 0.0, 0.5), v(0.0, 2.0, 0.5)];
        let b = clipped_bounds(&t, (DVec3::ZERO, DVec3::ONE), 0.0).unwrap();
        assert_eq!(b, (v(0.0, 0.0, 0.5), v(1.0, 1.0, 0.5)));
        // x + y <= 1.2 cut by x <= 0.5 leaves y up to 1.2 at x = 0 and x from 0 to 0.5.
        let t = [v(0.0, 0.0, 0.5), v(1.2, 0.0, 0.5), v(0.0, 1.2, 0.5)];
        let b = clipped_bounds(&t, (DVec3::ZERO, v(0.5, 2.0, 1.0)), 0.0).unwrap();
        assert_eq!((b.0, b.1.x, b.1.z), (v(0.0, 0.0, 0.5), 0.5, 0.5));
        assert!((b.1.y - 1.2).abs() < 1e-15);
    }

    #[test]
    fn a_triangle_outside_is_none_and_one_touching_a_face_is_kept() {
        let t = [v(2.0, 0.0, 0.0), v(3.0, 0.0, 0.0), v(2.0, 1.0, 0.0)];
        assert_eq!(clipped_bounds(&t, (DVec3::ZERO, DVec3::ONE), 0.0), None);
        // Touching the face x = 1 along an edge: a flat sliver at x = 1.
        let t = [v(1.0, 0.0, 0.0), v(3.0, 0.0, 0.0), v(1.0, 1.0, 0.0)];
        let b = clipped_bounds(&t, (DVec3::ZERO, DVec3::ONE), 0.0).unwrap();
        assert_eq!(b, (v(1.0, 0.0, 0.0), v(1.0, 1.0, 0.0)));
        // Just outside, within the pad: kept.
        let t = [v(1.0 + 1e-13, 0.0, 0.0), v(3.0, 0.0, 0.0), v(1.0, 1.0, 0.0)];
        assert!(clipped_bounds(&t, (DVec3::ZERO, DVec3::ONE), 1e-12).is_some());
    }

    #[test]
    fn a_triangle_in_an_axis_plane_keeps_that_coordinate_exactly() {
        let z = 0.3f64;
        let t = [v(-1.0, -1.0, z), v(2.0, -0.5, z), v(0.3, 2.5, z)];
        let b = clipped_bounds(&t, (DVec3::ZERO, DVec3::ONE), 1e-12).unwrap();
        assert_eq!((b.0.z, b.1.z), (z, z));
    }
}
