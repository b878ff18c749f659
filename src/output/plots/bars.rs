//! Grouped bars for a categorical axis: one group per category (a mesh, say), named under the
//! axis with a note (its size), one bar per series in each group with its 95 % interval as a
//! whisker. Nothing joins the groups: unrelated categories are not a curve. Each series has its
//! own look (colour and the marker drawn at each bar's top and in the legend), so that a bar
//! is known by its shape where its colour is not told apart.

use super::legend::{self, Entry, Look};
use super::line::minor;
use super::style::{distinct, look};
use super::ticks::{axis_labels, ticks, Keyed, Scale};
use super::{error, text_width, write_figure, Figure, FONT};
use plotters::coord::combinators::LogCoord;
use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor;
use std::path::Path;

/// One bar: its series (look index, as in the series list) and value with its 95 % interval
/// (NaN ends: no whisker).
#[derive(Clone, Debug)]
pub struct Bar {
    /// Look index of its series.
    pub series: usize,
    /// Its height.
    pub value: f64,
    /// Lower end of its interval.
    pub lo: f64,
    /// Upper end of its interval.
    pub hi: f64,
}

/// One category: its name and a note under it, and its bars.
#[derive(Clone, Debug)]
pub struct Group {
    /// Name under the axis.
    pub name: String,
    /// A second line under the name (e.g. its size).
    pub note: String,
    /// Its bars, in series order.
    pub bars: Vec<Bar>,
}

const HEIGHT: u32 = 640;
const TITLE: u32 = 48;
const MARGIN: u32 = 14;
const X_LABELS: u32 = 70;
/// Room beside the widest y tick label for the axis name and the gaps around it.
const Y_NAME: u32 = TICK_FONT + 18;
/// Tick labels and group names; the notes under them; the title (plotters' sizes: a line's
/// height, 1.24 em, so 19 reads as 15.3 px at the figure's own size).
const TICK_FONT: u32 = 19;
const NOTE_FONT: u32 = 17;
const TITLE_FONT: u32 = 24;
/// The least share of the figure's width that its data area takes, however long the legend.
const DATA_SHARE: f64 = 0.6;
/// Values spread wider than this (largest over smallest) go on a log axis.
const LOG_SPREAD: f64 = 30.0;

/// Draws `groups` of bars into a PNG at `path` and an SVG beside it: `series` names each look
/// index in the legend; `y` labels the axis. The y axis starts at 0, or is logarithmic (and
/// says so) where the values spread over more than a factor of 30. Two series of one look are
/// refused.
pub fn grouped_bars(
    path: &Path,
    title: &str,
    y: &str,
    series: &[(usize, String)],
    groups: &[Group],
) -> anyhow::Result<()> {
    distinct(series.iter().map(|(i, name)| (*i, name.as_str(), 0)))?;
    write_figure(path, &Bars::new(title, y, series, groups))
}

/// A bar chart laid out.
struct Bars<'a> {
    title: &'a str,
    y_desc: String,
    groups: &'a [Group],
    log: bool,
    y: (f64, f64),
    group_px: u32,
    legend: Vec<Entry>,
    /// Height of the figure: [`HEIGHT`], or more where the legend needs it.
    height: u32,
}

impl<'a> Bars<'a> {
    fn new(title: &'a str, y: &str, series: &[(usize, String)], groups: &'a [Group]) -> Self {
        let bars = || groups.iter().flat_map(|g| &g.bars).filter(|b| b.value.is_finite());
        let smallest = bars()
            .map(|b| b.value)
            .filter(|v| *v > 0.0)
            .fold(f64::INFINITY, f64::min);
        let largest = bars()
            .flat_map(|b| [b.value, b.hi])
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let log = smallest.is_finite() && largest / smallest > LOG_SPREAD;
        let range = match (log, largest > 0.0) {
            (true, _) => (smallest / 2.0, largest * 1.3),
            (false, true) => (0.0, largest * 1.08),
            (false, false) => (0.0, 1.0),
        };
        let per_bar = 26;
        let names = groups
            .iter()
            .map(|g| text_width(&g.name, TICK_FONT).max(text_width(&g.note, NOTE_FONT)))
            .max()
            .unwrap_or(0);
        let group_px = (names + 24).max(series.len() as u32 * per_bar + 28);
        let mut legend: Vec<Entry> = series
            .iter()
            .map(|(i, name)| Entry {
                label: name.clone(),
                look: Look::Bar(look(*i)),
            })
            .collect();
        let mut chart = Bars {
            title,
            y_desc: if log { format!("{y} (log scale)") } else { y.to_string() },
            groups,
            log,
            y: range,
            group_px,
            legend: vec![],
            height: HEIGHT,
        };
        if bars().any(|b| b.lo.is_finite() && b.hi.is_finite()) {
            legend.push(Entry {
                label: "95 % interval".into(),
                look: Look::Interval,
            });
        }
        if bars().any(|b| chart.clipped(b.lo, b.hi) != (false, false)) {
            legend.push(Entry {
                label: "interval beyond the axis".into(),
                look: Look::Clipped,
            });
        }
        chart.height = HEIGHT.max(TITLE + legend::height(&legend));
        chart.legend = legend;
        chart
    }

    /// Width of the chart left of the legend: room for the bars and the title, and for the data
    /// to take [`DATA_SHARE`] of the figure beside however wide a legend.
    fn chart_width(&self) -> u32 {
        let labels = 2 * MARGIN + self.y_labels();
        let bars = labels + (self.group_px * self.groups.len() as u32).max(560);
        let legend = legend::width(&self.legend, self.height - TITLE) as f64;
        let share = ((labels as f64 + DATA_SHARE * legend) / (1.0 - DATA_SHARE)).ceil() as u32;
        bars.max(share).max(text_width(self.title, TITLE_FONT) + 2 * MARGIN)
    }

    /// The labelled values of the y axis.
    fn y_ticks(&self) -> Vec<f64> {
        let height = (self.height - TITLE - 2 * MARGIN - X_LABELS) as f64;
        let up = |_: &str| TICK_FONT as f64 + 4.0;
        let scale = Scale {
            log: self.log,
            whole: false,
        };
        ticks(self.y.0, self.y.1, scale, height, &up)
    }

    /// Width of the y axis's labels: the widest tick label and the axis name.
    fn y_labels(&self) -> u32 {
        let ticks = self.y_ticks();
        let label = axis_labels(&ticks);
        ticks
            .iter()
            .map(|v| text_width(&label(v), TICK_FONT))
            .max()
            .unwrap_or(0)
            + Y_NAME
    }

    /// Whether an interval lo..hi runs past the bottom and the top of the y range.
    fn clipped(&self, lo: f64, hi: f64) -> (bool, bool) {
        (
            lo.is_finite() && (lo < self.y.0 || (self.log && lo <= 0.0)),
            hi.is_finite() && hi > self.y.1,
        )
    }

    fn chart<DB: DrawingBackend, Y>(&self, root: &DrawingArea<DB, Shift>, y: Keyed<Y>) -> anyhow::Result<()>
    where
        Y: Ranged<ValueType = f64>,
        DB::ErrorType: 'static,
    {
        let y_labels = y.labels();
        let (area, _) = root.split_horizontally(self.chart_width());
        let area = area.titled(self.title, (FONT, TITLE_FONT)).map_err(error)?;
        let n = self.groups.len().max(1) as f64;
        let mut chart = ChartBuilder::on(&area)
            .margin(MARGIN)
            .x_label_area_size(X_LABELS)
            .y_label_area_size(self.y_labels())
            .build_cartesian_2d(Keyed::<RangedCoordf64>::new(0.0..n, vec![], vec![]), y)
            .map_err(error)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .y_desc(self.y_desc.as_str())
            .y_label_formatter(&y_labels)
            .label_style((FONT, TICK_FONT))
            .axis_desc_style((FONT, TICK_FONT))
            .draw()
            .map_err(error)?;
        let (_, ys) = chart.plotting_area().get_pixel_range();
        let bottom = ys.end - 1;
        let px = |x: f64, v: f64| chart.backend_coord(&(x, v));
        for (i, g) in self.groups.iter().enumerate() {
            let (mid, _) = px(i as f64 + 0.5, self.y.0);
            let top = |size| {
                TextStyle::from((FONT, size).into_font())
                    .pos(text_anchor::Pos::new(text_anchor::HPos::Center, text_anchor::VPos::Top))
            };
            root.draw(&Text::new(g.name.clone(), (mid, bottom + 8), top(TICK_FONT)))
                .map_err(error)?;
            root.draw(&Text::new(g.note.clone(), (mid, bottom + 34), top(NOTE_FONT)))
                .map_err(error)?;
            let k = g.bars.len().max(1) as f64;
            let width = 0.76 / k;
            for (j, b) in g.bars.iter().enumerate() {
                let x0 = i as f64 + 0.12 + j as f64 * width;
                let (left, right) = (px(x0, self.y.0).0 + 1, px(x0 + width, self.y.0).0 - 1);
                let column = (left + right) / 2;
                if b.value.is_finite() && (!self.log || b.value > 0.0) {
                    let top = px(x0, b.value.min(self.y.1)).1;
                    legend::bar(root, (left, top, right, bottom), look(b.series))?;
                    legend::bar_marker(root, (column, top), look(b.series))?;
                }
                // The whisker over the marker, so that a short interval is not hidden under it.
                if b.lo.is_finite() && b.hi.is_finite() {
                    let (clip_lo, clip_hi) = self.clipped(b.lo, b.hi);
                    let low = if clip_lo { bottom } else { px(x0, b.lo).1 };
                    let high = if clip_hi { ys.start } else { px(x0, b.hi).1 };
                    legend::interval(root, column, (low, clip_lo), (high, clip_hi))?;
                }
            }
        }
        legend::draw(
            root,
            &self.legend,
            (self.chart_width() as i32, ys.start - 10),
            self.height - TITLE,
        )
    }
}

impl Figure for Bars<'_> {
    fn size(&self) -> (u32, u32) {
        (
            self.chart_width() + legend::width(&self.legend, self.height - TITLE),
            self.height,
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let (y0, y1) = self.y;
        let yt = self.y_ticks();
        let yl = minor(y0, y1, self.log);
        if self.log {
            let y: Keyed<LogCoord<f64>> = Keyed::new((y0..y1).log_scale(), yt, yl);
            self.chart(root, y)
        } else {
            self.chart(root, Keyed::<RangedCoordf64>::new(y0..y1, yt, yl))
        }
    }
}
