//! The real-time kind: frames continue each scheme's sequence through accumulation, a still
//! scene converges and a moving occluder leaves a ghost the running mean keeps, the CI twin's
//! outputs hold what the report claims, and bad files are refused at their key.

use crate::common;
use penumbra::experiment::realtime::reference::References;
use penumbra::experiment::realtime::spec::{RealtimeSpec, Variant};
use penumbra::render::cpu::CpuBackend;
use penumbra::render::denoise::{Accumulation, Accumulator};
use penumbra::render::{Backend, Sampling, View};
use penumbra::sampling::{DiskScheme, Pattern};
use penumbra::scene::{Light, Scene};

fn sphere(rays: u32) -> Scene {
    let mut scene = Scene::load(&common::repo("experiments/scenes/sphere.toml")).unwrap();
    for l in &mut scene.lights {
        if let Light::Disk(d) = l {
            d.samples = rays;
        }
    }
    scene
}

fn shadow(backend: &mut dyn Backend, scene: &Scene, scheme: DiskScheme, frame: u32) -> Vec<f32> {
    let view = View {
        camera: &scene.cameras["measure"],
        width: 24,
        height: 24,
    };
    let sampling = Sampling {
        scheme,
        pattern: Pattern::PerPixel,
        seed: 7,
        frame,
    };
    backend.render(scene, view, sampling).unwrap().visibility[0].clone()
}

/// Progressive schemes continue their sequence: the running mean of frames 0..4 of n rays is the
/// one frame of 4n rays, to f32 rounding, where the scheme's points do not depend on n (blue-noise
/// Sobol' continues too, but under the scramble fitted for n); re-seeded schemes draw new rays
/// each frame.
fn frames_continue_on(backend: &mut dyn Backend) {
    for scheme in [DiskScheme::Sobol, DiskScheme::Pmj02] {
        let (few, many) = (sphere(4), sphere(16));
        let mut acc = Accumulator::new(Accumulation::Mean, 24, 24);
        for f in 0..4 {
            acc.add(&shadow(backend, &few, scheme, f));
        }
        let whole = shadow(backend, &many, scheme, 0);
        let accumulated = acc.image();
        let partial = whole.iter().filter(|&&v| v > 0.0 && v < 1.0).count();
        assert!(
            partial > 20,
            "{scheme}: {partial} penumbra pixels; the view misses the edge"
        );
        for (i, (a, b)) in accumulated.iter().zip(&whole).enumerate() {
            assert!(
                (a - b).abs() < 1e-6,
                "{scheme}: pixel {i}: 4 frames of 4 rays {a}, one of 16 {b}"
            );
        }
    }
    let few = sphere(4);
    let (f0, f1) = (
        shadow(backend, &few, DiskScheme::Uniform, 0),
        shadow(backend, &few, DiskScheme::Uniform, 1),
    );
    assert_ne!(f0, f1, "uniform re-seeds each frame");
}

#[test]
fn frames_continue_each_schemes_sequence_through_accumulation() {
    frames_continue_on(&mut CpuBackend::default());
    if let Some(mut gpu) = common::gpu() {
        frames_continue_on(&mut *gpu);
    }
}

fn read(path: &std::path::Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header = r.headers().unwrap().clone();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            header
                .iter()
                .map(String::from)
                .zip(rec.iter().map(String::from))
                .collect()
        })
        .collect()
}

#[test]
fn the_ci_twin_converges_when_still_and_ghosts_when_moving() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::repo("experiments/realtime-ci.toml");
    common::run_experiment(&exp, dir.path(), &[]);
    for file in [
        "runs.csv",
        "summary.csv",
        "timings.csv",
        "report.md",
        "index.html",
        "plots/rmse_frames.svg",
    ] {
        assert!(dir.path().join(file).exists(), "{file} missing");
    }
    let summary = read(&dir.path().join("summary.csv"));
    let rmse = |variant: &str, scheme: &str, frames: &str, acc: &str, filter: &str| -> f64 {
        summary
            .iter()
            .find(|r| {
                r["variant"] == variant
                    && r["scheme"] == scheme
                    && r["rays"] == "4"
                    && r["frames"] == frames
                    && r["accumulation"] == acc
                    && r["filter"] == filter
            })
            .unwrap_or_else(|| panic!("{variant} {scheme} {frames} {acc} {filter} missing"))["rmse"]
            .parse()
            .unwrap()
    };
    // Uniform is unbiased: eight frames of four rays have about a third of one frame's error.
    let (one, eight) = (
        rmse("static", "uniform", "1", "mean", "none"),
        rmse("static", "uniform", "8", "mean", "none"),
    );
    assert!(eight < 0.5 * one, "static uniform: {one} at 1 frame, {eight} at 8");
    // The running mean keeps the three moving frames' ghost; the EMA (alpha 0.25) forgets it
    // faster, so after the stop the mean is further from the current exact image.
    let (mean, ema) = (
        rmse("moving", "uniform", "8", "mean", "none"),
        rmse("moving", "uniform", "8", "ema", "none"),
    );
    assert!(
        mean > eight && mean > ema,
        "moving: mean {mean}, ema {ema}, still {eight}"
    );
    // Every filter changes the still one-frame image, and every row has a finite width.
    let runs = read(&dir.path().join("runs.csv"));
    assert_eq!(
        runs.len(),
        2 * 4 * 2 * 3 * 3 * 4 * 4,
        "variants x schemes x rays x frames x acc x filters x seeds"
    );
    assert!(runs.iter().all(|r| r["width_px"].parse::<f64>().unwrap().is_finite()));
    // The sphere's reference is exact (quadrature): no share of any error is its noise.
    assert!(runs.iter().all(|r| r["reference_noise_mse"] == "0.0"), "{:?}", runs[0]);
    // Flicker is read at the last frame only, over the pixels of the penumbra that held still
    // through its window (on the still scene all of them; here the sphere moves in the window).
    for r in &runs {
        let flicker: f64 = r["flicker"].parse().unwrap();
        if r["frames"] != "8" {
            assert!(flicker.is_nan(), "{r:?}");
        } else if r["variant"] == "static" {
            assert!(flicker.is_finite() && flicker >= 0.0, "{r:?}");
        }
    }
    // The clamped history drops the moving sphere's ghost sooner than the same average unclamped.
    let ghost = |acc: &str| -> f64 {
        summary
            .iter()
            .find(|r| {
                r["variant"] == "moving"
                    && r["scheme"] == "uniform"
                    && r["rays"] == "4"
                    && r["frames"] == "8"
                    && r["accumulation"] == acc
                    && r["filter"] == "none"
            })
            .unwrap()["ghost"]
            .parse()
            .unwrap()
    };
    assert!(
        ghost("clamped") < ghost("ema"),
        "ghost: clamped {}, ema at the same alpha {}",
        ghost("clamped"),
        ghost("ema")
    );
    let report = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert!(report.contains("**Answer:**") && report.contains("## The paper's claim restated"));
    assert!(report.contains("The reference is exact"), "{report}");
    // The claim's table: per frame count a blue-noise pipeline at 4 rays at any cost, and one
    // at no more cost than the paper's frame where the timing places one there.
    let claim = &report[report.find("## The paper's claim restated").unwrap()..];
    let claim = &claim[..claim[3..].find("\n## ").map_or(claim.len(), |e| e + 3)];
    let blue_rows = |cost: &str| {
        claim
            .lines()
            .filter(|l| l.starts_with("| ") && l.contains(cost) && l.contains(" x 4 ray(s)"))
            .count()
    };
    assert_eq!(blue_rows("| any |"), 3, "{claim}");
    // A row at the paper's cost is answered only with a time the rule places within it; a frame
    // count without one says so.
    for frames in ["1", "2", "8"] {
        let row = claim
            .lines()
            .find(|l| l.starts_with(&format!("| {frames} | at most the paper's |")));
        match row {
            Some(row) => assert!(row.contains(": faster |") || row.contains(": equivalent |"), "{row}"),
            None => assert!(
                claim.lines().any(|l| l.starts_with("At ")
                    && l.contains("no blue-noise pipeline's time is placed")
                    && l.split(" frame(s)")
                        .next()
                        .unwrap()
                        .split([' ', ','])
                        .any(|w| w == frames)),
                "{frames} frames: no row at the paper's cost and no sentence saying why\n{claim}"
            ),
        }
    }
    // Each scheme's unfiltered running mean after every judged frame count, against uniform's.
    let temporal = &report[report.find("## Temporal error per scheme").expect("temporal section")..];
    for scheme in ["uniform", "paper", "bluenoise-cp", "sobol-bluenoise-t"] {
        for rays in [4, 16] {
            let row = temporal
                .lines()
                .find(|l| l.starts_with(&format!("| {scheme} x {rays} |")))
                .unwrap_or_else(|| panic!("{scheme} x {rays}: no row\n{temporal}"));
            assert_eq!(row.matches(" +- ").count(), 3, "{row}");
            if scheme == "uniform" {
                assert_eq!(row.matches("(1.00)").count(), 3, "{row}");
            }
        }
    }
}

#[test]
fn bad_realtime_files_are_refused_at_their_key() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(common::repo("experiments/realtime-ci.toml"))
        .unwrap()
        .replace(
            "\"scenes/",
            &format!("\"{}/", common::repo("experiments/scenes").display()),
        );
    for (edit, key, says) in [
        (
            ("\"atrous\"", "\"bilateral\""),
            "sweep.filters[2]",
            "unknown filter `bilateral`",
        ),
        (
            ("frames = 3", "frames = 8"),
            "motion.frames",
            "must stop before the last frame",
        ),
        (("shape = 0", "shape = 1"), "motion.shape", "not a sphere"),
        (("ema_alpha = 0.25", "ema_alpha = 0.0"), "sweep.ema_alpha", "(0, 1]"),
        (
            ("ema_alpha = 0.25", "ema_alpha = 0.25\nclamp_gamma = -1.0"),
            "sweep.clamp_gamma",
            "[0, 100]",
        ),
        (
            ("[timing]", "[verdict]\nlag_tolerance = 1.5\n\n[timing]"),
            "verdict.lag_tolerance",
            "(0, 1)",
        ),
        (
            ("[timing]", "[verdict]\nbudget_schemes = [[\"sobol\", 4]]\n\n[timing]"),
            "verdict.budget_schemes[0]",
            "not swept",
        ),
        (
            ("frames = [1, 2, 8]", "frames = [2, 1, 8]"),
            "sweep.frames[1]",
            "ascending",
        ),
        (
            (
                "variants = [\"static\", \"moving\"]",
                "variants = [\"static\", \"static\"]",
            ),
            "sweep.variants[1]",
            "`static` is listed twice",
        ),
        (
            (
                "[timing]",
                "[verdict]\nbudget_schemes = [[\"paper\", 16], [\"uniform\", 4], [\"paper\", 16]]\n\n[timing]",
            ),
            "verdict.budget_schemes[2]",
            "paper at 16 rays is listed twice",
        ),
        (
            ("seeds = [1, 2, 3, 4]", "seeds = [1, 1779033704]"),
            "sweep.seeds[1]",
            "a seed of the reference's renders",
        ),
    ] {
        let err = common::rejected_at(dir.path(), &text.replace(edit.0, edit.1), key);
        assert!(
            err.contains(&format!("key `{key}`")) && err.contains(says),
            "{edit:?}: {err}"
        );
    }
}

/// A rendered reference's noise estimate (a quarter of its two halves' squared difference) is
/// the error it actually has: the sphere scene with a triangle far outside the view has no exact
/// answer by construction, so its reference is rendered, while the same scene without the
/// triangle has the exact one, with the same receivers. 64 jittered rays per render, on the
/// f64 CPU backend and on the GPU that renders the committed references, keep the noise large
/// against any rounding; over about 3,000 penumbra pixels the summed squared errors agree within
/// 15 % (each sum's own sampling error is a few per cent; a rendered reference biased against
/// the exact image, or an estimator off by its factor of 2, would fail).
#[test]
fn a_rendered_references_noise_estimate_matches_its_error_against_the_exact_image() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = std::fs::read_to_string(common::repo("experiments/scenes/sphere.toml")).unwrap();
    std::fs::write(dir.path().join("exact.toml"), &sphere).unwrap();
    std::fs::write(
        dir.path().join("tri.obj"),
        "v 50 50 0.1\nv 50.1 50 0.1\nv 50 50.1 0.1\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("rendered.toml"),
        format!("{sphere}\n[[meshes]]\npath = \"tri.obj\"\n"),
    )
    .unwrap();
    let load = |scene: &str| {
        let text = format!(
            "kind = \"realtime\"\nname = \"noise\"\nscene = \"{scene}\"\nbackend = \"cpu\"\n\n\
             [measure]\ncamera = \"measure\"\nwidth = 128\nheight = 128\nplane = 0\n\n\
             [sweep]\nvariants = [\"static\"]\nschemes = [\"uniform\"]\nrays = [4]\nframes = [1]\n\
             accumulations = [\"mean\"]\nema_alpha = 0.1\nfilters = [\"none\"]\nseeds = [1]\n\n[reference]\nsamples = 64\n"
        );
        let path = dir.path().join(format!("{scene}.experiment.toml"));
        std::fs::write(&path, text).unwrap();
        RealtimeSpec::load(&path).unwrap_or_else(|e| panic!("{e}"))
    };
    let (rendered_spec, exact_spec) = (load("rendered.toml"), load("exact.toml"));
    let exact = References::default()
        .reference(&exact_spec, Variant::Static, 0, &mut CpuBackend::default())
        .unwrap();
    assert!(exact.exact);
    assert!(exact.mask.pixels.len() > 2000, "{}", exact.mask.pixels.len());
    let check = |name: &str, backend: &mut dyn Backend| {
        let rendered = References::default()
            .reference(&rendered_spec, Variant::Static, 0, backend)
            .unwrap();
        assert!(!rendered.exact);
        assert_eq!(rendered.receivers.pixels, exact.receivers.pixels);
        // Outside the exact penumbra every ray agrees, so the rendered mask is the exact one
        // less pixels whose few lit (or dark) rays all missed: compare sums, not means.
        let actual: f64 = exact
            .mask
            .pixels
            .iter()
            .map(|&i| (f64::from(rendered.image[i]) - f64::from(exact.image[i])).powi(2))
            .sum();
        let estimate = rendered.noise_mse * rendered.mask.pixels.len() as f64;
        let ratio = estimate / actual;
        println!(
            "{name}: noise estimate {estimate:.4e} over {} px, actual {actual:.4e} over {} px: {ratio:.3}",
            rendered.mask.pixels.len(),
            exact.mask.pixels.len()
        );
        assert!((ratio - 1.0).abs() < 0.15, "{name}: estimate / actual = {ratio}");
    };
    check("cpu", &mut CpuBackend::default());
    if let Some(mut gpu) = common::gpu() {
        check("gpu", &mut *gpu);
    }
}
