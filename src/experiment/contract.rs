//! The contract every kind implements ([`Experiment`]): what the driver asks of a kind (its
//! header, what it accepts, its inputs, its dry run, its run) and what it hands the kind while it
//! runs ([`RunContext`]) and back when it ends ([`Finished`]).

use super::cli::Cli;
use super::header::Header;
use super::outputs::Outputs;
use super::progress::Progress;
use crate::render::Backend;
use std::path::{Path, PathBuf};

/// What a kind accepts beyond the shared command line (every kind takes `--filter`, `--shard`
/// and `--merge`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Accepts {
    /// Whether it runs on the GPU; a kind that does not times the f64 CPU backend, where every
    /// structure is exact, and refuses `--backend gpu`.
    pub gpu: bool,
    /// The backend where neither the file nor the command line names one.
    pub backend: crate::render::BackendChoice,
}

/// Everything a kind's run may use.
pub struct RunContext<'a> {
    /// The device.
    pub backend: &'a mut dyn Backend,
    /// The command line.
    pub cli: &'a Cli,
    /// The results folder, where state that outlives a run stays (a sweep's journal, its
    /// ground-truth cache, shards); never the outputs themselves.
    pub home: &'a Path,
    /// Where this run's outputs go, swapped in as one set when the run succeeds.
    pub out: &'a Outputs,
    /// Progress bars or, off a terminal, timestamped log lines.
    pub progress: &'a Progress,
    /// When the run started (reports state its length).
    pub started: std::time::Instant,
}

/// How a run ended.
pub enum Finished {
    /// The outputs are written; `details` is the kind's table in the manifest; `failed` names
    /// runs that failed and where their errors are (exit status 3).
    Results {
        /// The kind's part of the manifest.
        details: toml::Table,
        /// Failed runs and the file whose rows say why.
        failed: Option<(usize, String)>,
    },
    /// A share of an experiment, written into its own folder; no result set to swap in.
    Shard {
        /// Failed runs and the file whose rows say why.
        failed: Option<(usize, String)>,
    },
}

/// An experiment of any kind, read from its file.
pub trait Experiment {
    /// The shared keys.
    fn header(&self) -> &Header;

    /// What it accepts beyond the shared command line.
    fn accepts(&self) -> Accepts;

    /// Every file it read (experiment, scenes, meshes), hashed into the manifest.
    fn inputs(&self) -> Vec<PathBuf>;

    /// What of it the GPU cannot run (a structure without a GPU form), located at its file and
    /// key; the driver asks before it chooses a
    /// backend. Kinds that render on the CPU only say nothing.
    fn gpu_gap(&self) -> Option<String> {
        None
    }

    /// What `--dry-run` prints: every unit and its render plan.
    fn dry_run(&self, cli: &Cli) -> anyhow::Result<String>;

    /// The results folder's name under `results/` (a sweep run with filters appends them).
    fn folder(&self, _cli: &Cli) -> anyhow::Result<String> {
        Ok(self.header().name.clone())
    }

    /// Runs and writes the outputs into `run.out`.
    fn run(&self, run: &mut RunContext) -> anyhow::Result<Finished>;
}

/// What of `scene`, read from `path`, the GPU cannot run: its structure without a GPU form
/// ([`crate::accel::Accelerator::gpu_refusal`]), at the scene's key. Every pass of the render
/// plan has a GPU kernel.
pub(crate) fn scene_gpu_gap(path: &Path, scene: &crate::scene::Scene) -> Option<String> {
    let refusal = scene.accel.as_ref()?.gpu_refusal()?;
    Some(format!("{}: key `accelerator`: {refusal}", path.display()))
}
