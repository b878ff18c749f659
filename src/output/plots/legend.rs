//! The legend: a column to the right of the data area, so that it never covers a point, each
//! entry drawn with its series' own colour, dashes and marker (a dashed series looks dashed in
//! its legend too), and notes for the interval whiskers and the carets of clipped intervals.

use super::style::{dashes, draw_marker, edge_marker, Look as SeriesLook, Marker, DASH, MARKER_RADIUS};
use super::{error, text_width, FONT};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor;

/// How an entry's sample looks.
#[derive(Clone, Debug)]
pub enum Look {
    /// A line in `colour`, dashed or solid, with its marker (filled or an outline) if it has one.
    Line {
        /// Its colour.
        colour: RGBColor,
        /// Dashes (on, off), or solid.
        dash: Option<(u32, u32)>,
        /// Marker and whether it is filled.
        marker: Option<(Marker, bool)>,
    },
    /// A bar of a series' look: filled (outlined with dashes where the look is dashed), its
    /// marker at its top as on the bars.
    Bar(SeriesLook),
    /// A 95 % interval's whisker.
    Interval,
    /// The caret that marks an interval clipped at the axis.
    Clipped,
}

/// One legend entry.
#[derive(Clone, Debug)]
pub struct Entry {
    /// Its text.
    pub label: String,
    /// Its sample.
    pub look: Look,
}

/// Text size of legend entries as plotters sizes text (a line's height, 1.24 em: 19 reads as
/// 15.3 px), legible where a page shows the figure at its own size.
const FONT_SIZE: u32 = 19;
/// Height of one entry.
const ROW: i32 = 28;
/// Width of an entry's sample.
const SAMPLE: i32 = 40;
/// Space around the legend and between its columns.
const PAD: i32 = 10;

/// Whisker and caret colour: dark enough on white and on every palette colour.
pub const INK: RGBColor = RGBColor(50, 50, 50);

/// Entries per column when `height` pixels are available.
fn per_column(height: u32) -> usize {
    ((height as i32 - PAD) / ROW).max(1) as usize
}

/// Height that `entries` need to stand in one column.
pub fn height(entries: &[Entry]) -> u32 {
    (2 * PAD + entries.len() as i32 * ROW) as u32
}

/// Width of the column(s) `entries` take in `height` pixels (0 for none).
pub fn width(entries: &[Entry], height: u32) -> u32 {
    if entries.is_empty() {
        return 0;
    }
    let text = entries
        .iter()
        .map(|e| text_width(&e.label, FONT_SIZE))
        .max()
        .unwrap_or(0) as i32;
    let columns = entries.len().div_ceil(per_column(height)) as i32;
    (PAD + columns * (SAMPLE + 8 + text + PAD)) as u32
}

/// Draws `entries` on `root` in the column(s) from pixel `x`, from `top` down `height` pixels.
pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    entries: &[Entry],
    (x, top): (i32, i32),
    height: u32,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let rows = per_column(height);
    let text = entries
        .iter()
        .map(|e| text_width(&e.label, FONT_SIZE))
        .max()
        .unwrap_or(0) as i32;
    for (i, e) in entries.iter().enumerate() {
        let x0 = x + PAD + (i / rows) as i32 * (SAMPLE + 8 + text + PAD);
        let y = top + PAD + (i % rows) as i32 * ROW + ROW / 2;
        sample(root, &e.look, (x0, y))?;
        root.draw(&Text::new(
            e.label.clone(),
            (x0 + SAMPLE + 8, y),
            TextStyle::from((FONT, FONT_SIZE).into_font()).pos(text_anchor::Pos::new(
                text_anchor::HPos::Left,
                text_anchor::VPos::Center,
            )),
        ))
        .map_err(error)?;
    }
    Ok(())
}

/// Draws an entry's sample with its left end at `(x, y)`.
fn sample<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, look: &Look, (x, y): (i32, i32)) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    match look {
        Look::Line { colour, dash, marker } => {
            for piece in dashes(&[(x, y), (x + SAMPLE, y)], *dash) {
                root.draw(&PathElement::new(piece, colour.stroke_width(2)))
                    .map_err(error)?;
            }
            if let Some((m, filled)) = marker {
                draw_marker(root, (x + SAMPLE / 2, y), *m, MARKER_RADIUS, *colour, *filled)?;
            }
        }
        Look::Bar(look) => {
            let (left, right, top, bottom) = (x + 10, x + SAMPLE - 10, y - 4, y + 10);
            bar(root, (left, top, right, bottom), *look)?;
            bar_marker(root, ((left + right) / 2, top), *look)?;
        }
        Look::Interval => interval(root, x + SAMPLE / 2, (y + 8, false), (y - 8, false))?,
        Look::Clipped => caret(root, (x + SAMPLE / 2, y + 6), false)?,
    }
    Ok(())
}

/// Draws an interval whisker at pixel column `x` from `low` to `high` (each a pixel row and
/// whether the interval was clipped there): a line with a cap at each end it reaches, and a
/// caret pointing off the axis at each end clipped to the axis edge.
pub fn interval<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    x: i32,
    low: (i32, bool),
    high: (i32, bool),
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    root.draw(&PathElement::new(vec![(x, low.0), (x, high.0)], INK.stroke_width(1)))
        .map_err(error)?;
    for (end, clipped, up) in [(low.0, low.1, false), (high.0, high.1, true)] {
        if clipped {
            caret(root, (x, end), up)?;
        } else {
            root.draw(&PathElement::new(vec![(x - 4, end), (x + 4, end)], INK.stroke_width(1)))
                .map_err(error)?;
        }
    }
    Ok(())
}

/// A filled caret with its tip at `tip`, pointing up or down: where an interval runs past the
/// axis.
pub fn caret<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, tip: (i32, i32), up: bool) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let (x, y) = tip;
    let back = if up { y + 8 } else { y - 8 };
    root.draw(&Polygon::new(vec![(x, y), (x + 5, back), (x - 5, back)], INK.filled()))
        .map_err(error)
}

/// Draws a bar of `look` over the pixel rectangle (left, top, right, bottom): filled in its
/// colour, or, for a dashed look, white with a dashed edge in its colour.
pub fn bar<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    (left, top, right, bottom): (i32, i32, i32, i32),
    look: SeriesLook,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    if !look.dashed {
        return root
            .draw(&Rectangle::new([(left, top), (right, bottom)], look.colour.filled()))
            .map_err(error);
    }
    let ring = [
        (left + 1, bottom),
        (left + 1, top + 1),
        (right - 1, top + 1),
        (right - 1, bottom),
    ];
    for piece in dashes(&ring, Some(DASH)) {
        root.draw(&PathElement::new(piece, look.colour.stroke_width(2)))
            .map_err(error)?;
    }
    Ok(())
}

/// Draws a bar's marker centred at `at` (the middle of its top): its look's shape in its
/// colour with a dark edge, so that it reads against the bar's own fill and against white.
pub fn bar_marker<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    at: (i32, i32),
    look: SeriesLook,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let r = MARKER_RADIUS + 1;
    if look.dashed {
        root.draw(&Circle::new(at, r + 2, WHITE.filled())).map_err(error)?;
    }
    draw_marker(root, at, look.marker, r, look.colour, !look.dashed)?;
    if !look.dashed {
        edge_marker(root, at, look.marker, r, INK)?;
    }
    Ok(())
}
