//! The figures as a reader meets them: the SVG beside each PNG parsed as XML and searched for its
//! legend, dashes, carets and bars; the colour bar read back from the PNG.

use super::legend::INK;
use super::*;
use roxmltree::{Document, Node};

/// `#RRGGBB` as plotters' SVG backend writes `c`.
fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// The points of a `<polyline>` or `<polygon>`.
fn points(n: &Node) -> Vec<(f64, f64)> {
    n.attribute("points")
        .unwrap_or("")
        .split_whitespace()
        .filter_map(|p| {
            let (x, y) = p.split_once(',')?;
            Some((x.parse().ok()?, y.parse().ok()?))
        })
        .collect()
}

/// The `<text>` element reading `text`, and its (x, y).
fn text_at(doc: &Document, text: &str) -> Option<(f64, f64)> {
    let n = doc
        .descendants()
        .find(|n| n.has_tag_name("text") && n.text().is_some_and(|t| t.trim() == text))?;
    Some((n.attribute("x")?.parse().ok()?, n.attribute("y")?.parse().ok()?))
}

/// Polylines stroked in `colour` wholly within `dx` of x range `xs` and `dy` of row `y`.
fn strokes_near<'a>(doc: &'a Document, colour: &str, xs: (f64, f64), y: f64) -> Vec<Node<'a, 'a>> {
    doc.descendants()
        .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some(colour))
        .filter(|n| {
            let p = points(n);
            !p.is_empty()
                && p.iter()
                    .all(|&(px, py)| px >= xs.0 && px <= xs.1 && (py - y).abs() <= 2.0)
        })
        .collect()
}

#[test]
fn a_line_plot_is_written_as_svg_with_its_dashes_in_the_legend_and_clipped_intervals_marked() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plot.png");
    let pts = |v: &[(f64, f64, f64)]| -> Vec<Point> { v.iter().map(|&(x, y, h)| Point::ci(x, y, h)).collect() };
    // Look 10: the second colour, dashed.
    let series = [
        Series {
            name: "solid one".into(),
            look: 0,
            points: pts(&[(1.0, 0.2, 0.01), (4.0, 0.1, 0.01), (16.0, 0.05, 0.01)]),
        },
        Series {
            name: "dashed one".into(),
            look: 10,
            // The middle interval reaches below zero: on a log axis it is clipped.
            points: pts(&[(1.0, 0.3, 0.01), (4.0, 0.12, 0.5), (16.0, 0.06, 0.01)]),
        },
    ];
    let axes = Axes::new("title", "rays", "RMSE", true, true);
    line_plot(&path, &axes, &series, &[]).unwrap();
    let png = image::open(&path).unwrap();
    let text = std::fs::read_to_string(path.with_extension("svg")).unwrap();
    let doc = Document::parse(&text).expect("the SVG is well-formed XML");
    let svg = doc.root_element();
    assert!(svg.has_tag_name(("http://www.w3.org/2000/svg", "svg")));
    assert_eq!(svg.attribute("width"), Some(png.width().to_string().as_str()));
    assert_eq!(svg.attribute("height"), Some(png.height().to_string().as_str()));
    assert!(
        doc.descendants()
            .filter(|n| n.has_tag_name("text"))
            .all(|n| n.attribute("font-family") == Some(FONT)),
        "every label names the embedded font"
    );

    // The legend lies right of every data point, and draws each series as it is drawn.
    let (solid_x, solid_y) = text_at(&doc, "solid one").expect("legend entry");
    let (dashed_x, dashed_y) = text_at(&doc, "dashed one").expect("legend entry");
    // Markers of the first series: its points', and the legend sample's right of them.
    let xs: Vec<f64> = doc
        .descendants()
        .filter(|n| n.has_tag_name("circle") && n.attribute("fill") == Some(hex(colour(0)).as_str()))
        .map(|n| n.attribute("cx").unwrap().parse().unwrap())
        .collect();
    let sample = solid_x - 28.0;
    assert_eq!(xs.len(), 3 + 1, "{xs:?}");
    assert_eq!(xs.iter().filter(|&&x| (x - sample).abs() < 4.0).count(), 1, "{xs:?}");
    assert!(
        xs.iter()
            .filter(|&&x| (x - sample).abs() >= 4.0)
            .all(|&x| x < sample - 40.0),
        "a data marker under the legend: {xs:?}"
    );
    let solid = strokes_near(&doc, &hex(colour(0)), (solid_x - 60.0, solid_x), solid_y);
    let dashed = strokes_near(&doc, &hex(colour(10)), (dashed_x - 60.0, dashed_x), dashed_y);
    assert_eq!(solid.len(), 1, "a solid series' legend line is one stroke");
    assert!(
        dashed.len() >= 3,
        "a dashed series' legend line is dashed: {} strokes",
        dashed.len()
    );
    for entry in ["95 % interval", "interval beyond the axis"] {
        assert!(text_at(&doc, entry).is_some(), "legend lacks {entry}");
    }

    // The clipped interval ends at the axis with a caret, not at the far edge of the image.
    let ink = hex(INK);
    let whiskers: Vec<Vec<(f64, f64)>> = doc
        .descendants()
        .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some(ink.as_str()))
        .map(|n| points(&n))
        .filter(|p| p.len() == 2 && p[0].0 == p[1].0 && p[0].0 < solid_x - 60.0)
        .collect();
    let longest = whiskers
        .iter()
        .max_by(|a, b| (a[0].1 - a[1].1).abs().total_cmp(&(b[0].1 - b[1].1).abs()));
    let longest = longest.expect("whiskers drawn");
    let bottom = longest[0].1.max(longest[1].1);
    assert!(
        bottom < png.height() as f64 - 40.0,
        "the whisker runs into the axis labels: {longest:?}"
    );
    let carets: Vec<Vec<(f64, f64)>> = doc
        .descendants()
        .filter(|n| n.has_tag_name("polygon") && n.attribute("fill") == Some(ink.as_str()))
        .map(|n| points(&n))
        .collect();
    assert!(
        carets
            .iter()
            .any(|c| c[0] == (longest[0].0, bottom) && c[1].1 < bottom && c[1].0 > c[0].0),
        "no caret points down at the clipped end {bottom}: {carets:?}"
    );
}

#[test]
fn grouped_bars_name_each_group_and_join_none() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bars.png");
    let group = |name: &str, scale: f64| Group {
        name: name.into(),
        note: "1000 triangles".into(),
        bars: (0..3)
            .map(|i| Bar {
                series: i,
                value: scale * (1.0 + i as f64),
                lo: scale * (0.9 + i as f64),
                hi: scale * (1.1 + i as f64),
            })
            .collect(),
    };
    let groups = [group("cow", 1.0), group("bull", 2.0)];
    let names: Vec<(usize, String)> = ["kdtree", "vlf", "bvh"]
        .iter()
        .enumerate()
        .map(|(i, s)| (i, s.to_string()))
        .collect();
    grouped_bars(&path, "title", "frame time (s)", &names, &groups).unwrap();
    let text = std::fs::read_to_string(path.with_extension("svg")).unwrap();
    let doc = Document::parse(&text).unwrap();
    for label in ["cow", "bull", "kdtree", "vlf", "bvh", "95 % interval", "frame time (s)"] {
        assert!(text_at(&doc, label).is_some(), "no text {label}");
    }
    let (cow, bull) = (text_at(&doc, "cow").unwrap(), text_at(&doc, "bull").unwrap());
    assert!(
        cow.0 < bull.0 && cow.1 == bull.1,
        "group names side by side under the axis"
    );
    for (i, _) in &names {
        let fill = hex(colour(*i));
        let bars = doc
            .descendants()
            .filter(|n| n.has_tag_name("rect") && n.attribute("fill") == Some(fill.as_str()))
            .count();
        // One per group, and the legend's swatch.
        assert_eq!(bars, groups.len() + 1, "bars of series {i}");
        // Each with its series' marker on top: a disc for the first, polygons for the others.
        let markers = doc
            .descendants()
            .filter(|n| {
                (n.has_tag_name("circle") || n.has_tag_name("polygon")) && n.attribute("fill") == Some(fill.as_str())
            })
            .count();
        assert_eq!(markers, groups.len() + 1, "markers of series {i}");
        let joined = doc
            .descendants()
            .filter(|n| n.has_tag_name("polyline") && n.attribute("stroke") == Some(fill.as_str()))
            .count();
        assert_eq!(joined, 0, "no line joins the groups");
    }
}

#[test]
fn an_error_map_gets_a_colour_bar_from_blue_to_red() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("grid.png");
    let map = crate::output::images::diverging(&[0.0; 16], &[0.0; 16], 0.5, 4, 4);
    let tiles = [Tile {
        bar: Some(ColourBar {
            scale: 0.5,
            what: "visibility difference".into(),
        }),
        ..Tile::new("run - truth", &map)
    }];
    image_grid(&path, &tiles, 1).unwrap();
    let img = image::open(&path).unwrap().to_rgb8();
    let plain = {
        let p = dir.path().join("plain.png");
        image_grid(&p, &[Tile::new("run - truth", &map)], 1).unwrap();
        image::open(&p).unwrap().to_rgb8()
    };
    assert!(img.height() > plain.height(), "room for the bar");
    // Below the tile, a row runs from full blue through white to full red.
    // (The tile itself is white: its two images agree.)
    let row = (60..img.height())
        .find(|&y| img.get_pixel(img.width() / 4, y).0 != [255, 255, 255])
        .expect("a bar under the tile")
        + 4;
    let at = |x: u32| img.get_pixel(x, row).0;
    let (left, right) = (
        (0..img.width()).find(|&x| at(x)[2] == 255 && at(x)[0] < 40).unwrap(),
        img.width() - 1,
    );
    let right = (0..=right).rev().find(|&x| at(x)[0] == 255 && at(x)[2] < 40).unwrap();
    assert!(
        at((left + right) / 2).iter().all(|&c| c > 240),
        "white at 0: {:?}",
        at((left + right) / 2)
    );
    assert!(right - left > img.width() / 2);
}

#[test]
fn an_axis_over_one_value_is_still_labelled() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("one.png");
    let series = [Series {
        name: "one radius".into(),
        look: 0,
        points: vec![Point::ci(20.0, 14.0, 0.5)],
    }];
    line_plot(
        &path,
        &Axes::new("t", "light radius (mm)", "width (mm)", false, false),
        &series,
        &[],
    )
    .unwrap();
    let text = std::fs::read_to_string(path.with_extension("svg")).unwrap();
    let doc = Document::parse(&text).unwrap();
    assert!(text_at(&doc, "20").is_some(), "the one x value is labelled");
}

/// A series of `look` through three points.
fn three(name: &str, look: usize, scale: f64) -> Series {
    Series {
        name: name.into(),
        look,
        points: vec![
            Point::ci(1.0, scale, 0.1 * scale),
            Point::ci(4.0, 0.5 * scale, 0.1 * scale),
            Point::ci(16.0, 0.25 * scale, 0.1 * scale),
        ],
    }
}

#[test]
fn two_series_of_one_look_are_refused_in_line_plots_and_bars() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("alike.png");
    let axes = Axes::new("t", "rays", "RMSE", true, true);
    // 3 and 3 + LOOKS: one colour, one marker, both solid.
    let alike = [three("paper", 3, 1.0), three("sobol", 3 + LOOKS, 2.0)];
    let e = line_plot(&path, &axes, &alike, &[]).unwrap_err().to_string();
    assert!(e.contains("`paper`") && e.contains("`sobol`"), "{e}");
    assert!(!path.exists(), "nothing written for a refused figure");
    // One colour but dashed: told apart.
    line_plot(&path, &axes, &[three("paper", 3, 1.0), three("sobol", 12, 2.0)], &[]).unwrap();
    let names = [(1, "kdtree".to_string()), (1 + LOOKS, "vlf".to_string())];
    let e = grouped_bars(&dir.path().join("bars.png"), "t", "s", &names, &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("`kdtree`") && e.contains("`vlf`"), "{e}");
}

#[test]
fn small_multiples_share_their_axes_and_name_each_series_once() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("panels.png");
    let panels = [
        Panel {
            title: "per-pixel pattern".into(),
            series: vec![three("uniform", 0, 1.0), three("paper", 1, 0.5)],
        },
        Panel {
            title: "shared pattern".into(),
            // Ten times smaller: on a shared axis it lies lower than the first panel's.
            series: vec![three("uniform", 0, 0.1), three("paper", 1, 0.05)],
        },
    ];
    let axes = Axes::new("Figure", "rays", "RMSE", true, true);
    line_panels(&path, &axes, &panels, &[]).unwrap();
    let text = std::fs::read_to_string(path.with_extension("svg")).unwrap();
    let doc = Document::parse(&text).unwrap();
    let texts: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text())
        .map(str::trim)
        .collect();
    for t in ["Figure", "per-pixel pattern", "shared pattern"] {
        assert_eq!(texts.iter().filter(|x| **x == t).count(), 1, "{t}: {texts:?}");
    }
    for t in ["uniform", "paper"] {
        assert_eq!(texts.iter().filter(|x| **x == t).count(), 1, "one legend entry for {t}");
    }
    assert_eq!(
        texts.iter().filter(|x| **x == "RMSE").count(),
        2,
        "each panel names its axes"
    );
    // The y labels of the two panels read alike: one range for both.
    let labels = |left: bool| -> Vec<String> {
        let (x_left, _) = text_at(&doc, "per-pixel pattern").unwrap();
        let (x_right, _) = text_at(&doc, "shared pattern").unwrap();
        let mid = (x_left + x_right) / 2.0;
        let mut v: Vec<(f64, String)> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text") && n.attribute("text-anchor") == Some("end"))
            .filter_map(|n| {
                let x: f64 = n.attribute("x")?.parse().ok()?;
                let y: f64 = n.attribute("y")?.parse().ok()?;
                let t = n.text()?.trim().to_string();
                ((x < mid) == left).then_some((y, t))
            })
            .collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v.into_iter().map(|(_, t)| t).collect()
    };
    let (l, r) = (labels(true), labels(false));
    assert!(l.len() >= 2, "{l:?}");
    assert_eq!(l, r, "panels on one y range");
    // The shared panel's first point (RMSE 0.1) lies lower than the per-pixel one's (1.0): the
    // indigo discs of uniform, three per panel and one in the legend.
    let indigo = hex(colour(0));
    let discs: Vec<(f64, f64)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("circle") && n.attribute("fill") == Some(indigo.as_str()))
        .map(|n| {
            (
                n.attribute("cx").unwrap().parse().unwrap(),
                n.attribute("cy").unwrap().parse().unwrap(),
            )
        })
        .collect();
    assert_eq!(discs.len(), 7, "{discs:?}");
    assert!(discs[3].1 > discs[0].1 + 100.0, "{discs:?}");
}

#[test]
fn a_long_legend_keeps_the_data_on_most_of_the_width_in_legible_text() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long.png");
    let series: Vec<Series> = (0..9)
        .map(|i| {
            three(
                &format!("a rather long series name, number {i} of nine"),
                i,
                1.0 + i as f64,
            )
        })
        .collect();
    line_plot(&path, &Axes::new("t", "rays", "RMSE", true, true), &series, &[]).unwrap();
    let text = std::fs::read_to_string(path.with_extension("svg")).unwrap();
    let doc = Document::parse(&text).unwrap();
    let width: f64 = doc.root_element().attribute("width").unwrap().parse().unwrap();
    // The data area: from the y axis's labels to the legend's first sample.
    let (legend_x, _) = text_at(&doc, "a rather long series name, number 0 of nine").unwrap();
    let axis_x = doc
        .descendants()
        .filter(|n| n.has_tag_name("text") && n.attribute("text-anchor") == Some("end"))
        .filter_map(|n| n.attribute("x")?.parse::<f64>().ok())
        .fold(f64::INFINITY, f64::min);
    assert!(
        legend_x - 60.0 - axis_x > 0.6 * width,
        "data {} of {width}",
        legend_x - 60.0 - axis_x
    );
    // Every legend entry and tick label at 15 px or more.
    for n in doc.descendants().filter(|n| n.has_tag_name("text")) {
        let size: f64 = n
            .attribute("font-size")
            .unwrap()
            .trim_end_matches("px")
            .parse()
            .unwrap();
        assert!(size >= 15.0, "{:?} at {size}", n.text());
    }
}

#[test]
fn one_wide_interval_is_clipped_rather_than_flattening_the_lines() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("outlier.png");
    let mut series = three("renders", 0, 2.0);
    for (i, p) in series.points.iter_mut().enumerate() {
        p.lo = p.y - 0.05;
        // The second point's interval reaches fifty times past the data.
        p.hi = if i == 1 { 50.0 } else { p.y + 0.05 };
    }
    line_plot(&path, &Axes::new("t", "frame", "seconds", false, false), &[series], &[]).unwrap();
    let text = std::fs::read_to_string(path.with_extension("svg")).unwrap();
    let doc = Document::parse(&text).unwrap();
    let top = doc
        .descendants()
        .filter(|n| n.has_tag_name("text") && n.attribute("text-anchor") == Some("end"))
        .filter_map(|n| n.text()?.trim().parse::<f64>().ok())
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(top > 1.5 && top < 4.0, "the y axis runs to {top}");
    assert!(text_at(&doc, "interval beyond the axis").is_some());
    let ink = hex(INK);
    assert!(
        doc.descendants()
            .any(|n| n.has_tag_name("polygon") && n.attribute("fill") == Some(ink.as_str())),
        "a caret marks the clipped end"
    );
}
