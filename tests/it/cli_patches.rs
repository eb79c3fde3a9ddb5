//! `scx analyze --patches` and `--form-factors` against independent truth: the form factors of `@cube:4`
//! agree with the closed forms of parallel and perpendicular squares (a chi-square over every entry);
//! rows of F sum to 1 in a closed scene and reciprocity holds within the errors; the geometry columns are
//! the scene's own.

use crate::support::{area_form_factor, scx, AxisRect};
use scene_complexity::internals::scenes;

/// Reads a CSV without quoted fields (the numeric files) into its header and rows.
fn read_csv(path: &std::path::Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

/// The upper tail of the chi-square distribution with `df` degrees of freedom (Wilson–Hilferty: the
/// cube root of chi^2 / df is close to normal; good to ~1e-3 at the hundreds of degrees used here).
fn chi_square_p_value(chi2: f64, df: f64) -> f64 {
    let k = 2.0 / (9.0 * df);
    let z = ((chi2 / df).cbrt() - (1.0 - k)) / k.sqrt();
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

/// The complementary error function (Numerical Recipes' `erfcc`, relative error below 1.2e-7).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.26551223
            + t * (1.00002368
                + t * (0.37409196
                    + t * (0.09678418
                        + t * (-0.18628806
                            + t * (0.27886807
                                + t * (-1.13520398
                                    + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
            .exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// `scx analyze @cube:4 --lines 1e7 --form-factors ff.csv`: every entry of F against the closed forms
/// of parallel and perpendicular squares. The segments of an empty convex room are independent (one
/// per line that meets it), so the unordered pair counts are multinomial with `p_ij = 2 A_i F_ij / A_T`;
/// Pearson's chi-square over every pair of patches that see each other must look like chance, every
/// entry must lie within 5 of its reported standard errors, no coplanar pair may be counted, every row
/// must sum to 1 and reciprocity `A_i F_ij = A_j F_ji` must hold within the errors.
#[test]
fn form_factors_of_the_unit_cube_agree_with_the_closed_forms() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, mtx) = (dir.path().join("ff.csv"), dir.path().join("ff.mtx"));
    let out = scx(&[
        "analyze",
        "@cube:4",
        "--lines",
        "1e7",
        "--seed",
        "3",
        "-q",
        "--format",
        "json",
        "--form-factors",
        csv.to_str().unwrap(),
        "--form-factors",
        mtx.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let scene = scenes::load("@cube:4").unwrap();
    let n = scene.patch_count();
    let rects: Vec<AxisRect> = (0..n).map(|p| AxisRect::of_patch(&scene, p)).collect();
    let area = |_: usize| 1.0 / 16.0;
    let exact = |i: usize, j: usize| area_form_factor(&rects[i], &rects[j]) / area(i);

    let (header, rows) = read_csv(&csv);
    assert_eq!(header, ["i", "j", "n_ij", "n_i", "f_ij", "f_ij_stderr"]);
    let mut counts = vec![vec![0u64; n]; n];
    let mut f = vec![vec![0.0; n]; n];
    let mut se = vec![vec![0.0; n]; n];
    let mut row_total = vec![0u64; n];
    for r in &rows {
        let (i, j): (usize, usize) = (r[0].parse().unwrap(), r[1].parse().unwrap());
        counts[i][j] = r[2].parse().unwrap();
        row_total[i] = r[3].parse().unwrap();
        f[i][j] = r[4].parse().unwrap();
        se[i][j] = r[5].parse().unwrap();
    }

    // Pearson's chi-square over the unordered pairs that see each other.
    let pairs: u64 = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .map(|(i, j)| counts[i][j])
        .sum();
    let (mut chi2, mut cells, mut worst) = (0.0, 0usize, (0.0f64, 0, 0));
    for i in 0..n {
        for j in 0..n {
            let fe = exact(i, j);
            if fe <= 1e-12 {
                assert_eq!(
                    counts[i][j], 0,
                    "coplanar patches {i} and {j} cannot see each other"
                );
                continue;
            }
            let z = (f[i][j] - fe) / se[i][j];
            if z.abs() > worst.0.abs() {
                worst = (z, i, j);
            }
            if j > i {
                let expected = pairs as f64 * 2.0 * area(i) * fe / 6.0;
                chi2 += (counts[i][j] as f64 - expected).powi(2) / expected;
                cells += 1;
            }
        }
    }
    let df = (cells - 1) as f64;
    let p = chi_square_p_value(chi2, df);
    let report = format!(
        "chi-square {chi2:.1} on {df} degrees of freedom (p = {p:.3}) over {cells} pairs of patches from \
         {pairs} segments; largest deviation {:.2} standard errors (F_{}_{})",
        worst.0, worst.1, worst.2
    );
    eprintln!("{report}");
    assert_eq!(cells, 3840, "{report}");
    assert!((1e-3..=0.999).contains(&p), "{report}");
    assert!(worst.0.abs() < 5.0, "{report}");

    // Rows sum to 1 (a closed scene: no escapes), reciprocity within the errors.
    for i in 0..n {
        let s: f64 = f[i].iter().sum();
        assert!((s - 1.0).abs() < 1e-12, "row {i} sums to {s}");
        assert_eq!(counts[i].iter().sum::<u64>(), row_total[i]);
    }
    let (mut z2, mut k) = (0.0, 0);
    for i in 0..n {
        for j in i + 1..n {
            if counts[i][j] == 0 {
                continue;
            }
            let d = area(i) * f[i][j] - area(j) * f[j][i];
            let s = (area(i) * se[i][j]).hypot(area(j) * se[j][i]);
            assert!(
                (d / s).abs() < 5.0,
                "reciprocity of {i} and {j}: {d} against {s}"
            );
            z2 += (d / s).powi(2);
            k += 1;
        }
    }
    // The two sides share N_ij, so their difference scatters less than the independent errors say.
    assert!(
        z2 / f64::from(k) < 1.0,
        "mean squared reciprocity deviation {}",
        z2 / f64::from(k)
    );

    // The Matrix Market file holds the same matrix, 1-based.
    let text = std::fs::read_to_string(&mtx).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('%'));
    assert!(text.starts_with("%%MatrixMarket matrix coordinate real general\n"));
    assert_eq!(lines.next().unwrap(), format!("{n} {n} {}", rows.len()));
    for (line, r) in lines.zip(&rows) {
        let v: Vec<&str> = line.split(' ').collect();
        let (i, j): (usize, usize) = (v[0].parse().unwrap(), v[1].parse().unwrap());
        assert_eq!(
            (i - 1, j - 1),
            (r[0].parse().unwrap(), r[1].parse().unwrap())
        );
        assert_eq!(v[2], r[4]);
    }
}

/// The per-patch file's geometry is the scene's own: on `@cube:4` (the unit cube, 4 x 4 squares per
/// face) every centroid is the middle of a square of side 1/4 on a face, every normal points into the
/// cube, every area is 1/16; on `@cornell` (millimetres) the areas add up to the box's.
#[test]
fn per_patch_file_has_the_scenes_own_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.csv");
    let out = scx(&[
        "analyze",
        "@cube:4",
        "--lines",
        "2e5",
        "-q",
        "--patches",
        path.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (header, rows) = read_csv(&path);
    assert_eq!(rows.len(), 96);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    let num = |r: &Vec<String>, name: &str| -> f64 { r[col(name)].parse().unwrap() };
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[col("id")], k.to_string());
        assert!((num(r, "area") - 1.0 / 16.0).abs() < 1e-12);
        let c = ["centroid_x", "centroid_y", "centroid_z"].map(|n| num(r, n));
        let nrm = ["normal_x", "normal_y", "normal_z"].map(|n| num(r, n));
        let on_face = (0..3).filter(|&a| c[a] == 0.0 || c[a] == 1.0).count();
        assert_eq!(on_face, 1, "patch {k}: centroid {c:?}");
        for a in 0..3 {
            if c[a] == 0.0 || c[a] == 1.0 {
                assert_eq!(
                    nrm[a],
                    if c[a] == 0.0 { 1.0 } else { -1.0 },
                    "patch {k}: normal {nrm:?}"
                );
            } else {
                assert_eq!(nrm[a], 0.0);
                assert!(
                    ((c[a] * 8.0) - (c[a] * 8.0).round()).abs() < 1e-12
                        && (c[a] * 8.0).round() % 2.0 == 1.0
                );
            }
        }
        assert_eq!(r[col("sampled")], "true");
        assert!(r[col("radiosity")].is_empty(), "nothing emits");
    }

    let out = scx(&[
        "analyze",
        "@cornell",
        "--lines",
        "1e5",
        "-q",
        "--format",
        "json",
        "--patches",
        path.to_str().unwrap(),
    ]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let (header, rows) = read_csv(&path);
    let area_col = header.iter().position(|h| h == "area").unwrap();
    let total: f64 = rows
        .iter()
        .map(|r| r[area_col].parse::<f64>().unwrap())
        .sum();
    let reported = report["area"].as_f64().unwrap();
    assert!(
        (total - reported).abs() < 1e-9 * reported,
        "{total} vs {reported} mm^2"
    );
    let b = header.iter().position(|h| h == "radiosity").unwrap();
    assert!(
        rows.iter().all(|r| r[b].parse::<f64>().unwrap() >= 0.0),
        "lit: every B_i is given"
    );
}

/// Wrong kinds of file are refused before any line is cast, with exit code 2.
#[test]
fn per_patch_files_are_checked_before_work() {
    for args in [
        &["analyze", "@cube:2", "--patches", "p.txt"][..],
        &["analyze", "@cube:2", "--form-factors", "f.json"],
        &[
            "analyze",
            "@cube:2",
            "--measures",
            "continuous",
            "--form-factors",
            "f.csv",
        ],
    ] {
        let out = scx(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--patches") || err.contains("--form-factors"),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"));
    }
    let out = scx(&["analyze", "@cube:2", "--patches", "/no/such/folder/p.csv"]);
    assert_eq!(out.status.code(), Some(3));
}

/// A run resumed from a state whose first run was not asked for `--patches` has no per-patch sums of
/// eq. (27): it says so, and leaves those columns empty rather than filling them from part of the lines
/// (with the sums kept, `tests/it/runs.rs` checks the files against the run cast at once).
#[test]
fn a_resumed_run_without_the_sums_leaves_the_continuous_columns_empty_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let (state, csv) = (dir.path().join("run.state"), dir.path().join("p.csv"));
    let out = scx(&[
        "analyze",
        "@cube:2",
        "--lines",
        "3e5",
        "-q",
        "--save",
        state.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = scx(&[
        "analyze",
        "--resume",
        state.to_str().unwrap(),
        "--lines",
        "4e5",
        "--patches",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("stay empty"));
    let (header, rows) = read_csv(&csv);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(rows.len(), 24);
    for r in &rows {
        assert!(r[col("continuous_mutual_information_term")].is_empty());
        assert!(r[col("lost_information")].is_empty());
        assert!(!r[col("mutual_information_term")].is_empty());
    }
}

/// `--objects`: one row per object of the file, by its name; their areas are the objects' own, their
/// shares of I_s, I_s^c and H_s add up to the scene's readings (to rounding), and the standard error of
/// each object's sum is at most the sum of its patches' errors (the norm of a sum); `--patches` names
/// each patch's object; the JSON report's `objects` holds the same numbers.
#[test]
fn object_results_add_up_to_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let mut obj = String::new();
    let mut faces = 0;
    for line in crate::support::room_with_box_obj(1.0).lines() {
        if line.starts_with("f ") {
            match faces {
                0 => obj.push_str("o room\n"),
                6 => obj.push_str("o box\n"),
                _ => {}
            }
            faces += 1;
        }
        obj.push_str(line);
        obj.push('\n');
    }
    let scene = dir.path().join("room.obj");
    std::fs::write(&scene, obj).unwrap();
    let (objects, patches) = (dir.path().join("o.csv"), dir.path().join("p.csv"));
    let out = scx(&[
        "analyze",
        scene.to_str().unwrap(),
        "--lines",
        "2e5",
        "--format",
        "json",
        "--objects",
        objects.to_str().unwrap(),
        "--patches",
        patches.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();

    let (header, rows) = read_csv(&objects);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let num = |row: &[String], name: &str| row[col(name)].parse::<f64>().unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r[col("object")].as_str()).collect();
    assert_eq!(names, ["room", "box"]);
    let box_area = 2.0 * (0.3 * 0.3 + 0.3 * 0.45 + 0.3 * 0.45);
    for (row, area) in rows.iter().zip([6.0, box_area]) {
        assert_eq!(num(row, "patches"), 6.0);
        assert!((num(row, "area") - area).abs() < 1e-9, "{row:?}");
        assert_eq!(num(row, "escapes"), 0.0, "a closed scene");
    }
    let fractions: f64 = rows.iter().map(|r| num(r, "area_fraction")).sum();
    assert!((fractions - 1.0).abs() < 1e-12);
    let scene_value = |key: &str| doc["visibility"][key]["value"].as_f64().unwrap();
    for (column, key) in [
        (
            "continuous_mutual_information_term",
            "continuous_mutual_information",
        ),
        ("mutual_information_term", "mutual_information"),
        ("row_entropy", "entropy"),
    ] {
        let sum: f64 = rows.iter().map(|r| num(r, column)).sum();
        let whole = scene_value(key);
        assert!(
            (sum - whole).abs() < 1e-9 * whole.abs(),
            "{column}: {sum} against {whole}"
        );
    }

    let (p_header, p_rows) = read_csv(&patches);
    let p_col = |name: &str| p_header.iter().position(|h| h == name).unwrap();
    let owners: Vec<&str> = p_rows.iter().map(|r| r[p_col("object")].as_str()).collect();
    assert_eq!(owners, [vec!["room"; 6], vec!["box"; 6]].concat());
    for (k, row) in rows.iter().enumerate() {
        let column = "continuous_mutual_information_term_stderr";
        let patch_errors: f64 = p_rows[6 * k..6 * k + 6]
            .iter()
            .map(|r| r[p_col(column)].parse::<f64>().unwrap())
            .sum();
        let error = num(row, column);
        assert!(
            error > 0.0 && error <= patch_errors * (1.0 + 1e-12),
            "{error} {patch_errors}"
        );
        let json = &doc["objects"][k];
        assert_eq!(json["name"], names[k]);
        assert_eq!(
            json["continuous_mutual_information_term"]["value"].as_f64(),
            Some(num(row, "continuous_mutual_information_term"))
        );
        assert_eq!(json["segments"].as_f64(), Some(num(row, "segments")));
    }
}

/// Runs `scx analyze` with `args` and the four per-patch files written into `dir` (`p.csv`, `ff.csv`,
/// `ff.mtx`, `o.csv`), and returns its JSON report.
fn run_with_all_files(dir: &std::path::Path, args: &[&str]) -> serde_json::Value {
    let file = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let (p, ff, mtx, o) = (file("p.csv"), file("ff.csv"), file("ff.mtx"), file("o.csv"));
    let mut all: Vec<&str> = args.to_vec();
    all.extend([
        "-q",
        "--format",
        "json",
        "--patches",
        &p,
        "--form-factors",
        &ff,
        "--form-factors",
        &mtx,
        "--objects",
        &o,
    ]);
    let out = scx(&all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// `scx analyze @cornell-open --enclose` with every per-patch file: the environment is the last row of
/// the patch table (id = the patch count, object and material `environment`, its counted area, no
/// centroid nor normal, no radiosity) and of F (row and column `patches`); the area fractions sum to 1;
/// the rows' H_s and I_s^c terms add up to the report's readings; every row of F sums to 1 in counts
/// (N_ij over j, plus the segments absorbed at back sides, is N_i); reciprocity A_i F_ij = A_j F_ji
/// holds within the errors with the environment's counted area. Both sides share N_ij, so what differs
/// is N_i / A_i against N_j / A_j: the error is the Poisson error of each row's segments (relative
/// 1 / sqrt(N_i)), and the pairs' deviations in it must look like chance (worst below 5, root mean
/// square below 1.5). The objects, the environment's last, add up too.
#[test]
fn enclosed_files_have_the_environment_row_and_add_up() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let doc = run_with_all_files(
        d,
        &["analyze", "@cornell-open", "--lines", "1e6", "--enclose"],
    );
    let n = doc["patches"].as_u64().unwrap() as usize;
    let (header, rows) = read_csv(&d.join("p.csv"));
    assert_eq!(rows.len(), n + 1, "the environment's row");
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let num = |r: &[String], name: &str| r[col(name)].parse::<f64>().unwrap();
    let env = &rows[n];
    assert_eq!(
        env[..3],
        [n.to_string(), "environment".into(), "environment".into()]
    );
    for empty in ["centroid_x", "normal_z", "radiosity", "incoming_radiosity"] {
        assert!(env[col(empty)].is_empty(), "{empty}: {env:?}");
    }
    // serde_json reads floats to within an ulp or so, not always to the bit.
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-10 * y.abs().max(1.0);
    let env_area = doc["environment_area"]["value"].as_f64().unwrap();
    assert!(close(num(env, "area"), env_area));
    let sum = |f: &dyn Fn(&[String]) -> f64| rows.iter().map(|r| f(r)).sum::<f64>();
    assert!(close(sum(&|r| num(r, "area_fraction")), 1.0));
    let reading = |m: &str| doc["visibility"][m]["value"].as_f64().unwrap();
    assert!(close(
        sum(&|r| num(r, "area_fraction") * num(r, "row_entropy")),
        reading("entropy")
    ));
    let isc = reading("continuous_mutual_information");
    assert!(close(
        sum(&|r| num(r, "continuous_mutual_information_term")),
        isc
    ));

    // F: rows sum to 1 in counts; reciprocity with the counted areas.
    let (_, ff) = read_csv(&d.join("ff.csv"));
    let mut row_sum = vec![0u64; n + 1];
    let mut entry = std::collections::HashMap::new();
    let mut totals = vec![0u64; n + 1];
    for e in &ff {
        let (i, j): (usize, usize) = (e[0].parse().unwrap(), e[1].parse().unwrap());
        let (n_ij, n_i): (u64, u64) = (e[2].parse().unwrap(), e[3].parse().unwrap());
        row_sum[i] += n_ij;
        totals[i] = n_i;
        entry.insert(
            (i, j),
            (e[4].parse::<f64>().unwrap(), e[5].parse::<f64>().unwrap()),
        );
    }
    for (i, r) in rows.iter().enumerate() {
        let absorbed: u64 = r[col("absorbed")].parse().unwrap();
        assert_eq!(row_sum[i] + absorbed, totals[i], "row {i}");
        assert_eq!(totals[i].to_string(), r[col("segments")], "row {i}");
    }
    assert!(entry.keys().any(|&(i, j)| i == n && j == n), "the misses");
    let area = |i: usize| num(&rows[i], "area");
    let deviations: Vec<f64> = entry
        .iter()
        .filter(|((i, j), _)| i < j)
        .map(|(&(i, j), &(f_ij, _))| {
            let (x, y) = (area(i) * f_ij, area(j) * entry[&(j, i)].0);
            (x - y) / (x * x / totals[i] as f64 + y * y / totals[j] as f64).sqrt()
        })
        .collect();
    let worst = deviations.iter().fold(0.0f64, |m, z| m.max(z.abs()));
    let rms = (deviations.iter().map(|z| z * z).sum::<f64>() / deviations.len() as f64).sqrt();
    assert!(
        worst < 5.0 && rms < 1.5,
        "reciprocity off by up to {worst} standard errors (rms {rms})"
    );
    assert!(
        entry.keys().filter(|&&(i, j)| i < j && j == n).count() > 20,
        "pairs with the environment among them"
    );
    let mtx = std::fs::read_to_string(d.join("ff.mtx")).unwrap();
    let size = mtx.lines().find(|l| !l.starts_with('%')).unwrap();
    assert_eq!(size, format!("{} {} {}", n + 1, n + 1, ff.len()));

    // The objects: the scene's, then the environment.
    let (oh, objects) = read_csv(&d.join("o.csv"));
    let ocol = |name: &str| oh.iter().position(|h| h == name).unwrap();
    let last = objects.last().unwrap();
    assert_eq!(last[0], "environment");
    assert_eq!(last[ocol("area")], env[col("area")]);
    let osum = |name: &str| {
        objects
            .iter()
            .map(|o| o[ocol(name)].parse::<f64>().unwrap())
            .sum::<f64>()
    };
    assert!(close(osum("area_fraction"), 1.0));
    assert!(close(osum("continuous_mutual_information_term"), isc));
    let json_objects = doc["objects"].as_array().unwrap();
    assert_eq!(json_objects.len(), objects.len());
    assert_eq!(json_objects.last().unwrap()["name"], "environment");
}

/// A closed scene has no environment: `--enclose` changes nothing, and every per-patch file is the
/// same bytes as without it (lines through the sphere both times: the environment is the sphere, so
/// `--enclose` keeps it where `auto` would draw a cube's lines through its box).
#[test]
fn enclose_leaves_the_files_of_a_closed_scene_alone() {
    let (plain, enclosed) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let args = [
        "analyze",
        "@cube:4",
        "--lines",
        "2e5",
        "--seed",
        "5",
        "--lines-through",
        "sphere",
    ];
    let a = run_with_all_files(plain.path(), &args);
    let mut with = args.to_vec();
    with.push("--enclose");
    let b = run_with_all_files(enclosed.path(), &with);
    assert_eq!(a["visibility"], b["visibility"]);
    assert!(b["environment_area"].is_null());
    for name in ["p.csv", "ff.csv", "ff.mtx", "o.csv"] {
        let x = std::fs::read(plain.path().join(name)).unwrap();
        let y = std::fs::read(enclosed.path().join(name)).unwrap();
        assert!(!x.is_empty() && x == y, "{name} differs");
    }
}

/// The information lost per patch, I_i^c - I_i, is at least 0 on every row of a closed scene (the
/// log-sum inequality); a plug-in I_i on rows sampled too thinly reads it below 0, and the run warns,
/// counting exactly the rows of the `--patches` file more than two standard errors below 0, with their
/// area. A well-sampled scene has none and no warning.
#[test]
fn negative_information_lost_is_warned_of_with_the_rows_that_show_it() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("p.csv");
    let run = |scene: &str, lines: &str| {
        let out = scx(&[
            "analyze",
            scene,
            "--lines",
            lines,
            "--tracer",
            "rust",
            "--patches",
            csv.to_str().unwrap(),
            "--format",
            "json",
            "--quiet",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let warning = doc["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|w| w["code"] == "negative-lost-information")
            .cloned();
        (warning, read_csv(&csv))
    };
    let (warning, (header, rows)) = run("@fig2:a", "1e5");
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (value, se, share) = (
        col("lost_information"),
        col("lost_information_stderr"),
        col("area_fraction"),
    );
    let (mut n, mut area) = (0usize, 0.0);
    for r in &rows {
        let (v, s): (f64, f64) = (r[value].parse().unwrap(), r[se].parse().unwrap());
        if v < -2.0 * s {
            n += 1;
            area += r[share].parse::<f64>().unwrap();
        }
    }
    assert!(n > 100, "{n} rows below 0");
    let warning = warning.expect("a warning");
    let numbers = &warning["numbers"];
    assert_eq!(numbers["patches"].as_f64().unwrap() as usize, n);
    assert!((numbers["area_fraction"].as_f64().unwrap() - area).abs() < 1e-6);
    assert!(warning["message"]
        .as_str()
        .unwrap()
        .contains("lost_information_corrected"));
    let (warning, (header, rows)) = run("@cube:2", "1e6");
    let value = header.iter().position(|h| h == "lost_information").unwrap();
    assert!(rows
        .iter()
        .all(|r| r[value].parse::<f64>().unwrap() > -0.01));
    assert!(warning.is_none(), "{warning:?}");
}
