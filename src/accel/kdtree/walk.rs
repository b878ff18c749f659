//! The CRT walk (Wald et al. 2001, after Havran's TA_B): descend to the near child, push the far
//! one with its entry and exit distances, test a leaf's triangles, pop. Planes are treated as
//! slabs `delta` thick, so a point rounding could put on either side is on both; `kdtree.wgsl`
//! walks the same way in f32 with its own `delta`.

use super::KdTree;
use crate::accel::{intersect, work, TriHit};
use crate::mesh::Triangles;
use glam::DVec3;

/// Entries of the traversal stack (a push per level at most).
pub const STACK: usize = 64;

/// Half-thickness of planes and box faces, relative to the largest coordinate in play: f64's
/// rounding of a plane distance is a few 1e-16 of it.
pub const DELTA: f64 = 1e-9;

/// The segment `[t0, t1]` of `origin + t dir`, `0 <= t <= tmax`, inside `bounds` grown by
/// `delta`, if any.
pub fn clip(bounds: (DVec3, DVec3), origin: DVec3, dir: DVec3, tmax: f64, delta: f64) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, tmax);
    for a in 0..3 {
        let (lo, hi) = (bounds.0[a] - delta, bounds.1[a] + delta);
        if dir[a] == 0.0 {
            if origin[a] < lo || origin[a] > hi {
                return None;
            }
            continue;
        }
        let (ta, tb) = ((lo - origin[a]) / dir[a], (hi - origin[a]) / dir[a]);
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Which children of a node splitting `axis` at `split` the part `[tn, tf]` of the ray meets,
/// near first, each with its part: a plane `delta` thick is entered from both sides.
#[allow(clippy::too_many_arguments)]
pub fn children(
    axis: usize,
    split: f64,
    left: usize,
    origin: DVec3,
    dir: DVec3,
    (tn, tf): (f64, f64),
    delta: f64,
) -> [Option<(usize, f64, f64)>; 2] {
    let (o, d) = (origin[axis], dir[axis]);
    if d == 0.0 {
        let l = (o <= split + delta).then_some((left, tn, tf));
        let r = (o >= split - delta).then_some((left + 1, tn, tf));
        return [l, r];
    }
    let (ta, tb) = ((split - delta - o) / d, (split + delta - o) / d);
    let (lo, hi) = (ta.min(tb), ta.max(tb));
    let (near, far) = if d > 0.0 { (left, left + 1) } else { (left + 1, left) };
    [
        (tn <= hi).then_some((near, tn, tf.min(hi))),
        (lo <= tf).then_some((far, tn.max(lo), tf)),
    ]
}

/// The plane half-thickness for rays from `origin`: [`DELTA`] of the largest coordinate in play.
pub fn delta(tree: &KdTree, origin: DVec3) -> f64 {
    let scale = tree
        .bounds
        .0
        .abs()
        .max(tree.bounds.1.abs())
        .max(origin.abs())
        .max_element();
    DELTA * scale.max(f64::MIN_POSITIVE)
}

/// Closest hit (or, with `any`, the first found) of triangles other than `skip` with
/// `0 < t < tmax`.
pub fn walk(
    tree: &KdTree,
    triangles: &Triangles,
    origin: DVec3,
    dir: DVec3,
    tmax: f64,
    skip: u32,
    any: bool,
) -> Option<TriHit> {
    let delta = delta(tree, origin);
    let (t0, t1) = clip(tree.bounds, origin, dir, tmax, delta)?;
    // Nodes examined: inner nodes descended through and leaves whose triangles are tested.
    let (mut nodes, mut prims) = (0u64, 0u64);
    let mut stack = [(0usize, 0.0f64, 0.0f64); STACK];
    let mut top = 0;
    let mut current = Some((0usize, t0, t1));
    let mut best: Option<TriHit> = None;
    loop {
        let Some((mut node, mut tn, mut tf)) = current.take() else {
            if top == 0 {
                work::add(nodes, prims);
                return best;
            }
            top -= 1;
            let entry = stack[top];
            // Entry distances are lower bounds: a subtree entered beyond the best hit holds
            // nothing nearer. Strictly beyond: an equal distance may still tie on a lower index.
            if best.is_some_and(|b| b.t < entry.1) {
                continue;
            }
            current = Some(entry);
            continue;
        };
        while let Some((axis, split, left)) = tree.split(node) {
            nodes += 1;
            let [near, far] = children(axis, split, left, origin, dir, (tn, tf), delta);
            match (near, far) {
                (Some(n), Some(f)) => {
                    stack[top] = f;
                    top += 1;
                    (node, tn, tf) = n;
                }
                (Some(c), None) | (None, Some(c)) => (node, tn, tf) = c,
                (None, None) => break,
            }
        }
        if tree.nodes[node].inner().is_some() {
            continue;
        }
        nodes += 1;
        let (first, count) = tree.nodes[node].items();
        for &i in &tree.items[first..first + count] {
            if i == skip {
                continue;
            }
            prims += 1;
            let Some(t) = intersect(origin, dir, &triangles.positions[i as usize]) else {
                continue;
            };
            if t > 0.0 && t < tmax && best.is_none_or(|b| t < b.t || (t == b.t && i < b.triangle)) {
                best = Some(TriHit { t, triangle: i });
                if any {
                    work::add(nodes, prims);
                    return best;
                }
            }
        }
    }
}
