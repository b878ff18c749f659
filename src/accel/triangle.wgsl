// The ray-triangle test every structure's WGSL shares: Moller-Trumbore in f32 over a triangle
// stored as a corner and two edges, the twin of `accel::intersect`. The distance, or -1 on a
// miss; both sides hit.
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
