//! Where an axis is labelled and how a label reads. The densest "nice" set of values whose labels
//! fit between their neighbours is chosen, so that no two labels ever touch (a log axis over
//! 60..1500 ms is labelled 100, 200, 300, 500, 1000, never "9001000"); [`Keyed`] hands the choice to
//! plotters.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use std::ops::Range;

/// Pixels kept free between two neighbouring labels.
const GAP: f64 = 10.0;

/// Most labels on one axis.
const MOST: usize = 10;

/// How an axis is scaled and what its values are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Scale {
    /// Logarithmic.
    pub log: bool,
    /// The data are whole numbers (frames, rays): labelled at whole numbers only.
    pub whole: bool,
}

/// The labelled values of an axis over `lo..hi` drawn `pixels` long, where `room(text)` is the
/// length along the axis that a label reading `text` takes: the densest nice set (on a log axis:
/// every 1..9 of each decade, then 1, 2, 3 and 5, then 1, 2 and 5, then decades, then every
/// second, third... decade; where fewer than two of those fall in range, or on a linear axis,
/// multiples of 1, 2 or 5 times a power of ten) whose neighbouring labels, as [`axis_labels`]
/// writes them, keep [`GAP`] apart.
pub fn ticks(lo: f64, hi: f64, scale: Scale, pixels: f64, room: &dyn Fn(&str) -> f64) -> Vec<f64> {
    let Scale { log, whole } = scale;
    if !(lo.is_finite() && hi.is_finite() && hi > lo) || (log && lo <= 0.0) {
        return vec![];
    }
    let at = |v: f64| {
        if log {
            (v / lo).ln() / (hi / lo).ln() * pixels
        } else {
            (v - lo) / (hi - lo) * pixels
        }
    };
    let fits = |vs: &[f64]| {
        let text = axis_labels(vs);
        let room = |v: f64| room(&text(&v));
        vs.len() <= MOST
            && vs
                .windows(2)
                .all(|w| at(w[1]) - at(w[0]) >= (room(w[0]) + room(w[1])) / 2.0 + GAP)
    };
    let whole_only = |set: Vec<f64>| -> Vec<f64> {
        if whole {
            set.into_iter().filter(|v| v.fract() == 0.0).collect()
        } else {
            set
        }
    };
    if log {
        for set in log_sets(lo, hi).into_iter().map(whole_only) {
            if set.len() >= 2 && fits(&set) {
                return set;
            }
        }
    }
    let mut fallback = vec![];
    for step in linear_steps(lo, hi).into_iter().filter(|s| !whole || *s >= 1.0) {
        let set = multiples(lo, hi, step);
        if set.len() >= 2 && fits(&set) {
            return set;
        }
        if !set.is_empty() {
            fallback = set;
        }
    }
    // Too short for two labels: one, in the middle of the range if nothing else.
    fallback.truncate(1);
    fallback
}

/// The candidate label sets of a log axis over `lo..hi`, densest first.
fn log_sets(lo: f64, hi: f64) -> Vec<Vec<f64>> {
    let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let within = |m: f64, e: i32| {
        let v = round_sig(m * 10f64.powi(e));
        (v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12)).then_some(v)
    };
    let of = |mantissas: &[f64], every: i32| -> Vec<f64> {
        (d0..=d1)
            .filter(|e| e.rem_euclid(every) == 0)
            .flat_map(|e| mantissas.iter().filter_map(move |&m| within(m, e)))
            .collect()
    };
    let mut sets = vec![
        of(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0], 1),
        of(&[1.0, 2.0, 3.0, 5.0], 1),
        of(&[1.0, 2.0, 5.0], 1),
    ];
    sets.extend((1..=(d1 - d0).max(1)).map(|every| of(&[1.0], every)));
    sets
}

/// Steps 1, 2 and 5 times a power of ten from about a hundredth of the range up.
fn linear_steps(lo: f64, hi: f64) -> Vec<f64> {
    let first = ((hi - lo) / 100.0).log10().floor() as i32;
    (first..first + 6)
        .flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e)))
        .collect()
}

/// Multiples of `step` in `lo..=hi`.
fn multiples(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let (a, b) = ((lo / step).ceil() as i64, (hi / step).floor() as i64);
    if b - a > 1000 {
        return vec![];
    }
    (a..=b).map(|k| round_sig(k as f64 * step)).collect()
}

/// An axis (linear or logarithmic, `R`) labelled at chosen values, with light grid lines at
/// others, in place of plotters' own choice.
pub struct Keyed<R> {
    inner: R,
    labelled: Vec<f64>,
    light: Vec<f64>,
}

impl<R: Ranged<ValueType = f64>> Keyed<R> {
    /// Axis `inner` labelled at `labelled`, with light lines at `light`.
    pub fn new(inner: impl Into<R>, labelled: Vec<f64>, light: Vec<f64>) -> Self {
        Keyed {
            inner: inner.into(),
            labelled,
            light,
        }
    }
}

impl<R> Keyed<R> {
    /// How its labels read ([`axis_labels`]).
    pub fn labels(&self) -> impl Fn(&f64) -> String {
        axis_labels(&self.labelled)
    }
}

impl<R: Ranged<ValueType = f64>> Ranged for Keyed<R> {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.labelled.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.inner.range()
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> Range<i32> {
        self.inner.axis_pixel_range(limit)
    }
}

/// `v` to twelve significant digits (multiples and powers computed in floating point arrive as
/// 0.30000000000000004).
fn round_sig(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    format!("{v:.11e}").parse().unwrap_or(v)
}

/// A tick label: at most four significant digits, no trailing zeros; exponent form (`1e6`,
/// `2.5e-5`) from a million up and below 0.0001, so that labels stay short.
pub fn label(v: f64) -> String {
    label_in(v, wants_exponent(v))
}

/// Whether `v` reads better in exponent form.
fn wants_exponent(v: f64) -> bool {
    v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs())
}

/// How the labels of one axis read: all in exponent form if any wants it (`5e-5`, `1e-4`, never
/// `5e-5` beside `0.0001`), with four significant digits or as many more as it takes for no two
/// labels to read the same (1.0002 and 1.0004, never 1 and 1).
pub fn axis_labels(values: &[f64]) -> impl Fn(&f64) -> String {
    let exponent = values.iter().any(|v| wants_exponent(*v));
    let distinct = |extra: usize| {
        let mut texts: Vec<String> = values.iter().map(|v| label_with(*v, exponent, extra)).collect();
        texts.sort();
        texts.dedup();
        texts.len() == values.len()
    };
    let extra = (0..=8).find(|&e| distinct(e)).unwrap_or(8);
    move |v| label_with(*v, exponent, extra)
}

/// `v` with at most four significant digits and no trailing zeros, in exponent form or not.
fn label_in(v: f64, exponent: bool) -> String {
    label_with(v, exponent, 0)
}

/// `v` with at most 4 + `extra` significant digits and no trailing zeros, in exponent form or
/// not.
fn label_with(v: f64, exponent: bool, extra: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{}", if v == 0.0 { 0.0 } else { v });
    }
    let trim = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if exponent {
        let s = format!("{v:.*e}", 3 + extra);
        let (mantissa, power) = s.split_once('e').expect("exponent form");
        return format!("{}e{power}", trim(mantissa));
    }
    let decimals = (3 + extra as i32 - v.abs().log10().floor() as i32).max(0) as usize;
    trim(&format!("{v:.decimals$}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_read_as_written() {
        for (v, s) in [
            (0.7000000000000001, "0.7"),
            (1000000.0, "1e6"),
            (250000.0, "250000"),
            (0.00001, "1e-5"),
            (0.000025, "2.5e-5"),
            (0.002, "0.002"),
            (12.5, "12.5"),
            (0.0, "0"),
            (-0.0, "0"),
            (-0.25, "-0.25"),
        ] {
            assert_eq!(label(v), s, "{v}");
        }
    }

    const LOG: Scale = Scale {
        log: true,
        whole: false,
    };
    const LINEAR: Scale = Scale {
        log: false,
        whole: false,
    };

    #[test]
    fn an_axis_reads_in_one_form() {
        let f = axis_labels(&[5e-5, 1e-4, 2e-4]);
        assert_eq!([f(&5e-5), f(&1e-4), f(&2e-4)], ["5e-5", "1e-4", "2e-4"]);
        let f = axis_labels(&[5e-4, 1e-3, 0.5]);
        assert_eq!([f(&5e-4), f(&1e-3), f(&0.5)], ["0.0005", "0.001", "0.5"]);
        let f = axis_labels(&[0.0, 0.5, 1.0]);
        assert_eq!([f(&0.0), f(&0.5), f(&1.0)], ["0", "0.5", "1"]);
        // Close values get the digits that tell them apart.
        let f = axis_labels(&[1.0, 1.0002, 1.0004]);
        assert_eq!([f(&1.0), f(&1.0002), f(&1.0004)], ["1", "1.0002", "1.0004"]);
        let f = axis_labels(&[1234600.0, 1234700.0]);
        assert_eq!([f(&1234600.0), f(&1234700.0)], ["1.2346e6", "1.2347e6"]);
    }

    /// Room for a label: 8 pixels a character, as the 15-pixel axis font roughly takes.
    fn room(text: &str) -> f64 {
        8.0 * text.len() as f64
    }

    #[test]
    fn log_axes_are_labelled_at_round_values() {
        // The axis that read "9001000": 900 and 1000 are too close to both be labelled.
        let t = ticks(60.0, 1500.0, LOG, 780.0, &room);
        assert_eq!(t, vec![100.0, 200.0, 300.0, 500.0, 1000.0]);
        // Wide log axes are labelled by decade, or every other decade.
        assert_eq!(ticks(0.5, 2e3, LOG, 780.0, &room), vec![1.0, 10.0, 100.0, 1000.0]);
        let wide = ticks(1e-9, 1.0, LOG, 300.0, &room);
        assert!(wide.len() >= 2 && wide.len() < 10, "{wide:?}");
        // Short of a decade: no power of ten inside, labelled all the same.
        let narrow = ticks(0.31, 0.39, LOG, 500.0, &room);
        assert!(narrow.len() >= 2, "{narrow:?}");
        let hundreds: Vec<f64> = (1..=10).map(|k| 100.0 * k as f64).collect();
        assert_eq!(ticks(1.0, 1000.0, LINEAR, 780.0, &room), hundreds);
        // Frames 0..2 are labelled 0, 1, 2, never 0.5.
        let whole = Scale {
            log: false,
            whole: true,
        };
        assert_eq!(ticks(-0.12, 2.12, whole, 780.0, &room), vec![0.0, 1.0, 2.0]);
        assert_eq!(ticks(-0.12, 2.12, LINEAR, 780.0, &room), vec![0.0, 0.5, 1.0, 1.5, 2.0]);
    }

    #[test]
    fn no_two_labels_ever_touch() {
        let mut seen = 0;
        for (i, lo) in [1e-7, 3e-4, 0.02, 0.9, 7.0, 60.0, 999.0, 3e4, 2e6].iter().enumerate() {
            for ratio in [1.0008, 1.05, 1.3, 2.0, 9.0, 31.0, 1e3, 1e6] {
                for log in [false, true] {
                    for pixels in [120.0, 480.0, 780.0] {
                        let hi = lo * ratio;
                        let t = ticks(*lo, hi, Scale { log, whole: false }, pixels, &room);
                        assert!(!t.is_empty(), "{lo}..{hi} log {log} {pixels} px: no label");
                        let at = |v: f64| {
                            if log {
                                (v / lo).ln() / (hi / lo).ln() * pixels
                            } else {
                                (v - lo) / (hi - lo) * pixels
                            }
                        };
                        let text = axis_labels(&t);
                        for w in t.windows(2) {
                            assert!(w[0] < w[1] && w[0] >= *lo * (1.0 - 1e-9) && w[1] <= hi * (1.0 + 1e-9));
                            let apart = at(w[1]) - at(w[0]);
                            let (a, b) = (text(&w[0]), text(&w[1]));
                            assert!(
                                apart >= (room(&a) + room(&b)) / 2.0 + GAP && a != b,
                                "{lo}..{hi} log {log} {pixels} px ({i}): {a} and {b} touch in {t:?}",
                            );
                            seen += 1;
                        }
                    }
                }
            }
        }
        assert!(seen > 500, "{seen} neighbouring labels checked");
    }
}
