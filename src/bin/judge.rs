//! `judge IMAGE.exr... --out DIR`: scores radiance images of an exported view (each beside the
//! `view.toml` its export wrote: Mitsuba's renders, penumbra's own, any renderer's) against
//! penumbra's exact reference (and, for a renderer whose export records a shadow-ray lift, the
//! answer for that lift too), and writes the folder `penumbra::peers::panel`
//! describes (judge.csv, groups.csv, profile.csv/png, report.md, reference EXRs,
//! provenance.toml). Exit status: 0 done, 2 bad input (an image of another view, size or scene;
//! a non-EXR; missing channels; a non-finite pixel; a scene without an exact answer), 1 else.

use clap::Parser;
use penumbra::experiment::cli::{finish, print_out};
use penumbra::peers::panel::Panel;
use penumbra::peers::write_folder;
use std::path::PathBuf;

/// Score renderers' images of an exported view against penumbra's exact reference.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// Radiance EXRs, each in a folder holding the view.toml of its export; `NAME-seedK.exr`
    /// are seeds of NAME.
    #[arg(required = true)]
    images: Vec<PathBuf>,
    /// The folder written (replaced as a whole, only once everything is written).
    #[arg(long)]
    out: PathBuf,
}

fn main() -> std::process::ExitCode {
    let args = Args::parse();
    let run = || -> anyhow::Result<()> {
        let panel = Panel::judge(&args.images)?;
        let groups = panel.groups();
        write_folder(&args.out, |dir| panel.write(dir, &groups))?;
        print_out(&panel.report(&groups))?;
        Ok(())
    };
    finish(run())
}
