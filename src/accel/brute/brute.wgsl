// Brute force: every triangle against every ray (mod.rs beside it). Implements the accelerator
// interface of src/accel/mod.rs; triangle i of the buffer is input triangle i.

struct BruteTri {
    v0: vec3<f32>,
    _p0: u32,
    e1: vec3<f32>,
    _p1: u32,
    e2: vec3<f32>,
    _p2: u32,
}

@group(2) @binding(0) var<storage, read> brute_tris: array<BruteTri>;

// Moller-Trumbore; the distance, or -1 on a miss. Both sides hit.
fn brute_t(o: vec3<f32>, d: vec3<f32>, tri: BruteTri) -> f32 {
    let p = cross(d, tri.e2);
    let det = dot(tri.e1, p);
    if (det == 0.0) {
        return -1.0;
    }
    let inv = 1.0 / det;
    let s = o - tri.v0;
    let u = dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) {
        return -1.0;
    }
    let q = cross(s, tri.e1);
    let v = dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0) {
        return -1.0;
    }
    return dot(tri.e2, q) * inv;
}

fn accel_closest(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> AccelHit {
    var best = AccelHit(tmax, NO_HIT);
    let n = arrayLength(&brute_tris);
    var i = 0u;
    for (; i < n; i++) {
        let t = brute_t(o, d, brute_tris[i]);
        if (i != skip && t > 0.0 && t < best.t) {
            best = AccelHit(t, i);
        }
    }
    cut_short = cut_short || i < n;
    return best;
}

fn accel_any(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> bool {
    let n = arrayLength(&brute_tris);
    var found = false;
    var i = 0u;
    for (; i < n && !found; i++) {
        let t = brute_t(o, d, brute_tris[i]);
        found = i != skip && t > 0.0 && t < tmax;
    }
    cut_short = cut_short || (i < n && !found);
    return found;
}
