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
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
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

/// Leaf of depth `z` in a median split (planes stored as f32 bits, in order): the number of
/// planes at or below `z`.
#[inline]
pub fn median_leaf(z: f64, planes: &[u32]) -> usize {
    planes.partition_point(|&p| f32::from_bits(p) as f64 <= z)
}

/// Smallest depth that a uniform split maps to leaf `l` or beyond, approximately (callers widen).
#[inline]
pub fn uniform_plane(l: usize, z0: f32, scale: f32) -> f64 {
    z0 as f64 + l as f64 / scale as f64
}

/// Bits of a leaf entry holding the triangle index: a split tile's entries also carry the
/// first leaf `f` and `L - 1 - last leaf` of the triangle's range, `depth` bits each above
/// them, so that a walk visiting several leaves tests each triangle once (in its first visited
/// leaf) without a mailbox. Depth 4 leaves 24 bits (16.7M triangles).
pub fn id_bits(depth: u32) -> u32 {
    32 - 2 * depth
}

/// Mask of the triangle index in an entry.
pub fn id_mask(depth: u32) -> u32 {
    if depth == 0 {
        u32::MAX
    } else {
        (1u32 << id_bits(depth)) - 1
    }
}

/// A split tile's entry for triangle `id` spanning leaves `first..=last` of `2^depth`.
pub fn entry(id: u32, first: usize, last: usize, depth: u32) -> u32 {
    let leaves = 1usize << depth;
    id | (first as u32) << id_bits(depth) | ((leaves - 1 - last) as u32) << (id_bits(depth) + depth)
}

/// u32 words of a split tile's header: its split values (f32 bits, [`Split::stride`]) then
/// each leaf's end, counted from the first id after the header.
pub fn header_len(kind: Split, leaves: usize) -> usize {
    kind.stride(leaves) + leaves
}

/// Builds the split of one tile into `block` (appended): the header ([`header_len`]), then
/// each leaf's triangles in leaf order; `boxes` gets each entry's footprint box (0 for header
/// words). `items` holds (triangle, z_lo, z_hi, box) with widened clipped depth ranges. Returns false, writing nothing, when the depth range is empty (every
/// triangle at one depth: no split helps).
pub fn build(
    items: &[(u32, f64, f64, u16)],
    kind: Split,
    depth: u32,
    block: &mut Vec<u32>,
    boxes: &mut Vec<u16>,
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
    let head = block.len();
    let mut planes = [0f32; 1024];
    let stride = kind.stride(leaves);
    match kind {
        Split::Uniform => {
            let scale = (leaves as f64 / (z1 as f64 - z0 as f64)) as f32;
            if !scale.is_finite() || scale <= 0.0 {
                return false;
            }
            planes[0] = z0;
            planes[1] = scale;
        }
        Split::Median => {
            scratch.clear();
            scratch.extend(items.iter().map(|it| 0.5 * (it.1 + it.2)));
            scratch.sort_unstable_by(f64::total_cmp);
            for k in 1..leaves {
                planes[k - 1] = scratch[(k * scratch.len() / leaves).min(scratch.len() - 1)] as f32;
            }
        }
    }
    let bits: Vec<u32> = planes[..stride].iter().map(|p| p.to_bits()).collect();
    let leaf = |z: f64| match kind {
        Split::Uniform => uniform_leaf(z, planes[0], planes[1], leaves),
        Split::Median => median_leaf(z, &bits),
    };
    block.extend_from_slice(&bits);
    block.resize(head + stride + leaves, 0);
    boxes.resize(block.len(), 0);
    let first = block.len();
    let ranges: Vec<(usize, usize)> = items.iter().map(|it| (leaf(it.1), leaf(it.2))).collect();
    for l in 0..leaves {
        for (it, r) in items.iter().zip(&ranges) {
            if r.0 <= l && l <= r.1 {
                block.push(entry(it.0, r.0, r.1, depth));
                boxes.push(it.3);
            }
        }
        block[head + stride + l] = (block.len() - first) as u32;
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
