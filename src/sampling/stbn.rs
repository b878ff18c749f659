//! Spatiotemporal blue noise (STBN): a stack of [`DEPTH`] masks of [`SIDE`] x [`SIDE`] in which
//! every slice is a blue-noise dither array in space and every pixel's values over the slices
//! are a blue-noise sequence in time (Wolfe, Morrical, Akenine-Moller & Ramamoorthi 2022,
//! "Spatiotemporal Blue Noise Masks", EGSR; the scalar masks of their Sec. 4).
//!
//! Why not a 2-D mask moved over frames ([`super::bluenoise::offset_at`])? Every frame of that is
//! blue in space, but a pixel's values over frames are a Kronecker sequence, not blue in time
//! ([`temporal_low_share`] 0.03 to 0.05 against 0.005 here, white noise 0.19). Why not
//! void-and-cluster in 3-D with the full Gaussian exp(-dxy^2 / 2 sigma_s^2 - dt^2 / 2 sigma_t^2)?
//! That makes 3-D blue noise, whose 2-D slices are not 2-D blue noise (the paper's point;
//! measured with this module's code at this size: the mean [`spatial_low_share`] of a slice is
//! 0.033 with the full 3-D Gaussian, white noise 0.060, the paper's energy 0.0001, and the
//! temporal share 0.16). The paper's energy is the Gaussian taken only between voxels that share
//! a slice (dt = 0: a 2-D Gaussian in x, y) or a pixel (dxy = 0: a 1-D Gaussian in t); other
//! pairs do not interact. Its reference code (NVIDIA SpatiotemporalBlueNoiseSDK,
//! `ReferenceController2Dx1Dx1D`) splats exactly these two kernels, sigma 1.9 on every axis.
//!
//! Ranking: the paper's code ranks the whole volume at once (one global void-and-cluster order)
//! and writes rank / voxels, which leaves each slice's histogram only near-uniform (measured at
//! this size with that order: a slice's sorted values stray up to 0.009 from uniform). This
//! module fills the slices in lock step instead: every step takes the tightest cluster only among
//! the slices with the most points (phase 1) and the largest void only among the slices with the
//! fewest (phases 2 and 3), under the paper's energy over the whole volume. Every slice then
//! gains its k-th point in round k, so a voxel's global rank r is its slice rank r / DEPTH
//! exactly: each slice holds every value (k + 0.5) / SIDE^2 once, and its thresholds are nested
//! blue-noise point sets. A pixel's values over time are not held to one per 1/DEPTH bin (the
//! energy spreads a pixel's points at each threshold over t, it does not count them): the
//! number of a pixel's values below 1/4, 1/2 or 3/4 strays from DEPTH times that by 0.75 rms,
//! against 2.6 for white noise, and a pixel leaves 10.1 of the 32 bins empty, white noise 11.6
//! (tests).
//!
//! Two masks from independent seeds give a pixel a 2-D offset per frame, for Cranley-Patterson
//! rotation of a shared low-discrepancy set ([`offset`]). The paper's vector masks (their Sec. 5)
//! come from a swap optimisation of a vector-valued energy (each candidate swap re-weighs some
//! 700 neighbour pairs; by that count tens of seconds or more at this size, too slow to build
//! on first use); two scalar masks build in a fraction of a second, and each channel keeps the
//! scalar guarantees (uniform slices, blue in space and time) with the channels uncorrelated
//! (tests). What they do not give is a jointly stratified 2-D offset over time: a pixel's
//! offsets over frames are spread per axis, not as a 2-D set, so on a 2-D integrand (a disk
//! light cut by a straight edge, one sample per frame) their temporal error is below independent
//! random offsets' but above the R2-moved mask's, whose offsets walk a 2-D Kronecker sequence;
//! on a 1-D integrand they beat that walk (tests, with the numbers).
//!
//! Everything is deterministic from [`SEEDS`]: integer energies (the Gaussian weights rounded to
//! multiples of 2^-20), ties to the lowest voxel index.

use super::bluenoise::{cp_shift, tile_index_in};
use super::rng::pcg;
use std::sync::OnceLock;

/// Side of every slice (pixels): the masks repeat with this period in x and y, the period of
/// [`super::bluenoise::TILE`].
pub const SIDE: usize = 64;

/// Slices (frames) of the stack: frames repeat with this period. A power of two, so that a frame
/// counter wrapping at 2^32 stays continuous modulo it; 32 frames cover the error after 4 to 32
/// frames the tests follow, and a stack of 64 x 64 x 32 builds in about 0.4 s (the SDK's
/// published masks are 128 x 128 x 64).
pub const DEPTH: usize = 32;

/// Seeds of the two masks (x and y offsets): each picks its initial random pattern.
pub const SEEDS: [u32; 2] = [0x057b_0e00, 0x057b_0e01];

/// Standard deviation (pixels) of the energy's spatial Gaussian: 1.9, the value the paper's
/// reference code (NVIDIA SpatiotemporalBlueNoiseSDK) uses on every axis for scalar masks.
pub const SIGMA_S: f64 = 1.9;

/// Standard deviation (frames) of the energy's temporal Gaussian: 1.9, as [`SIGMA_S`].
pub const SIGMA_T: f64 = 1.9;

/// Radius of the truncated kernels in pixels and in frames: the paper's SDK keeps a Gaussian out
/// to where it has lost 0.5 % of its energy, floor(sqrt(-2 sigma^2 ln 0.005)) = 6 for sigma 1.9
/// (the weight there is exp(-36 / 7.22) = 0.7 %). Updates stay within this window of a voxel.
pub const REACH: usize = 6;

/// Points per slice of the initial random pattern: a tenth, Ulichney's choice and the SDK's
/// initial density 0.1.
pub const INITIAL: usize = SIDE * SIDE / 10;

/// Frequencies below this, cycles per pixel (or per frame), are "low" for [`spatial_low_share`]
/// and [`temporal_low_share`]: a quarter of the Nyquist frequency, the cut of the error spectra
/// in `metrics::spectrum`.
pub const LOW_CUTOFF: f64 = 0.125;

/// Fixed-point scale of the energy weights.
const SCALE: f64 = (1u64 << 20) as f64;

const AREA: usize = SIDE * SIDE;
const VOXELS: usize = AREA * DEPTH;
const WIDTH: usize = 2 * REACH + 1;

/// Bits of a voxel index in a tracker's packed key.
const INDEX_BITS: u32 = VOXELS.trailing_zeros();

const _: () = assert!(SIDE.is_power_of_two() && DEPTH.is_power_of_two());
const _: () = assert!(WIDTH <= SIDE && WIDTH <= DEPTH);

/// The truncated kernels as integers: `space[(dy + REACH) * WIDTH + dx + REACH]` and `time[dt]`.
struct Kernel {
    space: [i64; WIDTH * WIDTH],
    time: [i64; REACH + 1],
}

impl Kernel {
    fn new() -> Kernel {
        let weight = |d2: f64, sigma: f64| ((-d2 / (2.0 * sigma * sigma)).exp() * SCALE).round() as i64;
        let space = std::array::from_fn(|i| {
            let (dx, dy) = ((i % WIDTH).abs_diff(REACH), (i / WIDTH).abs_diff(REACH));
            weight((dx * dx + dy * dy) as f64, SIGMA_S)
        });
        let time = std::array::from_fn(|dt| weight((dt * dt) as f64, SIGMA_T));
        Kernel { space, time }
    }
}

/// The best candidate of one kind in each slice, as a tournament tree per slice: a step finds its
/// voxel among DEPTH roots, and a splat re-decides O(WIDTH log AREA) nodes. A node is the packed
/// key `energy << INDEX_BITS | voxel` (minus the energy for clusters; `i64::MAX` for no
/// candidate), so the least node is the lowest energy with ties to the lowest index.
#[derive(Clone)]
struct Tracker {
    /// Clusters (the highest energy among points) rather than voids (the lowest among empty).
    clusters: bool,
    /// Per slice, 2 AREA nodes: node n is the least of its subtree (node 1 the root, leaves at
    /// AREA..2 AREA).
    node: Vec<i64>,
}

impl Tracker {
    fn new(clusters: bool, field: &Field) -> Tracker {
        let mut t = Tracker {
            clusters,
            node: vec![i64::MAX; DEPTH * 2 * AREA],
        };
        for g in 0..VOXELS {
            t.set(g, field.on[g], field.energy[g]);
        }
        for s in 0..DEPTH {
            t.lift(s, AREA, 2 * AREA - 1, usize::MAX);
        }
        t
    }

    /// Sets voxel `g`'s leaf (its ancestors wait for [`Tracker::lift`]).
    fn set(&mut self, g: usize, on: bool, energy: i64) {
        let key = match (self.clusters, on) {
            (false, false) => energy << INDEX_BITS | g as i64,
            (true, true) => -energy << INDEX_BITS | g as i64,
            _ => i64::MAX,
        };
        self.node[(g / AREA) * 2 * AREA + AREA + g % AREA] = key;
    }

    /// Re-decides, `levels` levels up (or to the root), the ancestors of nodes `lo..=hi` of slice
    /// `s`'s tree, stopping where a level comes out unchanged.
    fn lift(&mut self, s: usize, lo: usize, hi: usize, levels: usize) {
        let tree = &mut self.node[s * 2 * AREA..(s + 1) * 2 * AREA];
        let (mut lo, mut hi) = (lo / 2, hi / 2);
        for _ in 0..levels {
            let mut changed = false;
            for n in lo..=hi {
                let least = tree[2 * n].min(tree[2 * n + 1]);
                changed |= tree[n] != least;
                tree[n] = least;
            }
            if lo == 1 || !changed {
                break;
            }
            (lo, hi) = (lo / 2, hi / 2);
        }
    }

    /// The least voxel of the slices `eligible` picks.
    fn best(&self, eligible: impl Iterator<Item = usize>) -> usize {
        let least = eligible
            .map(|s| self.node[s * 2 * AREA + 1])
            .min()
            .expect("an eligible slice");
        debug_assert!(least != i64::MAX, "a candidate");
        (least & ((1 << INDEX_BITS) - 1)) as usize
    }
}

/// A binary pattern over the volume, its energy under the paper's kernel, its points per slice,
/// and the trackers that find its voids and clusters.
#[derive(Clone)]
struct Field {
    on: Vec<bool>,
    energy: Vec<i64>,
    count: [usize; DEPTH],
    voids: Option<Tracker>,
    clusters: Option<Tracker>,
}

impl Field {
    /// Turns voxel `g` on or off, moving its energy: the 2-D Gaussian over its slice and the
    /// 1-D Gaussian over its pixel's other slices.
    fn toggle(&mut self, g: usize, kernel: &Kernel) {
        let sign = if self.on[g] { -1 } else { 1 };
        self.on[g] = !self.on[g];
        let (s, p) = (g / AREA, g % AREA);
        self.count[s] = self.count[s].wrapping_add_signed(sign as isize);
        let (x0, y0) = ((p % SIDE + SIDE - REACH) % SIDE, (p / SIDE + SIDE - REACH) % SIDE);
        for dy in 0..WIDTH {
            let row = s * AREA + (y0 + dy) % SIDE * SIDE;
            for (dx, w) in kernel.space[dy * WIDTH..(dy + 1) * WIDTH].iter().enumerate() {
                self.energy[row + (x0 + dx) % SIDE] += sign * w;
            }
        }
        self.refresh_window(s, x0, y0);
        for dt in 1..=REACH {
            for t in [(s + dt) % DEPTH, (s + DEPTH - dt) % DEPTH] {
                let h = t * AREA + p;
                self.energy[h] += sign * kernel.time[dt];
                for tracker in [&mut self.voids, &mut self.clusters].into_iter().flatten() {
                    tracker.set(h, self.on[h], self.energy[h]);
                    tracker.lift(t, AREA + p, AREA + p, usize::MAX);
                }
            }
        }
    }

    /// Brings the trackers up to date over the kernel's window of slice `s` from column `x0`,
    /// row `y0` (wrapping): each row's leaves up to the row's node, then the rows' nodes up.
    fn refresh_window(&mut self, s: usize, x0: usize, y0: usize) {
        let split = |a: usize| {
            if a + WIDTH <= SIDE {
                [(a, a + WIDTH - 1), (1, 0)]
            } else {
                [(a, SIDE - 1), (0, a + WIDTH - SIDE - 1)]
            }
        };
        let (columns, rows) = (split(x0), split(y0));
        let row_levels = SIDE.trailing_zeros() as usize;
        for tracker in [&mut self.voids, &mut self.clusters].into_iter().flatten() {
            for &(r0, r1) in rows.iter().filter(|(a, b)| a <= b) {
                for r in r0..=r1 {
                    for &(c0, c1) in columns.iter().filter(|(a, b)| a <= b) {
                        for c in c0..=c1 {
                            let g = s * AREA + r * SIDE + c;
                            tracker.set(g, self.on[g], self.energy[g]);
                        }
                        tracker.lift(s, AREA + r * SIDE + c0, AREA + r * SIDE + c1, row_levels);
                    }
                }
                tracker.lift(s, SIDE + r0, SIDE + r1, usize::MAX);
            }
        }
    }

    /// The largest void among the slices with the fewest points.
    fn largest_void(&self) -> usize {
        let least = *self.count.iter().min().expect("slices");
        let eligible = (0..DEPTH).filter(|&s| self.count[s] == least);
        self.voids.as_ref().expect("a void tracker").best(eligible)
    }

    /// The tightest cluster among the slices with the most points.
    fn tightest_cluster(&self) -> usize {
        let most = *self.count.iter().max().expect("slices");
        let eligible = (0..DEPTH).filter(|&s| self.count[s] == most);
        self.clusters.as_ref().expect("a cluster tracker").best(eligible)
    }
}

/// One scalar STBN mask by void-and-cluster under the paper's energy, the slices filled in lock
/// step: every voxel's rank within its slice, scaled to [0, 1) as `(rank + 0.5) / SIDE^2`, at
/// `(t * SIDE + y) * SIDE + x`. About 0.4 s in a release build.
pub fn generate(seed: u32) -> Vec<f64> {
    let kernel = Kernel::new();
    let mut field = Field {
        on: vec![false; VOXELS],
        energy: vec![0; VOXELS],
        count: [0; DEPTH],
        voids: None,
        clusters: None,
    };
    // The initial pattern: INITIAL random pixels in every slice.
    for s in 0..DEPTH {
        let key = pcg(seed ^ pcg(s as u32 ^ 0x57b1_0000));
        let mut cells: Vec<usize> = (0..AREA).collect();
        for k in 0..INITIAL {
            let j = k + pcg(key ^ pcg(k as u32)) as usize % (AREA - k);
            cells.swap(k, j);
            field.toggle(s * AREA + cells[k], &kernel);
        }
    }
    field.voids = Some(Tracker::new(false, &field));
    field.clusters = Some(Tracker::new(true, &field));
    // Relax it: move the tightest cluster's point into the largest void (of the same slice, the
    // only one then a point short) until it stays put.
    for _ in 0..VOXELS {
        let cluster = field.tightest_cluster();
        field.toggle(cluster, &kernel);
        let void = field.largest_void();
        field.toggle(void, &kernel);
        if void == cluster {
            break;
        }
    }
    let ones = INITIAL * DEPTH;
    let mut rank = vec![0usize; VOXELS];
    // Phase 1: the initial points, ranked by removing the tightest cluster first.
    let mut removal = Field {
        on: field.on.clone(),
        energy: field.energy.clone(),
        count: field.count,
        voids: None,
        clusters: field.clusters.take(),
    };
    for r in (0..ones).rev() {
        let c = removal.tightest_cluster();
        removal.toggle(c, &kernel);
        rank[c] = r;
    }
    // Phases 2 and 3: fill the largest void next, up to every voxel. Past half full this is
    // Ulichney's phase 3 (the tightest cluster of the empty voxels): a window's kernel sum is the
    // same at every voxel, so the lowest energy of the points is the highest of the empty.
    for r in ones..VOXELS {
        let v = field.largest_void();
        field.toggle(v, &kernel);
        rank[v] = r;
    }
    rank.iter().map(|&r| ((r / DEPTH) as f64 + 0.5) / AREA as f64).collect()
}

/// The two masks (x and y offsets), built once, side by side.
pub fn masks() -> &'static [Vec<f64>; 2] {
    static MASKS: OnceLock<[Vec<f64>; 2]> = OnceLock::new();
    MASKS.get_or_init(|| {
        std::thread::scope(|scope| {
            let y = scope.spawn(|| generate(SEEDS[1]));
            [generate(SEEDS[0]), y.join().expect("the y mask")]
        })
    })
}

/// The slice that frame 0 reads under `tile_seed`: the stack is shifted in time as well as in
/// space per seed and light, so that they see independent realisations of it.
pub fn time_shift(tile_seed: u32) -> u32 {
    pcg(tile_seed ^ 0x7e3a_9f01) % DEPTH as u32
}

/// A pixel's Cranley-Patterson offset in frame `frame`, as 24-bit fractions: the two masks'
/// values at its place in the stack (the tile shifted by `tile_seed` in x and y as
/// [`super::bluenoise::tile_index`] does, and in t by [`time_shift`]; frames wrap modulo
/// [`DEPTH`]) plus the random shift every pixel gets under the tile seed
/// ([`super::bluenoise::cp_shift`]), modulo 1. Over seeds each offset is uniform on the square
/// (the estimator is unbiased); within a frame neighbours' offsets differ as in a blue-noise
/// mask, and over frames each of a pixel's two coordinates follows a blue-noise sequence.
pub fn offset(x: u32, y: u32, frame: u32, tile_seed: u32) -> (u32, u32) {
    let m = masks();
    let t = frame.wrapping_add(time_shift(tile_seed)) % DEPTH as u32;
    let i = t as usize * AREA + tile_index_in(x, y, tile_seed, SIDE as u32);
    let fix = |v: f64| (v * (1u32 << 24) as f64) as u32;
    let (sx, sy) = cp_shift(tile_seed);
    let wrap = |a: u32, b: u32| a.wrapping_add(b) & 0x00ff_ffff;
    (wrap(fix(m[0][i]), sx), wrap(fix(m[1][i]), sy))
}

/// Every setting the masks are generated from, in one sentence for reports.
pub fn settings() -> String {
    format!(
        "spatiotemporal blue noise (Wolfe et al. 2022): {DEPTH} slices of {SIDE} x {SIDE} by void-and-cluster under the paper's energy \
         (Gaussian of sigma {SIGMA_S} px within a slice and {SIGMA_T} frames along a pixel, cut at {REACH}), slices filled in lock step \
         (every rank once per slice), {INITIAL} initial points per slice, seeds {:#x}, {:#x}; shifted per seed and light in x, y and t",
        SEEDS[0], SEEDS[1]
    )
}

/// Signed frequency of DFT bin `k` of `n`, cycles per sample.
fn frequency(k: usize, n: usize) -> f64 {
    (if k <= n / 2 { k as f64 } else { k as f64 - n as f64 }) / n as f64
}

/// `e^{-2 pi i k / n}` for k in 0..n.
fn twiddles(n: usize) -> Vec<(f64, f64)> {
    let turn = std::f64::consts::TAU / n as f64;
    (0..n)
        .map(|k| ((turn * k as f64).cos(), -(turn * k as f64).sin()))
        .collect()
}

/// Share of a square slice's 2-D power spectrum (its mean removed, the slice taken as periodic,
/// as a tile is) at radial frequencies below [`LOW_CUTOFF`] cycles per pixel, out of the power
/// out to the Nyquist frequency 0.5 (the zero frequency and the corners beyond 0.5 left out, as
/// in `metrics::spectrum`). White noise gives about the area's share, (0.125 / 0.5)^2 = 1/16;
/// blue noise far less.
pub fn spatial_low_share(slice: &[f64]) -> f64 {
    let side = (slice.len() as f64).sqrt().round() as usize;
    assert_eq!(side * side, slice.len(), "a square slice");
    let mean = slice.iter().sum::<f64>() / slice.len() as f64;
    let w = twiddles(side);
    // The DFT of each row, then of each column of those.
    let mut rows = vec![(0.0, 0.0); slice.len()];
    for y in 0..side {
        for k in 0..side {
            rows[y * side + k] = (0..side).fold((0.0, 0.0), |(re, im), x| {
                let ((c, s), v) = (w[x * k % side], slice[y * side + x] - mean);
                (re + v * c, im + v * s)
            });
        }
    }
    let (mut low, mut all) = (0.0, 0.0);
    for ku in 0..side {
        for kv in 0..side {
            let f = frequency(ku, side).hypot(frequency(kv, side));
            if f == 0.0 || f > 0.5 {
                continue;
            }
            let (re, im) = (0..side).fold((0.0, 0.0), |(re, im), y| {
                let ((c, s), (r, i)) = (w[y * kv % side], rows[y * side + ku]);
                (re + r * c - i * s, im + r * s + i * c)
            });
            all += re * re + im * im;
            if f < LOW_CUTOFF {
                low += re * re + im * im;
            }
        }
    }
    low / all
}

/// Share of the temporal power spectrum below [`LOW_CUTOFF`] cycles per frame: each pixel's
/// sequence over a stack's slices (layout `(t * SIDE + y) * SIDE + x`, SIDE^2 pixels, as many
/// slices as the length holds) has its mean removed and is transformed as a periodic sequence;
/// the power spectra are averaged over the pixels and the share read from the average. White
/// noise gives the share of the bins below the cut: 6 of 31 for 32 frames (0 < |f| < 1/8).
pub fn temporal_low_share(stack: &[f64]) -> f64 {
    assert_eq!(stack.len() % AREA, 0, "whole slices of SIDE x SIDE");
    let depth = stack.len() / AREA;
    let w = twiddles(depth);
    let mut power = vec![0.0; depth];
    for p in 0..AREA {
        let mean = (0..depth).map(|t| stack[t * AREA + p]).sum::<f64>() / depth as f64;
        for (k, pk) in power.iter_mut().enumerate() {
            let (re, im) = (0..depth).fold((0.0, 0.0), |(re, im), t| {
                let ((c, s), v) = (w[t * k % depth], stack[t * AREA + p] - mean);
                (re + v * c, im + v * s)
            });
            *pk += re * re + im * im;
        }
    }
    let low: f64 = (1..depth)
        .filter(|&k| frequency(k, depth).abs() < LOW_CUTOFF)
        .map(|k| power[k])
        .sum();
    low / power[1..].iter().sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::bluenoise;
    use crate::sampling::rng::{to_unit, Seeded};

    /// A stack of white noise the size of a mask, from a seeded generator.
    fn white(seed: u32) -> Vec<f64> {
        let mut rng = Seeded(seed);
        (0..VOXELS).map(|_| rng.f()).collect()
    }

    /// The existing answer to frames, as a stack: the 2-D masks' offsets moved by R2 steps
    /// ([`bluenoise::offset_at`]), channel `c`, for DEPTH frames.
    fn r2_stack(c: usize, tile_seed: u32) -> Vec<f64> {
        assert_eq!(bluenoise::TILE, SIDE);
        (0..VOXELS)
            .map(|i| {
                let (t, p) = (i / AREA, i % AREA);
                let o = bluenoise::offset_at((p % SIDE) as u32, (p / SIDE) as u32, tile_seed, t as u32);
                [o.0, o.1][c] as f64 / (1u32 << 24) as f64
            })
            .collect()
    }

    #[test]
    fn every_slice_holds_every_rank_once() {
        for mask in masks() {
            for t in 0..DEPTH {
                let mut ranks: Vec<usize> = mask[t * AREA..(t + 1) * AREA]
                    .iter()
                    .map(|v| (v * AREA as f64) as usize)
                    .collect();
                ranks.sort_unstable();
                assert_eq!(ranks, (0..AREA).collect::<Vec<_>>(), "slice {t}");
            }
        }
        assert_eq!(generate(SEEDS[0]), masks()[0], "deterministic");
        assert_ne!(masks()[0], masks()[1]);
    }

    /// The rms over pixels and the thresholds 1/4, 1/2, 3/4 of how far a pixel's count of values
    /// below the threshold strays from DEPTH times it; and the mean number of the 1/DEPTH-wide
    /// bins a pixel's values leave empty.
    fn pixel_histograms(stack: &[f64]) -> (f64, f64) {
        let (mut spread, mut empty) = (0.0, 0.0);
        for p in 0..AREA {
            let values: Vec<f64> = (0..DEPTH).map(|t| stack[t * AREA + p]).collect();
            for v in [0.25, 0.5, 0.75] {
                let below = values.iter().filter(|&&x| x < v).count() as f64;
                spread += (below - DEPTH as f64 * v).powi(2);
            }
            let mut hit = [false; DEPTH];
            for x in &values {
                hit[((x * DEPTH as f64) as usize).min(DEPTH - 1)] = true;
            }
            empty += hit.iter().filter(|&&h| !h).count() as f64;
        }
        ((spread / (3 * AREA) as f64).sqrt(), empty / AREA as f64)
    }

    /// Each pixel's values over time are far more even than white noise's, though not one per
    /// bin. Measured: count spread 0.75 and 0.74 (x, y) against white noise's 2.60 (expected
    /// sqrt(32 * 5 / 24) = 2.58) and the R2-moved masks' 0.51 and 1.51; empty bins of 1/32 per
    /// pixel 10.1 against white noise's 11.6 (32 (31/32)^32 = 11.6) and R2's 10.5 and 16.1.
    #[test]
    fn pixels_spread_their_values_over_time() {
        let (white_spread, white_empty) = pixel_histograms(&white(0x3417_e000));
        eprintln!("white: count spread {white_spread:.2}, empty bins {white_empty:.2}");
        for c in 0..2 {
            let (r2_spread, r2_empty) = pixel_histograms(&r2_stack(c, 0));
            let (spread, empty) = pixel_histograms(&masks()[c]);
            eprintln!(
                "channel {c}: count spread {spread:.2} (R2 {r2_spread:.2}), empty bins {empty:.2} (R2 {r2_empty:.2})"
            );
            assert!(spread < white_spread / 3.0, "{spread} vs white {white_spread}");
            assert!(empty < white_empty, "{empty} vs white {white_empty}");
        }
        assert!((white_spread - 2.58).abs() < 0.1, "{white_spread}");
    }

    /// Every slice is blue in space. Measured: STBN slices' low share at most 0.00011 (mean
    /// 0.00008), white noise's slices 0.060 on average, the R2-moved 2-D masks' 0.0040 (the wrap
    /// modulo 1 as they move adds some low frequencies), the 2-D mask itself 0.00002.
    #[test]
    fn slices_are_blue_in_space() {
        let slices = |stack: &[f64]| -> Vec<f64> {
            (0..stack.len() / AREA)
                .map(|t| spatial_low_share(&stack[t * AREA..(t + 1) * AREA]))
                .collect()
        };
        let w = slices(&white(0x3417_e000));
        let white_mean = w.iter().sum::<f64>() / w.len() as f64;
        assert!((white_mean - 1.0 / 16.0).abs() < 0.01, "white noise: {white_mean}");
        let r2 = slices(&r2_stack(0, 0));
        let r2_mean = r2.iter().sum::<f64>() / r2.len() as f64;
        for (c, mask) in masks().iter().enumerate() {
            let s = slices(mask);
            let worst = s.iter().cloned().fold(0.0, f64::max);
            eprintln!(
                "channel {c}: worst slice {worst:.5}, mean {:.5}; white {white_mean:.4}; R2-moved 2-D mask {r2_mean:.5}",
                s.iter().sum::<f64>() / s.len() as f64
            );
            assert!(worst < white_mean / 50.0, "channel {c}: {worst} vs white {white_mean}");
        }
        let flat = spatial_low_share(&bluenoise::masks()[0]);
        eprintln!("the 2-D mask itself: {flat:.5}");
        assert!(flat < white_mean / 50.0);
    }

    /// Every pixel's sequence is blue in time, unlike white noise and unlike the R2-moved 2-D
    /// masks. Measured: 0.0049 and 0.0051 (x, y), white noise 0.190 (6/31 = 0.194 expected), the
    /// R2-moved masks 0.053 and 0.030.
    #[test]
    fn pixels_are_blue_in_time() {
        let w = temporal_low_share(&white(0x3417_e000));
        assert!((w - 6.0 / 31.0).abs() < 0.02, "white noise: {w}");
        for (c, mask) in masks().iter().enumerate() {
            let (s, r2) = (temporal_low_share(mask), temporal_low_share(&r2_stack(c, 0)));
            eprintln!("channel {c}: STBN {s:.4}, R2-moved 2-D mask {r2:.4}, white {w:.4}");
            assert!(s < w / 10.0, "channel {c}: {s} vs white {w}");
            assert!(s < r2 / 3.0, "channel {c}: {s} vs R2 {r2}");
        }
    }

    /// The two channels are uncorrelated, over the volume and along each pixel's sequence.
    /// Measured: -0.0024 over the volume, mean per-pixel correlation over time -0.0023.
    #[test]
    fn channels_are_uncorrelated() {
        let [a, b] = masks();
        let pearson = |a: &[f64], b: &[f64]| {
            let n = a.len() as f64;
            let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
            let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
            let (va, vb): (f64, f64) = (
                a.iter().map(|x| (x - ma).powi(2)).sum(),
                b.iter().map(|y| (y - mb).powi(2)).sum(),
            );
            cov / (va * vb).sqrt()
        };
        let whole = pearson(a, b);
        let per_pixel = (0..AREA)
            .map(|p| {
                let (x, y): (Vec<f64>, Vec<f64>) = (0..DEPTH).map(|t| (a[t * AREA + p], b[t * AREA + p])).unzip();
                pearson(&x, &y)
            })
            .sum::<f64>()
            / AREA as f64;
        eprintln!("correlation of the channels: {whole:.4} over the volume, {per_pixel:.4} per pixel over time");
        assert!(whole.abs() < 0.01 && per_pixel.abs() < 0.01, "{whole}, {per_pixel}");
    }

    /// Frames after the first of each scheme's offsets: 4, 8, 16, 32.
    const FRAMES: [usize; 4] = [4, 8, 16, 32];

    /// RMSE over pixels of the running mean after each of [`FRAMES`], one sample per frame, of
    /// `estimate(x, y, frame, tile_seed, test)` against `exact(test)`, for the pixels' test
    /// integrands drawn from `(angle, offset)` pairs: 4 tile seeds x 256 pixels.
    fn temporal_rmse(
        offsets: &dyn Fn(u32, u32, u32, u32) -> (u32, u32),
        hit: &dyn Fn((f64, f64), (f64, f64)) -> f64,
        exact: &dyn Fn((f64, f64)) -> f64,
    ) -> [f64; 4] {
        let mut sums = [0.0; 4];
        let mut n = 0.0;
        for seed in 11u32..15 {
            let tile_seed = bluenoise::tile_seed(seed, 0);
            for i in 0..256u32 {
                let h = pcg(pcg(seed ^ 0x7e57) ^ i);
                let (x, y) = (h % 256, (h >> 8) % 256);
                let test = (to_unit(pcg(h ^ 1)), to_unit(pcg(h ^ 2)));
                let mut sum = 0.0;
                for f in 0..DEPTH {
                    let (ox, oy) = offsets(x, y, f as u32, tile_seed);
                    let unit = |o: u32| o as f64 / (1u32 << 24) as f64;
                    sum += hit((unit(ox), unit(oy)), test);
                    if let Some(j) = FRAMES.iter().position(|&k| k == f + 1) {
                        sums[j] += (sum / (f + 1) as f64 - exact(test)).powi(2);
                    }
                }
                n += 1.0;
            }
        }
        sums.map(|s| (s / n).sqrt())
    }

    /// Independent uniform offsets per pixel and frame, hashed.
    fn random_offsets(x: u32, y: u32, f: u32, tile_seed: u32) -> (u32, u32) {
        let k = pcg(pcg(tile_seed ^ pcg(y << 16 | x)) ^ f);
        (k >> 8, pcg(k) >> 8)
    }

    /// A disk light cut by a straight occluder edge (the test's normal angle and signed distance
    /// in (-1, 1)), one sample per frame: the Cranley-Patterson-rotated first point of the shared
    /// set (the offset itself) through the concentric map, as `bluenoise-cp` draws it.
    ///
    /// Measured RMSE of the running mean (k = 4, 8, 16, 32 frames; 1024 pixels, 4 tile seeds):
    ///   STBN               0.155  0.100  0.067  0.045
    ///   R2-moved 2-D mask  0.129  0.087  0.058  0.037
    ///   independent random 0.186  0.134  0.099  0.070
    /// (five sets of 4 seeds: STBN 0.066 to 0.069 and 0.044 to 0.047 after 16 and 32 frames,
    /// R2 0.056 to 0.059 and 0.035 to 0.037, random 0.092 to 0.099 and 0.066 to 0.070). So STBN's
    /// two independent channels beat random offsets, by 1.4x to 1.5x after 16 and 32 frames, but
    /// not the R2 walk, which beats STBN by 1.15x to 1.31x: its offsets over frames are a 2-D
    /// Kronecker sequence, while STBN spreads each coordinate over time, not the pair (see the
    /// module's notes). This test pins both.
    #[test]
    fn temporal_error_on_a_disk_edge() {
        let hit = |(u, v): (f64, f64), (a, c): (f64, f64)| {
            let (angle, c) = (a * std::f64::consts::TAU, 2.0 * c - 1.0);
            let p = crate::sampling::concentric(u, v);
            f64::from(p.x * angle.cos() + p.y * angle.sin() > c)
        };
        let exact = |(_, c): (f64, f64)| {
            let c = 2.0 * c - 1.0;
            (c.acos() - c * (1.0 - c * c).sqrt()) / std::f64::consts::PI
        };
        let [stbn, r2, random] = three_ways(&hit, &exact);
        for j in [2, 3] {
            assert!(
                stbn[j] < random[j] / 1.3,
                "{} frames: STBN {} vs random {}",
                FRAMES[j],
                stbn[j],
                random[j]
            );
            assert!(
                r2[j] < stbn[j],
                "{} frames: R2 {} vs STBN {}",
                FRAMES[j],
                r2[j],
                stbn[j]
            );
        }
    }

    /// [`temporal_rmse`] of one integrand for STBN, the R2-moved 2-D mask and independent random
    /// offsets, in that order, printed as the tests' comments quote them.
    fn three_ways(hit: &dyn Fn((f64, f64), (f64, f64)) -> f64, exact: &dyn Fn((f64, f64)) -> f64) -> [[f64; 4]; 3] {
        let stbn = temporal_rmse(&offset, hit, exact);
        let r2 = temporal_rmse(&|x, y, f, s| bluenoise::offset_at(x, y, s, f), hit, exact);
        let random = temporal_rmse(&random_offsets, hit, exact);
        for (name, e) in [("STBN", stbn), ("R2-moved 2-D mask", r2), ("random", random)] {
            eprintln!("{name:>18}: {}", e.map(|v| format!("{v:.4}")).join("  "));
        }
        [stbn, r2, random]
    }

    /// The same with a 1-D integrand, the share of [0, 1) below a threshold, read from the x
    /// offset alone: what a scalar mask is for (the paper's use). Here STBN's temporal order
    /// beats the R2 walk's x coordinate.
    ///
    /// Measured RMSE of the running mean (k = 4, 8, 16, 32 frames; the same pixels and seeds):
    ///   STBN               0.138  0.084  0.054  0.034
    ///   R2-moved 2-D mask  0.100  0.090  0.072  0.040
    ///   independent random 0.199  0.140  0.102  0.072
    /// (five sets of 4 seeds: STBN 0.054 to 0.056 and 0.034 to 0.035 after 16 and 32 frames, R2
    /// 0.072 to 0.074 and 0.039 to 0.041, random 0.100 to 0.108 and 0.072 to 0.076): STBN beats
    /// random by 1.8x to 2.25x, and the R2 walk by 1.30x to 1.35x after 16 frames and 1.15x to
    /// 1.21x after 32; R2 is ahead after 4 frames.
    #[test]
    fn temporal_error_on_a_step() {
        let hit = |(u, _): (f64, f64), (_, c): (f64, f64)| f64::from(u < c);
        let exact = |(_, c): (f64, f64)| c;
        let [stbn, r2, random] = three_ways(&hit, &exact);
        for j in [2, 3] {
            assert!(
                stbn[j] < random[j] / 1.6,
                "{} frames: STBN {} vs random {}",
                FRAMES[j],
                stbn[j],
                random[j]
            );
            assert!(
                stbn[j] < r2[j],
                "{} frames: STBN {} vs R2 {}",
                FRAMES[j],
                stbn[j],
                r2[j]
            );
        }
        assert!(stbn[2] < r2[2] / 1.2, "16 frames: STBN {} vs R2 {}", stbn[2], r2[2]);
    }

    #[test]
    fn offsets_wrap_in_frames_and_tiles() {
        let s = bluenoise::tile_seed(7, 1);
        for (x, y) in [(0u32, 0u32), (5, 63), (100, 7)] {
            for f in [0u32, 1, 31, 77] {
                let o = offset(x, y, f, s);
                assert!(o.0 < 1 << 24 && o.1 < 1 << 24);
                assert_eq!(offset(x, y, f + DEPTH as u32, s), o);
                assert_eq!(offset(x + SIDE as u32, y + 2 * SIDE as u32, f, s), o);
            }
            // A frame counter that wraps at 2^32 stays continuous.
            assert_eq!(offset(x, y, u32::MAX, s), offset(x, y, DEPTH as u32 - 1, s));
        }
        // Frame f of one tile seed reads slice f + time_shift, pixel as the 2-D tile index.
        let (t, i) = (
            (3 + time_shift(s)) as usize % DEPTH,
            tile_index_in(9, 4, s, SIDE as u32),
        );
        let fix = |v: f64| (v * (1u32 << 24) as f64) as u32;
        let (sx, sy) = cp_shift(s);
        let want = (
            (fix(masks()[0][t * AREA + i]) + sx) & 0xff_ffff,
            (fix(masks()[1][t * AREA + i]) + sy) & 0xff_ffff,
        );
        assert_eq!(offset(9, 4, 3, s), want);
        assert!(settings().contains("64 x 64") && settings().contains("1.9"));
    }
}
