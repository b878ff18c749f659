//! Scenes exported for other renderers and their images judged against the exact reference:
//! the Mitsuba file says what penumbra simulates, penumbra's own render is judged unbiased by
//! the independent exact path, bad images and scenes are refused naming the file, and the
//! committed results/peers recompute from their CSVs.

use crate::common;
use penumbra::metrics::stats::mean_ci;
use penumbra::output::images::write_exr;
use std::path::{Path, PathBuf};
use std::process::Command;

fn run(bin: &str, args: &[&str]) -> (i32, String) {
    let exe = match bin {
        "export" => env!("CARGO_BIN_EXE_export"),
        _ => env!("CARGO_BIN_EXE_judge"),
    };
    let out = Command::new(exe).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn sphere() -> String {
    common::repo("experiments/scenes/sphere.toml").display().to_string()
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A penumbra export of the measuring view at 32 x 8 (a strip across the edge: 2.5 mm pixels,
/// a penumbra six pixels wide).
fn penumbra_strip(dir: &Path, spp: &str, seeds: &str) -> PathBuf {
    let out = dir.join("penumbra");
    let (code, err) = run(
        "export",
        &[
            &sphere(),
            "--camera",
            "measure",
            "--size",
            "32x8",
            "--to",
            "penumbra",
            "--spp",
            spp,
            "--seeds",
            seeds,
            "--out",
            path(&out),
        ],
    );
    assert_eq!(code, 0, "{err}");
    out
}

#[test]
fn the_mitsuba_file_holds_the_scene_penumbra_renders() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    let (code, err) = run(
        "export",
        &[
            &sphere(),
            "--camera",
            "picture",
            "--size",
            "64x48",
            "--to",
            "mitsuba",
            "--out",
            path(&out),
        ],
    );
    assert_eq!(code, 0, "{err}");
    let xml = std::fs::read_to_string(out.join("scene.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let find = |tag: &str, ty: &str| {
        doc.descendants()
            .find(|n| n.has_tag_name(tag) && n.attribute("type") == Some(ty))
            .unwrap()
    };
    let value = |n: roxmltree::Node, name: &str| {
        n.descendants()
            .find(|c| c.attribute("name") == Some(name))
            .and_then(|c| c.attribute("value"))
            .unwrap()
            .to_string()
    };
    // Direct lighting by emitter sampling alone: the transport penumbra simulates.
    let integrator = find("integrator", "direct");
    assert_eq!(value(integrator, "emitter_samples"), "1");
    assert_eq!(value(integrator, "bsdf_samples"), "0");
    let sensor = find("sensor", "perspective");
    assert_eq!(value(sensor, "fov"), "34.0");
    assert_eq!(value(sensor, "fov_axis"), "y");
    assert_eq!(value(sensor, "width"), "64");
    assert_eq!(value(sensor, "height"), "48");
    assert!(sensor
        .descendants()
        .any(|n| n.has_tag_name("rfilter") && n.attribute("type") == Some("box")));
    // The disk: radiance of a Lambertian disk emitting 60 W from radius 0.02 m, and its
    // transform taking the unit disk's normal +z to the light's -z at the light's centre.
    let disk = find("shape", "disk");
    let l: f64 = value(disk, "radiance")
        .split(',')
        .next()
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let expected = 60.0 / (std::f64::consts::PI.powi(2) * 0.02 * 0.02);
    assert!((l / expected - 1.0).abs() < 1e-12, "{l} vs {expected}");
    let matrix = disk
        .descendants()
        .find(|n| n.has_tag_name("matrix"))
        .unwrap()
        .attribute("value")
        .unwrap();
    let m: Vec<f64> = matrix.split_whitespace().map(|v| v.parse().unwrap()).collect();
    assert_eq!(m.len(), 16);
    let column = |c: usize| [m[c], m[4 + c], m[8 + c]];
    assert_eq!(column(2), [0.0, 0.0, -1.0], "unit normal maps to the light's");
    assert_eq!(column(3), [0.0, 0.0, 2.0], "centre");
    for c in 0..2 {
        let len = column(c).iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((len - 0.02).abs() < 1e-15, "in-plane axes scaled by the radius");
    }
    let sphere = find("shape", "sphere");
    assert_eq!(value(sphere, "radius"), "0.25");
    assert_eq!(value(sphere, "reflectance"), "0.8, 0.8, 0.8");
    let view = std::fs::read_to_string(out.join("view.toml")).unwrap();
    assert!(
        view.contains("pixel = \"box\"") && view.contains("camera = \"picture\""),
        "{view}"
    );
}

#[test]
fn scenes_the_file_would_render_otherwise_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(common::repo("experiments/scenes/sphere.toml")).unwrap();
    // A camera under the light looking up sees its disk, a surface in Mitsuba only.
    let looking_up = base.replace(
        "[cameras.picture]",
        "[cameras.up]\nprojection = \"perspective\"\nposition = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 2.0]\nup = [0.0, 1.0, 0.0]\nfov_y = 20.0\n\n[cameras.picture]",
    );
    let scene = dir.path().join("up.toml");
    std::fs::write(&scene, looking_up).unwrap();
    for (to, renderer) in [("mitsuba", "which Mitsuba renders"), ("pbrt", "which pbrt renders")] {
        let (code, err) = run(
            "export",
            &[
                path(&scene),
                "--camera",
                "up",
                "--size",
                "16x16",
                "--to",
                to,
                "--out",
                path(&dir.path().join("o")),
            ],
        );
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains("up.toml") && err.contains("sees light 0's disk") && err.contains(renderer),
            "{err}"
        );
    }
    let (code, err) = run(
        "export",
        &[
            &sphere(),
            "--camera",
            "nowhere",
            "--size",
            "16x16",
            "--to",
            "mitsuba",
            "--out",
            path(&dir.path().join("o")),
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("no camera `nowhere`") && err.contains("`measure`"),
        "{err}"
    );
    let (code, err) = run(
        "export",
        &[
            &sphere(),
            "--camera",
            "measure",
            "--size",
            "16by16",
            "--to",
            "mitsuba",
            "--out",
            path(&dir.path().join("o")),
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("WIDTHxHEIGHT"), "{err}");
    assert!(!dir.path().join("o").exists(), "a refused export writes nothing");
}

/// A box filter's rays cover the pixel's square, not its centre: a disk that reaches a fifth
/// of a pixel into the view, or one smaller than the rays' spacing, is a surface the exported
/// renderer sees; and a light between another light and the ground shadows it there and not
/// in penumbra. Each export is refused, naming the light.
#[test]
fn lights_seen_between_pixel_centres_or_shadowing_others_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    // A top-down view from `height`, over the ground.
    let scene = |height: f64, lights: &str| {
        format!(
            "[cameras.top]\nprojection = \"orthographic\"\nposition = [0.0, 0.0, {height:?}]\nlook_at = [0.0, 0.0, 0.0]\n\
             up = [0.0, 1.0, 0.0]\nwidth = 0.08\n\n[[planes]]\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\
             albedo = 0.8\n{lights}"
        )
    };
    let disk = |c: [f64; 3], r: f64| {
        format!(
            "\n[[lights]]\ntype = \"disk\"\ncenter = {c:?}\nnormal = [0.0, 0.0, -1.0]\nradius = {r}\npower = 60.0\nsamples = 16\n"
        )
    };
    let cases = [
        // The view spans x in [-0.04, 0.04] in 5 mm pixels; this disk's edge is at 0.039,
        // 0.2 px into the last column of rows 6 to 9, far from its centres (0.0375).
        (
            "edge",
            3.0,
            disk([0.059, 0.0, 1.0], 0.02),
            "the camera rays of 4 pixels meet it",
        ),
        // 0.4 mm across, 0.85 mm from the nearest ray of a 5 x 5 lattice of 1.25 mm spacing.
        (
            "tiny",
            3.0,
            disk([0.0006, 0.0006, 1.0], 0.0002),
            "its centre, between the pixels' rays",
        ),
        // Seen from under both lights.
        (
            "stacked",
            0.5,
            disk([0.0, 0.0, 2.0], 0.02) + &disk([0.0, 0.0, 1.0], 0.05),
            "light 1's disk may shadow light 0",
        ),
        // A disk blocks a point light's rays too.
        (
            "under-point",
            0.5,
            "\n[[lights]]\ntype = \"point\"\nposition = [0.0, 0.0, 2.0]\npower = 60.0\n".to_string()
                + &disk([0.0, 0.0, 1.0], 0.05),
            "light 1's disk may shadow light 0",
        ),
    ];
    let export = |file: &Path, to: &str, out: &Path| {
        run(
            "export",
            &[
                path(file),
                "--camera",
                "top",
                "--size",
                "16x16",
                "--to",
                to,
                "--out",
                path(out),
            ],
        )
    };
    for (name, height, lights, says) in cases {
        let file = dir.path().join(format!("{name}.toml"));
        std::fs::write(&file, scene(height, &lights)).unwrap();
        for to in ["mitsuba", "pbrt"] {
            let out = dir.path().join(format!("{name}-{to}"));
            let (code, err) = export(&file, to, &out);
            assert_eq!(code, 2, "{name} {to}: {err}");
            assert!(
                err.contains(&format!("{name}.toml")) && err.contains(says),
                "{name} {to}: {err}"
            );
            assert!(!out.exists());
        }
    }
    // Apart, neither light shadows the other where the view looks.
    let file = dir.path().join("apart.toml");
    std::fs::write(
        &file,
        scene(0.5, &(disk([0.0, 0.0, 2.0], 0.02) + &disk([1.0, 0.0, 1.0], 0.05))),
    )
    .unwrap();
    let (code, err) = export(&file, "pbrt", &dir.path().join("apart"));
    assert_eq!(code, 0, "{err}");
}

/// Penumbra's own CPU render against the exact reference, two independent paths (Monte Carlo
/// shadow rays and root-finding quadrature): over eight seeds the penumbra's mean signed error
/// is zero within its interval, the lit level is 1 within the estimator's weight noise, and
/// the width matches.
#[test]
fn penumbras_own_render_is_judged_unbiased() {
    let dir = tempfile::tempdir().unwrap();
    let images = penumbra_strip(dir.path(), "256", "8");
    let mut args: Vec<String> = (1..=8)
        .map(|s| {
            images
                .join(format!("penumbra-uniform-spp256-seed{s}.exr"))
                .display()
                .to_string()
        })
        .collect();
    let out = dir.path().join("judged");
    args.extend(["--out".into(), path(&out).into()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, err) = run("judge", &args);
    assert_eq!(code, 0, "{err}");
    let groups = read_csv(&out.join("groups.csv"));
    assert_eq!(groups.len(), 1);
    let g = &groups[0];
    let num = |k: &str| g[k].parse::<f64>().unwrap();
    assert_eq!(num("seeds"), 8.0);
    assert!(num("penumbra_bias").abs() <= num("penumbra_bias_ci95"), "{g:?}");
    assert!((num("lit_mean") - 1.0).abs() < 1e-3, "{g:?}");
    assert!(
        (num("width_10_90_px") - num("exact_width_10_90_px")).abs() <= num("width_10_90_px_ci95").max(0.05),
        "{g:?}"
    );
    // 256 rays: the RMSE is the binomial noise of a fraction, about sqrt(V (1 - V) / 256).
    assert!(num("penumbra_rmse") > 0.005 && num("penumbra_rmse") < 0.03, "{g:?}");
}

/// An image that is not of the view, not an EXR, without a usable channel, with a NaN, without
/// its view record, of another view, or of a scene edited since: each refused with status 2,
/// naming the file, and nothing written.
#[test]
fn images_that_are_not_of_the_view_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let images = penumbra_strip(dir.path(), "4", "1");
    let good = images.join("penumbra-uniform-spp4-seed1.exr");
    let out = dir.path().join("judged");
    let refused = |files: &[&Path], needle: &str| {
        let mut args: Vec<&str> = files.iter().map(|p| path(p)).collect();
        args.extend(["--out", path(&out)]);
        let (code, err) = run("judge", &args);
        assert_eq!(code, 2, "{needle}: {err}");
        assert!(err.contains(needle), "expected `{needle}` in: {err}");
        assert!(!out.exists(), "a refused judge writes nothing");
    };
    let small = images.join("small.exr");
    write_exr(&small, &[0.0; 16 * 8], 16, 8).unwrap();
    refused(&[&small], "a 16 x 8 image; the exported view is 32 x 8");
    let text = images.join("text.exr");
    std::fs::write(&text, "not an image").unwrap();
    refused(&[&text], "text.exr: not a readable EXR image");
    let nan = images.join("nan.exr");
    write_exr(&nan, &[f32::NAN; 32 * 8], 32, 8).unwrap();
    refused(&[&nan], "nan.exr: pixel (0, 0) is NaN");
    let z = images.join("z.exr");
    {
        use exr::prelude::*;
        let channels = SpecificChannels::build()
            .with_channel("Z")
            .with_pixel_fn(|_: Vec2<usize>| (0.5f32,));
        Image::from_channels((32, 8), channels).write().to_file(&z).unwrap();
    }
    refused(&[&z], "channels Z; the judge reads Y, or R, G and B");
    let alone = dir.path().join("alone.exr");
    std::fs::copy(&good, &alone).unwrap();
    refused(&[&alone], "no view.toml beside it");
    let other = dir.path().join("other");
    let (code, err) = run(
        "export",
        &[
            &sphere(),
            "--camera",
            "measure",
            "--size",
            "32x9",
            "--to",
            "penumbra",
            "--spp",
            "4",
            "--seeds",
            "1",
            "--out",
            path(&other),
        ],
    );
    assert_eq!(code, 0, "{err}");
    std::fs::rename(
        other.join("penumbra-uniform-spp4-seed1.exr"),
        other.join("elsewhere-seed1.exr"),
    )
    .unwrap();
    refused(&[&good, &other.join("elsewhere-seed1.exr")], "judge one view at a time");
    // An export of a copy of the scene, then the copy edited.
    let copy = dir.path().join("copy.toml");
    std::fs::copy(sphere(), &copy).unwrap();
    let edited = dir.path().join("edited");
    let (code, err) = run(
        "export",
        &[
            path(&copy),
            "--camera",
            "measure",
            "--size",
            "32x8",
            "--to",
            "penumbra",
            "--spp",
            "4",
            "--seeds",
            "1",
            "--out",
            path(&edited),
        ],
    );
    assert_eq!(code, 0, "{err}");
    std::fs::write(
        &copy,
        std::fs::read_to_string(&copy)
            .unwrap()
            .replace("radius = 0.25", "radius = 0.26"),
    )
    .unwrap();
    refused(
        &[&edited.join("penumbra-uniform-spp4-seed1.exr")],
        "changed since the export",
    );
    // One image twice, or two images of one name (a name is a seed of its group).
    refused(&[&good, &good], "given twice");
    let twin = dir.path().join("twin");
    let (code, err) = run(
        "export",
        &[
            &sphere(),
            "--camera",
            "measure",
            "--size",
            "32x8",
            "--to",
            "penumbra",
            "--spp",
            "4",
            "--seeds",
            "1",
            "--out",
            path(&twin),
        ],
    );
    assert_eq!(code, 0, "{err}");
    refused(
        &[&good, &twin.join("penumbra-uniform-spp4-seed1.exr")],
        "given twice, or named as",
    );
}

/// Scenes without a soft shadow of one disk light to judge on the view: the light under the
/// plane (no judged pixel), two lights, shading without shadow rays; each refused, naming it.
#[test]
fn views_without_a_shadow_to_judge_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(common::repo("experiments/scenes/sphere.toml")).unwrap();
    let cases = [
        ("below", base.replace("center = [0.0, 0.0, 2.0]", "center = [0.0, 0.0, -2.0]"), "nothing to judge"),
        (
            "two",
            format!("{base}\n[[lights]]\ntype = \"disk\"\ncenter = [0.5, 0.0, 2.0]\nnormal = [0.0, 0.0, -1.0]\nradius = 0.02\npower = 60.0\nsamples = 4\n"),
            "holds 2 light(s)",
        ),
        ("unshadowed", format!("{base}\n[shading]\nshadows = false\n"), "shading without shadow rays"),
    ];
    for (name, text, needle) in cases {
        let scene = dir.path().join(format!("{name}.toml"));
        std::fs::write(&scene, text).unwrap();
        let out = dir.path().join(name);
        let (code, err) = run(
            "export",
            &[
                path(&scene),
                "--camera",
                "measure",
                "--size",
                "16x4",
                "--to",
                "penumbra",
                "--spp",
                "4",
                "--seeds",
                "1",
                "--out",
                path(&out),
            ],
        );
        let err = if code == 0 {
            let (code, err) = run(
                "judge",
                &[
                    path(&out.join("penumbra-uniform-spp4-seed1.exr")),
                    "--out",
                    path(&dir.path().join("j")),
                ],
            );
            assert_eq!(code, 2, "{name}: {err}");
            err
        } else {
            assert_eq!(code, 2, "{name}: {err}");
            err
        };
        assert!(
            err.contains(needle) && err.contains(&format!("{name}.toml")),
            "{name}: {err}"
        );
        assert!(!dir.path().join("j").exists(), "{name}: a refused judge writes nothing");
    }
}

/// A CSV as one map per row.
fn read_csv(p: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut r = csv::Reader::from_path(p).unwrap();
    let headers = r.headers().unwrap().clone();
    r.records()
        .map(|rec| {
            headers
                .iter()
                .zip(rec.unwrap().iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// results/peers: every group's means and intervals recompute from judge.csv's rows, squared bias
/// plus variance equal its images' mean squared penumbra RMSE (the split's identity, so the
/// per-pixel split agrees with the per-image errors), and every row of the report's table is
/// groups.csv's row as written.
#[test]
fn committed_peers_recompute_from_their_csvs() {
    let dir = common::repo("results/peers");
    let rows = read_csv(&dir.join("judge.csv"));
    let groups = read_csv(&dir.join("groups.csv"));
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(!groups.is_empty());
    for g in &groups {
        let members: Vec<_> = rows
            .iter()
            .filter(|r| {
                r["group"] == g["group"]
                    && r["pixel_filter"] == g["pixel_filter"]
                    && r["shadow_origin_lift"] == g["shadow_origin_lift"]
            })
            .collect();
        let num = |k: &str| g[k].parse::<f64>().unwrap();
        assert_eq!(members.len() as f64, num("seeds"), "{g:?}");
        let col = |k: &str| members.iter().map(|r| r[k].parse::<f64>().unwrap()).collect::<Vec<_>>();
        for (mean, ci, column) in [
            ("penumbra_rmse", "penumbra_rmse_ci95", "penumbra_rmse"),
            ("penumbra_bias", "penumbra_bias_ci95", "penumbra_bias"),
            ("width_10_90_px", "width_10_90_px_ci95", "width_10_90_px"),
        ] {
            let m = mean_ci(&col(column));
            let same = |a: f64, b: f64| (a.is_nan() && b.is_nan()) || (a - b).abs() <= 1e-12 * a.abs().max(1.0);
            assert!(same(m.mean, num(mean)), "{mean} {g:?}");
            assert!(same(m.ci95, num(ci)), "{ci} {g:?}");
        }
        let mse: f64 = col("penumbra_rmse").iter().map(|r| r * r).sum::<f64>() / members.len() as f64;
        assert!(
            (num("bias2") + num("variance") - mse).abs() <= 1e-9 * mse,
            "split identity {g:?}: {mse}"
        );
        let row = format!(
            "| {} | {} | {} | {} | {:.5} +- {:.5} | {:+.5} +- {:.5} | {:.3} +- {:.3} | {:.3} |",
            g["group"],
            g["pixel_filter"],
            g["shadow_origin_lift"],
            g["seeds"],
            num("penumbra_rmse"),
            num("penumbra_rmse_ci95"),
            num("penumbra_bias"),
            num("penumbra_bias_ci95"),
            num("width_10_90_px"),
            num("width_10_90_px_ci95"),
            num("exact_width_10_90_px")
        );
        assert!(report.contains(&row), "report.md lacks `{row}`");
    }
}
