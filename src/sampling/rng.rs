//! Counter-based random numbers shared bit for bit by the CPU backend and the WGSL shaders.
//!
//! Every random value is a pure function of (stream, index), so a pixel's shadow-ray targets do
//! not depend on evaluation order, thread count or backend. The GPU copy lives in
//! `render/gpu/shaders/sampling.wgsl`; `tests/gpu_backend.rs` checks that the two agree.

/// PCG-RXS-M-XS 32-bit output permutation (Jarzynski & Olano, "Hash Functions for GPU
/// Rendering", JCGT 9(3), 2020): the best quality/speed trade-off among 32-bit GPU hashes there.
#[inline]
pub fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The constant a frame index is offset by before it is hashed into a key ([`at_frame`]):
/// distinct from the pixel's and the index's.
pub const FRAME_KEY: u32 = 0x2545_f491;

/// `key` re-keyed for frame `frame` of a temporal sequence: unchanged at frame 0 (a single frame
/// draws what it always did), else hashed with the frame ([`Stream::at_frame`], points' tile seed).
#[inline]
pub fn at_frame(key: u32, frame: u32) -> u32 {
    if frame == 0 {
        key
    } else {
        pcg(key ^ pcg(frame.wrapping_add(FRAME_KEY)))
    }
}

/// A stream of independent random numbers, identified by a 32-bit key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stream(pub u32);

impl Stream {
    /// The stream of pixel `pixel` for light `light` in a run seeded with `seed`.
    /// `None` for the pixel gives the stream shared by every pixel (the paper's precomputed set).
    pub fn new(seed: u32, light: u32, pixel: Option<u32>) -> Self {
        let base = pcg(seed ^ pcg(light.wrapping_add(0x68e3_1da4)));
        match pixel {
            Some(p) => Stream(pcg(base ^ pcg(p.wrapping_add(0x1b56_c4e9)))),
            None => Stream(pcg(base ^ 0x5bd1_e995)),
        }
    }

    /// The stream of frame `frame` of a temporal sequence: frame 0 is this stream unchanged (so a
    /// single frame draws what it always did), every other frame a fresh key hashed from both.
    pub fn at_frame(self, frame: u32) -> Self {
        Stream(at_frame(self.0, frame))
    }

    /// The `index`-th 32-bit value of the stream.
    #[inline]
    pub fn u32(self, index: u32) -> u32 {
        pcg(self.0 ^ pcg(index.wrapping_add(0x9e37_79b9)))
    }

    /// The `index`-th value as a float in [0, 1) with 24 bits, exactly representable in f32,
    /// so the CPU (f64) and GPU (f32) see the same number.
    #[inline]
    pub fn unit(self, index: u32) -> f64 {
        to_unit(self.u32(index))
    }
}

/// Top 24 bits of `x` as a float in [0, 1).
#[inline]
pub fn to_unit(x: u32) -> f64 {
    (x >> 8) as f64 * (1.0 / 16_777_216.0)
}

/// A sequential seeded generator of uniform numbers, for test fixtures and benchmarks: the same
/// seed gives the same rays in every test and bench that draws them (not for rendering, whose
/// numbers are [`Stream`]s, pure functions of their index).
#[derive(Clone, Debug)]
pub struct Seeded(pub u32);

impl Seeded {
    /// A uniform number in [0, 1) with 53 random bits (two hashes).
    pub fn f(&mut self) -> f64 {
        self.0 = pcg(self.0);
        let hi = pcg(self.0 ^ 0x9e37_79b9);
        (self.0 as f64 + hi as f64 / 4_294_967_296.0) / 4_294_967_296.0
    }

    /// A uniform number in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.f()
    }

    /// A uniform index below `n` (n > 0).
    pub fn index(&mut self, n: usize) -> usize {
        ((self.f() * n as f64) as usize).min(n - 1)
    }

    /// A uniform unit vector (rejection from the ball, short vectors refused).
    pub fn unit(&mut self) -> glam::DVec3 {
        loop {
            let v = glam::DVec3::new(self.range(-1., 1.), self.range(-1., 1.), self.range(-1., 1.));
            let l = v.length();
            if l > 1e-3 && l <= 1.0 {
                return v / l;
            }
        }
    }

    /// A uniform point of triangle `t`.
    pub fn point_on(&mut self, t: &[glam::DVec3; 3]) -> glam::DVec3 {
        let (mut a, mut b) = (self.f(), self.f());
        if a + b > 1.0 {
            (a, b) = (1.0 - a, 1.0 - b);
        }
        t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeded_draws_repeat_per_seed_and_fill_their_ranges() {
        let draw = |seed| {
            let mut r = Seeded(seed);
            (0..1000).map(|_| r.f()).collect::<Vec<f64>>()
        };
        let (a, b) = (draw(5), draw(6));
        assert_eq!(a, draw(5));
        assert_ne!(a, b);
        assert!(a.iter().all(|x| (0.0..1.0).contains(x)));
        // 1000 uniform draws: the mean within 5 standard errors of 1/2 (sigma = 1/sqrt(12000)).
        let mean = a.iter().sum::<f64>() / 1000.0;
        assert!((mean - 0.5).abs() < 5.0 * (1.0f64 / 12000.0).sqrt(), "{mean}");
        let mut r = Seeded(9);
        let t = [glam::DVec3::ZERO, glam::DVec3::X, glam::DVec3::Y];
        for _ in 0..1000 {
            let u = r.unit();
            assert!((u.length() - 1.0).abs() < 1e-12);
            let p = r.point_on(&t);
            assert!(p.x >= 0.0 && p.y >= 0.0 && p.x + p.y <= 1.0 && p.z == 0.0, "{p}");
            assert!(r.index(7) < 7);
        }
    }

    #[test]
    fn unit_values_are_in_range_and_exact_in_f32() {
        let s = Stream::new(7, 0, Some(123));
        for i in 0..10_000 {
            let u = s.unit(i);
            assert!((0.0..1.0).contains(&u));
            assert_eq!(u as f32 as f64, u);
        }
    }

    #[test]
    fn streams_differ_by_pixel_light_and_seed() {
        let a = Stream::new(1, 0, Some(5));
        assert_ne!(a, Stream::new(1, 0, Some(6)));
        assert_ne!(a, Stream::new(1, 1, Some(5)));
        assert_ne!(a, Stream::new(2, 0, Some(5)));
        assert_ne!(Stream::new(1, 0, None), Stream::new(2, 0, None));
    }

    #[test]
    fn frame_zero_is_the_stream_and_other_frames_differ() {
        let s = Stream::new(4, 1, Some(77));
        assert_eq!(s.at_frame(0), s);
        assert_eq!(s.at_frame(1), Stream(pcg(s.0 ^ pcg(1u32.wrapping_add(0x2545_f491)))));
        let keys: std::collections::HashSet<u32> = (0..64).map(|f| s.at_frame(f).0).collect();
        assert_eq!(keys.len(), 64);
    }

    #[test]
    fn unit_mean_and_variance_match_uniform() {
        let s = Stream::new(3, 0, None);
        let n = 200_000;
        let (mut m, mut m2) = (0.0, 0.0);
        for i in 0..n {
            let u = s.unit(i);
            m += u;
            m2 += u * u;
        }
        m /= n as f64;
        m2 /= n as f64;
        // Standard errors: 1/sqrt(12 n) ~ 6.5e-4 for the mean; 5 sigma bounds.
        assert!((m - 0.5).abs() < 3.3e-3, "mean {m}");
        assert!((m2 - m * m - 1.0 / 12.0).abs() < 3e-3, "variance {}", m2 - m * m);
    }
}
