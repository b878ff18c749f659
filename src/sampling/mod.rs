//! Where shadow rays land on a disk light: the schemes compared by the sweep.
//!
//! Each scheme maps (sample count n, sample index k, the pixel's [`Site`]: its random stream,
//! its position, the run's seed and the frame's index) to a point on the unit disk; the renderer
//! scales it by the light's radius and places it in the light's plane. A scheme is evaluated one
//! sample at a time so that the GPU can do the same; the schemes arranged over the screen read
//! tables the GPU gets as a buffer ([`tables`]).
//!
//! Adding a scheme: a variant in [`DiskScheme`] with its name appended to [`DiskScheme::ALL`]
//! (a built-in's WGSL id is its place there, so appending keeps the others' ids; the points id
//! follows the list), its point function in [`DiskScheme::point`], and the same function in
//! `render/gpu/shaders/sampling.wgsl` under the matching `SCHEME_*` id; a scheme that reads
//! tables says so in [`DiskScheme::uses_tables`] and gets its region in [`tables::pack`]. The
//! property tests in `tests/it/sampling_properties.rs` and the CPU/GPU agreement test then
//! cover it.
//!
//! A user's own point set needs no code: a `points:NAME` scheme reads it from a file
//! ([`points`]), and both backends sample it from the tables buffer.

pub mod bluenoise;
pub mod pmj02;
pub mod points;
pub mod rng;
pub mod sobol;
pub mod stbn;
pub mod tables;

use glam::DVec2;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, TAU};
use std::fmt;
use std::str::FromStr;

pub use rng::Stream;

/// Lights a frame samples: each has its own stream of shadow-ray targets and, for the
/// screen-arranged schemes, its own scramble table ([`tables::MAX_COUNTS`]); the renderers'
/// per-light ray counters and the GPU's light buffer are sized for this, and a scene file with
/// more is refused where it lists them.
pub const MAX_LIGHTS: usize = 8;

/// How the n shadow-ray targets of one receiver point are chosen on the unit disk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum DiskScheme {
    /// Eq. (1) of the soft-shadow paper: r = sqrt(u), theta = 2 pi v. Area-uniform, independent.
    Uniform,
    /// Eq. (2) + (3) as the text intends: the centre, then n - 1 points at evenly spaced angles
    /// theta_i = 2 pi i / (n - 1) with radii 0.3 + 0.7 sqrt(a), a uniform in [0, 1].
    Paper,
    /// Eq. (3) exactly as printed: x = 0.3 + 0.7 sqrt(a) cos(theta), y = 0.3 + 0.7 sqrt(a) sin(theta),
    /// which shifts every non-centre point by (0.3, 0.3), partly off the light.
    PaperLiteral,
    /// Jittered (stratified) samples on a rows x cols grid of the unit square, mapped by the
    /// concentric map (Shirley & Chiu 1997). rows is the largest divisor of n not above sqrt(n),
    /// so every stratum has equal area and the estimator stays unbiased for any n.
    Jittered,
    /// Owen-scrambled Sobol' (Burley 2020) through the concentric map.
    Sobol,
    /// Golden-angle spiral with one random rotation and one random radial offset per pattern:
    /// sample k is uniform over the k-th of n equal-area annuli, so it is unbiased.
    Spiral,
    /// Progressive multi-jittered (0,2) points (Christensen, Kensler & Kilpatrick 2018) from one
    /// shared sequence, each pixel's under its own random digital shift, through the concentric
    /// map ([`pmj02`]).
    Pmj02,
    /// A shared (0,2) set (unscrambled Sobol') shifted per pixel by a blue-noise mask's offset
    /// plus one random shift per run and light, modulo 1 (Cranley-Patterson rotation; Georgiev
    /// & Fajardo 2016), through the concentric map ([`bluenoise::offset`]).
    BluenoiseCp,
    /// Owen-scrambled Sobol' whose per-pixel scrambles are arranged over a tile so neighbouring
    /// pixels' errors differ (after Heitz et al. 2019), through the concentric map
    /// ([`bluenoise`]).
    SobolBluenoise,
    /// A user's own pattern, `points:NAME`, read from a points file ([`points`]).
    Points(points::PointsId),
    /// The shared (0,2) set of [`DiskScheme::BluenoiseCp`] Cranley-Patterson rotated by the
    /// pixel's offset from spatiotemporal blue-noise masks (Wolfe et al. 2022): frame f reads the
    /// masks' slice f (modulo their depth), so the offset changes over frames along each pixel's
    /// blue-noise sequence in time rather than by R2 steps ([`stbn::offset`]).
    StbnCp,
    /// [`DiskScheme::SobolBluenoise`] rescrambled every frame: frame f reads the scramble tile
    /// under a tile shift re-keyed by f ([`rng::at_frame`]) and draws the first n points of its
    /// pixel's new scramble, so every frame is a blue-noise arrangement of n-point (0,2) nets
    /// (the temporal variant of Heitz et al. 2019), where sobol-bluenoise's frames continue one
    /// scramble's sequence and are blue only at frame 0. The price: frames are independent, so
    /// the temporal mean converges as 1 / sqrt(F), not as the sequence does.
    SobolBluenoiseT,
}

/// Where one pixel's samples come from: its random stream, and, for the schemes arranged over
/// the screen, its position and the run's seed; and which frame of a temporal sequence it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Site {
    /// The pixel's (or the shared pattern's) random stream, as at frame 0.
    pub stream: Stream,
    /// Pixel column and row.
    pub pixel: [u32; 2],
    /// Seed of the blue-noise tile's shift, from the run's seed and the light
    /// ([`bluenoise::tile_seed`]), so that seeds and lights see independent arrangements.
    pub tile_seed: u32,
    /// Index of the frame in a temporal sequence (0 for a single frame): what each scheme does
    /// with it is [`DiskScheme::point`]'s business.
    pub frame: u32,
}

impl Site {
    /// The site of pixel `(x, y)` (index `index`) for light `light` in frame `frame` of a run
    /// seeded with `seed`.
    pub fn pixel(seed: u32, light: u32, [x, y]: [u32; 2], index: u32, frame: u32) -> Site {
        Site {
            stream: Stream::new(seed, light, Some(index)),
            pixel: [x, y],
            tile_seed: bluenoise::tile_seed(seed, light),
            frame,
        }
    }

    /// The site every pixel shares (the paper's precomputed buffer) in frame `frame`.
    pub fn shared(seed: u32, light: u32, frame: u32) -> Site {
        Site {
            stream: Stream::new(seed, light, None),
            pixel: [0, 0],
            tile_seed: bluenoise::tile_seed(seed, light),
            frame,
        }
    }
}

impl DiskScheme {
    /// Every scheme, in report order.
    pub const ALL: [DiskScheme; 11] = [
        DiskScheme::Uniform,
        DiskScheme::Paper,
        DiskScheme::PaperLiteral,
        DiskScheme::Jittered,
        DiskScheme::Sobol,
        DiskScheme::Spiral,
        DiskScheme::Pmj02,
        DiskScheme::BluenoiseCp,
        DiskScheme::SobolBluenoise,
        DiskScheme::StbnCp,
        DiskScheme::SobolBluenoiseT,
    ];

    /// The name used in experiment files and CSV columns.
    pub fn name(self) -> &'static str {
        match self {
            DiskScheme::Uniform => "uniform",
            DiskScheme::Paper => "paper",
            DiskScheme::PaperLiteral => "paper-literal",
            DiskScheme::Jittered => "jittered",
            DiskScheme::Sobol => "sobol",
            DiskScheme::Spiral => "spiral",
            DiskScheme::Pmj02 => "pmj02",
            DiskScheme::BluenoiseCp => "bluenoise-cp",
            DiskScheme::SobolBluenoise => "sobol-bluenoise",
            DiskScheme::StbnCp => "stbn-cp",
            DiskScheme::SobolBluenoiseT => "sobol-bluenoise-t",
            DiskScheme::Points(id) => id.label(),
        }
    }

    /// Where the scheme comes from, for reports and the documentation of every output.
    pub fn source(self) -> String {
        let built_in = match self {
            DiskScheme::Points(id) => {
                return match id.set() {
                    Some(set) => set.describe(),
                    None => "a points file (not loaded)".into(),
                }
            }
            DiskScheme::Uniform => "eq. (1) of the soft-shadow paper: independent, area-uniform",
            DiskScheme::Paper => "eq. (2) + (3) of the soft-shadow paper as intended",
            DiskScheme::PaperLiteral => "eq. (3) of the soft-shadow paper as printed",
            DiskScheme::Jittered => "stratified on a grid of the unit square, concentric map",
            DiskScheme::Sobol => "Owen-scrambled Sobol' (Burley 2020), concentric map",
            DiskScheme::Spiral => "golden-angle spiral over equal-area annuli",
            DiskScheme::Pmj02 => "progressive multi-jittered (0,2) (Christensen et al. 2018), per-pixel digital shift",
            DiskScheme::BluenoiseCp => {
                "blue-noise mask (void-and-cluster) rotating a shared (0,2) set (Georgiev & Fajardo 2016)"
            }
            DiskScheme::SobolBluenoise => {
                "Owen-scrambled Sobol' with blue-noise arranged scrambles (after Heitz et al. 2019)"
            }
            DiskScheme::StbnCp => {
                "spatiotemporal blue-noise masks (Wolfe et al. 2022) rotating a shared (0,2) set per frame (Cranley-Patterson)"
            }
            DiskScheme::SobolBluenoiseT => {
                "sobol-bluenoise rescrambled every frame: a blue-noise arrangement of n-point nets in each frame, independent over frames"
            }
        };
        built_in.into()
    }

    /// Whether the scheme reads per-pixel tables (which the GPU gets as a buffer).
    pub fn uses_tables(self) -> bool {
        matches!(
            self,
            DiskScheme::Pmj02
                | DiskScheme::BluenoiseCp
                | DiskScheme::SobolBluenoise
                | DiskScheme::StbnCp
                | DiskScheme::SobolBluenoiseT
                | DiskScheme::Points(_)
        )
    }

    /// Whether the scheme is one of [`DiskScheme::ALL`] (not a points file).
    pub fn is_built_in(self) -> bool {
        !matches!(self, DiskScheme::Points(_))
    }

    /// The most samples per pixel the scheme can give (its table's size; otherwise unbounded).
    /// A temporal run of F frames of n samples draws F n of them: the caller checks F n fits.
    pub fn max_samples(self) -> u32 {
        match self {
            DiskScheme::Pmj02 => pmj02::MAX_POINTS as u32,
            DiskScheme::Points(id) => id.set().map_or(0, |s| s.count),
            _ => u32::MAX,
        }
    }

    /// Numeric id shared with the WGSL `SCHEME_*` constants: a built-in's place in
    /// [`DiskScheme::ALL`]; every points scheme shares [`POINTS_GPU_ID`] (a frame's tables
    /// carry its one set).
    pub fn gpu_id(self) -> u32 {
        DiskScheme::ALL
            .iter()
            .position(|&s| s == self)
            .map_or(POINTS_GPU_ID, |i| i as u32)
    }

    /// Whether each sample is area-uniform on the disk, making the equal-weight estimator of
    /// visibility unbiased. The paper's schemes are not: they weight the rim more (FACTS.md).
    pub fn is_area_uniform(self) -> bool {
        !matches!(
            self,
            DiskScheme::Paper | DiskScheme::PaperLiteral | DiskScheme::Points(_)
        )
    }

    /// Sample `k` of `n` on the unit disk for the pixel at `site`, in its frame `f`: the
    /// progressive sequences (Sobol', pmj02, blue-noise Sobol') continue at index f n + k under
    /// the same scramble or shift, so F frames of n are the sequence's first F n points; the
    /// per-pixel random schemes draw from a fresh stream ([`Stream::at_frame`]); bluenoise-cp
    /// moves its offsets by f R2 steps ([`bluenoise::offset_at`]); stbn-cp reads its masks' slice
    /// f ([`stbn::offset`]); a points set's tile seed is re-keyed like a stream
    /// ([`rng::at_frame`]), as is sobol-bluenoise-t's, which restarts its sequence every frame.
    /// Frame 0 is the single frame, unchanged.
    pub fn point(self, n: u32, k: u32, site: Site) -> DVec2 {
        debug_assert!(k < n);
        // The re-seeded schemes' stream, and the progressive ones' index (wrapping, as on the GPU).
        let stream = site.stream.at_frame(site.frame);
        let index = site.frame.wrapping_mul(n).wrapping_add(k);
        match self {
            DiskScheme::Uniform => {
                let (u, v) = (stream.unit(2 * k), stream.unit(2 * k + 1));
                polar(u.sqrt(), TAU * v)
            }
            DiskScheme::Paper | DiskScheme::PaperLiteral => {
                if k == 0 {
                    return DVec2::ZERO;
                }
                let theta = TAU * k as f64 / (n - 1) as f64;
                let r = 0.7 * stream.unit(2 * k).sqrt();
                if self == DiskScheme::Paper {
                    polar(0.3 + r, theta)
                } else {
                    DVec2::splat(0.3) + polar(r, theta)
                }
            }
            DiskScheme::Jittered => {
                let (rows, cols) = strata(n);
                let (i, j) = (k % cols, k / cols);
                let u = (i as f64 + stream.unit(2 * k)) / cols as f64;
                let v = (j as f64 + stream.unit(2 * k + 1)) / rows as f64;
                concentric(u, v)
            }
            DiskScheme::Sobol => {
                let (x, y) = sobol::scrambled_sobol_2d(index, site.stream.u32(0x7fff_ffff));
                concentric(rng::to_unit(x), rng::to_unit(y))
            }
            DiskScheme::Spiral => {
                // The angle as a 32-bit fixed-point fraction of a turn: exact on both backends.
                let turn = k.wrapping_mul(GOLDEN_TURN).wrapping_add(stream.u32(0x7fff_fffe));
                let offset = stream.unit(0x7fff_fffd);
                let r = ((k as f64 + offset) / n as f64).sqrt();
                polar(r, TAU * rng::to_unit(turn))
            }
            DiskScheme::Pmj02 => {
                let shift = (site.stream.u32(0x7fff_fffc) >> 8, site.stream.u32(0x7fff_fffb) >> 8);
                let (u, v) = pmj02::point(index, shift);
                concentric(u, v)
            }
            DiskScheme::BluenoiseCp => {
                let [x, y] = site.pixel;
                let (ox, oy) = bluenoise::offset_at(x, y, site.tile_seed, site.frame);
                let (sx, sy) = (sobol::sobol_dim0(k) >> 8, sobol::sobol_dim1(k) >> 8);
                let wrap = |a: u32, b: u32| rng::to_unit((a.wrapping_add(b) & 0x00ff_ffff) << 8);
                concentric(wrap(sx, ox), wrap(sy, oy))
            }
            DiskScheme::SobolBluenoise | DiskScheme::SobolBluenoiseT => {
                // The sequence continued under one scramble, or restarted under the frame's.
                let (index, tile_seed) = match self {
                    DiskScheme::SobolBluenoise => (index, site.tile_seed),
                    _ => (k, rng::at_frame(site.tile_seed, site.frame)),
                };
                let [x, y] = site.pixel;
                let (sx, sy) = sobol::scrambled_sobol_2d(index, bluenoise::scramble(x, y, n, tile_seed));
                concentric(rng::to_unit(sx), rng::to_unit(sy))
            }
            DiskScheme::Points(id) => {
                let tile_seed = rng::at_frame(site.tile_seed, site.frame);
                id.loaded().point(k, site.pixel, tile_seed)
            }
            DiskScheme::StbnCp => {
                let [x, y] = site.pixel;
                let (ox, oy) = stbn::offset(x, y, site.frame, site.tile_seed);
                let (sx, sy) = (sobol::sobol_dim0(k) >> 8, sobol::sobol_dim1(k) >> 8);
                let wrap = |a: u32, b: u32| rng::to_unit((a.wrapping_add(b) & 0x00ff_ffff) << 8);
                concentric(wrap(sx, ox), wrap(sy, oy))
            }
        }
    }

    /// All `n` samples of one pixel.
    pub fn points(self, n: u32, site: Site) -> Vec<DVec2> {
        (0..n).map(|k| self.point(n, k, site)).collect()
    }
}

/// The WGSL id every `points:` scheme samples under (`SCHEME_POINTS`), past the built-ins'.
pub const POINTS_GPU_ID: u32 = DiskScheme::ALL.len() as u32;

/// The golden angle pi (3 - sqrt 5) as a 32-bit fraction of a turn, round(2^32 (3 - sqrt 5) / 2):
/// successive spiral points never line up radially (Vogel 1979).
pub const GOLDEN_TURN: u32 = 0x61c8_8647;

/// floor(sqrt(n)) exactly, digit by digit: the same integer algorithm as the WGSL twin, where a
/// float sqrt may land an ULP low on some drivers.
pub fn isqrt(n: u32) -> u32 {
    let (mut rest, mut root) = (n, 0u32);
    let mut bit = 1u32 << 30;
    while bit > n {
        bit >>= 2;
    }
    while bit != 0 {
        if rest >= root + bit {
            rest -= root + bit;
            root = (root >> 1) + bit;
        } else {
            root >>= 1;
        }
        bit >>= 2;
    }
    root
}

/// Grid of equal strata for n jittered samples: (rows, cols), rows <= cols, rows * cols = n.
pub fn strata(n: u32) -> (u32, u32) {
    let mut rows = isqrt(n);
    while rows > 1 && n % rows != 0 {
        rows -= 1;
    }
    let rows = rows.max(1);
    (rows, n / rows)
}

fn polar(r: f64, theta: f64) -> DVec2 {
    DVec2::new(r * theta.cos(), r * theta.sin())
}

/// Shirley & Chiu's concentric map from the unit square to the unit disk: area-preserving and
/// keeps strata compact, unlike eq. (1)'s polar map.
pub fn concentric(u: f64, v: f64) -> DVec2 {
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return DVec2::ZERO;
    }
    if a.abs() > b.abs() {
        polar(a, FRAC_PI_4 * (b / a))
    } else {
        polar(b, FRAC_PI_2 - FRAC_PI_4 * (a / b))
    }
}

/// Whether a scheme's random numbers are fresh per pixel or one set is shared by all pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Pattern {
    /// A new stream for every pixel: noise, no structure.
    PerPixel,
    /// One precomputed set in a GPU buffer for every pixel, as the paper did ("pre-computed in
    /// advance and stored in a buffer"): no per-pixel noise, but banding and bias shared by all.
    Shared,
}

impl Pattern {
    /// Both patterns, in report order.
    pub const ALL: [Pattern; 2] = [Pattern::PerPixel, Pattern::Shared];

    /// The name used in experiment files and CSV columns.
    pub fn name(self) -> &'static str {
        match self {
            Pattern::PerPixel => "per-pixel",
            Pattern::Shared => "shared",
        }
    }
}

macro_rules! named_enum {
    ($ty:ty, $what:literal) => {
        impl fmt::Display for $ty {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }
        impl FromStr for $ty {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                if let Some(user) = <$ty>::user_named(s) {
                    return user;
                }
                <$ty>::ALL.iter().copied().find(|x| x.name() == s).ok_or_else(|| {
                    let names: Vec<_> = <$ty>::ALL.iter().map(|x| x.name()).collect();
                    format!(
                        "unknown {} `{s}`; expected one of {}{}",
                        $what,
                        names.join(", "),
                        <$ty>::USER_NAMES
                    )
                })
            }
        }
        impl<'de> serde::Deserialize<'de> for $ty {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let s = String::deserialize(d)?;
                s.parse().map_err(serde::de::Error::custom)
            }
        }
        impl serde::Serialize for $ty {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }
    };
}
impl DiskScheme {
    /// What a user may name besides the built-ins, for error messages.
    const USER_NAMES: &'static str = ", or points:NAME";

    /// `points:NAME`, a user's scheme, by name (the experiment naming it loads its set).
    fn user_named(s: &str) -> Option<Result<DiskScheme, String>> {
        let name = s.strip_prefix("points:")?;
        Some(if points::valid_name(name) {
            Ok(DiskScheme::Points(points::PointsId::named(name)))
        } else {
            Err(format!(
                "`{s}`: a points scheme's name is 1 to 64 letters, digits, `-` or `_` (its [points.NAME] table names the file)"
            ))
        })
    }
}

impl Pattern {
    const USER_NAMES: &'static str = "";

    fn user_named(_: &str) -> Option<Result<Pattern, String>> {
        None
    }
}

named_enum!(DiskScheme, "sampling scheme");
named_enum!(Pattern, "pattern");

/// Points on the unit disk for the shared pattern (the paper's precomputed buffer) in frame
/// `frame`.
pub fn shared_points(scheme: DiskScheme, n: u32, seed: u32, light: u32, frame: u32) -> Vec<DVec2> {
    scheme.points(n, Site::shared(seed, light, frame))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strata_cover_n_exactly() {
        for n in 1..=300 {
            let (r, c) = strata(n);
            assert_eq!(r * c, n);
            assert!(r <= c);
        }
        assert_eq!(strata(16), (4, 4));
        assert_eq!(strata(32), (4, 8));
        assert_eq!(strata(7), (1, 7));
    }

    #[test]
    fn concentric_map_hits_corners_and_centre() {
        assert_eq!(concentric(0.5, 0.5), DVec2::ZERO);
        assert!((concentric(1.0, 0.5) - DVec2::new(1.0, 0.0)).length() < 1e-15);
        assert!((concentric(1.0, 1.0).length() - 1.0).abs() < 1e-15);
        assert!((concentric(0.5, 0.0) - DVec2::new(0.0, -1.0)).length() < 1e-15);
    }

    #[test]
    fn paper_scheme_small_counts_are_defined() {
        let s = Site::pixel(1, 0, [0, 0], 0, 0);
        assert_eq!(DiskScheme::Paper.points(1, s), vec![DVec2::ZERO]);
        let two = DiskScheme::Paper.points(2, s);
        assert_eq!(two[0], DVec2::ZERO);
        assert!(two[1].length() >= 0.3 - 1e-12 && two[1].length() <= 1.0);
        // theta_1 = 360 / (2 - 1) degrees: on the +x axis.
        assert!(two[1].y.abs() < 1e-12 && two[1].x > 0.0);
    }

    #[test]
    fn paper_angles_are_evenly_spaced() {
        let s = Site::pixel(5, 0, [9, 0], 9, 0);
        let p = DiskScheme::Paper.points(16, s);
        for (k, q) in p.iter().enumerate().skip(1) {
            let expected = TAU * k as f64 / 15.0;
            let d = (q.y.atan2(q.x) - expected).rem_euclid(TAU);
            assert!(d < 1e-9 || TAU - d < 1e-9, "k={k}");
        }
    }

    #[test]
    fn literal_reading_is_the_intended_one_shifted() {
        let s = Site::pixel(2, 1, [3, 0], 3, 0);
        let a = DiskScheme::Paper.points(16, s);
        let b = DiskScheme::PaperLiteral.points(16, s);
        assert_eq!(b[0], DVec2::ZERO);
        for k in 1..16 {
            // Same angle and random a; radius 0.3 + r versus centre (0.3, 0.3) with radius r.
            let r = a[k].length() - 0.3;
            assert!(((b[k] - DVec2::splat(0.3)).length() - r).abs() < 1e-12);
        }
    }

    /// Sample k of n at frame 0 as written before frames existed: every committed result was
    /// drawn with these formulas.
    fn single_frame(scheme: DiskScheme, n: u32, k: u32, site: Site) -> DVec2 {
        let stream = site.stream;
        let [x, y] = site.pixel;
        match scheme {
            DiskScheme::Uniform => polar(stream.unit(2 * k).sqrt(), TAU * stream.unit(2 * k + 1)),
            DiskScheme::Paper | DiskScheme::PaperLiteral if k == 0 => DVec2::ZERO,
            DiskScheme::Paper => polar(0.3 + 0.7 * stream.unit(2 * k).sqrt(), TAU * k as f64 / (n - 1) as f64),
            DiskScheme::PaperLiteral => {
                DVec2::splat(0.3) + polar(0.7 * stream.unit(2 * k).sqrt(), TAU * k as f64 / (n - 1) as f64)
            }
            DiskScheme::Jittered => {
                let (rows, cols) = strata(n);
                let u = ((k % cols) as f64 + stream.unit(2 * k)) / cols as f64;
                concentric(u, ((k / cols) as f64 + stream.unit(2 * k + 1)) / rows as f64)
            }
            DiskScheme::Sobol => {
                let (a, b) = sobol::scrambled_sobol_2d(k, stream.u32(0x7fff_ffff));
                concentric(rng::to_unit(a), rng::to_unit(b))
            }
            DiskScheme::Spiral => {
                let turn = k.wrapping_mul(GOLDEN_TURN).wrapping_add(stream.u32(0x7fff_fffe));
                let r = ((k as f64 + stream.unit(0x7fff_fffd)) / n as f64).sqrt();
                polar(r, TAU * rng::to_unit(turn))
            }
            DiskScheme::Pmj02 => {
                let (u, v) = pmj02::point(k, (stream.u32(0x7fff_fffc) >> 8, stream.u32(0x7fff_fffb) >> 8));
                concentric(u, v)
            }
            DiskScheme::BluenoiseCp => {
                let (ox, oy) = bluenoise::offset(x, y, site.tile_seed);
                let (sx, sy) = (sobol::sobol_dim0(k) >> 8, sobol::sobol_dim1(k) >> 8);
                let wrap = |a: u32, b: u32| rng::to_unit((a.wrapping_add(b) & 0x00ff_ffff) << 8);
                concentric(wrap(sx, ox), wrap(sy, oy))
            }
            // Newer than frames: its single frame is sobol-bluenoise's.
            DiskScheme::SobolBluenoise | DiskScheme::SobolBluenoiseT => {
                let (a, b) = sobol::scrambled_sobol_2d(k, bluenoise::scramble(x, y, n, site.tile_seed));
                concentric(rng::to_unit(a), rng::to_unit(b))
            }
            // Newer than frames: its single frame is frame 0 of the stack.
            DiskScheme::StbnCp => {
                let (ox, oy) = stbn::offset(x, y, 0, site.tile_seed);
                let (sx, sy) = (sobol::sobol_dim0(k) >> 8, sobol::sobol_dim1(k) >> 8);
                let wrap = |a: u32, b: u32| rng::to_unit((a.wrapping_add(b) & 0x00ff_ffff) << 8);
                concentric(wrap(sx, ox), wrap(sy, oy))
            }
            DiskScheme::Points(_) => unreachable!("not a built-in"),
        }
    }

    /// Frame 0 gives every built-in scheme's points bit for bit as before frames existed, per
    /// pixel and shared; a points set's re-keyed tile seed is its own at frame 0.
    #[test]
    fn frame_zero_is_the_single_frame() {
        for scheme in DiskScheme::ALL {
            for n in [1u32, 2, 7, 16, 33] {
                for site in [Site::pixel(3, 1, [5, 9], 581, 0), Site::shared(3, 1, 0)] {
                    for k in 0..n {
                        let (got, want) = (scheme.point(n, k, site), single_frame(scheme, n, k, site));
                        assert_eq!(got.to_array().map(f64::to_bits), want.to_array().map(f64::to_bits));
                    }
                }
            }
        }
        assert_eq!(rng::at_frame(0x1234_5678, 0), 0x1234_5678);
        assert_eq!(bluenoise::offset_at(5, 9, 77, 0), bluenoise::offset(5, 9, 77));
    }

    /// Sobol' and pmj02 continue their sequences: frames 0..F of n samples are exactly the first
    /// F n samples of frame 0 (their points do not depend on n).
    #[test]
    fn progressive_frames_continue_the_sequence() {
        let site = |frame| Site::pixel(8, 0, [17, 4], 273, frame);
        for scheme in [DiskScheme::Sobol, DiskScheme::Pmj02] {
            for (frames, n) in [(4u32, 1u32), (5, 3), (8, 16), (3, 64)] {
                let all = scheme.points(frames * n, site(0));
                let walked: Vec<DVec2> = (0..frames).flat_map(|f| scheme.points(n, site(f))).collect();
                assert_eq!(walked, all, "{scheme}: {frames} frames of {n}");
            }
        }
        // Blue-noise Sobol' (whose scramble table depends on n) walks the same way under its own n.
        let s = DiskScheme::SobolBluenoise;
        let (x, y) = sobol::scrambled_sobol_2d(3 * 16 + 5, bluenoise::scramble(17, 4, 16, bluenoise::tile_seed(8, 0)));
        assert_eq!(s.point(16, 5, site(3)), concentric(rng::to_unit(x), rng::to_unit(y)));
    }

    /// The re-seeded schemes draw frame f from the stream's frame-f key, bluenoise-cp moves its
    /// offset by f R2 steps (stbn-cp's frames: [`stbn_cp_reads_the_frames_slice`]); frame 1
    /// differs from frame 0 for every built-in scheme.
    #[test]
    fn other_frames_reseed_or_move() {
        use DiskScheme::{Jittered, Paper, PaperLiteral, Spiral, Uniform};
        let site = |frame| Site::pixel(8, 2, [40, 7], 488, frame);
        for scheme in DiskScheme::ALL {
            let n = 16;
            assert_ne!(scheme.points(n, site(1)), scheme.points(n, site(0)), "{scheme}");
            if [Uniform, Paper, PaperLiteral, Jittered, Spiral].contains(&scheme) {
                for f in [1u32, 5, u32::MAX] {
                    let fresh = Site {
                        stream: site(0).stream.at_frame(f),
                        ..site(0)
                    };
                    assert_eq!(scheme.points(n, site(f)), scheme.points(n, fresh), "{scheme} frame {f}");
                }
            }
        }
        let (ox, oy) = bluenoise::offset(40, 7, bluenoise::tile_seed(8, 2));
        let (r1, r2) = bluenoise::R2_STEP;
        let moved = ((ox + 5 * r1) & 0x00ff_ffff, (oy + 5 * r2) & 0x00ff_ffff);
        assert_eq!(bluenoise::offset_at(40, 7, bluenoise::tile_seed(8, 2), 5), moved);
    }

    /// stbn-cp rotates bluenoise-cp's shared set by the STBN offset of the site's frame: frames
    /// wrap with the masks' depth (a 32-bit frame counter's wrap included), and a pixel's offsets
    /// over one period are not all alike.
    #[test]
    fn stbn_cp_reads_the_frames_slice() {
        let site = |frame| Site::pixel(8, 2, [40, 7], 488, frame);
        let n = 16;
        for f in [0u32, 1, 5, 31, 77] {
            let (ox, oy) = stbn::offset(40, 7, f, bluenoise::tile_seed(8, 2));
            for k in 0..n {
                let (sx, sy) = (sobol::sobol_dim0(k) >> 8, sobol::sobol_dim1(k) >> 8);
                let u = rng::to_unit(((sx + ox) & 0x00ff_ffff) << 8);
                let v = rng::to_unit(((sy + oy) & 0x00ff_ffff) << 8);
                assert_eq!(
                    DiskScheme::StbnCp.point(n, k, site(f)),
                    concentric(u, v),
                    "frame {f} k={k}"
                );
            }
            let depth = stbn::DEPTH as u32;
            assert_eq!(
                DiskScheme::StbnCp.points(n, site(f + depth)),
                DiskScheme::StbnCp.points(n, site(f))
            );
        }
        let last = DiskScheme::StbnCp.points(n, site(u32::MAX));
        assert_eq!(last, DiskScheme::StbnCp.points(n, site(stbn::DEPTH as u32 - 1)));
        let firsts: std::collections::BTreeSet<[u64; 2]> = (0..stbn::DEPTH as u32)
            .map(|f| DiskScheme::StbnCp.point(n, 0, site(f)).to_array().map(f64::to_bits))
            .collect();
        assert_eq!(firsts.len(), stbn::DEPTH, "one slice per frame");
    }

    #[test]
    fn integer_square_roots_are_exact() {
        for n in 0..=(1u32 << 20) {
            assert_eq!(isqrt(n), n.isqrt(), "{n}");
        }
        for n in [
            u32::MAX,
            u32::MAX - 1,
            65535 * 65535,
            65536 * 65535,
            (1 << 31) - 1,
            1 << 31,
        ] {
            assert_eq!(isqrt(n), n.isqrt(), "{n}");
        }
    }

    #[test]
    fn names_round_trip_and_unknown_names_are_listed() {
        for s in DiskScheme::ALL {
            assert_eq!(s.name().parse::<DiskScheme>().unwrap(), s);
        }
        let e = "halton".parse::<DiskScheme>().unwrap_err();
        assert!(e.contains("halton") && e.contains("paper-literal"), "{e}");
    }
}
