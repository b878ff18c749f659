//! Sequential timing: rounds are added only while a comparison the report states is still
//! undecided, and the units compared with each other are visited back to back.
//!
//! **Blocks.** A round visits every open block in a seeded order and, inside a block, its units
//! in a seeded order; the odd round after an even one reverses the whole visit (ABBA, as
//! [`Schedule`] does for a flat list). Units that are compared sit in one block, so the ratio of
//! a pair is taken over frames a few hundred milliseconds apart: a machine that changes speed
//! for a while (another process, a clock step, lavapipe's two modes) slows both alike, where a
//! flat shuffle of hundreds of units would put them tens of seconds apart.
//!
//! **Looks.** After `first_look` rounds and every `every` rounds after, up to `cap`, each open
//! comparison reads its word from the 95 % interval of its paired per-round ratios
//! ([`Comparison::of`]); a decided word (faster, slower, equivalent) closes it, and a unit stops
//! being visited once every comparison it takes part in is closed. A unit in no comparison is
//! timed for `first_look` rounds. What each comparison took (rounds, word) is returned, so a
//! report can say how many rounds each answer took. The false-word rate and the power of this
//! stopping rule are measured by simulation in this module's tests.

use super::interval::paired_ratio;
use super::rule::Comparison;
use super::schedule::Schedule;
use super::Estimate;
use serde::{Deserialize, Serialize};

/// When a sequential design looks at its comparisons, and when it gives up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Looks {
    /// Rounds before the first look: at least 6, the fewest whose order-statistic interval of a
    /// median covers 95 %.
    pub first_look: u32,
    /// Rounds between looks.
    pub every: u32,
    /// Most rounds: a comparison still undecided there stays undecided.
    pub cap: u32,
}

impl Looks {
    /// The fewest rounds a look is taken at.
    pub const FEWEST: u32 = 6;

    /// Looks at 6, 9, 12, ... rounds up to `cap` (and at `cap`): the design the simulation in
    /// this module's tests measures.
    pub fn up_to(cap: u32) -> Looks {
        Looks {
            first_look: Self::FEWEST.min(cap),
            every: 3,
            cap,
        }
    }

    /// Whether the design looks after `rounds` rounds.
    pub fn looks_at(&self, rounds: u32) -> bool {
        rounds == self.cap
            || (rounds >= self.first_look && rounds < self.cap && (rounds - self.first_look) % self.every == 0)
    }
}

impl Default for Looks {
    /// One look, at the fewest rounds.
    fn default() -> Looks {
        Looks::up_to(Looks::FEWEST)
    }
}

/// One comparison a report states: the time ratio of unit `a` over unit `b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pair {
    /// The unit in the numerator.
    pub a: usize,
    /// The unit in the denominator.
    pub b: usize,
}

/// What a comparison came to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decided {
    /// The paired ratio a / b over the rounds both were visited in, with its interval.
    pub ratio: Estimate,
    /// The rule's word at the look that closed it (or at the cap).
    pub word: Comparison,
    /// Rounds it took.
    pub rounds: u32,
}

/// Result of a sequential timing: per unit its seconds, one per round it was visited in (a
/// prefix of the rounds), and per comparison what it came to.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SequentialTimes {
    /// Per unit, seconds per round visited, in round order.
    pub seconds: Vec<Vec<f64>>,
    /// Per comparison, in the order given.
    pub decided: Vec<Decided>,
    /// Rounds run in all.
    pub rounds: u32,
}

/// How far a sequential timing has come: passed to the caller after each round.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RoundDone {
    /// Rounds done.
    pub rounds: u32,
    /// Comparisons still undecided.
    pub open: usize,
    /// Units still visited in the next round.
    pub units: usize,
}

/// The word of the ratio a / b over these rounds.
fn at(a: &[f64], b: &[f64], rounds: u32) -> Decided {
    let ratio = paired_ratio(a, b);
    Decided {
        ratio,
        word: Comparison::of(&ratio),
        rounds,
    }
}

/// Whether a look closes a comparison: its word is decided, or a unit failed (any non-finite
/// time: no more rounds can give it an interval).
fn closes(d: &Decided, a: &[f64], b: &[f64]) -> bool {
    d.word.decided() || a.iter().chain(b).any(|v| !v.is_finite())
}

/// What the stopping rule made of two series timed under `looks` (or would have): the first
/// look, over the rounds both were visited in, at which the word is decided or a time is not
/// finite; else the word over all their common rounds. Replaying the rule on the committed
/// per-round times gives the words a sequential timing gave, so a report's every word
/// recomputes from its CSV.
pub fn decide(a: &[f64], b: &[f64], looks: Looks) -> Decided {
    let common = a.len().min(b.len());
    for rounds in 1..=common as u32 {
        if looks.looks_at(rounds) {
            let (x, y) = (&a[..rounds as usize], &b[..rounds as usize]);
            let d = at(x, y, rounds);
            if closes(&d, x, y) {
                return d;
            }
        }
    }
    at(&a[..common], &b[..common], common as u32)
}

impl Schedule {
    /// The order in which round `round` visits `blocks` (each a list of unit indices), open
    /// units only: blocks shuffled and units shuffled inside each on even rounds, the even
    /// round's whole visit reversed on odd ones.
    pub fn block_order(&self, blocks: &[Vec<usize>], round: u32) -> Vec<usize> {
        let even = round - round % 2;
        let mut visit = Vec::new();
        for b in self.order(blocks.len(), even) {
            let inner = Schedule {
                seed: self.seed ^ crate::sampling::rng::pcg(0x9e37_79b9 ^ b as u32),
                ..*self
            };
            visit.extend(inner.order(blocks[b].len(), even).into_iter().map(|i| blocks[b][i]));
        }
        if round % 2 == 1 {
            visit.reverse();
        }
        visit
    }

    /// Times `n` units grouped in `blocks` (every unit in exactly one) until every comparison
    /// in `pairs` is decided or `looks.cap` rounds are run: `visit(unit)` renders the unit's
    /// warm-up frames and returns the seconds of its timed frame; `on_round` hears after each
    /// round how far it has come.
    pub fn run_sequential<E>(
        &self,
        looks: Looks,
        blocks: &[Vec<usize>],
        pairs: &[Pair],
        mut visit: impl FnMut(usize) -> Result<f64, E>,
        mut on_round: impl FnMut(RoundDone),
    ) -> Result<SequentialTimes, E> {
        let n: usize = blocks.iter().map(Vec::len).sum();
        let mut seconds = vec![Vec::new(); n];
        let mut decided: Vec<Option<Decided>> = vec![None; pairs.len()];
        let compared = |u: usize| pairs.iter().any(|p| p.a == u || p.b == u);
        let mut active: Vec<bool> = vec![true; n];
        let mut rounds = 0;
        while rounds < looks.cap && active.iter().any(|&a| a) {
            for unit in self.block_order(blocks, rounds) {
                if active[unit] {
                    seconds[unit].push(visit(unit)?);
                }
            }
            rounds += 1;
            if looks.looks_at(rounds) {
                let r = rounds as usize;
                for (p, d) in pairs.iter().zip(decided.iter_mut()).filter(|(_, d)| d.is_none()) {
                    let (x, y) = (&seconds[p.a][..r], &seconds[p.b][..r]);
                    let now = at(x, y, rounds);
                    if closes(&now, x, y) || rounds == looks.cap {
                        *d = Some(now);
                    }
                }
                for (u, a) in active.iter_mut().enumerate() {
                    *a = pairs
                        .iter()
                        .zip(&decided)
                        .any(|(p, d)| d.is_none() && (p.a == u || p.b == u))
                        || (!compared(u) && rounds < looks.first_look);
                }
            }
            on_round(RoundDone {
                rounds,
                open: decided.iter().filter(|d| d.is_none()).count(),
                units: active.iter().filter(|&&a| a).count(),
            });
        }
        let decided = decided
            .into_iter()
            .zip(pairs)
            .map(|(d, p)| d.unwrap_or_else(|| decide(&seconds[p.a], &seconds[p.b], looks)))
            .collect();
        Ok(SequentialTimes {
            seconds,
            decided,
            rounds,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Stream;

    /// A per-round log-normal-ish factor of relative spread `sigma` (sum of four uniforms), and
    /// with probability `jump` a round where the machine runs at half or double speed for one
    /// unit only (a mode switch between two neighbouring visits).
    fn noise(s: &Stream, i: u32, sigma: f64, jump: f64) -> f64 {
        let u: f64 = (0..4).map(|k| s.unit(8 * i + k)).sum::<f64>() - 2.0;
        let mut f = (sigma * u * 3f64.sqrt()).exp();
        if s.unit(8 * i + 4) < jump {
            f *= if s.unit(8 * i + 5) < 0.5 { 2.0 } else { 0.5 };
        }
        f
    }

    /// One trial: unit 1 takes `truth` times unit 0's time, each visit with its own noise.
    fn trial(looks: Looks, truth: f64, sigma: f64, jump: f64, seed: u32) -> Decided {
        let s = Stream::new(seed, 3, None);
        let mut k = 0u32;
        let schedule = Schedule {
            seed,
            warmup: 0,
            repeats: looks.cap,
        };
        let times = schedule
            .run_sequential(
                looks,
                &[vec![0, 1]],
                &[Pair { a: 1, b: 0 }],
                |u| {
                    k += 1;
                    Ok::<_, ()>(0.02 * if u == 1 { truth } else { 1.0 } * noise(&s, k, sigma, jump))
                },
                |_| {},
            )
            .unwrap();
        times.decided[0]
    }

    /// Per-visit spread of the simulation: a ratio of two visits spreads by sqrt(2) times it,
    /// 5 %. With more the design's power at 1.1x falls below 90 % at the cap (two visits of
    /// 5 % each: 67 %); each report's A/A control shows the spread its machine had.
    const SPREAD: f64 = 0.035;

    /// The stopping rule's error rates, by simulation over seeded synthetic timing series with
    /// a known truth, with looks at 6, 9, ... up to 24 rounds ([`Looks::up_to`]`(24)`): per-visit
    /// spread of [`SPREAD`] (log-normal-ish; a per-round ratio of two visits spreads by 5 %),
    /// and again with one visit in ten at half or double speed.
    /// - equal units are given a direction (a false word) in at most 1 % of trials;
    /// - units 1.1x apart are called slower (the truth) in at least 90 % by the cap without
    ///   mode switches (measured 91.6 %; with them 74.7 %, and at least 50 % is asserted), never
    ///   faster, and called equivalent in at most 1 %;
    /// - at exactly the margin (1.05x) each of "equivalent" and "slower" is called in about 5 %
    ///   of trials (the level of a two one-sided test at 95 %, raised by looking several times):
    ///   a truth on the margin is no false word either way, and neither word is near certain.
    /// - units 1.1x apart at 1 % spread are decided at the first look.
    #[test]
    fn false_words_are_rare_and_a_tenth_is_found() {
        let looks = Looks::up_to(24);
        let trials = 2000u32;
        for jump in [0.0, 0.1] {
            let (mut false_words, mut found, mut wrong_way, mut false_equivalent) = (0, 0, 0, 0);
            let mut rounds_equal = 0;
            for t in 0..trials {
                let equal = trial(looks, 1.0, SPREAD, jump, 2 * t + 1);
                false_words += matches!(equal.word, Comparison::Faster | Comparison::Slower) as u32;
                rounds_equal += equal.rounds;
                let apart = trial(looks, 1.1, SPREAD, jump, 2 * t + 2);
                found += (apart.word == Comparison::Slower) as u32;
                wrong_way += (apart.word == Comparison::Faster) as u32;
                false_equivalent += (apart.word == Comparison::Equivalent) as u32;
            }
            let share = |k: u32| k as f64 / trials as f64;
            eprintln!(
                "jump {jump}: false words {:.4}, power at 1.1x {:.4}, equivalent at 1.1x {:.4}, mean rounds when equal {:.1}",
                share(false_words),
                share(found),
                share(false_equivalent),
                rounds_equal as f64 / trials as f64
            );
            assert!(share(false_words) <= 0.01, "false words {}", share(false_words));
            let least = if jump == 0.0 { 0.90 } else { 0.5 };
            assert!(share(found) >= least, "power {}", share(found));
            assert_eq!(wrong_way, 0);
            assert!(share(false_equivalent) <= 0.01, "{}", share(false_equivalent));
        }
        let (mut equivalent, mut slower) = (0, 0);
        for t in 0..trials {
            let d = trial(looks, 1.05, SPREAD, 0.0, 20_000 + t);
            equivalent += (d.word == Comparison::Equivalent) as u32;
            slower += (d.word == Comparison::Slower) as u32;
        }
        eprintln!(
            "at the margin: equivalent {:.4}, slower {:.4}",
            equivalent as f64 / trials as f64,
            slower as f64 / trials as f64
        );
        assert!(equivalent as f64 <= 0.08 * trials as f64 && slower as f64 <= 0.08 * trials as f64);
        for t in 0..200 {
            let d = trial(looks, 1.1, 0.01, 0.0, 10_000 + t);
            assert_eq!((d.word, d.rounds), (Comparison::Slower, 6), "trial {t}");
        }
    }

    /// Blocks are visited whole, reversed on odd rounds; a decided pair stops being visited,
    /// an undecided one runs to the cap; a unit in no comparison gets the first look's rounds.
    #[test]
    fn rounds_stop_when_their_comparisons_are_decided() {
        let s = Schedule {
            seed: 11,
            warmup: 0,
            repeats: 12,
        };
        let blocks = vec![vec![0, 1, 2], vec![3, 4], vec![5]];
        let even = s.block_order(&blocks, 4);
        assert_eq!(even.len(), 6);
        let first_block = blocks.iter().find(|b| b.contains(&even[0])).unwrap();
        assert!(
            even[..first_block.len()].iter().all(|u| first_block.contains(u)),
            "a block is visited back to back: {even:?}"
        );
        let mut odd = s.block_order(&blocks, 5);
        odd.reverse();
        assert_eq!(odd, even);
        let looks = Looks::up_to(12);
        // 0 vs 1: 2x apart, decided at 6; 3 vs 4: identical but noisy (never decided); 2 and 5
        // in no comparison.
        let mut visits = vec![0u32; 6];
        let mut progress = Vec::new();
        let times = s
            .run_sequential(
                looks,
                &blocks,
                &[Pair { a: 1, b: 0 }, Pair { a: 4, b: 3 }],
                |u| {
                    visits[u] += 1;
                    let wobble = if visits[u] % 2 == 0 { 1.3 } else { 0.7 };
                    Ok::<_, ()>(match u {
                        0 => 1.0,
                        1 => 2.0,
                        3 => wobble,
                        4 => 2.0 - wobble,
                        _ => 1.0,
                    })
                },
                |r| progress.push((r.rounds, r.open)),
            )
            .unwrap();
        assert_eq!(visits, vec![6, 6, 6, 12, 12, 6]);
        assert_eq!(times.rounds, 12);
        assert_eq!(
            (times.decided[0].word, times.decided[0].rounds),
            (Comparison::Slower, 6)
        );
        assert_eq!(
            (times.decided[1].word, times.decided[1].rounds),
            (Comparison::Undecided, 12)
        );
        assert_eq!(progress[5], (6, 1));
        assert_eq!(progress.last(), Some(&(12, 0)));
        assert!(Looks::up_to(12).looks_at(9) && !Looks::up_to(12).looks_at(10));
        // The rule replayed on the series gives the words the run gave.
        for (k, p) in [Pair { a: 1, b: 0 }, Pair { a: 4, b: 3 }].iter().enumerate() {
            assert_eq!(
                decide(&times.seconds[p.a], &times.seconds[p.b], looks),
                times.decided[k]
            );
        }
        assert_eq!(Looks::up_to(4).first_look, 4, "a cap under six looks once, at the cap");
    }
}
