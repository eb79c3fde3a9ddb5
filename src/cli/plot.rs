//! The convergence plot: error against run time, log-log, one line per measure (plotters).

use std::path::Path;

use plotters::prelude::*;
use plotters::style::FontStyle;

/// One curve: a measure's error (standard error, or distance to the largest run) against seconds.
pub struct Curve {
    /// Legend text.
    pub label: String,
    /// Colour index (the same for a measure's two curves).
    pub colour: usize,
    /// Dashed (distance to the largest run) or solid (standard error).
    pub dashed: bool,
    /// (seconds, error) points, both positive.
    pub points: Vec<(f64, f64)>,
}

/// Fonts tried for the labels, unless `SCX_FONT` names one.
const FONT_PATHS: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
];

/// Loads a TrueType font for the labels (plotters draws text with it, SVG and PNG alike).
fn register_font() -> Result<(), String> {
    let candidates: Vec<String> = std::env::var("SCX_FONT")
        .into_iter()
        .chain(FONT_PATHS.iter().map(|s| s.to_string()))
        .collect();
    let path = candidates
        .iter()
        .find(|p| Path::new(p).exists())
        .ok_or_else(|| {
            "a plot needs a TrueType font for its labels: install fonts-dejavu-core, or name a .ttf file in \
             SCX_FONT"
                .to_string()
        })?;
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    // plotters keeps fonts for the life of the process.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
        .map_err(|_| format!("{path}: not a usable TrueType font"))
}

/// Writes the plot to `path`, SVG or PNG by its extension.
pub fn write(path: &Path, title: &str, curves: &[Curve]) -> Result<(), String> {
    register_font()?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let shown = path.display().to_string();
    let fail = |e: &dyn std::fmt::Display| format!("{shown}: {e}");
    match ext.as_str() {
        "svg" => draw(
            SVGBackend::new(path, (960, 640)).into_drawing_area(),
            title,
            curves,
        )
        .map_err(|e| fail(&e)),
        "png" => draw(
            BitMapBackend::new(path, (960, 640)).into_drawing_area(),
            title,
            curves,
        )
        .map_err(|e| fail(&e)),
        _ => Err(format!("{shown}: the plot must be a .svg or .png file")),
    }
}

/// A compact tick label: 0.2, 15, 3e-4.
fn tick(v: f64) -> String {
    if (1e-2..1e4).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

fn bounds(curves: &[Curve]) -> ((f64, f64), (f64, f64)) {
    let pts = curves.iter().flat_map(|c| c.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return ((0.01, 1.0), (1e-4, 1.0));
    }
    ((x0 / 1.5, x1 * 1.5), (y0 / 2.0, y1 * 2.0))
}

fn draw<DB: DrawingBackend>(
    area: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    curves: &[Curve],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    area.fill(&WHITE)?;
    let ((x0, x1), (y0, y1)) = bounds(curves);
    let mut chart = ChartBuilder::on(&area)
        .caption(title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("run time (seconds, log scale)")
        .y_desc("error in bits (log scale)")
        .x_label_formatter(&|x| tick(*x))
        .y_label_formatter(&|y| tick(*y))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()?;
    for c in curves {
        let colour = Palette99::pick(c.colour).to_rgba();
        let style = ShapeStyle::from(colour).stroke_width(2);
        let series = if c.dashed {
            chart.draw_series(DashedLineSeries::new(c.points.iter().copied(), 8, 5, style))?
        } else {
            chart.draw_series(LineSeries::new(c.points.iter().copied(), style))?
        };
        // Markers tell the two kinds apart in the legend too: circles for the standard error, triangles
        // for the distance to the largest run.
        let dashed = c.dashed;
        series.label(c.label.clone()).legend(move |(x, y)| {
            let marker: DynElement<'static, DB, (i32, i32)> = if dashed {
                TriangleMarker::new((x + 10, y), 5, colour.filled()).into_dyn()
            } else {
                Circle::new((x + 10, y), 4, colour.filled()).into_dyn()
            };
            EmptyElement::at((0, 0)) + PathElement::new(vec![(x, y), (x + 20, y)], style) + marker
        });
        if dashed {
            chart.draw_series(
                c.points
                    .iter()
                    .map(|&p| TriangleMarker::new(p, 5, colour.filled())),
            )?;
        } else {
            chart.draw_series(c.points.iter().map(|&p| Circle::new(p, 4, colour.filled())))?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    area.present()
}
