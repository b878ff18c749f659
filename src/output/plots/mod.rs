//! Figures for every kind's report, drawn with plotters: line plots ([`line_plot`]) and small
//! multiples of them on shared axes ([`line_panels`]), grouped bars where the axis is categorical
//! ([`grouped_bars`]), and labelled image grids with colour bars ([`image_grid`]). Each chart is
//! written twice, a PNG and an SVG beside it (same name), keeps its legend in a column right of
//! the data, gives every series a look of its own (a colour-blind-safe colour, a marker shape and
//! dashes, all from one index, [`look`]) and refuses two series drawn alike, labels its axes so
//! that no two labels touch, and marks a 95 % interval that runs off a log axis with a caret
//! instead of drawing it to the far edge.

mod bars;
mod grid;
mod legend;
mod line;
mod style;
#[cfg(test)]
mod tests;
mod ticks;

pub use bars::{grouped_bars, Bar, Group};
pub use grid::{image_grid, ColourBar, Tile};
pub use line::{line_panels, line_plot, Axes, Panel, Point, Reference, Series};
pub use style::{colour, look, scheme_look, Look, Marker, LOOKS};

use super::images::{write_png, Rgb};
use crate::files::write_atomic;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// The font every figure names: the embedded DejaVu Sans, registered under a CSS font list so
/// that an SVG viewer without DejaVu falls back to its own sans-serif.
const FONT: &str = "DejaVu Sans, sans-serif";

/// Registers the embedded DejaVu Sans as [`FONT`] (no system fonts needed).
fn fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
    });
}

/// Width in pixels of `text` set in [`FONT`] at `size`.
fn text_width(text: &str, size: u32) -> u32 {
    fonts();
    (FONT, size)
        .into_font()
        .box_size(text)
        .map_or(size * text.len() as u32, |(w, _)| w)
}

/// A plotters error as an anyhow error (drawing errors carry their backend's error type).
fn error(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}

/// A figure that draws itself the same way on any plotters backend.
trait Figure {
    /// Its size in pixels.
    fn size(&self) -> (u32, u32);

    /// Draws it on `root`, which is white and `size()` large.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static;
}

/// Writes `figure` to `path` as a PNG and beside it as an SVG (the same name, `.svg`).
fn write_figure(path: &Path, figure: &impl Figure) -> anyhow::Result<()> {
    fonts();
    let (w, h) = figure.size();
    let mut data = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut data, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(error)?;
        figure.draw(&root)?;
        root.present().map_err(error)?;
    }
    write_png(
        path,
        &Rgb {
            width: w,
            height: h,
            data,
        },
    )?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(error)?;
        figure.draw(&root)?;
        root.present().map_err(error)?;
    }
    write_atomic(&path.with_extension("svg"), svg.as_bytes())
}
