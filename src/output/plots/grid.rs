//! Labelled image grids: tiles of equal size, each with a two-line caption above it and, under a
//! signed-error map, a colour bar with its scale labelled, so that a colour reads as a number.

use super::super::images::{diverging_colour, write_png, Rgb};
use super::ticks::label;
use super::{error, fonts, FONT};
use plotters::prelude::*;
use plotters::style::text_anchor;
use std::path::Path;

/// The scale of a diverging map ([`crate::output::images::diverging`]): white at 0, full red at
/// +`scale` and beyond, full blue at -`scale` and below.
#[derive(Clone, Debug)]
pub struct ColourBar {
    /// The difference shown at full colour.
    pub scale: f64,
    /// What the colour measures (e.g. "visibility difference").
    pub what: String,
}

/// One tile of a grid.
#[derive(Clone, Debug)]
pub struct Tile<'a> {
    /// Caption; a first ", " breaks it into two lines.
    pub label: String,
    /// The image.
    pub image: &'a Rgb,
    /// Its colour bar, for a diverging map.
    pub bar: Option<ColourBar>,
}

impl<'a> Tile<'a> {
    /// A tile without a colour bar.
    pub fn new(label: impl Into<String>, image: &'a Rgb) -> Self {
        Tile {
            label: label.into(),
            image,
            bar: None,
        }
    }
}

/// Caption height above each tile, colour-bar height under tiles of a row that has one, gap.
const CAPTION: u32 = 44;
const BAR: u32 = 58;
const GAP: u32 = 8;

/// Tiles of equal size in a grid of `columns`, each with its caption, into a PNG at `path`.
/// Small images are enlarged by a whole factor (nearest neighbour) to at least 260 pixels wide.
pub fn image_grid(path: &Path, tiles: &[Tile], columns: usize) -> anyhow::Result<()> {
    fonts();
    let Some(first) = tiles.first() else {
        return Ok(());
    };
    let scale = 260u32.div_ceil(first.image.width).max(1);
    let scaled: Vec<Rgb> = tiles.iter().map(|t| upscale(t.image, scale)).collect();
    let (tw, th) = (first.image.width * scale, first.image.height * scale);
    let rows: Vec<&[Tile]> = tiles.chunks(columns).collect();
    let row_height = |r: &[Tile]| CAPTION + th + if r.iter().any(|t| t.bar.is_some()) { BAR } else { 0 } + GAP;
    let size = (
        tw * columns as u32 + GAP * (columns as u32 + 1),
        rows.iter().map(|r| row_height(r)).sum::<u32>() + GAP,
    );
    let mut data = vec![255u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut data, size).into_drawing_area();
        let mut y = GAP as i32;
        let mut tile = 0;
        for row in &rows {
            for (c, t) in row.iter().enumerate() {
                let x = GAP as i32 + c as i32 * (tw + GAP) as i32;
                let (first_line, second_line) = t.label.split_once(", ").unwrap_or((&t.label, ""));
                for (i, line) in [first_line, second_line].into_iter().enumerate() {
                    root.draw(&Text::new(
                        line.to_string(),
                        (x, y + 2 + 19 * i as i32),
                        (FONT, 16).into_font(),
                    ))
                    .map_err(error)?;
                }
                let img = &scaled[tile];
                tile += 1;
                if let Some(el) =
                    BitMapElement::<_>::with_ref((x, y + CAPTION as i32), (img.width, img.height), &img.data)
                {
                    root.draw(&el).map_err(error)?;
                }
                if let Some(bar) = &t.bar {
                    colour_bar(&root, bar, (x, y + (CAPTION + th) as i32 + 6), tw)?;
                }
            }
            y += row_height(row) as i32;
        }
        root.present().map_err(error)?;
    }
    write_png(
        path,
        &Rgb {
            width: size.0,
            height: size.1,
            data,
        },
    )
}

/// Draws `bar` `width` pixels wide with its top left at `(x, y)`: the colour ramp, its ends and
/// middle labelled with the differences they stand for, and what it measures.
fn colour_bar(
    root: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    bar: &ColourBar,
    (x, y): (i32, i32),
    width: u32,
) -> anyhow::Result<()> {
    let (left, right) = (x + 12, x + width as i32 - 12);
    let span = (right - left).max(1);
    for px in left..right {
        let t = 2.0 * (px - left) as f64 / span as f64 - 1.0;
        let [r, g, b] = diverging_colour(t);
        root.draw(&Rectangle::new([(px, y), (px + 1, y + 12)], RGBColor(r, g, b).filled()))
            .map_err(error)?;
    }
    root.draw(&Rectangle::new([(left, y), (right, y + 12)], BLACK.stroke_width(1)))
        .map_err(error)?;
    let font = (FONT, 14).into_font();
    let centred = |h| TextStyle::from(font.clone()).pos(text_anchor::Pos::new(h, text_anchor::VPos::Top));
    for (at, text, h) in [
        (left, format!("-{}", label(bar.scale)), text_anchor::HPos::Left),
        ((left + right) / 2, "0".to_string(), text_anchor::HPos::Center),
        (right, format!("+{}", label(bar.scale)), text_anchor::HPos::Right),
    ] {
        root.draw(&PathElement::new(
            vec![(at, y + 12), (at, y + 16)],
            BLACK.stroke_width(1),
        ))
        .map_err(error)?;
        root.draw(&Text::new(text, (at, y + 18), centred(h))).map_err(error)?;
    }
    root.draw(&Text::new(
        bar.what.clone(),
        ((left + right) / 2, y + 35),
        centred(text_anchor::HPos::Center),
    ))
    .map_err(error)?;
    Ok(())
}

/// Nearest-neighbour enlargement by an integer factor, so that small measuring images stay
/// legible (and pixel-exact) in figures.
fn upscale(img: &Rgb, k: u32) -> Rgb {
    let (w, h) = (img.width * k, img.height * k);
    let mut data = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            let i = (((y / k) * img.width + x / k) * 3) as usize;
            data.extend_from_slice(&img.data[i..i + 3]);
        }
    }
    Rgb {
        width: w,
        height: h,
        data,
    }
}
