//! The convergence plot: error against run time, log-log, one series per measure (plotters).
//!
//! Readable by everyone: the Okabe–Ito colours (safe for the common colour-vision deficiencies), and a
//! marker shape per measure besides its colour; standard errors solid, distances to the largest run
//! dashed; the points labelled with their line counts; ticks in one notation; axes with their units.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::FontStyle;
use scene_complexity::render::colour::log_ticks;

use super::file_kind::{check_extension, extension};

/// Which measure a curve belongs to: its colour and marker.
#[derive(Clone, Copy, Debug)]
pub struct Series(pub usize);

/// One curve: a measure's error (standard error, or distance to the largest run) against seconds.
pub struct Curve {
    /// Legend text.
    pub label: String,
    /// The measure (the same for a measure's two curves).
    pub series: Series,
    /// Dashed (distance to the largest run) or solid (standard error).
    pub dashed: bool,
    /// (seconds, error, label) points, both numbers positive.
    pub points: Vec<(f64, f64, String)>,
}

/// Okabe and Ito's colour-blind-safe palette (blue, vermillion, bluish green, orange, reddish purple).
const OKABE_ITO: [RGBColor; 5] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(230, 159, 0),
    RGBColor(204, 121, 167),
];

/// Fonts tried for the labels, unless `SCX_FONT` names one.
const FONT_PATHS: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
];

/// Checks, before any work, that a plot can be drawn to `path`: its extension and a font.
pub fn check_target(path: &Path) -> Result<(), String> {
    check_extension("--plot", path, &["svg", "png"]).map_err(|f| f.message)?;
    font_path().map(drop)
}

pub(super) fn font_path() -> Result<String, String> {
    std::env::var("SCX_FONT")
        .into_iter()
        .chain(FONT_PATHS.iter().map(|s| s.to_string()))
        .find(|p| Path::new(p).exists())
        .ok_or_else(|| {
            "a plot needs a TrueType font for its labels: install fonts-dejavu-core, or name a .ttf file in \
             SCX_FONT"
                .to_string()
        })
}

/// Loads a TrueType font for the labels (plotters draws text with it, SVG and PNG alike).
pub(super) fn register_font() -> Result<(), String> {
    let path = font_path()?;
    let bytes = std::fs::read(&path).map_err(|e| format!("{path}: {e}"))?;
    // plotters keeps fonts for the life of the process.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
        .map_err(|_| format!("{path}: not a usable TrueType font"))
}

/// Writes the plot to `path`, SVG or PNG by its extension.
pub fn write(path: &Path, title: &str, curves: &[Curve]) -> Result<(), String> {
    check_target(path)?;
    register_font()?;
    let ext = extension(path);
    super::output::write_via(path, &ext, |temporary| {
        draw_to(temporary, &ext, title, curves)
    })
    .map_err(|f| f.message)
}

/// Draws the plot into `path`, as SVG or PNG by `ext`.
fn draw_to(path: &Path, ext: &str, title: &str, curves: &[Curve]) -> Result<(), String> {
    let shown = path.display().to_string();
    let fail = |e: &dyn std::fmt::Display| format!("cannot draw {shown}: {e}");
    if ext == "svg" {
        draw(
            SVGBackend::new(path, (1000, 680)).into_drawing_area(),
            title,
            curves,
        )
        .map_err(|e| fail(&e))
    } else {
        draw(
            BitMapBackend::new(path, (1000, 680)).into_drawing_area(),
            title,
            curves,
        )
        .map_err(|e| fail(&e))
    }
}

/// A tick label in one notation for the whole axis: powers of ten as `1e-3`, other values with the
/// mantissa (`2e-3`, `5e1`).
fn tick(v: f64) -> String {
    let s = format!("{v:.0e}");
    s.replace("e0", "")
}

/// The points' extent in seconds and in error, `None` without points.
fn extent(curves: &[Curve]) -> Option<((f64, f64), (f64, f64))> {
    let pts = curves.iter().flat_map(|c| c.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for &(x, y, _) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    (x0.is_finite() && y0.is_finite()).then_some(((x0, x1), (y0, y1)))
}

/// A log axis: its range and its labelled ticks.
#[derive(Clone, Debug, PartialEq)]
struct LogAxis {
    range: (f64, f64),
    ticks: Vec<f64>,
}

/// The fewest labelled ticks an axis gets.
const FEWEST_TICKS: usize = 3;

impl LogAxis {
    /// An axis over `lo..hi` (positive) with `pad` (below, above) as factors of room, ticked on 1, 2 and
    /// 5 x 10^k (powers of ten over many decades). A range holding fewer than [`FEWEST_TICKS`] of them
    /// (the points of one line count lie within a factor of a few) is widened to the powers of ten
    /// around it, which hold four.
    fn new(lo: f64, hi: f64, pad: (f64, f64)) -> Self {
        let (lo, hi) = (lo / pad.0, hi * pad.1);
        let ticks = log_ticks(lo, hi);
        if ticks.len() >= FEWEST_TICKS {
            return LogAxis {
                range: (lo, hi),
                ticks,
            };
        }
        let (below, mut above) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        if above == below {
            above += 1;
        }
        let range = (10f64.powi(below), 10f64.powi(above));
        LogAxis {
            range,
            ticks: log_ticks(range.0, range.1),
        }
    }

    /// The faint grid lines: 1 to 9 x 10^k within the range.
    fn grid(&self) -> Vec<f64> {
        let (lo, hi) = self.range;
        let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (first..=last)
            .flat_map(|k| (1..10).map(move |m| f64::from(m) * 10f64.powi(k)))
            .filter(|v| *v >= lo && *v <= hi)
            .collect()
    }
}

/// The axes of the plot: seconds and error, each with room around the points; a plot without points
/// gets the axes of a typical run.
fn axes(curves: &[Curve]) -> (LogAxis, LogAxis) {
    let ((x0, x1), (y0, y1)) = extent(curves).unwrap_or(((0.016, 0.4), (4e-4, 0.4)));
    (
        LogAxis::new(x0, x1, (1.6, 2.5)),
        LogAxis::new(y0, y1, (2.5, 2.5)),
    )
}

/// The marker of a series: circle, triangle, square, diamond, cross.
fn marker<DB: DrawingBackend>(
    series: Series,
    at: (i32, i32),
    colour: RGBColor,
) -> DynElement<'static, DB, (i32, i32)> {
    let style = colour.filled();
    let (x, y) = at;
    match series.0 % 5 {
        0 => Circle::new(at, 5, style).into_dyn(),
        1 => TriangleMarker::new(at, 6, style).into_dyn(),
        2 => Rectangle::new([(x - 4, y - 4), (x + 4, y + 4)], style).into_dyn(),
        3 => Polygon::new(vec![(x, y - 6), (x + 6, y), (x, y + 6), (x - 6, y)], style).into_dyn(),
        _ => Cross::new(at, 5, colour.stroke_width(2)).into_dyn(),
    }
}

fn draw<DB: DrawingBackend>(
    area: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    curves: &[Curve],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    area.fill(&WHITE)?;
    let (x, y) = axes(curves);
    let coordinates = |axis: &LogAxis| {
        (axis.range.0..axis.range.1)
            .log_scale()
            .with_key_points(axis.ticks.clone())
            .with_light_points(axis.grid())
    };
    let mut chart = ChartBuilder::on(&area)
        .caption(title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(52)
        .y_label_area_size(76)
        .build_cartesian_2d(coordinates(&x), coordinates(&y))?;
    chart
        .configure_mesh()
        .x_desc("run time (s, log scale)")
        .y_desc("error (bits, log scale)")
        .x_label_formatter(&|x| tick(*x))
        .y_label_formatter(&|y| tick(*y))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()?;
    for c in curves {
        let colour = OKABE_ITO[c.series.0 % OKABE_ITO.len()];
        let style = ShapeStyle::from(colour).stroke_width(2);
        let line = c.points.iter().map(|p| (p.0, p.1));
        let drawn = if c.dashed {
            chart.draw_series(DashedLineSeries::new(line, 9, 6, style))?
        } else {
            chart.draw_series(LineSeries::new(line, style))?
        };
        let series = c.series;
        let dashed = c.dashed;
        drawn.label(c.label.clone()).legend(move |(x, y)| {
            // Three pieces: apart for a dashed curve, overlapping into one line for a solid one.
            let (len, step) = if dashed { (6, 11) } else { (10, 9) };
            let piece =
                |k: i32| PathElement::new(vec![(x + k * step, y), (x + k * step + len, y)], style);
            EmptyElement::at((0, 0))
                + piece(0)
                + piece(1)
                + piece(2)
                + marker::<DB>(series, (x + 14, y), colour)
        });
        chart.draw_series(
            c.points
                .iter()
                .map(|p| EmptyElement::at((p.0, p.1)) + marker::<DB>(c.series, (0, 0), colour)),
        )?;
        // Line counts beside the first curve's points (every curve shares their x, and run time).
        if std::ptr::eq(c, &curves[0]) {
            chart.draw_series(c.points.iter().map(|p| {
                EmptyElement::at((p.0, p.1))
                    + Text::new(p.2.clone(), (7, -16), ("sans-serif", 12).into_font())
            }))?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    area.present()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_use_one_notation() {
        assert_eq!(tick(0.001), "1e-3");
        assert_eq!(tick(0.01), "1e-2");
        assert_eq!(tick(1.0), "1");
        assert_eq!(tick(100.0), "1e2");
        assert_eq!(tick(0.002), "2e-3");
    }

    /// Errors of one line count whose padded range holds two round ticks get the decade around them;
    /// points over decades keep their padded range and its ticks.
    #[test]
    fn a_narrow_axis_widens_to_whole_decades() {
        let one = LogAxis::new(0.03, 0.031, (2.5, 2.5));
        assert_eq!(one.range, (0.01, 0.1));
        let labels = |a: &LogAxis| a.ticks.iter().map(|&t| tick(t)).collect::<Vec<_>>();
        assert_eq!(labels(&one), ["1e-2", "2e-2", "5e-2", "1e-1"]);
        let many = LogAxis::new(1e-4, 0.1, (2.5, 2.5));
        assert_eq!(many.range, (1e-4 / 2.5, 0.1 * 2.5));
        assert_eq!(labels(&many), ["1e-4", "1e-3", "1e-2", "1e-1"]);
        assert!(many
            .grid()
            .iter()
            .all(|v| *v >= many.range.0 && *v <= many.range.1));
    }
}
