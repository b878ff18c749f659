//! The ambient-occlusion experiment kind (`kind = "ao"`): experiments/ao-ci.toml through the
//! binary (two meshes, every structure including brute force, the kd-tree and the field tuned
//! per mesh) writes its tables, images, plot and report, and every structure's AO image is
//! brute force's bit for bit; bad input is a
//! located error with exit status 2 and writes nothing; the verdict says when images differ.

use crate::common;

use penumbra::experiment::ao::report::verdict;
use penumbra::experiment::ao::{run_ao, AoSpec};
use penumbra::experiment::progress::Progress;
use penumbra::render::cpu::CpuBackend;

#[test]
fn the_ci_experiment_writes_its_outputs_and_every_structure_agrees() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ao-ci");
    let exp = common::repo("experiments/ao-ci.toml");
    common::run_experiment(&exp, &out, &[]);
    let csv = std::fs::read_to_string(out.join("ao.csv")).unwrap();
    let mut rows = csv::Reader::from_reader(csv.as_bytes());
    let header = rows.headers().unwrap().clone();
    let col = |name: &str| common::column(&header, name);
    let rows: Vec<csv::StringRecord> = rows.records().map(Result::unwrap).collect();
    // Per mesh: six structures with single rays, and bundled the three with bundles of their own.
    assert_eq!(rows.len(), 2 * (6 + 3), "{csv}");
    let bundled: Vec<&str> = rows
        .iter()
        .filter(|r| &r[col("issue")] == "bundled")
        .map(|r| &r[col("structure")])
        .collect();
    assert_eq!(bundled, ["kdtree", "kdtree-sah", "vlf"].repeat(2), "{csv}");
    for r in &rows {
        assert_eq!(&r[col("same_image_as_first")], "true", "{csv}");
        assert!(r[col("receivers")].parse::<usize>().unwrap() > 50, "{csv}");
        assert!(r[col("ao_rays")].parse::<u64>().unwrap() == 33 * r[col("receivers")].parse::<u64>().unwrap());
    }
    for file in [
        "report.md",
        "manifest.toml",
        "images/cow_brute.exr",
        "images/cow_vlf.png",
        "images/mech-holes-shark_kdtree.exr",
        "plots/frame_time.png",
        "plots/frame_time.svg",
        "index.html",
    ] {
        assert!(out.join(file).exists(), "{file} missing");
    }
    // Frame time is drawn as bars grouped by mesh, each mesh named under its group and each
    // structure in the legend.
    let svg = std::fs::read_to_string(out.join("plots/frame_time.svg")).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let texts: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text())
        .map(str::trim)
        .collect();
    for name in [
        "cow",
        "mech-holes-shark",
        "kdtree",
        "kdtree-sah",
        "vlf",
        "vlf bundled",
        "kdtree bundled",
        "bvh",
        "brute",
        "cwbvh",
        "95 % interval",
    ] {
        assert!(texts.contains(&name), "frame_time.svg lacks {name}: {texts:?}");
    }
    assert!(texts.iter().any(|t| t.ends_with("triangles")), "{texts:?}");
    common::browser::check_page(&out);
    // Each mesh's images are measured against brute force, which this experiment runs.
    let data = common::browser::page_data(&out).unwrap();
    for g in data["galleries"].as_array().unwrap() {
        let reference = &g["shots"][g["reference"].as_u64().expect("a reference") as usize];
        assert!(
            reference["exr"].as_str().unwrap().ends_with("_brute.exr"),
            "{}: reference {}",
            g["title"],
            reference["exr"]
        );
    }
    let tables = common::assert_tidy_tables(&out);
    assert_eq!(
        tables.len(),
        4,
        "ao.csv, rounds.csv, tuning.csv and tuning_rounds.csv: {tables:?}"
    );
    // Every timed frame is committed: each row's median and interval recompute from rounds.csv.
    let mut rounds = csv::Reader::from_path(out.join("rounds.csv")).unwrap();
    let rh = rounds.headers().unwrap().clone();
    let rc = |name: &str| common::column(&rh, name);
    let rounds: Vec<csv::StringRecord> = rounds.records().map(Result::unwrap).collect();
    for r in &rows {
        let mine: Vec<&csv::StringRecord> = rounds
            .iter()
            .filter(|x| {
                x[rc("mesh")] == r[col("mesh")]
                    && x[rc("structure")] == r[col("structure")]
                    && x[rc("issue")] == r[col("issue")]
            })
            .collect();
        let times: Vec<f64> = mine.iter().map(|x| x[rc("frame_s")].parse().unwrap()).collect();
        assert_eq!(times.len().to_string(), r[col("timed_frames")], "{r:?}");
        // One frame per round, rounds numbered from 0 in the order they ran.
        let numbers: Vec<usize> = mine.iter().map(|x| x[rc("round")].parse().unwrap()).collect();
        assert_eq!(numbers, (0..times.len()).collect::<Vec<_>>(), "{r:?}");
        let e = penumbra::timing::median_interval(&times);
        for (name, v) in [("frame_s", e.median), ("frame_s_lo", e.lo), ("frame_s_hi", e.hi)] {
            let committed: f64 = r[col(name)].parse().unwrap();
            assert!(
                (committed - v).abs() <= 1e-9 * v.abs(),
                "{name}: {committed} vs {v} from rounds.csv"
            );
        }
    }
    assert!(header.iter().any(|h| h == "vlf_depth") && header.iter().any(|h| h == "kdtree_max_depth"));
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("equals the first structure's, bit for bit"), "{report}");
    for row in [
        "| `kdtree-sah` bundled / `vlf` bundled |",
        "| `vlf` single / bundled |",
        "| `cwbvh` single / `vlf` bundled |",
    ] {
        assert!(report.contains(row), "the open question's table lacks {row}: {report}");
    }
    assert!(
        report.contains("the paper: 1.80-2.51x") && report.contains("Cow (5.8K)"),
        "{report}"
    );
}

#[test]
fn bad_input_is_located_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(common::repo("experiments/ao-ci.toml"))
        .unwrap()
        .replace("../assets/", &format!("{}/", common::repo("assets").display()));
    for (edit, key) in [
        (text.replace("\"vlf\", \"bvh\"", "\"vlf\", \"octree\""), "structures[3]"),
        (
            text.replace(
                "issue = [\"single\", \"bundled\"]",
                "issue = [\"bundled\", \"bundled\"]",
            ),
            "issue[1]",
        ),
        (text.replace("issue = [\"single\", \"bundled\"]", "issue = []"), "issue"),
        (
            text.replace("issue = [\"single\", \"bundled\"]", "issue = [\"bundled\"]"),
            "issue",
        ),
        (
            text.replace("issue = [\"single\", \"bundled\"]", "issue = [\"sideways\"]"),
            "issue",
        ),
        (
            text.replace(
                "max_depth = [8, 22]\nleaf_size = 2",
                "max_depth = [8, 22]\nleaf_size = 2\nsplit = \"median\"",
            ),
            "accel.kdtree-sah.split",
        ),
        (text.replace("rays = 33", "rays = 34"), "rays"),
        (text.replacen("repeats = 6", "repeats = 2", 1), "timing.repeats"),
        (text.replace("cow.off", "no-such.off"), "meshes[0].path"),
        (text.replace("depth = [2, 4]", "depth = [2, 9]"), "accel.vlf.depth"),
    ] {
        common::rejected_at(dir.path(), &edit, key);
    }
}

#[test]
fn the_verdict_reports_differing_images_and_speed_ups_from_the_rows() {
    let spec = AoSpec::load(&common::repo("experiments/ao-ci.toml")).unwrap();
    let mut small = spec.clone();
    small.meshes.truncate(1);
    small.structures.retain(|(s, _)| ["kdtree", "vlf"].contains(s));
    small.issues = vec![penumbra::accel::Issue::Single];
    small.width = 8;
    small.height = 8;
    let (mut rows, _) = run_ao(&small, &mut CpuBackend::default(), &Progress::default()).unwrap();
    assert!(verdict(&small, &rows).contains("equals"));
    rows[1].same_image = false;
    assert!(verdict(&small, &rows).contains("does NOT equal"));
    // Speed-ups from hand-set frame times, paired by round: apart, and within noise.
    rows[0].frame_seconds = vec![2.0, 2.1, 1.9, 2.0, 2.0];
    rows[1].frame_seconds = vec![1.0, 1.1, 0.9, 1.0, 1.0];
    let v = verdict(&small, &rows);
    assert!(
        v.contains("faster on 1 of 1 meshes, slower on 0, equivalent on 0, undecided on 0") && v.contains("cow 2.00 ["),
        "{v}"
    );
    rows[1].frame_seconds = vec![1.9, 2.2, 1.8, 2.1, 2.0];
    let v = verdict(&small, &rows);
    assert!(
        v.contains("faster on 0 of 1 meshes, slower on 0, equivalent on 0, undecided on 1")
            && v.contains("(undecided)"),
        "{v}"
    );
}

/// experiments/ao-ci.toml on the GPU (`--backend gpu`, lavapipe in CI): every structure's AO
/// image equals the first's bit for bit, single and direction-major alike (on the GPU every
/// structure, the BVHs and brute force included, takes the direction-major order); rows carry
/// the GPU's work counts and the open question's table its GPU rows in the GPU's words; the
/// report names the adapter. Against the f64 CPU's images, pixel by pixel.
#[test]
fn the_ci_experiment_runs_on_the_gpu() {
    let dir = tempfile::tempdir().unwrap();
    let Some((gpu, cpu)) = common::on_gpu_and_cpu(dir.path(), &common::repo("experiments/ao-ci.toml")) else {
        return;
    };
    let (header, rows) = common::table(&gpu.join("ao.csv"));
    let col = |name: &str| common::column(&header, name);
    assert_eq!(rows.len(), 2 * 6 * 2, "meshes x structures x issues");
    for r in &rows {
        assert_eq!(&r[col("same_image_as_first")], "true", "{r:?}");
        assert!(
            r[col("primitive_tests")].parse::<u64>().unwrap() > 0,
            "GPU work counted: {r:?}"
        );
        let receivers: u64 = r[col("receivers")].parse().unwrap();
        assert_eq!(r[col("ao_rays")].parse::<u64>().unwrap(), 33 * receivers, "{r:?}");
    }
    // A bundle on the GPU is an order of dispatch: each ray walks as it would alone.
    let work = |structure: &str, issue: &str| -> Vec<String> {
        let r = rows
            .iter()
            .find(|r| &r[col("mesh")] == "cow" && &r[col("structure")] == structure && &r[col("issue")] == issue)
            .unwrap_or_else(|| panic!("no cow {structure} {issue} row"));
        ["queries", "nodes_visited", "primitive_tests"]
            .iter()
            .map(|c| r[col(c)].to_string())
            .collect()
    };
    for structure in ["kdtree", "vlf", "bvh", "cwbvh"] {
        assert_eq!(work(structure, "single"), work(structure, "bundled"), "{structure}");
    }
    let report = std::fs::read_to_string(gpu.join("report.md")).unwrap();
    assert!(report.contains("s on the GPU backend on "), "{report}");
    assert!(
        report.contains("Bundled, on the GPU: the AO rays issued direction-major"),
        "{report}"
    );
    assert!(!report.contains("packets of 8"), "{report}");
    for row in [
        "| `vlf` single / bundled |",
        "| `bvh` single / bundled |",
        "| `cwbvh` bundled / `vlf` bundled |",
    ] {
        assert!(report.contains(row), "{row}: {report}");
    }
    // Against the f64 CPU's images: a ray f32 decides the other way moves a pixel by one ray's
    // weight (1/33); a few percent of the pixels, none by more than two rays.
    let images = common::images_against_cpu(&gpu, &cpu, 1e-6);
    assert_eq!(images.len(), 2 * 6, "an image per mesh and structure");
    for (file, off, pixels, worst) in images {
        assert!(
            off * 20 <= pixels && worst <= 2.5 / 33.0,
            "{file}: {off} of {pixels}, worst {worst}"
        );
    }
}

/// Embree in the ao kind (CPU only): its rows leave the work counters empty (it exposes none)
/// and count the pixels its f32 answers change against the first exact structure's image; the
/// report sets every structure's per-thread throughput against Embree's from the same rounds;
/// asked for on the GPU, the run is refused before any work at its place in `structures`.
#[test]
fn embree_runs_beside_the_exact_structures_and_is_refused_on_the_gpu() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(common::repo("experiments/ao-ci.toml"))
        .unwrap()
        .replace("../assets/", &format!("{}/", common::repo("assets").display()))
        .replace("\"cwbvh\", \"brute\"]", "\"cwbvh\", \"brute\", \"embree\"]")
        .replace("issue = [\"single\", \"bundled\"]", "issue = [\"single\"]");
    let exp = dir.path().join("ao-embree.toml");
    std::fs::write(&exp, &text).unwrap();
    let out = dir.path().join("out");
    common::run_experiment(&exp, &out, &["--backend", "cpu"]);
    let (header, rows) = common::table(&out.join("ao.csv"));
    let col = |name: &str| common::column(&header, name);
    let embree: Vec<_> = rows.iter().filter(|r| &r[col("structure")] == "embree").collect();
    assert_eq!(embree.len(), 2, "one row per mesh");
    for r in &embree {
        assert_eq!(
            (&r[col("nodes_visited")], &r[col("primitive_tests")]),
            ("", ""),
            "{r:?}"
        );
        let (same, differing) = (
            &r[col("same_image_as_first")],
            r[col("differing_pixels")].parse::<usize>().unwrap(),
        );
        assert_eq!(same == "true", differing == 0, "{r:?}");
        assert!(differing * 100 <= 24 * 24, "{r:?}");
        assert!(r[col("rays_per_s")].parse::<f64>().unwrap() > 0.0);
    }
    for r in rows.iter().filter(|r| &r[col("structure")] != "embree") {
        assert_eq!(
            (&r[col("same_image_as_first")], &r[col("differing_pixels")]),
            ("true", "0"),
            "{r:?}"
        );
        assert!(r[col("primitive_tests")].parse::<u64>().unwrap() > 0, "{r:?}");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("every exact structure's AO image equals"), "{report}");
    assert!(
        report.contains("**Inexact structures**") && report.contains("embree on cow:"),
        "{report}"
    );
    assert!(
        report.contains("## Per thread") && report.contains("| speed vs embree |"),
        "{report}"
    );
    assert!(
        report.contains("| cow | vlf | ") && report.contains("| cow | embree | "),
        "{report}"
    );
    // The GPU backend cannot run it: refused at its place in `structures`, nothing written.
    let refused = dir.path().join("gpu");
    let (code, err) = common::sweep(&[
        exp.as_os_str(),
        "--out".as_ref(),
        refused.as_os_str(),
        "--backend".as_ref(),
        "gpu".as_ref(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("ao-embree.toml:") && err.contains("structures[6]") && err.contains("no GPU form"),
        "{err}"
    );
    assert!(!refused.exists());
}
