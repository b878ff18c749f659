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
    direction_sigma: f32,
}

const NO_RECEIVER: f32 = -1.0;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> image_in: array<f32>;
@group(0) @binding(2) var<storage, read> variance_in: array<f32>;
@group(0) @binding(3) var<storage, read> depth: array<f32>;
@group(0) @binding(4) var<storage, read> normal: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> sigma: array<f32>;
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

fn line_pixel(x: i32, y: i32, k: i32, m: i32, x_major: bool) -> vec2<i32> {
    if (x_major) {
        return vec2<i32>(x + k, y + m);
    }
    return vec2<i32>(x + m, y + k);
}

fn catmull_rom(f: f32) -> array<f32, 4> {
    let f2 = f * f;
    let f3 = f2 * f;
    return array<f32, 4>(
        (-f + 2.0 * f2 - f3) / 2.0,
        (2.0 - 5.0 * f2 + 3.0 * f3) / 2.0,
        (f + 4.0 * f2 - 3.0 * f3) / 2.0,
        (-f2 + f3) / 2.0,
    );
}

// The line filter of cpu.rs `oriented_at`: the edge's normal from the weighted least-squares
// plane over the direction window, then a Gaussian of `along` pixels on the edge's line,
// Catmull-Rom interpolated across the four pixels around each step.
fn oriented_at(x: i32, y: i32, along: f32) -> f32 {
    let slope = depth_slope(x, y);
    let p = index(x, y);
    let sd = params.direction_sigma;
    let centre = image_in[p];
    let rd = i32(ceil(3.0 * sd));
    var w0 = 0.0;
    var wv = 0.0;
    var wd = vec2<f32>(0.0, 0.0);
    var wvd = vec2<f32>(0.0, 0.0);
    var wdd = vec3<f32>(0.0, 0.0, 0.0);
    for (var dy = -rd; dy <= rd; dy = dy + 1) {
        for (var dx = -rd; dx <= rd; dx = dx + 1) {
            if (!usable(x + dx, y + dy)) {
                continue;
            }
            let d = vec2<f32>(f32(dx), f32(dy));
            let q = index(x + dx, y + dy);
            let w = geometry_weight(p, q, slope, length(d)) * exp(-dot(d, d) / (2.0 * sd * sd));
            let v = image_in[q] - centre;
            w0 = w0 + w;
            wv = wv + w * v;
            wd = wd + w * d;
            wvd = wvd + w * v * d;
            wdd = wdd + w * vec3<f32>(d.x * d.x, d.x * d.y, d.y * d.y);
        }
    }
    let b = wvd - wv * wd / w0;
    if (length(b) <= params.directionless * w0) {
        return centre;
    }
    let c = wdd - vec3<f32>(wd.x * wd.x, wd.x * wd.y, wd.y * wd.y) / w0;
    let n = vec2<f32>(c.z * b.x - c.y * b.y, c.x * b.y - c.y * b.x);
    let norm = length(n);
    if (!(norm > 0.0)) {
        return centre;
    }
    let tangent = vec2<f32>(-n.y, n.x) / norm;
    let x_major = abs(tangent.x) >= abs(tangent.y);
    var minor_per_step = tangent.x / tangent.y;
    if (x_major) {
        minor_per_step = tangent.y / tangent.x;
    }
    let distance_per_step = sqrt(1.0 + minor_per_step * minor_per_step);
    let r = i32(ceil(3.0 * along));
    var sum = 0.0;
    var weight = 0.0;
    var lo = image_in[p];
    var hi = image_in[p];
    for (var k = -r; k <= r; k = k + 1) {
        let t = f32(k) * distance_per_step;
        let g = exp(-t * t / (2.0 * along * along));
        let offset = f32(k) * minor_per_step;
        let below = floor(offset);
        let f = offset - below;
        var whole = true;
        for (var j = 0; j < 4; j = j + 1) {
            let q = line_pixel(x, y, k, i32(below) + j - 1, x_major);
            whole = whole && usable(q.x, q.y);
        }
        var share = array<f32, 4>(0.0, 1.0 - f, f, 0.0);
        if (whole) {
            share = catmull_rom(f);
        }
        for (var j = 0; j < 4; j = j + 1) {
            let cell = line_pixel(x, y, k, i32(below) + j - 1, x_major);
            if (!usable(cell.x, cell.y)) {
                continue;
            }
            let q = index(cell.x, cell.y);
            let d = vec2<f32>(f32(cell.x - x), f32(cell.y - y));
            let v = image_in[q];
            let w = g * share[j] * geometry_weight(p, q, slope, length(d));
            sum = sum + w * v;
            weight = weight + w;
            lo = min(lo, v);
            hi = max(hi, v);
        }
    }
    if (weight < 0.5) {
        return centre;
    }
    return clamp(sum / weight, lo, hi);
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
    if (s < params.min_sigma) {
        image_out[p] = image_in[p];
        return;
    }
    image_out[p] = oriented_at(x, y, s);
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
