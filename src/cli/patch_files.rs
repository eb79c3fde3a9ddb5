//! `--patches FILE` and `--form-factors FILE` of `scx analyze` and `scx merge`: the per-patch results
//! and the sparse form-factor matrix, written for pandas, polars, numpy and scipy.
//!
//! * `--patches x.csv`: one row per patch, in the order `scx export` writes the faces
//!   (docs/per-patch.md, "Per-patch results", lists the columns and their units);
//! * `--form-factors x.csv`: one row per non-zero `F_ij` (i, j, N_ij, N_i, F_ij and its standard error
//!   `sqrt(F (1 - F) / N_i)`, the binomial error of a row's share);
//! * `--form-factors x.mtx`: the same matrix as Matrix Market coordinates (`scipy.io.mmread`), 1-based.

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use scene_complexity::report::{object_table, patch_table, FormFactors, Table};
use scene_complexity::Analysis;
use scene_complexity::PatchMeasure;
use scene_complexity::RunIdentity;
use scene_complexity::Scene;
use scene_complexity::Wanted;
use scene_complexity::{sphere_lines_of_drawn, LineBound};

use super::exit::Failure;
use super::file_kind::{check_csv, check_extension, extension};
use super::output::{self, warn};

/// The per-patch files of `scx analyze` and `scx merge`.
#[derive(clap::Args, Debug)]
pub struct PatchFiles {
    /// Also write one row per patch to FILE (.csv): id (the order `scx export` writes faces), material,
    /// area, centroid and normal in the scene's units, segments N_i, row entropy, its terms of I_s and
    /// I_s^c, the information it loses, radiosity when lit, each with its standard error. Repeat to
    /// write several files. After --resume or `scx merge`, the I_s^c and lost-information columns need
    /// the per-patch sums a run state keeps only when its run was asked for --patches.
    #[arg(long, value_name = "FILE")]
    pub patches: Vec<PathBuf>,
    /// Also write the sparse form-factor matrix to FILE: `.csv` (i, j, n_ij, n_i, f_ij, f_ij_stderr) or
    /// `.mtx` (Matrix Market, for scipy.io.mmread); any other extension is refused. Repeat to write
    /// both.
    #[arg(long, value_name = "FILE")]
    pub form_factors: Vec<PathBuf>,
    /// Also write one row per object (the groups, meshes or nodes the scene file names) to FILE (.csv):
    /// name, patches, triangles, area, segments, escapes and how lines met its sides, and its share of
    /// each per-patch quantity with its standard error (the sums of its patches' terms of I_s and I_s^c;
    /// sum a_i H_i for the row entropies; area-weighted means for the radiosities). Gathers what
    /// --patches gathers.
    #[arg(long, value_name = "FILE")]
    pub objects: Vec<PathBuf>,
}

impl PatchFiles {
    /// The files asked for, each with its option (for [`output::check_distinct`]).
    pub fn outputs(&self) -> Vec<(&'static str, &Path)> {
        let patches = self.patches.iter().map(|p| ("--patches", p.as_path()));
        let matrices = self
            .form_factors
            .iter()
            .map(|p| ("--form-factors", p.as_path()));
        let objects = self.objects.iter().map(|p| ("--objects", p.as_path()));
        patches.chain(matrices).chain(objects).collect()
    }

    /// Whether no per-patch file was asked for (`--objects` aside: it has rows for any run).
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty() && self.form_factors.is_empty()
    }

    /// Whether the run must gather the per-patch sums of eq. (27) ([`scene_complexity::RunSpec::per_patch`]).
    pub fn wants_per_patch(&self) -> bool {
        !self.patches.is_empty() || !self.objects.is_empty()
    }

    /// Checks, before any work, the files' kinds and that they can be written.
    pub fn check(&self) -> Result<(), Failure> {
        check_csv("--patches", self.patches.iter().map(PathBuf::as_path))?;
        check_csv("--objects", self.objects.iter().map(PathBuf::as_path))?;
        for p in &self.form_factors {
            check_extension("--form-factors", p, MATRIX_EXTENSIONS)?;
        }
        output::check_all(
            self.patches
                .iter()
                .chain(&self.form_factors)
                .chain(&self.objects)
                .map(PathBuf::as_path),
        )
    }

    /// Checks, before any line is cast or any measure computed, that a saved run (read from `file`, or
    /// the merge of states whose first is `file`) can give these files: it must have counted patch
    /// pairs. `wanted` is what the run gathers, and `without_sums` the state
    /// files that keep no per-patch sums of eq. (27) although their run computes I_s^c (their run was
    /// not asked for `--patches`): then the I_s^c columns are left empty, and a warning names them,
    /// rather than sharing out sums of only some of the lines.
    pub fn check_saved(
        &self,
        file: &str,
        identity: &RunIdentity,
        wanted: Wanted,
        without_sums: &[String],
    ) -> Result<(), Failure> {
        if self.is_empty() {
            return Ok(());
        }
        if !wanted.discrete {
            return Err(Failure::bad_input(format!(
                "{file}: the run counted no patch pairs (--measures without discrete): it has no \
                 per-patch results or form factors"
            )));
        }
        if !self.patches.is_empty() && wanted.continuous && !without_sums.is_empty() {
            warn(&format!(
                "{}: saved without the per-patch sums of eq. (27) (the run was not asked for \
                 --patches{}), so the {} and {} columns of --patches stay empty; give --patches to the \
                 first run (to every shard) to have them",
                without_sums.join(", "),
                if identity.spec.enclose {
                    ", or was enclosed by an scx from before the environment had a row of its own"
                } else {
                    ""
                },
                PatchMeasure::ContinuousTerm.info().column,
                PatchMeasure::LostInformation.info().column
            ));
        }
        Ok(())
    }

    /// Writes every file asked for from a finished analysis.
    pub fn write(&self, scene: &Scene, a: &Analysis) -> Result<(), Failure> {
        write_patches(&self.patches, scene, a)?;
        write_form_factors(&self.form_factors, scene, a)?;
        if !self.objects.is_empty() {
            let table = object_table(a);
            for path in &self.objects {
                write_with(path, |w| table_csv(w, &table))?;
            }
        }
        Ok(())
    }
}

/// The kinds of form-factor file, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum MatrixFormat {
    Csv,
    MatrixMarket,
}

/// The extensions of a form-factor file: CSV, or Matrix Market.
const MATRIX_EXTENSIONS: &[&str] = &["csv", "mtx"];

fn matrix_format(path: &Path) -> Result<MatrixFormat, Failure> {
    check_extension("--form-factors", path, MATRIX_EXTENSIONS)?;
    Ok(if extension(path) == "mtx" {
        MatrixFormat::MatrixMarket
    } else {
        MatrixFormat::Csv
    })
}

/// Writes the per-patch results to every file in `paths`.
fn write_patches(paths: &[PathBuf], scene: &Scene, a: &Analysis) -> Result<(), Failure> {
    if paths.is_empty() {
        return Ok(());
    }
    let Some(patches) = &a.patches else {
        return Err(Failure::bad_input(
            "no per-patch results: the run counted no patch pairs",
        ));
    };
    let table = patch_table(scene, patches);
    for path in paths {
        write_with(path, |w| table_csv(w, &table))?;
    }
    Ok(())
}

/// Writes the form-factor matrix to every file in `paths`.
fn write_form_factors(paths: &[PathBuf], scene: &Scene, a: &Analysis) -> Result<(), Failure> {
    if paths.is_empty() {
        return Ok(());
    }
    let Some(matrix) = FormFactors::of(a, scene.patch_count()) else {
        return Err(Failure::bad_input(
            "no form factors: the run counted no patch pairs (--measures without discrete)",
        ));
    };
    for path in paths {
        match matrix_format(path)? {
            MatrixFormat::Csv => write_with(path, |w| matrix_csv(w, &matrix))?,
            MatrixFormat::MatrixMarket => {
                write_with(path, |w| matrix_market(w, scene, a, &matrix))?
            }
        }
    }
    Ok(())
}

/// Writes `path` whole or not at all from what `fill` writes, and says so.
fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), Failure> {
    let mut fill = Some(fill);
    output::write_with(path, |w| match fill.take() {
        Some(f) => f(w),
        None => Ok(()),
    })
}

/// Entries formatted per chunk, in parallel: a fine mesh has millions of them, and formatting the
/// numbers, not writing them, is what takes the time.
const CHUNK: usize = 1 << 16;

/// Writes the entries `0..count` in order, each chunk turned into bytes by `format` on the thread
/// pool, a few chunks at a time (so that the whole file is never held in memory).
fn write_in_chunks(
    w: &mut dyn Write,
    count: usize,
    format: impl Fn(std::ops::Range<usize>) -> std::io::Result<Vec<u8>> + Sync,
) -> std::io::Result<()> {
    let chunks: Vec<std::ops::Range<usize>> = (0..count)
        .step_by(CHUNK)
        .map(|start| start..(start + CHUNK).min(count))
        .collect();
    for round in chunks.chunks(16) {
        let parts: Vec<std::io::Result<Vec<u8>>> =
            round.par_iter().map(|r| format(r.clone())).collect();
        for part in parts {
            w.write_all(&part?)?;
        }
    }
    Ok(())
}

fn matrix_csv(w: &mut dyn Write, matrix: &FormFactors) -> std::io::Result<()> {
    let mut header = csv::Writer::from_writer(&mut *w);
    header.write_record(["i", "j", "n_ij", "n_i", "f_ij", "f_ij_stderr"])?;
    header.flush()?;
    drop(header);
    write_in_chunks(w, matrix.entries.len(), |chunk| {
        let mut out = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(Vec::with_capacity(56 * chunk.len()));
        let mut fields: [String; 6] = Default::default();
        for k in chunk {
            let (i, j, c) = matrix.entries[k];
            let n_i = matrix.row_totals[i as usize];
            let (f, se) = matrix.value(k);
            fields.iter_mut().for_each(String::clear);
            let [fi, fj, fc, fn_, ff, fse] = &mut fields;
            let _ = (
                write!(fi, "{i}"),
                write!(fj, "{j}"),
                write!(fc, "{c}"),
                write!(fn_, "{n_i}"),
                write!(ff, "{f}"),
                write!(fse, "{se}"),
            );
            out.write_record(&fields)?;
        }
        out.into_inner().map_err(|e| e.into_error())
    })
}

fn matrix_market(
    w: &mut dyn Write,
    scene: &Scene,
    a: &Analysis,
    matrix: &FormFactors,
) -> std::io::Result<()> {
    let n = matrix.patches;
    writeln!(w, "%%MatrixMarket matrix coordinate real general")?;
    writeln!(
        w,
        "% form factors F_ij = N_ij / N_i of {} from {} global lines{} (seed {}), written by scx {}",
        scene.name.replace('\n', " "),
        sphere_lines_of_drawn(scene, a.spec.bound, a.lines),
        match a.spec.bound {
            LineBound::Sphere => String::new(),
            bound => format!(" ({} drawn through the bounding {})", a.lines, bound.name()),
        },
        a.spec.seed,
        env!("CARGO_PKG_VERSION")
    )?;
    writeln!(w, "% row i, column j (1-based: patch index + 1)")?;
    if a.enclosed {
        writeln!(
            w,
            "% row and column {n}: the environment of the enclosed scene (--enclose)"
        )?;
    }
    writeln!(w, "{n} {n} {}", matrix.entries.len())?;
    write_in_chunks(w, matrix.entries.len(), |chunk| {
        let mut out = Vec::with_capacity(32 * chunk.len());
        for k in chunk {
            let (i, j, _) = matrix.entries[k];
            let (f, _) = matrix.value(k);
            writeln!(out, "{} {} {f}", i + 1, j + 1)?;
        }
        Ok(out)
    })
}

/// A table as CSV: its header, then one record per row.
fn table_csv(w: &mut dyn Write, table: &Table) -> std::io::Result<()> {
    let mut out = csv::Writer::from_writer(w);
    out.write_record(table.header())?;
    for row in 0..table.rows() {
        out.write_record(table.row_text(row))?;
    }
    out.flush()
}
