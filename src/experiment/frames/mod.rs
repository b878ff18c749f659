//! Frame-time experiments (`kind = "frames"`): the visibility-field paper's scaling (Fig. 5),
//! walkthrough (Fig. 6) and dynamic-scene claims, measured per acceleration structure.

pub mod report;
pub mod runner;
pub mod spec;
pub mod verdict;

pub use runner::run_frames;
pub use spec::FramesSpec;

use crate::experiment::cli::Cli;
use crate::experiment::header::Header;
use crate::experiment::{Accepts, Experiment, Finished, Run};
use std::path::PathBuf;

impl Experiment for FramesSpec {
    fn header(&self) -> &Header {
        &self.header
    }

    fn accepts(&self) -> Accepts {
        Accepts {
            subsets: false,
            gpu: false,
        }
    }

    fn inputs(&self) -> Vec<PathBuf> {
        vec![self.path.clone()]
    }

    fn dry_run(&self, _cli: &Cli) -> anyhow::Result<String> {
        let mut out = String::new();
        for g in self.scenes() {
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

    fn run(&self, run: &mut Run) -> anyhow::Result<Finished> {
        let outcome = run_frames(self, run.backend, run.progress)?;
        let threads = rayon::current_num_threads();
        report::write_frames(
            self,
            &outcome,
            threads,
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
        Ok(Finished::Results { details, failed: None })
    }
}
