//! A sampling scheme from a points file: a file holding a built-in scheme's own points renders
//! that scheme's images bit for bit on the CPU and on the GPU, an experiment naming one writes it
//! into every output like a built-in, and bad files are refused with the file, line and value.

use crate::common;
use penumbra::render::cpu::CpuBackend;
use penumbra::render::{Backend, Frame, Sampling, View};
use penumbra::sampling::bluenoise::{masks, TILE};
use penumbra::sampling::points::{Domain, Layout, PointSet, PointsId, Settings};
use penumbra::sampling::{pmj02, sobol, DiskScheme, Pattern, Site};
use penumbra::scene::Scene;
use std::path::Path;

/// A 24-bit fraction as text that parses back to exactly it.
fn fraction(q: u32) -> String {
    format!("{}", q as f64 / (1u32 << 24) as f64)
}

/// Writes `rows` (u, v) as a points file.
fn write_points(path: &Path, rows: impl Iterator<Item = (u32, u32)>) {
    let mut text = String::from("# written by the test\nu,v\n");
    for (u, v) in rows {
        text += &format!("{},{}\n", fraction(u), fraction(v));
    }
    std::fs::write(path, text).unwrap();
}

/// Registers a set under `name`.
fn install(name: &str, settings: Settings, needed: u32) -> DiskScheme {
    DiskScheme::Points(PointsId::install(PointSet::load(name, &settings, needed).unwrap()).unwrap())
}

/// Renders the measuring view of the sphere scene with 16 rays.
fn render(backend: &mut dyn Backend, scene: &Scene, scheme: DiskScheme, pattern: Pattern, seed: u32) -> Frame {
    let view = View {
        camera: &scene.cameras["measure"],
        width: 80,
        height: 72,
    };
    backend
        .render(
            scene,
            view,
            Sampling {
                scheme,
                pattern,
                seed,
                frame: 0,
            },
        )
        .unwrap()
}

/// The shipped sphere scene (its light sampled 16 times).
fn scene() -> Scene {
    Scene::load(&common::repo("experiments/scenes/sphere.toml")).unwrap()
}

#[test]
fn a_points_file_holding_a_built_in_schemes_points_renders_its_images_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    // bluenoise-cp: the shared (0,2) set rotated by the two masks, as a mask layout.
    let set = dir.path().join("sobol.csv");
    write_points(
        &set,
        (0..16).map(|k| (sobol::sobol_dim0(k) >> 8, sobol::sobol_dim1(k) >> 8)),
    );
    let mask = dir.path().join("mask.csv");
    let fix = |v: f64| (v * (1u32 << 24) as f64) as u32;
    write_points(
        &mask,
        (0..TILE * TILE).map(|i| (fix(masks()[0][i]), fix(masks()[1][i]))),
    );
    let cp = install(
        "test-bluenoise-cp",
        Settings {
            path: set,
            domain: Domain::Square,
            layout: Layout::Mask(TILE as u32),
            mask: Some(mask),
        },
        16,
    );
    // pmj02's shared pattern of seed 5: its sequence under that seed's one digital shift.
    let seed = 5;
    let stream = Site::shared(seed, 0, 0).stream;
    let shift = (stream.u32(0x7fff_fffc) >> 8, stream.u32(0x7fff_fffb) >> 8);
    let shared = dir.path().join("pmj02.csv");
    let q = |x: f64| (x * (1u32 << 24) as f64) as u32;
    write_points(
        &shared,
        (0..16).map(|k| pmj02::point(k, shift)).map(|(u, v)| (q(u), q(v))),
    );
    let pmj = install(
        "test-pmj02-shared",
        Settings {
            path: shared,
            domain: Domain::Square,
            layout: Layout::Shared,
            mask: None,
        },
        16,
    );
    let scene = scene();
    let cases = [
        (DiskScheme::BluenoiseCp, cp, Pattern::PerPixel, 3),
        (DiskScheme::BluenoiseCp, cp, Pattern::Shared, 4),
        (DiskScheme::Pmj02, pmj, Pattern::Shared, seed),
    ];
    let mut cpu = CpuBackend::default();
    for (built_in, file, pattern, seed) in cases {
        let (a, b) = (
            render(&mut cpu, &scene, built_in, pattern, seed),
            render(&mut cpu, &scene, file, pattern, seed),
        );
        assert_eq!(a.visibility, b.visibility, "cpu: {built_in} against {file}, {pattern}");
        assert_eq!(a.radiance, b.radiance, "cpu: {built_in} against {file}, {pattern}");
    }
    let Some(mut gpu) = common::gpu() else { return };
    for (built_in, file, pattern, seed) in cases {
        let (a, b) = (
            render(&mut *gpu, &scene, built_in, pattern, seed),
            render(&mut *gpu, &scene, file, pattern, seed),
        );
        assert_eq!(a.visibility, b.visibility, "gpu: {built_in} against {file}, {pattern}");
        assert_eq!(a.radiance, b.radiance, "gpu: {built_in} against {file}, {pattern}");
    }
}

/// The committed example, and a tile layout and a set on the disk: the GPU renders what the
/// CPU does, as for the built-ins (visibility within one ray's worth at a few f32 grazing
/// pixels).
#[test]
fn points_schemes_render_the_same_on_both_backends() {
    let dir = tempfile::tempdir().unwrap();
    let fib = install(
        "test-fibonacci16",
        Settings {
            path: common::repo("experiments/patterns/fibonacci16.csv"),
            domain: Domain::Square,
            layout: Layout::Shared,
            mask: None,
        },
        16,
    );
    // A 4 x 4 tile whose pixels each hold 16 jittered points (u, v), the tile pixel-major.
    let tile = dir.path().join("tile.csv");
    let cell = |i: u32, k: u32| ((k % 4) * 4 + i % 4, (k / 4) * 4 + i / 4);
    write_points(
        &tile,
        (0..16u32)
            .flat_map(|i| (0..16).map(move |k| cell(i, k)))
            .map(|(a, b)| (a << 20, b << 20)),
    );
    let tiled = install(
        "test-tile",
        Settings {
            path: tile,
            domain: Domain::Square,
            layout: Layout::Tile(4),
            mask: None,
        },
        16,
    );
    let disk = dir.path().join("disk.csv");
    let ring: String = (0..16)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 16.0;
            format!("{} {}\n", 0.9 * a.cos(), 0.9 * a.sin())
        })
        .collect();
    std::fs::write(&disk, ring).unwrap();
    let on_disk = install(
        "test-ring",
        Settings {
            path: disk,
            domain: Domain::Disk,
            layout: Layout::Shared,
            mask: None,
        },
        16,
    );
    let Some(mut gpu) = common::gpu() else { return };
    let scene = scene();
    for scheme in [fib, tiled, on_disk] {
        let g = render(&mut *gpu, &scene, scheme, Pattern::PerPixel, 2);
        let c = render(&mut CpuBackend::default(), &scene, scheme, Pattern::PerPixel, 2);
        let (mut differing, mut max) = (0, 0f32);
        for (a, b) in g.visibility[0].iter().zip(&c.visibility[0]) {
            let d = (a - b).abs();
            differing += (d > 1e-6) as usize;
            max = max.max(d);
        }
        assert!(
            differing <= 10 && max <= 1.0 / 16.0 + 1e-6,
            "{scheme}: {differing} pixels differ, max {max}"
        );
    }
}

/// An experiment with schemes `uniform`, `paper` and the example file, the verdict set to the
/// file against uniform.
fn own_pattern_experiment(dir: &Path) -> std::path::PathBuf {
    let fib = common::repo("experiments/patterns/fibonacci16.csv");
    common::tiny_experiment(dir, |t| {
        t.replace(
            "schemes = [\"uniform\", \"paper\"]",
            "schemes = [\"uniform\", \"paper\", \"points:fib\"]",
        )
        .replace("samples = [4, 16]", "samples = [16]")
            + &format!(
                "\n[points.fib]\npath = \"{}\"\n\n[verdict]\nsubject = \"points:fib\"\nbaseline = \"uniform\"\n\n[figures]\ncamera = \"picture\"\nwidth = 32\nheight = 24\nsamples = 16\nground_truth_samples = 64\n",
                fib.display()
            )
    })
}

#[test]
fn a_points_scheme_appears_in_every_output_like_a_built_in() {
    let dir = tempfile::tempdir().unwrap();
    let example = common::repo("experiments/patterns/fibonacci16.csv");
    let copy = dir.path().join("fib.csv");
    std::fs::copy(&example, &copy).unwrap();
    let exp = own_pattern_experiment(dir.path());
    let text = std::fs::read_to_string(&exp).unwrap();
    std::fs::write(
        &exp,
        text.replace(&example.display().to_string(), &copy.display().to_string()),
    )
    .unwrap();
    let out = dir.path().join("out");
    let (code, err) = common::sweep(&[exp.as_os_str(), "--out".as_ref(), out.as_os_str()]);
    assert_eq!(code, 0, "{err}");
    let read = |f: &str| std::fs::read_to_string(out.join(f)).unwrap();
    let runs = read("runs.csv");
    assert_eq!(
        runs.lines().filter(|l| l.contains("points:fib")).count(),
        2 * 2,
        "two patterns x two seeds"
    );
    assert!(read("summary.csv").contains("points:fib"));
    let report = read("report.md");
    assert!(report.contains("`points:fib` against `uniform`"), "the verdict's pair");
    assert!(report.contains("with `points:fib` and"), "the verdict's sentences");
    assert!(
        report.contains("| points:fib | points file"),
        "the scheme table names its source"
    );
    let manifest = read("manifest.toml");
    assert!(
        manifest.contains(&copy.display().to_string()),
        "the manifest lists the points file"
    );
    for f in [
        "images/points-fib_per-pixel_16.exr",
        "images/points-fib_shared_16.exr",
        "images/fig2_measure.png",
        "images/fig2_picture.png",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    // Edited in place, the file is a new scheme to the journal: its runs are redone, the other
    // schemes' reused.
    let text = std::fs::read_to_string(&copy).unwrap();
    std::fs::write(&copy, text.replace("0.031250,0.000000", "0.031250,0.500000")).unwrap();
    let (code, err) = common::sweep(&[exp.as_os_str(), "--out".as_ref(), out.as_os_str()]);
    assert_eq!(code, 0, "{err}");
    let again = read("runs.csv");
    let rows = |csv: &str, s: &str| {
        csv.lines()
            .filter(|l| l.contains(s))
            .map(String::from)
            .collect::<Vec<_>>()
    };
    assert_ne!(
        rows(&again, "points:fib"),
        rows(&runs, "points:fib"),
        "the edited file's runs are redone"
    );
    assert_eq!(
        rows(&again, "uniform"),
        rows(&runs, "uniform"),
        "the others' are reused"
    );
    assert!(err.contains("units taken from the journal"), "{err}");
}

/// What spreadsheets and printouts write is read: a byte-order mark, a header, CRLF line ends,
/// points on the disk's rim printed to six decimals.
#[test]
fn spreadsheet_files_and_rim_points_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rim.csv");
    let rim: String = (0..16)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 16.0;
            format!("{:.6},{:.6}\r\n", a.cos(), a.sin())
        })
        .collect();
    std::fs::write(&path, format!("\u{feff}x,y\r\n{rim}")).unwrap();
    let settings = Settings {
        path,
        domain: Domain::Disk,
        layout: Layout::Shared,
        mask: None,
    };
    let set = PointSet::load("test-rim", &settings, 16).unwrap();
    assert_eq!(set.count, 16);
    for k in 0..16 {
        let p = set.point(k, [0, 0], 0);
        assert!((p.length() - 1.0).abs() < 1e-6, "{k}: {p}");
    }
}

/// Each bad points file or table: exit 2, the file (and line) and the value named, nothing
/// written.
#[test]
fn bad_points_files_are_refused_with_file_line_and_value() {
    let dir = tempfile::tempdir().unwrap();
    let good: String = (0..16)
        .map(|k| format!("{},{}\n", (k as f64 + 0.5) / 16.0, 0.25))
        .collect();
    let cases: Vec<(&str, Vec<u8>, &str, Vec<&str>)> = vec![
        (
            "out of range",
            format!("u,v\n0.5,0.5\n1.5,0.2\n{good}").into_bytes(),
            "",
            vec!["pts.csv:3", "1.5", "outside [0, 1)"],
        ),
        (
            "negative",
            format!("{good}-0.1 0.2\n").into_bytes(),
            "",
            vec!["pts.csv:17", "-0.1"],
        ),
        (
            "NaN",
            format!("0.5,NaN\n{good}").into_bytes(),
            "",
            vec!["pts.csv:1", "`NaN` is not a finite number"],
        ),
        (
            "NaN first",
            format!("nan,nan\n{good}").into_bytes(),
            "",
            vec!["pts.csv:1", "`nan` is not a finite number"],
        ),
        (
            "inf first",
            format!("inf inf\n{good}").into_bytes(),
            "",
            vec!["pts.csv:1", "`inf` is not a finite number"],
        ),
        (
            "one written as 0.99..9",
            format!("{good}0.99999999999999999,0.5\n").into_bytes(),
            "",
            vec!["pts.csv:17", "`0.99999999999999999` outside [0, 1)"],
        ),
        (
            "three values",
            format!("0.5,0.5,0.5\n{good}").into_bytes(),
            "",
            vec!["pts.csv:1", "expected two numbers"],
        ),
        (
            "too few",
            "0.1,0.1\n0.2,0.2\n".to_string().into_bytes(),
            "",
            vec!["pts.csv", "2 points per pixel, fewer than the 16"],
        ),
        (
            "empty",
            b"# nothing here\n\n".to_vec(),
            "",
            vec!["pts.csv", "holds no points"],
        ),
        (
            "binary",
            vec![0x7f, b'E', b'L', b'F', 0, 1, 2, 0],
            "",
            vec!["pts.csv", "binary"],
        ),
        (
            "not utf-8",
            vec![0xff, 0xfe, b'0', b'.', b'5'],
            "",
            vec!["pts.csv", "not UTF-8"],
        ),
        (
            "off the disk",
            format!("{}0.9,0.9\n", "0.1,0.1\n".repeat(16)).into_bytes(),
            "domain = \"disk\"\n",
            vec!["pts.csv:17", "outside the unit disk"],
        ),
        (
            "tile uneven",
            good.clone().into_bytes(),
            "layout = \"tile\"\ntile = 3\n",
            vec!["pts.csv", "do not split evenly"],
        ),
        (
            "tile without side",
            good.clone().into_bytes(),
            "layout = \"tile\"\n",
            vec!["bad.toml", "points.own.layout", "needs `tile`"],
        ),
        (
            "unknown layout",
            good.clone().into_bytes(),
            "layout = \"spiral\"\n",
            vec!["bad.toml", "points.own.layout", "`spiral`"],
        ),
        (
            "mask without file",
            good.clone().into_bytes(),
            "layout = \"mask\"\ntile = 4\n",
            vec!["bad.toml", "points.own.mask"],
        ),
    ];
    let pts = dir.path().join("pts.csv");
    for (what, bytes, extra, wanted) in cases {
        std::fs::write(&pts, &bytes).unwrap();
        let text = std::fs::read_to_string(own_pattern_experiment(dir.path()))
            .unwrap()
            .replace("points:fib", "points:own")
            .replace("[points.fib]", "[points.own]")
            .replace(
                &format!(
                    "path = \"{}\"",
                    common::repo("experiments/patterns/fibonacci16.csv").display()
                ),
                &format!("path = \"{}\"\n{extra}", pts.display()),
            );
        let exp = dir.path().join("bad.toml");
        std::fs::write(&exp, text).unwrap();
        let out = dir.path().join("out");
        let (code, err) = common::sweep(&[exp.as_os_str(), "--out".as_ref(), out.as_os_str()]);
        assert_eq!(code, 2, "{what}: {err}");
        for w in wanted {
            assert!(err.contains(w), "{what}: no `{w}` in {err}");
        }
        assert!(!err.contains("panicked"), "{what}: {err}");
        assert!(!out.exists(), "{what}: wrote {}", out.display());
    }
    // Names and tables that do not match.
    let base = std::fs::read_to_string(own_pattern_experiment(dir.path())).unwrap();
    let missing = base.replace("[points.fib]", "[points.other]");
    common::rejected_at(dir.path(), &missing, "points.other");
    let unnamed = base.replace("\"points:fib\"]", "\"points:../fib\"]");
    common::rejected_at(dir.path(), &unnamed, "sweep.schemes");
    let no_table = base.replace("points:fib\"]", "points:fib\", \"points:lost\"]");
    common::rejected_at(dir.path(), &no_table, "sweep.schemes[3]");
    let lonely_verdict = base.replace("baseline = \"uniform\"", "baseline = \"sobol\"");
    common::rejected_at(dir.path(), &lonely_verdict, "verdict.baseline");
}
