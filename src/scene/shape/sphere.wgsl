// An analytic sphere: the f32 twin of sphere.rs beside it. `object` is its id in the scene.

struct Sphere {
    center: vec3<f32>,
    radius: f32,
    albedo: f32,
    object: u32,
    _p0: u32,
    _p1: u32,
}

// Both roots, or z = 0 on a miss (z = 1 on a hit) (Haines et al., Ray Tracing Gems ch. 7).
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
