//! The cells of the calibration suite (a scene, a line count, seeds, optionally a precision target) and
//! the three built-in lists.
//!
//! Seeds per cell: cheap cells get 200 (a coverage near 95% then has a binomial standard error of 1.5%,
//! against 2.8% with 60 runs); the precision targets of `small` and the expensive cells fewer, judged by
//! their pooled coverage and their mean error in standard errors.

use std::ops::Range;

use super::scenes::CalibrationScene;
use crate::measure::Measure;
use crate::run::LinesThrough;
use crate::sample::lines::Sampler;
use crate::scenes::solids::Solid;

/// Which measures a cell's runs compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellMeasures {
    /// Every measure (the radiosity ones when the scene emits).
    All,
    /// I_s^c alone (`scx analyze --measures continuous`): no pair counts, so a precision target on it
    /// is checked at the cost of the kernel sums only.
    ContinuousOnly,
}

/// A precision target of a cell's runs (`--target-stderr` on `--target-measure`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellTarget {
    /// The measure watched (one a precision target accepts, [`Measure::targets`]).
    pub measure: Measure,
    /// The standard error to reach (on an `ok` reading).
    pub stderr: f64,
}

/// A cell: runs of one scene at one line count, one per seed.
#[derive(Clone, Copy, Debug)]
pub struct Cell {
    /// The scene.
    pub scene: CalibrationScene,
    /// Lines per run (a cap when there is a target).
    pub lines: u64,
    /// The first seed.
    pub first_seed: u64,
    /// How many seeds (runs).
    pub seeds: u64,
    /// Which measures the runs compute.
    pub measures: CellMeasures,
    /// A precision target: each run stops when the watched standard error is reached on an `ok` reading.
    pub target: Option<CellTarget>,
    /// How the runs draw their lines (`scx analyze --sampler`).
    pub sampler: Sampler,
    /// Where the runs draw their lines (`scx analyze --lines-through`), the line count read as lines
    /// through the sphere, as `scx analyze --lines` reads it.
    pub through: LinesThrough,
    /// The independent groups of lines behind each run's standard errors (`scx analyze --groups`).
    pub groups: usize,
}

impl Cell {
    /// Every measure, seeds `1..=seeds`, no target.
    pub fn new(scene: CalibrationScene, lines: u64, seeds: u64) -> Cell {
        Cell {
            scene,
            lines,
            first_seed: 1,
            seeds,
            measures: CellMeasures::All,
            target: None,
            sampler: Sampler::Independent,
            through: LinesThrough::Auto,
            groups: crate::run::DEFAULT_GROUPS,
        }
    }

    /// The same cell with lines drawn by `sampler`.
    pub fn with_sampler(self, sampler: Sampler) -> Cell {
        Cell { sampler, ..self }
    }

    /// The same cell with lines drawn through `through`.
    pub fn with_bound(self, through: LinesThrough) -> Cell {
        Cell { through, ..self }
    }

    /// The same cell with `groups` independent groups behind each run's standard errors.
    pub fn with_groups(self, groups: usize) -> Cell {
        Cell { groups, ..self }
    }

    /// The same cell with a precision target on `measure` (and `lines` as the cap).
    pub fn with_target(self, measure: Measure, stderr: f64) -> Cell {
        Cell {
            target: Some(CellTarget { measure, stderr }),
            ..self
        }
    }

    /// The same cell computing only I_s^c (what `--measures continuous` asks for).
    pub fn continuous_only(self) -> Cell {
        Cell {
            measures: CellMeasures::ContinuousOnly,
            ..self
        }
    }

    /// The seeds of its runs.
    pub fn seeds(&self) -> Range<u64> {
        self.first_seed..self.first_seed + self.seeds
    }

    /// How its lines read in a table: the count, or the target and the cap; and the sampler and the
    /// bound when they are not the defaults (`auto`: through the box for the Sobol' sampler on a scene
    /// whose box is smaller than its sphere).
    pub fn lines_label(&self) -> String {
        let lines = match self.target {
            None => short_count(self.lines),
            Some(t) => format!(
                "target se {} on {}, cap {}",
                t.stderr,
                t.measure.key(),
                short_count(self.lines)
            ),
        };
        let lines = match self.sampler {
            Sampler::Independent => lines,
            other => format!("{lines} {}", other.name()),
        };
        match self.through {
            LinesThrough::Auto => lines,
            other => format!("{lines} {}", other.name()),
        }
    }
}

/// `1e5`, `3.4e7`, `2e9`: a count in the short form of the command line.
pub fn short_count(n: u64) -> String {
    if n < 1000 {
        return n.to_string();
    }
    let exponent = (n as f64).log10().floor() as i32;
    let mantissa = n as f64 / 10f64.powi(exponent);
    let rounded = (mantissa * 100.0).round() / 100.0;
    if rounded.fract() == 0.0 {
        format!("{}e{exponent}", rounded as u64)
    } else {
        format!("{rounded}e{exponent}")
    }
}

/// The built-in lists of cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SuiteLevel {
    /// Cheap cells of every kind, 60 to 200 seeds each: about 25 s on two idle cores, 40 s on two
    /// loaded ones (what CI runs, through `tests/it/calibration.rs`).
    Small,
    /// The cube from 4 x 4 to 30 x 30 patches per face at 1e5 to 1e8 lines, the regular solids, the open
    /// scenes, the flipped face, the lit cube and precision targets: hours, for the docs and before
    /// and after an estimator change.
    Standard,
    /// Standard, and the expensive cells of issue 27: `@cube:20` at 3.4e7 lines, `@cube:30` at 2e8
    /// lines, and a precision target of 0.01 on the corrected I_s of `@cube:30` with up to 2e9 lines.
    Full,
}

impl SuiteLevel {
    /// Reads `small`, `standard` or `full`.
    pub fn parse(s: &str) -> Option<SuiteLevel> {
        match s {
            "small" => Some(SuiteLevel::Small),
            "standard" => Some(SuiteLevel::Standard),
            "full" => Some(SuiteLevel::Full),
            _ => None,
        }
    }

    /// The name `parse` reads.
    pub fn name(self) -> &'static str {
        match self {
            SuiteLevel::Small => "small",
            SuiteLevel::Standard => "standard",
            SuiteLevel::Full => "full",
        }
    }
}

/// The cells of a suite level, cheapest first within each group.
pub fn suite(level: SuiteLevel) -> Vec<Cell> {
    match level {
        SuiteLevel::Small => small(),
        SuiteLevel::Standard => standard(),
        SuiteLevel::Full => {
            let mut cells = standard();
            cells.extend(issue_27());
            cells
        }
    }
}

fn cube(n: usize) -> CalibrationScene {
    CalibrationScene::Cube(n)
}

fn solid(which: Solid, k: usize) -> CalibrationScene {
    CalibrationScene::Solid(which, k)
}

fn parallel_squares(patches: usize) -> CalibrationScene {
    CalibrationScene::ParallelSquares {
        patches,
        distance: 1.0,
    }
}

fn perpendicular_squares(patches: usize) -> CalibrationScene {
    CalibrationScene::PerpendicularSquares { patches }
}

/// One cheap cell of every kind: a closed mesh where the plug-in readings are biased and the corrected
/// ones are not (`@cube:4` at 1e5), a well-sampled solid, both open scenes, the flipped face, the lit
/// cube, and precision targets on I_s^c alone and on the corrected I_s, both met after the first check
/// (so that the stopping rule is what is judged, not just the first round). The scenes have 4 to 96
/// patches, so their exact values take milliseconds.
fn small() -> Vec<Cell> {
    vec![
        Cell::new(cube(4), 100_000, 200),
        Cell::new(solid(Solid::Tetrahedron, 1), 20_000, 200),
        // 5e4 lines: about 2000 pairs between the squares, enough for I_s^c to be judged (a run with
        // fewer than 1000 calls it unusable).
        Cell::new(parallel_squares(1), 50_000, 200),
        Cell::new(perpendicular_squares(1), 50_000, 200),
        Cell::new(CalibrationScene::FlippedCube(1), 20_000, 200),
        Cell::new(CalibrationScene::LitCube(1), 20_000, 200),
        Cell::new(cube(1), 10_000_000, 60)
            .continuous_only()
            .with_target(Measure::ContinuousMutualInformation, 0.005),
        Cell::new(cube(4), 10_000_000, 60).with_target(Measure::MutualInformationCorrected, 0.004),
    ]
}

/// The standard suite.
fn standard() -> Vec<Cell> {
    let mut cells = Vec::new();
    // The cube: rows from well sampled (4 x 4 at 1e6) to undersampled (30 x 30 at 1e6).
    for (n, lines, seeds) in [
        (4, 100_000, 200),
        (4, 1_000_000, 200),
        (6, 100_000, 200),
        (6, 1_000_000, 200),
        (10, 100_000, 200),
        (10, 1_000_000, 200),
        (10, 10_000_000, 40),
        (15, 1_000_000, 200),
        (15, 10_000_000, 40),
        (20, 1_000_000, 200),
        (20, 10_000_000, 40),
        (30, 1_000_000, 200),
        (30, 10_000_000, 30),
        (30, 100_000_000, 10),
    ] {
        cells.push(Cell::new(cube(n), lines, seeds));
    }
    // The regular solids (I_s^c of paper Table 4), whole faces and cut into triangles.
    for (scene, lines) in [
        (cube(1), 100_000),
        (solid(Solid::Tetrahedron, 1), 100_000),
        (solid(Solid::Octahedron, 1), 100_000),
        (solid(Solid::Icosahedron, 1), 100_000),
        (solid(Solid::Dodecahedron, 1), 100_000),
        (solid(Solid::Tetrahedron, 4), 1_000_000),
        (solid(Solid::Octahedron, 3), 1_000_000),
        (solid(Solid::Icosahedron, 2), 1_000_000),
        (solid(Solid::Dodecahedron, 2), 1_000_000),
    ] {
        cells.push(Cell::new(scene, lines, 200));
    }
    // Open scenes, the flipped face and light.
    for (scene, lines) in [
        (parallel_squares(1), 100_000),
        (parallel_squares(4), 1_000_000),
        (perpendicular_squares(1), 100_000),
        (perpendicular_squares(4), 1_000_000),
        (CalibrationScene::FlippedCube(1), 100_000),
        (CalibrationScene::FlippedCube(4), 1_000_000),
        (CalibrationScene::LitCube(1), 100_000),
        (CalibrationScene::LitCube(4), 1_000_000),
    ] {
        cells.push(Cell::new(scene, lines, 200));
    }
    // Precision targets: I_s^c alone (cheap), and the corrected I_s on meshes that reach it.
    cells.push(
        Cell::new(cube(1), 10_000_000, 200)
            .continuous_only()
            .with_target(Measure::ContinuousMutualInformation, 0.003),
    );
    cells.push(
        Cell::new(cube(4), 100_000_000, 200)
            .with_target(Measure::MutualInformationCorrected, 0.005),
    );
    cells.push(
        Cell::new(cube(10), 1_000_000_000, 40)
            .with_target(Measure::MutualInformationCorrected, 0.002),
    );
    cells
}

/// The expensive cells of issue 27.
fn issue_27() -> Vec<Cell> {
    vec![
        Cell::new(cube(20), 34_000_000, 20),
        Cell::new(cube(30), 200_000_000, 8),
        Cell::new(cube(30), 2_000_000_000, 3)
            .with_target(Measure::MutualInformationCorrected, 0.01),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_read_short() {
        assert_eq!(short_count(100_000), "1e5");
        assert_eq!(short_count(34_000_000), "3.4e7");
        assert_eq!(short_count(2_000_000_000), "2e9");
        assert_eq!(short_count(999), "999");
    }

    /// Small cells have at least 60 seeds (a coverage near 95% then has a binomial standard error
    /// of 2.8%), cheap standard cells 200; the full suite holds the standard one; every target watches
    /// a measure a target accepts.
    #[test]
    fn suites_are_nested_and_cheap_cells_have_enough_seeds() {
        for cell in suite(SuiteLevel::Small) {
            assert!(cell.seeds >= 60, "{cell:?}");
        }
        for cell in suite(SuiteLevel::Full) {
            if let Some(t) = cell.target {
                assert!(t.measure.info().target, "{cell:?}");
            }
        }
        let (standard, full) = (suite(SuiteLevel::Standard), suite(SuiteLevel::Full));
        let key = |c: &Cell| (c.scene.name(), c.lines, c.seeds, c.target.is_some());
        assert!(full.len() > standard.len());
        for (s, f) in standard.iter().zip(&full) {
            assert_eq!(key(s), key(f));
        }
        for cell in standard.iter().filter(|c| c.lines <= 1_000_000) {
            assert!(cell.seeds >= 200, "{cell:?}");
        }
    }
}
