// Compressed wide BVH traversal (mod.rs and gpu.rs beside it; Ylitie, Karras & Laine 2017): the
// nodes are obvhs' 80-byte CWBVH8 nodes, re-based into the frame's local coordinates, each child
// box decoded from its 8-bit planes as p + 2^e q. A node popped from the stack (unless it was
// entered beyond the best hit so far) has its eight children tested at once: leaf children's
// triangles are tested on the spot, inner children are pushed far to near with their entry
// distances so the nearest is walked first. Near and far planes come from min and max of
// the two slab distances, never from the direction's sign, so a -0.0 direction component (on
// which obvhs' CPU node test picks the planes the wrong way round, see ray.rs) cannot swap them.
// Written with flags and structured exits (no return inside the loops: lavapipe miscompiled
// early returns under divergence).

struct CwNode {
    p: vec3<f32>,
    // The three exponent bytes, then the mask of inner children.
    e_imask: u32,
    child_base: u32,
    prim_base: u32,
    child_meta: vec2<u32>,
    // Per axis the children's quantised min and max planes: x min, x max, y min, ..., z max.
    q: array<vec2<u32>, 6>,
}

const CW_STACK: u32 = 128u;
const CW_BIG: f32 = 3.4e38;

// Module scope: cleared once per invocation rather than at every call.
var<private> cw_stack: array<u32, CW_STACK>;
var<private> cw_stack_t: array<f32, CW_STACK>;
var<private> cw_order_t: array<f32, 8>;
var<private> cw_order_node: array<u32, 8>;

@group(2) @binding(0) var<storage, read> cw_nodes: array<CwNode>;
@group(2) @binding(1) var<storage, read> cw_tris: array<AccelTri>;

fn cw_byte(v: vec2<u32>, i: u32) -> u32 {
    return (v[i >> 2u] >> (8u * (i & 3u))) & 0xffu;
}

fn cw_inverse(d: vec3<f32>) -> vec3<f32> {
    let tiny = vec3<f32>(1e-30);
    return 1.0 / select(d, select(-tiny, tiny, d >= vec3<f32>(0.0)), abs(d) < tiny);
}

// Entry distance into child i's box within [0, tmax], or CW_BIG when missed. The box is grown
// by 4 f32 ulps of its largest coordinate: the node's corner was rounded once more when it was
// re-based, and the triangles were rounded in the local frame, not the tree's.
fn cw_child(n: CwNode, i: u32, o: vec3<f32>, inv_d: vec3<f32>, tmax: f32) -> f32 {
    let e = vec3<f32>(
        bitcast<f32>((n.e_imask & 0xffu) << 23u),
        bitcast<f32>(((n.e_imask >> 8u) & 0xffu) << 23u),
        bitcast<f32>(((n.e_imask >> 16u) & 0xffu) << 23u),
    );
    let qlo = vec3<f32>(f32(cw_byte(n.q[0], i)), f32(cw_byte(n.q[2], i)), f32(cw_byte(n.q[4], i)));
    let qhi = vec3<f32>(f32(cw_byte(n.q[1], i)), f32(cw_byte(n.q[3], i)), f32(cw_byte(n.q[5], i)));
    let lo = n.p + e * qlo;
    let hi = n.p + e * qhi;
    let m = max(abs(lo), abs(hi));
    let pad = 4.0 * 1.1920929e-7 * max(max(m.x, m.y), m.z);
    let t1 = (lo - pad - o) * inv_d;
    let t2 = (hi + pad - o) * inv_d;
    let tn = max(max(min(t1.x, t2.x), min(t1.y, t2.y)), max(min(t1.z, t2.z), 0.0));
    let tf = min(min(max(t1.x, t2.x), max(t1.y, t2.y)), min(max(t1.z, t2.z), tmax));
    return select(CW_BIG, tn, tn <= tf);
}

// Closest hit of a triangle other than `skip` with 0 < t < tmax, ties to the lower index; with
// `any`, the first found.
fn cw_walk(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32, any: bool) -> AccelHit {
    var best = AccelHit(tmax, NO_HIT);
    let inv_d = cw_inverse(d);
    var sp = 1u;
    cw_stack[0] = 0u;
    cw_stack_t[0] = 0.0;
    var found = false;
    var overflow = false;
    while (sp > 0u && !found && !overflow) {
        sp -= 1u;
        // Entry distances are lower bounds: a node entered beyond the best hit holds nothing
        // nearer (strictly beyond: an equal distance may still tie on a lower index).
        if (cw_stack_t[sp] > best.t) {
            continue;
        }
        work_nodes += 1u;
        let n = cw_nodes[cw_stack[sp]];
        let imask = n.e_imask >> 24u;
        var inner = 0u;
        var i = 0u;
        for (; i < 8u && !found; i++) {
            let child_meta = cw_byte(n.child_meta, i);
            var t = CW_BIG;
            if (child_meta != 0u) {
                t = cw_child(n, i, o, inv_d, best.t);
            }
            if (t != CW_BIG && ((imask >> i) & 1u) == 1u) {
                // Kept in decreasing entry distance (insertion into at most seven).
                var j = inner;
                for (; j > 0u && cw_order_t[j - 1u] < t; j--) {
                    cw_order_t[j] = cw_order_t[j - 1u];
                    cw_order_node[j] = cw_order_node[j - 1u];
                }
                cw_order_t[j] = t;
                cw_order_node[j] = n.child_base + countOneBits(imask & ((1u << i) - 1u));
                inner += 1u;
            } else if (t != CW_BIG) {
                let first = n.prim_base + (child_meta & 31u);
                let count = countOneBits(child_meta >> 5u);
                for (var k = 0u; k < count && !found; k++) {
                    work_prims += 1u;
                    let tri = cw_tris[first + k];
                    let th = triangle_t(o, d, tri.v0, tri.e1, tri.e2);
                    if (tri.index != skip && th > 0.0 && th < tmax && (th < best.t || (th == best.t && tri.index < best.triangle))) {
                        best = AccelHit(th, tri.index);
                        found = any;
                    }
                }
            }
        }
        cut_short = cut_short || (i < 8u && !found);
        overflow = sp + inner > CW_STACK;
        for (var j = 0u; j < inner && !overflow; j++) {
            cw_stack[sp] = cw_order_node[j];
            cw_stack_t[sp] = cw_order_t[j];
            sp += 1u;
        }
    }
    cut_short = cut_short || overflow || (sp > 0u && !found);
    return best;
}

fn accel_closest(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> AccelHit {
    return cw_walk(o, d, tmax, skip, false);
}

fn accel_any(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> bool {
    return cw_walk(o, d, tmax, skip, true).triangle != NO_HIT;
}
