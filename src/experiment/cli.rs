//! The `sweep` command line, shared by every kind, and the errors that choose its exit status.

use super::args::{Filter, Shard, FILTER_HELP};
use crate::render::BackendChoice;
use std::path::PathBuf;

/// `--version`: the package version, the commit the binary was built from and whether that
/// checkout was clean, as every manifest records them; scripts/regenerate.sh compares them
/// with HEAD before running anything.
const BUILD: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (",
    env!("PENUMBRA_COMMIT"),
    ", clean = ",
    env!("PENUMBRA_CLEAN"),
    ")"
);

/// Exit statuses, stated in `--help`.
pub const AFTER_HELP: &str = "Exit status: 0 when every run rendered and the results are written; 2 for bad \
input (the experiment or scene file, a mesh, a command-line value, an output folder that holds something \
else), before any work; 3 when some runs failed (their rows say why; the results, or the shard, are \
written); 4 when --merge is refused (a shard missing, unfinished, duplicated or from another sweep, build \
or device: the message lists the runs and the shards to rerun; nothing is written); 1 for any other error \
(no GPU where one was required, a device lost, a file that could not be written). Outputs are written into \
a staging folder beside the results folder and swapped in only when the run finishes, so a failed or \
killed run leaves the earlier results whole. Logging: -v and -q raise and lower the level; RUST_LOG \
(e.g. RUST_LOG=penumbra=debug) overrides both; off a terminal, log lines and progress carry timestamps.

An experiment too big for one machine (any kind): run `--shard K/N` for K = 1..N (anywhere that shares \
the results folder, or copy the shard folders and cache/ back), then `--merge RESULTS/shards/*-of-N` on \
the same kind of device with the same binary; scripts/slurm/sweep.sbatch and scripts/parallel.sh do both.";

/// Runs an experiment file of any kind (sweep, fps, ao, frames) and writes its results folder.
#[derive(clap::Parser, Debug, Clone)]
#[command(name = "sweep", version = BUILD, after_help = AFTER_HELP)]
pub struct Cli {
    /// Experiment file, e.g. experiments/sphere.toml.
    pub experiment: PathBuf,
    /// Results folder (default: results/NAME, NAME from the experiment file; with --filter,
    /// results/NAME--FILTERS, so a subset never replaces the whole sweep's results).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Redo every unit, reading nothing from the journal (a run that succeeds drops the units it
    /// did not write; one that fails leaves the journal as it was); replace a results folder
    /// that holds another experiment's results.
    #[arg(long)]
    pub fresh: bool,
    /// Override the experiment's backend.
    #[arg(long, value_enum)]
    pub backend: Option<BackendChoice>,
    /// Print the axes, the units of work and the render plan, then exit without rendering.
    #[arg(long)]
    pub dry_run: bool,
    /// Run only the K-th of N deterministic shares of the experiment's units (dealt by expected
    /// work) into RESULTS/shards/K-of-N/, from which a killed shard resumes; no final outputs.
    #[arg(long, value_name = "K/N", conflicts_with = "merge")]
    pub shard: Option<Shard>,
    /// Merge finished shards into the results, checking that every unit is present exactly once:
    /// N merges RESULTS/shards/1-of-N .. N-of-N, or name shard folders. Nothing is measured
    /// again: times and pictures were taken inside the shards' units.
    #[arg(long, value_name = "N|SHARD_DIR", num_args = 1..)]
    pub merge: Vec<PathBuf>,
    /// Build each structure an ao or frames experiment tunes at the setting an earlier run kept
    /// (its results folder's tuning.csv) instead of timing the candidates again, so that shards,
    /// reruns and other hosts count the same work; give it to every shard and to the merge.
    /// Structures the file keeps nothing for are tuned as usual.
    #[arg(long, value_name = "TUNING_CSV")]
    pub tuning: Option<PathBuf>,
    /// Subset filters; the help text names the axes from the axis list.
    #[arg(long, value_name = "AXIS=VALUE", help = FILTER_HELP)]
    pub filter: Vec<Filter>,
    /// More log output (repeatable).
    #[arg(short, long, action = clap::ArgAction::Count)]
    pub verbose: u8,
    /// Less log output (repeatable).
    #[arg(short, long, action = clap::ArgAction::Count, conflicts_with = "verbose")]
    pub quiet: u8,
}

impl Cli {
    /// A command line running `experiment` with nothing else set (library callers, tests).
    pub fn plain(experiment: impl Into<PathBuf>) -> Cli {
        Cli {
            experiment: experiment.into(),
            out: None,
            fresh: false,
            backend: None,
            dry_run: false,
            shard: None,
            merge: Vec::new(),
            tuning: None,
            filter: Vec::new(),
            verbose: 0,
            quiet: 0,
        }
    }
}

/// Bad input: exit status 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

/// Some runs failed: exit status 3. The text says where their errors are.
#[derive(Debug, thiserror::Error)]
#[error("{0} runs failed; {1}")]
pub struct RunsFailed(pub usize, pub String);

/// Standard output could not take what a command prints (a reader that closed its pipe, a full
/// disk): the command ends with status 1 instead of a panic, quietly where the reader went away
/// (`sweep --dry-run ... | head -1`).
#[derive(Debug, thiserror::Error)]
#[error("writing to standard output: {0}")]
pub struct StdoutFailed(pub std::io::Error);

/// Prints `text` on standard output and flushes it; a failure there is returned, not a panic.
pub fn print_out(text: &str) -> Result<(), StdoutFailed> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(StdoutFailed)
}

/// How every command ends: the error, if any, reported ([`report_error`]) and the exit status
/// its kind calls for ([`crate::experiment::driver::exit_status`]: 2 for bad input).
pub fn finish(result: anyhow::Result<()>) -> std::process::ExitCode {
    if let Err(e) = &result {
        report_error(e);
    }
    crate::experiment::driver::exit_status(&result)
}

/// Prints the error a command ends on to standard error where it can still be written there
/// (a full or closed standard error loses the message, never the exit status), except a closed
/// standard output, whose reader asked for no more.
pub fn report_error(e: &anyhow::Error) {
    use std::io::Write;
    let reader_gone = e
        .downcast_ref::<StdoutFailed>()
        .is_some_and(|s| s.0.kind() == std::io::ErrorKind::BrokenPipe);
    if !reader_gone {
        let _ = writeln!(std::io::stderr(), "error: {e:#}");
    }
}
