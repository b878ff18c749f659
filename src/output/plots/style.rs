//! How series look: a colour-blind-safe palette, a marker shape per series as a second channel
//! beside colour, and dashes drawn the same way in the data and in the legend.

use super::error;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Okabe and Ito's colour-blind-safe palette (2008), less its yellow (too pale on white) and
/// its black (kept for reference lines): blue, vermillion, bluish green, reddish purple, orange,
/// sky blue.
const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// Colour of the i-th series (series of one scheme share a colour across plots).
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// A point marker's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Marker {
    /// A disc.
    Circle,
    /// A square.
    Square,
    /// A triangle pointing up.
    Triangle,
    /// A diamond.
    Diamond,
    /// A triangle pointing down.
    Wedge,
}

const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Square,
    Marker::Triangle,
    Marker::Diamond,
    Marker::Wedge,
];

/// Marker of the i-th series: five shapes against six colours, so the first thirty series
/// differ in colour or shape or both, and two series of one colour never share a shape.
pub fn marker(i: usize) -> Marker {
    MARKERS[i % MARKERS.len()]
}

/// Dashes of a dashed series (pixels on, pixels off).
pub const DASH: (u32, u32) = (9, 5);

/// Dashes of the i-th reference line: longer than a series' and different for the first four.
pub fn reference_dash(i: usize) -> (u32, u32) {
    (14 + 4 * (i as u32).min(3), 6)
}

/// The pieces of a pixel polyline drawn with `dash` (on, off), the pattern running on across
/// its corners; `None` gives the whole line as one piece.
pub fn dashes(points: &[(i32, i32)], dash: Option<(u32, u32)>) -> Vec<Vec<(i32, i32)>> {
    let Some((on, off)) = dash else {
        return vec![points.to_vec()];
    };
    let (on, period) = (on as f64, (on + off) as f64);
    let mut out: Vec<Vec<(i32, i32)>> = Vec::new();
    let mut phase = 0.0; // distance into the current period
    let mut current: Vec<(i32, i32)> = Vec::new();
    for w in points.windows(2) {
        let (a, b) = ((w[0].0 as f64, w[0].1 as f64), (w[1].0 as f64, w[1].1 as f64));
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        let at = |t: f64| {
            let f = if len > 0.0 { t / len } else { 0.0 };
            (
                (a.0 + f * (b.0 - a.0)).round() as i32,
                (a.1 + f * (b.1 - a.1)).round() as i32,
            )
        };
        let mut t = 0.0;
        while t < len {
            let drawing = phase < on;
            let until = if drawing { on - phase } else { period - phase };
            let step = until.min(len - t);
            if drawing {
                if current.is_empty() {
                    current.push(at(t));
                }
                current.push(at(t + step));
            }
            t += step;
            phase += step;
            if phase >= on && drawing && !current.is_empty() {
                out.push(std::mem::take(&mut current));
            }
            if phase >= period {
                phase = 0.0;
            }
        }
    }
    if current.len() > 1 {
        out.push(current);
    }
    out.retain(|p| p.len() > 1);
    out
}

/// Draws `marker` of radius `r` centred at pixel `c`, filled or as an outline.
pub fn draw_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: (i32, i32),
    marker: Marker,
    r: i32,
    colour: RGBColor,
    filled: bool,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let (x, y) = c;
    let corners: Vec<(i32, i32)> = match marker {
        Marker::Circle => {
            let style = if filled {
                colour.filled()
            } else {
                colour.stroke_width(2)
            };
            return area.draw(&Circle::new(c, r, style)).map_err(error);
        }
        Marker::Square => vec![(x - r, y - r), (x + r, y - r), (x + r, y + r), (x - r, y + r)],
        Marker::Triangle => vec![(x, y - r - 1), (x + r + 1, y + r), (x - r - 1, y + r)],
        Marker::Diamond => vec![(x, y - r - 1), (x + r + 1, y), (x, y + r + 1), (x - r - 1, y)],
        Marker::Wedge => vec![(x - r - 1, y - r), (x + r + 1, y - r), (x, y + r + 1)],
    };
    if filled {
        area.draw(&Polygon::new(corners, colour.filled())).map_err(error)
    } else {
        let mut ring = corners.clone();
        ring.push(corners[0]);
        area.draw(&PathElement::new(ring, colour.stroke_width(2)))
            .map_err(error)
    }
}

/// Whether pixel `p` lies in `rect` (left, top, right, bottom, inclusive).
pub fn within(p: (i32, i32), rect: (i32, i32, i32, i32)) -> bool {
    p.0 >= rect.0 && p.0 <= rect.2 && p.1 >= rect.1 && p.1 <= rect.3
}

/// Draws a pixel polyline clipped to `rect`, solid or dashed.
pub fn draw_line<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    line: &[(i32, i32)],
    rect: (i32, i32, i32, i32),
    c: RGBColor,
    dash: Option<(u32, u32)>,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    for piece in clip(line, rect) {
        for d in dashes(&piece, dash) {
            root.draw(&PathElement::new(d, c.stroke_width(2))).map_err(error)?;
        }
    }
    Ok(())
}

/// The parts of a pixel polyline inside `rect` (left, top, right, bottom), each segment cut
/// where it crosses the edge (Liang-Barsky).
pub fn clip(line: &[(i32, i32)], rect: (i32, i32, i32, i32)) -> Vec<Vec<(i32, i32)>> {
    let mut out: Vec<Vec<(i32, i32)>> = Vec::new();
    let mut current: Vec<(i32, i32)> = Vec::new();
    for w in line.windows(2) {
        let (a, b) = ((w[0].0 as f64, w[0].1 as f64), (w[1].0 as f64, w[1].1 as f64));
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        let mut visible = true;
        for (p, q) in [
            (-dx, a.0 - rect.0 as f64),
            (dx, rect.2 as f64 - a.0),
            (-dy, a.1 - rect.1 as f64),
            (dy, rect.3 as f64 - a.1),
        ] {
            if p == 0.0 {
                visible &= q >= 0.0;
            } else if p < 0.0 {
                t0 = t0.max(q / p);
            } else {
                t1 = t1.min(q / p);
            }
        }
        if !visible || t0 > t1 {
            if current.len() > 1 {
                out.push(std::mem::take(&mut current));
            }
            current.clear();
            continue;
        }
        let at = |t: f64| ((a.0 + t * dx).round() as i32, (a.1 + t * dy).round() as i32);
        let (s, e) = (at(t0), at(t1));
        if current.last() != Some(&s) {
            if current.len() > 1 {
                out.push(std::mem::take(&mut current));
            }
            current = vec![s];
        }
        current.push(e);
        if t1 < 1.0 {
            out.push(std::mem::take(&mut current));
        }
    }
    if current.len() > 1 {
        out.push(current);
    }
    if line.len() == 1 && within(line[0], rect) {
        out.push(line.to_vec());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dashes_alternate_along_the_line_and_run_on_across_corners() {
        let d = dashes(&[(0, 0), (30, 0)], Some((8, 4)));
        assert_eq!(
            d,
            vec![vec![(0, 0), (8, 0)], vec![(12, 0), (20, 0)], vec![(24, 0), (30, 0)]]
        );
        // A corner inside a dash keeps the dash one piece through it.
        let d = dashes(&[(0, 0), (4, 0), (4, 10)], Some((8, 4)));
        assert_eq!(d[0], vec![(0, 0), (4, 0), (4, 4)]);
        assert_eq!(d[1], vec![(4, 8), (4, 10)]);
        assert_eq!(dashes(&[(0, 0), (30, 0)], None), vec![vec![(0, 0), (30, 0)]]);
    }

    #[test]
    fn lines_are_cut_at_the_edge_of_the_data_area() {
        let rect = (0, 0, 100, 100);
        assert_eq!(clip(&[(50, 50), (150, 50)], rect), vec![vec![(50, 50), (100, 50)]]);
        // Leaving and coming back gives two pieces; a line wholly outside none.
        assert_eq!(
            clip(&[(10, 10), (10, 200), (20, 200), (20, 10)], rect),
            vec![vec![(10, 10), (10, 100)], vec![(20, 100), (20, 10)]]
        );
        assert!(clip(&[(-10, -10), (-10, 500)], rect).is_empty());
    }

    #[test]
    fn colour_and_marker_pairs_repeat_only_after_thirty_series() {
        let pairs: std::collections::HashSet<_> = (0..30).map(|i| (colour(i), marker(i))).collect();
        assert_eq!(pairs.len(), 30);
        assert_eq!((colour(30), marker(30)), (colour(0), marker(0)));
    }
}
