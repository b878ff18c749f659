//! Packet traversal (Wald, Slusallek, Benthin & Wagner 2001, the coherent ray tracing the
//! visibility-field paper's CRT baseline is named after): up to [`WIDTH`] rays whose directions
//! share a sign octant descend the tree together. At an inner node each lane takes the
//! children its own [`walk::children`] would give it ([`split_lanes`]); the packet enters a
//! child when any lane does, near child first (the same child for every lane: the octant fixes
//! it). A leaf's triangles are tested against the lanes still open. Each lane therefore visits
//! exactly the leaves of its single-ray walk, in the same order, and any-hit answers are the
//! single queries'. A node is fetched once for the whole packet: the work counters count packet
//! node visits and lane triangle tests.

use super::walk::{self, clip, STACK};
use super::KdTree;
use crate::accel::{intersect_edges, work, Query};
use glam::DVec3;

/// Rays per packet (the CRT's SSE packets held 4 f32 rays; 8 f64 lanes fill two AVX-512 or four
/// AVX registers). The lanes are loops over fixed arrays, left to the compiler.
pub const WIDTH: usize = 8;

/// Each lane's part of the ray, `(t_near, t_far)`.
type Spans = [(f64, f64); WIDTH];

/// Bit a of the result set where `dir[a]` is negative (-0.0 counts as positive, as it does in
/// [`walk::children`]'s near-child order).
fn octant(dir: DVec3) -> u8 {
    (dir.x < 0.0) as u8 | ((dir.y < 0.0) as u8) << 1 | ((dir.z < 0.0) as u8) << 2
}

/// The lanes set in `mask`, lowest first.
fn lanes(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        let l = mask.trailing_zeros() as usize;
        mask &= mask.wrapping_sub(1);
        (l < 32).then_some(l)
    })
}

/// Any hit for each query: grouped by octant (in issue order within one), traced in packets.
pub fn any_hits(tree: &KdTree, queries: &[Query], hits: &mut [bool]) {
    hits.fill(false);
    let mut stack = Vec::with_capacity(STACK);
    let mut order: Vec<u32> = (0..queries.len() as u32).collect();
    order.sort_by_key(|&i| octant(queries[i as usize].dir));
    for group in order.chunk_by(|&a, &b| octant(queries[a as usize].dir) == octant(queries[b as usize].dir)) {
        for packet in group.chunks(WIDTH) {
            trace(tree, queries, packet, hits, &mut stack);
        }
    }
}

/// [`walk::children`] for every lane at once, in the packet's near-far order, computed the same
/// way (so each lane's decision is its single walk's) but without branches, for the compiler to
/// vectorise: each lane's part of the ray in the near and the far child and the lanes that enter
/// each. A zero direction component enters a side when the origin lies within `delta` of it.
fn split_lanes(
    split: f64,
    o: &[f64; WIDTH],
    d: &[f64; WIDTH],
    delta: &[f64; WIDTH],
    span: &Spans,
) -> (Spans, Spans, u32, u32) {
    let (mut near, mut far) = (*span, *span);
    let (mut near_mask, mut far_mask) = (0u32, 0u32);
    for l in 0..WIDTH {
        let (tn, tf) = span[l];
        let (ta, tb) = ((split - delta[l] - o[l]) / d[l], (split + delta[l] - o[l]) / d[l]);
        let (lo, hi) = (ta.min(tb), ta.max(tb));
        let flat = d[l] == 0.0;
        // Along the axis the near child is the left one (non-negative d) or the right one.
        let (enter_near, enter_far) = if flat {
            (o[l] <= split + delta[l], o[l] >= split - delta[l])
        } else {
            (tn <= hi, lo <= tf)
        };
        if !flat {
            near[l].1 = tf.min(hi);
            far[l].0 = tn.max(lo);
        }
        near_mask |= (enter_near as u32) << l;
        far_mask |= (enter_far as u32) << l;
    }
    (near, far, near_mask, far_mask)
}

/// A far child left for later: node, the lanes that enter it, their parts of the ray.
type Deferred = (usize, u32, Spans);

/// One packet of `queries` (indices `packet`, one octant); `stack` is scratch space.
fn trace(tree: &KdTree, queries: &[Query], packet: &[u32], hits: &mut [bool], stack: &mut Vec<Deferred>) {
    let q = |l: usize| &queries[packet[l] as usize];
    let negative = octant(q(0).dir);
    let mut delta = [0.0; WIDTH];
    let mut spans: Spans = [(0.0, 0.0); WIDTH];
    // Origins and directions by axis, lane by lane (unused lanes: a harmless ray along +x).
    let (mut o, mut d) = ([[0.0; WIDTH]; 3], [[1.0; WIDTH]; 3]);
    let mut open = 0u32;
    for l in 0..packet.len() {
        for a in 0..3 {
            o[a][l] = q(l).origin[a];
            d[a][l] = q(l).dir[a];
        }
        delta[l] = walk::delta(tree, q(l).origin);
        if let Some(s) = clip(tree.bounds, q(l).origin, q(l).dir, q(l).tmax, delta[l]) {
            spans[l] = s;
            open |= 1 << l;
        }
    }
    let (mut nodes, mut prims) = (0u64, 0u64);
    stack.clear();
    let mut current = (open != 0).then_some((0usize, open, spans));
    while open != 0 {
        let Some((mut node, mut mask, mut span)) = current.take() else {
            let Some((node, mask, span)) = stack.pop() else {
                break;
            };
            // Lanes answered since the push have nothing left to find.
            current = (mask & open != 0).then_some((node, mask & open, span));
            continue;
        };
        while let Some((axis, split, left)) = tree.split(node) {
            nodes += 1;
            let (near_node, far_node) = if negative & (1 << axis) != 0 {
                (left + 1, left)
            } else {
                (left, left + 1)
            };
            let (near, far, near_mask, far_mask) = split_lanes(split, &o[axis], &d[axis], &delta, &span);
            let (near_mask, far_mask) = (near_mask & mask, far_mask & mask);
            match (near_mask, far_mask) {
                (0, 0) => break,
                (0, _) => (node, mask, span) = (far_node, far_mask, far),
                (_, 0) => (node, mask, span) = (near_node, near_mask, near),
                _ => {
                    stack.push((far_node, far_mask, far));
                    (node, mask, span) = (near_node, near_mask, near);
                }
            }
        }
        if tree.nodes[node].inner().is_some() {
            continue;
        }
        nodes += 1;
        let (first, count) = tree.nodes[node].items();
        for &t in &tree.items[first..first + count] {
            let [v0, v1, v2] = tree.triangles.positions[t as usize];
            let edges = (v1 - v0, v2 - v0);
            for l in lanes(mask & open) {
                let q = q(l);
                if t == q.skip {
                    continue;
                }
                prims += 1;
                if intersect_edges(q.origin, q.dir, v0, edges).is_some_and(|x| x > 0.0 && x < q.tmax) {
                    hits[packet[l] as usize] = true;
                    open &= !(1 << l);
                }
            }
            if mask & open == 0 {
                break;
            }
        }
    }
    work::add(nodes, prims);
}
