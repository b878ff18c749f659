//! `sweep EXPERIMENT.toml`: runs an experiment's sweep and writes its results folder.

use anyhow::Context;
use clap::{Parser, ValueEnum};
use penumbra::config::ConfigError;
use penumbra::experiment::ao::{self, run_ao, AoSpec};
use penumbra::experiment::fps::{self, FpsSpec};
use penumbra::experiment::frames::{self, FramesSpec};
use penumbra::experiment::sweep::filter::{self, Filter};
use penumbra::experiment::sweep::merge::{merge_shards, MergePlan, MergeRefused};
use penumbra::experiment::sweep::report::{write_all, Results};
use penumbra::experiment::sweep::run::expand;
use penumbra::experiment::sweep::runner::{dry_run, verdict_radius};
use penumbra::experiment::sweep::shard::{self, run_shard, Shard};
use penumbra::experiment::sweep::{pictures::render_pictures, run_sweep, Spec};
use penumbra::experiment::Experiment;
use penumbra::render::{open_backend, BackendChoice};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use tracing::info;
use tracing_subscriber::EnvFilter;

/// Exit statuses, stated in `--help`.
const AFTER_HELP: &str = "Exit status: 0 when every run rendered and the results are written; 2 for bad \
input (the experiment or scene file, an OBJ, a command-line value), before any work; 3 when some runs \
failed (their rows say why; the results, or the shard, are written); 4 when --merge is refused (a shard \
missing, unfinished, duplicated or from another sweep, build or device: the message lists the runs and \
the shards to rerun; nothing is written); 1 for any other error (no GPU where one was required, a \
device lost, a file that could not be written). Logging: -v and -q raise and lower the level; RUST_LOG \
(e.g. RUST_LOG=penumbra=debug) overrides both.

A sweep too big for one machine: run `--shard K/N` for K = 1..N (anywhere that shares the results \
folder, or copy the shard folders and cache/ back), then `--merge RESULTS/shards/*-of-N` on the same \
kind of device with the same binary; scripts/slurm/sweep.sbatch and scripts/parallel.sh do both.";

/// Sweep sampling scheme x pattern x shadow-ray count x light radius x seed, measure every run
/// against a ground truth checked against the exact answer, and write CSV, plots and a report.
#[derive(Parser)]
#[command(version, after_help = AFTER_HELP)]
struct Args {
    /// Experiment file, e.g. experiments/sphere.toml.
    experiment: PathBuf,
    /// Results folder (default: results/NAME, NAME from the experiment file; with --filter,
    /// results/NAME--FILTERS, so a subset never replaces the whole sweep's results).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Discard the journal of an interrupted sweep and redo every run.
    #[arg(long)]
    fresh: bool,
    /// Override the experiment's backend.
    #[arg(long, value_enum)]
    backend: Option<BackendChoice>,
    /// Print the expanded runs and the render plan, then exit without rendering.
    #[arg(long)]
    dry_run: bool,
    /// Run only the K-th of N deterministic shares of the runs (balanced by expected rays) into
    /// RESULTS/shards/K-of-N/, from which a killed shard resumes; no final outputs.
    #[arg(long, value_name = "K/N", conflicts_with = "merge")]
    shard: Option<Shard>,
    /// Merge finished shards into the results, checking that every run is present exactly once:
    /// N merges RESULTS/shards/1-of-N .. N-of-N, or name shard folders; times the configurations
    /// and draws the figures here.
    #[arg(long, value_name = "N|SHARD_DIR", num_args = 1..)]
    merge: Vec<PathBuf>,
    /// Subset filters; the help text names the axes from the axis list.
    #[arg(long, value_name = "AXIS=VALUE", help = filter::help())]
    filter: Vec<Filter>,
    /// More log output (repeatable).
    #[arg(short, long, action = clap::ArgAction::Count)]
    verbose: u8,
    /// Less log output (repeatable).
    #[arg(short, long, action = clap::ArgAction::Count, conflicts_with = "verbose")]
    quiet: u8,
}

/// Bad input: exit status 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
struct BadInput(String);

/// Some runs failed: exit status 3.
#[derive(Debug, thiserror::Error)]
#[error("{0} runs failed; see the `error` column of {1}")]
struct RunsFailed(usize, String);

fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kb| kb * 1024)
}

/// Loads an experiment file; its errors are bad input.
fn load<T>(load: impl FnOnce() -> Result<T, ConfigError>) -> anyhow::Result<T> {
    load().map_err(|e| BadInput(e.to_string()).into())
}

/// A frame-rate experiment (`kind = "fps"`): times configurations, no sweep.
fn run_fps_experiment(args: &Args, spec: FpsSpec, started: Instant) -> anyhow::Result<()> {
    if !args.filter.is_empty() || args.shard.is_some() || !args.merge.is_empty() {
        return Err(
            BadInput("--filter, --shard and --merge apply to sweeps, not to frame-rate experiments".into()).into(),
        );
    }
    if args.dry_run {
        print!("{}", fps::runner::dry_run(&spec)?);
        return Ok(());
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(&spec.name));
    let mut backend = open_backend(args.backend.unwrap_or(BackendChoice::Auto))?;
    let adapter = backend.adapter().clone();
    let rows = fps::run_fps(&spec, backend.as_mut())?;
    fps::report::write_fps(&spec, &rows, &adapter, started.elapsed().as_secs_f64(), &out)?;
    info!(
        "{} configurations timed; wrote {}",
        rows.len(),
        out.join("report.md").display()
    );
    Ok(())
}

fn run(args: Args) -> anyhow::Result<()> {
    let started = Instant::now();
    match load(|| Experiment::load(&args.experiment))? {
        Experiment::Sweep(spec) => run_sweep_experiment(&args, *spec, started),
        Experiment::Fps(spec) => run_fps_experiment(&args, spec, started),
        Experiment::Ao(spec) => run_ao_experiment(&args, spec, started),
        Experiment::Frames(spec) => run_frames_experiment(&args, spec, started),
    }
}

/// An ambient-occlusion experiment (`kind = "ao"`): times each structure on each mesh on the
/// f64 CPU backend, where every structure's answers are exact and its images comparable bit for
/// bit.
fn run_ao_experiment(args: &Args, spec: AoSpec, started: Instant) -> anyhow::Result<()> {
    if !args.filter.is_empty() || args.shard.is_some() || !args.merge.is_empty() {
        return Err(BadInput(
            "--filter, --shard and --merge apply to sweeps, not to ambient-occlusion experiments".into(),
        )
        .into());
    }
    if matches!(args.backend, Some(BackendChoice::Gpu)) {
        return Err(BadInput(
            "ambient-occlusion experiments time the f64 CPU backend (render AO scenes on the GPU through a sweep or the library)".into(),
        )
        .into());
    }
    if args.dry_run {
        for m in &spec.meshes {
            println!(
                "{}: {} triangles x [{}], {}x{}, {} AO rays per hit",
                m.name,
                m.triangles.positions.len(),
                spec.structures.join(", "),
                spec.width,
                spec.height,
                spec.ao.rays
            );
        }
        return Ok(());
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(&spec.name));
    let (rows, tuning) = run_ao(&spec, &|mesh, structure| info!("{mesh}: {structure}"))?;
    let threads = rayon::current_num_threads();
    ao::report::write_ao(&spec, (&rows, &tuning), threads, started.elapsed().as_secs_f64(), &out)?;
    info!("{} rows; wrote {}", rows.len(), out.join("report.md").display());
    Ok(())
}

/// A frame-time experiment (`kind = "frames"`): times each structure frame by frame along a
/// generated scene's camera path on the f64 CPU backend (the OpenGL-like and Whitted passes have
/// no GPU kernels).
fn run_frames_experiment(args: &Args, spec: FramesSpec, started: Instant) -> anyhow::Result<()> {
    if !args.filter.is_empty() || args.shard.is_some() || !args.merge.is_empty() {
        return Err(
            BadInput("--filter, --shard and --merge apply to sweeps, not to frame-time experiments".into()).into(),
        );
    }
    if matches!(args.backend, Some(BackendChoice::Gpu)) {
        return Err(BadInput(
            "frame-time experiments time the f64 CPU backend (the OpenGL-like and Whitted passes have no GPU kernels)"
                .into(),
        )
        .into());
    }
    if args.dry_run {
        for g in spec.scenes() {
            println!(
                "{}: [{}] x {} shadings x {} viewpoints x {} frames at {}x{}{}",
                g.description,
                spec.structures.iter().map(|s| s.name).collect::<Vec<_>>().join(", "),
                spec.shadings.len(),
                spec.viewpoints.len(),
                spec.frames,
                spec.width,
                spec.height,
                spec.motion
                    .as_ref()
                    .map_or(String::new(), |m| format!(", `{}` moving", m.part))
            );
        }
        return Ok(());
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(&spec.name));
    let outcome = frames::run_frames(&spec, &|what| info!("{what}"))?;
    let threads = rayon::current_num_threads();
    frames::report::write_frames(&spec, &outcome, threads, started.elapsed().as_secs_f64(), &out)?;
    info!(
        "{} frames; wrote {}",
        outcome.frames.len(),
        out.join("report.md").display()
    );
    Ok(())
}

/// The shard folders `--merge` names, and N where it was given: a number alone stands for
/// every shard of an N-way split under the results folder `out`.
fn shard_dirs(merge: &[PathBuf], out: &std::path::Path) -> anyhow::Result<(Vec<PathBuf>, Option<u32>)> {
    let count = match merge {
        [one] => one.to_str().and_then(|s| s.parse::<u32>().ok()),
        _ => None,
    };
    match count {
        Some(0) => Err(BadInput("--merge N needs N >= 1".into()).into()),
        Some(n) => Ok((
            (1..=n).map(|index| Shard { index, count: n }.dir(out)).collect(),
            Some(n),
        )),
        None => Ok((merge.to_vec(), None)),
    }
}

/// `text` as one shell word.
fn shell_word(text: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "/._-=,:+@%".contains(c);
    if !text.is_empty() && text.chars().all(plain) {
        text.to_string()
    } else {
        format!("'{}'", text.replace('\'', r"'\''"))
    }
}

/// How to rerun one shard of this sweep, for the merge's refusal.
fn rerun_command(args: &Args) -> String {
    let mut words = vec!["sweep".to_string(), args.experiment.display().to_string()];
    if let Some(out) = &args.out {
        words.extend(["--out".into(), out.display().to_string()]);
    }
    if let Some(b) = args.backend {
        let name = b.to_possible_value().expect("a named value").get_name().to_string();
        words.extend(["--backend".into(), name]);
    }
    for f in &args.filter {
        words.extend(["--filter".into(), format!("{}={}", f.axis.name(), f.value)]);
    }
    words.push("--shard".into());
    words.iter().map(|w| shell_word(w)).collect::<Vec<_>>().join(" ")
}

/// A sweep: renders and measures every run (or a shard's share, or merges shards), then writes
/// the results folder.
fn run_sweep_experiment(args: &Args, spec: Spec, started: Instant) -> anyhow::Result<()> {
    let spec = spec.filtered(&args.filter).map_err(BadInput)?;
    if args.dry_run {
        match args.shard {
            Some(s) => print!("{}", shard::dry_run(&spec, s)),
            None => print!("{}", dry_run(&spec)?),
        }
        return Ok(());
    }
    let out = args.out.clone().unwrap_or_else(|| {
        let name = match args.filter.as_slice() {
            [] => spec.name.clone(),
            f => format!("{}--{}", spec.name, filter::label(f)),
        };
        PathBuf::from("results").join(name)
    });
    let mut backend = open_backend(args.backend.unwrap_or(spec.backend))?;
    let adapter = backend.adapter().clone();
    info!(
        "{}: {} runs on {} ({}, {})",
        spec.name,
        expand(&spec).iter().map(|g| g.runs.len()).sum::<usize>(),
        adapter.name,
        adapter.backend,
        adapter.api
    );
    if let Some(s) = args.shard {
        let done = run_shard(&spec, backend.as_mut(), s, &out, args.fresh)?;
        let m = &done.manifest;
        info!(
            "shard {s}: {} runs ({} failed, {} groups resumed) in {:.1} s; wrote {}",
            m.runs,
            m.failed,
            m.resumed,
            m.seconds,
            done.dir.display()
        );
        if m.failed > 0 {
            let records = done.dir.join(shard::RECORDS);
            return Err(RunsFailed(m.failed, records.display().to_string()).into());
        }
        return Ok(());
    }
    let outcome = if args.merge.is_empty() {
        run_sweep(
            &spec,
            backend.as_mut(),
            &out.join(".journal"),
            &out.join("cache"),
            args.fresh,
        )?
    } else {
        let (dirs, split) = shard_dirs(&args.merge, &out)?;
        let plan = MergePlan {
            dirs: &dirs,
            split,
            rerun: &rerun_command(args),
            fresh: args.fresh,
        };
        merge_shards(&spec, backend.as_mut(), &plan, &out)?
    };
    info!("render plan of a run:\n{}", outcome.plan);
    let pictures =
        render_pictures(&spec, backend.as_mut(), verdict_radius(&spec)).context("rendering the figures' pictures")?;
    let seconds = started.elapsed().as_secs_f64();
    let results = Results {
        spec: &spec,
        outcome: &outcome,
        pictures: pictures.as_ref(),
        adapter: &adapter,
        seconds,
        peak_rss: peak_rss(),
    };
    write_all(&results, &out)?;
    info!(
        "{} runs ({} failed, {} groups resumed) in {seconds:.1} s; peak RSS {:.0} MiB; wrote {}",
        outcome.records.len(),
        outcome.failures,
        outcome.resumed,
        results.peak_rss.unwrap_or(0) as f64 / 1048576.0,
        out.join("report.md").display()
    );
    if outcome.failures > 0 {
        return Err(RunsFailed(outcome.failures, out.join("runs.csv").display().to_string()).into());
    }
    Ok(())
}

/// Logs to stderr at info (warn with -q, error with -qq; debug with -v, trace with -vv) for
/// penumbra, warn for its dependencies; RUST_LOG overrides.
fn init_logging(args: &Args) {
    let level = match args.verbose as i8 - args.quiet as i8 {
        i8::MIN..=-2 => "error",
        -1 => "warn",
        0 => "info",
        1 => "debug",
        _ => "trace",
    };
    let filter = EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| EnvFilter::new(format!("warn,penumbra={level},sweep={level}")));
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::stderr().is_terminal())
        .without_time()
        .with_target(false)
        .init();
}

fn main() -> ExitCode {
    // Mesa's software Vulkan driver prints "error: XDG_RUNTIME_DIR is invalid" on headless
    // machines without one, though nothing fails; give it the temporary folder instead.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let args = Args::parse();
    init_logging(&args);
    match run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.is::<BadInput>() {
                ExitCode::from(2)
            } else if e.is::<RunsFailed>() {
                ExitCode::from(3)
            } else if e.is::<MergeRefused>() {
                ExitCode::from(4)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
