// What every structure's WGSL shares: the triangle as stored (`accel::GpuTri`, 48 bytes: corner
// 0, the two edges from it, the input index) and the ray-triangle test over it, Moller-Trumbore
// in f32, the twin of `accel::intersect`: the distance, or -1 on a miss; both sides hit.

struct AccelTri {
    v0: vec3<f32>,
    _p0: u32,
    e1: vec3<f32>,
    index: u32,
    e2: vec3<f32>,
    _p1: u32,
}

fn triangle_t(o: vec3<f32>, d: vec3<f32>, v0: vec3<f32>, e1: vec3<f32>, e2: vec3<f32>) -> f32 {
    let p = cross(d, e2);
    let det = dot(e1, p);
    if (det == 0.0) {
        return -1.0;
    }
    let inv = 1.0 / det;
    let s = o - v0;
    let u = dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) {
        return -1.0;
    }
    let q = cross(s, e1);
    let v = dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0) {
        return -1.0;
    }
    return dot(e2, q) * inv;
}
