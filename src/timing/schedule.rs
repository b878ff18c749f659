//! The visiting order: seeded, counterbalanced interleaved rounds (the module doc of
//! [`super`] says why).

use crate::sampling::rng::pcg;
use serde::{Deserialize, Serialize};

/// Default seed of the visiting order, where an experiment file gives none (recorded in the
/// manifest either way).
pub const DEFAULT_SEED: u32 = 0x510e_527f;

/// How an experiment's timed units are visited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Schedule {
    /// Seed of the visiting order and of the bootstrap.
    pub seed: u32,
    /// Untimed frames right before each timed one.
    pub warmup: u32,
    /// Interleaved rounds: timed frames per unit.
    pub repeats: u32,
}

impl Schedule {
    /// The order in which round `round` visits `n` units: for an even round a Fisher-Yates
    /// shuffle over a counter-based stream of the seed (the same for the same seed on every
    /// machine), for an odd round the reverse of the round before.
    pub fn order(&self, n: usize, round: u32) -> Vec<usize> {
        if round % 2 == 1 {
            let mut v = self.order(n, round - 1);
            v.reverse();
            return v;
        }
        let mut v: Vec<usize> = (0..n).collect();
        let stream = pcg(self.seed ^ pcg(round));
        for i in (1..n).rev() {
            let j = pcg(stream ^ pcg(i as u32)) as usize % (i + 1);
            v.swap(i, j);
        }
        v
    }

    /// Times `n` units over every round: `visit(unit)` renders the unit's warm-up frames and
    /// returns the seconds of its timed frame. The result holds, per unit, one time per round
    /// in round order (so units are paired by round).
    pub fn run<E>(&self, n: usize, mut visit: impl FnMut(usize) -> Result<f64, E>) -> Result<Vec<Vec<f64>>, E> {
        let mut out = vec![Vec::with_capacity(self.repeats as usize); n];
        for round in 0..self.repeats {
            for unit in self.order(n, round) {
                out[unit].push(visit(unit)?);
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_are_seeded_permutations_that_differ_between_rounds() {
        let s = Schedule {
            seed: 7,
            warmup: 0,
            repeats: 5,
        };
        let rounds: Vec<Vec<usize>> = (0..5).map(|r| s.order(50, r)).collect();
        for o in &rounds {
            let mut sorted = o.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..50).collect::<Vec<_>>());
        }
        assert!(rounds.windows(2).all(|w| w[0] != w[1]));
        for pair in rounds.chunks(2).filter(|c| c.len() == 2) {
            assert!(
                pair[0].iter().eq(pair[1].iter().rev()),
                "odd rounds reverse the even ones"
            );
        }
        assert_ne!(rounds[0], rounds[2], "every even round draws afresh");
        assert_eq!(s.order(50, 3), rounds[3]);
        assert_ne!(Schedule { seed: 8, ..s }.order(50, 3), rounds[3], "the seed matters");
        let mut visits = Vec::new();
        let times = s
            .run(3, |u| {
                visits.push(u);
                Ok::<_, ()>(u as f64)
            })
            .unwrap();
        assert_eq!(visits.len(), 15);
        assert_eq!(times, vec![vec![0.0; 5], vec![1.0; 5], vec![2.0; 5]]);
    }
}
