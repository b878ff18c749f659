//! A median with its 95 % interval, as every kind reports a time, and as a table writes it: a
//! group of three columns ([`EstimateColumns`]).

use crate::output::table::Float;
use serde::ser::SerializeStruct;
use serde::{Deserialize, Serialize, Serializer};

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

    /// This estimate as the column group `names` of a table row ([`EstimateColumns`]).
    pub fn columns(self, names: [&'static str; 3]) -> EstimateColumns {
        EstimateColumns { names, estimate: self }
    }

    /// `12.34 [11.90, 12.80] ms`: a time in seconds, shown in milliseconds; `n/a` when untimed.
    pub fn show_ms(&self) -> String {
        if self.median.is_finite() {
            format!("{} ms", self.scaled(1e3).show(2))
        } else {
            "n/a".into()
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

/// Frame seconds with their interval: the columns `frame_s`, `frame_s_lo`, `frame_s_hi`.
pub const FRAME_S: [&str; 3] = ["frame_s", "frame_s_lo", "frame_s_hi"];

/// An [`Estimate`] as three columns of a CSV row ([`crate::output::table`]): the median under
/// `names[0]`, the ends of its 95 % interval under `names[1]` and `names[2]` (`frame_s`,
/// `frame_s_lo`, `frame_s_hi`: [`FRAME_S`]), each as [`Float`] writes a float (shortest round-trip
/// text, NaN empty), so a table keeps its bytes when its three fields become one group.
///
/// The csv crate writes a header from the fields of a row's struct, or of each struct of a row
/// that is a tuple of them, but refuses a struct inside a struct's field, and
/// `#[serde(flatten)]` (which serializes as a map). A group of columns is therefore one part of
/// a row made of parts, as [`crate::accel::settings::ParameterColumns`] is. To write a row's
/// estimate this way, cut its struct where the three fields stood and make the row a tuple:
///
/// ```ignore
/// type Row<'a> = (Before<'a>, EstimateColumns, After);
/// let row: Row = (Before { .. }, r.frame.columns(FRAME_S), After { .. });
/// ```
///
/// A table whose estimate is named otherwise names its three columns once in a constant beside
/// its row (`const TUNING_S: [&str; 3] = ["tuning_s", "tuning_s_lo", "tuning_s_hi"]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateColumns {
    /// The columns' names: the median's, the lower end's, the upper end's.
    pub names: [&'static str; 3],
    /// The values.
    pub estimate: Estimate,
}

impl Serialize for EstimateColumns {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let e = self.estimate;
        let mut row = s.serialize_struct("EstimateColumns", 3)?;
        for (name, value) in self.names.into_iter().zip([e.median, e.lo, e.hi]) {
            row.serialize_field(name, &Float(value))?;
        }
        row.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn csv<T: Serialize>(row: T) -> Result<String, csv::Error> {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.serialize(row)?;
        Ok(String::from_utf8(w.into_inner().unwrap()).unwrap())
    }

    /// The group writes the columns its three fields wrote, byte for byte, as a part of a row; a
    /// struct in a field or a flattened one would be refused.
    #[test]
    fn a_time_shows_in_milliseconds_or_as_not_available() {
        assert_eq!(Estimate::NAN.show_ms(), "n/a");
        let e = Estimate {
            median: 0.0123,
            lo: 0.0119,
            hi: 0.0128,
        };
        assert_eq!(e.show_ms(), "12.30 [11.90, 12.80] ms");
    }

    #[test]
    fn an_estimate_writes_the_columns_its_fields_wrote() {
        #[derive(Serialize)]
        struct Before {
            frames: usize,
        }
        #[derive(Serialize)]
        struct After {
            chosen: bool,
        }
        #[derive(Serialize)]
        struct ByHand {
            frames: usize,
            #[serde(with = "crate::output::table::float")]
            frame_s: f64,
            #[serde(with = "crate::output::table::float")]
            frame_s_lo: f64,
            #[serde(with = "crate::output::table::float")]
            frame_s_hi: f64,
            chosen: bool,
        }
        let e = Estimate {
            median: 0.012_5,
            lo: f64::NAN,
            hi: 1e-7,
        };
        let grouped = csv((Before { frames: 3 }, e.columns(FRAME_S), After { chosen: true })).unwrap();
        let by_hand = csv(ByHand {
            frames: 3,
            frame_s: e.median,
            frame_s_lo: e.lo,
            frame_s_hi: e.hi,
            chosen: true,
        })
        .unwrap();
        assert_eq!(grouped, by_hand);
        assert_eq!(
            grouped,
            "frames,frame_s,frame_s_lo,frame_s_hi,chosen\n3,0.0125,,0.0000001,true\n"
        );
        #[derive(Serialize)]
        struct Nested {
            frames: usize,
            frame: EstimateColumns,
        }
        #[derive(Serialize)]
        struct Flattened {
            frames: usize,
            #[serde(flatten)]
            frame: EstimateColumns,
        }
        let frame = e.columns(FRAME_S);
        assert!(csv(Nested { frames: 3, frame }).is_err());
        assert!(csv(Flattened { frames: 3, frame }).is_err());
    }
}
