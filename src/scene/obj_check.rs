//! A light pre-scan of OBJ text: the problems `tobj` reports without a line number (or not at all), found
//! with their line, before `tobj` parses the file.
//!
//! `tobj` drops faces of one or two vertices without a word (as points and lines) and says only
//! "malformed face" or "malformed vertex position" for the rest; a scene missing faces would be a silent
//! partial result, and a message without a line leaves the user searching. The scan checks the `v` and
//! `f` statements only (what scx uses) and remembers the line of every face, so that later messages about
//! a face (non-planar, zero area) can name its line too.

use std::borrow::Cow;

use super::SceneError;

/// The OBJ statements whose arguments are names (of objects, groups, materials, libraries), which tools
/// write in their own encoding.
pub(crate) const OBJ_NAMES: &[&str] = &["o", "g", "usemtl", "mtllib", "maplib", "usemap"];

/// The MTL statements whose arguments are names: the material's, and texture files' (which scx does not
/// read).
pub(crate) const MTL_NAMES: &[&str] = &[
    "newmtl", "map_Ka", "map_Kd", "map_Ks", "map_Ke", "map_Ns", "map_d", "map_bump", "bump",
    "disp", "decal", "refl", "norm",
];

/// Where OBJ or MTL bytes are not text: a byte that is not UTF-8 outside a name or a comment. The
/// message leaves the line out: it goes with the file's name (`room.obj:12`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{}byte 0x{byte:02X} at column {column} is not text (UTF-8){}; only names ({names}) and comments \
     may hold other bytes",
    // A line whose first word is not text either is no statement: binary bytes, most likely.
    if .statement.is_none() { "not a text file: " } else { "" },
    .statement.as_ref().map(|k| format!(" in a `{k}` statement")).unwrap_or_default()
)]
pub(crate) struct NotText {
    /// The line (1-based).
    pub line: usize,
    /// The column of the byte (1-based, in bytes).
    pub column: usize,
    /// The byte.
    pub byte: u8,
    /// The statement's keyword, when it is text.
    pub statement: Option<String>,
    /// The statements whose names may hold any byte, as the message lists them.
    pub names: String,
}

/// OBJ or MTL bytes as text. Tools write names and comments in their own encoding (Latin-1 and the
/// like), and a file refused whole for one accented name is a file the user cannot read: a byte that is
/// not UTF-8 in a comment or in the arguments of a statement of `names` is read as the Latin-1
/// character of its value. Distinct bytes stay distinct characters (U+FFFD for each would merge two
/// names), and a name written in Latin-1 reads as the same name written in UTF-8. Such bytes anywhere
/// else (a number, a keyword, a face) are an error naming the line.
pub(crate) fn text_of<'a>(bytes: &'a [u8], names: &[&str]) -> Result<Cow<'a, str>, NotText> {
    let first_bad = match std::str::from_utf8(bytes) {
        Ok(text) => return Ok(Cow::Borrowed(text)),
        Err(e) => e.valid_up_to(),
    };
    // The lines before the first bad byte are text: copied as they are.
    let start = bytes[..first_bad]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |k| k + 1);
    let mut text = String::with_capacity(bytes.len() + 16);
    text.push_str(std::str::from_utf8(&bytes[..start]).expect("checked above"));
    let before = bytes[..start].iter().filter(|&&b| b == b'\n').count();
    for (k, line) in bytes[start..].split_inclusive(|&b| b == b'\n').enumerate() {
        check_line(line, names).map_err(|(column, byte, statement)| NotText {
            line: before + k + 1,
            column,
            byte,
            statement,
            names: names
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", "),
        })?;
        for chunk in line.utf8_chunks() {
            text.push_str(chunk.valid());
            text.extend(chunk.invalid().iter().map(|&b| char::from(b)));
        }
    }
    Ok(Cow::Owned(text))
}

/// Whether a line's bytes that are not UTF-8 are all in a comment or in a name statement's arguments;
/// `Err` gives the first other one: its column (1-based), the byte, and the statement's keyword.
fn check_line(line: &[u8], names: &[&str]) -> Result<(), (usize, u8, Option<String>)> {
    let Err(e) = std::str::from_utf8(line) else {
        return Ok(());
    };
    let at = e.valid_up_to();
    let keyword = line
        .split(|b| b.is_ascii_whitespace())
        .find(|w| !w.is_empty())
        .and_then(|w| std::str::from_utf8(w).ok());
    let in_name = keyword.is_some_and(|k| names.contains(&k));
    // `#` is ASCII: no byte of a multi-byte character is one, so the comment starts at the first.
    let code = line.split(|&b| b == b'#').next().unwrap_or(line);
    if in_name || std::str::from_utf8(code).is_ok() {
        return Ok(());
    }
    Err((at + 1, line[at], keyword.map(str::to_string)))
}

impl NotText {
    /// The error for OBJ bytes read from `shown`, naming the line as the other OBJ errors do.
    pub(crate) fn in_file(self, shown: &str) -> SceneError {
        SceneError::File {
            path: format!("{shown}:{}", self.line),
            message: self.to_string(),
        }
    }
}

/// OBJ text as scx reads it, and what the scan found on the way.
pub(crate) struct Prepared<'a> {
    /// The line numbers (1-based) of the `f` statements, in file order.
    pub faces: Vec<usize>,
    /// The text for `tobj`: the input, or a copy with the statements scx ignores blanked out (same lines).
    pub text: Cow<'a, str>,
    /// `v` statements whose fourth number (`w`) was dropped: how many, and the first one's line.
    pub weights: (usize, usize),
    /// `l` and `p` statements (lines and points: no area), blanked out: how many, the first one's line.
    pub lines_and_points: (usize, usize),
    /// Every `usemtl`: its line and the material it names.
    pub usemtl: Vec<(usize, String)>,
}

/// Scans OBJ text ([`scan`]) and prepares it for `tobj`: the optional `w` of `v x y z w` is dropped (the
/// OBJ specification gives it a meaning for rational curves and surfaces only, and `tobj` would divide
/// x, y and z by it), and `l` and `p` statements are blanked (`tobj` reads an `l` of three or more
/// vertices as a polygon).
pub(crate) fn prepare<'a>(shown: &str, text: &'a str) -> Result<Prepared<'a>, SceneError> {
    let faces = scan(shown, text)?;
    let mut weights = (0, 0);
    let mut lines_and_points = (0, 0);
    let mut usemtl = Vec::new();
    let mut rewritten: Vec<(usize, String)> = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let mut tokens = raw.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let numbers: Vec<&str> = tokens.collect();
                if numbers.len() == 4 {
                    note(&mut weights, k + 1);
                    rewritten.push((k, format!("v {} {} {}", numbers[0], numbers[1], numbers[2])));
                }
            }
            Some("l" | "p") => {
                note(&mut lines_and_points, k + 1);
                rewritten.push((k, String::new()));
            }
            Some("usemtl") => {
                let name = raw.trim_start()["usemtl".len()..].trim();
                usemtl.push((k + 1, name.to_string()));
            }
            _ => {}
        }
    }
    let text = if rewritten.is_empty() {
        Cow::Borrowed(text)
    } else {
        let mut lines: Vec<&str> = text.lines().collect();
        for (k, new) in &rewritten {
            lines[*k] = new.as_str();
        }
        Cow::Owned(lines.join("\n"))
    };
    Ok(Prepared {
        faces,
        text,
        weights,
        lines_and_points,
        usemtl,
    })
}

/// Counts one more statement of a kind, remembering the first one's line.
fn note(seen: &mut (usize, usize), line: usize) {
    if seen.0 == 0 {
        seen.1 = line;
    }
    seen.0 += 1;
}

/// The line (1-based) of each `newmtl` in MTL text, by material name.
pub(crate) fn material_lines(text: &str) -> Vec<(String, usize)> {
    text.lines()
        .enumerate()
        .filter_map(|(k, raw)| {
            let t = raw.trim_start();
            let rest = t.strip_prefix("newmtl")?;
            rest.starts_with(char::is_whitespace)
                .then(|| (rest.trim().to_string(), k + 1))
        })
        .collect()
}

/// The line numbers (1-based) of the `f` statements, in file order; or the first problem found.
pub(crate) fn scan(shown: &str, text: &str) -> Result<Vec<usize>, SceneError> {
    let error = |line: usize, problem: StatementProblem| SceneError::File {
        path: format!("{shown}:{line}"),
        message: problem.to_string(),
    };
    let vertices = text.lines().filter(|l| keyword(l) == Some("v")).count();
    let mut seen = 0usize;
    let mut faces = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let mut tokens = raw.split_whitespace();
        match tokens.next() {
            Some("v") => {
                seen += 1;
                check_vertex(tokens, seen).map_err(|m| error(line, m))?;
            }
            Some("f") => {
                check_face(tokens, seen, vertices).map_err(|m| error(line, m))?;
                faces.push(line);
            }
            _ => {}
        }
    }
    Ok(faces)
}

fn keyword(line: &str) -> Option<&str> {
    line.split_whitespace().next()
}

/// What is wrong with a `v` or `f` statement (the message follows the file's name and the line).
#[derive(Debug, thiserror::Error)]
pub(crate) enum StatementProblem {
    /// A vertex with fewer than three coordinates: its number (1-based) and how many it has.
    #[error("vertex {index} (`v`) has {found} coordinate(s); a vertex needs x, y and z")]
    VertexTooShort {
        /// The vertex's number (1-based).
        index: usize,
        /// How many coordinates it has.
        found: usize,
    },
    /// A vertex coordinate that is not a number: the vertex's number and the token.
    #[error("vertex {index} (`v`): `{token}` is not a number")]
    NotANumber {
        /// The vertex's number (1-based).
        index: usize,
        /// The token where a coordinate should be.
        token: String,
    },
    /// A vertex with an infinite or NaN coordinate: its number and its coordinates.
    #[error("vertex {index} has a non-finite coordinate ({}, {}, {})", .xyz[0], .xyz[1], .xyz[2])]
    NotFinite {
        /// The vertex's number (1-based).
        index: usize,
        /// Its coordinates.
        xyz: [f64; 3],
    },
    /// A face of fewer than three corners: how many it has.
    #[error("a face (`f`) needs at least 3 vertices, it has {0}")]
    FaceTooSmall(usize),
    /// A face corner whose vertex is not an integer: the corner and its vertex part.
    #[error("face corner `{corner}`: `{vertex}` is not a vertex index")]
    NotAnIndex {
        /// The corner as written (`v`, `v/vt`, ...).
        corner: String,
        /// Its vertex part.
        vertex: String,
    },
    /// A face corner naming a vertex that does not exist: the corner, the vertex it resolves to, and
    /// how many vertices the file has.
    #[error(
        "face corner `{corner}` refers to vertex {resolved}, but the file has {total} vertices"
    )]
    NoSuchVertex {
        /// The corner as written.
        corner: String,
        /// The vertex number it resolves to (a negative index counted back from the last vertex).
        resolved: i64,
        /// How many vertices the file has.
        total: usize,
    },
}

/// A `v` statement: three finite numbers (a fourth, or colours, may follow).
fn check_vertex<'a>(
    mut tokens: impl Iterator<Item = &'a str>,
    index: usize,
) -> Result<(), StatementProblem> {
    let mut xyz = [0.0f64; 3];
    for (a, c) in xyz.iter_mut().enumerate() {
        let token = tokens
            .next()
            .ok_or(StatementProblem::VertexTooShort { index, found: a })?;
        *c = token.parse().map_err(|_| StatementProblem::NotANumber {
            index,
            token: token.to_string(),
        })?;
    }
    if xyz.iter().any(|c| !c.is_finite()) {
        return Err(StatementProblem::NotFinite { index, xyz });
    }
    Ok(())
}

/// An `f` statement: at least 3 corners, each `v`, `v/vt`, `v//vn` or `v/vt/vn` with a vertex index that
/// exists (positive: from the start of the file; negative: back from the last vertex read).
fn check_face<'a>(
    tokens: impl Iterator<Item = &'a str>,
    seen: usize,
    total: usize,
) -> Result<(), StatementProblem> {
    let corners: Vec<&str> = tokens.collect();
    if corners.len() < 3 {
        return Err(StatementProblem::FaceTooSmall(corners.len()));
    }
    for corner in corners {
        let first = corner.split('/').next().unwrap_or("");
        let index: i64 = first.parse().map_err(|_| StatementProblem::NotAnIndex {
            corner: corner.to_string(),
            vertex: first.to_string(),
        })?;
        let resolved = if index < 0 {
            seen as i64 + index + 1
        } else {
            index
        };
        if resolved < 1 || resolved > total as i64 {
            return Err(StatementProblem::NoSuchVertex {
                corner: corner.to_string(),
                resolved,
                total,
            });
        }
    }
    Ok(())
}

/// Checks the colour statements of MTL text (`Ka`, `Kd`, `Ks`, `Ke`: three numbers), which `tobj` would
/// panic on with fewer than three values.
pub(crate) fn scan_mtl(shown: &str, text: &str) -> Result<(), SceneError> {
    for (k, raw) in text.lines().enumerate() {
        let mut tokens = raw.split_whitespace();
        let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = tokens.next() else {
            continue;
        };
        let values: Vec<&str> = tokens.take(3).collect();
        let numbers = values.iter().filter(|v| v.parse::<f64>().is_ok()).count();
        if values.len() < 3 || numbers < 3 {
            return Err(SceneError::File {
                path: format!("{shown}:{}", k + 1),
                message: format!(
                    "`{key}` needs three numbers (red, green, blue), it has `{}`",
                    values.join(" ")
                ),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    /// Found by fuzzing: tobj 4.0.5 panics on `Kd 02 4` (two values).
    #[test]
    fn short_colours_in_an_mtl_are_refused() {
        assert!(scan_mtl("m.mtl", "newmtl m\nKd 0.5 0.5 0.5\nKe 1 1 1\n").is_ok());
        for text in ["newmtl m\nKd 02 4\n", "Ke 1\n", "Ka\n", "Ks 1 x 1\n"] {
            let e = scan_mtl("m.mtl", text).unwrap_err().to_string();
            assert!(
                e.starts_with("m.mtl:") && e.contains("needs three numbers"),
                "{e}"
            );
        }
    }

    use super::*;

    /// Bytes that are not UTF-8 in names and comments are read as Latin-1 characters, each its own
    /// (U+FFFD for all would merge `caf\xe9` and `caf\xe8`); anywhere else they are an error naming
    /// the line, the column and the statement (the whole file was "not a text file").
    #[test]
    fn names_and_comments_may_be_in_latin_1() {
        let bytes =
            b"# \xa9 1999\no caf\xe9\ng caf\xe8 # \xff\nv 0 0 0 # d\xe9j\xe0\nusemtl r\xf6t\n";
        assert_eq!(
            text_of(bytes, OBJ_NAMES).unwrap(),
            "# \u{a9} 1999\no caf\u{e9}\ng caf\u{e8} # \u{ff}\nv 0 0 0 # d\u{e9}j\u{e0}\nusemtl r\u{f6}t\n"
        );
        assert!(matches!(
            text_of(b"v 0 0 0\n", OBJ_NAMES),
            Ok(Cow::Borrowed(_))
        ));
        let e = text_of(b"o caf\xe9\nv 0 \xe9 0\n", OBJ_NAMES).unwrap_err();
        assert_eq!(e.line, 2);
        assert_eq!(
            e.to_string(),
            "byte 0xE9 at column 5 is not text (UTF-8) in a `v` statement; only names (`o`, `g`, \
             `usemtl`, `mtllib`, `maplib`, `usemap`) and comments may hold other bytes"
        );
        assert_eq!(
            text_of(b"newmtl \xe9\nKd 1 \xe9 1\n", MTL_NAMES)
                .unwrap_err()
                .line,
            2
        );
    }

    #[test]
    fn problems_are_found_on_their_line() {
        let ok = "# a triangle\nv 0 0 0\nv 1 0 0 1\nv 0 1 0\nf 1 2/1 -1//3\n";
        assert_eq!(scan("t.obj", ok).unwrap(), vec![5]);
        for (text, line, what) in [
            ("v 0 0\n", 1, "has 2 coordinate(s)"),
            ("v 0 0 0\nv 1 x 0\n", 2, "`x` is not a number"),
            ("v 0 0 0\nv 1 NaN 0\n", 2, "non-finite"),
            (
                "v 0 0 0\nv 1 0 0\n\nf 1 2\n",
                4,
                "at least 3 vertices, it has 2",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
                4,
                "refers to vertex 4",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
                4,
                "refers to vertex 0",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a\n",
                4,
                "not a vertex index",
            ),
        ] {
            let e = scan("t.obj", text).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("t.obj:{line}: ")) && e.contains(what),
                "{e}"
            );
        }
    }
}
