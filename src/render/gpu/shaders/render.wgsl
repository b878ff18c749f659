// The render plan's passes: `primary` (camera rays, closest hit), `shadow` (per light, one
// dispatch per chunk of its samples, any-hit with early exit; with `params.shadows` off the
// same kernel is the plan's `direct` pass: every target visible, no rays), `mirror_*`
// (Whitted's mirror chains, src/render/mirror.rs, split per bounce) and `ambient` (where the
// scene asks for ambient occlusion, one dispatch per chunk of its rays). Mirrors
// src/render/cpu.rs and src/render/shading.rs in f32, in coordinates re-based on the camera's
// look-at point so that large translations cost nothing. Shapes' structs and tests come from
// src/scene/shape/*.wgsl, mesh queries from the scene's acceleration structure (accel_closest,
// accel_any), which counts its nodes and primitive tests into `work_nodes` and `work_prims`.

struct Params {
    width: u32,
    height: u32,
    sphere_count: u32,
    plane_count: u32,
    light_count: u32,
    scheme: u32,
    shared_pattern: u32,
    seed: u32,
    cam_origin: vec3<f32>,
    ortho: u32,
    cam_right: vec3<f32>,
    half_x: f32,
    cam_up: vec3<f32>,
    half_y: f32,
    cam_forward: vec3<f32>,
    triangle_count: u32,
    ao_rays: u32,
    ao_mode: u32,
    ao_scheme: u32,
    ao_max_distance: f32,
    frame: u32,
    shadows: u32,
    mirror_depth: u32,
    stats: u32,
}

struct Light {
    center: vec3<f32>,
    radius: f32,
    normal: vec3<f32>,
    power: f32,
    u: vec3<f32>,
    kind: u32,
    v: vec3<f32>,
    samples: u32,
    shared_offset: u32,
    _p0: u32,
    _p1: u32,
    _p2: u32,
}

struct Hit {
    position: vec3<f32>,
    object: u32,
    normal: vec3<f32>,
    albedo: f32,
    triangle: u32,
    mirror: f32,
    _h1: u32,
    _h2: u32,
}

// What an acceleration structure's query returns (src/accel/mod.rs).
struct AccelHit {
    t: f32,
    triangle: u32,
}

struct PassInfo {
    light: u32,
    first_sample: u32,
    sample_count: u32,
    _p0: u32,
}

const LIGHT_POINT: u32 = 0u;

// Set when a loop ended before its own exit condition held (an adapter's loop-iteration cap) or
// a traversal dropped work because its stack was full: the invocation's answer is not to be
// trusted, and the kernel reports it in `counters[CUT_SHORT_SLOT]`.
var<private> cut_short: bool = false;
const NO_RECEIVER: f32 = -1.0;

// The invocation's work (src/accel/work.rs): queries asked of the scene, traversal steps and
// primitive tests; added to the counters once at the end of a kernel when `params.stats` is on.
var<private> work_queries: u32 = 0u;
var<private> work_nodes: u32 = 0u;
var<private> work_prims: u32 = 0u;
const AO_RAYS_SLOT: u32 = CUT_SHORT_SLOT + 1u;
const REFLECTION_RAYS_SLOT: u32 = CUT_SHORT_SLOT + 3u;
const QUERIES_SLOT: u32 = CUT_SHORT_SLOT + 5u;
const NODES_SLOT: u32 = CUT_SHORT_SLOT + 7u;
const PRIMS_SLOT: u32 = CUT_SHORT_SLOT + 9u;
const MIRROR_CUT_SLOT: u32 = CUT_SHORT_SLOT + 11u;
// Chains still live after a bounce's step (read and reset by `mirror_gate`), and the bounces
// that ran (mirror_gate.wgsl).
const MIRROR_LIVE_SLOT: u32 = CUT_SHORT_SLOT + 12u;
const MIRROR_BOUNCES_SLOT: u32 = CUT_SHORT_SLOT + 13u;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> spheres: array<Sphere>;
@group(0) @binding(2) var<storage, read> planes: array<Plane>;
@group(0) @binding(3) var<storage, read> lights: array<Light>;
@group(0) @binding(4) var<storage, read> shared_points: array<vec2<f32>>;
@group(0) @binding(5) var<storage, read_write> hits: array<Hit>;
@group(0) @binding(6) var<storage, read_write> visibility: array<f32>;
@group(0) @binding(7) var<storage, read_write> radiance: array<f32>;
@group(0) @binding(8) var<storage, read_write> counters: array<atomic<u32>>;
@group(0) @binding(9) var<storage, read> mesh_tris: array<MeshTri>;
@group(0) @binding(10) var<storage, read> ao_dirs: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> ambient_out: array<f32>;
@group(0) @binding(12) var<storage, read> scheme_tables: array<u32>;
// Per object id, its mirror weight (0 for every analytic shape).
@group(0) @binding(13) var<storage, read> mirrors: array<f32>;
// Per light and pixel, the running sum of a light's sample terms between its chunks.
@group(0) @binding(14) var<storage, read_write> light_sums: array<f32>;
@group(1) @binding(0) var<uniform> pass_info: PassInfo;

// Any-hit along origin -> origin + d, skipping the receiver's own sphere or plane (`skip`) or
// triangle (`skip_tri`); see shading::Receiver for why.
fn occluded(origin: vec3<f32>, d: vec3<f32>, skip: u32, skip_tri: u32) -> bool {
    let len = length(d);
    return blocked(origin, d / len, len, skip, skip_tri);
}

// Moves the invocation's node and test counts into the frame's 64-bit counters once either
// reaches 2^31, so that no private u32 wraps however many queries an invocation asks (each query
// counts fewer than 2^31). Called before every query.
fn keep_counts_narrow() {
    if (params.stats != 0u && max(work_nodes, work_prims) >= 0x80000000u) {
        add_wide(NODES_SLOT, work_nodes);
        add_wide(PRIMS_SLOT, work_prims);
        work_nodes = 0u;
        work_prims = 0u;
    }
}

// Any-hit along origin + t dir, 0 < t < len (len may be infinite), with the same skips.
fn blocked(origin: vec3<f32>, dir: vec3<f32>, len: f32, skip: u32, skip_tri: u32) -> bool {
    keep_counts_narrow();
    work_queries += 1u;
    var i = 0u;
    for (; i < params.sphere_count; i++) {
        work_prims += u32(spheres[i].object != skip);
        let r = sphere_roots(origin, dir, spheres[i].center, spheres[i].radius);
        if (spheres[i].object != skip && r.z > 0.0 && ((r.x > 0.0 && r.x < len) || (r.y > 0.0 && r.y < len))) {
            return true;
        }
    }
    var j = 0u;
    for (; j < params.plane_count; j++) {
        work_prims += u32(planes[j].object != skip);
        let t = plane_t(origin, dir, planes[j]);
        if (planes[j].object != skip && t > 0.0 && t < len) {
            return true;
        }
    }
    cut_short = cut_short || i < params.sphere_count || j < params.plane_count;
    return accel_any(origin, dir, len, skip_tri);
}

// Pixel `xy`'s camera ray: (origin, unit direction).
fn camera_ray(xy: vec2<u32>) -> array<vec3<f32>, 2> {
    let sx = (2.0 * (f32(xy.x) + 0.5) / f32(params.width) - 1.0) * params.half_x;
    let sy = (1.0 - 2.0 * (f32(xy.y) + 0.5) / f32(params.height)) * params.half_y;
    if (params.ortho != 0u) {
        return array<vec3<f32>, 2>(params.cam_origin + sx * params.cam_right + sy * params.cam_up, params.cam_forward);
    }
    return array<vec3<f32>, 2>(params.cam_origin, normalize(params.cam_forward + sx * params.cam_right + sy * params.cam_up));
}

// The closest surface along origin + t dir, t > 0, skipping triangle `skip_tri` (a secondary
// ray's own): cpu::closest_hit_skipping in f32. Analytic shapes by kind, equal distances going
// to the lower object id as on the CPU, then the accelerator within the distance found; the
// point re-projected onto analytic surfaces, the normal facing the ray.
fn closest(origin: vec3<f32>, dir: vec3<f32>, skip_tri: u32) -> Hit {
    keep_counts_narrow();
    work_queries += 1u;
    work_prims += params.sphere_count + params.plane_count;
    // `best` indexes spheres, then planes.
    var best_t = 3.4e38;
    var best = NO_HIT;
    var best_object = NO_HIT;
    for (var i = 0u; i < params.sphere_count; i++) {
        let r = sphere_roots(origin, dir, spheres[i].center, spheres[i].radius);
        let t = select(r.y, r.x, r.x > 0.0);
        if (r.z > 0.0 && t > 0.0 && (t < best_t || (t == best_t && spheres[i].object < best_object))) {
            best_t = t;
            best = i;
            best_object = spheres[i].object;
        }
    }
    for (var i = 0u; i < params.plane_count; i++) {
        let t = plane_t(origin, dir, planes[i]);
        if (t > 0.0 && (t < best_t || (t == best_t && planes[i].object < best_object))) {
            best_t = t;
            best = params.sphere_count + i;
            best_object = planes[i].object;
        }
    }
    let mesh_hit = accel_closest(origin, dir, best_t, skip_tri);
    var hit: Hit;
    hit.object = NO_HIT;
    hit.triangle = NO_HIT;
    hit.mirror = 0.0;
    if (mesh_hit.triangle != NO_HIT) {
        let tri = mesh_tris[mesh_hit.triangle];
        hit.object = tri.object;
        hit.position = origin + mesh_hit.t * dir;
        hit.normal = normalize(cross(tri.e1, tri.e2));
        hit.albedo = tri.albedo;
        hit.triangle = mesh_hit.triangle;
    } else if (best != NO_HIT) {
        let raw = origin + best_t * dir;
        if (best < params.sphere_count) {
            let s = spheres[best];
            let n = normalize(raw - s.center);
            hit.object = s.object;
            hit.position = s.center + n * s.radius;
            hit.normal = n;
            hit.albedo = s.albedo;
        } else {
            let pl = planes[best - params.sphere_count];
            hit.object = pl.object;
            hit.position = raw - pl.normal * dot(raw - pl.point, pl.normal);
            hit.normal = pl.normal;
            hit.albedo = pl.albedo;
        }
    }
    if (hit.object != NO_HIT) {
        hit.mirror = mirrors[hit.object];
        if (dot(hit.normal, dir) > 0.0) {
            hit.normal = -hit.normal;
        }
    }
    return hit;
}

// Adds `n` to the 64-bit counter at words (slot, slot + 1).
fn add_wide(slot: u32, n: u32) {
    if (n == 0u) {
        return;
    }
    let old = atomicAdd(&counters[slot], n);
    if (old + n < old) {
        atomicAdd(&counters[slot + 1u], 1u);
    }
}

// The end of every kernel: the invocation's work where the frame counts it, and whether a loop
// was cut short, counted at `cut_slot` (the mirror pass's trace has its own: a single walk past
// the cap is one no smaller chunk of samples can help).
fn finish_invocation(cut_slot: u32) {
    if (params.stats != 0u) {
        add_wide(QUERIES_SLOT, work_queries);
        add_wide(NODES_SLOT, work_nodes);
        add_wide(PRIMS_SLOT, work_prims);
    }
    if (cut_short) {
        atomicAdd(&counters[cut_slot], 1u);
    }
}

@compute @workgroup_size(8, 8)
fn primary(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    let ray = camera_ray(gid.xy);
    radiance[pixel] = 0.0;
    hits[pixel] = closest(ray[0], ray[1], NO_HIT);
    finish_invocation(CUT_SHORT_SLOT);
}

// What a receiver has gathered from one light so far: the visible targets, the running sum of
// their geometric terms (cos cos' / d^4 for a disk, cos / d^2 for a point) and the rays traced.
// The sum is one left fold over the samples in order, whichever dispatches they were split into,
// so a frame's bits do not depend on how an adapter's loop cap chunks a pass. The twin of
// shading::shade_light; with `params.shadows` off every target counts as visible and no ray is
// traced (OpenGL-like shading).
struct LightSample {
    visible: f32,
    sum: f32,
    rays: u32,
}

// `so_far` continued over the light's samples first .. first + count.
fn sample_light(li: u32, hit: Hit, first: u32, count: u32, xy: vec2<u32>, pixel: u32, so_far: LightSample) -> LightSample {
    let light = lights[li];
    let p = hit.position;
    let n = hit.normal;
    let origin = select(p, offset_origin(p, n), hit.triangle != NO_HIT);
    let shadows = params.shadows != 0u;
    var out = so_far;
    if (light.kind == LIGHT_POINT && first == 0u) {
        let d = light.center - p;
        if (dot(n, d) > 0.0) {
            out.rays = u32(shadows);
            if (!shadows || !occluded(origin, light.center - origin, hit.object, hit.triangle)) {
                out.visible = 1.0;
                out.sum = dot(n, normalize(d)) / dot(d, d);
            }
        }
    } else if (light.kind != LIGHT_POINT) {
        let tilt = sqrt(max(1.0 - dot(n, light.normal) * dot(n, light.normal), 0.0));
        let reachable = dot(light.normal, p - light.center) > 0.0 && dot(n, light.center - p) + light.radius * tilt > 0.0;
        if (reachable) {
            let stream = stream_pixel(params.seed, li, pixel);
            let last = first + min(count, light.samples - min(first, light.samples));
            var k = first;
            for (; k < last; k++) {
                var s: vec2<f32>;
                if (params.shared_pattern != 0u) {
                    s = shared_points[light.shared_offset + k];
                } else {
                    s = disk_point(params.scheme, light.samples, k, stream, xy, tile_seed(params.seed, li), params.frame);
                }
                let q = light.center + light.radius * (s.x * light.u + s.y * light.v);
                let d = q - p;
                if (dot(n, d) > 0.0 && dot(light.normal, d) < 0.0) {
                    out.rays += u32(shadows);
                    if (!shadows || !occluded(origin, q - origin, hit.object, hit.triangle)) {
                        out.visible += 1.0;
                        let d2 = dot(d, d);
                        out.sum += dot(n, d) * -dot(light.normal, d) / (d2 * d2);
                    }
                }
            }
            cut_short = cut_short || k < last;
        }
    }
    return out;
}

// (visibility, irradiance) of a light's gathered samples.
fn light_finish(li: u32, s: LightSample) -> vec2<f32> {
    let light = lights[li];
    if (light.kind == LIGHT_POINT) {
        return vec2<f32>(s.visible, light.power / (4.0 * PI) * s.sum);
    }
    return vec2<f32>(s.visible / f32(light.samples), light.power / (PI * f32(light.samples)) * s.sum);
}

@compute @workgroup_size(8, 8)
fn shadow(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    let li = pass_info.light;
    let out = li * params.width * params.height + pixel;
    let hit = hits[pixel];
    if (hit.object == NO_HIT) {
        visibility[out] = NO_RECEIVER;
        return;
    }
    // Chunks of one light's samples carry the visible count (in `visibility`) and the running
    // sum (in `light_sums`, cleared each frame) to the next; the last turns them into the
    // light's visibility and radiance, a mirror's diffuse part weighted by 1 - mirror.
    let first = pass_info.first_sample;
    let so_far = LightSample(visibility[out], light_sums[out], 0u);
    let s = sample_light(li, hit, first, pass_info.sample_count, gid.xy, pixel, so_far);
    let samples = lights[li].samples;
    if (pass_info.sample_count >= samples - min(first, samples)) {
        let f = light_finish(li, s);
        visibility[out] = f.x;
        radiance[pixel] += (1.0 - hit.mirror) * hit.albedo / PI * f.y;
    } else {
        visibility[out] = s.visible;
        light_sums[out] = s.sum;
    }
    add_wide(2u * li, s.rays);
    finish_invocation(CUT_SHORT_SLOT);
}

// Whitted's mirror chains (src/render/mirror.rs in f32), split so that no invocation runs more
// than one query's walk or one chunk of a light's samples: per bounce, `mirror_trace` follows
// each pixel's reflected ray to its closest hit, `mirror_shade` shades that vertex from every
// light, chunk by chunk as the shadow pass does (shadow rays where the scene has shadows), and
// `mirror_step` folds it into the chain and turns the ray; `mirror_finish` adds what the chain
// brought back. Radiance leaving a vertex is (1 - m) x diffuse + m x reflected; a chain cut at
// the depth limit or leaving the scene brings back nothing more. The chain lives in `chains`
// between the dispatches; `pass_info.first_sample` is the bounce. `mirror_step` counts the
// chains still live, and between bounces `mirror_gate` (mirror_gate.wgsl) turns that count into
// the next bounce's workgroups: none once every chain has ended.
const CHAIN_NONE: u32 = 0u;
const CHAIN_LIVE: u32 = 1u;
const CHAIN_ENDED: u32 = 2u;

// One pixel's mirror chain between the mirror pass's dispatches.
struct Chain {
    // The chain's last vertex: the receiver, then each reflected ray's closest hit, which the
    // trace writes over the vertex it left (its origin and normal are spent by then).
    at: Hit,
    dir: vec3<f32>,
    weight: f32,
    reflected: f32,
    // `at`'s irradiance over the lights shaded so far, and the light being shaded's samples
    // gathered so far (its chunks' carry, as `light_sums` is the shadow pass's).
    irradiance: f32,
    visible: f32,
    sum: f32,
    state: u32,
    _c0: u32,
    _c1: u32,
    _c2: u32,
}

@group(0) @binding(15) var<storage, read_write> chains: array<Chain>;

@compute @workgroup_size(8, 8)
fn mirror_trace(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    var c: Chain;
    if (pass_info.first_sample == 0u) {
        c.at = hits[pixel];
        c.reflected = 0.0;
        c.state = CHAIN_NONE;
        if (c.at.object != NO_HIT && c.at.mirror != 0.0) {
            c.state = CHAIN_LIVE;
            c.weight = c.at.mirror;
            c.dir = normalize(reflect(camera_ray(gid.xy)[1], c.at.normal));
        }
    } else {
        c = chains[pixel];
    }
    if (c.state == CHAIN_LIVE) {
        let origin = select(c.at.position, offset_origin(c.at.position, c.at.normal), c.at.triangle != NO_HIT);
        c.at = closest(origin, c.dir, c.at.triangle);
        if (c.at.object == NO_HIT) {
            c.state = CHAIN_ENDED;
        }
        c.irradiance = 0.0;
        c.visible = 0.0;
        c.sum = 0.0;
        add_wide(REFLECTION_RAYS_SLOT, 1u);
    }
    chains[pixel] = c;
    // A closest-hit walk past the loop cap cannot be split further: its own slot.
    finish_invocation(MIRROR_CUT_SLOT);
}

@compute @workgroup_size(8, 8)
fn mirror_shade(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    let li = pass_info.light;
    let c = chains[pixel];
    if (li >= params.light_count || c.state != CHAIN_LIVE || c.at.mirror >= 1.0) {
        return;
    }
    let first = pass_info.first_sample;
    let s = sample_light(li, c.at, first, pass_info.sample_count, gid.xy, pixel, LightSample(c.visible, c.sum, 0u));
    let samples = lights[li].samples;
    if (pass_info.sample_count >= samples - min(first, samples)) {
        chains[pixel].irradiance = c.irradiance + light_finish(li, s).y;
        chains[pixel].visible = 0.0;
        chains[pixel].sum = 0.0;
    } else {
        chains[pixel].visible = s.visible;
        chains[pixel].sum = s.sum;
    }
    add_wide(2u * li, s.rays);
    finish_invocation(CUT_SHORT_SLOT);
}

// The chain ends where a vertex is no mirror at all (weight 0 on the host, as on the CPU), not
// where the f32 product of weights underflows.
@compute @workgroup_size(8, 8)
fn mirror_step(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    var c = chains[pixel];
    if (c.state != CHAIN_LIVE) {
        return;
    }
    if (c.at.mirror < 1.0) {
        c.reflected += c.weight * (1.0 - c.at.mirror) * c.at.albedo / PI * c.irradiance;
    }
    c.weight *= c.at.mirror;
    c.dir = normalize(reflect(c.dir, c.at.normal));
    if (c.at.mirror == 0.0) {
        c.state = CHAIN_ENDED;
    } else {
        atomicAdd(&counters[MIRROR_LIVE_SLOT], 1u);
    }
    chains[pixel] = c;
}

@compute @workgroup_size(8, 8)
fn mirror_finish(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    if (chains[pixel].state != CHAIN_NONE) {
        radiance[pixel] += chains[pixel].reflected;
    }
}

// Ambient occlusion (src/render/ambient.rs in f32): rays `first_sample ..` of the pass's chunk
// into the hemisphere of each receiver, any-hit up to `ao_max_distance`. Chunks accumulate
// (unoccluded weight, total weight) per pixel; the host divides.
const AO_GRID_PLAIN: u32 = 1u;
const AO_GRID_COSINE: u32 = 2u;
const AO_DISK_PLAIN: u32 = 3u;
const AMBIENT_STREAM: u32 = 0x414fu;

// An orthonormal (t, b) completing unit n (Duff et al. 2017), as tangent_basis in ambient.rs.
fn tangent_basis(n: vec3<f32>) -> mat2x3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return mat2x3<f32>(
        vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        vec3<f32>(b, sign + n.y * n.y * a, -n.y),
    );
}

@compute @workgroup_size(8, 8)
fn ambient(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    let hit = hits[pixel];
    if (hit.object == NO_HIT) {
        return;
    }
    let p = hit.position;
    let n = hit.normal;
    let origin = select(p, offset_origin(p, n), hit.triangle != NO_HIT);
    let tb = tangent_basis(n);
    let stream = stream_pixel(params.seed, AMBIENT_STREAM, pixel);
    let grid = params.ao_mode == AO_GRID_PLAIN || params.ao_mode == AO_GRID_COSINE;
    // Chunks of the pass continue one running (unoccluded, total) sum, so the image's bits do
    // not depend on how the rays were split into dispatches.
    var seen = ambient_out[2u * pixel];
    var total = ambient_out[2u * pixel + 1u];
    let first = pass_info.first_sample;
    let last = min(first + pass_info.sample_count, params.ao_rays);
    var k = first;
    for (; k < last; k++) {
        var d: vec3<f32>;
        var w = 1.0;
        if (grid) {
            let l = ao_dirs[k].xyz;
            let c = dot(l, n);
            d = select(l, -l, c < 0.0);
            if (params.ao_mode == AO_GRID_COSINE) {
                w = abs(c);
            }
        } else {
            var s: vec2<f32>;
            if (params.shared_pattern != 0u) {
                s = ao_dirs[k].xy;
            } else {
                s = disk_point(params.ao_scheme, params.ao_rays, k, stream, gid.xy, tile_seed(params.seed, AMBIENT_STREAM), params.frame);
            }
            let r2 = min(dot(s, s), 1.0);
            var l: vec3<f32>;
            if (params.ao_mode == AO_DISK_PLAIN) {
                let q = sqrt(2.0 - r2);
                l = vec3<f32>(s.x * q, s.y * q, 1.0 - r2);
            } else {
                l = vec3<f32>(s.x, s.y, sqrt(1.0 - r2));
            }
            d = tb[0] * l.x + tb[1] * l.y + n * l.z;
        }
        total += w;
        if (!blocked(origin, d, params.ao_max_distance, hit.object, hit.triangle)) {
            seen += w;
        }
    }
    cut_short = cut_short || k < last;
    ambient_out[2u * pixel] = seen;
    ambient_out[2u * pixel + 1u] = total;
    add_wide(AO_RAYS_SLOT, select(0u, last - first, last > first));
    finish_invocation(CUT_SHORT_SLOT);
}
