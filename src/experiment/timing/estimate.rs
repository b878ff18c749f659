//! A median with its 95 % interval, as every kind reports a time.

use serde::{Deserialize, Serialize};

/// A median and its 95 % interval; all NaN when nothing was timed, the interval NaN when one
/// value cannot give one.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The median.
    pub median: f64,
    /// Lower end of the 95 % interval.
    pub lo: f64,
    /// Upper end of the 95 % interval.
    pub hi: f64,
}

impl Estimate {
    /// Nothing measured.
    pub const NAN: Estimate = Estimate {
        median: f64::NAN,
        lo: f64::NAN,
        hi: f64::NAN,
    };

    /// Every value scaled by `k` (seconds to milliseconds; rays to rays per second...).
    pub fn scaled(self, k: f64) -> Estimate {
        let (a, b) = (self.lo * k, self.hi * k);
        Estimate {
            median: self.median * k,
            lo: a.min(b),
            hi: a.max(b),
        }
    }

    /// The reciprocal (a time ratio as a speed-up), its interval's ends swapped.
    pub fn recip(self) -> Estimate {
        Estimate {
            median: 1.0 / self.median,
            lo: 1.0 / self.hi,
            hi: 1.0 / self.lo,
        }
    }

    /// `1.23 [1.10, 1.41]` with `digits` decimals.
    pub fn show(&self, digits: usize) -> String {
        if self.median.is_nan() {
            return "n/a".into();
        }
        if self.lo.is_nan() {
            return format!("{:.digits$} [n/a]", self.median);
        }
        format!("{:.digits$} [{:.digits$}, {:.digits$}]", self.median, self.lo, self.hi)
    }
}
