//! The sweep's outputs, written into the run's staging folder (the driver adds the manifest and
//! swaps the set in): CSV tables, plots, images, the markdown report with its verdict, the
//! comparison page (index.html), and the regression thresholds checked against them.

pub mod equal_time;
pub mod images;
pub mod markdown;
pub mod plots;
pub mod results;
pub mod schemes;
pub mod structures;
pub mod summary;
pub mod tables;
pub mod thresholds;
pub mod verdict;

use crate::experiment::outputs::Outputs;
use crate::files::write_atomic;
use crate::output::page::{self, Page};
use images::picture_flip;
use markdown::report;
pub use results::{details, Results};

/// Writes every output into `outputs`.
pub fn write_all(r: &Results, outputs: &Outputs) -> anyhow::Result<()> {
    let out = outputs.dir();
    let flip = match r.pictures {
        Some(p) => picture_flip(p)?,
        None => Default::default(),
    };
    let summaries = summary::summarise(r.outcome, &flip);
    tables::write_tables(r, &summaries, out)?;
    plots::write_plots(r, &summaries, &out.join("plots"))?;
    let galleries = images::write_images(r, &out.join("images"))?;
    let report = report(r.spec, r.outcome, &summaries, r.adapter, r.seconds);
    write_atomic(&out.join("report.md"), report.as_bytes())?;
    page::write(
        out,
        &Page {
            title: format!("{}: soft-shadow sampling sweep", r.spec.name),
            report,
            galleries,
        },
    )
}
