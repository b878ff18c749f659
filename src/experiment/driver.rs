//! The one driver every experiment kind runs through: reads the file (header first), applies the
//! command line's refusals, chooses and checks the results folder, opens the backend, runs the
//! kind with progress, writes the manifest and swaps the new set of outputs in; then maps the
//! outcome to the exit status stated in `--help`.

use super::cli::{BadInput, Cli, RunsFailed};
use super::contract::{Experiment, Finished, RunContext};
use super::core::MergeRefused;
use super::kinds::load;
use super::manifest::{peak_rss, utc, Build, Input, Machine, Manifest, RunInfo, SCHEMA};
use super::outputs::{check_home, resolve_home, Outputs};
use super::progress::Progress;
use crate::render::{cpu::CpuBackend, open_backend, Backend, BackendChoice};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Instant, SystemTime};
use tracing::info;

/// Runs the experiment `cli` names; the error's type chooses the exit status ([`exit_status`]).
pub fn run(cli: &Cli) -> anyhow::Result<()> {
    let (started, started_utc) = (Instant::now(), utc(SystemTime::now()));
    let experiment = load(&cli.experiment).map_err(|e| BadInput(e.to_string()))?;
    let header = experiment.header().clone();
    let kind = header.kind.name();
    let accepts = experiment.accepts();
    let choice = cli.backend.or(header.backend).unwrap_or(accepts.backend);
    if !accepts.gpu && choice == BackendChoice::Gpu {
        return Err(BadInput(format!(
            "`{kind}` experiments time the f64 CPU backend, where every structure answers exactly; --backend gpu (or backend = \"gpu\") does not apply"
        ))
        .into());
    }
    let choice = backend_for(experiment.as_ref(), choice)?;
    let mut inputs = Vec::new();
    // A reused tuning decides what is built, so it is an input as the experiment file is.
    for path in experiment.inputs().into_iter().chain(cli.tuning.clone()) {
        inputs.push(Input::read(&path).map_err(|e| BadInput(format!("{}: cannot read: {e}", path.display())))?);
    }
    if cli.dry_run {
        super::cli::print_out(&experiment.dry_run(cli)?)?;
        return Ok(());
    }
    // The folder's name checks the filters: a wrong one is refused here, before any folder or
    // backend is opened, whether or not --out names the folder.
    let folder = experiment.folder(cli)?;
    let out = match &cli.out {
        Some(out) => out.clone(),
        None => PathBuf::from("results").join(folder),
    };
    // The folders this run makes for its results, innermost first: a failed run removes those
    // it left empty (a journal worth resuming keeps its folder).
    let made = crate::files::missing_folders(&out);
    let home = resolve_home(&out).map_err(BadInput)?;
    let result = run_into(experiment.as_ref(), cli, choice, &home, started, started_utc, inputs);
    if result.is_err() {
        crate::files::remove_empty(&made);
    }
    result
}

/// Runs `experiment` into the results folder `home` ([`resolve_home`]).
fn run_into(
    experiment: &dyn Experiment,
    cli: &Cli,
    choice: BackendChoice,
    home: &std::path::Path,
    started: Instant,
    started_utc: String,
    inputs: Vec<Input>,
) -> anyhow::Result<()> {
    let header = experiment.header().clone();
    let kind = header.kind.name();
    let accepts = experiment.accepts();
    check_home(home, kind, &header.name, &cli.experiment, cli.fresh).map_err(BadInput)?;
    let out = match cli.shard {
        Some(shard) => Outputs::begin_shard(home, &shard.dir(home)),
        None => Outputs::begin(home),
    }
    .map_err(|e| BadInput(format!("{e:#}")))?;
    let mut backend: Box<dyn Backend> = if accepts.gpu {
        open_backend(choice)?
    } else {
        Box::new(CpuBackend::default())
    };
    let adapter = backend.adapter().clone();
    info!(
        "{kind} experiment `{}` on {} ({}, {}); results into {}",
        header.name,
        adapter.name,
        adapter.backend,
        adapter.api,
        home.display()
    );
    let progress = Progress::new();
    let finished = experiment.run(&mut RunContext {
        backend: backend.as_mut(),
        cli,
        home,
        out: &out,
        progress: &progress,
        started,
    })?;
    let failed = match finished {
        Finished::Shard { failed } => failed,
        Finished::Results { details, failed } => {
            let manifest = Manifest {
                schema: SCHEMA,
                kind: header.kind,
                name: header.name.clone(),
                build: Build::current(),
                run: RunInfo {
                    command_line: std::env::args_os().map(|a| a.to_string_lossy().into_owned()).collect(),
                    started_utc,
                    seconds: started.elapsed().as_secs_f64(),
                    peak_rss_bytes: peak_rss(),
                },
                machine: Machine::current(),
                adapter,
                timing: header.schedule,
                inputs,
                details,
            };
            crate::files::write_atomic(&out.path("manifest.toml")?, toml::to_string(&manifest)?.as_bytes())?;
            out.commit()?;
            info!(
                "`{}` done in {:.1} s (peak RSS {:.0} MiB); wrote {}",
                header.name,
                manifest.run.seconds,
                manifest.run.peak_rss_bytes.unwrap_or(0) as f64 / 1048576.0,
                home.display()
            );
            failed
        }
    };
    match failed {
        Some((n, table)) if n > 0 => Err(RunsFailed(n, table).into()),
        _ => Ok(()),
    }
}

/// The backend a run opens: `choice`, except that `auto` takes the f64 CPU backend where a scene
/// asks for something the GPU has no kernel for (and says so), and `gpu` for such a scene is
/// refused before any work, naming the scene file and key.
fn backend_for(experiment: &dyn Experiment, choice: BackendChoice) -> Result<BackendChoice, BadInput> {
    Ok(match (choice, experiment.gpu_gap()) {
        (BackendChoice::Gpu, Some(gap)) => {
            let instead = "use backend = \"cpu\" or \"auto\"";
            return Err(BadInput(format!(
                "{gap}; --backend gpu (or backend = \"gpu\") cannot run this experiment: {instead}"
            )));
        }
        (BackendChoice::Auto, Some(gap)) => {
            info!("backend auto: the f64 CPU backend, because {gap}");
            BackendChoice::Cpu
        }
        (choice, _) => choice,
    })
}

/// The exit status of an outcome: 0 done, 2 bad input, 3 runs failed, 4 merge refused, 1 else.
pub fn exit_status(result: &anyhow::Result<()>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e)
            if e.is::<BadInput>()
                || e.is::<crate::config::ConfigError>()
                || e.is::<crate::files::Refused>()
                || e.is::<crate::render::limit::DeviceLimit>() =>
        {
            ExitCode::from(2)
        }
        Err(e) if e.is::<RunsFailed>() => ExitCode::from(3),
        Err(e) if e.is::<MergeRefused>() => ExitCode::from(4),
        Err(_) => ExitCode::from(1),
    }
}

/// Logs to stderr at info (warn with -q, error with -qq; debug with -v, trace with -vv) for
/// penumbra, warn for its dependencies; RUST_LOG overrides. Off a terminal every line carries
/// its UTC time.
pub fn init_logging(cli: &Cli) {
    let level = match cli.verbose as i8 - cli.quiet as i8 {
        i8::MIN..=-2 => "error",
        -1 => "warn",
        0 => "info",
        1 => "debug",
        _ => "trace",
    };
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(format!("warn,penumbra={level},sweep={level}")));
    let terminal = std::io::stderr().is_terminal();
    let builder = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(terminal)
        .with_target(false)
        // A full or closed standard error loses log lines, never the run: no fallback print.
        .log_internal_errors(false);
    if terminal {
        builder.without_time().init();
    } else {
        builder.init();
    }
}
