//! Ambient-occlusion experiments (`kind = "ao"`): the visibility-field paper's Table 1 (513 AO
//! rays per camera hit, 256 x 256) timed for each acceleration structure at its best settings
//! on the same meshes, with the paper's numbers beside ours and a verdict on its claim that
//! VLF-RT beats a CRT kd-tree (by 1.45-2.51x), and on how it fares against a modern BVH.
//!
//! Declared on the experiment core: axes mesh x structure x issue; a unit is one mesh with all
//! its structures, so a mesh's tuning and timing stay on one machine.

pub mod report;
pub mod runner;
pub mod spec;

pub use runner::{run_ao, run_mesh, AoRow, MeshOutcome, TuningRow};
pub use spec::AoSpec;

use crate::experiment::contract::RunContext;
use crate::experiment::core::filter::{keep_at, Axis};
use crate::experiment::core::{Cost, Declaration, Unit};
use crate::experiment::header::Header;
use crate::experiment::progress::Progress;
use crate::experiment::tuning::KeptTuning;
use crate::render::Backend;
use std::path::{Path, PathBuf};

crate::axis_keys! {
    /// The ambient-occlusion table's axes.
    pub enum AoAxis {
        /// A mesh.
        Mesh => "mesh",
        /// An acceleration structure.
        Structure => "structure",
        /// How rays are issued (single or bundled).
        Issue => "issue",
    }
}

impl Declaration for AoSpec {
    type Outcome = MeshOutcome;

    fn header(&self) -> &Header {
        &self.header
    }

    fn locate(&self, e: anyhow::Error) -> anyhow::Error {
        self.places.locate(e)
    }

    fn inputs(&self) -> Vec<PathBuf> {
        let mut v = vec![self.path.clone()];
        v.extend(self.meshes.iter().map(|m| m.path.clone()));
        v.extend(self.reused.iter().map(|k| k.path.clone()));
        v.dedup();
        v
    }

    fn reuse_tuning(&mut self, path: &Path) -> Result<(), String> {
        let kept = KeptTuning::read(path, "mesh")?;
        for mesh in &self.meshes {
            kept.check(self.structures.iter().map(|(_, c)| (mesh.name.as_str(), c.as_slice())))?;
        }
        self.reused = Some(kept);
        Ok(())
    }

    type Axis = AoAxis;

    fn axes(&self) -> Vec<Axis<AoAxis>> {
        vec![
            Axis::of(AoAxis::Mesh, self.meshes.iter().map(|m| m.name.clone())),
            Axis::of(AoAxis::Structure, self.structures.iter().map(|(s, _)| s.to_string())),
            Axis::of(AoAxis::Issue, self.issues.iter().map(|i| i.name().to_string())),
        ]
    }

    fn restrict(&mut self, axis: AoAxis, keep: &[usize]) {
        match axis {
            AoAxis::Mesh => keep_at(&mut self.meshes, keep),
            AoAxis::Structure => keep_at(&mut self.structures, keep),
            AoAxis::Issue => keep_at(&mut self.issues, keep),
        }
    }

    fn units(&self) -> Vec<Unit> {
        self.meshes
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let label = format!("mesh={}", m.name);
                // Rays per frame, every structure and issue: the timed rounds dominate.
                let rays = (self.width * self.height) as f64 * (1 + self.ao.rays) as f64;
                let work = rays
                    * (self.structures.len() * self.issues.len()) as f64
                    * (m.triangles.positions.len() as f64).ln().max(1.0);
                Unit {
                    at: vec![i],
                    cost: Cost {
                        work,
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
        for m in units.iter().map(|u| &self.meshes[u.at[0]]) {
            let structures: Vec<String> = self
                .structures
                .iter()
                .map(|(s, c)| format!("{s} ({} candidates)", c.len()))
                .collect();
            out += &format!(
                "{}: {} triangles x [{}], {}x{}, {} AO rays per hit\n",
                m.name,
                m.triangles.positions.len(),
                structures.join(", "),
                self.width,
                self.height,
                self.ao.rays
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
        self.places.gpu_gap(self.structures.iter().map(|(s, _)| *s))
    }

    fn backend(&self) -> crate::render::BackendChoice {
        crate::render::BackendChoice::Cpu
    }

    fn measure(&self, unit: &Unit, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<MeshOutcome> {
        backend.count_work(true);
        run_mesh(self, &self.meshes[unit.at[0]], backend, progress)
    }

    fn report(&self, outcomes: Vec<MeshOutcome>, run: &mut RunContext) -> anyhow::Result<toml::Table> {
        let (mut rows, mut tuning) = (Vec::new(), Vec::new());
        for o in outcomes {
            rows.extend(o.rows);
            tuning.extend(o.tuning);
        }
        let seconds = run.started.elapsed().as_secs_f64();
        report::write_ao(self, (&rows, &tuning), run.backend.adapter(), seconds, run.out)?;
        tracing::info!("{} rows", rows.len());
        let mut details = toml::Table::new();
        details.insert("rows".into(), (rows.len() as i64).into());
        details.insert("tuning_repeats".into(), (self.tuning.repeats as i64).into());
        Ok(details)
    }
}
