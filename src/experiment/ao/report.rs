//! Outputs of an ambient-occlusion experiment: ao.csv, tuning.csv, each structure's AO image per
//! mesh (EXR and PNG), a plot of frame time per mesh, the comparison page, and report.md with the paper's Table 1 beside ours and a verdict
//! computed from the rows by the one timing rule.

use super::runner::{AoRow, TuningRow};
use super::spec::AoSpec;
use crate::accel::settings::ParameterColumns;
use crate::accel::Issue;
use crate::experiment::outputs::Outputs;
use crate::experiment::tuning::{round_rows, REUSED};
use crate::files::write_atomic;
use crate::metrics::stats::median;
use crate::output::numbers::{per_triangle, thousands};
use crate::output::page::{self, write_shots, Gallery, Page, Shot, Tone};
use crate::output::plots::{grouped_bars, Bar, Group};
use crate::output::table::{float, write_rows};
use crate::render::AdapterInfo;
use crate::timing::{paired_ratio, Comparison, Estimate, EstimateColumns, FRAME_S, RULE};
use serde::Serialize;

/// A row of ao.csv: the mesh, the structure and its parameters, one column each
/// ([`ParameterColumns`]), the build, the frame time with its interval ([`FRAME_S`]) and what
/// the frame cost ([`Measured`]).
type CsvRow<'a> = (Named<'a>, ParameterColumns, Built, EstimateColumns, Measured);

/// The columns before the parameters in ao.csv.
#[derive(Serialize)]
struct Named<'a> {
    mesh: &'a str,
    triangles: usize,
    structure: &'a str,
    issue: &'a str,
}

/// The columns between the parameters and the frame time in ao.csv.
#[derive(Serialize)]
struct Built {
    #[serde(with = "float")]
    build_s: f64,
    memory_bytes: u64,
    timed_frames: usize,
}

/// The columns after the frame time in ao.csv.
#[derive(Serialize)]
struct Measured {
    primary_rays: u64,
    ao_rays: u64,
    queries: u64,
    /// Empty where the structure exposes no counters (Embree).
    nodes_visited: Option<u64>,
    primitive_tests: Option<u64>,
    #[serde(with = "float")]
    rays_per_s: f64,
    receivers: usize,
    #[serde(with = "float")]
    mean_ao: f64,
    same_image_as_first: bool,
    differing_pixels: usize,
    #[serde(with = "float")]
    ao_difference: f64,
}

/// A row of rounds.csv: one timed frame of one mesh, structure and issue, in round order, so
/// every "median of per-round ratios" in the report recomputes from committed numbers.
#[derive(Serialize)]
struct RoundCsv<'a> {
    mesh: &'a str,
    structure: &'a str,
    issue: &'a str,
    round: usize,
    #[serde(with = "float")]
    frame_s: f64,
}

/// A row of tuning.csv: a candidate's mesh and structure, its parameters one column each, then
/// its time ([`FRAME_S`]) and work.
type TuningCsv<'a> = (Tuned<'a>, ParameterColumns, EstimateColumns, Candidate<'a>);

/// The columns before the parameters in tuning.csv.
#[derive(Serialize)]
struct Tuned<'a> {
    mesh: &'a str,
    structure: &'a str,
}

/// The columns after the time in tuning.csv: its work, and how it was judged
/// ([`crate::experiment::tuning::Verdict`]).
#[derive(Serialize)]
struct Candidate<'a> {
    nodes_visited: Option<u64>,
    primitive_tests: Option<u64>,
    candidate: usize,
    against: usize,
    word: &'a str,
    chosen: bool,
}

/// Whether the row's structure counts its walk's nodes and tests (Embree's do not).
fn counts_work(r: &AoRow) -> bool {
    crate::accel::counts_work(r.structure)
}

/// Whether the row's structure answers as the f64 reference does (Embree's f32 tests do not).
fn exact(r: &AoRow) -> bool {
    crate::accel::is_exact(r.structure)
}

/// The row of `structure` on `mesh` with single rays (the paper's measurement).
fn find<'a>(rows: &'a [AoRow], mesh: &str, structure: &str) -> Option<&'a AoRow> {
    find_issued(rows, mesh, structure, Issue::Single)
}

/// The row of `structure` on `mesh` with its rays issued as `issue`.
fn find_issued<'a>(rows: &'a [AoRow], mesh: &str, structure: &str, issue: Issue) -> Option<&'a AoRow> {
    rows.iter()
        .find(|r| r.mesh == mesh && r.structure == structure && r.issue == issue)
}

/// Speed-up of `subject` over `other` on one mesh: `other`'s time over `subject`'s (median of
/// per-round ratios with its interval), and the rule's word for `subject`.
fn speedup(subject: &AoRow, other: &AoRow) -> (Estimate, Comparison) {
    if subject.frame_seconds.len() != other.frame_seconds.len() || subject.frame_seconds.is_empty() {
        return (Estimate::NAN, Comparison::Undecided);
    }
    let ratio = paired_ratio(&subject.frame_seconds, &other.frame_seconds);
    (ratio.recip(), Comparison::of(&ratio))
}

/// The verdict on the paper's claim, from the rows: the subject against its baseline and every
/// other structure, per mesh by the rule, with the work and memory behind each time.
pub fn verdict(spec: &AoSpec, rows: &[AoRow]) -> String {
    let mut out = String::new();
    let identical = rows.iter().filter(|r| exact(r)).all(|r| r.same_image);
    let inexact: Vec<&AoRow> = rows.iter().filter(|r| !exact(r)).collect();
    let compared = rows.iter().any(exact);
    let qualifier = if inexact.is_empty() { "" } else { "exact " };
    out += &format!(
        "- **Exactness**: every {qualifier}structure's AO image {} the first {qualifier}structure's, bit for bit, on every mesh.\n",
        if identical { "equals" } else { "does NOT equal" }
    );
    if !inexact.is_empty() && !compared {
        out += "- **Inexact structures**: no exact structure ran, so their images were compared with none.\n";
    } else if !inexact.is_empty() {
        let per_mesh: Vec<String> = inexact
            .iter()
            .map(|r| match r.differing_pixels {
                0 => format!("{} on {}: none", r.label(), r.mesh),
                n => format!(
                    "{} on {}: {n} of {} pixels (mean AO difference {:+.2e})",
                    r.label(),
                    r.mesh,
                    r.image.len(),
                    r.ao_difference
                ),
            })
            .collect();
        out += &format!(
            "- **Inexact structures** (their own f32 triangle tests from f32 origins: a ray that grazes an edge, or leaves a point within f32 rounding of a neighbouring triangle, is decided otherwise): pixels that differ from the exact image, {}.\n",
            per_mesh.join("; ")
        );
    }
    let subject = spec.claim.subject.as_str();
    for (other, _) in spec.structures.iter().filter(|(s, _)| *s != subject) {
        let per_mesh: Vec<(String, Estimate, Comparison)> = spec
            .meshes
            .iter()
            .filter_map(|m| {
                let (a, b) = (find(rows, &m.name, subject)?, find(rows, &m.name, other)?);
                let (e, c) = speedup(a, b);
                Some((m.name.clone(), e, c))
            })
            .collect();
        if per_mesh.is_empty() || per_mesh.iter().all(|m| m.1.median.is_nan()) {
            continue;
        }
        let count = |c: Comparison| per_mesh.iter().filter(|m| m.2 == c).count();
        let listed: Vec<String> = per_mesh
            .iter()
            .map(|(m, e, c)| format!("{m} {}x ({})", e.show_speedup(2), c.word()))
            .collect();
        let claim = if *other == spec.claim.baseline {
            let paper: Vec<f64> = spec
                .meshes
                .iter()
                .filter_map(|m| m.paper.as_ref().map(|p| p.crt_seconds / p.vlf_seconds))
                .collect();
            let range = if paper.is_empty() {
                String::new()
            } else {
                format!(
                    "; the paper: {:.2}-{:.2}x",
                    paper.iter().cloned().fold(f64::INFINITY, f64::min),
                    paper.iter().cloned().fold(0.0, f64::max)
                )
            };
            format!(" (the paper's claim: faster than its baseline{range})")
        } else {
            String::new()
        };
        out += &format!(
            "- **`{subject}` vs `{other}`**{claim}: faster on {} of {} meshes, slower on {}, equivalent on {}, undecided on {}; speed-up (`{other}`'s time / `{subject}`'s, 95 % interval): {}; median over meshes {:.2}x.\n",
            count(Comparison::Faster),
            per_mesh.len(),
            count(Comparison::Slower),
            count(Comparison::Equivalent),
            count(Comparison::Undecided),
            listed.join(", "),
            median(&per_mesh.iter().map(|m| m.1.median).collect::<Vec<_>>()),
        );
    }
    let cost: Vec<String> = spec
        .meshes
        .iter()
        .filter_map(|m| {
            let v = find(rows, &m.name, subject)?;
            let others: Vec<String> = rows
                .iter()
                .filter(|o| o.mesh == m.name && o.structure != subject && o.issue == Issue::Single)
                .map(|o| {
                    format!(
                        "{} {:.2} MB ({} B per triangle) / {:.2} s",
                        o.structure,
                        o.memory_bytes as f64 / 1e6,
                        per_triangle(o.memory_bytes, o.triangles),
                        o.build_seconds
                    )
                })
                .collect();
            Some(format!(
                "{} {:.0} MB ({} B per triangle) / {:.2} s ({})",
                m.name,
                v.memory_bytes as f64 / 1e6,
                per_triangle(v.memory_bytes, v.triangles),
                v.build_seconds,
                others.join(", ")
            ))
        })
        .collect();
    if !cost.is_empty() {
        out += &format!(
            "- **What `{subject}` costs** (memory / build time): {}.\n",
            cost.join("; ")
        );
    }
    out
}

/// Writes ao.csv, tuning.csv, images/, plots/frame_time.png, report.md and index.html into `outputs`
/// (each path checked to stay in it: mesh names become file names).
pub fn write_ao(
    spec: &AoSpec,
    (rows, tuning): (&[AoRow], &[TuningRow]),
    adapter: &AdapterInfo,
    seconds: f64,
    outputs: &Outputs,
) -> anyhow::Result<()> {
    let out = |name: &str| outputs.path(name);
    // Written where a structure had candidates to choose among, as the frames kind does: a file
    // with no rows would have no header either (its parameter columns come from the rows).
    if !tuning.is_empty() {
        write_rows(
            &out("tuning.csv")?,
            tuning.iter().map(|t| -> TuningCsv {
                (
                    Tuned {
                        mesh: &t.mesh,
                        structure: t.structure,
                    },
                    ParameterColumns::of(&t.settings),
                    t.frame.columns(FRAME_S),
                    Candidate {
                        nodes_visited: t.verdict.timed().then_some(t.work.nodes),
                        primitive_tests: t.verdict.timed().then_some(t.work.primitives),
                        candidate: t.verdict.candidate,
                        against: t.verdict.against,
                        word: &t.verdict.word,
                        chosen: t.chosen,
                    },
                )
            }),
        )?;
        if tuning.iter().any(|t| t.verdict.timed()) {
            write_rows(
                &out("tuning_rounds.csv")?,
                tuning.iter().flat_map(|t| round_rows(&t.mesh, t.structure, &t.verdict)),
            )?;
        }
    }
    let csv = rows.iter().map(|r| -> CsvRow {
        (
            Named {
                mesh: &r.mesh,
                triangles: r.triangles,
                structure: r.structure,
                issue: r.issue.name(),
            },
            ParameterColumns::of(&r.settings),
            Built {
                build_s: r.build_seconds,
                memory_bytes: r.memory_bytes,
                timed_frames: r.frame_seconds.len(),
            },
            r.frame.columns(FRAME_S),
            Measured {
                primary_rays: r.rays.0,
                ao_rays: r.rays.1,
                queries: r.work.queries,
                nodes_visited: counts_work(r).then_some(r.work.nodes),
                primitive_tests: counts_work(r).then_some(r.work.primitives),
                rays_per_s: r.rays_per_s(),
                receivers: r.receivers,
                mean_ao: r.mean_ao,
                same_image_as_first: r.same_image,
                differing_pixels: r.differing_pixels,
                ao_difference: r.ao_difference,
            },
        )
    });
    write_rows(&out("ao.csv")?, csv)?;
    write_rows(
        &out("rounds.csv")?,
        rows.iter().flat_map(|r| {
            r.frame_seconds.iter().enumerate().map(move |(round, &s)| RoundCsv {
                mesh: &r.mesh,
                structure: r.structure,
                issue: r.issue.name(),
                round,
                frame_s: s,
            })
        }),
    )?;
    let galleries = galleries(spec, rows);
    for g in &galleries {
        for s in &g.shots {
            out(&s.exr)?;
            out(&s.png)?;
        }
        write_shots(outputs.dir(), g)?;
    }
    let groups: Vec<Group> = spec
        .meshes
        .iter()
        .filter_map(|m| {
            let of_mesh: Vec<&AoRow> = rows.iter().filter(|r| r.mesh == m.name).collect();
            let first = of_mesh.first()?;
            let bars = variants(spec, rows)
                .iter()
                .enumerate()
                .filter_map(|(i, &(s, issue))| {
                    let r = of_mesh.iter().find(|r| r.structure == s && r.issue == issue)?;
                    Some(Bar {
                        series: i,
                        value: r.frame.median,
                        lo: r.frame.lo,
                        hi: r.frame.hi,
                    })
                })
                .collect();
            Some(Group {
                name: m.name.clone(),
                note: format!("{} triangles", thousands(first.triangles)),
                bars,
            })
        })
        .collect();
    let names: Vec<(usize, String)> = variants(spec, rows)
        .iter()
        .enumerate()
        .map(|(i, &(s, issue))| (i, issue.label(s)))
        .collect();
    grouped_bars(
        &out("plots/frame_time.png")?,
        &format!(
            "AO frame time per mesh: {} rays per hit, {}x{}, {}",
            spec.ao.rays,
            spec.width,
            spec.height,
            adapter.short()
        ),
        "frame time, median (s)",
        &names,
        &groups,
    )?;
    let report = report(spec, rows, adapter, seconds);
    write_atomic(&out("report.md")?, report.as_bytes())?;
    page::write(
        outputs.dir(),
        &Page {
            title: format!("{}: ambient occlusion per structure", spec.name),
            report,
            galleries,
        },
    )
}

/// One gallery per mesh: its AO image from each structure (`images/MESH_STRUCTURE.exr`), brute
/// force the reference where it ran (else the first structure).
fn galleries(spec: &AoSpec, rows: &[AoRow]) -> Vec<Gallery> {
    spec.meshes
        .iter()
        .filter_map(|m| {
            // Bundled rays give the same image (checked bit for bit): one shot per structure.
            let single: Vec<&AoRow> = rows
                .iter()
                .filter(|r| r.mesh == m.name && r.issue == Issue::Single)
                .collect();
            let shots: Vec<Shot> = single
                .iter()
                .map(|r| Shot {
                    label: format!("{}: {}", r.mesh, r.structure),
                    exr: format!("images/{}_{}.exr", r.mesh, r.structure),
                    png: format!("images/{}_{}.png", r.mesh, r.structure),
                    values: r.image.clone(),
                    key: vec![
                        ("mesh".into(), r.mesh.clone()),
                        ("structure".into(), r.structure.into()),
                    ],
                })
                .collect();
            let reference = single.iter().position(|r| r.structure == "brute").unwrap_or(0);
            (!shots.is_empty()).then(|| Gallery {
                title: format!("{}: ambient occlusion", m.name),
                width: spec.width,
                height: spec.height,
                tone: Tone::Linear,
                reference: Some(reference),
                against: None,
                shots,
            })
        })
        .collect()
}

/// The structure every other is set against in the per-thread table, where the experiment
/// runs it: the kernel production CPU renderers use.
const PER_THREAD_BASELINE: &str = "embree";

/// Throughput per CPU thread of every single-ray row (rays over the frame time's median and
/// its interval's ends, over the backend's threads), and each structure's speed against
/// Embree's on the same mesh in the same rounds (median of per-round ratios, 95 % interval,
/// the rule's word): the per-core figure of the visibility field, the BVHs and Embree on one
/// AO workload.
pub fn per_thread(spec: &AoSpec, rows: &[AoRow], threads: usize) -> String {
    let against = spec.structures.iter().any(|(s, _)| *s == PER_THREAD_BASELINE);
    let mut md = format!(
        "\n## Per thread\n\nMrays/s per thread: camera and AO rays of a frame over its median time [over the interval's ends], divided by the CPU backend's {threads} threads (all of them working: a share of the machine, not one core alone); every structure tests triangles in f64 but Embree, whose traversal and tests are f32{}.\n\n| mesh | structure | Mrays/s per thread |{}\n|---|---|---|{}\n",
        if against {
            format!("; against `{PER_THREAD_BASELINE}`: its frame time over the structure's, median of per-round ratios [95 %] and the rule's word")
        } else {
            String::new()
        },
        if against { format!(" speed vs {PER_THREAD_BASELINE} |") } else { String::new() },
        if against { "---|" } else { "" },
    );
    for r in rows.iter().filter(|r| r.issue == Issue::Single) {
        let rays = (r.rays.0 + r.rays.1) as f64 / threads as f64 / 1e6;
        md += &format!(
            "| {} | {} | {:.3} [{:.3}, {:.3}] |",
            r.mesh,
            r.structure,
            rays / r.frame.median,
            rays / r.frame.hi,
            rays / r.frame.lo
        );
        if against {
            md += &match find(rows, &r.mesh, PER_THREAD_BASELINE) {
                Some(e) if e.structure != r.structure => {
                    let (ratio, word) = speedup(r, e);
                    format!(" {}x ({}) |", ratio.show_speedup(2), word.word())
                }
                Some(_) => " 1 |".to_string(),
                None => " n/a |".to_string(),
            };
        }
        md += "\n";
    }
    md
}

/// A work count in the table's words: "n/a" where the structure counts none.
fn counted(r: &AoRow, n: u64) -> String {
    if counts_work(r) {
        format!("{:.3e}", n as f64)
    } else {
        "n/a".into()
    }
}

fn report(spec: &AoSpec, rows: &[AoRow], adapter: &AdapterInfo, seconds: f64) -> String {
    let schedule = spec.header.schedule;
    let device = adapter.describe();
    let gpu = adapter.is_gpu();
    let tuned: Vec<String> = spec
        .structures
        .iter()
        .filter(|(_, c)| c.len() > 1)
        .map(|(s, c)| {
            format!(
                "`{s}` over {} candidates ({})",
                c.len(),
                c.iter().map(|x| x.describe()).collect::<Vec<_>>().join("; ")
            )
        })
        .collect();
    let mut md = format!(
        "# {}: ambient occlusion, the visibility-field paper's Table 1 measured\n\n",
        spec.name
    );
    md += &format!(
        "Experiment `{}`, {:.0} s on {device}. Each mesh is scaled into the unit ball and seen at {}x{} by one camera; every camera hit casts {} AO rays along the visibility field's grid lines (each oriented into the normal's hemisphere, `{}` weighting, length {}). Each structure is first tuned per mesh, as the paper tuned both methods ({}; each candidate timed in {} interleaved rounds at {}x{}, the first listed kept unless a later one is *faster* than the one kept so far by the rule below, `tuning.csv`, its rounds in `tuning_rounds.csv`{}); then the kept settings render one untimed frame, which gives the image and the work counts, and every structure of a mesh is timed in {} interleaved rounds (order seed {}). Rays/s count camera and AO rays. {RULE}\n\n",
        spec.path.display(),
        seconds,
        spec.width,
        spec.height,
        spec.ao.rays,
        spec.ao.weighting.name(),
        spec.ao.max_distance,
        if tuned.is_empty() { "nothing to tune".to_string() } else { tuned.join("; ") },
        spec.tuning.repeats,
        spec.tuning.width,
        spec.tuning.height,
        spec.reused.as_ref().map_or(String::new(), |k| format!(
            "; settings the file `{}` keeps taken as kept there (`--tuning`, word `{REUSED}`)",
            k.path.display()
        )),
        schedule.repeats,
        schedule.seed,
    );
    md += "## Verdict\n\n";
    md += &verdict(spec, rows);
    md += &open_question(spec, rows, gpu);
    let packets = if gpu {
        "every ray walking on its own (on the GPU a bundle is an order of dispatch, so its counts are the single rays')"
    } else {
        "a kd-tree packet's node once for its rays"
    };
    md += &format!("\n## Ours\n\nFrame seconds: median [95 % interval]; nodes and tests: per frame, deterministic (nodes: tree nodes, or the field's tiles and tile-BSP leaves, visited, {packets}; tests: ray-triangle tests).\n\n| mesh | triangles | structure | parameters | build s | MB | bytes per triangle | frame s | Mrays/s | nodes | tests | same image |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        md += &format!(
            "| {} | {} | {} | {} | {:.2} | {:.1} | {} | {} | {:.2} | {} | {} | {} |\n",
            r.mesh,
            r.triangles,
            r.label(),
            r.settings.describe(),
            r.build_seconds,
            r.memory_bytes as f64 / 1e6,
            per_triangle(r.memory_bytes, r.triangles),
            r.frame.show(3),
            r.rays_per_s() / 1e6,
            counted(r, r.work.nodes),
            counted(r, r.work.primitives),
            match (r.same_image, exact(r)) {
                (true, _) => "yes".to_string(),
                (false, true) => "NO".to_string(),
                (false, false) => format!("{} px differ (f32)", r.differing_pixels),
            }
        );
    }
    if let (false, Some(threads)) = (gpu, adapter.threads) {
        md += &per_thread(spec, rows, threads);
    }
    let (subject, baseline) = (&spec.claim.subject, &spec.claim.baseline);
    md += &format!("\n## The paper's Table 1 beside ours\n\nThe paper (2.8 GHz Pentium 4, 256x256, 513 rays per point): CRT and VLF-RT seconds at each one's best depth. Ours: `{baseline}`'s frame time over `{subject}`'s (median of per-round ratios, 95 % interval).\n\n| mesh | paper CRT s (depth) | paper VLF-RT s (depth) | paper speed-up | our speed-up |\n|---|---|---|---|---|\n");
    for m in &spec.meshes {
        let ours = match (find(rows, &m.name, subject), find(rows, &m.name, baseline)) {
            (Some(a), Some(b)) => format!("{}x", speedup(a, b).0.show_speedup(2)),
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
    md += "\nOutputs: `ao.csv` (one row per mesh, structure and way of issuing rays), `rounds.csv` (every timed frame, in round order: the per-round ratios recompute from it), `tuning.csv` (every candidate of the tuning sweep, where a structure had more than one, with the word that kept or passed it) and `tuning_rounds.csv` (its per-round times), `images/MESH_STRUCTURE.exr` and `.png` (each structure's AO image), `index.html` (the comparison page), `plots/frame_time.png`.\n";
    md
}

/// A structure and how its rays were issued.
type Variant<'a> = (&'a str, Issue);

/// Every (structure, issue) the experiment timed, structures in file order (on the CPU a
/// structure without bundles of its own is timed with single rays only).
fn variants(spec: &AoSpec, rows: &[AoRow]) -> Vec<(&'static str, Issue)> {
    spec.structures
        .iter()
        .flat_map(|(s, _)| spec.issues.iter().map(move |&i| (*s, i)))
        .filter(|&(s, i)| rows.iter().any(|r| r.structure == s && r.issue == i))
        .collect()
}

/// The paper's open question (Section 9: SAH and ray bundles for both algorithms), answered
/// from the rows where the experiment timed more than the paper's set-up: the claim's subject
/// against every other structure with the rays issued the same way, and what bundling gains
/// each structure; one cell per mesh, `other`'s time over `subject`'s with its interval and the
/// rule's word.
pub fn open_question(spec: &AoSpec, rows: &[AoRow], gpu: bool) -> String {
    if spec.issues.len() < 2 && spec.structures.len() < 3 {
        return String::new();
    }
    let subject = spec.claim.subject.as_str();
    let timed = variants(spec, rows);
    // Each rival with its best way of issuing rays against the subject's single and bundled.
    let mut pairs: Vec<(String, Variant, Variant)> = Vec::new();
    for &(s, issue) in timed.iter().filter(|v| v.0 == subject) {
        for &(other, other_issue) in timed.iter().filter(|v| v.0 != subject) {
            pairs.push((
                format!("`{other}` {} / `{subject}` {}", other_issue.name(), issue.name()),
                (s, issue),
                (other, other_issue),
            ));
        }
    }
    for &(s, _) in timed.iter().filter(|v| v.1 == Issue::Bundled) {
        pairs.push((
            format!("`{s}` single / bundled"),
            (s, Issue::Bundled),
            (s, Issue::Single),
        ));
    }
    let bundled = if gpu {
        "Bundled, on the GPU: the AO rays issued direction-major, one dispatch per grid line with every receiver's ray along it, so the invocations running side by side walk one direction's part of a structure (each ray still walks on its own: the order, not the walk, is what changes, and every structure can take it)"
    } else {
        "Bundled: the AO rays of one grid line for 4096 receivers at a time, the field walking them in tile order, the kd-trees in packets of 8 (f32 SIMD lanes for the walk, f64 lanes for the triangle tests); a structure without bundles of its own (the BVHs) is timed with single rays only, its best order"
    };
    let mut md = format!("\n### The open question: SAH and ray bundles\n\nThe paper closes by asking how the field fares when a better split heuristic (SAH) and ray bundles are given to both algorithms. Each cell: the first named's frame time over the second's, median of per-round ratios with its 95 % interval, and the rule's word for the second (faster: above 1 beyond noise). {bundled}.\n\n| comparison |");
    for m in &spec.meshes {
        md += &format!(" {} |", m.name);
    }
    md += "\n|---|";
    md += &"---|".repeat(spec.meshes.len());
    md += "\n";
    for (label, (a, ia), (b, ib)) in &pairs {
        let cells: Vec<String> = spec
            .meshes
            .iter()
            .map(
                |m| match (find_issued(rows, &m.name, a, *ia), find_issued(rows, &m.name, b, *ib)) {
                    (Some(x), Some(y)) => {
                        let (e, c) = speedup(x, y);
                        format!("{}x {}", e.show_speedup(2), c.word())
                    }
                    _ => "n/a".into(),
                },
            )
            .collect();
        md += &format!("| {label} | {} |\n", cells.join(" | "));
    }
    md
}
