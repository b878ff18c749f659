//! Frame-rate experiments (`kind = "fps"`): the soft-shadow paper's Table 1 (frames per second,
//! 16 shadow rays per pixel, sphere and dressed body, one and two lights) on today's adapter,
//! with the paper's numbers beside ours.

pub mod report;
pub mod runner;
pub mod spec;

pub use runner::{run_fps, FpsRow};
pub use spec::{timed_scene, FpsScene, FpsSpec};

use crate::experiment::cli::Cli;
use crate::experiment::header::Header;
use crate::experiment::{Accepts, Experiment, Finished, Run};
use std::path::PathBuf;

impl Experiment for FpsSpec {
    fn header(&self) -> &Header {
        &self.header
    }

    fn accepts(&self) -> Accepts {
        Accepts {
            subsets: false,
            gpu: true,
        }
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
            .find_map(|(path, s)| crate::experiment::scene_gpu_gap(path, &s.scene))
    }

    fn dry_run(&self, _cli: &Cli) -> anyhow::Result<String> {
        runner::dry_run(self)
    }

    fn run(&self, run: &mut Run) -> anyhow::Result<Finished> {
        let rows = run_fps(self, run.backend, run.progress)?;
        let adapter = run.backend.adapter().clone();
        report::write_fps(
            self,
            &rows,
            &adapter,
            run.started.elapsed().as_secs_f64(),
            run.out.dir(),
        )?;
        tracing::info!("{} configurations timed", rows.len());
        let mut details = toml::Table::new();
        details.insert("configurations".into(), (rows.len() as i64).into());
        Ok(Finished::Results { details, failed: None })
    }
}
