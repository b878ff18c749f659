// An infinite plane: the f32 twin of plane.rs beside it. `object` is its id in the scene.

struct Plane {
    point: vec3<f32>,
    albedo: f32,
    normal: vec3<f32>,
    object: u32,
}

// Distance along `dir` to the plane, or -1 when the ray is parallel to it.
fn plane_t(origin: vec3<f32>, dir: vec3<f32>, pl: Plane) -> f32 {
    let denom = dot(dir, pl.normal);
    if (denom == 0.0) {
        return -1.0;
    }
    return dot(pl.point - origin, pl.normal) / denom;
}
