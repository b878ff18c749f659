//! Line plots: series with markers and 95 % interval whiskers, and reference lines (exact
//! answers, a paper's numbers), on linear or logarithmic axes.

use super::legend::{self, Entry, Look};
use super::style::{colour, draw_line, draw_marker, marker, reference_dash, within, DASH};
use super::ticks::{ticks, Keyed, Scale};
use super::{error, text_width, write_figure, Figure, FONT};
use plotters::coord::ranged1d::Ranged;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One line of a plot: points (x, y, 95 % CI half-width or NaN).
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label.
    pub name: String,
    /// Points.
    pub points: Vec<(f64, f64, f64)>,
    /// Dashed with outlined markers (e.g. the shared pattern), or solid with filled ones.
    pub dashed: bool,
}

/// A reference line (e.g. the exact penumbra width).
#[derive(Clone, Debug)]
pub struct Reference {
    /// Legend label.
    pub name: String,
    /// Either one y for all x, or a curve of (x, y).
    pub points: Vec<(f64, f64)>,
    /// Colour of the series it belongs to (see [`colour`]), or dark grey.
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
}

impl<'a> Axes<'a> {
    /// Axes with data-driven ranges.
    pub fn new(title: &'a str, x: &'a str, y: &'a str, log_x: bool, log_y: bool) -> Self {
        Axes {
            title,
            x,
            y,
            log_x,
            log_y,
            x_range: None,
        }
    }
}

/// Size of the chart left of the legend.
const CHART: (u32, u32) = (960, 640);
/// Title, margin and label areas around the data area, pixels.
const TITLE: u32 = 44;
const MARGIN: u32 = 14;
const X_LABELS: u32 = 48;
const Y_LABELS: u32 = 84;
/// Text size of tick labels and of the title.
const TICK_FONT: u32 = 15;
const TITLE_FONT: u32 = 22;
/// Reference lines without a series colour.
const REFERENCE_GREY: RGBColor = RGBColor(40, 40, 40);

/// Draws `series` (each with its palette index) and `references` into a PNG at `path` and an SVG
/// beside it.
pub fn line_plot(path: &Path, axes: &Axes, series: &[(usize, Series)], references: &[Reference]) -> anyhow::Result<()> {
    write_figure(path, &LinePlot::new(axes, series, references))
}

/// A line plot laid out: its ranges and legend.
struct LinePlot<'a> {
    axes: &'a Axes<'a>,
    series: &'a [(usize, Series)],
    references: &'a [Reference],
    x: (f64, f64),
    y: (f64, f64),
    /// Every x of the data is a whole number.
    whole_x: bool,
    legend: Vec<Entry>,
}

impl<'a> LinePlot<'a> {
    fn new(axes: &'a Axes, series: &'a [(usize, Series)], references: &'a [Reference]) -> Self {
        let ok = |x: f64, y: f64| {
            x.is_finite()
                && y.is_finite()
                && (!axes.log_x || x > 0.0)
                && (!axes.log_y || y > 0.0)
                && axes.x_range.is_none_or(|(a, b)| x >= a && x <= b)
        };
        let points: Vec<(f64, f64)> = series
            .iter()
            .flat_map(|(_, s)| s.points.iter().map(|p| (p.0, p.1)))
            .chain(references.iter().flat_map(|r| r.points.iter().copied()))
            .filter(|&(x, y)| ok(x, y))
            .collect();
        let lowest = points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        // Interval ends widen the range, except a lower end at or below zero, or more than a
        // decade below the lowest point, on a log axis: that interval is clipped and marked.
        let ends = series.iter().flat_map(|(_, s)| {
            s.points
                .iter()
                .filter(|p| p.2.is_finite() && p.2 > 0.0 && ok(p.0, p.1))
                .flat_map(|p| [(p.0, p.1 - p.2), (p.0, p.1 + p.2)])
        });
        let shown_ends: Vec<(f64, f64)> = ends
            .filter(|&(x, y)| ok(x, y) && (!axes.log_y || y >= lowest / 10.0))
            .collect();
        let range = |v: &mut dyn Iterator<Item = f64>, log: bool| -> (f64, f64) {
            let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
            if !lo.is_finite() {
                return (1.0, 2.0);
            }
            let single = hi - lo <= 1e-9 * hi.abs().max(lo.abs());
            match (log, single) {
                // One value: a range around it, so that the axis still has labels.
                (true, true) => (lo / 2.0, hi * 2.0),
                (false, true) if lo == 0.0 => (-1.0, 1.0),
                (false, true) => (lo - 0.2 * lo.abs(), hi + 0.2 * hi.abs()),
                (true, false) => (lo / 1.3, hi * 1.3),
                (false, false) => (lo - 0.06 * (hi - lo), hi + 0.06 * (hi - lo)),
            }
        };
        let x = axes
            .x_range
            .unwrap_or_else(|| range(&mut points.iter().map(|p| p.0), axes.log_x));
        let y = range(&mut points.iter().chain(&shown_ends).map(|p| p.1), axes.log_y);
        let mut plot = LinePlot {
            axes,
            series,
            references,
            x,
            y,
            whole_x: points.iter().all(|p| p.0.fract() == 0.0),
            legend: vec![],
        };
        plot.legend = plot.entries();
        plot
    }

    /// The legend: every series and reference, then what whiskers and carets mean where drawn.
    fn entries(&self) -> Vec<Entry> {
        let mut out: Vec<Entry> = self
            .series
            .iter()
            .map(|(ci, s)| Entry {
                label: s.name.clone(),
                look: Look::Line {
                    colour: colour(*ci),
                    dash: s.dashed.then_some(DASH),
                    marker: Some((marker(*ci), !s.dashed)),
                },
            })
            .collect();
        out.extend(self.references.iter().enumerate().map(|(i, r)| Entry {
            label: r.name.clone(),
            look: Look::Line {
                colour: r.colour.map_or(REFERENCE_GREY, colour),
                dash: Some(reference_dash(i)),
                marker: None,
            },
        }));
        let intervals: Vec<(f64, f64)> = self
            .series
            .iter()
            .flat_map(|(_, s)| s.points.iter())
            .filter(|p| p.1.is_finite() && p.2.is_finite() && p.2 > 0.0)
            .map(|p| (p.1 - p.2, p.1 + p.2))
            .collect();
        if !intervals.is_empty() {
            out.push(Entry {
                label: "95 % interval".into(),
                look: Look::Interval,
            });
        }
        if intervals.iter().any(|&(lo, hi)| self.clipped(lo, hi) != (false, false)) {
            out.push(Entry {
                label: "interval beyond the axis".into(),
                look: Look::Clipped,
            });
        }
        out
    }

    /// Whether an interval lo..hi runs past the bottom and the top of the y range.
    fn clipped(&self, lo: f64, hi: f64) -> (bool, bool) {
        (lo < self.y.0 || (self.axes.log_y && lo <= 0.0), hi > self.y.1)
    }

    /// Draws the chart on `area` with the given x and y coordinates.
    fn chart<DB: DrawingBackend, X, Y>(
        &self,
        root: &DrawingArea<DB, Shift>,
        x: Keyed<X>,
        y: Keyed<Y>,
    ) -> anyhow::Result<()>
    where
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
        DB::ErrorType: 'static,
    {
        let (x_labels, y_labels) = (x.labels(), y.labels());
        let (area, _) = root.split_horizontally(self.chart_width());
        let area = area.titled(self.axes.title, (FONT, TITLE_FONT)).map_err(error)?;
        let mut chart = ChartBuilder::on(&area)
            .margin(MARGIN)
            .x_label_area_size(X_LABELS)
            .y_label_area_size(Y_LABELS)
            .build_cartesian_2d(x, y)
            .map_err(error)?;
        chart
            .configure_mesh()
            .x_desc(self.axes.x)
            .y_desc(self.axes.y)
            .x_label_formatter(&x_labels)
            .y_label_formatter(&y_labels)
            .label_style((FONT, TICK_FONT))
            .axis_desc_style((FONT, TICK_FONT))
            .draw()
            .map_err(error)?;
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        let rect = (xs.start, ys.start, xs.end - 1, ys.end - 1);
        let px = |x: f64, y: f64| chart.backend_coord(&(x, y));
        let log = (self.axes.log_x, self.axes.log_y);
        let valid = |x: f64, y: f64| x.is_finite() && y.is_finite() && (!log.0 || x > 0.0) && (!log.1 || y > 0.0);
        for (_, s) in self.series {
            for p in s
                .points
                .iter()
                .filter(|p| valid(p.0, p.1) && p.2.is_finite() && p.2 > 0.0)
            {
                let (column, _) = px(p.0, p.1);
                if column < rect.0 || column > rect.2 {
                    continue;
                }
                let (lo, hi) = (p.1 - p.2, p.1 + p.2);
                let (clip_lo, clip_hi) = self.clipped(lo, hi);
                let low = if clip_lo { ys.end - 1 } else { px(p.0, lo).1 };
                let high = if clip_hi { ys.start } else { px(p.0, hi).1 };
                legend::interval(root, column, (low, clip_lo), (high, clip_hi))?;
            }
        }
        for (ci, s) in self.series {
            let c = colour(*ci);
            let line: Vec<(i32, i32)> = s
                .points
                .iter()
                .filter(|p| valid(p.0, p.1))
                .map(|p| px(p.0, p.1))
                .collect();
            draw_line(root, &line, rect, c, s.dashed.then_some(DASH))?;
            for &p in line.iter().filter(|p| within(**p, rect)) {
                draw_marker(root, p, marker(*ci), 4, c, !s.dashed)?;
            }
        }
        for (i, r) in self.references.iter().enumerate() {
            let mut line: Vec<(i32, i32)> = r
                .points
                .iter()
                .filter(|p| valid(p.0, p.1))
                .map(|p| px(p.0, p.1))
                .collect();
            if let [(x, y)] = line[..] {
                // A reference at one x: a level mark across it.
                line = vec![(x - 24, y), (x + 24, y)];
            }
            let c = r.colour.map_or(REFERENCE_GREY, colour);
            draw_line(root, &line, rect, c, Some(reference_dash(i)))?;
        }
        legend::draw(
            root,
            &self.legend,
            (self.chart_width() as i32, ys.start - 10),
            CHART.1 - TITLE,
        )
    }
}

impl LinePlot<'_> {
    /// Width of the chart left of the legend: wide enough for its title.
    fn chart_width(&self) -> u32 {
        CHART.0.max(text_width(self.axes.title, TITLE_FONT) + 2 * MARGIN)
    }
}

impl Figure for LinePlot<'_> {
    fn size(&self) -> (u32, u32) {
        (
            self.chart_width() + legend::width(&self.legend, CHART.1 - TITLE),
            CHART.1,
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let width = (self.chart_width() - 2 * MARGIN - Y_LABELS) as f64;
        let height = (CHART.1 - TITLE - 2 * MARGIN - X_LABELS) as f64;
        let across = |text: &str| text_width(text, TICK_FONT) as f64;
        let up = |_: &str| TICK_FONT as f64 + 4.0;
        let (x0, x1) = self.x;
        let (y0, y1) = self.y;
        let x_scale = Scale {
            log: self.axes.log_x,
            whole: self.whole_x,
        };
        let y_scale = Scale {
            log: self.axes.log_y,
            whole: false,
        };
        let xt = ticks(x0, x1, x_scale, width, &across);
        let yt = ticks(y0, y1, y_scale, height, &up);
        let (xl, yl) = (minor(x0, x1, self.axes.log_x), minor(y0, y1, self.axes.log_y));
        use plotters::coord::types::RangedCoordf64;
        type Log = plotters::coord::combinators::LogCoord<f64>;
        let linear = |(a, b): (f64, f64), t, l| Keyed::<RangedCoordf64>::new(a..b, t, l);
        let log = |(a, b): (f64, f64), t, l| Keyed::<Log>::new((a..b).log_scale(), t, l);
        match (self.axes.log_x, self.axes.log_y) {
            (false, false) => self.chart(root, linear(self.x, xt, xl), linear(self.y, yt, yl)),
            (true, false) => self.chart(root, log(self.x, xt, xl), linear(self.y, yt, yl)),
            (false, true) => self.chart(root, linear(self.x, xt, xl), log(self.y, yt, yl)),
            (true, true) => self.chart(root, log(self.x, xt, xl), log(self.y, yt, yl)),
        }
    }
}

/// The light grid lines of an axis: every 1..9 of each decade on a log axis, none on a linear
/// one.
pub(super) fn minor(lo: f64, hi: f64, log: bool) -> Vec<f64> {
    if !log || lo <= 0.0 || hi.is_nan() || hi <= lo {
        return vec![];
    }
    let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    (d0..=d1)
        .flat_map(|e| (1..10).map(move |m| m as f64 * 10f64.powi(e)))
        .filter(|v| *v >= lo && *v <= hi)
        .collect()
}
