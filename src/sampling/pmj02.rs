//! Progressive multi-jittered (0,2) sequences (Christensen, Kensler & Kilpatrick 2018,
//! "Progressive Multi-Jittered Sample Sequences", Section 5): every prefix of 2^m points puts one
//! point in each elementary interval of area 2^-m (each 2^a x 2^(m-a) grid), so any prefix a
//! ray count takes is stratified like a (0,2)-sequence's, with jitter inside the strata.
//!
//! The sequence is built once (seeded, [`MAX_POINTS`] points) and shared: a pixel draws its
//! samples from it through its own random digital shift (an XOR of the 24-bit coordinates),
//! which maps elementary intervals onto elementary intervals and so keeps every prefix's
//! stratification ([`crate::sampling::DiskScheme::Pmj02`]).

use super::rng::{pcg, to_unit};

/// Points in the shared sequence, and so the most rays pmj02 samples (experiments asking for
/// more are refused: point k would repeat point k - 4096).
pub const MAX_POINTS: usize = 4096;

/// Seed of the shared sequence (recorded in the report).
pub const SEED: u32 = 0x0b1e_5eed;

/// Bits of a coordinate: the points lie on a 2^24 grid, exact in f32 and f64 alike.
const BITS: u32 = 24;

/// Occupied elementary intervals of the points placed so far, for a total of `2^m` points.
struct Strata {
    m: u32,
    /// Per shape a (2^a x 2^(m-a) cells), a bit per cell.
    occupied: Vec<Vec<bool>>,
}

impl Strata {
    fn new(m: u32) -> Strata {
        Strata {
            m,
            occupied: (0..=m).map(|_| vec![false; 1 << m]).collect(),
        }
    }

    fn cells(&self, x: u32, y: u32) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..=self.m).map(move |a| {
            let (cx, cy) = (x >> (BITS - a), y >> (BITS - (self.m - a)));
            (a as usize, ((cy << a) | cx) as usize)
        })
    }

    fn free(&self, x: u32, y: u32) -> bool {
        self.cells(x, y).all(|(a, c)| !self.occupied[a][c])
    }

    fn mark(&mut self, x: u32, y: u32) {
        let cells: Vec<(usize, usize)> = self.cells(x, y).collect();
        for (a, c) in cells {
            self.occupied[a][c] = true;
        }
    }
}

/// A seeded stream of 32-bit values.
struct Rng(u32);

impl Rng {
    fn next(&mut self) -> u32 {
        self.0 = pcg(self.0.wrapping_add(0x9e37_79b9));
        self.0
    }
}

/// A point of the 2^24 grid inside the sub-square `(i + xh/2, j + yh/2) / n` of side 1/(2n)
/// that no occupied elementary interval holds; `None` when seeded tries find none.
fn place(rng: &mut Rng, strata: &Strata, (i, j): (u32, u32), (xh, yh): (u32, u32), n: u32) -> Option<(u32, u32)> {
    let side = (1u32 << BITS) / (2 * n);
    for _ in 0..100_000 {
        let x = (2 * i + xh) * side + rng.next() % side;
        let y = (2 * j + yh) * side + rng.next() % side;
        if strata.free(x, y) {
            return Some((x, y));
        }
    }
    None
}

/// The first `count` (a power of two) points of a pmj02 sequence seeded with `seed`, as 24-bit
/// fixed-point coordinates.
pub fn generate(count: usize, seed: u32) -> Vec<[u32; 2]> {
    assert!(count.is_power_of_two() && count <= 1 << 20, "a power of two points");
    let mut rng = Rng(pcg(seed));
    let mut points = vec![[rng.next() >> (32 - BITS), rng.next() >> (32 - BITS)]];
    let sub = |p: u32, n: u32| {
        // Stratum index and which half of it, at n strata per axis.
        let cell = (p as u64 * n as u64) >> BITS;
        let half = ((p as u64 * 2 * n as u64) >> BITS) & 1;
        (cell as u32, half as u32)
    };
    while points.len() < count {
        let total = points.len();
        let n = (total as f64).sqrt().round() as u32;
        let m = (2 * total).trailing_zeros();
        if n * n == total as u32 {
            // Even step, N = n^2 -> 2N: each new point in the sub-square diagonally opposite
            // its parent's within the parent's stratum.
            let mut strata = Strata::new(m);
            for p in &points {
                strata.mark(p[0], p[1]);
            }
            for s in 0..total {
                let [x, y] = points[s];
                let ((i, xh), (j, yh)) = (sub(x, n), sub(y, n));
                let q = place(&mut rng, &strata, (i, j), (1 - xh, 1 - yh), n)
                    .expect("a pmj02 point in the diagonally opposite sub-square");
                strata.mark(q.0, q.1);
                points.push([q.0, q.1]);
            }
        } else {
            // Odd step, N = 2 n^2 -> 2N: the two sub-squares of each stratum not yet used, one
            // from each parent of the previous step, in a random one of the two assignments.
            let n = ((total / 2) as f64).sqrt().round() as u32;
            let mut strata = Strata::new(m);
            for p in &points {
                strata.mark(p[0], p[1]);
            }
            let half = total / 2;
            for s in 0..half {
                let [x, y] = points[s];
                let ((i, xh), (j, yh)) = (sub(x, n), sub(y, n));
                let flip_x = rng.next() & 1 == 1;
                let (a, b) = if flip_x {
                    ((1 - xh, yh), (xh, 1 - yh))
                } else {
                    ((xh, 1 - yh), (1 - xh, yh))
                };
                let first = place(&mut rng, &strata, (i, j), a, n);
                let first = match first {
                    Some(q) => (q, b),
                    None => {
                        let q = place(&mut rng, &strata, (i, j), b, n).expect("a pmj02 point in a free sub-square");
                        (q, a)
                    }
                };
                strata.mark(first.0 .0, first.0 .1);
                let second = place(&mut rng, &strata, (i, j), first.1, n)
                    .expect("a pmj02 point in the last sub-square of its stratum");
                strata.mark(second.0, second.1);
                points.push([first.0 .0, first.0 .1]);
                points.push([second.0, second.1]);
            }
            // Keep the progressive order: the new points alternate between the two halves.
            let new: Vec<[u32; 2]> = points.split_off(total);
            let (evens, odds): (Vec<_>, Vec<_>) = new.chunks(2).map(|c| (c[0], c[1])).unzip();
            points.extend(evens);
            points.extend(odds);
        }
    }
    points.truncate(count);
    points
}

/// The shared sequence ([`MAX_POINTS`] points, [`SEED`]), built once.
pub fn shared() -> &'static [[u32; 2]] {
    static POINTS: std::sync::OnceLock<Vec<[u32; 2]>> = std::sync::OnceLock::new();
    POINTS.get_or_init(|| generate(MAX_POINTS, SEED))
}

/// Point `k` of the shared sequence under a pixel's digital shift `shift` (24 bits per axis),
/// in [0, 1)^2.
pub fn point(k: u32, shift: (u32, u32)) -> (f64, f64) {
    let p = shared()[k as usize % MAX_POINTS];
    (to_unit((p[0] ^ shift.0) << 8), to_unit((p[1] ^ shift.1) << 8))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every prefix of 2^m points holds one point in every elementary interval of area 2^-m:
    /// all m + 1 shapes, every cell exactly once.
    fn prefixes_are_02_nets(points: &[[u32; 2]], shift: (u32, u32)) {
        let mut m = 0;
        while (1usize << m) <= points.len() {
            let prefix = &points[..1 << m];
            for a in 0..=m {
                let mut seen = vec![0u32; 1 << m];
                for p in prefix {
                    let (x, y) = (p[0] ^ shift.0, p[1] ^ shift.1);
                    let (cx, cy) = (x >> (BITS - a), y >> (BITS - (m - a)));
                    seen[((cy << a) | cx) as usize] += 1;
                }
                assert!(seen.iter().all(|&c| c == 1), "m = {m}, shape 2^{a} x 2^{}", m - a);
            }
            m += 1;
        }
    }

    #[test]
    fn every_power_of_two_prefix_fills_every_elementary_interval_once() {
        let points = generate(1024, 7);
        prefixes_are_02_nets(&points, (0, 0));
        // A pixel's digital shift keeps it.
        prefixes_are_02_nets(&points, (0x00ab_cdef, 0x0012_3456));
        prefixes_are_02_nets(&shared()[..256], (0x0055_aa55, 0x00ff_0001));
    }

    #[test]
    fn the_sequence_is_seeded_and_its_points_lie_in_the_unit_square() {
        assert_eq!(generate(64, 3), generate(64, 3));
        assert_ne!(generate(64, 3), generate(64, 4));
        let (x, y) = point(5, (0x00ff_ffff, 0));
        assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
    }
}
