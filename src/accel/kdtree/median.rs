//! Spatial-median planes, the visibility-field paper's CRT baseline (a BSP with spatial-median
//! splits, Section 7): each node is cut in the middle of its longest side until it holds at most
//! `leaf_size` triangles or reaches `max_depth`. A triangle goes to each side its bounding box
//! meets (closed half-spaces: one touching the plane goes to both).

use super::{halves, KdSettings, Layout};
use glam::DVec3;

/// Fills `layout` with the median tree over triangles with bounding boxes `boxes` inside
/// `bounds`.
pub(super) fn build(layout: &mut Layout, boxes: &[(DVec3, DVec3)], bounds: (DVec3, DVec3), settings: &KdSettings) {
    let tris = (0..boxes.len() as u32).collect();
    node(layout, boxes, settings, 0, tris, bounds, 0);
}

/// Fills node `at` (already allocated) for `tris` inside `bounds` at `depth`.
fn node(
    layout: &mut Layout,
    boxes: &[(DVec3, DVec3)],
    settings: &KdSettings,
    at: usize,
    tris: Vec<u32>,
    bounds: (DVec3, DVec3),
    depth: u32,
) {
    if layout.overflowed {
        return layout.leaf(at, &[], depth);
    }
    let split = (tris.len() > settings.leaf_size as usize && depth < settings.max_depth)
        .then(|| split(layout, boxes, &tris, bounds))
        .flatten();
    let Some((axis, s, left, right)) = split else {
        layout.leaf(at, &tris, depth);
        return;
    };
    let first = layout.inner(at, axis, s);
    let (lo, hi) = halves(bounds, axis, s);
    node(layout, boxes, settings, first, left, lo, depth + 1);
    node(layout, boxes, settings, first + 1, right, hi, depth + 1);
}

/// The spatial median of the longest side (rounded to the f32 the node stores) and each side's
/// triangles; `None` where the plane would not divide anything.
#[allow(clippy::type_complexity)]
fn split(
    layout: &Layout,
    boxes: &[(DVec3, DVec3)],
    tris: &[u32],
    (lo, hi): (DVec3, DVec3),
) -> Option<(usize, f64, Vec<u32>, Vec<u32>)> {
    let axis = (hi - lo).max_position();
    let s = layout.stored(axis, (lo[axis] + hi[axis]) * 0.5);
    if !(s > lo[axis] && s < hi[axis]) {
        return None;
    }
    let (mut left, mut right) = (Vec::new(), Vec::new());
    for &t in tris {
        let (a, b) = boxes[t as usize];
        if a[axis] <= s {
            left.push(t);
        }
        if b[axis] >= s {
            right.push(t);
        }
    }
    (left.len() < tris.len() || right.len() < tris.len()).then_some((axis, s, left, right))
}
