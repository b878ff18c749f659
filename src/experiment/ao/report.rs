//! Outputs of an ambient-occlusion experiment: ao.csv, the AO images, a plot of frame time
//! against triangle count, and report.md with the paper's Table 1 beside ours and a verdict
//! computed from the rows.

use super::runner::{AoRow, TuningRow};
use super::spec::AoSpec;
use crate::files::write_atomic;
use crate::metrics::stats::median;
use crate::output::images::{grey, write_png};
use crate::output::plots::{line_plot, Axes, Series};
use crate::output::table::{float, write_rows};
use serde::Serialize;
use std::path::Path;

/// A row of ao.csv.
#[derive(Serialize)]
struct CsvRow<'a> {
    mesh: &'a str,
    triangles: usize,
    structure: &'a str,
    parameters: &'a str,
    #[serde(with = "float")]
    build_s: f64,
    memory_mb: String,
    frames: usize,
    #[serde(with = "float")]
    frame_s_median: f64,
    primary_rays: u64,
    ao_rays: u64,
    #[serde(with = "float")]
    mrays_per_s: f64,
    receivers: usize,
    #[serde(with = "float")]
    mean_ao: f64,
    same_image_as_first: bool,
}

/// The row of `structure` on `mesh`.
fn find<'a>(rows: &'a [AoRow], mesh: &str, structure: &str) -> Option<&'a AoRow> {
    rows.iter().find(|r| r.mesh == mesh && r.structure == structure)
}

/// The verdict on the paper's claims, from the rows: VLF-RT against the CRT-like kd-tree and
/// against the BVH, with the memory and build time it costs.
pub fn verdict(spec: &AoSpec, rows: &[AoRow]) -> String {
    let mut out = String::new();
    // (mesh, speed-up of `a` over `b`, whether their frame times' interquartile ranges are
    // disjoint: a difference beyond the noise of the rounds)
    let ratio = |a: &str, b: &str| -> Vec<(String, f64, bool)> {
        spec.meshes
            .iter()
            .filter_map(|m| {
                let (x, y) = (find(rows, &m.name, a)?, find(rows, &m.name, b)?);
                let ((x1, x3), (y1, y3)) = (x.quartile_seconds(), y.quartile_seconds());
                Some((
                    m.name.clone(),
                    y.median_seconds() / x.median_seconds(),
                    x3 < y1 || y3 < x1,
                ))
            })
            .collect()
    };
    let identical = rows.iter().all(|r| r.same_image);
    out += &format!(
        "- **Exactness**: every structure's AO image {} the first structure's, bit for bit, on every mesh.\n",
        if identical { "equals" } else { "does NOT equal" }
    );
    for (baseline, label, paper) in [
        (
            "kdtree",
            "the CRT-like kd-tree (the paper's baseline)",
            Some("1.45-2.51x"),
        ),
        (
            "bvh",
            "obvhs' BVH2 (very-slow build, the project's f64 traversal)",
            None,
        ),
    ] {
        let r = ratio("vlf", baseline);
        if r.is_empty() {
            continue;
        }
        let faster = r.iter().filter(|(_, x, apart)| *x > 1.0 && *apart).count();
        let slower = r.iter().filter(|(_, x, apart)| *x < 1.0 && *apart).count();
        let listed: Vec<String> = r
            .iter()
            .map(|(m, x, apart)| format!("{m} {x:.2}x{}", if *apart { "" } else { " (within noise)" }))
            .collect();
        out += &format!(
            "- **VLF-RT vs {label}**: faster on {faster} of {} meshes and slower on {slower}, counting only frame times whose interquartile ranges are disjoint; speed-up (their median frame time / VLF-RT's) {}, median {:.2}x{}.\n",
            r.len(),
            listed.join(", "),
            median(&r.iter().map(|x| x.1).collect::<Vec<_>>()),
            paper.map_or(String::new(), |p| format!(" (the paper: {p})"))
        );
    }
    let cost: Vec<String> = spec
        .meshes
        .iter()
        .filter_map(|m| {
            let v = find(rows, &m.name, "vlf")?;
            let others: Vec<String> = ["kdtree", "bvh"]
                .iter()
                .filter_map(|s| find(rows, &m.name, s))
                .map(|o| {
                    format!(
                        "{} {:.2} MB / {:.2} s",
                        o.structure,
                        o.memory_bytes as f64 / 1e6,
                        o.build_seconds
                    )
                })
                .collect();
            Some(format!(
                "{} {:.0} MB / {:.2} s ({})",
                m.name,
                v.memory_bytes as f64 / 1e6,
                v.build_seconds,
                others.join(", ")
            ))
        })
        .collect();
    if !cost.is_empty() {
        out += &format!("- **What VLF-RT costs** (memory / build time): {}.\n", cost.join("; "));
    }
    out
}

/// A row of tuning.csv.
#[derive(Serialize)]
struct TuningCsv<'a> {
    mesh: &'a str,
    structure: &'a str,
    parameters: &'a str,
    #[serde(with = "float")]
    frame_s_median: f64,
    chosen: bool,
}

/// Writes ao.csv, tuning.csv, images/, plots/frame_time.png, report.md and manifest.toml under
/// `out`.
pub fn write_ao(
    spec: &AoSpec,
    (rows, tuning): (&[AoRow], &[TuningRow]),
    threads: usize,
    seconds: f64,
    out: &Path,
) -> anyhow::Result<()> {
    write_rows(
        &out.join("tuning.csv"),
        tuning.iter().map(|t| TuningCsv {
            mesh: &t.mesh,
            structure: t.structure,
            parameters: &t.parameters,
            frame_s_median: t.frame_seconds,
            chosen: t.chosen,
        }),
    )?;
    let csv = rows.iter().map(|r| CsvRow {
        mesh: &r.mesh,
        triangles: r.triangles,
        structure: r.structure,
        parameters: &r.parameters,
        build_s: r.build_seconds,
        memory_mb: format!("{:.3}", r.memory_bytes as f64 / 1e6),
        frames: r.frame_seconds.len(),
        frame_s_median: r.median_seconds(),
        primary_rays: r.rays.0,
        ao_rays: r.rays.1,
        mrays_per_s: r.mrays_per_s(),
        receivers: r.receivers,
        mean_ao: r.mean_ao,
        same_image_as_first: r.same_image,
    });
    write_rows(&out.join("ao.csv"), csv)?;
    for m in &spec.meshes {
        if let Some(r) = rows.iter().find(|r| r.mesh == m.name) {
            write_png(
                &out.join(format!("images/{}.png", m.name)),
                &grey(&r.image, spec.width, spec.height),
            )?;
        }
    }
    let series: Vec<(usize, Series)> = spec
        .structures
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let points = rows
                .iter()
                .filter(|r| r.structure == *s)
                .map(|r| (r.triangles as f64, r.median_seconds(), f64::NAN))
                .collect();
            (
                i,
                Series {
                    name: s.to_string(),
                    points,
                    dashed: false,
                },
            )
        })
        .collect();
    line_plot(
        &out.join("plots/frame_time.png"),
        &Axes::new(
            &format!(
                "AO, {} rays per hit, {}x{}, CPU f64",
                spec.ao.rays, spec.width, spec.height
            ),
            "triangles",
            "frame seconds (median)",
            true,
            true,
        ),
        &series,
        &[],
    )?;
    write_atomic(&out.join("report.md"), report(spec, rows, threads, seconds).as_bytes())?;
    crate::output::write_cpu_manifest(out, &spec.path, seconds, threads)
}

fn report(spec: &AoSpec, rows: &[AoRow], threads: usize, seconds: f64) -> String {
    let mut md = format!(
        "# {}: ambient occlusion, the visibility-field paper's Table 1 measured\n\n",
        spec.name
    );
    md += &format!(
        "Experiment `{}`, {:.0} s on the f64 CPU backend ({threads} threads). Each mesh is scaled into the unit ball and seen at {}x{} by one camera; every camera hit casts {} AO rays along the visibility field's grid lines (each oriented into the normal's hemisphere, `{}` weighting, length {}). Each method is first tuned per mesh, as the paper tuned both (the kd-tree over maximum depths {:?} and leaf sizes {:?}, the field over tile-BSP depths {:?}; {} timed frames each at {}x{}, `tuning.csv`), then the kept settings render one untimed frame, which gives the image, and every structure of a mesh is timed in {} interleaved rounds (a fresh seeded order each); the frame time is their median (quartiles beside it), rays/s count camera and AO rays.\n\n",
        spec.path.display(),
        seconds,
        spec.width,
        spec.height,
        spec.ao.rays,
        spec.ao.weighting.name(),
        spec.ao.max_distance,
        spec.tuning.kdtree_depths,
        spec.tuning.kdtree_leaves,
        spec.tuning.vlf_depths,
        spec.tuning.frames,
        spec.tuning.width,
        spec.tuning.height,
        spec.repeats
    );
    md += "## Verdict\n\n";
    md += &verdict(spec, rows);
    md += "\n## Ours\n\n| mesh | triangles | structure | parameters | build s | MB | frame s (q1-q3) | Mrays/s | vs kdtree | vs bvh | same image |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for r in rows {
        let vs = |s: &str| {
            find(rows, &r.mesh, s).map_or("n/a".to_string(), |b| {
                format!("{:.2}x", b.median_seconds() / r.median_seconds())
            })
        };
        md += &format!(
            "| {} | {} | {} | {} | {:.2} | {:.1} | {:.3} ({:.3}-{:.3}) | {:.2} | {} | {} | {} |\n",
            r.mesh,
            r.triangles,
            r.structure,
            r.parameters,
            r.build_seconds,
            r.memory_bytes as f64 / 1e6,
            r.median_seconds(),
            r.quartile_seconds().0,
            r.quartile_seconds().1,
            r.mrays_per_s(),
            vs("kdtree"),
            vs("bvh"),
            if r.same_image { "yes" } else { "NO" }
        );
    }
    md += "\n## The paper's Table 1 beside ours\n\nThe paper (2.8 GHz Pentium 4, 256x256, 513 rays per point): CRT and VLF-RT seconds at each one's best depth. Ours: the same ratio, CRT-like kd-tree frame time over VLF-RT's.\n\n| mesh | paper CRT s (depth) | paper VLF-RT s (depth) | paper speed-up | our speed-up |\n|---|---|---|---|---|\n";
    for m in &spec.meshes {
        let ours = match (find(rows, &m.name, "kdtree"), find(rows, &m.name, "vlf")) {
            (Some(k), Some(v)) => format!("{:.2}x", k.median_seconds() / v.median_seconds()),
            _ => "n/a".into(),
        };
        match &m.paper {
            Some(p) => {
                md += &format!(
                    "| {} for {} | {:.2} ({}) | {:.2} ({}) | {:.2}x | {ours} |\n",
                    m.name,
                    p.scene,
                    p.crt_seconds,
                    p.crt_depth,
                    p.vlf_seconds,
                    p.vlf_depth,
                    p.crt_seconds / p.vlf_seconds
                )
            }
            None => md += &format!("| {} | not in the paper | | | {ours} |\n", m.name),
        }
    }
    md += "\nOutputs: `ao.csv` (one row per mesh and structure), `tuning.csv` (every candidate of the tuning sweep), `images/MESH.png` (the AO image), `plots/frame_time.png`.\n";
    md
}
