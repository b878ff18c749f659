// Visibility-field traversal (accel/vlf; paper Sections 3.3-5), the twin of query.rs over the
// buffers gpu.rs lays out: the nearest stored line from the lookup table, the segment clipped
// to the scene's ball and moved into that direction's tile space, the tiles it touches walked
// front to back (columns along the major axis, rows within each), and in each tile the leaves
// between its entry and exit depth visited linearly, each triangle tested once (bsp.rs,
// LeafBounds: after the first leaf, only the triangles that start there walking up, or end
// there walking down). One walk serves both queries: any-hit stops at the first hit, closest-hit
// where no later tile or leaf can hold a nearer one. Bounds are widened well beyond f32
// rounding, so the candidates hold every triangle `triangle_t` hits; ties in t go to the lower
// triangle index.

@group(2) @binding(0) var<storage, read> vlf_tris: array<AccelTri>;
@group(2) @binding(1) var<storage, read> vlf_head: array<u32>;
@group(2) @binding(2) var<storage, read> vlf_table: array<u32>;
@group(2) @binding(3) var<storage, read> vlf_tile_first: array<u32>;
@group(2) @binding(4) var<storage, read> vlf_ids0: array<u32>;
@group(2) @binding(5) var<storage, read> vlf_ids1: array<u32>;
@group(2) @binding(6) var<storage, read> vlf_ids2: array<u32>;
@group(2) @binding(7) var<storage, read> vlf_ids3: array<u32>;
@group(2) @binding(8) var<storage, read> vlf_overlay_ids: array<u32>;

const VLF_SPLIT: u32 = 0x80000000u;
// Header words (gpu.rs writes them).
const VLF_H_CENTRE: u32 = 0u;
const VLF_H_RADIUS: u32 = 3u;
const VLF_H_HALF_TILES: u32 = 4u;
const VLF_H_TILES: u32 = 5u;
const VLF_H_DEPTH: u32 = 6u;
const VLF_H_MEDIAN: u32 = 7u;
const VLF_H_SIDE: u32 = 8u;
const VLF_H_LAYERS: u32 = 9u;
const VLF_H_OVERLAY_TILES: u32 = 10u;
const VLF_H_EPS_TILE: u32 = 11u;
const VLF_H_EPS_Z: u32 = 12u;
const VLF_H_CHUNK_START: u32 = 13u;
const VLF_H_DIRS: u32 = 17u;
// Bit 0: the base layer's entries go in three-word pairs (two ids, both boxes); bit 1: the overlay's.
const VLF_H_WIDE: u32 = 18u;
const VLF_H_ROWS: u32 = 19u;

fn vlf_f(i: u32) -> f32 {
    return bitcast<f32>(vlf_head[i]);
}

fn vlf_vec(i: u32) -> vec3<f32> {
    return vec3<f32>(vlf_f(i), vlf_f(i + 1u), vlf_f(i + 2u));
}

// Where a tile's words live: layer 0's chunk of the ray's direction, or the overlay.
struct VlfIds {
    layer: u32,
    chunk: u32,
}

fn vlf_word(at: VlfIds, i: u32) -> u32 {
    if (at.layer == 1u) {
        return vlf_overlay_ids[i];
    }
    switch at.chunk {
        case 0u: {
            return vlf_ids0[i];
        }
        case 1u: {
            return vlf_ids1[i];
        }
        case 2u: {
            return vlf_ids2[i];
        }
        default: {
            return vlf_ids3[i];
        }
    }
}

// A ray in one direction's tile space: x, y in tiles, z in ball radii, per unit of t; the
// segment [t0, t1] inside the ball (empty when t0 > t1); the widening in tiles and in ball
// radii (the structure's own plus the f32 rounding of this ray's origin).
struct VlfRay {
    k: u32,
    o: vec3<f32>,
    d: vec3<f32>,
    t0: f32,
    t1: f32,
    e_tile: f32,
    e_z: f32,
}

fn vlf_ray(o: vec3<f32>, d: vec3<f32>, tmax: f32) -> VlfRay {
    let radius = vlf_f(VLF_H_RADIUS);
    let oc = o - vlf_vec(VLF_H_CENTRE);
    let b = dot(d, oc);
    let r = radius * 1.001;
    // r^2 less the squared distance from the centre to the line (not b^2 - (|oc|^2 - r^2),
    // which cancels in f32 once the origin is a few hundred radii away).
    let f = oc - b * d;
    let disc = r * r - dot(f, f);
    var ray = VlfRay(0u, vec3<f32>(0.0), vec3<f32>(0.0), 1.0, 0.0, 0.0, 0.0);
    if (!(disc >= 0.0)) {
        return ray;
    }
    let sq = sqrt(disc);
    ray.t0 = max(-b - sq, 0.0);
    ray.t1 = min(-b + sq, tmax);
    // The octahedral projection of d, folded into the upper hemisphere, picks a table cell.
    let side = vlf_head[VLF_H_SIDE];
    let half = f32(side) * 0.5;
    let flip = select(1.0, -1.0, d.z < 0.0);
    let s = abs(d.x) + abs(d.y) + abs(d.z);
    let cx = u32(clamp((d.x * flip / s + 1.0) * half, 0.0, f32(side - 1u)));
    let cy = u32(clamp((d.y * flip / s + 1.0) * half, 0.0, f32(side - 1u)));
    ray.k = vlf_table[cy * side + cx];
    let rows = VLF_H_ROWS + 9u * ray.k;
    let a = vlf_vec(rows);
    let bb = vlf_vec(rows + 3u);
    let w = vlf_vec(rows + 6u);
    let ht = vlf_f(VLF_H_HALF_TILES);
    let sc = ht / radius;
    ray.o = vec3<f32>(dot(a, oc) * sc + ht, dot(bb, oc) * sc + ht, dot(w, oc) / radius);
    ray.d = vec3<f32>(dot(a, d) * sc, dot(bb, d) * sc, dot(w, d) / radius);
    let rounding = 1e-6 * length(oc) / radius;
    ray.e_z = vlf_f(VLF_H_EPS_Z) + rounding;
    ray.e_tile = vlf_f(VLF_H_EPS_TILE) + rounding * ht;
    return ray;
}

// The t range over which the ray's tile coordinate (origin po, slope pd) lies in the widened
// cell [c - e, c + 1 + e], within [ta, tb].
fn vlf_slab(c: u32, po: f32, pd: f32, ta: f32, tb: f32, e: f32) -> vec2<f32> {
    if (pd == 0.0) {
        return vec2<f32>(ta, tb);
    }
    let a = (f32(c) - e - po) / pd;
    let b = (f32(c) + 1.0 + e - po) / pd;
    return vec2<f32>(max(ta, min(a, b)), min(tb, max(a, b)));
}

fn vlf_cell(v: f32) -> u32 {
    return u32(clamp(floor(v), 0.0, f32(vlf_head[VLF_H_TILES] - 1u)));
}

// Entries a..b of a leaf, counted from the tile's first entry at word h: a word `id | box << 16`
// each, or when wide pairs of three words (`id0`, `id1`, boxes; layer.rs); an id of all ones
// (in its 16 or 32 bits) is a removed triangle.
struct VlfLeaf {
    h: u32,
    a: u32,
    b: u32,
    wide: bool,
}

fn vlf_leaf(at: VlfIds, leaf: VlfLeaf, o: vec3<f32>, d: vec3<f32>, skip: u32, best_in: AccelHit, any: bool) -> AccelHit {
    var best = best_in;
    let mask = select(0xffffu, 0xffffffffu, leaf.wide);
    var i = leaf.a;
    for (; i < leaf.b && !(any && best.triangle != NO_HIT); i++) {
        let id = vlf_word(at, leaf.h + select(i, 3u * (i >> 1u) + (i & 1u), leaf.wide)) & mask;
        if (id == mask || id == skip) {
            continue;
        }
        work_prims += 1u;
        let tri = vlf_tris[id];
        let t = triangle_t(o, d, tri.v0, tri.e1, tri.e2);
        if (t > 0.0 && (t < best.t || (t == best.t && id < best.triangle && best.triangle != NO_HIT))) {
            best = AccelHit(t, id);
        }
    }
    cut_short = cut_short || (i < leaf.b && !(any && best.triangle != NO_HIT));
    return best;
}

// Leaf of depth z in the split whose values start at word `v` (uniform slabs: one multiply;
// median: the planes at or below z, by binary search).
fn vlf_leaf_of(at: VlfIds, z: f32, v: u32, leaves: u32) -> u32 {
    if (vlf_head[VLF_H_MEDIAN] == 0u) {
        let z0 = bitcast<f32>(vlf_word(at, v));
        let scale = bitcast<f32>(vlf_word(at, v + 1u));
        return u32(clamp((z - z0) * scale, 0.0, f32(leaves - 1u)));
    }
    var lo = 0u;
    var hi = leaves - 1u;
    var steps = 0u;
    for (; lo < hi && steps < 32u; steps++) {
        let mid = (lo + hi) / 2u;
        if (bitcast<f32>(vlf_word(at, v + mid)) <= z) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    cut_short = cut_short || lo < hi;
    return lo;
}

// Depth of the plane between leaf l and the next one walking up (l + 1) or down (l - 1),
// moved by e towards leaf l: no hit in a later leaf lies before it.
fn vlf_leaf_exit(at: VlfIds, l: u32, up: bool, v: u32, e: f32) -> f32 {
    if (vlf_head[VLF_H_MEDIAN] == 0u) {
        let z0 = bitcast<f32>(vlf_word(at, v));
        let scale = bitcast<f32>(vlf_word(at, v + 1u));
        return select(z0 + f32(l) / scale + e, z0 + f32(l + 1u) / scale - e, up);
    }
    return select(bitcast<f32>(vlf_word(at, v + l - 1u)) + e, bitcast<f32>(vlf_word(at, v + l)) - e, up);
}

// One tile of one layer over the ray's [ta, tb].
fn vlf_tile(layer: u32, ray: VlfRay, tile: u32, ta: f32, tb: f32, o: vec3<f32>, d: vec3<f32>, skip: u32, best_in: AccelHit, any: bool) -> AccelHit {
    work_nodes += 1u;
    let n = vlf_head[VLF_H_TILES];
    let dirs = vlf_head[VLF_H_DIRS];
    let chunk = select(vlf_head[VLF_H_ROWS + 9u * dirs + ray.k], 0u, layer == 1u);
    let at = VlfIds(layer, chunk);
    let rebase = select(vlf_head[VLF_H_CHUNK_START + chunk], 0u, layer == 1u);
    let k = select(0u, vlf_head[VLF_H_OVERLAY_TILES], layer == 1u) + ray.k * n * n + tile;
    let first = vlf_tile_first[k];
    let start = (first & ~VLF_SPLIT) - rebase;
    let end = (vlf_tile_first[k + 1u] & ~VLF_SPLIT) - rebase;
    let wide = ((vlf_head[VLF_H_WIDE] >> layer) & 1u) == 1u;
    if ((first & VLF_SPLIT) == 0u) {
        let entries = select(end - start, 2u * ((end - start) / 3u), wide);
        // An empty tile is no leaf visited, as the CPU's walk counts it.
        work_nodes += u32(end > start);
        return vlf_leaf(at, VlfLeaf(start, 0u, entries, wide), o, d, skip, best_in, any);
    }
    var best = best_in;
    let depth = vlf_head[VLF_H_DEPTH];
    let leaves = 1u << depth;
    let stride = select(leaves - 1u, 2u, vlf_head[VLF_H_MEDIAN] == 0u);
    let bounds = start + stride;
    let h = bounds + 2u * leaves;
    let e = ray.e_z;
    let za = ray.o.z + ray.d.z * ta;
    let zb = ray.o.z + ray.d.z * tb;
    let l0 = vlf_leaf_of(at, min(za, zb) - e, start, leaves);
    let l1 = vlf_leaf_of(at, max(za, zb) + e, start, leaves);
    let up = ray.d.z >= 0.0;
    var i = 0u;
    var done = false;
    for (; i <= l1 - l0 && !done; i++) {
        let l = select(l1 - i, l0 + i, up);
        // The leaf's group bounds (bsp.rs, LeafBounds): all of the first leaf visited, then
        // only the triangles starting here walking up, ending here walking down.
        let w0 = vlf_word(at, bounds + 2u * l);
        let w1 = vlf_word(at, bounds + 2u * l + 1u);
        var a = select(vlf_word(at, bounds + 2u * l - 1u) >> 16u, 0u, l == 0u);
        var b = w1 >> 16u;
        if (i > 0u && up) {
            b = w0 >> 16u;
        } else if (i > 0u) {
            a = w0 & 0xffffu;
            b = w1 & 0xffffu;
        }
        work_nodes += 1u;
        best = vlf_leaf(at, VlfLeaf(h, a, b, wide), o, d, skip, best, any);
        if (best.triangle != NO_HIT && l != select(l0, l1, up)) {
            // Closest hit: later leaves only hold hits beyond this leaf's exit plane.
            let exit = (vlf_leaf_exit(at, l, up, start, e) - ray.o.z) / ray.d.z;
            done = any || (abs(ray.d.z) > 0.0 && best.t < exit);
        }
        done = done || (any && best.triangle != NO_HIT);
    }
    cut_short = cut_short || (i <= l1 - l0 && !done);
    return best;
}

// The walk both queries share: tiles front to back, each layer's part of each tile.
fn vlf_query(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32, any: bool) -> AccelHit {
    var best = AccelHit(tmax, NO_HIT);
    let ray = vlf_ray(o, d, tmax);
    if (!(ray.t0 <= ray.t1)) {
        return best;
    }
    let e = ray.e_tile;
    let n = vlf_head[VLF_H_TILES];
    let layers = vlf_head[VLF_H_LAYERS];
    let xa = ray.o.x + ray.d.x * ray.t0;
    let xb = ray.o.x + ray.d.x * ray.t1;
    let ya = ray.o.y + ray.d.y * ray.t0;
    let yb = ray.o.y + ray.d.y * ray.t1;
    let swap = abs(ray.d.y) > abs(ray.d.x);
    let mo = select(ray.o.x, ray.o.y, swap);
    let md = select(ray.d.x, ray.d.y, swap);
    let so = select(ray.o.y, ray.o.x, swap);
    let sd = select(ray.d.y, ray.d.x, swap);
    let c0 = select(vlf_cell(min(xa, xb) - e), vlf_cell(min(ya, yb) - e), swap);
    let c1 = select(vlf_cell(max(xa, xb) + e), vlf_cell(max(ya, yb) + e), swap);
    var done = false;
    var ci = 0u;
    for (; ci <= c1 - c0 && !done; ci++) {
        let c = select(c1 - ci, c0 + ci, md >= 0.0);
        let tc = vlf_slab(c, mo, md, ray.t0, ray.t1, e);
        if (tc.x > tc.y) {
            continue;
        }
        // Columns are entered in increasing t: none beyond the best hit can improve on it.
        done = tc.x > best.t;
        let sa = so + sd * tc.x;
        let sb = so + sd * tc.y;
        let r0 = vlf_cell(min(sa, sb) - e);
        let r1 = vlf_cell(max(sa, sb) + e);
        var ri = 0u;
        for (; ri <= r1 - r0 && !done; ri++) {
            let r = select(r1 - ri, r0 + ri, sd >= 0.0);
            let tr = vlf_slab(r, so, sd, tc.x, tc.y, e);
            if (tr.x > tr.y || tr.x > best.t) {
                continue;
            }
            let tile = select(r * n + c, c * n + r, swap);
            var layer = 0u;
            for (; layer < layers; layer++) {
                best = vlf_tile(layer, ray, tile, tr.x, tr.y, o, d, skip, best, any);
            }
            cut_short = cut_short || layer < layers;
            done = any && best.triangle != NO_HIT;
        }
        cut_short = cut_short || (ri <= r1 - r0 && !done);
    }
    cut_short = cut_short || (ci <= c1 - c0 && !done);
    return best;
}

fn accel_closest(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> AccelHit {
    return vlf_query(o, d, tmax, skip, false);
}

fn accel_any(o: vec3<f32>, d: vec3<f32>, tmax: f32, skip: u32) -> bool {
    return vlf_query(o, d, tmax, skip, true).triangle != NO_HIT;
}
