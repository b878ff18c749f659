// Disk sampling schemes and counter-based random numbers: the WGSL twin of src/sampling/.
// Every function here must return, bit for bit in its integer part, what the Rust one does.

// The SCHEME_* ids and the table layout's constants (PMJ02_POINTS, BLUE_TILE, TABLE_COUNTS,
// POINTS_HEADER, STBN_HEADER, STBN_SIDE, STBN_DEPTH) are generated from the Rust side (gpu::scheme_prelude, sampling::tables) and
// prepended; the tables themselves are `scheme_tables` (render.wgsl's binding, sampling::tables::pack).

const TAU: f32 = 6.283185307179586;
const PI: f32 = 3.141592653589793;
const GOLDEN_TURN: u32 = 0x61c88647u;

fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn stream_pixel(seed: u32, light: u32, pixel: u32) -> u32 {
    let base = pcg(seed ^ pcg(light + 0x68e31da4u));
    return pcg(base ^ pcg(pixel + 0x1b56c4e9u));
}

// A key re-keyed for frame `frame` of a temporal sequence: unchanged at frame 0 (rng::at_frame).
fn at_frame(key: u32, frame: u32) -> u32 {
    if (frame == 0u) {
        return key;
    }
    return pcg(key ^ pcg(frame + 0x2545f491u));
}

fn stream_u32(stream: u32, index: u32) -> u32 {
    return pcg(stream ^ pcg(index + 0x9e3779b9u));
}

fn to_unit(x: u32) -> f32 {
    return f32(x >> 8u) * (1.0 / 16777216.0);
}

fn stream_unit(stream: u32, index: u32) -> f32 {
    return to_unit(stream_u32(stream, index));
}

fn polar(r: f32, theta: f32) -> vec2<f32> {
    return vec2<f32>(r * cos(theta), r * sin(theta));
}

fn concentric(u: f32, v: f32) -> vec2<f32> {
    let a = 2.0 * u - 1.0;
    let b = 2.0 * v - 1.0;
    if (a == 0.0 && b == 0.0) {
        return vec2<f32>(0.0);
    }
    if (abs(a) > abs(b)) {
        return polar(a, 0.25 * PI * (b / a));
    }
    return polar(b, 0.5 * PI - 0.25 * PI * (a / b));
}

// floor(sqrt(n)) exactly, digit by digit (sampling::isqrt): a float sqrt may land an ULP low.
fn isqrt(n: u32) -> u32 {
    var rest = n;
    var root = 0u;
    var bit = 1u << 30u;
    while (bit > n) {
        bit = bit >> 2u;
    }
    while (bit != 0u) {
        if (rest >= root + bit) {
            rest = rest - (root + bit);
            root = (root >> 1u) + bit;
        } else {
            root = root >> 1u;
        }
        bit = bit >> 2u;
    }
    return root;
}

fn strata_rows(n: u32) -> u32 {
    var rows = isqrt(n);
    while (rows > 1u && n % rows != 0u) {
        rows = rows - 1u;
    }
    return max(rows, 1u);
}

fn sobol_dim1(index_in: u32) -> u32 {
    var index = index_in;
    var v = 1u << 31u;
    var x = 0u;
    while (index != 0u) {
        if ((index & 1u) != 0u) {
            x = x ^ v;
        }
        index = index >> 1u;
        v = v ^ (v >> 1u);
    }
    return x;
}

fn laine_karras(x_in: u32, seed: u32) -> u32 {
    var x = x_in;
    x = x ^ (x * 0x3d20adeau);
    x = x + seed;
    x = x * ((seed >> 16u) | 1u);
    x = x ^ (x * 0x05526c56u);
    x = x ^ (x * 0x53a22864u);
    return x;
}

fn owen_scramble(x: u32, seed: u32) -> u32 {
    return reverseBits(laine_karras(reverseBits(x), seed));
}

fn scrambled_sobol_2d(index: u32, seed: u32) -> vec2<u32> {
    let shuffled = owen_scramble(index, pcg(seed ^ 0xa511e9b3u));
    let x = owen_scramble(reverseBits(shuffled), pcg(seed ^ 0x63d83595u));
    let y = owen_scramble(sobol_dim1(shuffled), pcg(seed ^ 0x2c1b3c6du));
    return vec2<u32>(x, y);
}

// The pmj02 sequence's point k under a pixel's digital shift (sampling::pmj02::point).
fn pmj02_point(k: u32, shift: vec2<u32>) -> vec2<f32> {
    let at = scheme_tables[0] + 2u * (k % PMJ02_POINTS);
    let x = (scheme_tables[at] ^ shift.x) << 8u;
    let y = (scheme_tables[at + 1u] ^ shift.y) << 8u;
    return vec2<f32>(to_unit(x), to_unit(y));
}

// The seed of a light's tile shift (bluenoise::tile_seed).
fn tile_seed(seed: u32, light: u32) -> u32 {
    return seed ^ (light * 0x9e3779b9u);
}

// A pixel's place in a tile of `side` pixels, shifted by its tile seed (bluenoise::tile_index_in).
fn tile_index_in(pixel: vec2<u32>, tile_seed: u32, side: u32) -> u32 {
    let shift = pcg(tile_seed ^ 0x7ab1e5edu);
    let sx = shift % side;
    let sy = (shift >> 16u) % side;
    return ((pixel.y % side + sy) % side) * side + (pixel.x % side + sx) % side;
}

// A pixel's place in the blue-noise tile (bluenoise::tile_index).
fn tile_index(pixel: vec2<u32>, tile_seed: u32) -> u32 {
    return tile_index_in(pixel, tile_seed, BLUE_TILE);
}

// The tile seed's shared Cranley-Patterson shift, 24-bit (bluenoise::cp_shift).
fn cp_shift(tile_seed: u32) -> vec2<u32> {
    return vec2<u32>(pcg(tile_seed ^ 0x0c9a5e01u) >> 8u, pcg(tile_seed ^ 0x5b1d93c7u) >> 8u);
}

// The 2-D Kronecker (R2) steps a pixel's offset takes per frame, 24-bit (bluenoise::R2_STEP).
const R2_STEP: vec2<u32> = vec2<u32>(12664746u, 9560334u);

// A pixel's Cranley-Patterson offset in frame `frame`: the two masks' values plus the tile
// seed's shared shift plus `frame` R2 steps, 24-bit (bluenoise::offset_at).
fn bluenoise_offset(pixel: vec2<u32>, tile_seed: u32, frame: u32) -> vec2<u32> {
    let i = tile_index(pixel, tile_seed);
    let m = scheme_tables[1];
    let mask = vec2<u32>(scheme_tables[m + i], scheme_tables[m + BLUE_TILE * BLUE_TILE + i]);
    let o = (mask + cp_shift(tile_seed)) & vec2<u32>(0x00ffffffu);
    return (o + frame * R2_STEP) & vec2<u32>(0x00ffffffu);
}

// The STBN slice that frame 0 reads under a tile seed (stbn::time_shift).
fn stbn_time_shift(tile_seed: u32) -> u32 {
    return pcg(tile_seed ^ 0x7e3a9f01u) % STBN_DEPTH;
}

// A pixel's Cranley-Patterson offset in frame `frame` from the spatiotemporal blue-noise masks,
// 24-bit (stbn::offset): their values at the pixel's place in the stack (the tile shifted by the
// tile seed in x and y and by stbn_time_shift in t; frames wrap modulo STBN_DEPTH, u32 addition
// wrapping as the Rust side's) plus the tile seed's shared shift. The masks lie at the offset in
// the header's STBN_HEADER word, x's stack then y's (sampling::tables::pack).
fn stbn_offset(pixel: vec2<u32>, tile_seed: u32, frame: u32) -> vec2<u32> {
    let t = (frame + stbn_time_shift(tile_seed)) % STBN_DEPTH;
    let i = t * STBN_SIDE * STBN_SIDE + tile_index_in(pixel, tile_seed, STBN_SIDE);
    let m = scheme_tables[STBN_HEADER];
    let mask = vec2<u32>(scheme_tables[m + i], scheme_tables[m + STBN_SIDE * STBN_SIDE * STBN_DEPTH + i]);
    return (mask + cp_shift(tile_seed)) & vec2<u32>(0x00ffffffu);
}

// Point k of the shared (0,2) set (unscrambled Sobol', 24-bit) rotated by the 24-bit offset `o`
// modulo 1, through the concentric map: bluenoise-cp's and stbn-cp's sample.
fn rotated_02(k: u32, o: vec2<u32>) -> vec2<f32> {
    let sx = reverseBits(k) >> 8u;
    let sy = sobol_dim1(k) >> 8u;
    let u = to_unit(((sx + o.x) & 0x00ffffffu) << 8u);
    let v = to_unit(((sy + o.y) & 0x00ffffffu) << 8u);
    return concentric(u, v);
}

// Where the scramble table serving n rays starts in scheme_tables, or 0 (the header's place,
// never a table's) when the frame carries none: the table fitted for the power of two at or
// above n (bluenoise::table_rays).
fn bluenoise_table(n: u32) -> u32 {
    var rays = 1u;
    while (rays < n) {
        rays = rays * 2u;
    }
    for (var d = 0u; d < min(scheme_tables[2], TABLE_COUNTS); d = d + 1u) {
        if (scheme_tables[3u + 2u * d] == rays) {
            return scheme_tables[4u + 2u * d];
        }
    }
    return 0u;
}

// Sample k of a points file's set for the pixel at `pixel` (sampling::points::PointSet::point):
// its header at POINTS_HEADER holds the data's offset, the layout (0 shared, 1 tile, 2 mask),
// the points per pixel, the tile's side, the domain (0 square, 1 disk) and the mask's offset.
fn points_point(k: u32, pixel: vec2<u32>, tile_seed: u32) -> vec2<f32> {
    let base = scheme_tables[POINTS_HEADER];
    if (base == 0u) {
        // No set packed (sampling::tables::pack packs the frame's): NaN, never stray numbers.
        return vec2<f32>(bitcast<f32>(0x7fc00000u));
    }
    let arrangement = scheme_tables[POINTS_HEADER + 1u];
    let count = scheme_tables[POINTS_HEADER + 2u];
    let side = max(scheme_tables[POINTS_HEADER + 3u], 1u);
    var at = base + 2u * k;
    if (arrangement == 1u) {
        at = base + 2u * (tile_index_in(pixel, tile_seed, side) * count + k);
    }
    var q = vec2<u32>(scheme_tables[at], scheme_tables[at + 1u]);
    if (arrangement == 2u) {
        let m = scheme_tables[POINTS_HEADER + 5u] + 2u * tile_index_in(pixel, tile_seed, side);
        let offset = vec2<u32>(scheme_tables[m], scheme_tables[m + 1u]);
        q = (q + offset + cp_shift(tile_seed)) & vec2<u32>(0x00ffffffu);
    }
    if (scheme_tables[POINTS_HEADER + 4u] == 1u) {
        return vec2<f32>(f32(bitcast<i32>(q.x)), f32(bitcast<i32>(q.y))) * (1.0 / 8388608.0);
    }
    return concentric(to_unit(q.x << 8u), to_unit(q.y << 8u));
}

// Sample k of n on the unit disk for the pixel at `pixel` under the tile shift of `tile_seed`,
// drawing its randomness from `stream` (as at frame 0), in frame `frame` of a temporal sequence
// (see DiskScheme::point and Site): progressive sequences continue at index frame n + k,
// random schemes re-key their stream, bluenoise-cp moves its offset, stbn-cp reads the frame's
// slice of its masks, points re-key the tile seed.
fn disk_point(scheme: u32, n: u32, k: u32, stream_0: u32, pixel: vec2<u32>, tile_seed: u32, frame: u32) -> vec2<f32> {
    let stream = at_frame(stream_0, frame);
    let index = frame * n + k;
    switch scheme {
        case SCHEME_UNIFORM: {
            let u = stream_unit(stream, 2u * k);
            let v = stream_unit(stream, 2u * k + 1u);
            return polar(sqrt(u), TAU * v);
        }
        case SCHEME_PAPER, SCHEME_PAPER_LITERAL: {
            if (k == 0u) {
                return vec2<f32>(0.0);
            }
            let theta = TAU * f32(k) / f32(n - 1u);
            let r = 0.7 * sqrt(stream_unit(stream, 2u * k));
            if (scheme == SCHEME_PAPER) {
                return polar(0.3 + r, theta);
            }
            return vec2<f32>(0.3) + polar(r, theta);
        }
        case SCHEME_JITTERED: {
            let rows = strata_rows(n);
            let cols = n / rows;
            let u = (f32(k % cols) + stream_unit(stream, 2u * k)) / f32(cols);
            let v = (f32(k / cols) + stream_unit(stream, 2u * k + 1u)) / f32(rows);
            return concentric(u, v);
        }
        case SCHEME_SOBOL: {
            let s = scrambled_sobol_2d(index, stream_u32(stream_0, 0x7fffffffu));
            return concentric(to_unit(s.x), to_unit(s.y));
        }
        case SCHEME_SPIRAL: {
            let turn = k * GOLDEN_TURN + stream_u32(stream, 0x7ffffffeu);
            let offset = stream_unit(stream, 0x7ffffffdu);
            let r = sqrt((f32(k) + offset) / f32(n));
            return polar(r, TAU * to_unit(turn));
        }
        case SCHEME_PMJ02: {
            let shift = vec2<u32>(stream_u32(stream_0, 0x7ffffffcu) >> 8u, stream_u32(stream_0, 0x7ffffffbu) >> 8u);
            let p = pmj02_point(index, shift);
            return concentric(p.x, p.y);
        }
        case SCHEME_BLUENOISE_CP: {
            return rotated_02(k, bluenoise_offset(pixel, tile_seed, frame));
        }
        case SCHEME_STBN_CP: {
            if (scheme_tables[STBN_HEADER] == 0u) {
                // No masks packed (sampling::tables::pack packs them for stbn-cp): NaN.
                return vec2<f32>(bitcast<f32>(0x7fc00000u));
            }
            return rotated_02(k, stbn_offset(pixel, tile_seed, frame));
        }
        case SCHEME_SOBOL_BLUENOISE: {
            let table = bluenoise_table(n);
            if (table == 0u) {
                // No table packed for n (sampling::tables::pack packs every count a frame uses):
                // NaN, which no test or metric mistakes for a point.
                return vec2<f32>(bitcast<f32>(0x7fc00000u));
            }
            let s = scrambled_sobol_2d(index, scheme_tables[table + tile_index(pixel, tile_seed)]);
            return concentric(to_unit(s.x), to_unit(s.y));
        }
        case SCHEME_SOBOL_BLUENOISE_T: {
            // sobol-bluenoise rescrambled per frame: the tile shift re-keyed, the first n points.
            let table = bluenoise_table(n);
            if (table == 0u) {
                return vec2<f32>(bitcast<f32>(0x7fc00000u));
            }
            let s = scrambled_sobol_2d(k, scheme_tables[table + tile_index(pixel, at_frame(tile_seed, frame))]);
            return concentric(to_unit(s.x), to_unit(s.y));
        }
        case SCHEME_POINTS: {
            return points_point(k, pixel, at_frame(tile_seed, frame));
        }
        default: {
            // An id no scheme has: NaN, which no test or metric mistakes for a point.
            return vec2<f32>(bitcast<f32>(0x7fc00000u));
        }
    }
}
