// The real-time reconstruction filters in f32: the WGSL twin of src/render/denoise/cpu.rs,
// which holds the formulas and their sources; change both together.

struct Params {
    width: u32,
    height: u32,
    // A-trous step (pixels) of this dispatch.
    step: u32,
    _pad: u32,
    gaussian_sigma: f32,
    sigma_luminance: f32,
    sigma_depth: f32,
    sigma_normal: f32,
    min_sigma: f32,
    luminance_epsilon: f32,
    directionless: f32,
    _pad2: f32,
}

const NO_RECEIVER: f32 = -1.0;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> image_in: array<f32>;
@group(0) @binding(2) var<storage, read> variance_in: array<f32>;
@group(0) @binding(3) var<storage, read> depth: array<f32>;
@group(0) @binding(4) var<storage, read> normal: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> sigma: array<vec2<f32>>;
@group(0) @binding(6) var<storage, read_write> image_out: array<f32>;
@group(0) @binding(7) var<storage, read_write> variance_out: array<f32>;

const B3 = array<f32, 5>(0.0625, 0.25, 0.375, 0.25, 0.0625);

fn index(x: i32, y: i32) -> u32 {
    return u32(y) * params.width + u32(x);
}

fn usable(x: i32, y: i32) -> bool {
    return x >= 0 && y >= 0 && x < i32(params.width) && y < i32(params.height) && image_in[index(x, y)] != NO_RECEIVER;
}

fn depth_axis(x: i32, y: i32, dx: i32, dy: i32) -> f32 {
    let ua = usable(x - dx, y - dy);
    let ub = usable(x + dx, y + dy);
    if (ua && ub) {
        return abs(depth[index(x + dx, y + dy)] - depth[index(x - dx, y - dy)]) / 2.0;
    }
    if (ua) {
        return abs(depth[index(x, y)] - depth[index(x - dx, y - dy)]);
    }
    if (ub) {
        return abs(depth[index(x + dx, y + dy)] - depth[index(x, y)]);
    }
    return 0.0;
}

fn depth_slope(x: i32, y: i32) -> f32 {
    return max(depth_axis(x, y, 1, 0), depth_axis(x, y, 0, 1));
}

fn geometry_weight(p: u32, q: u32, slope: f32, distance: f32) -> f32 {
    let zp = depth[p];
    let scale = max(params.sigma_depth * slope * distance, 1e-3 * zp);
    let wz = exp(-abs(zp - depth[q]) / scale);
    let c = dot(normal[p].xyz, normal[q].xyz);
    if (c <= 0.0) {
        return 0.0;
    }
    return wz * pow(c, params.sigma_normal);
}

fn gaussian_at(x: i32, y: i32, s: f32, guided: bool) -> f32 {
    let r = i32(ceil(3.0 * s));
    let slope = depth_slope(x, y);
    let p = index(x, y);
    var sum = 0.0;
    var weight = 0.0;
    for (var dy = -r; dy <= r; dy = dy + 1) {
        for (var dx = -r; dx <= r; dx = dx + 1) {
            let qx = x + dx;
            let qy = y + dy;
            if (!usable(qx, qy)) {
                continue;
            }
            let d2 = f32(dx * dx + dy * dy);
            var w = exp(-d2 / (2.0 * s * s));
            let q = index(qx, qy);
            if (guided) {
                w = w * geometry_weight(p, q, slope, sqrt(d2));
            }
            sum = sum + w * image_in[q];
            weight = weight + w;
        }
    }
    return sum / weight;
}

@compute @workgroup_size(8, 8)
fn gaussian(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let x = i32(gid.x);
    let y = i32(gid.y);
    let p = index(x, y);
    if (!usable(x, y)) {
        image_out[p] = NO_RECEIVER;
        return;
    }
    image_out[p] = gaussian_at(x, y, params.gaussian_sigma, false);
}

// The oriented Gaussian of cpu.rs `oriented_at`: the edge's normal from the weighted
// regression slope over the window, then `along` pixels along it and `across` across.
fn oriented_at(x: i32, y: i32, along: f32, across: f32) -> f32 {
    let r = i32(ceil(3.0 * along));
    let slope = depth_slope(x, y);
    let p = index(x, y);
    var sum = 0.0;
    var weight = 0.0;
    for (var dy = -r; dy <= r; dy = dy + 1) {
        for (var dx = -r; dx <= r; dx = dx + 1) {
            if (!usable(x + dx, y + dy)) {
                continue;
            }
            let d = vec2<f32>(f32(dx), f32(dy));
            let q = index(x + dx, y + dy);
            let w = geometry_weight(p, q, slope, length(d)) * exp(-dot(d, d) / (2.0 * along * along));
            sum = sum + w * image_in[q];
            weight = weight + w;
        }
    }
    let mean = sum / weight;
    var n = vec2<f32>(0.0, 0.0);
    for (var dy = -r; dy <= r; dy = dy + 1) {
        for (var dx = -r; dx <= r; dx = dx + 1) {
            if (!usable(x + dx, y + dy)) {
                continue;
            }
            let d = vec2<f32>(f32(dx), f32(dy));
            let q = index(x + dx, y + dy);
            let w = geometry_weight(p, q, slope, length(d)) * exp(-dot(d, d) / (2.0 * along * along));
            n = n + w * (image_in[q] - mean) * d;
        }
    }
    let norm = length(n);
    let oriented = norm > params.directionless * weight;
    sum = 0.0;
    weight = 0.0;
    for (var dy = -r; dy <= r; dy = dy + 1) {
        for (var dx = -r; dx <= r; dx = dx + 1) {
            if (!usable(x + dx, y + dy)) {
                continue;
            }
            let d = vec2<f32>(f32(dx), f32(dy));
            let q = index(x + dx, y + dy);
            var e = dot(d, d) / (2.0 * across * across);
            if (oriented) {
                let a = dot(d, n) / norm;
                let t = (d.y * n.x - d.x * n.y) / norm;
                e = a * a / (2.0 * across * across) + t * t / (2.0 * along * along);
            }
            let w = geometry_weight(p, q, slope, length(d)) * exp(-e);
            sum = sum + w * image_in[q];
            weight = weight + w;
        }
    }
    return sum / weight;
}

@compute @workgroup_size(8, 8)
fn penumbra(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let x = i32(gid.x);
    let y = i32(gid.y);
    let p = index(x, y);
    if (!usable(x, y)) {
        image_out[p] = NO_RECEIVER;
        return;
    }
    let s = sigma[p];
    if (s.x < params.min_sigma) {
        image_out[p] = image_in[p];
        return;
    }
    image_out[p] = oriented_at(x, y, s.x, s.y);
}

fn blurred_variance(x: i32, y: i32) -> f32 {
    let k = array<f32, 3>(0.25, 0.5, 0.25);
    var sum = 0.0;
    var weight = 0.0;
    for (var j = -1; j <= 1; j = j + 1) {
        for (var i = -1; i <= 1; i = i + 1) {
            if (usable(x + i, y + j)) {
                let w = k[i + 1] * k[j + 1];
                sum = sum + w * variance_in[index(x + i, y + j)];
                weight = weight + w;
            }
        }
    }
    return sum / weight;
}

// One a-trous iteration at step params.step: the filtered value and its variance.
@compute @workgroup_size(8, 8)
fn atrous(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let x = i32(gid.x);
    let y = i32(gid.y);
    let p = index(x, y);
    if (!usable(x, y)) {
        image_out[p] = NO_RECEIVER;
        variance_out[p] = 0.0;
        return;
    }
    let step = i32(params.step);
    let denom = params.sigma_luminance * sqrt(blurred_variance(x, y)) + params.luminance_epsilon;
    let slope = depth_slope(x, y);
    var sum = 0.0;
    var weight = 0.0;
    var variance = 0.0;
    for (var j = -2; j <= 2; j = j + 1) {
        for (var i = -2; i <= 2; i = i + 1) {
            let qx = x + step * i;
            let qy = y + step * j;
            if (!usable(qx, qy)) {
                continue;
            }
            let q = index(qx, qy);
            let distance = f32(step) * sqrt(f32(i * i + j * j));
            let h = B3[i + 2] * B3[j + 2];
            let w = h * geometry_weight(p, q, slope, distance) * exp(-abs(image_in[p] - image_in[q]) / denom);
            sum = sum + w * image_in[q];
            weight = weight + w;
            variance = variance + w * w * variance_in[q];
        }
    }
    image_out[p] = sum / weight;
    variance_out[p] = variance / (weight * weight);
}
