// Test hooks, compiled only when a test calls them (render/gpu/hooks.rs): they expose the WGSL
// sampler and the acceleration structure's queries to tests, bound at their own group 3.

// Test hook: the unit-disk points a scheme gives pixel `params.height` (at column height % 64,
// row height / 64 of a notional image 64 wide) in frame `params.frame`, for the CPU/GPU sampler
// agreement test. Writes params.width points into `visibility`.
@compute @workgroup_size(64)
fn dump_samples(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if (k >= params.width) {
        return;
    }
    let stream = stream_pixel(params.seed, 0u, params.height);
    let pixel = vec2<u32>(params.height % 64u, params.height / 64u);
    let s = disk_point(params.scheme, params.width, k, stream, pixel, tile_seed(params.seed, 0u), params.frame);
    visibility[2u * k] = s.x;
    visibility[2u * k + 1u] = s.y;
}

// Test hook: closest and any hit of probe rays against the acceleration structure. Ray k is
// probe_rays[2k] = (origin, tmax) and probe_rays[2k + 1] = (direction, 0); writes
// visibility[3k..3k+3] = (t, triangle index as bits, any-hit flag).
@group(3) @binding(0) var<storage, read> probe_rays: array<vec4<f32>>;

@compute @workgroup_size(64)
fn trace_probes(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if (k >= params.width) {
        return;
    }
    let o = probe_rays[2u * k].xyz;
    let tmax = probe_rays[2u * k].w;
    let d = probe_rays[2u * k + 1u].xyz;
    let h = accel_closest(o, d, tmax, NO_HIT);
    visibility[3u * k] = select(-1.0, h.t, h.triangle != NO_HIT);
    visibility[3u * k + 1u] = bitcast<f32>(h.triangle);
    visibility[3u * k + 2u] = select(0.0, 1.0, accel_any(o, d, tmax, NO_HIT));
}
