//! Planes chosen by the surface area heuristic, as Wald & Havran 2006 ("On building fast kd-trees
//! for ray tracing, and on doing that in O(N log N)") build them, in their O(N log^2 N) form: each
//! node sorts its own events.
//!
//! A ray through a node's box `V` meets a child box `V_i` with probability `P_i = SA(V_i) / SA(V)`
//! (surface areas), so a split at `p` costs (their SAH cost, with their empty-space factor)
//!
//! ```text
//! C(p) = lambda(p) * (K_T + K_I * (P_L N_L + P_R N_R)),   lambda = 0.8 where N_L or N_R is 0
//! ```
//!
//! against `K_I * N` for a leaf. The candidate planes are the faces of each triangle clipped to
//! `V` ("perfect splits": a triangle's part outside the node does not count), rounded outward
//! onto the f32 planes a node stores, so that the sweep counts what the split will do. One sweep per
//! axis over the sorted start, end and planar events (their incremental sweep) gives
//! `N_L`, `N_R` and the triangles lying in the plane (`N_P`), which go to whichever side is
//! cheaper. A node becomes a leaf where no plane costs less than the leaf (their
//! termination), or at `max_depth`, or with at most `leaf_size` triangles.

use super::clip::clipped_bounds;
use super::{halves, KdSettings, KdTree, Layout};
use glam::DVec3;

/// Clipping pad relative to the scene's largest coordinate: far above f64's rounding of a clipped
/// corner, far below the walk's plane thickness (`walk::DELTA`, 1e-9), so that no triangle meeting
/// a node is lost to rounding.
const PAD: f64 = 1e-12;

/// Event kinds in the order a sweep meets them at one position: ends, planar, starts (their
/// order `- < | < +`).
const END: u8 = 0;
const PLANAR: u8 = 1;
const START: u8 = 2;

/// Axis-aligned box (low, high corner).
type Aabb = (DVec3, DVec3);

/// The cheapest plane found and where triangles lying in it go.
#[derive(Clone, Copy, Debug)]
struct Plane {
    cost: f64,
    axis: usize,
    position: f64,
    planar_left: bool,
}

/// Surface area of a box: the measure of the rays meeting it (up to a constant).
fn area((lo, hi): Aabb) -> f64 {
    let d = (hi - lo).max(DVec3::ZERO);
    2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
}

struct Builder<'a> {
    positions: &'a [[DVec3; 3]],
    settings: &'a KdSettings,
    pad: f64,
    layout: &'a mut Layout,
}

/// Fills `layout` with the SAH tree over `positions` (bounding boxes `boxes`) inside `bounds`.
pub(super) fn build(
    layout: &mut Layout,
    positions: &[[DVec3; 3]],
    boxes: &[Aabb],
    bounds: Aabb,
    settings: &KdSettings,
) {
    let scale = bounds.0.abs().max(bounds.1.abs()).max_element();
    let pad = PAD
        * if scale.is_finite() {
            scale.max(f64::MIN_POSITIVE)
        } else {
            0.0
        };
    let tris = boxes.iter().enumerate().map(|(i, b)| (i as u32, *b)).collect();
    Builder {
        positions,
        settings,
        pad,
        layout,
    }
    .node(0, tris, bounds, 0);
}

impl Builder<'_> {
    /// Fills node `at` (already allocated) for `tris`, each with its bounds clipped to `bounds`.
    fn node(&mut self, at: usize, tris: Vec<(u32, Aabb)>, bounds: Aabb, depth: u32) {
        if self.layout.overflowed {
            return self.layout.leaf(at, &[], depth);
        }
        let n = tris.len();
        let plane = (n > self.settings.leaf_size as usize && depth < self.settings.max_depth)
            .then(|| self.best_plane(&tris, bounds))
            .flatten();
        let leaf = |layout: &mut Layout, tris: &[(u32, Aabb)]| {
            let ids: Vec<u32> = tris.iter().map(|t| t.0).collect();
            layout.leaf(at, &ids, depth);
        };
        let Some(plane) = plane else {
            return leaf(self.layout, &tris);
        };
        let axis = plane.axis;
        let s = self.layout.stored(axis, plane.position);
        if !(s > bounds.0[axis] && s < bounds.1[axis]) {
            return leaf(self.layout, &tris);
        }
        let (lo_box, hi_box) = halves(bounds, axis, s);
        let (mut left, mut right) = (Vec::new(), Vec::new());
        for &(id, (a, b)) in &tris {
            let planar = a[axis] == s && b[axis] == s;
            let (l, r) = if planar {
                (plane.planar_left, !plane.planar_left)
            } else {
                (a[axis] < s, b[axis] > s)
            };
            let tri = &self.positions[id as usize];
            for (goes, side, list) in [(l, lo_box, &mut left), (r, hi_box, &mut right)] {
                if let Some(c) = goes.then(|| clipped_bounds(tri, side, self.pad)).flatten() {
                    list.push((id, c));
                }
            }
        }
        // The sweep's counts are the split's own (its planes are storable), but the children's
        // counts are taken after clipping: the split is kept only if it costs less than a leaf
        // with them, as every kept split does.
        let whole = area(bounds);
        let (pl, pr) = (area(lo_box) / whole, area(hi_box) / whole);
        if self.cost(pl, pr, left.len(), right.len()) >= self.leaf_cost(n) {
            return leaf(self.layout, &tris);
        }
        drop(tris);
        let first = self.layout.inner(at, axis, s);
        self.node(first, left, lo_box, depth + 1);
        self.node(first + 1, right, hi_box, depth + 1);
    }

    /// The cheapest plane strictly inside `bounds`, if it costs less than a leaf.
    fn best_plane(&self, tris: &[(u32, Aabb)], bounds: Aabb) -> Option<Plane> {
        let whole = area(bounds);
        if whole <= 0.0 || !whole.is_finite() {
            return None;
        }
        let n = tris.len();
        let cost = |pl, pr, nl, nr| self.cost(pl, pr, nl, nr);
        let mut best: Option<Plane> = None;
        let mut events: Vec<(f64, u8)> = Vec::with_capacity(2 * n);
        for axis in 0..3 {
            let (lo, hi) = (bounds.0[axis], bounds.1[axis]);
            if hi <= lo {
                continue;
            }
            // Every candidate must be a plane the node can store (f32): with each triangle's
            // extent rounded outward onto those planes, the sweep's counts at a plane are the
            // split's own (a triangle is left of a storable plane exactly when its rounded start
            // is), and a triangle lies in one only where it lies there exactly.
            events.clear();
            for (_, (a, b)) in tris {
                let (a, b) = (
                    self.layout.stored_toward(axis, a[axis], false),
                    self.layout.stored_toward(axis, b[axis], true),
                );
                if a == b {
                    events.push((a, PLANAR));
                } else {
                    events.push((a, START));
                    events.push((b, END));
                }
            }
            events.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            let (mut nl, mut nr) = (0usize, n);
            let mut i = 0;
            while i < events.len() {
                let p = events[i].0;
                let mut count = [0usize; 3];
                for kind in [END, PLANAR, START] {
                    while i < events.len() && events[i].0.total_cmp(&p).is_eq() && events[i].1 == kind {
                        count[kind as usize] += 1;
                        i += 1;
                    }
                }
                let [ends, planar, starts] = count;
                nr -= planar + ends;
                if p > lo && p < hi {
                    let (l, r) = halves(bounds, axis, p);
                    let (pl, pr) = (area(l) / whole, area(r) / whole);
                    for (planar_left, c) in [
                        (true, cost(pl, pr, nl + planar, nr)),
                        (false, cost(pl, pr, nl, nr + planar)),
                    ] {
                        if best.is_none_or(|b| c < b.cost) {
                            best = Some(Plane {
                                cost: c,
                                axis,
                                position: p,
                                planar_left,
                            });
                        }
                    }
                }
                nl += starts + planar;
            }
        }
        best.filter(|b| b.cost < self.leaf_cost(n))
    }

    /// A split's cost with hit probabilities `pl`, `pr` and `nl`, `nr` triangles on each side
    /// (the SAH cost with the empty-space factor).
    fn cost(&self, pl: f64, pr: f64, nl: usize, nr: usize) -> f64 {
        let k = self.settings.costs();
        let lambda = if nl == 0 || nr == 0 { k.empty_factor } else { 1.0 };
        lambda * (k.traversal + k.intersection * (pl * nl as f64 + pr * nr as f64))
    }

    /// A leaf's cost: every triangle tested.
    fn leaf_cost(&self, n: usize) -> f64 {
        self.settings.costs().intersection * n as f64
    }
}

impl KdTree {
    /// The tree's expected cost for a ray through its root box under the SAH's model (Wald &
    /// Havran 2006, unrolled over the tree): `traversal_cost` per inner node and
    /// `intersection_cost` per triangle of each leaf, weighted by the node's surface area over the
    /// root's. A leaf holding everything costs `intersection_cost * N`. With `empty_factor` 1 a
    /// tree the SAH built with these constants costs no more, at its root or any node (each split
    /// it keeps costs less than the leaf it replaces, and its children no more than theirs); the
    /// empty-space bonus lets a split cost up to 1 / lambda times its leaf, for the empty space
    /// it cuts off.
    pub fn sah_cost(&self, traversal_cost: f64, intersection_cost: f64) -> f64 {
        let root = area(self.bounds);
        let weight = |b: Aabb| if root > 0.0 { area(b) / root } else { 1.0 };
        let mut total = 0.0;
        let mut stack = vec![(0usize, self.bounds)];
        while let Some((node, b)) = stack.pop() {
            match self.split(node) {
                Some((axis, s, left)) => {
                    total += traversal_cost * weight(b);
                    let (l, r) = halves(b, axis, s);
                    stack.push((left, l));
                    stack.push((left + 1, r));
                }
                None => total += intersection_cost * self.nodes[node].items().1 as f64 * weight(b),
            }
        }
        total
    }
}
