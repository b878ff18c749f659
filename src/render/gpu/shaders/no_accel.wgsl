// The accelerator interface (src/accel/mod.rs) for a scene without triangles: every query
// misses, so a scene of analytic shapes compiles with no mesh traversal at all.

fn accel_closest(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> AccelHit {
    return AccelHit(tmax, NO_HIT);
}

fn accel_any(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> bool {
    return false;
}
