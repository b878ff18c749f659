//! `sweep EXPERIMENT.toml`: runs an experiment's sweep and writes its results folder.

use anyhow::Context;
use clap::Parser;
use penumbra::experiment::fps::{is_fps, run_fps, FpsSpec};
use penumbra::experiment::{pictures::render_pictures, run_sweep, spec::BackendChoice, Spec};
use penumbra::render::open_backend;
use penumbra::report::fps::write_fps;
use penumbra::report::markdown::verdict_radius;
use penumbra::report::write::{write_all, Results};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Sweep sampling scheme x pattern x shadow-ray count x light radius x seed, measure every run
/// against a ground truth checked against the exact answer, and write CSV, plots and a report.
#[derive(Parser)]
#[command(version)]
struct Args {
    /// Experiment file, e.g. experiments/sphere.toml.
    experiment: PathBuf,
    /// Results folder (default: results/NAME, NAME from the experiment file).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Discard the journal of an interrupted sweep and redo every run.
    #[arg(long)]
    fresh: bool,
    /// Override the experiment's backend: auto, gpu or cpu.
    #[arg(long)]
    backend: Option<String>,
}

fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kb| kb * 1024)
}

/// A frame-rate experiment (`kind = "fps"`): times configurations, no sweep.
fn run_fps_experiment(args: &Args, started: Instant) -> anyhow::Result<()> {
    let spec = FpsSpec::load(&args.experiment)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(&spec.name));
    let mut backend = open_backend(backend_choice(args, BackendChoice::Auto)?)?;
    let adapter = backend.adapter().clone();
    let rows = run_fps(&spec, backend.as_mut())?;
    write_fps(&spec, &rows, &adapter, started.elapsed().as_secs_f64(), &out)?;
    eprintln!(
        "{} configurations timed; wrote {}",
        rows.len(),
        out.join("report.md").display()
    );
    Ok(())
}

fn backend_choice(args: &Args, default: BackendChoice) -> anyhow::Result<BackendChoice> {
    Ok(match args.backend.as_deref() {
        None => default,
        Some("auto") => BackendChoice::Auto,
        Some("gpu") => BackendChoice::Gpu,
        Some("cpu") => BackendChoice::Cpu,
        Some(other) => anyhow::bail!("--backend must be auto, gpu or cpu, got `{other}`"),
    })
}

fn run(args: Args) -> anyhow::Result<()> {
    let started = Instant::now();
    if is_fps(&args.experiment) {
        return run_fps_experiment(&args, started);
    }
    let spec = Spec::load(&args.experiment)?;
    let choice = backend_choice(&args, spec.backend)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(&spec.name));
    let mut backend = open_backend(choice)?;
    let adapter = backend.adapter().clone();
    eprintln!(
        "{}: {} runs on {} ({}, {})",
        spec.name,
        penumbra::experiment::run::expand(&spec)
            .iter()
            .map(|g| g.runs.len())
            .sum::<usize>(),
        adapter.name,
        adapter.backend,
        adapter.api
    );
    let outcome = run_sweep(
        &spec,
        backend.as_mut(),
        &out.join(".journal"),
        &out.join("cache"),
        args.fresh,
    )?;
    eprint!("render plan of a run:\n{}", outcome.plan);
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
    eprintln!(
        "{} runs ({} failed, {} groups resumed) in {seconds:.1} s; peak RSS {:.0} MiB; wrote {}",
        outcome.records.len(),
        outcome.failures,
        outcome.resumed,
        results.peak_rss.unwrap_or(0) as f64 / 1048576.0,
        out.join("report.md").display()
    );
    if outcome.failures > 0 {
        anyhow::bail!(
            "{} runs failed; see the `error` column of {}",
            outcome.failures,
            out.join("runs.csv").display()
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    // Mesa's software Vulkan driver prints "error: XDG_RUNTIME_DIR is invalid" on headless
    // machines without one, though nothing fails; give it the temporary folder instead.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    match run(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
