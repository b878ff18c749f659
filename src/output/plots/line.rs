//! Line plots: series with markers and 95 % interval whiskers, and reference lines (exact
//! answers, a paper's numbers), on linear or logarithmic axes; as one panel ([`line_plot`]) or
//! as small multiples ([`line_panels`]): panels side by side on shared axis ranges with one
//! legend, so that no panel carries more lines than a reader can follow.

use super::legend::{self, Entry, Look as Sample};
use super::style::{colour, distinct, draw_line, draw_marker, look, reference_dash, within, DASH, MARKER_RADIUS};
use super::ticks::{axis_labels, ticks, Keyed, Scale};
use super::{error, text_width, write_figure, Figure, FONT};
use plotters::coord::ranged1d::Ranged;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// One point of a series: where it lies and the ends of its interval (NaN: none drawn).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// Lower end of its interval.
    pub lo: f64,
    /// Upper end of its interval.
    pub hi: f64,
}

impl Point {
    /// A point without an interval (one deterministic value, or one measurement).
    pub fn bare(x: f64, y: f64) -> Point {
        Point {
            x,
            y,
            lo: f64::NAN,
            hi: f64::NAN,
        }
    }

    /// A mean with its interval's half-width (NaN: none).
    pub fn ci(x: f64, y: f64, half: f64) -> Point {
        Point {
            x,
            y,
            lo: y - half,
            hi: y + half,
        }
    }

    /// A value with an interval that need not be symmetric (a median's order statistics).
    pub fn between(x: f64, y: f64, lo: f64, hi: f64) -> Point {
        Point { x, y, lo, hi }
    }

    /// Its interval, where it has one wider than nothing.
    fn interval(&self) -> Option<(f64, f64)> {
        (self.lo.is_finite() && self.hi.is_finite() && self.hi > self.lo).then_some((self.lo, self.hi))
    }
}

/// One line of a plot.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label.
    pub name: String,
    /// Index of its look (colour, marker and dashes together, [`super::style::look`]): a caller
    /// gives a thing (a scheme, a structure) one index in every plot, so it keeps its look.
    pub look: usize,
    /// Points.
    pub points: Vec<Point>,
}

/// A reference line (e.g. the exact penumbra width).
#[derive(Clone, Debug)]
pub struct Reference {
    /// Legend label.
    pub name: String,
    /// Either one y for all x, or a curve of (x, y).
    pub points: Vec<(f64, f64)>,
    /// Look index of the series it belongs to, whose colour it takes, or none: dark grey.
    pub colour: Option<usize>,
}

/// One panel of small multiples: its title (what sets it apart) and its series.
#[derive(Clone, Debug)]
pub struct Panel {
    /// Title over the panel.
    pub title: String,
    /// Its series.
    pub series: Vec<Series>,
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
    /// What the whiskers are, as the legend names them.
    pub interval: &'a str,
}

impl<'a> Axes<'a> {
    /// Axes with data-driven ranges whose whiskers are 95 % intervals.
    pub fn new(title: &'a str, x: &'a str, y: &'a str, log_x: bool, log_y: bool) -> Self {
        Axes {
            title,
            x,
            y,
            log_x,
            log_y,
            x_range: None,
            interval: "95 % interval",
        }
    }
}

/// Width of the whole figure, panels and legend, where the legend, the data's share and the
/// title leave it so: about the width a page shows a figure at.
const FIGURE: u32 = 1280;
/// Width of the panels together, left of the legend, at the least.
const WIDTH: u32 = 760;
/// Height of a row of panels when there is one row, and when there are more.
const ROW: u32 = 600;
const SHORT_ROW: u32 = 470;
/// Title, panel title, margin and label areas around a data area, pixels.
const TITLE: u32 = 48;
const SUBTITLE: u32 = 34;
const MARGIN: u32 = 14;
const X_LABELS: u32 = 60;
/// Room beside the widest y tick label for the axis name and the gaps around it.
const Y_NAME: u32 = TICK_FONT + 18;
/// Text size of tick labels and axis names, of a panel's title and of the figure's title, as
/// plotters sizes text: a line's height, the em being 1/1.24 of it (so 19 reads as 15.3 px,
/// legible where a page shows the figure at its own size).
const TICK_FONT: u32 = 19;
const SUBTITLE_FONT: u32 = 22;
const TITLE_FONT: u32 = 24;
/// The least share of the figure's width that its data areas take, however long the legend.
const DATA_SHARE: f64 = 0.6;
/// Reference lines without a series colour.
const REFERENCE_GREY: RGBColor = RGBColor(40, 40, 40);

/// Draws `series` and `references` as one panel into a PNG at `path` and an SVG beside it;
/// refuses two series of one look.
pub fn line_plot(path: &Path, axes: &Axes, series: &[Series], references: &[Reference]) -> anyhow::Result<()> {
    write_figure(path, &LinePlot::new(axes, vec![("", series)], references)?)
}

/// Draws `panels` as small multiples into a PNG at `path` and an SVG beside it: side by side
/// (two columns from three panels on, three from five), every panel on the same axis ranges
/// with the `references` drawn in each, and one legend naming each series once. A series keeps
/// its look from panel to panel; two series of one look in a panel, or two names for one look,
/// are refused. One panel is drawn as [`line_plot`] draws it.
pub fn line_panels(path: &Path, axes: &Axes, panels: &[Panel], references: &[Reference]) -> anyhow::Result<()> {
    let panels: Vec<(&str, &[Series])> = match panels {
        [one] => vec![("", one.series.as_slice())],
        _ => panels.iter().map(|p| (p.title.as_str(), p.series.as_slice())).collect(),
    };
    write_figure(path, &LinePlot::new(axes, panels, references)?)
}

/// A line plot laid out: its panels, shared ranges, legend and size.
struct LinePlot<'a> {
    axes: &'a Axes<'a>,
    panels: Vec<(&'a str, &'a [Series])>,
    references: &'a [Reference],
    x: (f64, f64),
    y: (f64, f64),
    /// Labelled and light values of each axis.
    x_ticks: (Vec<f64>, Vec<f64>),
    y_ticks: (Vec<f64>, Vec<f64>),
    legend: Vec<Entry>,
    columns: usize,
    rows: usize,
    /// Width of the panels together; width of a panel's y labels (ticks and axis name); height
    /// of a panel's chart and of its title.
    width: u32,
    y_labels: u32,
    panel_height: u32,
    subtitle: u32,
}

impl<'a> LinePlot<'a> {
    fn new(axes: &'a Axes, panels: Vec<(&'a str, &'a [Series])>, references: &'a [Reference]) -> anyhow::Result<Self> {
        distinct(
            panels
                .iter()
                .enumerate()
                .flat_map(|(k, (_, ss))| ss.iter().map(move |s| (s.look, s.name.as_str(), k))),
        )?;
        let all = || panels.iter().flat_map(|(_, ss)| ss.iter());
        let ok = |x: f64, y: f64| {
            x.is_finite()
                && y.is_finite()
                && (!axes.log_x || x > 0.0)
                && (!axes.log_y || y > 0.0)
                && axes.x_range.is_none_or(|(a, b)| x >= a && x <= b)
        };
        let points: Vec<(f64, f64)> = all()
            .flat_map(|s| s.points.iter().map(|p| (p.x, p.y)))
            .chain(references.iter().flat_map(|r| r.points.iter().copied()))
            .filter(|&(x, y)| ok(x, y))
            .collect();
        let lowest = points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        let highest = points.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
        // Interval ends widen the range by up to half the points' span (a decade on a log axis)
        // each way, so that one wide interval (a slow render among three) does not flatten
        // every line; an end past that, or at or below zero on a log axis, is clipped and
        // marked.
        let span = highest - lowest;
        let reach = |y: f64| {
            if axes.log_y {
                y >= lowest / 10.0 && y <= highest * 10.0
            } else {
                y >= lowest - 0.5 * span && y <= highest + 0.5 * span
            }
        };
        let shown_ends: Vec<(f64, f64)> = all()
            .flat_map(|s| s.points.iter())
            .filter(|p| ok(p.x, p.y))
            .filter_map(|p| p.interval().map(|(lo, hi)| [(p.x, lo), (p.x, hi)]))
            .flatten()
            .filter(|&(x, y)| ok(x, y) && ((span == 0.0 && !axes.log_y) || reach(y)))
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
        let n = panels.len().max(1);
        let columns = match n {
            1 | 2 => n,
            3 | 4 => 2,
            _ => 3,
        };
        let rows = n.div_ceil(columns);
        let mut plot = LinePlot {
            axes,
            panels,
            references,
            x,
            y,
            x_ticks: (vec![], vec![]),
            y_ticks: (vec![], vec![]),
            legend: vec![],
            columns,
            rows,
            width: 0,
            y_labels: 0,
            panel_height: 0,
            subtitle: 0,
        };
        plot.legend = plot.entries();
        plot.subtitle = if plot.panels.iter().any(|(t, _)| !t.is_empty()) {
            SUBTITLE
        } else {
            0
        };
        let row = if rows == 1 { ROW } else { SHORT_ROW };
        // A legend too long for the figure makes the panels taller, never a second column.
        let room = rows as u32 * (row + plot.subtitle) - plot.legend_offset();
        let need = legend::height(&plot.legend).saturating_sub(room);
        plot.panel_height = row + need.div_ceil(rows as u32);
        let up = |_: &str| TICK_FONT as f64 + 4.0;
        let y_scale = Scale {
            log: axes.log_y,
            whole: false,
        };
        let (_, h) = plot.data_size();
        plot.y_ticks = (ticks(y.0, y.1, y_scale, h, &up), minor(y.0, y.1, axes.log_y));
        let label = axis_labels(&plot.y_ticks.0);
        let widest = plot.y_ticks.0.iter().map(|v| text_width(&label(v), TICK_FONT)).max();
        plot.y_labels = widest.unwrap_or(0) + Y_NAME;
        let legend_width = legend::width(&plot.legend, plot.legend_room()) as f64;
        let labels = (columns as u32 * (plot.y_labels + 2 * MARGIN)) as f64;
        let widest_subtitle = plot
            .panels
            .iter()
            .map(|(t, _)| text_width(t, SUBTITLE_FONT) + 2 * MARGIN)
            .max()
            .unwrap_or(0);
        plot.width = WIDTH
            .max(FIGURE.saturating_sub(legend_width as u32))
            .max(((labels + DATA_SHARE * legend_width) / (1.0 - DATA_SHARE)).ceil() as u32)
            .max(text_width(axes.title, TITLE_FONT) + 2 * MARGIN)
            .max(columns as u32 * widest_subtitle);
        let (w, _) = plot.data_size();
        let across = |text: &str| text_width(text, TICK_FONT) as f64;
        let x_scale = Scale {
            log: axes.log_x,
            whole: points.iter().all(|p| p.0.fract() == 0.0),
        };
        plot.x_ticks = (ticks(x.0, x.1, x_scale, w, &across), minor(x.0, x.1, axes.log_x));
        Ok(plot)
    }

    /// Every series of every panel.
    fn series(&self) -> impl Iterator<Item = &Series> {
        self.panels.iter().flat_map(|(_, ss)| ss.iter())
    }

    /// Height of the figure.
    fn height(&self) -> u32 {
        TITLE + self.rows as u32 * (self.subtitle + self.panel_height)
    }

    /// How far below the title the legend starts: level with the top of the first data area.
    fn legend_offset(&self) -> u32 {
        self.subtitle + MARGIN - 10
    }

    /// Height of the legend's column.
    fn legend_room(&self) -> u32 {
        self.height() - TITLE - self.legend_offset()
    }

    /// Width and height in pixels of one panel's data area (about: plotters lays it out).
    fn data_size(&self) -> (f64, f64) {
        (
            (self.width / self.columns as u32).saturating_sub(2 * MARGIN + self.y_labels) as f64,
            self.panel_height.saturating_sub(2 * MARGIN + X_LABELS) as f64,
        )
    }

    /// The legend: every series once (in look order) and every reference, then what whiskers
    /// and carets mean where drawn.
    fn entries(&self) -> Vec<Entry> {
        let mut series: Vec<&Series> = Vec::new();
        for s in self.series() {
            if !series.iter().any(|t| t.look == s.look && t.name == s.name) {
                series.push(s);
            }
        }
        series.sort_by_key(|s| s.look);
        let mut out: Vec<Entry> = series
            .iter()
            .map(|s| {
                let l = look(s.look);
                let on_axis = self
                    .series()
                    .filter(|t| t.look == s.look)
                    .flat_map(|t| &t.points)
                    .any(|p| self.plottable(p.x, p.y));
                Entry {
                    label: if on_axis {
                        s.name.clone()
                    } else {
                        format!("{} (no point on this axis)", s.name)
                    },
                    look: Sample::Line {
                        colour: l.colour,
                        dash: l.dashed.then_some(DASH),
                        marker: Some((l.marker, !l.dashed)),
                    },
                }
            })
            .collect();
        out.extend(self.references.iter().enumerate().map(|(i, r)| Entry {
            label: r.name.clone(),
            look: Sample::Line {
                colour: r.colour.map_or(REFERENCE_GREY, colour),
                dash: Some(reference_dash(i)),
                marker: None,
            },
        }));
        let intervals: Vec<(f64, f64)> = self
            .series()
            .flat_map(|s| s.points.iter())
            .filter(|p| p.y.is_finite())
            .filter_map(Point::interval)
            .collect();
        if !intervals.is_empty() {
            out.push(Entry {
                label: self.axes.interval.into(),
                look: Sample::Interval,
            });
        }
        if intervals.iter().any(|&(lo, hi)| self.clipped(lo, hi) != (false, false)) {
            out.push(Entry {
                label: "interval beyond the axis".into(),
                look: Sample::Clipped,
            });
        }
        out
    }

    /// Whether a point at (x, y) can be drawn on these axes (a log axis has no place for 0).
    fn plottable(&self, x: f64, y: f64) -> bool {
        x.is_finite()
            && y.is_finite()
            && (!self.axes.log_x || x > 0.0)
            && (!self.axes.log_y || y > 0.0)
            && self.axes.x_range.is_none_or(|(a, b)| x >= a && x <= b)
    }

    /// Whether an interval lo..hi runs past the bottom and the top of the y range.
    fn clipped(&self, lo: f64, hi: f64) -> (bool, bool) {
        (lo < self.y.0 || (self.axes.log_y && lo <= 0.0), hi > self.y.1)
    }

    /// Draws one panel's `series` on `area` (the panel's part of `root`), on the figure's axes.
    fn panel<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        area: &DrawingArea<DB, Shift>,
        series: &[Series],
    ) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        use plotters::coord::types::RangedCoordf64;
        type Log = plotters::coord::combinators::LogCoord<f64>;
        let linear = |(a, b): (f64, f64), (t, l): &(Vec<f64>, Vec<f64>)| {
            Keyed::<RangedCoordf64>::new(a..b, t.clone(), l.clone())
        };
        let log = |(a, b): (f64, f64), (t, l): &(Vec<f64>, Vec<f64>)| {
            Keyed::<Log>::new((a..b).log_scale(), t.clone(), l.clone())
        };
        let (x, y) = (&self.x_ticks, &self.y_ticks);
        match (self.axes.log_x, self.axes.log_y) {
            (false, false) => self.chart(root, area, series, linear(self.x, x), linear(self.y, y)),
            (true, false) => self.chart(root, area, series, log(self.x, x), linear(self.y, y)),
            (false, true) => self.chart(root, area, series, linear(self.x, x), log(self.y, y)),
            (true, true) => self.chart(root, area, series, log(self.x, x), log(self.y, y)),
        }
    }

    /// Draws `series` and the references on `area` with the given x and y coordinates.
    fn chart<DB: DrawingBackend, X, Y>(
        &self,
        root: &DrawingArea<DB, Shift>,
        area: &DrawingArea<DB, Shift>,
        series: &[Series],
        x: Keyed<X>,
        y: Keyed<Y>,
    ) -> anyhow::Result<()>
    where
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
        DB::ErrorType: 'static,
    {
        let (x_labels, y_labels) = (x.labels(), y.labels());
        let mut chart = ChartBuilder::on(area)
            .margin(MARGIN)
            .x_label_area_size(X_LABELS)
            .y_label_area_size(self.y_labels)
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
        for s in series {
            for (p, (lo, hi)) in s
                .points
                .iter()
                .filter(|p| valid(p.x, p.y))
                .filter_map(|p| Some((p, p.interval()?)))
            {
                let (column, _) = px(p.x, p.y);
                if column < rect.0 || column > rect.2 {
                    continue;
                }
                let (clip_lo, clip_hi) = self.clipped(lo, hi);
                let low = if clip_lo { ys.end - 1 } else { px(p.x, lo).1 };
                let high = if clip_hi { ys.start } else { px(p.x, hi).1 };
                legend::interval(root, column, (low, clip_lo), (high, clip_hi))?;
            }
        }
        for s in series {
            let l = look(s.look);
            let line: Vec<(i32, i32)> = s
                .points
                .iter()
                .filter(|p| valid(p.x, p.y))
                .map(|p| px(p.x, p.y))
                .collect();
            draw_line(root, &line, rect, l.colour, l.dashed.then_some(DASH))?;
            for &p in line.iter().filter(|p| within(**p, rect)) {
                draw_marker(root, p, l.marker, MARKER_RADIUS, l.colour, !l.dashed)?;
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
        Ok(())
    }
}

impl Figure for LinePlot<'_> {
    fn size(&self) -> (u32, u32) {
        let height = self.height();
        (self.width + legend::width(&self.legend, self.legend_room()), height)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let (left, _) = root.split_horizontally(self.width);
        let centred = |size: u32| TextStyle::from((FONT, size).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
        left.draw(&Text::new(
            self.axes.title.to_string(),
            ((self.width / 2) as i32, (TITLE / 2) as i32),
            centred(TITLE_FONT),
        ))
        .map_err(error)?;
        let grid = left.margin(TITLE, 0, 0, 0).split_evenly((self.rows, self.columns));
        for (&(title, series), area) in self.panels.iter().zip(&grid) {
            let area = if self.subtitle > 0 {
                let (w, _) = area.dim_in_pixel();
                area.draw(&Text::new(
                    title.to_string(),
                    ((w / 2) as i32, (self.subtitle / 2) as i32),
                    centred(SUBTITLE_FONT),
                ))
                .map_err(error)?;
                area.margin(self.subtitle, 0, 0, 0)
            } else {
                area.clone()
            };
            self.panel(root, &area, series)?;
        }
        let top = (TITLE + self.legend_offset()) as i32;
        legend::draw(root, &self.legend, (self.width as i32, top), self.legend_room())
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
