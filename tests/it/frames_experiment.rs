//! The frame-time experiment kind (`kind = "frames"`) through the binary: the CI walkthrough
//! (experiments/frames-ci.toml) and small scaling and dynamic variants of it write their tables,
//! plots, strips and reports, and every structure, including brute force, renders every frame
//! identically: the committed threshold is zero differing pixels, static or moving. Bad input is
//! a located error with exit status 2 that writes nothing.

use crate::common;

use std::path::Path;

/// Runs `text` as an experiment; returns frames.csv as (header, rows) and the report.
fn run(dir: &Path, text: &str) -> (csv::StringRecord, Vec<csv::StringRecord>, String) {
    let exp = common::write_experiment(dir, text);
    let out = dir.join("out");
    common::run_experiment(&exp, &out, &[]);
    let (header, rows) = common::table(&out.join("frames.csv"));
    (header, rows, std::fs::read_to_string(out.join("report.md")).unwrap())
}

fn ci() -> String {
    std::fs::read_to_string(common::repo("experiments/frames-ci.toml")).unwrap()
}

/// The CI walkthrough as a scaling experiment: random triangles at two sizes, seen from outside
/// and inside, OpenGL-like shading.
fn scaling() -> String {
    ci().replace(
        "generator = \"classroom\"",
        "generator = \"random-triangles\"\ntriangles = [300, 2400]\nseed = 5",
    )
    .replace("frames = 3", "frames = 2\nviewpoints = [\"outside\", \"inside\"]")
    .replace("shadings = [\"opengl\", \"whitted\"]", "shadings = [\"opengl\"]")
}

/// The CI walkthrough with a moving part: every camera of the walk looks at the teacher's desk
/// while the chrome ball rolls on it.
fn moving() -> String {
    ci().replace(
        "[path]\nframes = 3",
        "[path]\nframes = 3\nlook_at = [-3.5, 0.0, 0.9]\n\n[motion]\npart = \"chrome-ball\"\nstep = [0.0, -0.05, 0.0]",
    )
}

/// Random cameras and per-scene tuning: each tuned structure keeps exactly one candidate, the
/// one built (builds.csv), chosen on tuning cameras apart from the frames; frames drawn with one
/// seed are the same frames on a second run, and another seed draws others; the verdict's
/// intervals are order statistics over independent frames.
#[test]
fn random_cameras_and_tuning_keep_one_candidate_and_draw_seeded_independent_frames() {
    let tuned = |seed: u32| {
        ci().replace(
            "[path]\nframes = 3",
            &format!("[path]\nframes = 6\ncameras = \"random\"\nseed = {seed}"),
        )
        .replace("shadings = [\"opengl\", \"whitted\"]", "shadings = [\"opengl\"]")
        .replace("tiles = 32\ndepth = 3", "tiles = 32\ndepth = [2, 3]")
            + "\n[accel.kdtree]\nmax_depth = [8, 20]\n\n[tuning]\ncameras = 2\nrepeats = 6\n"
    };
    let dir = tempfile::tempdir().unwrap();
    let (header, rows, report) = run(dir.path(), &tuned(7));
    let out = dir.path().join("out");
    let mut tuning = csv::Reader::from_path(out.join("tuning.csv")).unwrap();
    let th = tuning.headers().unwrap().clone();
    let trows: Vec<csv::StringRecord> = tuning.records().map(Result::unwrap).collect();
    let tc = |n: &str| common::column(&th, n);
    assert_eq!(trows.len(), 4, "two candidates each for kdtree and vlf: {trows:?}");
    let builds = std::fs::read_to_string(out.join("builds.csv")).unwrap();
    let kept_line = report
        .lines()
        .find_map(|l| l.split_once("Kept: ").map(|(_, k)| k.to_string()))
        .unwrap_or_else(|| panic!("no Kept line: {report}"));
    for structure in ["kdtree", "vlf"] {
        let chosen: Vec<&csv::StringRecord> = trows
            .iter()
            .filter(|r| &r[tc("structure")] == structure && &r[tc("chosen")] == "true")
            .collect();
        assert_eq!(chosen.len(), 1, "{structure}: {trows:?}");
        let depth = match structure {
            "kdtree" => format!(",{},median,", &chosen[0][tc("kdtree_max_depth")]),
            _ => format!("51224,vlf,,{},", &chosen[0][tc("vlf_depth")]),
        };
        assert!(
            builds.contains(&depth),
            "{structure}: the kept candidate is the one built ({depth}): {builds}"
        );
        // The report names the kept candidate, not merely the structure: its depth and no other.
        let (key, other) = match structure {
            "kdtree" => ("kdtree_max_depth", ["8", "20"]),
            _ => ("vlf_depth", ["2", "3"]),
        };
        let kept = &chosen[0][tc(key)];
        let name = key.trim_start_matches(structure).trim_start_matches('_');
        let said = kept_line
            .split("; ")
            .find(|k| k.contains(&format!("`{structure}` ")))
            .unwrap_or_else(|| panic!("{structure} not kept: {kept_line}"));
        let words: Vec<&str> = said.split(' ').collect();
        assert!(
            words.contains(&format!("{name}={kept}").as_str()),
            "{said} (kept {kept})"
        );
        for o in other.iter().filter(|o| **o != kept) {
            assert!(!words.contains(&format!("{name}={o}").as_str()), "{said}");
        }
    }
    assert!(
        kept_line.starts_with("scene=classroom shading=opengl viewpoint=walk frames=0..6: "),
        "{kept_line}"
    );
    assert!(report.contains("95 % interval over independent frames"), "{report}");
    let col = |name: &str| common::column(&header, name);
    let rays = |rows: &[csv::StringRecord]| -> Vec<String> {
        rows.iter()
            .filter(|r| &r[col("structure")] == "brute")
            .map(|r| r[col("rays")].to_string())
            .collect()
    };
    let again = tempfile::tempdir().unwrap();
    let (_, same, _) = run(again.path(), &tuned(7));
    let image = |d: &std::path::Path| std::fs::read(d.join("out/images/strip_opengl.png")).unwrap();
    assert_eq!(image(dir.path()), image(again.path()), "one seed, the same frames");
    assert_eq!(rays(&rows), rays(&same));
    let other = tempfile::tempdir().unwrap();
    run(other.path(), &tuned(8));
    assert_ne!(
        image(dir.path()),
        image(other.path()),
        "another seed draws other cameras"
    );
}

#[test]
fn the_ci_walkthrough_renders_every_frame_identically_with_every_structure() {
    let dir = tempfile::tempdir().unwrap();
    let (header, rows, report) = run(dir.path(), &ci());
    let col = |name: &str| common::column(&header, name);
    assert_eq!(rows.len(), 2 * 3 * 5, "2 shadings x 3 frames x 5 structures");
    let tables = common::assert_tidy_tables(&dir.path().join("out"));
    assert_eq!(
        tables.len(),
        4,
        "frames.csv, rounds.csv, builds.csv and summary.csv: {tables:?}"
    );
    let builds = std::fs::read_to_string(dir.path().join("out/builds.csv")).unwrap();
    assert!(
        builds.starts_with("triangles,structure,bvh_preset,") && builds.contains("\n51224,vlf,,3,32,4,uniform,32,,,"),
        "the field's parameters one per column: {builds}"
    );
    for r in &rows {
        let same_frame: Vec<&csv::StringRecord> = rows
            .iter()
            .filter(|o| o[col("shading")] == r[col("shading")] && o[col("frame")] == r[col("frame")])
            .collect();
        assert!(
            same_frame.iter().all(|o| o[col("rays")] == r[col("rays")]),
            "every structure traces the same rays"
        );
        // Whitted's bound: camera rays, a shadow ray per light at the hit, and per bounce (3) a
        // reflected ray and a shadow ray per light (4).
        assert!(
            r[col("rays")].parse::<u64>().unwrap() <= 32 * 32 * (1 + 4 + 3 * 5),
            "{r:?}"
        );
    }
    for r in &rows {
        assert_eq!(&r[col("differing_pixels")], "0", "{r:?}");
        let rays: u64 = r[col("rays")].parse().unwrap();
        match &r[col("shading")] {
            "opengl" => assert_eq!(rays, 32 * 32, "OpenGL-like shading traces camera rays only"),
            _ => assert!(
                rays > 4 * 32 * 32,
                "Whitted: shadow rays to 4 lights and reflections; {rays}"
            ),
        }
        let (lo, med, hi) = (
            r[col("frame_s_lo")].parse::<f64>().unwrap(),
            r[col("frame_s")].parse::<f64>().unwrap(),
            r[col("frame_s_hi")].parse::<f64>().unwrap(),
        );
        assert!(0.0 < lo && lo <= med && med <= hi, "{r:?}");
        assert_eq!(&r[col("timed_renders")], "3");
    }
    let out = dir.path().join("out");
    for file in [
        "builds.csv",
        "summary.csv",
        "manifest.toml",
        "plots/frame_time_opengl.png",
        "plots/frame_time_opengl.svg",
        "plots/frame_time_whitted.png",
        "plots/frame_time_whitted.svg",
        "images/strip_opengl.png",
        "images/strip_whitted.png",
        "images/strip_whitted_0.exr",
        "index.html",
    ] {
        assert!(out.join(file).exists(), "{file} missing");
    }
    common::browser::check_page(&out);
    // The two strips are set against each other: opengl frame N against whitted frame N.
    let data = common::browser::page_data(&out).unwrap();
    let galleries = data["galleries"].as_array().unwrap();
    assert_eq!(galleries.len(), 2);
    for (i, g) in galleries.iter().enumerate() {
        assert_eq!(g["against"].as_u64(), Some(1 - i as u64), "{}", g["title"]);
        assert_eq!(
            g["shots"].as_array().unwrap().len(),
            galleries[1 - i]["shots"].as_array().unwrap().len()
        );
    }
    assert!(
        report.contains("equals the first structure's pixel for pixel"),
        "{report}"
    );
    assert!(
        report.contains("Is `vlf` faster than `kdtree` (the paper's baseline), whitted shading?"),
        "{report}"
    );
    assert!(
        !out.join("plots/scaling_opengl.png").exists(),
        "one scene size: no scaling plot"
    );
    // The page rebuilt from the folder's files alone (the `page` binary) still draws each strip
    // as its PNGs show it (each strip at its own exposure).
    penumbra::output::page::rebuild(&out).unwrap();
    common::browser::check_page(&out);
}

#[test]
fn random_scenes_at_two_sizes_give_the_scaling_plots_and_slopes() {
    let dir = tempfile::tempdir().unwrap();
    let (header, rows, report) = run(dir.path(), &scaling());
    let col = |name: &str| common::column(&header, name);
    assert_eq!(rows.len(), 2 * 2 * 2 * 5, "sizes x viewpoints x frames x structures");
    assert!(rows.iter().all(|r| &r[col("differing_pixels")] == "0"));
    for file in [
        "plots/scaling_opengl.png",
        "plots/scaling_opengl.svg",
        "plots/memory.png",
        "plots/memory.svg",
        "plots/build_time.png",
        "plots/build_time.svg",
    ] {
        assert!(dir.path().join("out").join(file).exists(), "{file} missing");
    }
    assert!(report.contains("median frame time grows as kdtree N^"), "{report}");
    assert!(report.contains("Memory grows as"), "{report}");
    assert!(!report.contains("NaN"), "{report}");
}

#[test]
fn a_moving_part_leaves_every_update_method_rendering_what_a_rebuild_renders() {
    let dir = tempfile::tempdir().unwrap();
    let (header, rows, report) = run(dir.path(), &moving());
    let col = |name: &str| common::column(&header, name);
    let methods: Vec<String> = rows
        .iter()
        .map(|r| format!("{} {}", &r[col("structure")], &r[col("update")]))
        .collect();
    for m in [
        "kdtree rebuild",
        "vlf update",
        "bvh rebuild",
        "bvh rebuild-fastest",
        "bvh refit",
        "cwbvh rebuild",
        "brute rebuild",
    ] {
        assert!(methods.iter().any(|x| x == m), "{m} missing: {methods:?}");
    }
    assert_eq!(rows.len(), 2 * 3 * 7);
    for r in &rows {
        assert_eq!(&r[col("differing_pixels")], "0", "{r:?}");
        assert!(r[col("update_s")].parse::<f64>().unwrap() > 0.0, "{r:?}");
        let said = match &r[col("update")] {
            "update" => "in-place",
            "refit" => "refit",
            _ => "rebuild",
        };
        assert_eq!(&r[col("update_kind")], said, "what the structure says it did: {r:?}");
    }
    assert!(
        report.contains("Is `vlf (update)` cheaper than `bvh (refit)`?"),
        "{report}"
    );
    assert!(dir.path().join("out/plots/update_time_whitted.png").exists());
}

#[test]
fn bad_input_is_located_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let text = ci();
    let random = text.replace(
        "generator = \"classroom\"",
        "generator = \"random-triangles\"\ntriangles = [300, 2400]",
    );
    for (edit, key) in [
        (
            text.replace("generator = \"classroom\"", "generator = \"office\""),
            "scene.generator",
        ),
        (
            text.replace("\"cwbvh\", \"brute\"", "\"cwbvh\", \"octree\""),
            "structures[4]",
        ),
        (
            text.replace("\"opengl\", \"whitted\"", "\"opengl\", \"opengl\""),
            "shadings[1]",
        ),
        (text.replace("mirror_depth = 3", "mirror_depth = 0"), "mirror_depth"),
        (text.replace("frames = 3", "frames = 0"), "path.frames"),
        (text.replace("depth = 3", "depth = 9"), "accel.vlf.depth"),
        (
            text.replace(
                "frames = 3",
                "frames = 3\n\n[motion]\npart = \"piano\"\nstep = [0.0, 0.0, 0.1]",
            ),
            "motion.part",
        ),
        (
            text.replace(
                "generator = \"classroom\"",
                "generator = \"classroom\"\ntriangles = [10]",
            ),
            "scene.triangles",
        ),
        (random.replace("[300, 2400]", "[2400, 300]"), "scene.triangles[1]"),
        (random.clone(), "path.viewpoints"),
        (
            text.replace("frames = 3", "frames = 3\nlook_at = [-4.2, 0.0, 1.6]"),
            "path.look_at",
        ),
        (
            text.replace(
                "frames = 3",
                "frames = 3\n\n[motion]\npart = \"chrome-ball\"\nstep = [0.0, 0.0, 3.0]",
            ),
            "motion.step",
        ),
        (text.replace("strip = 3", "strip = 0"), "strip"),
        (
            random.replace("frames = 3", "frames = 3\nviewpoints = [\"above\"]"),
            "path.viewpoints[0]",
        ),
    ] {
        common::rejected_at(dir.path(), &edit, key);
    }
}

/// The verdict is computed from the rows: a structure whose frames differ fails exactness by
/// name, and "is `vlf` faster" reads yes, no or undecided from the interval of the median of
/// per-frame ratios.
#[test]
fn the_verdict_names_differing_structures_and_answers_from_the_ratios() {
    use penumbra::experiment::frames::runner::{FrameRow, FramesOutcome};
    use penumbra::experiment::frames::spec::ShadingName;
    use penumbra::experiment::frames::verdict::verdict;
    let mut spec = penumbra::experiment::frames::FramesSpec::load(&common::repo("experiments/frames-ci.toml")).unwrap();
    spec.shadings.truncate(1);
    let row = |structure: &'static str, frame: u32, seconds: f64, differing_pixels: usize| FrameRow {
        triangles: 100,
        structure,
        update: "none",
        shading: ShadingName::Opengl,
        viewpoint: "walk".into(),
        frame,
        seconds,
        renders: vec![seconds; 3],
        update_seconds: None,
        updated: None,
        rays: Default::default(),
        work: Default::default(),
        differing_pixels,
    };
    // kd-tree about 2x slower than the field on every one of 36 frames (jittered, no trend);
    // the BVH faster on half the frames, slower on the other half.
    let jitter = |f: u32| 0.01 * ((f * 7) % 5) as f64;
    let mut frames = Vec::new();
    for f in 0..36 {
        frames.push(row("kdtree", f, 2.0 + jitter(f), 0));
        frames.push(row("vlf", f, 1.0, if f == 2 { 7 } else { 0 }));
        frames.push(row("bvh", f, if f % 2 == 0 { 1.5 } else { 0.5 }, 0));
    }
    let outcome = FramesOutcome {
        frames,
        ..Default::default()
    };
    let v = verdict(&spec, &outcome);
    assert!(
        v.contains("Exactness FAILED") && v.contains("vlf: 7 pixels on 1 frames (at most 7)"),
        "{v}"
    );
    assert!(
        v.contains("Is `vlf` faster than `kdtree` (the paper's baseline), opengl shading?** **yes**"),
        "{v}"
    );
    assert!(v.contains("faster on 36 of 36 frames"), "{v}");
    assert!(
        v.contains("Is `vlf` faster than `bvh`, opengl shading?** **undecided**"),
        "{v}"
    );
    assert!(v.contains("faster on 18 of 36 frames"), "{v}");
    // Three frames, all 2x faster, give no interval: undecided.
    let few = FramesOutcome {
        frames: (0..3)
            .flat_map(|f| [row("kdtree", f, 2.0, 0), row("vlf", f, 1.0, 0)])
            .collect(),
        ..Default::default()
    };
    let v = verdict(&spec, &few);
    assert!(
        v.contains("(the paper's baseline), opengl shading?** **undecided**"),
        "{v}"
    );
    frames_all_slower(&spec);
}

/// Every frame slower reads "no".
fn frames_all_slower(spec: &penumbra::experiment::frames::FramesSpec) {
    use penumbra::experiment::frames::runner::{FrameRow, FramesOutcome};
    use penumbra::experiment::frames::spec::ShadingName;
    use penumbra::experiment::frames::verdict::verdict;
    let frames = (0..36)
        .flat_map(|f| {
            [("kdtree", 0.5), ("vlf", 1.0 + 0.01 * ((f * 7) % 5) as f64)].map(|(structure, seconds)| FrameRow {
                triangles: 100,
                structure,
                update: "none",
                shading: ShadingName::Opengl,
                viewpoint: "walk".into(),
                frame: f,
                seconds,
                renders: vec![seconds; 3],
                update_seconds: None,
                updated: None,
                rays: Default::default(),
                work: Default::default(),
                differing_pixels: 0,
            })
        })
        .collect();
    let v = verdict(
        spec,
        &FramesOutcome {
            frames,
            ..Default::default()
        },
    );
    assert!(
        v.contains("opengl shading?** **no**") && v.contains("- **Exactness**: every structure"),
        "{v}"
    );
}

/// The scaling and walkthrough files load, draw their cameras at random and tune
/// both kd-trees, and their cameras can all look where they are told (checked on load).
#[test]
fn the_random_camera_designs_load_and_tune_both_kd_trees() {
    use penumbra::experiment::frames::spec::Cameras;
    for name in ["scaling", "walkthrough"] {
        let spec = penumbra::experiment::frames::FramesSpec::load(&common::repo(&format!("experiments/{name}.toml")))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(spec.cameras, Cameras::Random { seed: 1 }, "{name}");
        for (structure, candidates) in spec.structures.iter().zip(&spec.candidates) {
            let tuned = candidates.len() > 1;
            assert_eq!(
                tuned,
                structure.name.starts_with("kdtree"),
                "{name}: {}",
                structure.name
            );
        }
    }
}

/// Experiment `text` (a frames kind) on the GPU (`--backend gpu`, lavapipe in CI) and on the f64
/// CPU: on the GPU every structure renders every frame as the first structure does, every row
/// counts the GPU's work, the report and manifest name the adapter; and every strip frame is
/// within 1e-3 W m^-2 sr^-1 (about 1e-4 of the brightest pixel's radiance) of the CPU's but on
/// at most 1 % of its pixels, where f32 decides a ray grazing an edge the other way. Returns the
/// GPU's frames.csv; none where there is no GPU.
fn on_the_gpu_as_on_the_cpu(text: &str) -> Option<(csv::StringRecord, Vec<csv::StringRecord>)> {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::write_experiment(dir.path(), text);
    let (gpu, cpu) = common::on_gpu_and_cpu(dir.path(), &exp)?;
    let (header, rows) = common::table(&gpu.join("frames.csv"));
    let (cpu_header, cpu_rows) = common::table(&cpu.join("frames.csv"));
    assert_eq!(header, cpu_header);
    assert_eq!(rows.len(), cpu_rows.len());
    let col = |name: &str| common::column(&header, name);
    let count = |r: &csv::StringRecord, name: &str| -> u64 { r[col(name)].parse().unwrap() };
    for (r, c) in rows.iter().zip(&cpu_rows) {
        for id in ["triangles", "structure", "update", "shading", "viewpoint", "frame"] {
            assert_eq!(r[col(id)], c[col(id)], "the same row order: {r:?} {c:?}");
        }
        assert_eq!(&r[col("differing_pixels")], "0", "{r:?}");
        assert!(count(r, "primitive_tests") > 0, "GPU work counted: {r:?}");
        assert!(
            count(r, "nodes_visited") > 0 || &r[col("structure")] == "brute",
            "{r:?}"
        );
        assert_eq!(count(r, "queries"), count(r, "rays"), "a query per ray: {r:?}");
        // The same rays as the CPU's but where f32 sends a grazing ray to another surface.
        assert_eq!(count(r, "primary_rays"), count(c, "primary_rays"), "{r:?}");
        for kind in ["rays", "shadow_rays", "reflection_rays"] {
            let (g, f) = (count(r, kind), count(c, kind));
            assert!(g.abs_diff(f) * 100 <= f + 100, "{kind}: GPU {g}, CPU {f}: {r:?}");
        }
    }
    let report = std::fs::read_to_string(gpu.join("report.md")).unwrap();
    assert!(report.contains("s on the GPU backend on "), "{report}");
    let manifest = std::fs::read_to_string(gpu.join("manifest.toml")).unwrap();
    assert!(manifest.contains("backend = \"gpu\""), "{manifest}");
    for (file, off, pixels, worst) in common::images_against_cpu(&gpu, &cpu, 1e-3) {
        assert!(off * 100 <= pixels, "{file}: {off} of {pixels}, worst {worst}");
    }
    Some((header, rows))
}

/// experiments/frames-ci.toml on the GPU: the classroom's walk under both shadings, every
/// structure (brute force over its 51K triangles included: the mirror pass runs one reflected
/// ray's walk per dispatch, so no invocation outgrows an adapter's loop cap), Whitted's frames
/// tracing shadow rays to the four lights and the mirrors' reflections.
#[test]
fn the_ci_walkthrough_runs_on_the_gpu() {
    let Some((header, rows)) = on_the_gpu_as_on_the_cpu(&ci()) else {
        return;
    };
    let col = |name: &str| common::column(&header, name);
    assert_eq!(rows.len(), 2 * 3 * 5, "2 shadings x 3 frames x 5 structures");
    let mut reflections = 0;
    for r in &rows {
        let rays: u64 = r[col("rays")].parse().unwrap();
        match &r[col("shading")] {
            "opengl" => assert_eq!(rays, 32 * 32, "OpenGL-like shading traces camera rays only"),
            _ => assert!(rays > 4 * 32 * 32, "Whitted: shadow rays to 4 lights; {rays}"),
        }
        reflections += r[col("reflection_rays")].parse::<u64>().unwrap();
    }
    assert!(reflections > 0, "the walk sees the mirrors");
}

/// The scaling variant (random triangles at two sizes, two viewpoints) on the GPU.
#[test]
fn random_scenes_at_two_sizes_run_on_the_gpu() {
    let Some((_, rows)) = on_the_gpu_as_on_the_cpu(&scaling()) else {
        return;
    };
    assert_eq!(rows.len(), 2 * 2 * 2 * 5, "sizes x viewpoints x frames x structures");
}

/// The dynamic variant (the chrome ball rolling on the desk in view, in the wall mirrors and in
/// itself) on the GPU: every update method renders what a rebuild renders.
#[test]
fn a_moving_part_runs_on_the_gpu() {
    let Some((header, rows)) = on_the_gpu_as_on_the_cpu(&moving()) else {
        return;
    };
    let col = |name: &str| common::column(&header, name);
    assert_eq!(rows.len(), 2 * 3 * 7, "2 shadings x 3 frames x 7 update methods");
    assert!(rows.iter().any(|r| &r[col("update")] == "refit"));
}

/// Embree listed first in the CI walkthrough: the exact structures are held to the first exact
/// one's frames (zero differing pixels), Embree's f32 answers are counted against them and kept
/// apart from the exactness line, and its rows leave the work counters empty.
#[test]
fn embree_is_measured_against_the_first_exact_structure() {
    let dir = tempfile::tempdir().unwrap();
    let text = ci().replace(
        "structures = [\"kdtree\", \"vlf\", \"bvh\", \"cwbvh\", \"brute\"]",
        "structures = [\"embree\", \"kdtree\", \"vlf\", \"bvh\"]",
    );
    let (header, rows, report) = run(dir.path(), &text);
    let col = |name: &str| common::column(&header, name);
    let pixels = 32 * 32;
    let mut embree = 0;
    for r in &rows {
        let differing: usize = r[col("differing_pixels")].parse().unwrap();
        if &r[col("structure")] == "embree" {
            embree += 1;
            assert_eq!(
                (&r[col("nodes_visited")], &r[col("primitive_tests")]),
                ("", ""),
                "{r:?}"
            );
            assert!(differing * 100 <= pixels, "{r:?}");
        } else {
            assert_eq!(differing, 0, "{r:?}");
            assert!(r[col("primitive_tests")].parse::<u64>().unwrap() > 0, "{r:?}");
        }
    }
    assert_eq!(embree, 2 * 3, "both shadings, 3 frames");
    assert!(
        report.contains("every exact structure's frame equals the first exact structure's"),
        "{report}"
    );
    assert!(!report.contains("Exactness FAILED"), "{report}");
    assert!(report.contains("no work counters"), "{report}");
}
