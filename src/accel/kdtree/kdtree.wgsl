// kd-tree walk (mod.rs and walk.rs beside it; the accelerator interface of src/accel/mod.rs):
// descend to the near child, push the far one with its entry and exit distances, test a leaf's
// triangles, pop; planes and the root box are slabs `delta` thick, so f32 rounding never
// decides a side alone. Written with flags and structured exits (no return inside the loops:
// lavapipe miscompiled early returns under divergence).

struct KdHeader {
    lo: vec3<f32>,
    pad0: u32,
    hi: vec3<f32>,
    pad1: u32,
}

struct KdEntry {
    node: u32,
    tn: f32,
    tf: f32,
}

const KD_STACK: u32 = 64u;

// Half-thickness of planes relative to the largest coordinate in play (the scene's or the
// origin's): f32 rounding of triangles, splits and plane distances is a few 1e-7 of it.
//
// It is also why this walk's work counts can exceed the f64 walk's (walk::DELTA, 1e-9) on the
// same tree: a segment that ends or starts within this slab of a plane, but outside the f64
// walk's, enters the leaf across the plane here only and tests its triangles. Where such a point
// lies under dense leaves, that dominates: the classroom's point lights at z = 2.9 lie 9.5e-8 m
// below the plane stored as 2.9000001, under four leaves holding a lamp's 96 fan triangles each,
// so each unoccluded shadow ray tests 384 more triangles: 417 per shadow ray against the CPU's
// 121 (3.4x) at 15 % more nodes (frame 0 of the walk, 32 x 32); its camera at z = 1.6, 2.4e-8 m
// below the plane 1.6000000238, costs camera rays 11 % more nodes. A thinner slab would not
// remove it: at 1e-9 the shadow rays still test 1.5x the CPU's triangles, light and plane lying
// less than one f32 step apart in the frame's coordinates; with the lights 1 cm lower the two
// agree within 1 %. The CPU's rays walked in f64 with this slab give this walk's counts to the
// ray; tests/it/kdtree_work_counts.rs shows both cases on a small scene.
const KD_DELTA: f32 = 2e-5;

// Module scope: cleared once per invocation rather than at every call.
var<private> kd_stack: array<KdEntry, KD_STACK>;

@group(2) @binding(0) var<storage, read> kd_header: KdHeader;
@group(2) @binding(1) var<storage, read> kd_nodes: array<vec2<u32>>;
@group(2) @binding(2) var<storage, read> kd_items: array<u32>;
@group(2) @binding(3) var<storage, read> kd_tris: array<AccelTri>;

fn kd_max_abs(v: vec3<f32>) -> f32 {
    let a = abs(v);
    return max(max(a.x, a.y), a.z);
}

// The part [t0, t1] of the segment inside the root box grown by delta; t0 > t1 when missed.
fn kd_clip(o: vec3<f32>, d: vec3<f32>, tmax: f32, delta: f32) -> vec2<f32> {
    var t0 = 0.0;
    var t1 = tmax;
    for (var a = 0u; a < 3u; a++) {
        let lo = kd_header.lo[a] - delta;
        let hi = kd_header.hi[a] + delta;
        if (d[a] == 0.0) {
            if (o[a] < lo || o[a] > hi) {
                t0 = 1.0;
                t1 = 0.0;
            }
        } else {
            let ta = (lo - o[a]) / d[a];
            let tb = (hi - o[a]) / d[a];
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        }
    }
    return vec2<f32>(t0, t1);
}

// Closest hit of a triangle other than `skip` with 0 < t < tmax, ties to the lower index; with
// `any`, the first found.
fn kd_walk(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32, any: bool) -> AccelHit {
    var best = AccelHit(tmax, NO_HIT);
    let scale = max(max(kd_max_abs(kd_header.lo), kd_max_abs(kd_header.hi)), kd_max_abs(o));
    let delta = KD_DELTA * max(scale, 1e-30);
    let span = kd_clip(o, d, tmax, delta);
    var sp = 0u;
    if (span.x <= span.y) {
        kd_stack[0] = KdEntry(0u, span.x, span.y);
        sp = 1u;
    }
    var found = false;
    while (sp > 0u && !found) {
        sp -= 1u;
        var e = kd_stack[sp];
        // Entry distances are lower bounds: nothing nearer lies beyond the best hit.
        if (best.triangle != NO_HIT && best.t < e.tn) {
            continue;
        }
        var n = kd_nodes[e.node];
        var overflow = false;
        while ((n.y & 3u) != 3u && !overflow) {
            work_nodes += 1u;
            let axis = n.y & 3u;
            let left = n.y >> 2u;
            let split = bitcast<f32>(n.x);
            let oa = o[axis];
            let da = d[axis];
            var near = KdEntry(left, e.tn, e.tf);
            var far = KdEntry(left + 1u, e.tn, e.tf);
            var near_ok = oa <= split + delta;
            var far_ok = oa >= split - delta;
            if (da != 0.0) {
                let ta = (split - delta - oa) / da;
                let tb = (split + delta - oa) / da;
                let lo = min(ta, tb);
                let hi = max(ta, tb);
                near = KdEntry(select(left + 1u, left, da > 0.0), e.tn, min(e.tf, hi));
                far = KdEntry(select(left, left + 1u, da > 0.0), max(e.tn, lo), e.tf);
                near_ok = e.tn <= hi;
                far_ok = lo <= e.tf;
            }
            if (near_ok && far_ok) {
                if (sp >= KD_STACK) {
                    overflow = true;
                } else {
                    kd_stack[sp] = far;
                    sp += 1u;
                    e = near;
                }
            } else if (near_ok) {
                e = near;
            } else {
                e = far;
            }
            n = kd_nodes[e.node];
        }
        cut_short = cut_short || overflow;
        if (!overflow) {
            work_nodes += 1u;
            let first = n.x;
            let count = n.y >> 2u;
            var i = 0u;
            for (; i < count && !found; i++) {
                let id = kd_items[first + i];
                work_prims += u32(id != skip);
                let tri = kd_tris[id];
                let t = triangle_t(o, d, tri.v0, tri.e1, tri.e2);
                if (id != skip && t > 0.0 && t < tmax && (t < best.t || (t == best.t && id < best.triangle))) {
                    best = AccelHit(t, id);
                    found = any;
                }
            }
            cut_short = cut_short || (i < count && !found);
        }
    }
    cut_short = cut_short || (sp > 0u && !found);
    return best;
}

fn accel_closest(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> AccelHit {
    return kd_walk(o, d, tmax, skip, false);
}

fn accel_any(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> bool {
    return kd_walk(o, d, tmax, skip, true).triangle != NO_HIT;
}
