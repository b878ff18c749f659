// Robust ray origins: the f32 twin of src/geometry.rs.

const NO_HIT: u32 = 0xffffffffu;

// Waechter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (RTG ch. 6).
fn offset_origin(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let of_i = vec3<i32>(256.0 * n);
    let p_i = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(of_i, -of_i, p < vec3<f32>(0.0)));
    let float_scale = 1.0 / 65536.0;
    return select(p_i, p + float_scale * n, abs(p) < vec3<f32>(1.0 / 32.0));
}
