//! The frame experiments can decide their claims either way at the size they are committed at.
//! Scaling and the walkthrough draw each frame's camera independently ([`Cameras::Random`]), so
//! a median of per-frame speed-ups has an exact order-statistic interval; whether that interval
//! is narrow enough depends on how much the speed-up varies from camera to camera. This test
//! measures that spread where it was measured: in every size, viewpoint, shading and pair of
//! the committed `frames.csv`, the per-frame log speed-ups are centred on their median and
//! resampled (seeded) into as many frames as the experiment file asks for, shifted to a true
//! speed-up of 1.3 (the rule must say "faster" in at least 90 % of trials) and of 1 (an A/A
//! pair: no direction, "equivalent" or "undecided", in at least 95 %), judged by the verdict's own code. Cells that
//! fall short are findings, listed with their power in [`SHORTFALLS`].

use crate::common;
use penumbra::experiment::frames::spec::Cameras;
use penumbra::experiment::frames::verdict::Speedup;
use penumbra::experiment::frames::FramesSpec;
use penumbra::metrics::stats::median;
use penumbra::sampling::Stream;
use penumbra::timing::Comparison;
use std::collections::BTreeMap;

/// Trials per cell and pair.
const TRIALS: u32 = 1000;
/// The true speed-up the design must detect.
const TRUE_SPEEDUP: f64 = 1.3;
/// Least share of trials at [`TRUE_SPEEDUP`] called faster.
const POWER: f64 = 0.90;
/// Least share of A/A trials given no direction (equivalent or undecided).
const AA_EQUAL: f64 = 0.95;

/// Cells where the committed frames fall short of [`POWER`], each with the power this seeded
/// simulation computes from them (to three decimals): findings, reported with the results, not
/// exemptions to grow. A listed cell must still compute exactly this value, so a regeneration
/// that changes it fails here until someone looks again; a listed cell that reaches [`POWER`],
/// and any unlisted cell below it, fail too.
///
/// None in the committed frames. An earlier regeneration of scaling had three (inside the
/// scene at 4K against BVH2 and CWBVH, at 16K against the SAH kd-tree: MAD 0.12-0.23); the
/// current one reaches full power everywhere, so a spread that wide is host noise a rerun can
/// bring back, and this list is where it would be recorded.
const SHORTFALLS: &[(&str, f64)] = &[];

/// Per (shading, triangles, viewpoint), per structure, frame -> seconds.
type Frames = BTreeMap<(String, usize, String), BTreeMap<String, BTreeMap<u32, f64>>>;

fn committed_frames(name: &str) -> Frames {
    let mut reader = csv::Reader::from_path(common::repo(&format!("results/{name}/frames.csv"))).unwrap();
    let header = reader.headers().unwrap().clone();
    let col = |k: &str| {
        header
            .iter()
            .position(|h| h == k)
            .unwrap_or_else(|| panic!("no column {k}"))
    };
    let (t, s, sh, v, f, secs) = (
        col("triangles"),
        col("structure"),
        col("shading"),
        col("viewpoint"),
        col("frame"),
        col("frame_s"),
    );
    let mut out = Frames::new();
    for r in reader.records() {
        let r = r.unwrap();
        out.entry((r[sh].to_string(), r[t].parse().unwrap(), r[v].to_string()))
            .or_default()
            .entry(r[s].to_string())
            .or_default()
            .insert(r[f].parse().unwrap(), r[secs].parse().unwrap());
    }
    out
}

/// Shares of trials called faster at [`TRUE_SPEEDUP`] and equal at 1, resampling `centred`
/// log speed-ups into `n` frames.
fn trials(centred: &[f64], n: usize, seed: u32) -> (f64, f64) {
    let (mut faster, mut equal) = (0, 0);
    for trial in 0..TRIALS {
        let stream = Stream::new(seed, trial, None);
        let draw = |shift: f64, offset: u32| -> Vec<f64> {
            (0..n as u32)
                .map(|i| {
                    let k = (stream.unit(offset + i) * centred.len() as f64) as usize;
                    (shift + centred[k.min(centred.len() - 1)]).exp()
                })
                .collect()
        };
        if Speedup::of(&draw(TRUE_SPEEDUP.ln(), 0), Cameras::Random { seed: 0 }).comparison() == Comparison::Faster {
            faster += 1;
        }
        if !matches!(
            Speedup::of(&draw(0.0, n as u32), Cameras::Random { seed: 0 }).comparison(),
            Comparison::Faster | Comparison::Slower
        ) {
            equal += 1;
        }
    }
    (faster as f64 / TRIALS as f64, equal as f64 / TRIALS as f64)
}

fn check(name: &str) {
    let spec = FramesSpec::load(&common::repo(&format!("experiments/{name}.toml"))).unwrap();
    assert!(
        matches!(spec.cameras, Cameras::Random { .. }),
        "{name}: the power argument holds for independent frames only"
    );
    let n = spec.frames as usize;
    let subject = spec.claim.subject.as_str();
    let mut worst = (f64::INFINITY, f64::INFINITY);
    let mut cells = 0;
    let mut short = Vec::new();
    let mut recovered = Vec::new();
    for ((shading, triangles, viewpoint), by_structure) in committed_frames(name) {
        let ours = &by_structure[subject];
        for (other, theirs) in by_structure.iter().filter(|(s, _)| s.as_str() != subject) {
            let logs: Vec<f64> = ours.iter().map(|(f, s)| (theirs[f] / s).ln()).collect();
            assert_eq!(logs.len(), n, "{name}: every frame of the file is committed");
            let m = median(&logs);
            let centred: Vec<f64> = logs.iter().map(|x| x - m).collect();
            let (power, aa) = trials(&centred, n, cells);
            eprintln!(
                "{name} {shading} {triangles} {viewpoint} {other}: spread (MAD) {:.3}, power {power:.3}, A/A equal {aa:.3}",
                median(&centred.iter().map(|x| x.abs()).collect::<Vec<_>>())
            );
            let cell = format!("{name} {shading} {triangles} {viewpoint} {other}");
            let listed = SHORTFALLS.iter().find(|(c, _)| *c == cell);
            if power < POWER {
                short.push((cell, power));
            } else {
                if listed.is_some() {
                    recovered.push(format!("{cell}: listed as short of {POWER} but reaches {power:.3}"));
                }
                worst.0 = worst.0.min(power);
            }
            worst.1 = worst.1.min(aa);
            cells += 1;
        }
    }
    assert!(cells > 0, "{name}: no frames compared");
    assert!(recovered.is_empty(), "{}", recovered.join("\n"));
    eprintln!(
        "{name}: {cells} cells and pairs, {n} frames each: least power {:.3} outside the listed shortfalls, least A/A equal {:.3}",
        worst.0, worst.1
    );
    for (listed, _) in SHORTFALLS.iter().filter(|(c, _)| c.starts_with(&format!("{name} "))) {
        assert!(
            short.iter().any(|(c, _)| c == listed),
            "{listed}: a listed shortfall no longer found"
        );
    }
    for (cell, power) in &short {
        let listed = SHORTFALLS.iter().find(|(c, _)| c == cell);
        assert!(
            listed.is_some_and(|(_, p)| format!("{p:.3}") == format!("{power:.3}")),
            "{cell}: a true {TRUE_SPEEDUP}x speed-up is called faster in only {:.1} % of trials ({})",
            100.0 * power,
            listed.map_or("not a listed shortfall".to_string(), |(_, p)| format!(
                "listed at {p:.3}"
            ))
        );
    }
    assert!(
        worst.0 >= POWER,
        "{name}: a true {TRUE_SPEEDUP}x speed-up is called faster in only {:.1} % of trials somewhere",
        100.0 * worst.0
    );
    assert!(
        worst.1 >= AA_EQUAL,
        "{name}: an A/A pair is called equal in only {:.1} % of trials somewhere",
        100.0 * worst.1
    );
}

#[test]
fn scaling_decides_a_true_speedup_and_calls_an_aa_pair_equal() {
    check("scaling");
}

#[test]
fn the_walkthrough_decides_a_true_speedup_and_calls_an_aa_pair_equal() {
    check("walkthrough");
}
