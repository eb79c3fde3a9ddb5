//! `scx render`: a picture of the scene with each patch coloured by a per-patch result of a run, with a
//! labelled colour bar (PNG), and optionally the coloured mesh (PLY).

use std::path::{Path, PathBuf};

use plotters::prelude::*;
use scene_complexity::render::colour::viridis;
use scene_complexity::render::{
    bar_labels, default_camera, fit_title, noise_summary, trace_view, write_ply, Camera,
    ColourScale, PlyFormat, Quantity, Sample, TitleLayout, TitleParts, BACK_SIDE, NO_DATA,
};
use scene_complexity::PatchMaterials;
use scene_complexity::Scene;
use scene_complexity::{sphere_lines_of_drawn, Measures, RunSpec, StopReason};
use scene_complexity::{PatchMeasure, RunWarningKind};
use scene_complexity::{Point, Vector};

use super::args::{parse_count, RunOptions};
use super::exit::{Exit, Failure};
use super::file_kind::check_extension;
use super::output::{self, warn};
use super::plot::{font_path, register_font};
use super::runner::Runner;

/// Arguments of `scx render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// The scene: a file in OBJ, glTF/GLB, PLY or STL (told by its content), a built-in such as
    /// `@cornell` (`scx scenes` lists them), or `-` for a scene on standard input.
    scene: String,
    /// What colours the patches: a per-patch result of the run. scx warns when the colours are mostly
    /// noise: more than 10% of the area left by no line, or an area-weighted median relative standard
    /// error above 20%, and says how many lines would bring it to 10% (errors fall as 1/sqrt(lines)).
    #[arg(long, value_parser = quantity_parser())]
    color: Quantity,
    /// The picture to write (.png).
    #[arg(short, long, value_name = "FILE.png")]
    output: PathBuf,
    /// Also write the mesh with a colour per patch (PLY, for MeshLab or Blender; binary unless
    /// --patches-mesh-format ascii), each face's number in `value` (`valued` 0 where a patch has none).
    #[arg(long, value_name = "FILE.ply")]
    patches_mesh: Option<PathBuf>,
    /// How --patches-mesh stores its numbers: `binary` (binary little-endian PLY: exact, and about a
    /// third of the size of the text) or `ascii` (text, to read or diff).
    #[arg(long, value_enum, default_value_t = MeshFormat::Binary, value_name = "FORMAT",
          requires = "patches_mesh")]
    patches_mesh_format: MeshFormat,
    /// Global lines of the run behind the colours (accepts `1e7`), counted through the bounding sphere as
    /// `scx analyze --lines` counts them.
    #[arg(long, default_value = "1e6", value_parser = parse_count, allow_hyphen_values = true)]
    lines: u64,
    #[command(flatten)]
    run: RunOptions,
    /// The camera, in the scene's units: `ex,ey,ez,tx,ty,tz,ux,uy,uz,fov` (eye, target, up, vertical
    /// field of view in degrees). Default: chosen from the geometry (+y up): small probe pictures
    /// from inside each wall of the bounding box (three quarters up, framing the far wall, the floor
    /// and the lights), from outside each side (a room open on one side is
    /// seen through the opening) and around an object, the one showing most of the scene's area from
    /// the front, with fewest back sides, kept (the classic view from the -z wall unless another is
    /// over 10% better).
    #[arg(long, value_parser = parse_camera, allow_hyphen_values = true)]
    camera: Option<Camera>,
    /// The size of the scene's picture in pixels, WIDTHxHEIGHT; the file is larger by the colour bar on
    /// the right (210 pixels) and the title strip above (34): 800x600 makes a file of 1010x634. A long
    /// title takes two lines in a smaller font; a picture too narrow even for that wraps it on a taller
    /// strip.
    #[arg(long, default_value = "800x600", value_parser = parse_size)]
    size: (usize, usize),
    /// Divide the shares of a sum over patches (mutual-information, continuous-mutual-information,
    /// lost-information) by the patch's area fraction: bits per unit area fraction, comparable between
    /// patches of different sizes.
    #[arg(long)]
    per_area: bool,
    /// The values at the two ends of the colour bar, `LO,HI`. Default: the range of the patches
    /// between the 1% and 99% area quantiles (values beyond are drawn in the end colours).
    #[arg(long, value_parser = parse_range, allow_hyphen_values = true)]
    range: Option<(f64, f64)>,
    /// How values map to colours: `linear`, `log` (equal ratios, equal steps; positive values), or
    /// `auto` (log for the radiosities, which span orders of magnitude; linear otherwise).
    #[arg(long, value_enum, default_value_t = ScaleArg::Auto)]
    scale: ScaleArg,
}

/// `--patches-mesh-format`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum MeshFormat {
    Binary,
    Ascii,
}

impl MeshFormat {
    fn ply(self) -> PlyFormat {
        match self {
            MeshFormat::Binary => PlyFormat::Binary,
            MeshFormat::Ascii => PlyFormat::Ascii,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum ScaleArg {
    Auto,
    Linear,
    Log,
}

/// The per-patch quantities `--color` takes, each with its label in `--help`.
fn quantity_parser() -> impl clap::builder::TypedValueParser<Value = Quantity> {
    let values =
        Quantity::all().map(|q| clap::builder::PossibleValue::new(q.name()).help(q.label()));
    clap::builder::TypedValueParser::map(clap::builder::PossibleValuesParser::new(values), |name| {
        Quantity::from_name(&name).expect("a possible value names a quantity")
    })
}

fn numbers(s: &str, count: usize, what: &str) -> Result<Vec<f64>, String> {
    super::args::not_a_flag(s)?;
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("`{s}`: {what} must be {count} numbers separated by commas"))?;
    if v.len() != count || v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "`{s}`: {what} must be {count} finite numbers separated by commas"
        ));
    }
    Ok(v)
}

fn parse_camera(s: &str) -> Result<Camera, String> {
    let v = numbers(s, 10, "the camera (eye, target, up, field of view)")?;
    let camera = Camera {
        eye: Point::new(v[0], v[1], v[2]),
        target: Point::new(v[3], v[4], v[5]),
        up: Vector::new(v[6], v[7], v[8]),
        fov_degrees: v[9],
    };
    camera.validate().map_err(|e| format!("`{s}`: {e}"))?;
    Ok(camera)
}

fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let (w, h) = s
        .split_once('x')
        .ok_or_else(|| format!("`{s}`: the size is WIDTHxHEIGHT, e.g. 800x600"))?;
    let dim = |d: &str| match d.trim().parse::<usize>() {
        Ok(n) if (64..=8192).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{s}`: width and height must be whole numbers from 64 to 8192"
        )),
    };
    Ok((dim(w)?, dim(h)?))
}

fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let v = numbers(s, 2, "the range")?;
    if v[1] <= v[0] {
        return Err(format!(
            "`{s}`: the range's high end must be above its low end"
        ));
    }
    Ok((v[0], v[1]))
}

/// Samples per pixel along each axis (anti-aliasing).
const SUPERSAMPLING: usize = 2;
/// The width of the colour-bar panel right of the picture, pixels.
const PANEL: u32 = 210;
/// The space left and right of the title, pixels.
const MARGIN: u32 = 10;
/// The room a colour bar's label needs (its 14-pixel text and a little space), pixels.
const LABEL_GAP: u32 = 16;

/// Runs `scx render`.
pub fn run(args: &RenderArgs) -> Result<Exit, Failure> {
    check_extension("-o", &args.output, &["png"])?;
    if let Some(ply) = &args.patches_mesh {
        check_extension("--patches-mesh", ply, &["ply"])?;
    }
    font_path().map_err(Failure::bad_input)?;
    let mut outputs = vec![("-o", args.output.as_path())];
    outputs.extend(args.patches_mesh.as_deref().map(|p| ("--patches-mesh", p)));
    output::check_distinct(&outputs, &[("scene", Path::new(&args.scene))], &[])?;
    output::check_all(outputs.iter().map(|(_, p)| *p))?;
    if args.per_area && !args.color.is_share() {
        return Err(Failure::bad_input(format!(
            "--per-area applies to the shares of a sum over patches, not to {}",
            args.color.name()
        )));
    }
    let runner = Runner::new(&args.scene, &args.run)?;
    output::check_not_read_by(&outputs, &runner.scene)?;
    if args.color.needs_light() && !emits(&runner.scene)? {
        return Err(Failure::bad_input(format!(
            "{}: --color {} needs light, and nothing in this scene emits (no material has Ke above 0)",
            runner.scene.name,
            args.color.name()
        )));
    }
    let cfg = RunSpec {
        measures: Measures::ALL,
        per_patch: true,
        ..args.run.spec(args.lines, args.run.seed.value)
    };
    let analysis = runner.analyze(cfg, "")?;
    for w in &analysis.warnings {
        warn(&w.message);
    }
    let patches = analysis.patches.as_ref().ok_or_else(|| {
        Failure::bad_input("no per-patch results: the run counted no patch pairs")
    })?;
    if analysis.pairs == 0 && !analysis.enclosed && !args.color.needs_light() {
        if let Quantity::Patch(_) = args.color {
            // As the report says: without pairs there are no form factors, and a per-patch reading of 0
            // would read as a measurement.
            let what = if analysis.hits == 0 {
                "no line met the scene: cast more lines".to_string()
            } else {
                "the warnings say what the lines met; --color segments shows where they left the \
                 patches"
                    .to_string()
            };
            return Err(Failure::bad_input(format!(
                "{}: no line segment joined two patches, so --color {} is undefined on every patch \
                 ({what})",
                runner.scene.name,
                args.color.name()
            )));
        }
    }
    let scene = &runner.scene;
    let values = patch_values(scene, patches, args.color, args.per_area);
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
    // In lines through the sphere, as --lines counts them and the advice gives them back.
    let sphere_lines = sphere_lines_of_drawn(&runner.scene, analysis.spec.bound, analysis.lines);
    let noise = noise_summary(patches, &areas, args.color, sphere_lines);
    if let Some(message) = noise.warning(args.color.label()) {
        warn(&format!("{}: {message}", scene.name));
    }
    let log = match args.scale {
        ScaleArg::Auto => args.color.log_by_default(),
        ScaleArg::Linear => false,
        ScaleArg::Log => true,
    };
    let scale = match args.range {
        Some((lo, _)) if log && lo <= 0.0 => {
            return Err(Failure::bad_input(
                "a logarithmic colour scale needs a positive low end in --range",
            ))
        }
        Some((lo, hi)) => ColourScale { lo, hi, log },
        None => ColourScale::spanning(&values, &areas, 0.01, log).ok_or_else(|| {
            Failure::bad_input(format!(
                "no patch has a {}value of {} to show",
                if log { "positive " } else { "" },
                args.color.name()
            ))
        })?,
    };
    let colours: Vec<[u8; 3]> = values.iter().map(|&v| scale.colour(v)).collect();
    let camera = match args.camera {
        Some(c) => c,
        None => default_camera(scene, runner.tracer()).map_err(tracer_failure)?,
    };
    let (w, h) = args.size;
    let image = runner
        .pool
        .install(|| {
            trace_view(
                scene,
                runner.tracer(),
                &camera,
                w * SUPERSAMPLING,
                h * SUPERSAMPLING,
            )
        })
        .map_err(tracer_failure)?;
    let shown = Legend {
        back_sides: image
            .samples
            .iter()
            .any(|s| matches!(s, Sample::Back { .. })),
        no_data: image
            .samples
            .iter()
            .any(|s| matches!(s, Sample::Front { patch, .. } if values[*patch as usize].is_none())),
        clipped_low: values.iter().flatten().any(|&v| v < scale.lo),
        clipped_high: values.iter().flatten().any(|&v| v > scale.hi),
        below_theory: below_theory(args.color, &analysis, &scale),
    };
    let (pw, ph, pixels) = image.to_rgb(&colours, SUPERSAMPLING);
    let quantity = format!(
        "{} [{}]",
        args.color.label(),
        args.color.unit(args.per_area)
    );
    let lines = format!("{} lines", grouped(sphere_lines));
    let title = TitleParts {
        scene: &scene.name,
        quantity: &quantity,
        lines: &lines,
    };
    let mut picture = Some((pw, ph, pixels));
    output::write_via(&args.output, "png", |temporary| {
        let picture = picture.take().unwrap_or_default();
        draw_png(temporary, picture, &title, &scale, &shown).map_err(|f| f.message)
    })?;
    output::wrote(&args.output);
    if let Some(ply) = &args.patches_mesh {
        let comment = format!(
            "{} coloured by {} ({}) from {} lines, viridis from {} to {}\n\
             value: the patch's number; valued 0: the patch has none (its value written as 0)\n\
             written by scx {}",
            scene.name,
            args.color.label(),
            args.color.unit(args.per_area),
            sphere_lines,
            scale.lo,
            scale.hi,
            env!("CARGO_PKG_VERSION")
        );
        output::write_with(ply, |out| {
            write_ply(
                out,
                scene,
                &colours,
                &values,
                &comment,
                args.patches_mesh_format.ply(),
            )
        })?;
    }
    Ok(if analysis.stop_reason == StopReason::Interrupted {
        Exit::Interrupted
    } else {
        Exit::Ok
    })
}

fn emits(scene: &Scene) -> Result<bool, Failure> {
    Ok(PatchMaterials::of_scene(scene)
        .map_err(Failure::bad_input)?
        .any_emission())
}

fn tracer_failure(e: impl ToString) -> Failure {
    Failure {
        code: Exit::Failed,
        message: e.to_string(),
    }
}

/// Each patch's value of the quantity, divided by its area fraction when `per_area`.
fn patch_values(
    scene: &Scene,
    patches: &[scene_complexity::PatchResult],
    quantity: Quantity,
    per_area: bool,
) -> Vec<Option<f64>> {
    let total = scene.total_area();
    patches
        .iter()
        .zip(&scene.patches)
        .map(|(p, patch)| {
            let v = quantity.of(p)?;
            Some(if per_area { v * total / patch.area } else { v })
        })
        .collect()
}

/// What the legend under the colour bar explains.
struct Legend {
    back_sides: bool,
    no_data: bool,
    clipped_low: bool,
    clipped_high: bool,
    /// The least value the theory allows, when the bar runs below it, and what the part below is.
    below_theory: Option<(f64, &'static str)>,
}

/// The least value the theory allows the quantity, when the colour scale runs below it, and what the
/// readings below it are: the run's own warning names the plug-in bias when it counted such patches.
fn below_theory(
    quantity: Quantity,
    analysis: &scene_complexity::Analysis,
    scale: &ColourScale,
) -> Option<(f64, &'static str)> {
    let closed = analysis.escapes == 0 && analysis.pairs > 0;
    let least = quantity
        .least_in_theory(closed)
        .filter(|&least| scale.lo < least)?;
    let warned = analysis
        .warnings
        .iter()
        .any(|w| w.kind == RunWarningKind::NegativeLostInformation);
    let plug_in = quantity == Quantity::Patch(PatchMeasure::LostInformation);
    Some((
        least,
        if plug_in && warned {
            "below 0: plug-in bias, see warning"
        } else {
            "below 0: the estimate's error (0 or more in theory)"
        },
    ))
}

fn draw_png(
    path: &Path,
    (w, h, pixels): (usize, usize, Vec<u8>),
    title: &TitleParts,
    scale: &ColourScale,
    legend: &Legend,
) -> Result<(), Failure> {
    register_font().map_err(Failure::bad_input)?;
    let title = fit_title(title, f64::from(w as u32 + PANEL - 2 * MARGIN), &text_width);
    let header = title.height().ceil() as u32;
    let panel = Panel::new(h as i32, &legend.entries());
    let size = (
        w as u32 + PANEL,
        (h as u32).max(panel.height as u32) + header,
    );
    let fail = |e: &dyn std::fmt::Display| Failure {
        code: Exit::Io,
        message: format!("cannot draw {}: {e}", path.display()),
    };
    let root = BitMapBackend::new(path, size).into_drawing_area();
    let (title_area, rest) = root.split_vertically(header);
    draw_title(&title_area, &title).map_err(|e| fail(&e))?;
    draw(&rest, (w, h, pixels), scale, legend).map_err(|e| fail(&e))?;
    root.present().map_err(|e| fail(&e))
}

/// The width of `text` in the labels' font at `size`, pixels (unmeasurable text counts as too wide).
fn text_width(text: &str, size: f64) -> f64 {
    ("sans-serif", size)
        .into_font()
        .box_size(text)
        .map_or(f64::INFINITY, |(w, _)| f64::from(w))
}

fn draw_title<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &TitleLayout,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    area.fill(&WHITE)?;
    let font = ("sans-serif", title.size).into_font().color(&BLACK);
    for (k, line) in title.lines.iter().enumerate() {
        let at = (MARGIN as i32, title.top(k) as i32);
        area.draw(&Text::new(line.clone(), at, font.clone()))?;
    }
    Ok(())
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    (w, h, pixels): (usize, usize, Vec<u8>),
    scale: &ColourScale,
    legend: &Legend,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let picture = BitMapElement::with_owned_buffer((0, 0), (w as u32, h as u32), pixels)
        .expect("the buffer has 3 bytes per pixel");
    root.draw(&picture)?;
    let entries = legend.entries();
    let panel = Panel::new(h as i32, &entries);
    let x0 = w as i32 + 22;
    draw_bar(root, x0, &panel, scale, legend)?;
    draw_entries(root, x0, panel.legend_top, &entries)
}

fn label_font(size: u32) -> TextStyle<'static> {
    ("sans-serif", size).into_font().color(&BLACK)
}

/// The bar: viridis from the bottom (lo) to the top (hi), labels on its right.
fn draw_bar<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    x0: i32,
    panel: &Panel,
    scale: &ColourScale,
    legend: &Legend,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (top, height) = (BAR_TOP, panel.length);
    for k in 0..height {
        let t = 1.0 - f64::from(k) / f64::from(height - 1);
        let [r, g, b] = viridis(t);
        root.draw(&Rectangle::new(
            [(x0, top + k), (x0 + 26, top + k + 1)],
            RGBColor(r, g, b).filled(),
        ))?;
    }
    let y_of = |position: f64| top + ((1.0 - position) * f64::from(height - 1)).round() as i32;
    let marks: Vec<f64> = legend.below_theory.iter().map(|b| b.0).collect();
    if let Some(&least) = marks.first() {
        hatch(
            root,
            [(x0, y_of(scale.position(least))), (x0 + 26, top + height)],
        )?;
    }
    root.draw(&Rectangle::new([(x0, top), (x0 + 26, top + height)], BLACK))?;
    let labels = bar_labels(
        scale,
        (legend.clipped_low, legend.clipped_high),
        &marks,
        f64::from(height - 1),
        f64::from(LABEL_GAP),
    );
    for label in labels {
        let y = y_of(label.position);
        root.draw(&PathElement::new(vec![(x0 + 26, y), (x0 + 32, y)], BLACK))?;
        root.draw(&Text::new(label.text, (x0 + 36, y - 7), label_font(14)))?;
    }
    Ok(())
}

/// The legend under the bar: a swatch and its wrapped text per entry, from `y` down.
fn draw_entries<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    x0: i32,
    mut y: i32,
    entries: &[Entry],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for entry in entries {
        let [r, g, b] = entry.colour;
        let swatch = [(x0, y), (x0 + 18, y + 14)];
        root.draw(&Rectangle::new(swatch, RGBColor(r, g, b).filled()))?;
        if entry.hatched {
            hatch(root, swatch)?;
        }
        root.draw(&Rectangle::new(swatch, BLACK))?;
        for (k, line) in entry.lines().iter().enumerate() {
            root.draw(&Text::new(
                line.clone(),
                (x0 + 24, y + ENTRY_LINE * k as i32),
                label_font(13),
            ))?;
        }
        y += entry.height();
    }
    Ok(())
}

/// The top of the colour bar in the panel right of the picture, pixels (room for its top label).
const BAR_TOP: i32 = 28;
/// What a picture of ordinary height leaves under the bar for the legend, pixels.
const UNDER_BAR: i32 = 130;
/// The shortest bar: room for its two ends' labels and a tick between, pixels.
const SHORTEST_BAR: i32 = 40;
/// The space between the bar and the legend, pixels.
const LEGEND_SPACE: i32 = 22;
/// The distance between two lines of a legend entry, pixels.
const ENTRY_LINE: i32 = 16;

/// Light diagonal lines over the rectangle from its top left to its bottom right corner: the part of
/// the bar the theory rules out, its colours still showing between them.
fn hatch<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    [(x0, y0), (x1, y1)]: [(i32, i32); 2],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let style = WHITE.mix(0.75).stroke_width(1);
    // The lines x - y = c through the rectangle, each from where it enters to where it leaves.
    for c in ((x0 - y1)..=(x1 - y0)).step_by(HATCH_SPACING) {
        let (top, bottom) = (y0.max(x0 - c), y1.min(x1 - c));
        if top < bottom {
            root.draw(&PathElement::new(
                vec![(top + c, top), (bottom + c, bottom)],
                style,
            ))?;
        }
    }
    Ok(())
}

/// The distance between hatching lines along the bar, pixels.
const HATCH_SPACING: usize = 6;

/// An entry of the legend under the bar.
struct Entry {
    colour: [u8; 3],
    /// Hatched: the part of the bar below what the theory allows.
    hatched: bool,
    text: &'static str,
}

impl Entry {
    fn lines(&self) -> Vec<String> {
        wrap(self.text, 20)
    }

    /// Its lines and the space after it, pixels.
    fn height(&self) -> i32 {
        ENTRY_LINE * self.lines().len() as i32 + 12
    }
}

/// Where the bar and the legend go in the panel, pixels from its top.
struct Panel {
    /// The bar's length.
    length: i32,
    /// The top of the legend.
    legend_top: i32,
    /// The height the bar and the legend need: a small picture's file grows to it.
    height: i32,
}

impl Panel {
    /// The bar as long as the picture allows with the legend under it, at least [`SHORTEST_BAR`].
    fn new(picture_height: i32, entries: &[Entry]) -> Self {
        let legend: i32 = entries.iter().map(Entry::height).sum();
        let under = UNDER_BAR.max(LEGEND_SPACE + legend + 8);
        let length = (picture_height - BAR_TOP - under).max(SHORTEST_BAR);
        let legend_top = BAR_TOP + length + LEGEND_SPACE;
        // The bottom label reaches half a label below the bar.
        let height = if entries.is_empty() {
            BAR_TOP + length + LABEL_GAP as i32 / 2 + 2
        } else {
            legend_top + legend
        };
        Panel {
            length,
            legend_top,
            height,
        }
    }
}

impl Legend {
    /// The entries the picture needs: the colours it shows that the bar does not cover.
    fn entries(&self) -> Vec<Entry> {
        let all = [
            (self.back_sides, BACK_SIDE, "back side (seen from behind)"),
            (self.no_data, NO_DATA, "no value (no segment left it)"),
        ];
        let below = self.below_theory.map(|(_, text)| Entry {
            colour: viridis(0.0),
            hatched: true,
            text,
        });
        all.into_iter()
            .filter(|(shown, ..)| *shown)
            .map(|(_, colour, text)| Entry {
                colour,
                hatched: false,
                text,
            })
            .chain(below)
            .collect()
    }
}

/// A whole number with its digits in groups of three (`10 000 000`).
fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (k, c) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// Breaks `s` into lines of at most about `width` characters at spaces.
fn wrap(s: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in s.split(' ') {
        match lines.last_mut() {
            Some(l) if l.len() + 1 + word.len() <= width => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_size_and_range_parse_or_say_why_not() {
        let c = parse_camera("0.5,0.5,0.01, 0.5,0.5,1, 0,1,0, 60").unwrap();
        assert_eq!(c.fov_degrees, 60.0);
        assert!(parse_camera("0,0,0,0,0,0,0,1,0,60")
            .unwrap_err()
            .contains("same point"));
        assert!(parse_camera("0,0,0,0,0,1,0,0,1,60")
            .unwrap_err()
            .contains("up"));
        assert!(parse_camera("0,0,0,0,0,1,0,1,0,180")
            .unwrap_err()
            .contains("between 0 and 180"));
        assert!(parse_camera("1,2,3").unwrap_err().contains("10"));
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        assert!(parse_size("640").is_err() && parse_size("10x10").is_err());
        assert_eq!(parse_range("-1,2"), Ok((-1.0, 2.0)));
        assert!(parse_range("2,1").is_err());
        assert_eq!(grouped(10_000_000), "10 000 000");
        assert_eq!(grouped(999), "999");
    }
}
