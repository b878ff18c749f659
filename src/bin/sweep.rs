//! `sweep EXPERIMENT.toml`: runs an experiment of any kind through the one driver and writes its
//! results folder (`--help` states the options and exit statuses).

use clap::Parser;
use penumbra::experiment::cli::Cli;
use penumbra::experiment::driver;

fn main() -> std::process::ExitCode {
    // Mesa's software Vulkan driver prints "error: XDG_RUNTIME_DIR is invalid" on headless
    // machines without one, though nothing fails; give it the temporary folder instead.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let cli = Cli::parse();
    driver::init_logging(&cli);
    penumbra::experiment::cli::finish(driver::run(&cli))
}
