//! Frame-time experiments (`kind = "frames"`): the visibility-field paper's scaling (Fig. 5),
//! walkthrough (Fig. 6) and dynamic-scene claims, measured per acceleration structure.
//!
//! Declared on the experiment core: axes scene x shading x viewpoint; a unit is a block of
//! frames of one scene ([`runner::Block`]), every structure timed in the same interleaved rounds
//! on one machine, so per-frame ratios stay paired.

pub mod cameras;
pub mod candidates;
pub mod memory;
pub mod motion;
pub mod report;
pub mod runner;
pub mod scenes;
pub mod spec;
pub mod tuning;
pub mod verdict;

pub use runner::{run_block, run_frames, Block, FramesOutcome};
pub use spec::{FramesSpec, Generator};

use crate::experiment::contract::RunContext;
use crate::experiment::core::filter::{keep_at, Axis};
use crate::experiment::core::{Cost, Declaration, Unit};
use crate::experiment::header::Header;
use crate::experiment::progress::Progress;
use crate::experiment::tuning::KeptTuning;
use crate::render::Backend;
use std::path::{Path, PathBuf};

impl FramesSpec {
    /// The scenes as the `scene` axis names them: `classroom`, or each triangle count.
    pub fn scene_names(&self) -> Vec<String> {
        match &self.generator {
            Generator::Classroom => vec!["classroom".into()],
            Generator::RandomTriangles { counts, .. } => counts.iter().map(usize::to_string).collect(),
        }
    }

    /// Triangles of scene `i`, known before it is generated (random triangles; the classroom is
    /// one scene, so its blocks compare by their frames alone).
    fn triangles_of(&self, i: usize) -> Option<usize> {
        match &self.generator {
            Generator::Classroom => None,
            Generator::RandomTriangles { counts, .. } => Some(counts[i]),
        }
    }
}

crate::axis_keys! {
    /// The frame-time experiments' axes.
    pub enum FramesAxis {
        /// A generated scene (its triangle count, or the classroom).
        Scene => "scene",
        /// Shading (OpenGL-like, Whitted).
        Shading => "shading",
        /// A camera path or viewpoint.
        Viewpoint => "viewpoint",
    }
}

impl Declaration for FramesSpec {
    type Outcome = FramesOutcome;

    fn header(&self) -> &Header {
        &self.header
    }

    fn locate(&self, e: anyhow::Error) -> anyhow::Error {
        self.places.locate(e)
    }

    fn inputs(&self) -> Vec<PathBuf> {
        let mut v = vec![self.path.clone()];
        v.extend(self.reused.iter().map(|k| k.path.clone()));
        v
    }

    fn reuse_tuning(&mut self, path: &Path) -> Result<(), String> {
        let kept = KeptTuning::read(path, "scene")?;
        for scene in self.scene_names() {
            kept.check(self.candidates.iter().map(|c| (scene.as_str(), c.as_slice())))?;
        }
        self.reused = Some(kept);
        Ok(())
    }

    type Axis = FramesAxis;

    fn axes(&self) -> Vec<Axis<FramesAxis>> {
        vec![
            Axis::of(FramesAxis::Scene, self.scene_names()),
            Axis::of(
                FramesAxis::Shading,
                self.shadings.iter().map(|(n, _)| n.name().to_string()),
            ),
            Axis::of(FramesAxis::Viewpoint, self.viewpoints.clone()),
        ]
    }

    fn restrict(&mut self, axis: FramesAxis, keep: &[usize]) {
        match axis {
            FramesAxis::Scene => {
                if let Generator::RandomTriangles { counts, .. } = &mut self.generator {
                    keep_at(counts, keep);
                }
            }
            FramesAxis::Shading => keep_at(&mut self.shadings, keep),
            FramesAxis::Viewpoint => keep_at(&mut self.viewpoints, keep),
        }
    }

    fn units(&self) -> Vec<Unit> {
        let pixels = (self.width * self.height) as f64;
        runner::blocks(self)
            .into_iter()
            .map(|b| {
                let label = b.label(self);
                let frames = (b.shadings.len() * b.viewpoints.len()) as f64 * b.frames.len() as f64;
                let n = self.triangles_of(b.scene).map_or(1.0, |n| n as f64);
                let repeats = self.header.schedule.repeats.max(1) as f64;
                let structures = self.structures.len() as f64;
                // Tuning (only ever in a scene's one unit: blocks refuse candidates): each
                // candidate built, rendered once for its work and once per round.
                let tuning_renders =
                    (1 + self.tuning.repeats) as f64 * self.tuning.cameras as f64 * self.viewpoints.len() as f64;
                let candidates: f64 = self
                    .candidates
                    .iter()
                    .filter(|c| c.len() > 1)
                    .map(|c| c.len() as f64 * (tuning_renders * pixels + n))
                    .sum();
                Unit {
                    at: b.at(),
                    cost: Cost {
                        // Renders (rays times a logarithmic walk) and builds (n log n).
                        work: (structures * (frames * repeats * pixels + n) + candidates) * n.ln().max(1.0),
                        setup: None,
                        tie: label.clone(),
                    },
                    label,
                }
            })
            .collect()
    }

    fn plan(&self, units: &[Unit]) -> anyhow::Result<String> {
        let mut out = String::new();
        let mut scenes: Vec<usize> = units.iter().map(|u| Block::of(&u.at).scene).collect();
        scenes.dedup();
        for (_, g) in self.scenes().enumerate().filter(|(i, _)| scenes.contains(i)) {
            out += &format!(
                "{}: [{}] x {} shadings x {} viewpoints x {} frames at {}x{}, {} timed renders each{}\n",
                g.description,
                self.structures.iter().map(|s| s.name).collect::<Vec<_>>().join(", "),
                self.shadings.len(),
                self.viewpoints.len(),
                self.frames,
                self.width,
                self.height,
                self.header.schedule.repeats,
                self.motion
                    .as_ref()
                    .map_or(String::new(), |m| format!(", `{}` moving", m.part))
            );
        }
        Ok(out)
    }

    /// On the GPU when asked (`backend = "gpu"` or `--backend gpu`); the f64 CPU backend, where
    /// every structure answers exactly, by default.
    fn gpu(&self) -> bool {
        true
    }

    fn gpu_gap(&self) -> Option<String> {
        self.places.gpu_gap(self.structures.iter().map(|s| s.name))
    }

    fn backend(&self) -> crate::render::BackendChoice {
        crate::render::BackendChoice::Cpu
    }

    fn measure(&self, unit: &Unit, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<FramesOutcome> {
        backend.count_work(true);
        run_block(self, &Block::of(&unit.at), backend, progress)
    }

    fn report(&self, outcomes: Vec<FramesOutcome>, run: &mut RunContext) -> anyhow::Result<toml::Table> {
        let mut outcome = FramesOutcome::default();
        for o in outcomes {
            outcome.frames.extend(o.frames);
            outcome.builds.extend(o.builds);
            outcome.pictures.extend(o.pictures);
            outcome.scenes.extend(o.scenes);
            outcome.tuning.extend(o.tuning);
        }
        report::write_frames(
            self,
            &outcome,
            run.backend.adapter(),
            run.started.elapsed().as_secs_f64(),
            run.out.dir(),
        )?;
        tracing::info!("{} frames", outcome.frames.len());
        let mut details = toml::Table::new();
        details.insert("frames".into(), (outcome.frames.len() as i64).into());
        details.insert(
            "scenes".into(),
            toml::Value::Array(outcome.scenes.iter().map(|s| s.clone().into()).collect()),
        );
        Ok(details)
    }
}
