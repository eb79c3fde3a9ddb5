//! How a picture's title fits the strip above it: whole, on one line, in the largest size that fits;
//! else on two lines, the scene and the line count above the quantity, in a smaller size; a scene name
//! too long for its line (a deep path) loses the middle of its characters to `…`, keeping its start and
//! the file's name. Only a picture too narrow for the quantity on one line gets a taller strip, with the
//! quantity wrapped at its spaces. No letter is ever cut by the picture's edge.
//!
//! Widths come from the caller's `measure` (the drawing's own font), so the layout holds for the font
//! that draws it.

/// The height of the title strip when the title takes one or two lines, pixels.
pub const STRIP: f64 = 34.0;

/// The font sizes a title may take on one line, pixels, the largest first.
const ONE_LINE: [f64; 4] = [17.0, 16.0, 15.0, 14.0];

/// The font sizes on two lines (two lines of them fit the strip), the largest first.
const TWO_LINES: [f64; 2] = [13.0, 12.0];

/// What stands between the title's parts on a line.
const SEPARATOR: &str = "   ";

/// What a picture's title says, in the parts that may go on lines of their own.
#[derive(Clone, Copy, Debug)]
pub struct TitleParts<'a> {
    /// The scene's name (a built-in's, or the file's path).
    pub scene: &'a str,
    /// What the colours are, with their unit.
    pub quantity: &'a str,
    /// How many lines the run cast (`1 000 000 lines`).
    pub lines: &'a str,
}

/// A title laid out to fit a width.
#[derive(Clone, Debug, PartialEq)]
pub struct TitleLayout {
    /// The font size, pixels.
    pub size: f64,
    /// The lines of text, from the top.
    pub lines: Vec<String>,
}

impl TitleLayout {
    /// The distance between two lines' tops, pixels.
    pub fn pitch(&self) -> f64 {
        self.size + 2.0
    }

    /// The height of the strip the title needs: [`STRIP`], or more for three lines or more.
    pub fn height(&self) -> f64 {
        STRIP.max(4.0 + self.lines.len() as f64 * self.pitch())
    }

    /// The top of line `k`, pixels from the top of the strip: the lines centred in it.
    pub fn top(&self, k: usize) -> f64 {
        let block = self.lines.len() as f64 * self.pitch() - 2.0;
        (0.5 * (self.height() - block)).floor() + k as f64 * self.pitch()
    }
}

/// Lays `parts` out within `width` pixels, `measure(text, size)` giving the width of a text in a font
/// size (module documentation).
pub fn fit_title(
    parts: &TitleParts,
    width: f64,
    measure: &dyn Fn(&str, f64) -> f64,
) -> TitleLayout {
    let whole = [parts.scene, parts.quantity, parts.lines].join(SEPARATOR);
    for size in ONE_LINE {
        if measure(&whole, size) <= width {
            return TitleLayout {
                size,
                lines: vec![whole],
            };
        }
    }
    for size in TWO_LINES {
        if measure(parts.quantity, size) <= width {
            let first = scene_line(parts, width, size, measure);
            return TitleLayout {
                size,
                lines: vec![first, parts.quantity.to_string()],
            };
        }
    }
    wrapped(parts, width, measure)
}

/// The scene and the line count on one line at `size`, the scene elided to make room; the scene alone
/// when even `…` leaves no room for both.
fn scene_line(
    parts: &TitleParts,
    width: f64,
    size: f64,
    measure: &dyn Fn(&str, f64) -> f64,
) -> String {
    let tail = format!("{SEPARATOR}{}", parts.lines);
    let room = width - measure(&tail, size);
    let scene = elide_middle(parts.scene, room, size, measure);
    if measure(&scene, size) <= room {
        format!("{scene}{tail}")
    } else {
        elide_middle(parts.scene, width, size, measure)
    }
}

/// The title in the smallest size, its quantity wrapped at spaces, on as many lines as it takes.
fn wrapped(parts: &TitleParts, width: f64, measure: &dyn Fn(&str, f64) -> f64) -> TitleLayout {
    let size = TWO_LINES[TWO_LINES.len() - 1];
    let fits = |s: &str| measure(s, size) <= width;
    let mut lines = vec![elide_middle(parts.scene, width, size, measure)];
    for word in parts.quantity.split(' ') {
        let joined = format!("{} {word}", lines[lines.len() - 1]);
        if lines.len() > 1 && fits(&joined) {
            *lines.last_mut().expect("a line") = joined;
        } else {
            lines.push(elide_middle(word, width, size, measure));
        }
    }
    let with_count = format!("{}{SEPARATOR}{}", lines[lines.len() - 1], parts.lines);
    if fits(&with_count) {
        *lines.last_mut().expect("a line") = with_count;
    } else {
        lines.push(parts.lines.to_string());
    }
    TitleLayout { size, lines }
}

/// `text`, or as much of its start and end as fits `width` around `…` (a third of the characters
/// kept from the start, two thirds from the end, where a file's name is).
pub fn elide_middle(
    text: &str,
    width: f64,
    size: f64,
    measure: &dyn Fn(&str, f64) -> f64,
) -> String {
    if measure(text, size) <= width {
        return text.to_string();
    }
    let chars: Vec<char> = text.chars().collect();
    (0..chars.len())
        .rev()
        .map(|kept| {
            let head = kept / 3;
            let start: String = chars[..head].iter().collect();
            let end: String = chars[chars.len() - (kept - head)..].iter().collect();
            format!("{start}…{end}")
        })
        .find(|s| measure(s, size) <= width)
        .unwrap_or_else(|| "…".to_string())
}
