//! The sweep as an experiment kind: a whole sweep, a shard's share of it (`--shard`), or the
//! merge of finished shards (`--merge`), then the figures and the outputs.

use super::merge::{merge_shards, MergePlan};
use super::pictures::render_pictures;
use super::report::{write_all, Results};
use super::run::expand;
use super::runner::{dry_run, run_sweep, verdict_radius};
use super::shard::{self, run_shard};
use super::Spec;
use crate::experiment::cli::{BadInput, Cli};
use crate::experiment::core::filter;
use crate::experiment::core::merge::{rerun_command, shard_dirs};
use crate::experiment::header::Header;
use crate::experiment::{Accepts, Experiment, Finished, RunContext};
use anyhow::Context;
use std::path::PathBuf;
use tracing::info;

impl Spec {
    /// This sweep restricted by the command line's filters.
    fn for_cli(&self, cli: &Cli) -> anyhow::Result<Spec> {
        Ok(self.clone().filtered(&cli.filter).map_err(BadInput)?)
    }
}

impl Experiment for Spec {
    fn header(&self) -> &Header {
        &self.header
    }

    fn accepts(&self) -> Accepts {
        Accepts {
            gpu: true,
            backend: crate::render::BackendChoice::Auto,
        }
    }

    fn inputs(&self) -> Vec<PathBuf> {
        let mut v = vec![self.path.clone(), self.scene_path.clone()];
        v.extend(self.scene.meshes().map(|m| PathBuf::from(&m.source)));
        v.extend(self.points_files());
        v
    }

    fn gpu_gap(&self) -> Option<String> {
        if let Some(gap) = crate::experiment::scene_gpu_gap(&self.scene_path, &self.scene) {
            return Some(gap);
        }
        self.axes.accelerators.iter().enumerate().find_map(|(i, name)| {
            let refusal = self.structures.get(name)?.as_ref()?.gpu_refusal()?;
            Some(if *name == self.scene.accel_settings.name {
                format!("{}: key `accelerator`: {refusal}", self.scene_path.display())
            } else {
                format!("{}: key `sweep.accelerators[{i}]`: {refusal}", self.path.display())
            })
        })
    }

    fn dry_run(&self, cli: &Cli) -> anyhow::Result<String> {
        let spec = self.for_cli(cli)?;
        Ok(match cli.shard {
            Some(s) => shard::dry_run(&spec, s),
            None => dry_run(&spec)?,
        })
    }

    fn folder(&self, cli: &Cli) -> anyhow::Result<String> {
        self.for_cli(cli)?;
        Ok(match cli.filter.as_slice() {
            [] => self.name.clone(),
            f => format!("{}--{}", self.name, filter::label(f)),
        })
    }

    fn run(&self, run: &mut RunContext) -> anyhow::Result<Finished> {
        let spec = self.for_cli(run.cli)?;
        let cli = run.cli;
        info!("{} runs", expand(&spec).iter().map(|g| g.runs.len()).sum::<usize>());
        if let Some(s) = cli.shard {
            let done = run_shard(&spec, run.backend, s, run.home, cli.fresh, run.progress)?;
            let m = &done.manifest;
            info!(
                "shard {s}: {} runs ({} failed, {} groups resumed) in {:.1} s; wrote {}",
                m.runs,
                m.failed,
                m.resumed,
                m.seconds,
                done.dir.display()
            );
            let table = done.dir.join(shard::RECORDS).display().to_string();
            return Ok(Finished::Shard {
                failed: Some((m.failed, table)),
            });
        }
        let outcome = if cli.merge.is_empty() {
            run_sweep(
                &spec,
                run.backend,
                &run.home.join(".journal"),
                &run.home.join("cache"),
                cli.fresh,
                run.progress,
            )?
        } else {
            let (dirs, split) = shard_dirs(&cli.merge, run.home)?;
            let plan = MergePlan {
                dirs: &dirs,
                split,
                rerun: &rerun_command(cli),
                fresh: cli.fresh,
            };
            merge_shards(&spec, run.backend, &plan, run.home, run.progress)?
        };
        info!("render plan of a run:\n{}", outcome.plan);
        let pictures =
            render_pictures(&spec, run.backend, verdict_radius(&spec)).context("rendering the figures' pictures")?;
        let adapter = run.backend.adapter().clone();
        let results = Results {
            spec: &spec,
            outcome: &outcome,
            pictures: pictures.as_ref(),
            adapter: &adapter,
            seconds: run.started.elapsed().as_secs_f64(),
        };
        write_all(&results, run.out)?;
        info!(
            "{} runs ({} failed, {} groups resumed)",
            outcome.records.len(),
            outcome.failures,
            outcome.resumed
        );
        Ok(Finished::Results {
            details: super::report::manifest::details(&results),
            failed: Some((outcome.failures, run.home.join("runs.csv").display().to_string())),
        })
    }
}
