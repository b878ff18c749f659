//! Owen-scrambled Sobol' points in two dimensions, after Burley, "Practical Hash-based Owen
//! Scrambling", JCGT 9(4), 2020: at 16 samples it reports about 12x lower RMSE than independent
//! random sampling for direct lighting (FACTS.md).

/// First Sobol' dimension: the van der Corput radical inverse in base 2.
#[inline]
pub fn sobol_dim0(index: u32) -> u32 {
    index.reverse_bits()
}

/// Second Sobol' dimension (primitive polynomial x + 1): direction numbers v_k = v_{k-1} ^ (v_{k-1} >> 1).
#[inline]
pub fn sobol_dim1(mut index: u32) -> u32 {
    let mut v: u32 = 1 << 31;
    let mut x = 0;
    while index != 0 {
        if index & 1 != 0 {
            x ^= v;
        }
        index >>= 1;
        v ^= v >> 1;
    }
    x
}

/// Burley's improved Laine-Karras permutation: bit k depends only on lower bits, so applied to
/// bit-reversed values it is a nested uniform (Owen) scramble.
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x
}

/// Nested uniform scramble of a 32-bit binary fraction.
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// Sample `index` of a shuffled, Owen-scrambled 2-D Sobol' sequence, as 32-bit fractions.
/// The index is shuffled by the same scramble (Burley sec. 4) so that a prefix is a random block.
pub fn scrambled_sobol_2d(index: u32, seed: u32) -> (u32, u32) {
    let shuffled = owen_scramble(index, super::rng::pcg(seed ^ 0xa511_e9b3));
    let x = owen_scramble(sobol_dim0(shuffled), super::rng::pcg(seed ^ 0x63d8_3595));
    let y = owen_scramble(sobol_dim1(shuffled), super::rng::pcg(seed ^ 0x2c1b_3c6d));
    (x, y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every elementary interval of volume 2^-m holds exactly one of the first 2^m points:
    /// the (0, m, 2)-net property that makes Sobol' stratify at every power of two.
    fn assert_net(points: &[(u32, u32)], m: u32) {
        for split in 0..=m {
            let (bx, by) = (split, m - split);
            let mut seen = vec![0u32; 1 << m];
            for &(x, y) in points {
                let cx = if bx == 0 { 0 } else { x >> (32 - bx) };
                let cy = if by == 0 { 0 } else { y >> (32 - by) };
                seen[((cx << by) | cy) as usize] += 1;
            }
            assert!(seen.iter().all(|&c| c == 1), "m={m} split={split}");
        }
    }

    #[test]
    fn first_points_are_the_textbook_ones() {
        let p: Vec<_> = (0..4).map(|i| (sobol_dim0(i), sobol_dim1(i))).collect();
        let h = 1u32 << 31;
        assert_eq!(p, vec![(0, 0), (h, h), (h >> 1, h + (h >> 1)), (h + (h >> 1), h >> 1)]);
    }

    #[test]
    fn unscrambled_and_scrambled_prefixes_are_nets() {
        for m in 0..=8 {
            let plain: Vec<_> = (0..1u32 << m).map(|i| (sobol_dim0(i), sobol_dim1(i))).collect();
            assert_net(&plain, m);
            for seed in [1u32, 99, 0xdead_beef] {
                let s: Vec<_> = (0..1u32 << m).map(|i| scrambled_sobol_2d(i, seed)).collect();
                assert_net(&s, m);
            }
        }
    }

    #[test]
    fn scrambling_depends_on_seed() {
        assert_ne!(scrambled_sobol_2d(3, 1), scrambled_sobol_2d(3, 2));
    }
}
