//! How series look: one index gives a series its colour, marker shape and dashes together, so
//! that a series keeps its look in every plot that draws it (a sampling scheme, say) and two
//! series tell apart by shape where colours do not.

use super::error;
use crate::sampling::DiskScheme;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Paul Tol's colour-blind-safe "muted" qualitative scheme (Tol 2021, "Colour Schemes", SRON
/// technical note SRON/EPS/TN/09-002, figure 4), less its pale grey for missing data, ordered so
/// that the first few series get the colours furthest apart and the two palest come last:
/// indigo, rose, teal, olive, purple, cyan, green, wine, sand.
const PALETTE: [RGBColor; 9] = [
    RGBColor(0x33, 0x22, 0x88),
    RGBColor(0xCC, 0x66, 0x77),
    RGBColor(0x44, 0xAA, 0x99),
    RGBColor(0x99, 0x99, 0x33),
    RGBColor(0xAA, 0x44, 0x99),
    RGBColor(0x88, 0xCC, 0xEE),
    RGBColor(0x11, 0x77, 0x33),
    RGBColor(0x88, 0x22, 0x55),
    RGBColor(0xDD, 0xCC, 0x77),
];

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
    /// An upright cross.
    Plus,
    /// A diagonal cross.
    Cross,
    /// A five-pointed star.
    Star,
    /// A triangle pointing right.
    Pointer,
}

/// One shape per palette colour, so that the first nine series differ in shape as in colour.
const MARKERS: [Marker; 9] = [
    Marker::Circle,
    Marker::Square,
    Marker::Triangle,
    Marker::Diamond,
    Marker::Wedge,
    Marker::Plus,
    Marker::Cross,
    Marker::Star,
    Marker::Pointer,
];

/// How many series can be told apart: every colour with its own shape, solid with filled
/// markers, then the same dashed with outlined markers. The look of index `i` is that of
/// `i + LOOKS`.
pub const LOOKS: usize = 2 * PALETTE.len();

/// A series' look: its colour, its marker's shape, and whether it is dashed (with outlined
/// markers) or solid (with filled ones).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Look {
    /// Line, marker and bar colour.
    pub colour: RGBColor,
    /// Marker shape.
    pub marker: Marker,
    /// Dashed line, outlined marker (and an outlined bar).
    pub dashed: bool,
}

/// The look of index `i`: colour and shape run through their nine together, and the second
/// nine are dashed, so indices under [`LOOKS`] apart never share a look.
pub fn look(i: usize) -> Look {
    Look {
        colour: PALETTE[i % PALETTE.len()],
        marker: MARKERS[i % MARKERS.len()],
        dashed: (i / PALETTE.len()) % 2 == 1,
    }
}

/// Colour of look `i` (a reference line drawn in its series' colour).
pub fn colour(i: usize) -> RGBColor {
    look(i).colour
}

/// Radius of a marker in pixels.
pub const MARKER_RADIUS: i32 = 5;

/// Refuses a figure in which two series that are not one share a look: `series` gives each
/// series' look index, name and group (its panel); within a group no two may share a look,
/// and across groups one look must name one series, or the legend could not tell them apart.
pub fn distinct<'a>(series: impl IntoIterator<Item = (usize, &'a str, usize)>) -> anyhow::Result<()> {
    let all: Vec<(usize, &str, usize)> = series.into_iter().collect();
    for (k, &(i, a, ga)) in all.iter().enumerate() {
        for &(j, b, gb) in &all[k + 1..] {
            if look(i) == look(j) && (ga == gb || a != b) {
                anyhow::bail!(
                    "series `{a}` (look {i}) and `{b}` (look {j}) would be drawn alike: same colour, marker and dashes"
                );
            }
        }
    }
    Ok(())
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

/// The corners of `marker` around the origin for radius 1 (every shape but the disc), sized
/// so that the shapes look about as large as one another.
fn outline(marker: Marker) -> Vec<(f64, f64)> {
    let turn = |k: usize, n: usize, r: f64, phase: f64| {
        let a = phase + std::f64::consts::TAU * k as f64 / n as f64;
        (r * a.sin(), -r * a.cos())
    };
    let plus = |phase: f64| -> Vec<(f64, f64)> {
        let (arm, half) = (1.25, 0.42);
        let c = [
            (-half, -arm),
            (half, -arm),
            (half, -half),
            (arm, -half),
            (arm, half),
            (half, half),
        ];
        let c: Vec<(f64, f64)> = c.iter().chain(&c.map(|(x, y)| (-x, -y))).copied().collect();
        let (s, co) = phase.sin_cos();
        c.into_iter().map(|(x, y)| (x * co - y * s, x * s + y * co)).collect()
    };
    match marker {
        Marker::Circle => (0..24).map(|k| turn(k, 24, 1.0, 0.0)).collect(),
        Marker::Square => vec![(-0.9, -0.9), (0.9, -0.9), (0.9, 0.9), (-0.9, 0.9)],
        Marker::Triangle => vec![(0.0, -1.25), (1.2, 0.85), (-1.2, 0.85)],
        Marker::Diamond => vec![(0.0, -1.3), (1.15, 0.0), (0.0, 1.3), (-1.15, 0.0)],
        Marker::Wedge => vec![(-1.2, -0.85), (1.2, -0.85), (0.0, 1.25)],
        Marker::Plus => plus(0.0),
        Marker::Cross => plus(std::f64::consts::FRAC_PI_4),
        Marker::Star => (0..10)
            .map(|k| turn(k, 10, if k % 2 == 0 { 1.45 } else { 0.6 }, 0.0))
            .collect(),
        Marker::Pointer => vec![(-0.85, -1.2), (1.25, 0.0), (-0.85, 1.2)],
    }
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
    if marker == Marker::Circle {
        let style = if filled {
            colour.filled()
        } else {
            colour.stroke_width(2)
        };
        return area.draw(&Circle::new(c, r, style)).map_err(error);
    }
    let corners: Vec<(i32, i32)> = outline(marker)
        .iter()
        .map(|&(x, y)| (c.0 + (x * r as f64).round() as i32, c.1 + (y * r as f64).round() as i32))
        .collect();
    if filled {
        area.draw(&Polygon::new(corners, colour.filled())).map_err(error)
    } else {
        let mut ring = corners.clone();
        ring.push(corners[0]);
        area.draw(&PathElement::new(ring, colour.stroke_width(2)))
            .map_err(error)
    }
}

/// Draws a dark edge round `marker` (a marker on a bar of its own colour).
pub fn edge_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: (i32, i32),
    marker: Marker,
    r: i32,
    ink: RGBColor,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    if marker == Marker::Circle {
        return area.draw(&Circle::new(c, r, ink.stroke_width(1))).map_err(error);
    }
    let mut ring: Vec<(i32, i32)> = outline(marker)
        .iter()
        .map(|&(x, y)| (c.0 + (x * r as f64).round() as i32, c.1 + (y * r as f64).round() as i32))
        .collect();
    ring.push(ring[0]);
    area.draw(&PathElement::new(ring, ink.stroke_width(1))).map_err(error)
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

/// The look index of `scheme` among an experiment's `schemes`: a built-in scheme's place in
/// [`DiskScheme::ALL`], so that it looks the same in every plot of every experiment; a user's
/// points scheme takes the first index no built-in of `schemes` holds, in the order listed.
pub fn scheme_look(scheme: DiskScheme, schemes: &[DiskScheme]) -> usize {
    if let Some(i) = DiskScheme::ALL.iter().position(|s| *s == scheme) {
        return i;
    }
    let mut users = schemes.iter().filter(|s| !s.is_built_in());
    let nth = users.position(|s| *s == scheme).unwrap_or(0);
    (0..)
        .filter(|i| !schemes.iter().any(|s| DiskScheme::ALL.get(*i) == Some(s)))
        .nth(nth)
        .unwrap_or(0)
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
    fn looks_repeat_only_after_eighteen_series_and_the_first_nine_differ_in_colour_and_shape() {
        let looks: std::collections::HashSet<Look> = (0..LOOKS).map(look).collect();
        assert_eq!(looks.len(), LOOKS);
        assert_eq!(look(LOOKS), look(0));
        assert_ne!(look(LOOKS - 1), look(0));
        let colours: std::collections::HashSet<_> = (0..9).map(colour).collect();
        let shapes: std::collections::HashSet<_> = (0..9).map(|i| look(i).marker).collect();
        assert_eq!((colours.len(), shapes.len()), (9, 9));
        assert!((0..9).all(|i| !look(i).dashed && look(i + 9).dashed));
    }

    #[test]
    fn two_series_with_one_look_are_refused() {
        assert!(distinct([(0, "a", 0), (1, "b", 0), (9, "c", 0)]).is_ok());
        let e = distinct([(0, "uniform", 0), (3, "paper", 0), (LOOKS + 3, "sobol", 0)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("`paper`") && e.contains("`sobol`"), "{e}");
        // One series in two panels is one legend entry; two series in two panels are not.
        assert!(distinct([(2, "jittered", 0), (2, "jittered", 1)]).is_ok());
        assert!(distinct([(2, "jittered", 0), (2, "spiral", 1)]).is_err());
    }
}
