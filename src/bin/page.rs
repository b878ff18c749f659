//! `page RESULTS_FOLDER...`: rebuilds each results folder's comparison page (index.html) from
//! the files in it, without rerunning its experiment: for folders written before pages existed,
//! or after the page changed. A fresh run writes a richer page (labels, table links, FLIP maps
//! against each gallery's reference) than one rebuilt from file names. Exit status: 0 done, 2 a
//! folder refused (no report.md; a link, pipe or device where its files or folders belong; an
//! unreadable image), 1 else (standard output closed or full included).

use clap::Parser;
use penumbra::experiment::cli::{finish, print_out};
use std::path::PathBuf;

/// Rebuild results folders' comparison pages from their files.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// Results folders (each with a report.md).
    #[arg(required = true)]
    folders: Vec<PathBuf>,
}

fn main() -> std::process::ExitCode {
    let args = Args::parse();
    // A folder whose files cannot be taken as they are is bad input (status 2); the first
    // failure ends the command.
    finish(args.folders.iter().try_for_each(|dir| {
        penumbra::output::page::rebuild(dir)?;
        print_out(&format!("wrote {}\n", dir.join("index.html").display()))?;
        Ok(())
    }))
}
