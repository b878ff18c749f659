//! Outputs of a frame-time experiment: frames.csv, builds.csv, plots (frame time along the
//! path; with several scene sizes, frame time, memory and build time against triangle count on
//! log-log axes; with motion, update time along the path), a strip of frames, and report.md
//! around the verdict ([`super::verdict`]).

use super::runner::{BuildRow, FrameRow, FramesOutcome};
use super::spec::{FramesSpec, Generator};
use super::verdict::{label, labels, median_at, verdict};
use crate::files::write_atomic;
use crate::metrics::stats::{median, quartiles};
use crate::output::images::tonemap;
use crate::output::plots::{image_grid, line_plot, Axes, Series};
use crate::output::table::{float, write_rows};
use crate::scene::procedural::random;
use serde::Serialize;
use std::path::Path;

#[derive(Serialize)]
struct FrameCsv<'a> {
    triangles: usize,
    structure: &'a str,
    update: &'a str,
    shading: &'a str,
    viewpoint: &'a str,
    frame: u32,
    #[serde(with = "float")]
    frame_s: f64,
    #[serde(with = "float")]
    update_s: f64,
    rays: u64,
    differing_pixels: usize,
}

#[derive(Serialize)]
struct BuildCsv<'a> {
    triangles: usize,
    structure: &'a str,
    parameters: &'a str,
    #[serde(with = "float")]
    build_s: f64,
    memory_mb: String,
}

/// Writes frames.csv, builds.csv, plots/, images/ and report.md under `out`.
pub fn write_frames(
    spec: &FramesSpec,
    outcome: &FramesOutcome,
    threads: usize,
    seconds: f64,
    out: &Path,
) -> anyhow::Result<()> {
    let rows = &outcome.frames;
    write_rows(
        &out.join("frames.csv"),
        rows.iter().map(|r| FrameCsv {
            triangles: r.triangles,
            structure: r.structure,
            update: r.update,
            shading: r.shading.name(),
            viewpoint: &r.viewpoint,
            frame: r.frame,
            frame_s: r.seconds,
            update_s: r.update_seconds.unwrap_or(f64::NAN),
            rays: r.rays,
            differing_pixels: r.differing_pixels,
        }),
    )?;
    write_rows(
        &out.join("builds.csv"),
        outcome.builds.iter().map(|b: &BuildRow| BuildCsv {
            triangles: b.triangles,
            structure: b.structure,
            parameters: &b.parameters,
            build_s: b.build_seconds,
            memory_mb: format!("{:.3}", b.memory_bytes as f64 / 1e6),
        }),
    )?;
    let all = labels(rows);
    let largest = outcome.builds.iter().map(|b| b.triangles).max().unwrap_or(0);
    for &(shading, _) in &spec.shadings {
        let series = |value: &dyn Fn(&FrameRow) -> f64| -> Vec<(usize, Series)> {
            all.iter()
                .enumerate()
                .map(|(i, l)| {
                    let points = rows
                        .iter()
                        .filter(|r| r.shading == shading && r.triangles == largest && label(r) == *l)
                        .filter(|r| r.viewpoint == spec.viewpoints[0])
                        .map(|r| (r.frame as f64, value(r), f64::NAN))
                        .collect();
                    (
                        i,
                        Series {
                            name: l.clone(),
                            points,
                            dashed: false,
                        },
                    )
                })
                .collect()
        };
        let title = format!(
            "{} shading, {}x{}, {}K triangles, viewpoint {}, CPU f64",
            shading.name(),
            spec.width,
            spec.height,
            largest as f64 / 1e3,
            spec.viewpoints[0]
        );
        line_plot(
            &out.join(format!("plots/frame_time_{}.png", shading.name())),
            &Axes::new(&title, "frame", "render seconds", false, false),
            &series(&|r| r.seconds),
            &[],
        )?;
        if spec.motion.is_some() {
            line_plot(
                &out.join(format!("plots/update_time_{}.png", shading.name())),
                &Axes::new(&title, "frame", "update seconds", false, true),
                &series(&|r| r.update_seconds.unwrap_or(f64::NAN)),
                &[],
            )?;
        }
        let sizes: Vec<usize> = outcome.builds.iter().map(|b| b.triangles).collect();
        if sizes.iter().any(|&t| t != largest) {
            let series: Vec<(usize, Series)> = all
                .iter()
                .enumerate()
                .map(|(i, l)| {
                    let mut points: Vec<(f64, f64, f64)> = sizes
                        .iter()
                        .filter_map(|&t| Some((t as f64, median_at(rows, shading, l, t)?, f64::NAN)))
                        .collect();
                    points.dedup_by(|a, b| a.0 == b.0);
                    (
                        i,
                        Series {
                            name: l.clone(),
                            points,
                            dashed: false,
                        },
                    )
                })
                .collect();
            line_plot(
                &out.join(format!("plots/scaling_{}.png", shading.name())),
                &Axes::new(
                    &format!(
                        "{} shading, {}x{}, median over the path",
                        shading.name(),
                        spec.width,
                        spec.height
                    ),
                    "triangles",
                    "frame seconds",
                    true,
                    true,
                ),
                &series,
                &[],
            )?;
        }
    }
    if outcome.builds.iter().any(|b| b.triangles != largest) {
        for (file, what, value) in [
            (
                "memory",
                "MB beyond the triangles",
                &(|b: &BuildRow| b.memory_bytes as f64 / 1e6) as &dyn Fn(&BuildRow) -> f64,
            ),
            ("build_time", "build seconds", &|b: &BuildRow| b.build_seconds),
        ] {
            let series: Vec<(usize, Series)> = spec
                .structures
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    (
                        i,
                        Series {
                            name: s.name.to_string(),
                            points: outcome
                                .builds
                                .iter()
                                .filter(|b| b.structure == s.name)
                                .map(|b| (b.triangles as f64, value(b), f64::NAN))
                                .collect(),
                            dashed: false,
                        },
                    )
                })
                .collect();
            line_plot(
                &out.join(format!("plots/{file}.png")),
                &Axes::new(what, "triangles", what, true, true),
                &series,
                &[],
            )?;
        }
    }
    for &(shading, _) in &spec.shadings {
        let pictures: Vec<_> = outcome
            .pictures
            .iter()
            .filter(|p| p.shading == shading)
            .map(|p| {
                (
                    format!("frame {}", p.frame),
                    tonemap(&p.radiance, spec.width, spec.height),
                )
            })
            .collect();
        let tiles: Vec<(String, &_)> = pictures.iter().map(|(c, img)| (c.clone(), img)).collect();
        image_grid(
            &out.join(format!("images/strip_{}.png", shading.name())),
            &tiles,
            tiles.len().max(1),
        )?;
    }
    write_atomic(
        &out.join("report.md"),
        report(spec, outcome, threads, seconds).as_bytes(),
    )?;
    crate::output::write_cpu_manifest(out, &spec.path, seconds, threads)
}

fn report(spec: &FramesSpec, outcome: &FramesOutcome, threads: usize, seconds: f64) -> String {
    let rows = &outcome.frames;
    let mut md = format!("# {}: frame times per acceleration structure\n\n", spec.name);
    md += &format!(
        "Experiment `{}`, {:.0} s on the f64 CPU backend ({threads} threads). Scenes: {}. {} frames per viewpoint ({}) at {}x{}, shadings {}; every frame is rendered by every structure in a fresh seeded order, {} timed render(s) each (median kept), and compared pixel for pixel with the first structure's.{}\n\n",
        spec.path.display(),
        seconds,
        outcome.scenes.join("; "),
        spec.frames,
        spec.viewpoints.join(", "),
        spec.width,
        spec.height,
        spec.shadings.iter().map(|s| s.0.name()).collect::<Vec<_>>().join(", "),
        spec.repeats,
        spec.motion.as_ref().map_or(String::new(), |m| format!(
            " Before each frame the part `{}` moves by {:?} m and each structure is brought up to date (the field by its own update, the BVH by a refit and by rebuilds with its own preset and with obvhs' fastest, the kd-tree by a rebuild), the update timed.",
            m.part,
            m.step.to_array()
        ))
    );
    md += &match spec.generator {
        Generator::RandomTriangles { .. } => format!("Random triangles: {}.\n\n", random::DISTRIBUTION),
        Generator::Classroom => "The classroom (src/scene/procedural/classroom.rs): a 10 x 8 x 3.2 m room with tessellated walls, floor and ceiling, four windows, a blackboard, 20 desks with chairs, a teacher's desk, two bookshelves of books, four ceiling lamps over four point lights, two wall mirrors (weight 0.85) and a chrome ball (0.7); the camera walks one loop round the desks.\n\n".to_string(),
    };
    md += "## Verdict\n\n";
    md += &verdict(spec, outcome);
    md += "\n## Medians\n\n| triangles | shading | structure | frame s (q1-q3) | update s | rays per frame | frames |\n|---|---|---|---|---|---|---|\n";
    let mut sizes: Vec<usize> = outcome.builds.iter().map(|b| b.triangles).collect();
    sizes.dedup();
    for &t in &sizes {
        for &(shading, _) in &spec.shadings {
            for l in labels(rows) {
                let sel: Vec<&FrameRow> = rows
                    .iter()
                    .filter(|r| r.triangles == t && r.shading == shading && label(r) == l)
                    .collect();
                if sel.is_empty() {
                    continue;
                }
                let secs: Vec<f64> = sel.iter().map(|r| r.seconds).collect();
                let (q1, m, q3) = quartiles(&secs);
                let upd: Vec<f64> = sel.iter().filter_map(|r| r.update_seconds).collect();
                md += &format!(
                    "| {t} | {} | {l} | {m:.4} ({q1:.4}-{q3:.4}) | {} | {:.0} | {} |\n",
                    shading.name(),
                    if upd.is_empty() {
                        "-".into()
                    } else {
                        format!("{:.4}", median(&upd))
                    },
                    median(&sel.iter().map(|r| r.rays as f64).collect::<Vec<_>>()),
                    sel.len()
                );
            }
        }
    }
    md += "\n## Builds\n\n| triangles | structure | parameters | build s | MB |\n|---|---|---|---|---|\n";
    for b in &outcome.builds {
        md += &format!(
            "| {} | {} | {} | {:.3} | {:.1} |\n",
            b.triangles,
            b.structure,
            b.parameters,
            b.build_seconds,
            b.memory_bytes as f64 / 1e6
        );
    }
    md += "\nOutputs: `frames.csv` (one row per frame and structure), `builds.csv`, `plots/frame_time_SHADING.png` (render time along the path, largest scene, first viewpoint)";
    if spec.motion.is_some() {
        md += ", `plots/update_time_SHADING.png` (update time along the path)";
    }
    if sizes.len() > 1 {
        md += ", `plots/scaling_SHADING.png`, `plots/memory.png`, `plots/build_time.png` (log-log against triangle count)";
    }
    md += ", `images/strip_SHADING.png` (frames along the path, first structure).\n";
    md
}
