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

/// u32 words of a split tile's header: its split values (f32 bits, [`Split::stride`]) then
/// two words per leaf packing its group bounds ([`LeafBounds`]).
pub fn header_len(kind: Split, leaves: usize) -> usize {
    kind.stride(leaves) + 2 * leaves
}

/// Most entries a split tile's block may hold: its leaf bounds are 16-bit.
pub const MAX_BLOCK_ENTRIES: usize = u16::MAX as usize;

/// Where one leaf's entries lie, counted in entries from the first entry after the header.
///
/// A triangle spanning leaves `f..=g` is listed in each of them; a walk that visits several
/// leaves must test it once. Each leaf therefore orders its entries in four groups, by where
/// the triangle's range starts and ends relative to leaf `l`: `f == l < g`, then `f == l == g`,
/// then `f < l == g`, then `f < l < g`. A walk up (near to far along `+z`) tests all of the
/// first leaf it visits and, in each later leaf, only the triangles starting there (the first
/// two groups, `start..c`); a walk down tests, after its first leaf, only the triangles ending
/// there (the middle two, `a..d`). Every triangle meeting the visited range is tested exactly
/// once, with no mailbox and no key bits in the entries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LeafBounds {
    /// First entry of the leaf (the previous leaf's end).
    pub start: usize,
    /// End of the `f == l < g` group.
    pub a: usize,
    /// End of the `f == l == g` group.
    pub c: usize,
    /// End of the `f < l == g` group.
    pub d: usize,
    /// End of the leaf.
    pub end: usize,
}

impl LeafBounds {
    /// Bounds of leaf `l` from its header words (`pairs`: the two words per leaf).
    #[inline(always)]
    pub fn read(pairs: &[u32], l: usize) -> LeafBounds {
        let (w0, w1) = (pairs[2 * l], pairs[2 * l + 1]);
        LeafBounds {
            start: if l == 0 { 0 } else { (pairs[2 * l - 1] >> 16) as usize },
            a: (w0 & 0xffff) as usize,
            c: (w0 >> 16) as usize,
            d: (w1 & 0xffff) as usize,
            end: (w1 >> 16) as usize,
        }
    }

    /// The entries a walk tests in this leaf: all of them in the first leaf it visits, else
    /// those starting here walking up or ending here walking down.
    #[inline(always)]
    pub fn tested(&self, first_visited: bool, up: bool) -> (usize, usize) {
        match (first_visited, up) {
            (true, _) => (self.start, self.end),
            (false, true) => (self.start, self.c),
            (false, false) => (self.a, self.d),
        }
    }
}

/// Builds the split of one tile into `block` (appended): the header ([`header_len`]), then each
/// leaf's entries in the group order of [`LeafBounds`], each entry written by `push(block, id,
/// box)`. `items` holds (triangle, z_lo, z_hi, box) with widened clipped depth ranges. Returns
/// false, writing nothing, when the depth range is empty (every triangle at one depth: no
/// split helps) or the entries would overflow the 16-bit leaf bounds.
pub fn build(
    items: &[(u32, f64, f64, u16)],
    kind: Split,
    depth: u32,
    block: &mut Vec<u32>,
    scratch: &mut Vec<f64>,
    push: impl Fn(&mut Vec<u32>, u32, u16),
) -> bool {
    let leaves = 1usize << depth;
    let lo = items.iter().fold(f64::INFINITY, |a, it| a.min(it.1));
    let hi = items.iter().fold(f64::NEG_INFINITY, |a, it| a.max(it.2));
    // Outward-rounded f32 bounds.
    let (z0, z1) = (down(lo), up(hi));
    if z1 <= z0 {
        return false;
    }
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
    let ranges: Vec<(usize, usize)> = items.iter().map(|it| (leaf(it.1), leaf(it.2))).collect();
    let total: usize = ranges.iter().map(|r| r.1 - r.0 + 1).sum();
    if total > MAX_BLOCK_ENTRIES {
        return false;
    }
    let head = block.len();
    block.extend_from_slice(&bits);
    block.resize(head + header_len(kind, leaves), 0);
    let mut count = 0u32;
    for l in 0..leaves {
        // (starts here, ends here) of each group, in order.
        let groups = [(true, false), (true, true), (false, true), (false, false)];
        let mut ends = [0u32; 4];
        for (group, end) in groups.iter().zip(&mut ends) {
            for (it, &(f, g)) in items.iter().zip(&ranges) {
                if f <= l && l <= g && (f == l, g == l) == *group {
                    push(block, it.0, it.3);
                    count += 1;
                }
            }
            *end = count;
        }
        block[head + stride + 2 * l] = ends[0] | ends[1] << 16;
        block[head + stride + 2 * l + 1] = ends[2] | ends[3] << 16;
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
