//! Ray queries (paper Sections 3.3, 4 and 5): nearest stored direction from the table, the
//! segment clipped to the scene's ball, both ends projected, the tiles between them walked
//! front to back with the build's conservative rule (a thick segment: every tile whose widened
//! square it touches), and in each tile the leaves between the entry and exit depth visited
//! linearly, near to far. No allocation, no recursion, no dynamic dispatch.
//!
//! Every candidate is tested with [`crate::accel::intersect`] on the original world-space
//! triangle, so answers are bit-identical to brute force; the structure only narrows the set.
//! Closest-hit ties (equal t) go to the lower triangle index, as `brute_force`'s `min_by` keeps
//! the first.

use super::bsp::{self, median_leaf, uniform_leaf, uniform_plane, Split};
use super::layer::{box_word, dead_id, entries_in, entry_id, id_word, Layer};
use super::raster::sub_range;
use super::{VisibilityField, EPS};
use crate::accel::work;
use glam::DVec3;
use std::cell::Cell;

/// A ray in one direction's tile space: `x, y` in tiles, `z` in ball units, per unit of world t.
#[derive(Clone, Copy, Debug)]
pub struct TileRay {
    /// Stored direction used.
    pub dir: u32,
    /// Origin.
    pub o: DVec3,
    /// Direction (per world unit of t).
    pub d: DVec3,
    /// 1 / d.z (infinite when the ray is perpendicular to the beam).
    pub inv_dz: f64,
    /// The segment inside the scene's ball, in world t.
    pub t0: f64,
    /// End of that segment.
    pub t1: f64,
}

/// A triangle as the exact test reads it: corner 0 and the edges to corners 1 and 2, exactly
/// as [`crate::accel::intersect`] computes them (9 f64).
pub fn pack(t: &[DVec3; 3]) -> [f64; 9] {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    [t[0].x, t[0].y, t[0].z, e1.x, e1.y, e1.z, e2.x, e2.y, e2.z]
}

/// [`crate::accel::intersect`] on a packed triangle, with the same operations in the same order
/// (so the same t, bit for bit) but no early returns: the t of a hit, NaN otherwise. A zero
/// determinant makes `u` infinite or NaN, which fails the same test `intersect` returns early on.
#[inline(always)]
pub fn exact_t(origin: DVec3, dir: DVec3, k: &[f64]) -> f64 {
    let v0 = DVec3::new(k[0], k[1], k[2]);
    let e1 = DVec3::new(k[3], k[4], k[5]);
    let e2 = DVec3::new(k[6], k[7], k[8]);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    let inv = 1.0 / det;
    let s = origin - v0;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    let miss = !(0.0..=1.0).contains(&u) | (v < 0.0) | (u + v > 1.0);
    if miss {
        f64::NAN
    } else {
        e2.dot(q) * inv
    }
}

/// One leaf's entries as a walk visits them.
#[derive(Clone, Copy, Debug)]
pub struct Leaf<'a> {
    /// The tile's entries from its first ([`super::layer`]: a word each, or three-word pairs
    /// when `wide`).
    pub words: &'a [u32],
    /// The entries to test, `a..b` counted from the first.
    pub entries: (usize, usize),
    /// Whether entries go in pairs.
    pub wide: bool,
    /// The ray's own sub-cell box over the tile, packed as the entries' boxes.
    pub ray_box: [u32; 4],
    /// The t beyond which no hit in a later leaf of this tile lies.
    pub exit: f64,
}

impl Leaf<'_> {
    /// Entries the leaf lists for this walk.
    pub fn entries(&self) -> usize {
        self.entries.1 - self.entries.0
    }

    /// Calls `f` with each triangle index whose footprint box meets the ray's (removed ones
    /// skipped); stops when it returns true (returning true).
    #[inline(always)]
    pub fn each(&self, mut f: impl FnMut(u32) -> bool) -> bool {
        // Two loops, so that each compiles without a branch on the width per entry.
        let (a, b) = self.entries;
        if self.wide {
            let w = self.words;
            let pair = |i: usize| {
                let (at, shift) = box_word(i, true);
                (w[id_word(i, true)], w[at] >> shift)
            };
            self.scan((a..b).map(pair), dead_id(true), &mut f)
        } else {
            let narrow = |&w: &u32| (entry_id(w, false), w >> 16);
            self.scan(self.words[a..b].iter().map(narrow), dead_id(false), &mut f)
        }
    }

    #[inline(always)]
    fn scan(&self, entries: impl Iterator<Item = (u32, u32)>, dead: u32, f: &mut impl FnMut(u32) -> bool) -> bool {
        let [rx0, rx1, ry0, ry1] = self.ray_box;
        for (id, b) in entries {
            let apart = (b & 15 > rx1) | ((b >> 4) & 15 < rx0) | ((b >> 8) & 15 > ry1) | ((b >> 12) & 15 < ry0);
            if apart || id == dead {
                continue;
            }
            if f(id) {
                return true;
            }
        }
        false
    }
}

/// The tile column or row of coordinate `v` (in tiles) among `n`, clamped to the grid: floor
/// for v >= 0 is truncation (`as` saturates; NaN gives 0), so no libm call.
#[inline(always)]
pub fn tile_cell(v: f64, n: usize) -> usize {
    (v.max(0.0) as usize).min(n - 1)
}

impl VisibilityField {
    /// The ray in the nearest direction's tile space, clipped to the ball and to (0, tmax);
    /// None when that leaves nothing.
    #[inline]
    pub fn tile_ray(&self, origin: DVec3, dir: DVec3, tmax: f64) -> Option<TileRay> {
        let f = &self.frame;
        let oc = origin - f.centre;
        let dd = dir.length_squared();
        let b = dir.dot(oc) / dd;
        let r = f.radius * (1.0 + 4.0 * EPS);
        // r^2 less the squared distance from the centre to the line, over |dir|^2: not
        // b^2 - (|oc|^2 - r^2) / dd, which cancels catastrophically when the origin is far.
        let disc = (r * r - (oc - dir * b).length_squared()) / dd;
        if disc.is_nan() || disc < 0.0 {
            return None;
        }
        let sq = disc.sqrt();
        let (t0, t1) = ((-b - sq).max(0.0), (-b + sq).min(tmax));
        if t0.is_nan() || t1.is_nan() || t0 > t1 {
            return None;
        }
        let k = f.directions.lookup(dir);
        let rot = f.directions.rotation(k);
        let s = f.inv_radius * f.half_tiles;
        let o = DVec3::new(
            rot[0].dot(oc) * s + f.half_tiles,
            rot[1].dot(oc) * s + f.half_tiles,
            rot[2].dot(oc) * f.inv_radius,
        );
        let d = DVec3::new(rot[0].dot(dir) * s, rot[1].dot(dir) * s, rot[2].dot(dir) * f.inv_radius);
        Some(TileRay {
            dir: k,
            o,
            d,
            inv_dz: 1.0 / d.z,
            t0,
            t1,
        })
    }

    /// Walks the tiles `ray` touches front to back, calling `visit(tile, t_in, t_out)` (tile
    /// index within the direction); stops when `visit` returns true (returning true) or when
    /// the next tiles start beyond `cutoff()`.
    #[inline]
    pub fn walk(
        &self,
        ray: &TileRay,
        cutoff: impl Fn() -> f64,
        mut visit: impl FnMut(usize, f64, f64) -> bool,
    ) -> bool {
        let n = self.settings.tiles as usize;
        let e = EPS * self.frame.half_tiles;
        let (o, d) = (ray.o, ray.d);
        let (xa, xb) = (o.x + d.x * ray.t0, o.x + d.x * ray.t1);
        let (ya, yb) = (o.y + d.y * ray.t0, o.y + d.y * ray.t1);
        let cell = |v: f64| tile_cell(v, n);
        let (x0, x1) = (cell(xa.min(xb) - e), cell(xa.max(xb) + e));
        let (y0, y1) = (cell(ya.min(yb) - e), cell(ya.max(yb) + e));
        if x0 == x1 && y0 == y1 {
            return visit(y0 * n + x0, ray.t0, ray.t1);
        }
        // Columns along the major axis, front to back; rows within a column likewise.
        let swap = d.y.abs() > d.x.abs();
        let (mo, md, so, sd) = if swap {
            (o.y, d.y, o.x, d.x)
        } else {
            (o.x, d.x, o.y, d.y)
        };
        let (c0, c1) = if swap { (y0, y1) } else { (x0, x1) };
        let slab = |lo: f64, po: f64, pd: f64, ta: f64, tb: f64| -> (f64, f64) {
            if pd == 0.0 {
                return (ta, tb);
            }
            let (a, b) = ((lo - e - po) / pd, (lo + 1.0 + e - po) / pd);
            (ta.max(a.min(b)), tb.min(a.max(b)))
        };
        let columns = c1 - c0 + 1;
        for ci in 0..columns {
            let c = if md >= 0.0 { c0 + ci } else { c1 - ci };
            let (ta, tb) = slab(c as f64, mo, md, ray.t0, ray.t1);
            if ta > tb {
                continue;
            }
            if ta > cutoff() {
                break;
            }
            let (sa, sb) = (so + sd * ta, so + sd * tb);
            let (r0, r1) = (cell(sa.min(sb) - e), cell(sa.max(sb) + e));
            for ri in 0..=(r1 - r0) {
                let r = if sd >= 0.0 { r0 + ri } else { r1 - ri };
                let (ua, ub) = slab(r as f64, so, sd, ta, tb);
                if ua > ub {
                    continue;
                }
                if ua > cutoff() {
                    break;
                }
                let tile = if swap { c * n + r } else { r * n + c };
                if visit(tile, ua, ub) {
                    return true;
                }
            }
        }
        false
    }

    /// Visits the leaves of `tile` (of `layer`, direction `ray.dir`) that the ray's depth range
    /// over `[ta, tb]` meets, near to far: `leaf(ids, exit_t)` with the t beyond which no hit
    /// in a later leaf of this tile lies; stops when it returns true (returning true).
    #[inline]
    pub fn leaves(
        &self,
        layer: &Layer,
        ray: &TileRay,
        tile: usize,
        ta: f64,
        tb: f64,
        mut leaf: impl FnMut(Leaf) -> bool,
    ) -> bool {
        let n2 = (self.settings.tiles * self.settings.tiles) as usize;
        let (start, end, split) = layer.offsets.block(ray.dir as usize * n2 + tile);
        let e = EPS * self.frame.half_tiles;
        let n = self.settings.tiles as usize;
        let (tx, ty) = ((tile % n) as f64, (tile / n) as f64);
        let (xa, xb) = (ray.o.x + ray.d.x * ta - tx, ray.o.x + ray.d.x * tb - tx);
        let (ya, yb) = (ray.o.y + ray.d.y * ta - ty, ray.o.y + ray.d.y * tb - ty);
        let (rx0, rx1) = sub_range(xa.min(xb), xa.max(xb), e);
        let (ry0, ry1) = sub_range(ya.min(yb), ya.max(yb), e);
        let ray_box = [rx0, rx1, ry0, ry1];
        let wide = layer.wide;
        if !split {
            return start < end
                && leaf(Leaf {
                    words: &layer.words[start..end],
                    entries: (0, entries_in(end - start, wide)),
                    wide,
                    ray_box,
                    exit: f64::INFINITY,
                });
        }
        let leaves = 1usize << self.settings.depth;
        let kind = self.settings.split;
        let stride = kind.stride(leaves);
        let head = &layer.words[start..start + bsp::header_len(kind, leaves)];
        let bounds = &head[stride..];
        let h = start + head.len();
        let (za, zb) = (ray.o.z + ray.d.z * ta, ray.o.z + ray.d.z * tb);
        let (zlo, zhi) = (za.min(zb) - EPS, za.max(zb) + EPS);
        let up = ray.d.z >= 0.0;
        // Depth of the boundary between leaves b - 1 and b.
        let boundary = |b: usize| -> f64 {
            match kind {
                Split::Uniform => uniform_plane(b, f32::from_bits(head[0]), f32::from_bits(head[1])),
                Split::Median => f32::from_bits(head[b - 1]) as f64,
            }
        };
        let leaf_of = |z: f64| match kind {
            Split::Uniform => uniform_leaf(z, f32::from_bits(head[0]), f32::from_bits(head[1]), leaves),
            Split::Median => median_leaf(z, &head[..stride]),
        };
        let (l0, l1) = (leaf_of(zlo), leaf_of(zhi));
        for i in 0..=(l1 - l0) {
            let l = if up { l0 + i } else { l1 - i };
            let exit = if l == (if up { l1 } else { l0 }) {
                f64::INFINITY
            } else if up {
                (boundary(l + 1) - EPS - ray.o.z) * ray.inv_dz
            } else {
                (boundary(l) + EPS - ray.o.z) * ray.inv_dz
            };
            let (a, b) = bsp::LeafBounds::read(bounds, l).tested(i == 0, up);
            if leaf(Leaf {
                words: &layer.words[h..end],
                entries: (a, b),
                wide,
                ray_box,
                exit,
            }) {
                return true;
            }
        }
        false
    }

    /// Any-hit over one layer; counts tiles and tile-BSP leaves as traversal steps.
    #[inline]
    pub(super) fn any_in(&self, layer: &Layer, ray: &TileRay, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        let tri = &self.tri;
        let (nodes, prims) = (Cell::new(0u64), Cell::new(0u64));
        let hit = self.walk(
            ray,
            || f64::INFINITY,
            |tile, ta, tb| {
                nodes.set(nodes.get() + 1);
                self.leaves(layer, ray, tile, ta, tb, |leaf| {
                    nodes.set(nodes.get() + 1);
                    leaf.each(|id| {
                        if id == skip {
                            return false;
                        }
                        prims.set(prims.get() + 1);
                        let t = exact_t(origin, dir, &tri[9 * id as usize..9 * id as usize + 9]);
                        t > 0.0 && t < tmax
                    })
                })
            },
        );
        work::add(nodes.get(), prims.get());
        hit
    }

    /// Closest hit over one layer, improving on `best` (t, triangle).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn closest_in(
        &self,
        layer: &Layer,
        ray: &TileRay,
        origin: DVec3,
        dir: DVec3,
        tmax: f64,
        skip: u32,
        best: &mut (f64, u32),
    ) {
        let tri = &self.tri;
        let cell = Cell::new(*best);
        let (nodes, prims) = (Cell::new(0u64), Cell::new(0u64));
        self.walk(
            ray,
            || cell.get().0,
            |tile, ta, tb| {
                nodes.set(nodes.get() + 1);
                self.leaves(layer, ray, tile, ta, tb, |leaf| {
                    nodes.set(nodes.get() + 1);
                    let mut b = cell.get();
                    leaf.each(|id| {
                        if id == skip {
                            return false;
                        }
                        prims.set(prims.get() + 1);
                        let t = exact_t(origin, dir, &tri[9 * id as usize..9 * id as usize + 9]);
                        if t > 0.0 && t < tmax && (t < b.0 || (t == b.0 && id < b.1)) {
                            b = (t, id);
                        }
                        false
                    });
                    cell.set(b);
                    b.0 < leaf.exit
                });
                false
            },
        );
        work::add(nodes.get(), prims.get());
        *best = cell.get();
    }
}
