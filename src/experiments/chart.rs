//! Charts of the sweeps as plain data ([`Chart`]: titled, labelled axes, linear or log, and
//! named series) and their rendering to SVG and PNG with `plotters`. Text uses the Ubuntu Light
//! font compiled into `epaint_default_fonts`, registered with plotters' `ab_glyph` backend, so
//! no system font (fontconfig) is needed and the PNG looks the same on every machine.

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use serde::Serialize;

use super::labels;
use crate::export::{ExportError, write_atomically, write_text};

/// The legend's and the point labels' font sizes.
const LEGEND_FONT: u32 = 14;
const LABEL_FONT: u32 = 12;

/// Pixel size of the PNG (and the SVG's view box).
pub const CHART_SIZE: (u32, u32) = (960, 620);

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SeriesStyle {
    /// Points joined in order.
    LinePoints,
    /// Points only (the values of the series have no order, e.g. methods).
    Points,
    /// A thick black line over the other series (the Pareto front), points ringed.
    Front,
}

/// One named series of `(x, y)` points.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub style: SeriesStyle,
    /// A text next to each point (empty: none).
    pub labels: Vec<String>,
}

impl Series {
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            style: SeriesStyle::LinePoints,
            labels: Vec::new(),
        }
    }

    /// The same series drawn as `style` with `labels` next to its points.
    pub fn styled(self, style: SeriesStyle, labels: Vec<String>) -> Self {
        Self {
            style,
            labels,
            ..self
        }
    }
}

/// A 2D chart: axes (linear or log) and series.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
}

/// Writes `{stem}.svg` and `{stem}.png`.
pub fn write_chart(chart: &Chart, stem: &Path) -> Result<(), ExportError> {
    let svg_path = stem.with_extension("svg");
    let png_path = stem.with_extension("png");
    let svg = chart_svg(chart).map_err(|reason| ExportError {
        path: svg_path.display().to_string(),
        reason,
    })?;
    write_text(&svg_path, &svg)?;
    let rgb = chart_rgb(chart).map_err(|reason| ExportError {
        path: png_path.display().to_string(),
        reason,
    })?;
    write_atomically(&png_path, |out| {
        let mut encoder = png::Encoder::new(out, CHART_SIZE.0, CHART_SIZE.1);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(&rgb).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())
    })
}

/// The chart as SVG text.
pub fn chart_svg(chart: &Chart) -> Result<String, String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, CHART_SIZE).into_drawing_area();
        draw(&root, chart)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(svg)
}

/// The chart as 8-bit RGB pixels, row-major, [`CHART_SIZE`].
pub fn chart_rgb(chart: &Chart) -> Result<Vec<u8>, String> {
    let (w, h) = CHART_SIZE;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        draw(&root, chart)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(buf)
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font compiled into the binary; a failure here would
        // only make text disappear, never fail a chart.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

/// The data range of the points on one axis (positive values only on a log axis), padded.
fn axis_range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        // Whole decades: plotters labels a log axis only from its first power of ten up.
        // Padded a little so the end labels are inside the plot.
        let lo = 10f64.powf(lo.log10().floor());
        let hi = 10f64.powf(hi.log10().ceil());
        let hi = if lo == hi { hi * 10.0 } else { hi };
        (lo / 1.05, hi * 1.05)
    } else {
        let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.5 };
        let lo = if lo >= 0.0 && lo - pad < 0.0 {
            0.0
        } else {
            lo - pad
        };
        (lo, hi + pad)
    }
}

/// A tick label: plain for moderate values, `1e-6` style for the rest.
pub fn format_tick(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(1e-2..1e4).contains(&a) {
        format!("{v:.0e}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, chart: &Chart) -> Result<(), String> {
    register_font();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let xs = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0));
    let ys = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1));
    let (x0, x1) = axis_range(xs, chart.x_log);
    let (y0, y1) = axis_range(ys, chart.y_log);
    let legend = legend_corner(chart, (x0, x1), (y0, y1));
    match (chart.x_log, chart.y_log) {
        (false, false) => plot(root, chart, x0..x1, y0..y1, legend),
        (true, false) => plot(root, chart, (x0..x1).log_scale(), y0..y1, legend),
        (false, true) => plot(root, chart, x0..x1, (y0..y1).log_scale(), legend),
        (true, true) => plot(
            root,
            chart,
            (x0..x1).log_scale(),
            (y0..y1).log_scale(),
            legend,
        ),
    }
}

/// A point the axes can show: finite, and positive on a log axis.
fn drawable(chart: &Chart, p: &(f64, f64)) -> bool {
    p.0.is_finite() && p.1.is_finite() && (!chart.x_log || p.0 > 0.0) && (!chart.y_log || p.1 > 0.0)
}

/// A corner of a plot, for its legend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Corner {
    UpperRight,
    UpperLeft,
    LowerRight,
    LowerLeft,
}

/// The corner where a legend of `size` (its width and height as shares of the plot's) covers
/// the fewest of `points` (each as shares of the plot's width and height from the lower left,
/// 0 to 1): upper right on a tie, then upper left, lower right, lower left. Both the exported
/// charts and the viewer's plot place their legend so.
pub fn emptiest_corner(points: &[(f64, f64)], (w, h): (f64, f64)) -> Corner {
    let corners = [
        (Corner::UpperRight, true, true),
        (Corner::UpperLeft, false, true),
        (Corner::LowerRight, true, false),
        (Corner::LowerLeft, false, false),
    ];
    let covered = |right: bool, upper: bool| {
        points
            .iter()
            .filter(|&&(px, py)| {
                (if right { px >= 1.0 - w } else { px <= w })
                    && (if upper { py >= 1.0 - h } else { py <= h })
            })
            .count()
    };
    let mut best = (Corner::UpperRight, usize::MAX);
    for (corner, right, upper) in corners {
        let n = covered(right, upper);
        if n < best.1 {
            best = (corner, n);
        }
    }
    best.0
}

/// The corner of the plot where the legend covers the fewest points ([`emptiest_corner`]).
fn legend_corner(chart: &Chart, x: (f64, f64), y: (f64, f64)) -> SeriesLabelPosition {
    // Where a value falls along an axis, 0 to 1.
    let along = |v: f64, (lo, hi): (f64, f64), log: bool| {
        if log {
            (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
        } else {
            (v - lo) / (hi - lo)
        }
    };
    let points: Vec<(f64, f64)> = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| drawable(chart, p))
        .map(|p| (along(p.0, x, chart.x_log), along(p.1, y, chart.y_log)))
        .collect();
    // The legend box is about this much of the plot's width and height.
    match emptiest_corner(&points, (0.4, 0.35)) {
        Corner::UpperRight => SeriesLabelPosition::UpperRight,
        Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
        Corner::LowerRight => SeriesLabelPosition::LowerRight,
        Corner::LowerLeft => SeriesLabelPosition::LowerLeft,
    }
}

fn plot<DB, X, Y>(
    root: &DrawingArea<DB, Shift>,
    chart: &Chart,
    x: X,
    y: Y,
    legend_position: SeriesLabelPosition,
) -> Result<(), String>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let mut cc = ChartBuilder::on(root)
        .caption(&chart.title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    cc.configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .x_labels(12)
        .y_labels(12)
        .x_label_formatter(&|v| format_tick(*v))
        .y_label_formatter(&|v| format_tick(*v))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    let mut colour_index = 0;
    // Every point's pixel, and the labels wanted at them.
    let mut markers: Vec<(i32, i32)> = Vec::new();
    let mut lines: Vec<labels::Segment> = Vec::new();
    let mut wanted: Vec<labels::Wanted> = Vec::new();
    for s in &chart.series {
        let shown: Vec<(usize, (f64, f64))> = s
            .points
            .iter()
            .copied()
            .enumerate()
            .filter(|(_, p)| drawable(chart, p))
            .collect();
        let points: Vec<(f64, f64)> = shown.iter().map(|(_, p)| *p).collect();
        let (colour, line_width, ring) = match s.style {
            SeriesStyle::Front => (BLACK.to_rgba(), 3, true),
            _ => {
                colour_index += 1;
                (Palette99::pick(colour_index - 1).to_rgba(), 2, false)
            }
        };
        let legend = move |(x, y): (i32, i32)| {
            PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
        };
        if s.style == SeriesStyle::Points {
            cc.draw_series(points.iter().map(|&p| Circle::new(p, 5, colour.filled())))
                .map_err(err)?
                .label(s.name.as_str())
                .legend(legend);
        } else {
            cc.draw_series(LineSeries::new(
                points.clone(),
                colour.stroke_width(line_width),
            ))
            .map_err(err)?
            .label(s.name.as_str())
            .legend(legend);
            cc.draw_series(points.iter().map(|&p| {
                if ring {
                    Circle::new(p, 7, colour.stroke_width(2))
                } else {
                    Circle::new(p, 3, colour.filled())
                }
            }))
            .map_err(err)?;
        }
        let first_marker = markers.len();
        markers.extend(points.iter().map(|p| cc.backend_coord(p)));
        if s.style != SeriesStyle::Points {
            lines.extend(markers[first_marker..].windows(2).map(|w| (w[0], w[1])));
        }
        let labelled =
            shown
                .iter()
                .zip(&markers[first_marker..])
                .filter_map(|((i, _), &anchor)| {
                    s.labels.get(*i).map(|l| labels::Wanted {
                        anchor,
                        text: l.clone(),
                    })
                });
        // The front's labels first: they get the places next to their points.
        if s.style == SeriesStyle::Front {
            wanted.splice(0..0, labelled);
        } else {
            wanted.extend(labelled);
        }
    }
    let (legend_at, legend_box) = legend_layout(chart, cc.plotting_area(), legend_position)?;
    draw_labels(
        root,
        &wanted,
        &markers,
        &lines,
        legend_box,
        cc.plotting_area(),
    )?;
    cc.configure_series_labels()
        .position(legend_at)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", LEGEND_FONT))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// Where the legend goes in `corner` of the plot `area` (as plotters lays it out: its lines,
/// a 30-pixel sample and 10-pixel margins, 5 pixels from the plot's sides): the position to
/// give plotters, and its box in the chart's pixels, for the labels to keep clear of.
fn legend_layout<DB: DrawingBackend, CT: CoordTranslate>(
    chart: &Chart,
    area: &DrawingArea<DB, CT>,
    corner: SeriesLabelPosition,
) -> Result<(SeriesLabelPosition, labels::Rect), String> {
    let font: TextStyle = ("sans-serif", LEGEND_FONT).into_font().into();
    let mut lines = MultiLineText::<_, &str>::new((0, 0), &font);
    for s in chart.series.iter().filter(|s| !s.name.is_empty()) {
        lines.push_line(s.name.as_str());
    }
    let (w, h) = lines.estimate_dimension().map_err(|e| e.to_string())?;
    let (w, h) = (w + 30 + 20, h + 20);
    let (xs, ys) = area.get_pixel_range();
    let (aw, ah) = (xs.end - xs.start, ys.end - ys.start);
    let (x, y) = match corner {
        SeriesLabelPosition::UpperLeft => (5, 5),
        SeriesLabelPosition::LowerLeft => (5, ah - h - 5),
        SeriesLabelPosition::LowerRight => (aw - w - 5, ah - h - 5),
        _ => (aw - w - 5, 5),
    };
    let rect = labels::Rect {
        x0: xs.start + x,
        y0: ys.start + y,
        x1: xs.start + x + w + 1,
        y1: ys.start + y + h + 1,
    };
    Ok((SeriesLabelPosition::Coordinate(x, y), rect))
}

/// The point labels, merged where points share a spot and placed clear of one another, of the
/// markers, of the legend and where they can of the series' lines ([`labels::place`]), with a grey leader line where a label had
/// to move away from its point.
fn draw_labels<DB: DrawingBackend, CT: CoordTranslate>(
    root: &DrawingArea<DB, Shift>,
    wanted: &[labels::Wanted],
    markers: &[(i32, i32)],
    lines: &[labels::Segment],
    legend: labels::Rect,
    area: &DrawingArea<DB, CT>,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let font: TextStyle = ("sans-serif", LABEL_FONT).into_font().into();
    // The width as laid out; the height a whole line's (the glyphs' own box is shorter, and
    // the text drawn reaches past it).
    let line = LABEL_FONT as i32 + 3;
    let size = |t: &str| {
        root.estimate_text_size(t, &font)
            .map_or((7 * t.chars().count() as i32, line), |(w, _)| {
                (w as i32 + 1, line)
            })
    };
    let (xs, ys) = area.get_pixel_range();
    let plot = labels::Rect {
        x0: xs.start,
        y0: ys.start,
        x1: xs.end,
        y1: ys.end,
    };
    let merged = labels::merge(wanted);
    for p in labels::place(&merged, size, markers, &[legend], lines, plot) {
        if let Some(end) = p.leader_to {
            // From the marker's edge, not its centre, so the point stays readable.
            let (dx, dy) = ((end.0 - p.anchor.0) as f64, (end.1 - p.anchor.1) as f64);
            let len = dx.hypot(dy).max(1.0);
            let edge = (labels::MARKER_PX - 1) as f64 / len;
            let start = (
                p.anchor.0 + (dx * edge).round() as i32,
                p.anchor.1 + (dy * edge).round() as i32,
            );
            root.draw(&PathElement::new(
                vec![start, end],
                RGBColor(150, 150, 150).stroke_width(1),
            ))
            .map_err(err)?;
        }
        root.draw(&Text::new(p.text, (p.rect.x0, p.rect.y0), font.clone()))
            .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_legend_goes_where_it_covers_fewest_points() {
        let chart = |points: Vec<(f64, f64)>, log: bool| Chart {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x_log: log,
            y_log: log,
            series: vec![Series::new("s", points)],
        };
        let corner = |c: &Chart| {
            let xs = c.series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
            let ys = c.series.iter().flat_map(|s| s.points.iter().map(|p| p.1));
            legend_corner(c, axis_range(xs, c.x_log), axis_range(ys, c.y_log))
        };
        // Rising, log-log (time against size): the upper right is taken, the upper left free.
        let rising = chart(
            (0..7).map(|i| (10f64.powi(i), 10f64.powi(i))).collect(),
            true,
        );
        assert_eq!(corner(&rising), SeriesLabelPosition::UpperLeft);
        // Falling, linear: the upper right is free.
        let falling = chart((0..10).map(|i| (i as f64, 9.0 - i as f64)).collect(), false);
        assert_eq!(corner(&falling), SeriesLabelPosition::UpperRight);
        // Everything high: the legend goes below.
        let high = chart(
            (0..10)
                .map(|i| (i as f64, 10.0 + (i % 2) as f64))
                .chain([(5.0, 0.0)])
                .collect(),
            false,
        );
        assert!(matches!(
            corner(&high),
            SeriesLabelPosition::LowerRight | SeriesLabelPosition::LowerLeft
        ));
    }

    #[test]
    fn the_emptiest_corner_is_the_one_with_fewest_points_under_a_legend_of_its_size() {
        // A sweep's shape: a cluster upper left, a front falling to the lower right.
        let mut points = vec![
            (0.05, 0.95),
            (0.1, 0.8),
            (0.12, 0.7),
            (0.3, 0.7),
            (0.45, 0.7),
        ];
        points.extend((0..6).map(|i| (0.5 + 0.1 * i as f64, 0.6 - 0.1 * i as f64)));
        // A short legend fits in the upper right; a tall one (the viewer's nine series) would
        // reach down to the front there, and goes lower left.
        assert_eq!(emptiest_corner(&points, (0.4, 0.35)), Corner::UpperRight);
        assert_eq!(emptiest_corner(&points, (0.4, 0.55)), Corner::LowerLeft);
        assert_eq!(emptiest_corner(&[], (0.4, 0.55)), Corner::UpperRight);
    }

    #[test]
    fn ticks_are_short() {
        assert_eq!(format_tick(0.0), "0");
        assert_eq!(format_tick(1e-6), "1e-6");
        assert_eq!(format_tick(1e6), "1e6");
        assert_eq!(format_tick(0.25), "0.25");
        assert_eq!(format_tick(100.0), "100");
    }

    #[test]
    fn renders_log_and_linear_charts() {
        let chart = Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x_log: true,
            y_log: false,
            series: vec![
                Series::new("a", vec![(1.0, 0.0), (10.0, 5.0), (0.0, 1.0)]),
                Series::new("front", vec![(1.0, 0.0), (10.0, 5.0)])
                    .styled(SeriesStyle::Front, vec!["a".into(), "b".into()]),
                Series::new("methods", vec![(2.0, 1.0), (3.0, 2.0)])
                    .styled(SeriesStyle::Points, vec![]),
            ],
        };
        let svg = chart_svg(&chart).expect("svg");
        assert!(svg.starts_with("<svg") && svg.contains("front"));
        let rgb = chart_rgb(&chart).expect("bitmap");
        assert!(rgb.iter().any(|&b| b < 128), "something drawn");
        let empty = Chart {
            series: vec![],
            y_log: true,
            ..chart
        };
        chart_svg(&empty).expect("an empty chart still renders");
    }
}
