// Ray-shape intersection and robust ray origins: the f32 twin of src/geometry.rs.

const NO_HIT: u32 = 0xffffffffu;

// Both roots, or vec2(-1, -1) on a miss (Haines et al., Ray Tracing Gems ch. 7).
fn sphere_roots(origin: vec3<f32>, dir: vec3<f32>, center: vec3<f32>, radius: f32) -> vec3<f32> {
    let f = origin - center;
    let b = -dot(f, dir);
    let l = f + b * dir;
    let disc = radius * radius - dot(l, l);
    if (disc < 0.0) {
        return vec3<f32>(0.0, 0.0, 0.0);
    }
    let c = dot(f, f) - radius * radius;
    let q = b + select(-sqrt(disc), sqrt(disc), b >= 0.0);
    var t0 = 0.0;
    var t1 = 0.0;
    if (q != 0.0) {
        t0 = c / q;
        t1 = q;
    }
    return vec3<f32>(min(t0, t1), max(t0, t1), 1.0);
}

// Waechter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (RTG ch. 6).
fn offset_origin(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let of_i = vec3<i32>(256.0 * n);
    let p_i = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(of_i, -of_i, p < vec3<f32>(0.0)));
    let float_scale = 1.0 / 65536.0;
    return select(p_i, p + float_scale * n, abs(p) < vec3<f32>(1.0 / 32.0));
}
