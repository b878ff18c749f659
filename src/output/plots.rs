//! Line plots and labelled image grids, drawn with plotters into PNG files.

use super::images::Rgb;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// One line of a plot: points (x, y, 95 % CI half-width or NaN).
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label.
    pub name: String,
    /// Points.
    pub points: Vec<(f64, f64, f64)>,
    /// Dashed (e.g. the shared pattern) or solid.
    pub dashed: bool,
}

/// A horizontal reference line (e.g. the exact penumbra width).
#[derive(Clone, Debug)]
pub struct Reference {
    /// Legend label.
    pub name: String,
    /// Either one y for all x, or a curve of (x, y).
    pub points: Vec<(f64, f64)>,
    /// Colour of the series it belongs to (see [`colour`]), or black.
    pub colour: Option<usize>,
}

/// A plot's labels and axis kinds.
pub struct Axes<'a> {
    /// Title.
    pub title: &'a str,
    /// x-axis label.
    pub x: &'a str,
    /// y-axis label.
    pub y: &'a str,
    /// Logarithmic x.
    pub log_x: bool,
    /// Logarithmic y.
    pub log_y: bool,
    /// Fixed x range instead of the data's.
    pub x_range: Option<(f64, f64)>,
    /// Where the legend goes.
    pub legend: SeriesLabelPosition,
}

impl<'a> Axes<'a> {
    /// Axes with data-driven ranges and the legend at the upper right.
    pub fn new(title: &'a str, x: &'a str, y: &'a str, log_x: bool, log_y: bool) -> Self {
        Axes {
            title,
            x,
            y,
            log_x,
            log_y,
            x_range: None,
            legend: SeriesLabelPosition::UpperRight,
        }
    }
}

const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(127, 127, 127),
];

/// Registers the embedded DejaVu Sans as plotters' sans-serif (no system fonts needed).
fn fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
}

/// Colour of the i-th series (series of one scheme share a colour across plots).
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

const SIZE: (u32, u32) = (960, 640);

/// Draws series and references into a PNG.
pub fn line_plot(path: &Path, axes: &Axes, series: &[(usize, Series)], references: &[Reference]) -> anyhow::Result<()> {
    fonts();
    let pts = series
        .iter()
        .flat_map(|(_, s)| s.points.iter().map(|p| (p.0, p.1)))
        .chain(references.iter().flat_map(|r| r.points.iter().copied()));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    let in_x = |x: f64| axes.x_range.is_none_or(|(a, b)| x >= a && x <= b);
    for (x, y) in pts.filter(|(x, y)| {
        x.is_finite() && y.is_finite() && in_x(*x) && (!axes.log_x || *x > 0.0) && (!axes.log_y || *y > 0.0)
    }) {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (1.0, 2.0, 1.0, 2.0);
    }
    let pad = |lo: f64, hi: f64, log: bool| -> (f64, f64) {
        if log {
            (lo / 1.3, hi * 1.3)
        } else {
            let d = (hi - lo).max(1e-12 * hi.abs().max(1e-300));
            (lo - 0.06 * d, hi + 0.06 * d)
        }
    };
    let (x0, x1) = axes.x_range.unwrap_or_else(|| pad(x0, x1, axes.log_x));
    let (y0, y1) = pad(y0, y1, axes.log_y);
    let mut buf = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        match (axes.log_x, axes.log_y) {
            (false, false) => draw(&root, axes, series, references, x0..x1, y0..y1)?,
            (true, false) => draw(&root, axes, series, references, (x0..x1).log_scale(), y0..y1)?,
            (false, true) => draw(&root, axes, series, references, x0..x1, (y0..y1).log_scale())?,
            (true, true) => draw(
                &root,
                axes,
                series,
                references,
                (x0..x1).log_scale(),
                (y0..y1).log_scale(),
            )?,
        }
        root.present()?;
    }
    super::images::write_png(
        path,
        &Rgb {
            width: SIZE.0,
            height: SIZE.1,
            data: buf,
        },
    )
}

/// A tick label with at most four significant digits and no trailing zeros (log axes'
/// ticks are computed in floating point: 0.7 arrives as 0.7000000000000001).
fn tick(v: &f64) -> String {
    if *v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn draw<DB: DrawingBackend, X, Y>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    axes: &Axes,
    series: &[(usize, Series)],
    references: &[Reference],
    x: X,
    y: Y,
) -> anyhow::Result<()>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
    DB::ErrorType: 'static,
{
    let mut chart = ChartBuilder::on(root)
        .caption(axes.title, ("sans-serif", 24))
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(84)
        .build_cartesian_2d(x, y)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc(axes.x)
        .y_desc(axes.y)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    for (ci, s) in series {
        let c = colour(*ci);
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|p| p.1.is_finite() && !(axes.log_y && p.1 <= 0.0) && !(axes.log_x && p.0 <= 0.0))
            .map(|p| (p.0, p.1))
            .collect();
        let stroke = c.stroke_width(2);
        let anno = if s.dashed {
            chart
                .draw_series(DashedLineSeries::new(pts.clone(), 8, 5, stroke))
                .map_err(|e| anyhow::anyhow!("{e}"))?
        } else {
            chart
                .draw_series(LineSeries::new(pts.clone(), stroke))
                .map_err(|e| anyhow::anyhow!("{e}"))?
        };
        anno.label(s.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let bars = s
            .points
            .iter()
            .filter(|p| p.1.is_finite() && p.2.is_finite() && p.2 > 0.0);
        chart
            .draw_series(bars.map(|p| PathElement::new(vec![(p.0, p.1 - p.2), (p.0, p.1 + p.2)], c.stroke_width(1))))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    for (i, r) in references.iter().enumerate() {
        let style = r.colour.map_or(BLACK.mix(0.75), |c| colour(c).mix(0.9)).stroke_width(2);
        chart
            .draw_series(DashedLineSeries::new(r.points.clone(), 10 + 6 * i as u32, 6, style))
            .map_err(|e| anyhow::anyhow!("{e}"))?
            .label(r.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(axes.legend.clone())
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(())
}

/// Tiles of equal size in a grid, each with a caption above it.
pub fn image_grid(path: &Path, tiles: &[(String, &Rgb)], columns: usize) -> anyhow::Result<()> {
    fonts();
    let Some((_, first)) = tiles.first() else {
        return Ok(());
    };
    let scale = 260u32.div_ceil(first.width).max(1);
    let scaled: Vec<Rgb> = tiles.iter().map(|(_, t)| upscale(t, scale)).collect();
    let (tw, th, caption) = (first.width * scale, first.height * scale, 44u32);
    let rows = tiles.len().div_ceil(columns) as u32;
    let size = (
        tw * columns as u32 + 8 * (columns as u32 + 1),
        (th + caption + 8) * rows + 8,
    );
    let mut buf = vec![255u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        for (i, ((label, _), img)) in tiles.iter().zip(&scaled).enumerate() {
            let (c, r) = ((i % columns) as i32, (i / columns) as i32);
            let x = 8 + c * (tw as i32 + 8);
            let y = 8 + r * (th as i32 + caption as i32 + 8);
            let (first_line, second_line) = label.split_once(", ").unwrap_or((label, ""));
            root.draw(&Text::new(
                first_line.to_string(),
                (x, y + 2),
                ("sans-serif", 16).into_font(),
            ))?;
            root.draw(&Text::new(
                second_line.to_string(),
                (x, y + 21),
                ("sans-serif", 16).into_font(),
            ))?;
            if let Some(el) = BitMapElement::<_>::with_ref((x, y + caption as i32), (img.width, img.height), &img.data)
            {
                root.draw(&el)?;
            }
        }
        root.present()?;
    }
    super::images::write_png(
        path,
        &Rgb {
            width: size.0,
            height: size.1,
            data: buf,
        },
    )
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

#[cfg(test)]
mod tests {
    #[test]
    fn ticks_read_as_written() {
        for (v, s) in [
            (0.7000000000000001, "0.7"),
            (1000000.0, "1000000"),
            (0.00001, "0.00001"),
            (12.5, "12.5"),
            (0.0, "0"),
            (-0.25, "-0.25"),
        ] {
            assert_eq!(super::tick(&v), s);
        }
    }
}
