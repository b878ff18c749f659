// BVH2 traversal over full-f32 triangles: closest hit for camera rays, any hit with early exit
// for shadow rays. The node array is obvhs' (children of an inner node are adjacent); leaves
// index the triangle array directly (laid out in leaf order). Twin of mod.rs beside it; the
// interface (accel_closest, accel_any) is the accelerator seam's (src/accel/mod.rs).

struct Node {
    min: vec3<f32>,
    prim_count: u32,
    max: vec3<f32>,
    first_index: u32,
}

struct MeshHit {
    t: f32,
    slot: u32,
}

const STACK_SIZE: u32 = 64u;

const BIG: f32 = 3.4e38;

// One traversal stack per invocation, shared by both walks (never live at once). Module scope,
// so it is zero-initialised once per invocation rather than at every call: a function-local
// array is cleared on each call, which tripled the cost of analytic-only shadow rays on lavapipe.
var<private> stack: array<u32, STACK_SIZE>;

@group(2) @binding(0) var<storage, read> nodes: array<Node>;
@group(2) @binding(1) var<storage, read> tris: array<AccelTri>;

// Entry distance into a node's box within [0, tmax], or BIG when missed.
fn slab(o: vec3<f32>, inv_d: vec3<f32>, tmax: f32, n: Node) -> f32 {
    let t1 = (n.min - o) * inv_d;
    let t2 = (n.max - o) * inv_d;
    let lo = max(max(min(t1.x, t2.x), min(t1.y, t2.y)), max(min(t1.z, t2.z), 0.0));
    let hi = min(min(max(t1.x, t2.x), max(t1.y, t2.y)), min(max(t1.z, t2.z), tmax));
    return select(BIG, lo, lo <= hi);
}

fn safe_inverse(d: vec3<f32>) -> vec3<f32> {
    let tiny = vec3<f32>(1e-30);
    return 1.0 / select(d, select(-tiny, tiny, d >= vec3<f32>(0.0)), abs(d) < tiny);
}

// Closest triangle with 0 < t < tmax, skipping the triangle whose `index` is `skip`.
fn accel_closest(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> AccelHit {
    let h = bvh_closest(o, d, tmax, skip);
    if (h.slot == NO_HIT) {
        return AccelHit(h.t, NO_HIT);
    }
    return AccelHit(h.t, tris[h.slot].index);
}

fn bvh_closest(o: vec3<f32>, d: vec3<f32>, tmax_in: f32, skip: u32) -> MeshHit {
    var best = MeshHit(tmax_in, NO_HIT);
    let inv_d = safe_inverse(d);
    var sp = 1u;
    stack[0] = 0u;
    while (sp > 0u) {
        sp -= 1u;
        work_nodes += 1u;
        let n = nodes[stack[sp]];
        let entered = slab(o, inv_d, best.t, n) != BIG;
        if (entered && n.prim_count > 0u) {
            var i = n.first_index;
            for (; i < n.first_index + n.prim_count; i++) {
                work_prims += 1u;
                let t = triangle_t(o, d, tris[i].v0, tris[i].e1, tris[i].e2);
                // Equal distances go to the lower input index, as every other structure's.
                let tie = t == best.t && best.slot != NO_HIT && tris[i].index < tris[best.slot].index;
                if (t > 0.0 && (t < best.t || tie) && tris[i].index != skip) {
                    best = MeshHit(t, i);
                }
            }
            cut_short = cut_short || i < n.first_index + n.prim_count;
        } else if (entered && sp + 2u > STACK_SIZE) {
            cut_short = true;
        } else if (entered) {
            // Visit the nearer child first.
            let a = slab(o, inv_d, best.t, nodes[n.first_index]);
            let b = slab(o, inv_d, best.t, nodes[n.first_index + 1u]);
            let near_first = a <= b;
            stack[sp] = select(n.first_index, n.first_index + 1u, near_first);
            stack[sp + 1u] = select(n.first_index + 1u, n.first_index, near_first);
            sp += 2u;
        }
    }
    cut_short = cut_short || sp > 0u;
    return best;
}

// Whether any triangle other than `skip` is hit with 0 < t < tmax; stops at the first. (Written
// with a flag and structured exits rather than a return from inside the loops: lavapipe
// miscompiled the early return under divergence, dropping whole workgroups' shadow rays.)
fn accel_any(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> bool {
    let inv_d = safe_inverse(d);
    var sp = 1u;
    stack[0] = 0u;
    var found = false;
    while (sp > 0u && !found) {
        sp -= 1u;
        work_nodes += 1u;
        let n = nodes[stack[sp]];
        let entered = slab(o, inv_d, tmax, n) != BIG;
        if (entered && n.prim_count > 0u) {
            var i = n.first_index;
            for (; i < n.first_index + n.prim_count; i++) {
                work_prims += 1u;
                let t = triangle_t(o, d, tris[i].v0, tris[i].e1, tris[i].e2);
                found = found || (t > 0.0 && t < tmax && tris[i].index != skip);
            }
            cut_short = cut_short || i < n.first_index + n.prim_count;
        } else if (entered && sp + 2u > STACK_SIZE) {
            cut_short = true;
        } else if (entered) {
            stack[sp] = n.first_index;
            stack[sp + 1u] = n.first_index + 1u;
            sp += 2u;
        }
    }
    cut_short = cut_short || (sp > 0u && !found);
    return found;
}
