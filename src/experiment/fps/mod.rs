//! Frame-rate experiments (`kind = "fps"`): the soft-shadow paper's Table 1 (frames per second,
//! 16 shadow rays per pixel, sphere and dressed body, one and two lights) on today's adapter,
//! with the paper's numbers beside ours.
//!
//! Declared on the experiment core: axes scene x lights x resolution; a unit is one scene with
//! its light counts and resolutions, timed together in one schedule.

pub mod report;
pub mod runner;
pub mod spec;

pub use runner::{run_fps, run_scenes, FpsRow};
pub use spec::{timed_scene, FpsScene, FpsSpec};

use crate::experiment::contract::RunContext;
use crate::experiment::core::filter::{keep_at, Axis};
use crate::experiment::core::{Cost, Declaration, Unit};
use crate::experiment::header::Header;
use crate::experiment::progress::Progress;
use crate::render::Backend;
use std::path::PathBuf;

impl FpsSpec {
    /// Every light count some scene times, ascending.
    fn light_counts(&self) -> Vec<u32> {
        let mut all: Vec<u32> = self.scenes.iter().flat_map(|s| s.lights.iter().copied()).collect();
        all.sort_unstable();
        all.dedup();
        all
    }
}

crate::axis_keys! {
    /// The frame-rate table's axes.
    pub enum FpsAxis {
        /// A scene of the paper's Table 1.
        Scene => "scene",
        /// Lights on.
        Lights => "lights",
        /// Output resolution.
        Resolution => "resolution",
    }
}

impl Declaration for FpsSpec {
    type Outcome = Vec<FpsRow>;

    fn header(&self) -> &Header {
        &self.header
    }

    fn locate(&self, e: anyhow::Error) -> anyhow::Error {
        self.places.locate(e)
    }

    fn gpu(&self) -> bool {
        true
    }

    fn inputs(&self) -> Vec<PathBuf> {
        let mut v = vec![self.path.clone()];
        v.extend(self.scene_paths.iter().cloned());
        for s in &self.scenes {
            v.extend(s.scene.meshes().map(|m| PathBuf::from(&m.source)));
        }
        v.dedup();
        v
    }

    fn gpu_gap(&self) -> Option<String> {
        self.scene_paths
            .iter()
            .zip(&self.scenes)
            .find_map(|(path, s)| crate::experiment::contract::scene_gpu_gap(path, &s.scene))
    }

    type Axis = FpsAxis;

    fn axes(&self) -> Vec<Axis<FpsAxis>> {
        vec![
            Axis::of(FpsAxis::Scene, self.scenes.iter().map(|s| s.name.clone())),
            Axis::of(FpsAxis::Lights, self.light_counts().iter().map(u32::to_string)),
            Axis::of(
                FpsAxis::Resolution,
                self.resolutions.iter().map(|[w, h]| format!("{w}x{h}")),
            ),
        ]
    }

    fn restrict(&mut self, axis: FpsAxis, keep: &[usize]) {
        match axis {
            FpsAxis::Scene => {
                keep_at(&mut self.scenes, keep);
                keep_at(&mut self.scene_paths, keep);
            }
            FpsAxis::Lights => {
                let counts = self.light_counts();
                let kept: Vec<u32> = keep.iter().map(|&i| counts[i]).collect();
                for s in &mut self.scenes {
                    let at: Vec<usize> = (0..s.lights.len()).filter(|&i| kept.contains(&s.lights[i])).collect();
                    keep_at(&mut s.lights, &at);
                    keep_at(&mut s.paper_fps, &at);
                }
                let with: Vec<usize> = (0..self.scenes.len())
                    .filter(|&i| !self.scenes[i].lights.is_empty())
                    .collect();
                keep_at(&mut self.scenes, &with);
                keep_at(&mut self.scene_paths, &with);
            }
            FpsAxis::Resolution => keep_at(&mut self.resolutions, keep),
        }
    }

    fn units(&self) -> Vec<Unit> {
        self.scenes
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let label = format!("scene={}", s.name);
                let pixels: f64 = self.resolutions.iter().map(|[w, h]| (w * h) as f64).sum();
                let lights: u32 = s.lights.iter().sum();
                Unit {
                    at: vec![i],
                    cost: Cost {
                        work: pixels * (1 + lights * self.samples) as f64,
                        setup: None,
                        tie: label.clone(),
                    },
                    label,
                }
            })
            .collect()
    }

    fn plan(&self, units: &[Unit]) -> anyhow::Result<String> {
        let which: Vec<usize> = units.iter().map(|u| u.at[0]).collect();
        runner::dry_run(self, &which)
    }

    fn measure(&self, unit: &Unit, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<Vec<FpsRow>> {
        run_scenes(self, &unit.at, backend, progress)
    }

    fn report(&self, outcomes: Vec<Vec<FpsRow>>, run: &mut RunContext) -> anyhow::Result<toml::Table> {
        let rows: Vec<FpsRow> = outcomes.into_iter().flatten().collect();
        report::write_fps(
            self,
            &rows,
            &run.backend.adapter().clone(),
            run.started.elapsed().as_secs_f64(),
            run.out.dir(),
        )?;
        tracing::info!("{} configurations timed", rows.len());
        let mut details = toml::Table::new();
        details.insert("configurations".into(), (rows.len() as i64).into());
        Ok(details)
    }
}
