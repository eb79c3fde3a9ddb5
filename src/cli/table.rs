//! Text tables whose columns stay aligned whatever the values, and the number format they use.

/// How a column's cells line up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Align {
    Left,
    Right,
}

/// A table of text cells, rendered with every column as wide as its widest cell.
pub struct Table {
    header: Vec<String>,
    align: Vec<Align>,
    rows: Vec<Option<Vec<String>>>,
}

impl Table {
    /// A table with these column headers and alignments.
    pub fn new(header: &[&str], align: &[Align]) -> Self {
        Table {
            header: header.iter().map(|h| h.to_string()).collect(),
            align: align.to_vec(),
            rows: Vec::new(),
        }
    }

    /// Adds a row (one cell per column).
    pub fn row(&mut self, cells: Vec<String>) {
        self.rows.push(Some(cells));
    }

    /// Adds an empty line between rows.
    pub fn separator(&mut self) {
        self.rows.push(None);
    }

    /// The table as lines of text, two spaces between columns, no trailing spaces.
    pub fn render(&self) -> String {
        let mut widths: Vec<usize> = self.header.iter().map(|h| h.chars().count()).collect();
        for row in self.rows.iter().flatten() {
            for (w, c) in widths.iter_mut().zip(row) {
                *w = (*w).max(c.chars().count());
            }
        }
        let line = |cells: &[String]| {
            let mut s = String::new();
            for (k, (c, &w)) in cells.iter().zip(&widths).enumerate() {
                if k > 0 {
                    s.push_str("  ");
                }
                let pad = w - c.chars().count();
                match self.align[k] {
                    Align::Left => {
                        s.push_str(c);
                        s.extend(std::iter::repeat_n(' ', pad));
                    }
                    Align::Right => {
                        s.extend(std::iter::repeat_n(' ', pad));
                        s.push_str(c);
                    }
                }
            }
            s.truncate(s.trim_end().len());
            s.push('\n');
            s
        };
        let mut out = line(&self.header);
        for row in &self.rows {
            match row {
                Some(cells) => out += &line(cells),
                None => out.push('\n'),
            }
        }
        out
    }
}

/// A reading for the table: six decimals, or four significant digits in scientific notation from 10^6
/// up; never a negative zero; `n/a` when not finite.
pub fn fixed(v: f64) -> String {
    if !v.is_finite() {
        return "n/a".into();
    }
    let v = v + 0.0;
    if v.abs() >= 1e6 {
        return format!("{v:.3e}");
    }
    let s = format!("{v:.6}");
    // A tiny negative value rounds to -0.000000.
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        return s.trim_start_matches('-').to_string();
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_well_and_never_as_negative_zero() {
        assert_eq!(fixed(1.5), "1.500000");
        assert_eq!(fixed(-0.0), "0.000000");
        assert_eq!(fixed(-1e-12), "0.000000");
        assert_eq!(fixed(6.1e-17), "0.000000");
        assert_eq!(fixed(15413.97), "15413.970000");
        assert_eq!(fixed(2.5e7), "2.500e7");
        assert_eq!(fixed(f64::NAN), "n/a");
    }

    #[test]
    fn columns_align_whatever_the_widths() {
        let mut t = Table::new(&["a", "b"], &[Align::Left, Align::Right]);
        t.row(vec!["x".into(), "1.0".into()]);
        t.row(vec!["longer".into(), "15413.970000".into()]);
        let text = t.render();
        let ends: Vec<usize> = text.lines().map(|l| l.len()).collect();
        assert!(ends.iter().all(|&e| e == ends[0]), "{text}");
    }
}
