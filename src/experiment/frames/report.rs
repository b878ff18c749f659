//! Outputs of a frame-time experiment: frames.csv, builds.csv, plots (frame time along the
//! path; with several scene sizes, frame time, memory and build time against triangle count on
//! log-log axes; with motion, update time along the path), a strip of frames, and report.md
//! around the verdict ([`super::verdict`]).

use super::runner::{BuildRow, FrameRow, FramesOutcome};
use super::spec::{Cameras, FramesSpec, Generator};
use super::verdict::{label, labels, over_frames, verdict};
use crate::accel::settings::ParameterColumns;
use crate::experiment::tuning::{round_rows, REUSED};
use crate::files::write_atomic;
use crate::metrics::stats::median;
use crate::output::images::{exposure, tonemap};
use crate::output::numbers::thousands;
use crate::output::page::{self, write_shots, Gallery, Page, Shot, Tone};
use crate::output::plots::{image_grid, line_plot, Axes, Point, Series, Tile};
use crate::output::table::{float, write_rows};
use crate::render::AdapterInfo;
use crate::scene::procedural::random;
use crate::timing::{coverage, median_interval, Estimate, EstimateColumns, FRAME_S, RULE};
use serde::Serialize;
use std::path::Path;

/// A row of frames.csv: which frame of which structure, its time with its interval over timed
/// renders ([`FRAME_S`]), then what it cost.
type FrameCsv<'a> = (FrameOf<'a>, EstimateColumns, FrameCost);

/// The columns before the frame time in frames.csv.
#[derive(Serialize)]
struct FrameOf<'a> {
    triangles: usize,
    structure: &'a str,
    update: &'a str,
    shading: &'a str,
    viewpoint: &'a str,
    frame: u32,
}

impl<'a> FrameOf<'a> {
    fn of(r: &'a FrameRow) -> FrameOf<'a> {
        FrameOf {
            triangles: r.triangles,
            structure: r.structure,
            update: r.update,
            shading: r.shading.name(),
            viewpoint: &r.viewpoint,
            frame: r.frame,
        }
    }
}

/// The columns after the frame time in frames.csv.
#[derive(Serialize)]
struct FrameCost {
    timed_renders: usize,
    #[serde(with = "float")]
    update_s: f64,
    /// `refit`, `in-place` or `rebuild`, as the structure says.
    update_kind: &'static str,
    rays: u64,
    primary_rays: u64,
    shadow_rays: u64,
    reflection_rays: u64,
    ambient_rays: u64,
    queries: u64,
    /// Empty where the structure exposes no counters (Embree).
    nodes_visited: Option<u64>,
    primitive_tests: Option<u64>,
    differing_pixels: usize,
}

/// A row of builds.csv: the scene size and structure, its parameters one column each, then its
/// build's time and memory.
type BuildCsv<'a> = (Built<'a>, ParameterColumns, BuildCost);

/// The columns before the parameters in builds.csv.
#[derive(Serialize)]
struct Built<'a> {
    triangles: usize,
    structure: &'a str,
}

/// The columns after the parameters in builds.csv.
#[derive(Serialize)]
struct BuildCost {
    #[serde(with = "float")]
    build_s: f64,
    memory_bytes: u64,
}

/// A row of rounds.csv: one timed render of one frame and structure ([`FrameOf`]), in round
/// order, so every frame's median and interval in frames.csv, and every per-frame ratio,
/// recomputes from committed numbers.
type RoundCsv<'a> = (FrameOf<'a>, Round);

/// The columns after the frame in rounds.csv.
#[derive(Serialize)]
struct Round {
    round: usize,
    #[serde(with = "float")]
    frame_s: f64,
}

/// The columns of a candidate's time over the tuning cameras in tuning.csv.
const TUNING_S: [&str; 3] = ["tuning_s", "tuning_s_lo", "tuning_s_hi"];

/// A row of tuning.csv: the unit that tuned, the scene size and structure, the candidate's
/// parameters one column each, its build, its time over the tuning cameras ([`TUNING_S`]) and
/// its work.
type TuningCsv<'a> = (Tuned<'a>, ParameterColumns, BuildTime, EstimateColumns, TuningWork<'a>);

/// The columns before the parameters in tuning.csv.
#[derive(Serialize)]
struct Tuned<'a> {
    unit: &'a str,
    scene: &'a str,
    triangles: usize,
    structure: &'a str,
}

/// The column between the parameters and the time in tuning.csv.
#[derive(Serialize)]
struct BuildTime {
    #[serde(with = "float")]
    build_s: f64,
}

/// The columns after the time in tuning.csv: its work, and how it was judged
/// ([`crate::experiment::tuning::Verdict`]).
#[derive(Serialize)]
struct TuningWork<'a> {
    nodes_visited: Option<u64>,
    primitive_tests: Option<u64>,
    candidate: usize,
    against: usize,
    word: &'a str,
    chosen: bool,
}

/// Writes frames.csv, builds.csv, tuning.csv (where a structure was tuned), plots/, images/, report.md and index.html under `out`.
pub fn write_frames(
    spec: &FramesSpec,
    outcome: &FramesOutcome,
    adapter: &AdapterInfo,
    seconds: f64,
    out: &Path,
) -> anyhow::Result<()> {
    let device = adapter.describe();
    let on = adapter.short();
    let rows = &outcome.frames;
    write_rows(
        &out.join("frames.csv"),
        rows.iter().map(|r| -> FrameCsv {
            (
                FrameOf::of(r),
                Estimate {
                    median: r.seconds,
                    ..median_interval(&r.renders)
                }
                .columns(FRAME_S),
                FrameCost {
                    timed_renders: r.renders.len(),
                    update_s: r.update_seconds.unwrap_or(f64::NAN),
                    update_kind: r.updated.map_or("", |u| u.name()),
                    rays: r.rays.total(),
                    primary_rays: r.rays.primary,
                    shadow_rays: r.rays.shadow_total(),
                    reflection_rays: r.rays.reflection,
                    ambient_rays: r.rays.ambient,
                    queries: r.work.queries,
                    nodes_visited: counts_work(r).then_some(r.work.nodes),
                    primitive_tests: counts_work(r).then_some(r.work.primitives),
                    differing_pixels: r.differing_pixels,
                },
            )
        }),
    )?;
    write_rows(
        &out.join("rounds.csv"),
        rows.iter().flat_map(|r| {
            r.renders
                .iter()
                .enumerate()
                .map(move |(round, &frame_s)| -> RoundCsv { (FrameOf::of(r), Round { round, frame_s }) })
        }),
    )?;
    write_rows(
        &out.join("builds.csv"),
        outcome.builds.iter().map(|b: &BuildRow| -> BuildCsv {
            (
                Built {
                    triangles: b.triangles,
                    structure: b.structure,
                },
                ParameterColumns::of(&b.settings),
                BuildCost {
                    build_s: b.build_seconds,
                    memory_bytes: b.memory_bytes,
                },
            )
        }),
    )?;
    if !outcome.tuning.is_empty() {
        write_rows(
            &out.join("tuning.csv"),
            outcome.tuning.iter().map(|(unit, t)| -> TuningCsv {
                (
                    Tuned {
                        unit,
                        scene: &t.scene,
                        triangles: t.triangles,
                        structure: t.structure,
                    },
                    ParameterColumns::of(&t.settings),
                    BuildTime {
                        build_s: t.build_seconds,
                    },
                    t.seconds.columns(TUNING_S),
                    TuningWork {
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
        if outcome.tuning.iter().any(|(_, t)| t.verdict.timed()) {
            write_rows(
                &out.join("tuning_rounds.csv"),
                outcome
                    .tuning
                    .iter()
                    .flat_map(|(_, t)| round_rows(&t.scene, t.structure, &t.verdict)),
            )?;
        }
    }
    let summaries = summarise(spec, outcome);
    write_rows(&out.join("summary.csv"), summaries.iter().map(Summary::row))?;
    let all = labels(rows);
    let largest = outcome.builds.iter().map(|b| b.triangles).max().unwrap_or(0);
    // Each structure (and way of following motion) keeps one look in every plot.
    let look = |l: &str| all.iter().position(|x| x == l).unwrap_or(0);
    for &(shading, _) in &spec.shadings {
        let series = |value: &dyn Fn(&FrameRow) -> Point| -> Vec<Series> {
            all.iter()
                .map(|l| Series {
                    name: l.clone(),
                    look: look(l),
                    points: rows
                        .iter()
                        .filter(|r| r.shading == shading && r.triangles == largest && label(r) == *l)
                        .filter(|r| r.viewpoint == spec.viewpoints[0])
                        .map(value)
                        .collect(),
                })
                .collect()
        };
        let title = format!(
            "{} shading, {}x{}, {} triangles, viewpoint {}, {on}",
            shading.name(),
            spec.width,
            spec.height,
            thousands(largest),
            spec.viewpoints[0]
        );
        let frame_times = series(&|r| {
            let e = median_interval(&r.renders);
            Point::between(r.frame as f64, r.seconds, e.lo, e.hi)
        });
        let renders = rows.iter().map(|r| r.renders.len()).min().unwrap_or(0);
        let interval = format!("{:.0} % interval of {renders} renders", coverage(renders) * 100.0);
        line_plot(
            &out.join(format!("plots/frame_time_{}.png", shading.name())),
            &Axes {
                interval: &interval,
                ..Axes::new(
                    &title,
                    "frame",
                    "render seconds (median of the renders)",
                    false,
                    spread(&frame_times) > 30.0,
                )
            },
            &frame_times,
            &[],
        )?;
        if spec.motion.is_some() {
            line_plot(
                &out.join(format!("plots/update_time_{}.png", shading.name())),
                &Axes::new(&title, "frame", "update seconds (one update per frame)", false, true),
                &series(&|r| Point::bare(r.frame as f64, r.update_seconds.unwrap_or(f64::NAN))),
                &[],
            )?;
        }
        let sizes: Vec<usize> = outcome.builds.iter().map(|b| b.triangles).collect();
        if sizes.iter().any(|&t| t != largest) {
            // The medians over the path with their intervals, as the report's table gives them.
            let series: Vec<Series> = all
                .iter()
                .map(|l| Series {
                    name: l.clone(),
                    look: look(l),
                    points: summaries
                        .iter()
                        .filter(|s| s.shading == shading.name() && s.structure == *l)
                        .map(|s| Point::between(s.triangles as f64, s.frame.median, s.frame.lo, s.frame.hi))
                        .collect(),
                })
                .collect();
            line_plot(
                &out.join(format!("plots/scaling_{}.png", shading.name())),
                &Axes {
                    interval: "95 % interval over the frames",
                    ..Axes::new(
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
                    )
                },
                &series,
                &[],
            )?;
        }
    }
    if outcome.builds.iter().any(|b| b.triangles != largest) {
        // One structure's look: its first label's (the structure, or how it first followed motion).
        let structure_look = |name: &str| rows.iter().find(|r| r.structure == name).map_or(0, |r| look(&label(r)));
        for (file, title, what, value) in [
            (
                "memory",
                "Memory beyond the triangles: one exact count per structure and size",
                "MB beyond the triangles (exact, no interval)",
                &(|b: &BuildRow| b.memory_bytes as f64 / 1e6) as &dyn Fn(&BuildRow) -> f64,
            ),
            (
                "build_time",
                "Build time: one build per structure and size, timed once",
                "build seconds (one timing, no interval)",
                &|b: &BuildRow| b.build_seconds,
            ),
        ] {
            let series: Vec<Series> = spec
                .structures
                .iter()
                .map(|s| Series {
                    name: s.name.to_string(),
                    look: structure_look(s.name),
                    points: outcome
                        .builds
                        .iter()
                        .filter(|b| b.structure == s.name)
                        .map(|b| Point::bare(b.triangles as f64, value(b)))
                        .collect(),
                })
                .collect();
            line_plot(
                &out.join(format!("plots/{file}.png")),
                &Axes::new(title, "triangles", what, true, true),
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
        let tiles: Vec<Tile> = pictures.iter().map(|(c, img)| Tile::new(c.clone(), img)).collect();
        image_grid(
            &out.join(format!("images/strip_{}.png", shading.name())),
            &tiles,
            tiles.len().max(1),
        )?;
    }
    let galleries = strips(spec, outcome);
    for g in &galleries {
        write_shots(out, g)?;
    }
    let report = report(spec, outcome, &device, seconds);
    write_atomic(&out.join("report.md"), report.as_bytes())?;
    page::write(
        out,
        &Page {
            title: format!("{}: frames along a camera path", spec.name),
            report,
            galleries,
        },
    )
}

/// One gallery per shading: the strip's frames (`images/strip_SHADING_FRAME.exr`, radiance,
/// the first structure's), shown at the first frame's exposure, each against the next
/// shading's strip (the same frame under the other shading).
fn strips(spec: &FramesSpec, outcome: &FramesOutcome) -> Vec<Gallery> {
    let mut strips: Vec<Gallery> = spec
        .shadings
        .iter()
        .filter_map(|&(shading, _)| {
            let frames: Vec<_> = outcome.pictures.iter().filter(|p| p.shading == shading).collect();
            let first = frames.first()?;
            Some(Gallery {
                title: format!("{} frames along the path", shading.name()),
                width: spec.width,
                height: spec.height,
                tone: Tone::Radiance {
                    p99: exposure(&Tone::radiance_stored(&first.radiance)),
                },
                reference: None,
                against: None,
                shots: frames
                    .iter()
                    .map(|p| Shot {
                        label: format!("{} frame {}", shading.name(), p.frame),
                        exr: format!("images/strip_{}_{}.exr", shading.name(), p.frame),
                        png: format!("images/strip_{}_{}.png", shading.name(), p.frame),
                        values: p.radiance.clone(),
                        key: vec![
                            ("shading".into(), shading.name().into()),
                            ("frame".into(), p.frame.to_string()),
                        ],
                    })
                    .collect(),
            })
        })
        .collect();
    let n = strips.len();
    for (i, g) in strips.iter_mut().enumerate() {
        g.against = (n > 1).then_some((i + 1) % n);
    }
    strips
}

/// The largest positive y of `series` over the smallest: where it is large, one structure's
/// times would flatten the others' on a linear axis.
fn spread(series: &[Series]) -> f64 {
    let ys = || {
        series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.y))
            .filter(|y| *y > 0.0)
    };
    ys().fold(0.0, f64::max) / ys().fold(f64::INFINITY, f64::min)
}

/// One structure (and way of following motion) at one scene size and shading, over its path:
/// a row of summary.csv ([`Summary::row`]) and of the report's medians.
struct Summary {
    triangles: usize,
    shading: &'static str,
    structure: String,
    frame: Estimate,
    block_frames: usize,
    update: Estimate,
    rays: f64,
    nodes_visited: f64,
    primitive_tests: f64,
    frames: usize,
}

/// A row of summary.csv: the size, shading and structure, the frame time over the path with
/// its interval ([`FRAME_S`]), then the rest of the medians.
type SummaryCsv<'a> = (Summarised<'a>, EstimateColumns, PathMedians);

/// The columns before the frame time in summary.csv.
#[derive(Serialize)]
struct Summarised<'a> {
    triangles: usize,
    shading: &'static str,
    structure: &'a str,
}

/// The columns after the frame time in summary.csv.
#[derive(Serialize)]
struct PathMedians {
    block_frames: usize,
    #[serde(with = "float")]
    update_s: f64,
    #[serde(with = "float")]
    rays: f64,
    #[serde(with = "float")]
    nodes_visited: f64,
    #[serde(with = "float")]
    primitive_tests: f64,
    frames: usize,
}

impl Summary {
    /// Its row of summary.csv.
    fn row(&self) -> SummaryCsv<'_> {
        (
            Summarised {
                triangles: self.triangles,
                shading: self.shading,
                structure: &self.structure,
            },
            self.frame.columns(FRAME_S),
            PathMedians {
                block_frames: self.block_frames,
                update_s: self.update.median,
                rays: self.rays,
                nodes_visited: self.nodes_visited,
                primitive_tests: self.primitive_tests,
                frames: self.frames,
            },
        )
    }
}

/// Whether the row's structure counts its walk's nodes and tests (Embree's do not).
fn counts_work(r: &FrameRow) -> bool {
    crate::accel::counts_work(r.structure)
}

/// A median work count in the report's words: "n/a" where none was counted.
fn count(x: f64) -> String {
    if x.is_nan() {
        "n/a".into()
    } else {
        format!("{x:.3e}")
    }
}

/// Every size x shading x structure of the rows, in scene, shading and first-seen order.
fn summarise(spec: &FramesSpec, outcome: &FramesOutcome) -> Vec<Summary> {
    let rows = &outcome.frames;
    let mut sizes: Vec<usize> = outcome.builds.iter().map(|b| b.triangles).collect();
    sizes.dedup();
    let mut out = Vec::new();
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
                let (frame, block) = over_frames(&secs, spec.cameras);
                let upd: Vec<f64> = sel.iter().filter_map(|r| r.update_seconds).collect();
                let update = if upd.is_empty() {
                    Estimate::NAN
                } else {
                    over_frames(&upd, spec.cameras).0
                };
                let of = |f: fn(&FrameRow) -> u64| median(&sel.iter().map(|r| f(r) as f64).collect::<Vec<_>>());
                // NaN (an empty field, "n/a") where the structure counts no work.
                let counted = |f: fn(&FrameRow) -> u64| if counts_work(sel[0]) { of(f) } else { f64::NAN };
                out.push(Summary {
                    triangles: t,
                    shading: shading.name(),
                    structure: l,
                    frame,
                    block_frames: block,
                    update,
                    rays: of(|r| r.rays.total()),
                    nodes_visited: counted(|r| r.work.nodes),
                    primitive_tests: counted(|r| r.work.primitives),
                    frames: sel.len(),
                });
            }
        }
    }
    out
}

/// What was tuned, over which candidates, and what each scene kept.
fn tuning_paragraph(spec: &FramesSpec, outcome: &FramesOutcome) -> String {
    let tuned: Vec<String> = spec
        .candidates
        .iter()
        .filter(|c| c.len() > 1)
        .map(|c| {
            format!(
                "`{}` over {} candidates ({})",
                c[0].name,
                c.len(),
                c.iter().map(|x| x.describe()).collect::<Vec<_>>().join("; ")
            )
        })
        .collect();
    if tuned.is_empty() {
        return "Every structure runs at the one setting its file gives (nothing listed to tune).\n\n".into();
    }
    let fixed: Vec<String> = spec
        .candidates
        .iter()
        .filter(|c| c.len() == 1)
        .map(|c| format!("`{}` ({})", c[0].name, c[0].describe()))
        .collect();
    let kept: Vec<String> = outcome
        .tuning
        .iter()
        .filter(|(_, t)| t.chosen)
        .map(|(unit, t)| {
            format!(
                "{unit}: `{}` {} ({})",
                t.structure,
                t.settings.describe(),
                t.verdict.word
            )
        })
        .collect();
    let reused = spec.reused.as_ref().map_or(String::new(), |k| {
        format!(
            " Settings the file `{}` keeps are taken as kept there (`--tuning`, word `{REUSED}`), not timed again.",
            k.path.display()
        )
    });
    let t = &spec.tuning;
    format!(
        "Tuning, per scene before its frames are timed: {}; each candidate built and timed rendering {} camera(s) per viewpoint drawn at random with their own seed ({}, never the frames measured) at {}x{} under {} shading, in {} interleaved rounds; the first listed is kept unless a later one is *faster* than the one kept so far by the rule below (`tuning.csv` gives each candidate's word, `tuning_rounds.csv` its rounds).{} At one setting: {}. Kept: {}.\n\n",
        tuned.join("; "),
        t.cameras,
        t.seed,
        spec.width,
        spec.height,
        super::tuning::tuning_shading(spec).name(),
        t.repeats,
        reused,
        if fixed.is_empty() { "none".to_string() } else { fixed.join(", ") },
        kept.join("; ")
    )
}

fn report(spec: &FramesSpec, outcome: &FramesOutcome, device: &str, seconds: f64) -> String {
    let rows = &outcome.frames;
    let mut md = format!("# {}: frame times per acceleration structure\n\n", spec.name);
    md += &format!(
        "Experiment `{}`, {:.0} s on {device}. Scenes: {}. {} frames per viewpoint ({}; {}) at {}x{}, shadings {}. Every frame is rendered by every structure in {} interleaved rounds (counterbalanced seeded orders of the structures; order seed {}), the median kept (`frames.csv`: every frame with the interval of its renders: their range for three, a 75 % interval), and compared pixel for pixel with the first structure's; before each path every structure renders its first frame {} time(s) untimed. {RULE}{}\n\n",
        spec.path.display(),
        seconds,
        outcome.scenes.join("; "),
        spec.frames,
        spec.viewpoints.join(", "),
        match spec.cameras {
            Cameras::Path => "frames follow each viewpoint's path".to_string(),
            Cameras::Random { seed } => format!(
                "each frame's camera an independent draw from its viewpoint's cameras, seed {seed}, so every interval over frames is the exact order-statistic interval of a median"
            ),
        },
        spec.width,
        spec.height,
        spec.shadings.iter().map(|s| s.0.name()).collect::<Vec<_>>().join(", "),
        spec.header.schedule.repeats,
        spec.header.schedule.seed,
        spec.header.schedule.warmup,
        spec.motion.as_ref().map_or(String::new(), |m| format!(
            " Before each frame the part `{}` moves by {:?} m and each structure is brought up to date in every way it offers ({}); an update changes the structure, so each is timed once per frame and its interval comes from the frames.",
            m.part,
            m.step.to_array(),
            labels(rows).join(", ")
        ))
    );
    md += &match spec.generator {
        Generator::RandomTriangles { .. } => format!("Random triangles: {}.\n\n", random::DISTRIBUTION),
        Generator::Classroom => "The classroom (src/scene/procedural/classroom.rs): a 10 x 8 x 3.2 m room with tessellated walls, floor and ceiling, four windows, a blackboard, 20 desks with chairs, a teacher's desk, two bookshelves of books, four ceiling lamps over four point lights, two wall mirrors (weight 0.85) and a chrome ball (0.7); the camera walks one loop round the desks.\n\n".to_string(),
    };
    md += &tuning_paragraph(spec, outcome);
    md += "## Verdict\n\n";
    md += &verdict(spec, outcome);
    md += &format!("\n## Medians\n\nFrame seconds: the median over the frames with its 95 % interval ({}); rays, nodes visited and primitive tests: per-frame medians (deterministic).\n\n| triangles | shading | structure | frame s | update s | rays per frame | nodes per frame | tests per frame | frames |\n|---|---|---|---|---|---|---|---|---|\n",
        match spec.cameras {
            Cameras::Random { .. } => "order statistics over independent frames",
            Cameras::Path => "from the medians of blocks of consecutive frames, block length in `summary.csv`; n/a where the path is too short or too correlated for six blocks",
        });
    let summaries = summarise(spec, outcome);
    for r in &summaries {
        md += &format!(
            "| {} | {} | {} | {} | {} | {:.0} | {} | {} | {} |\n",
            r.triangles,
            r.shading,
            r.structure,
            r.frame.show(4),
            if r.update.median.is_nan() {
                "-".into()
            } else {
                r.update.show(4)
            },
            r.rays,
            count(r.nodes_visited),
            count(r.primitive_tests),
            r.frames
        );
    }
    let sizes: Vec<usize> = summaries.iter().map(|r| r.triangles).fold(Vec::new(), |mut v, t| {
        if !v.contains(&t) {
            v.push(t);
        }
        v
    });
    md += "\n## Builds\n\n| triangles | structure | parameters | build s | MB | bytes per triangle |\n|---|---|---|---|---|---|\n";
    for b in &outcome.builds {
        md += &format!(
            "| {} | {} | {} | {:.3} | {:.1} | {} |\n",
            b.triangles,
            b.structure,
            b.settings.describe(),
            b.build_seconds,
            b.memory_bytes as f64 / 1e6,
            crate::output::numbers::per_triangle(b.memory_bytes, b.triangles)
        );
    }
    md += "\nOutputs: `frames.csv` (one row per frame and structure), `rounds.csv` (every timed render, in round order), `summary.csv` (the medians above), `builds.csv`, `tuning.csv` and `tuning_rounds.csv` (where a structure was tuned), `plots/frame_time_SHADING.png` (render time along the path, largest scene, first viewpoint)";
    if spec.motion.is_some() {
        md += ", `plots/update_time_SHADING.png` (update time along the path)";
    }
    if sizes.len() > 1 {
        md += ", `plots/scaling_SHADING.png`, `plots/memory.png`, `plots/build_time.png` (log-log against triangle count)";
    }
    md += ", `images/strip_SHADING.png` (frames along the path, first structure; each frame also as `images/strip_SHADING_FRAME.exr` and `.png`), `index.html` (the comparison page).\n";
    md
}
