//! `scx render`: a picture of the scene with each patch coloured by a per-patch result of a run, with a
//! labelled colour bar (PNG), and optionally the coloured mesh (PLY).

use std::path::{Path, PathBuf};

use plotters::prelude::*;
use scene_complexity::render::{
    bar_labels, default_camera, noise_summary, trace_view, write_ply, Camera, ColourScale,
    PlyFormat, Quantity, Sample, BACK_SIDE, NO_DATA,
};
use scene_complexity::PatchMaterials;
use scene_complexity::Scene;
use scene_complexity::{Measures, RunSpec, StopReason};
use scene_complexity::{Point, Vector};

use super::args::{parse_count, RunOptions};
use super::exit::{Exit, Failure};
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
    /// Global lines of the run behind the colours (accepts `1e7`).
    #[arg(long, default_value = "1e6", value_parser = parse_count, allow_hyphen_values = true)]
    lines: u64,
    #[command(flatten)]
    run: RunOptions,
    /// The camera, in the scene's units: `ex,ey,ez,tx,ty,tz,ux,uy,uz,fov` (eye, target, up, vertical
    /// field of view in degrees). Default: chosen from the geometry (+y up): small probe pictures
    /// from inside each wall of the bounding box, from outside each side (a room open on one side is
    /// seen through the opening) and around an object, the one showing most of the scene's area from
    /// the front, with fewest back sides, kept (the classic view from the -z wall unless another is
    /// over 10% better).
    #[arg(long, value_parser = parse_camera, allow_hyphen_values = true)]
    camera: Option<Camera>,
    /// The size of the scene's picture in pixels, WIDTHxHEIGHT; the file is larger by the colour bar on
    /// the right (210 pixels) and the title strip above (34): 800x600 makes a file of 1010x634.
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
/// The height of the title strip above the picture, pixels.
const HEADER: u32 = 34;
/// The room a colour bar's label needs (its 14-pixel text and a little space), pixels.
const LABEL_GAP: u32 = 16;

/// Runs `scx render`.
pub fn run(args: &RenderArgs) -> Result<Exit, Failure> {
    check_extension(&args.output, "png", "-o")?;
    if let Some(ply) = &args.patches_mesh {
        check_extension(ply, "ply", "--patches-mesh")?;
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
    let analysis = runner.analyze(&cfg, Some(args.lines), "")?;
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
    let noise = noise_summary(patches, &areas, args.color, analysis.lines);
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
    };
    let (pw, ph, pixels) = image.to_rgb(&colours, SUPERSAMPLING);
    let title = format!(
        "{}   {} [{}]   {} lines",
        scene.name,
        args.color.label(),
        args.color.unit(args.per_area),
        grouped(analysis.lines)
    );
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
            analysis.lines,
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

fn check_extension(path: &Path, ext: &str, flag: &str) -> Result<(), Failure> {
    let actual = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if actual == ext {
        Ok(())
    } else {
        Err(Failure::bad_input(format!(
            "{}: {flag} writes a .{ext} file",
            path.display()
        )))
    }
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
}

fn draw_png(
    path: &Path,
    (w, h, pixels): (usize, usize, Vec<u8>),
    title: &str,
    scale: &ColourScale,
    legend: &Legend,
) -> Result<(), Failure> {
    register_font().map_err(Failure::bad_input)?;
    let size = (w as u32 + PANEL, h as u32 + HEADER);
    let fail = |e: &dyn std::fmt::Display| Failure {
        code: Exit::Io,
        message: format!("cannot draw {}: {e}", path.display()),
    };
    let root = BitMapBackend::new(path, size).into_drawing_area();
    draw(&root, (w, h, pixels), title, scale, legend).map_err(|e| fail(&e))?;
    root.present().map_err(|e| fail(&e))
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    (w, h, pixels): (usize, usize, Vec<u8>),
    title: &str,
    scale: &ColourScale,
    legend: &Legend,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let text = |size: u32| ("sans-serif", size).into_font().color(&BLACK);
    root.draw(&Text::new(title.to_string(), (10, 8), text(17)))?;
    let picture =
        BitMapElement::with_owned_buffer((0, HEADER as i32), (w as u32, h as u32), pixels)
            .expect("the buffer has 3 bytes per pixel");
    root.draw(&picture)?;

    // The bar: viridis from the bottom (lo) to the top (hi), ticks on its right.
    let x0 = w as i32 + 22;
    let (top, bottom) = (HEADER as i32 + 28, HEADER as i32 + h as i32 - 130);
    let height = (bottom - top).max(20);
    for k in 0..height {
        let t = 1.0 - f64::from(k) / f64::from(height - 1);
        let [r, g, b] = scene_complexity::render::colour::viridis(t);
        root.draw(&Rectangle::new(
            [(x0, top + k), (x0 + 26, top + k + 1)],
            RGBColor(r, g, b).filled(),
        ))?;
    }
    root.draw(&Rectangle::new([(x0, top), (x0 + 26, top + height)], BLACK))?;
    let y_of = |position: f64| top + ((1.0 - position) * f64::from(height - 1)).round() as i32;
    let labels = bar_labels(
        scale,
        (legend.clipped_low, legend.clipped_high),
        &[],
        f64::from(height - 1),
        f64::from(LABEL_GAP),
    );
    for label in labels {
        let y = y_of(label.position);
        root.draw(&PathElement::new(vec![(x0 + 26, y), (x0 + 32, y)], BLACK))?;
        root.draw(&Text::new(label.text, (x0 + 36, y - 7), text(14)))?;
    }

    // Swatches for what the bar does not cover.
    let mut y = bottom + 22;
    let swatches = [
        (legend.back_sides, BACK_SIDE, "back side (seen from behind)"),
        (legend.no_data, NO_DATA, "no value (no segment left it)"),
    ];
    for (shown, [r, g, b], label) in swatches {
        if !shown {
            continue;
        }
        root.draw(&Rectangle::new(
            [(x0, y), (x0 + 18, y + 14)],
            RGBColor(r, g, b).filled(),
        ))?;
        root.draw(&Rectangle::new([(x0, y), (x0 + 18, y + 14)], BLACK))?;
        for (k, line) in wrap(label, 20).iter().enumerate() {
            root.draw(&Text::new(
                line.clone(),
                (x0 + 24, y + 16 * k as i32),
                text(13),
            ))?;
        }
        y += 44;
    }
    Ok(())
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
