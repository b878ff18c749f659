//! Which of a structure's candidate settings to keep, by the words of the rule ([`super::RULE`]):
//! the first listed candidate is the default, and a later one replaces the one kept so far only
//! where it is *faster* than it (its per-round time ratio's whole interval below 1 / 1.05).
//! Picking the fastest median instead turns a timing difference smaller than the noise into a
//! different structure, and with it every non-timing number (nodes visited, memory) of the run;
//! under this rule a rerun, a shard or another host of the same kind keeps the same setting
//! unless a candidate is decidedly faster on one and not on the other.

use super::interval::{coverage, paired_ratio};
use super::rule::Comparison;
use super::Estimate;

/// How one candidate fared when it was considered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Considered {
    /// The candidate it was compared with: the one kept so far (itself for the default).
    pub against: usize,
    /// Its time over `against`'s (median of per-round ratios) with its 95 % interval.
    pub ratio: Estimate,
    /// The rule's word for that ratio; `None` for the default, which is compared with nothing.
    pub word: Option<Comparison>,
}

/// The candidate kept and how each was judged ([`keep`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Kept {
    /// Index of the candidate kept.
    pub index: usize,
    /// One entry per candidate, in the listed order.
    pub considered: Vec<Considered>,
}

/// The candidate to keep among `times` (one series of per-round times per candidate, all timed
/// in the same interleaved rounds; the first is the default), walking them in listed order: a
/// candidate replaces the one kept so far only where the rule calls it *faster*. A candidate
/// whose rounds do not pair with the default's (a failed timing), or that has too few rounds for
/// a 95 % interval (under six), is never kept.
pub fn keep(times: &[Vec<f64>]) -> Kept {
    assert!(!times.is_empty(), "at least the default is timed");
    let mut index = 0;
    let mut considered = vec![Considered {
        against: 0,
        ratio: Estimate {
            median: 1.0,
            lo: 1.0,
            hi: 1.0,
        },
        word: None,
    }];
    for (i, t) in times.iter().enumerate().skip(1) {
        // Fewer rounds than a 95 % interval needs give no word (three give [min, max]: 75 %).
        let ratio = if t.len() == times[index].len() && !t.is_empty() && coverage(t.len()) >= 0.95 {
            paired_ratio(t, &times[index])
        } else {
            Estimate::NAN
        };
        let word = Comparison::of(&ratio);
        considered.push(Considered {
            against: index,
            ratio,
            word: Some(word),
        });
        if word == Comparison::Faster {
            index = i;
        }
    }
    Kept { index, considered }
}

/// What [`Considered::word`] prints in a tuning table: `default`, or the word against the
/// candidate it was compared with.
pub fn considered_word(c: &Considered) -> &'static str {
    c.word.map_or("default", Comparison::word)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Per-round times of `mean` with a small deterministic wobble, shared by every candidate
    /// (the paired ratio then sees the means' ratio within the wobble's spread).
    fn series(mean: f64, n: usize, phase: u32) -> Vec<f64> {
        (0..n)
            .map(|i| mean * (1.0 + 0.002 * (((i as u32 * 7 + phase) % 5) as f64 - 2.0)))
            .collect()
    }

    #[test]
    fn the_default_stays_unless_a_candidate_is_decidedly_faster() {
        // 3 % faster: inside the margin, so the default stays whatever the medians say.
        let k = keep(&[series(1.0, 9, 0), series(0.97, 9, 1)]);
        assert_eq!(k.index, 0);
        assert_eq!(k.considered[1].word, Some(Comparison::Equivalent));
        assert_eq!(considered_word(&k.considered[0]), "default");
        // 20 % faster: kept.
        let k = keep(&[series(1.0, 9, 0), series(0.8, 9, 1)]);
        assert_eq!(k.index, 1);
        assert_eq!(k.considered[1].word, Some(Comparison::Faster));
    }

    #[test]
    fn a_later_candidate_must_beat_the_one_kept_so_far() {
        // 1 beats the default by 20 %; 2 is 3 % faster than 1 (not decided): 1 stays. 3 beats
        // 1 by 25 %: kept, compared with 1, not with the default.
        let k = keep(&[
            series(1.0, 9, 0),
            series(0.8, 9, 1),
            series(0.776, 9, 2),
            series(0.6, 9, 3),
        ]);
        assert_eq!(k.index, 3);
        let against: Vec<usize> = k.considered.iter().map(|c| c.against).collect();
        assert_eq!(against, [0, 0, 1, 1]);
        assert_eq!(k.considered[2].word, Some(Comparison::Equivalent));
        assert!((k.considered[3].ratio.median - 0.75).abs() < 0.01);
    }

    #[test]
    fn an_unpaired_or_single_round_candidate_is_undecided_and_never_kept() {
        let k = keep(&[series(1.0, 9, 0), series(0.5, 8, 1)]);
        assert_eq!((k.index, k.considered[1].word), (0, Some(Comparison::Undecided)));
        // One round, or three (a [min, max] interval covers 75 %): no word, however large the
        // difference.
        let k = keep(&[vec![1.0], vec![0.1]]);
        assert_eq!((k.index, k.considered[1].word), (0, Some(Comparison::Undecided)));
        let k = keep(&[series(1.0, 3, 0), series(0.5, 3, 1)]);
        assert_eq!((k.index, k.considered[1].word), (0, Some(Comparison::Undecided)));
        let k = keep(&[series(1.0, 6, 0), series(0.5, 6, 1)]);
        assert_eq!((k.index, k.considered[1].word), (1, Some(Comparison::Faster)));
    }
}
