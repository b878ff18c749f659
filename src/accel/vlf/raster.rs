//! Conservative rasterisation of a triangle's projection onto a parallel subfield's tiles
//! (paper Section 3.2: every tile the projection touches, the 8-connected rule, not a DDA line),
//! and the depth range of a triangle clipped to one tile's beam (Section 4: polygons are
//! clipped to the tile before their depth is compared with the split planes).
//!
//! Coordinates are tile units: tile `(tx, ty)` spans `[tx, tx + 1] x [ty, ty + 1]`. Every
//! square is widened by `e` (tile units) so that rounding never drops a touching tile: a
//! triangle on a tile boundary, or one smaller than a tile, is listed in every tile whose
//! closed, widened square its projection meets (a separating-axis test with the square's axes
//! and the triangle's edge normals).

use glam::{DVec2, DVec3};

/// Calls `f(tx, ty)` for every tile of an `n x n` grid whose square widened by `e` meets the
/// projected triangle `p` (which may be degenerate: a segment or a point).
pub fn for_each_tile(p: [DVec2; 3], n: u32, e: f64, mut f: impl FnMut(u32, u32)) {
    let lo = p[0].min(p[1]).min(p[2]) - e;
    let hi = p[0].max(p[1]).max(p[2]) + e;
    let last = n as f64 - 1.0;
    if hi.x < 0.0 || hi.y < 0.0 || lo.x > n as f64 || lo.y > n as f64 {
        return;
    }
    let (x0, x1) = (
        lo.x.floor().clamp(0.0, last) as u32,
        hi.x.floor().clamp(0.0, last) as u32,
    );
    let (y0, y1) = (
        lo.y.floor().clamp(0.0, last) as u32,
        hi.y.floor().clamp(0.0, last) as u32,
    );
    if x0 == x1 && y0 == y1 {
        f(x0, y0);
        return;
    }
    // Edge normals and the triangle's extent along each.
    let mut axes = [(DVec2::ZERO, 0.0, 0.0); 3];
    for (k, axis) in axes.iter_mut().enumerate() {
        let d = p[(k + 1) % 3] - p[k];
        let nrm = DVec2::new(-d.y, d.x);
        let s = [nrm.dot(p[0]), nrm.dot(p[1]), nrm.dot(p[2])];
        let slack = 1e-12 * s.iter().fold(0f64, |a, b| a.max(b.abs()));
        *axis = (nrm, s[0].min(s[1]).min(s[2]) - slack, s[0].max(s[1]).max(s[2]) + slack);
    }
    let half = 0.5 + e;
    for ty in y0..=y1 {
        for tx in x0..=x1 {
            let c = DVec2::new(tx as f64 + 0.5, ty as f64 + 0.5);
            let touches = axes.iter().all(|&(nrm, a, b)| {
                let m = nrm.dot(c);
                let r = (nrm.x.abs() + nrm.y.abs()) * half;
                m + r >= a && m - r <= b
            });
            if touches {
                f(tx, ty);
            }
        }
    }
}

/// Depth (`z`) range of triangle `p` (tile units in x, y) clipped to tile `(tx, ty)`'s square
/// widened by `e`: Sutherland-Hodgman against the four sides. Falls back to the whole
/// triangle's range if rounding leaves nothing (the rasteriser said the two meet).
pub fn clipped_z_range(p: &[DVec3; 3], tx: u32, ty: u32, e: f64) -> (f64, f64) {
    let (x0, x1) = (tx as f64 - e, tx as f64 + 1.0 + e);
    let (y0, y1) = (ty as f64 - e, ty as f64 + 1.0 + e);
    if p.iter().all(|q| q.x >= x0 && q.x <= x1 && q.y >= y0 && q.y <= y1) {
        // Inside the tile: nothing to clip (the common case for small triangles).
        return (p[0].z.min(p[1].z).min(p[2].z), p[0].z.max(p[1].z).max(p[2].z));
    }
    let mut poly: [DVec3; 9] = [DVec3::ZERO; 9];
    let mut len = 3;
    poly[..3].copy_from_slice(p);
    // Each side as (axis, bound, keep-if-greater).
    for (axis, bound, greater) in [(0, x0, true), (0, x1, false), (1, y0, true), (1, y1, false)] {
        let mut out: [DVec3; 9] = [DVec3::ZERO; 9];
        let mut n = 0;
        let inside = |q: DVec3| if greater { q[axis] >= bound } else { q[axis] <= bound };
        for k in 0..len {
            let (a, b) = (poly[k], poly[(k + 1) % len]);
            let (ia, ib) = (inside(a), inside(b));
            if ia {
                out[n] = a;
                n += 1;
            }
            if ia != ib {
                let s = ((bound - a[axis]) / (b[axis] - a[axis])).clamp(0.0, 1.0);
                out[n] = a + (b - a) * s;
                n += 1;
            }
        }
        poly = out;
        len = n;
        if len == 0 {
            break;
        }
    }
    let src: &[DVec3] = if len == 0 { p } else { &poly[..len] };
    src.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
        (lo.min(q.z), hi.max(q.z))
    })
}

/// Sub-cells per tile side in an entry's footprint box ([`sub_box`]).
pub const SUB: f64 = 16.0;

/// The part of a tile a triangle's projection can occupy, as a box of 16 x 16 sub-cells packed
/// `x0 | x1 << 4 | y0 << 8 | y1 << 12` (inclusive, rounded outwards by `e`): a query whose own
/// sub-cell range misses it skips the triangle without the exact test (the tiles' lateral
/// resolution, refined 16 times per entry at two bytes).
pub fn sub_box(p: &[DVec3; 3], tx: u32, ty: u32, e: f64) -> u16 {
    let lo = p[0].min(p[1]).min(p[2]);
    let hi = p[0].max(p[1]).max(p[2]);
    let (x0, x1) = sub_range(lo.x - tx as f64, hi.x - tx as f64, e);
    let (y0, y1) = sub_range(lo.y - ty as f64, hi.y - ty as f64, e);
    (x0 | x1 << 4 | y0 << 8 | y1 << 12) as u16
}

/// Sub-cells `[a, b]` (tile-relative, any order-preserving pair) covers, widened by `e`, clamped.
#[inline]
pub fn sub_range(a: f64, b: f64, e: f64) -> (u32, u32) {
    // floor for v >= 0 is truncation (`as` saturates; NaN gives 0): no libm call.
    let c = |v: f64| ((v * SUB).max(0.0) as u32).min(SUB as u32 - 1);
    (c(a - e), c(b + e))
}
