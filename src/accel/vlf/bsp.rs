//! The tile BSP (paper Section 4): a 1-D partition of a tile's triangles along its beam into
//! `2^depth` leaves, stored as a flat array ordered along the beam so that a ray visits the
//! leaves between its entry and exit depth linearly, near to far.
//!
//! The paper names both "uniform depth partitioning" (Section 1) and "a simple median split"
//! (Section 4); both are here ([`Split`]). Each maps a depth `z` to a leaf with a monotone
//! function of `z` evaluated identically at build and query time, so a triangle whose (clipped,
//! widened) depth range contains the hit depth is always in the leaf the ray looks up there.

use serde::Deserialize;

/// How a tile's depth range is cut into leaves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Split {
    /// Equal slabs between the tile's nearest and farthest depth: a leaf index is one
    /// multiply (Section 1's "uniform depth partitioning"). Stores `z0, scale` (2 f32).
    #[default]
    Uniform,
    /// Planes at the quantiles `k / 2^depth` of the triangles' clipped depth midpoints (the
    /// recursive median split of Section 4 with each triangle classified by its midpoint):
    /// balanced leaves, a short search per lookup. Stores `2^depth - 1` planes (f32).
    Median,
}

impl Split {
    /// Name in parameters and reports.
    pub fn name(self) -> &'static str {
        match self {
            Split::Uniform => "uniform",
            Split::Median => "median",
        }
    }

    /// f32 values stored per split tile for `leaves` leaves.
    pub fn stride(self, leaves: usize) -> usize {
        match self {
            Split::Uniform => 2,
            Split::Median => leaves - 1,
        }
    }
}

/// Leaf of depth `z` in a uniform split stored as `[z0, scale]`.
#[inline]
pub fn uniform_leaf(z: f64, z0: f32, scale: f32, leaves: usize) -> usize {
    // `as usize` saturates negatives (and NaN) to 0.
    (((z - z0 as f64) * scale as f64) as usize).min(leaves - 1)
}

/// Leaf of depth `z` in a median split: the number of planes at or below `z`.
#[inline]
pub fn median_leaf(z: f64, planes: &[f32]) -> usize {
    planes.partition_point(|&p| p as f64 <= z)
}

/// Smallest depth that a uniform split maps to leaf `l` or beyond, approximately (callers widen).
#[inline]
pub fn uniform_plane(l: usize, z0: f32, scale: f32) -> f64 {
    z0 as f64 + l as f64 / scale as f64
}

/// Builds the split of one tile. `items` holds (triangle, z_lo, z_hi) with widened clipped
/// depth ranges. Appends the split values to `split`, then for each leaf its triangles to
/// `ids`, pushing each leaf's end (absolute in `ids`) to `leaf_end`. Returns false, writing
/// nothing, when the depth range is empty (every triangle at one depth): no split helps.
pub fn build(
    items: &[(u32, f64, f64)],
    kind: Split,
    depth: u32,
    split: &mut Vec<f32>,
    ids: &mut Vec<u32>,
    leaf_end: &mut Vec<u32>,
    scratch: &mut Vec<f64>,
) -> bool {
    let leaves = 1usize << depth;
    let lo = items.iter().fold(f64::INFINITY, |a, it| a.min(it.1));
    let hi = items.iter().fold(f64::NEG_INFINITY, |a, it| a.max(it.2));
    // Outward-rounded f32 bounds.
    let (z0, z1) = (down(lo), up(hi));
    if z1 <= z0 {
        return false;
    }
    let leaf_range: Box<dyn Fn(f64, f64) -> (usize, usize)> = match kind {
        Split::Uniform => {
            let scale = (leaves as f64 / (z1 as f64 - z0 as f64)) as f32;
            if !scale.is_finite() || scale <= 0.0 {
                return false;
            }
            split.extend([z0, scale]);
            Box::new(move |a, b| (uniform_leaf(a, z0, scale, leaves), uniform_leaf(b, z0, scale, leaves)))
        }
        Split::Median => {
            scratch.clear();
            scratch.extend(items.iter().map(|it| 0.5 * (it.1 + it.2)));
            scratch.sort_unstable_by(f64::total_cmp);
            let at = split.len();
            for k in 1..leaves {
                split.push(scratch[(k * scratch.len() / leaves).min(scratch.len() - 1)] as f32);
            }
            let planes = split[at..].to_vec();
            Box::new(move |a, b| (median_leaf(a, &planes), median_leaf(b, &planes)))
        }
    };
    let ranges: Vec<(usize, usize)> = items.iter().map(|it| leaf_range(it.1, it.2)).collect();
    for l in 0..leaves {
        for (it, r) in items.iter().zip(&ranges) {
            if r.0 <= l && l <= r.1 {
                ids.push(it.0);
            }
        }
        leaf_end.push(ids.len() as u32);
    }
    true
}

/// An f32 at or below `x` (one step below when rounding went up; `f32::next_down` needs a
/// newer Rust than the project's minimum).
fn down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        f - f.abs() * f32::EPSILON - f32::MIN_POSITIVE
    } else {
        f
    }
}

/// An f32 at or above `x`.
fn up(x: f64) -> f32 {
    -down(-x)
}
