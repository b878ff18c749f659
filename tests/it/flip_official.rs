//! The project's FLIP (`penumbra::metrics::flip`, through the `nv-flip` crate) against NVIDIA's
//! official implementation: the fixtures in `tests/fixtures/flip` hold 8-bit sRGB image pairs and
//! the mean error and per-pixel map that the official `flip-evaluator` package (LDR, sRGB
//! inputs) gives them at two viewing conditions, made by `scripts/flip-fixtures.py` (which says
//! how). Every FLIP the harness reports is this LDR variant at
//! [`PIXELS_PER_DEGREE`] (the fixtures' `default` condition).

use crate::common;
use penumbra::metrics::flip::{flip_map, flip_mean, PIXELS_PER_DEGREE};
use std::path::Path;

/// Largest relative difference of a mean error from the official one.
const MEAN_RELATIVE: f64 = 1e-4;
/// Largest difference of one pixel's error from the official map's.
const PIXEL_ABSOLUTE: f64 = 1e-4;

fn rgb8(path: &Path) -> (Vec<u8>, u32, u32) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    let (w, h) = img.dimensions();
    (img.into_raw(), w, h)
}

#[test]
fn flip_matches_the_official_implementation() {
    let dir = common::repo("tests/fixtures/flip");
    let mut reader = csv::Reader::from_path(dir.join("official.csv")).unwrap();
    let mut checked = 0;
    for row in reader.records() {
        let row = row.unwrap();
        let (pair, condition, ppd, official) = (
            &row[0],
            &row[1],
            row[2].parse::<f32>().unwrap(),
            row[3].parse::<f64>().unwrap(),
        );
        let (reference, w, h) = rgb8(&dir.join(format!("{pair}_reference.png")));
        let (test, tw, th) = rgb8(&dir.join(format!("{pair}_test.png")));
        assert_eq!((w, h), (tw, th), "{pair}");
        if condition == "default" {
            assert!(
                (ppd - PIXELS_PER_DEGREE).abs() < 1e-4,
                "the fixtures' default condition is {ppd} ppd, the harness's {PIXELS_PER_DEGREE}"
            );
        }
        let ours = flip_mean(&reference, &test, w, h, ppd).unwrap();
        let relative = (ours - official).abs() / official;
        eprintln!("{pair} {condition}: ours {ours:.9e}, official {official:.9e}, relative {relative:.2e}");
        assert!(
            relative <= MEAN_RELATIVE,
            "{pair} at {condition}: mean FLIP {ours} against the official {official} ({relative:.2e} relative)"
        );
        let map = flip_map(&reference, &test, w, h, ppd).unwrap();
        let text = std::fs::read_to_string(dir.join(format!("{pair}_{condition}_map.txt"))).unwrap();
        let official_map: Vec<f64> = text.split_whitespace().map(|v| v.parse().unwrap()).collect();
        assert_eq!(official_map.len(), map.len(), "{pair} at {condition}");
        let (worst, at) = map
            .iter()
            .zip(&official_map)
            .enumerate()
            .map(|(i, (&a, &b))| ((a as f64 - b).abs(), i))
            .fold((0.0, 0), |m, x| if x.0 > m.0 { x } else { m });
        assert!(
            worst <= PIXEL_ABSOLUTE,
            "{pair} at {condition}: pixel ({}, {}) differs from the official map by {worst:.2e}",
            at as u32 % w,
            at as u32 / w
        );
        checked += 1;
    }
    // Five pairs at two conditions: a fixture that lost rows would check less than it says.
    assert_eq!(checked, 10);
}
