// Brute force: every triangle against every ray (mod.rs beside it). Implements the accelerator
// interface of src/accel/mod.rs; triangle i of the buffer is input triangle i.

@group(2) @binding(0) var<storage, read> brute_tris: array<AccelTri>;

fn accel_closest(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> AccelHit {
    var best = AccelHit(tmax, NO_HIT);
    let n = arrayLength(&brute_tris);
    var i = 0u;
    for (; i < n; i++) {
        work_prims += 1u;
        let tri = brute_tris[i];
        let t = triangle_t(o, d, tri.v0, tri.e1, tri.e2);
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
        work_prims += 1u;
        let tri = brute_tris[i];
        let t = triangle_t(o, d, tri.v0, tri.e1, tri.e2);
        found = i != skip && t > 0.0 && t < tmax;
    }
    cut_short = cut_short || (i < n && !found);
    return found;
}
