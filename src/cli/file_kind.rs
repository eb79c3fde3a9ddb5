//! What a file's name says it holds, one rule for every command: a report's format is the one `--format`
//! gives, else the one the extension of `-o` names (`.json`, `.csv`), else the command's default, and a
//! `--format` that contradicts the extension is refused; an option that writes files of one kind
//! (`--patches x.csv`, `--plot x.svg`) is refused a name with another extension. Both are checked before
//! any work, so a script never finds a table in `r.json`.

use std::path::Path;

use clap::ValueEnum;

use super::exit::Failure;
use super::output::is_standard_output;

/// The kinds of report a file's extension can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Text for people: a table, Markdown, a listing.
    Text,
    /// One JSON document.
    Json,
    /// CSV rows with a header.
    Csv,
}

impl Kind {
    /// The kind a file's extension names, in any case: `.json`, `.csv`. Any other name (`.txt`, `.md`,
    /// none) names no kind: text by default, or whatever `--format` asks for.
    pub fn named_by(path: &Path) -> Option<Kind> {
        match extension(path).as_str() {
            "json" => Some(Kind::Json),
            "csv" => Some(Kind::Csv),
            _ => None,
        }
    }

    /// The kind's name in messages.
    fn name(self) -> &'static str {
        match self {
            Kind::Text => "text",
            Kind::Json => "JSON",
            Kind::Csv => "CSV",
        }
    }

    /// The extensions a file of this kind is given, for messages.
    fn extensions(self) -> &'static str {
        match self {
            Kind::Text => ".txt or .md",
            Kind::Json => ".json",
            Kind::Csv => ".csv",
        }
    }
}

/// The extension of a path, lower case; empty without one.
pub fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// A value of a command's `--format`: the kind of file it makes.
pub trait ReportFormat: ValueEnum + Copy + PartialEq {
    /// The kind of file this format writes.
    fn kind(self) -> Kind;
}

/// One format a command writes its report in: its name, and the kind of file it makes.
struct Offer {
    name: String,
    kind: Kind,
}

/// The format a report is written in: `given` (`--format`), else the one the extension of `output`
/// (`-o`) names, else the command's first format (its default). Refuses, naming both, a `--format` the
/// extension contradicts, and an extension that names a kind `command` does not write (`hint` may say
/// where that kind is to be had). `-o -` (standard output) names no kind.
pub fn report_format<F: ReportFormat>(
    command: &str,
    given: Option<F>,
    output: Option<&Path>,
    hint: &str,
) -> Result<F, Failure> {
    let formats = F::value_variants();
    let offers: Vec<Offer> = formats
        .iter()
        .map(|f| Offer {
            name: f
                .to_possible_value()
                .map_or_else(String::new, |v| v.get_name().to_string()),
            kind: f.kind(),
        })
        .collect();
    let given = given.and_then(|g| formats.iter().position(|f| *f == g));
    choose(command, given, &offers, output, hint).map(|k| formats[k])
}

/// Refuses an `-o` of a command whose report is text of one kind only (`what`: `Markdown`, `a
/// listing`) when the file's extension names JSON or CSV (`hint` may say where that kind is to be had).
pub fn text_report(
    command: &str,
    what: &str,
    output: Option<&Path>,
    hint: &str,
) -> Result<(), Failure> {
    let offers = [Offer {
        name: what.to_string(),
        kind: Kind::Text,
    }];
    choose(command, None, &offers, output, hint).map(drop)
}

/// The index of the offer to write: see [`report_format`].
fn choose(
    command: &str,
    given: Option<usize>,
    offers: &[Offer],
    output: Option<&Path>,
    hint: &str,
) -> Result<usize, Failure> {
    let path = output.filter(|p| !is_standard_output(p));
    let named = path.and_then(|p| Kind::named_by(p).map(|kind| (p, kind)));
    match (given, named) {
        (Some(g), Some((path, kind))) if offers[g].kind != kind => {
            Err(Failure::bad_input(format!(
                "--format {} and -o {} disagree: .{} names {} and --format {} writes {}; drop \
                 --format (the extension then chooses) or name a {} file",
                offers[g].name,
                path.display(),
                extension(path),
                kind.name(),
                offers[g].name,
                offers[g].kind.name(),
                offers[g].kind.extensions()
            )))
        }
        (Some(g), _) => Ok(g),
        (None, Some((path, kind))) => offers.iter().position(|o| o.kind == kind).ok_or_else(|| {
            let names: Vec<&str> = offers.iter().map(|o| o.name.as_str()).collect();
            let fitting: Vec<&str> = offers.iter().map(|o| o.kind.extensions()).collect();
            Failure::bad_input(format!(
                "-o {} names a {} file, and scx {command} writes its report as {} only; name a {} \
                 file{hint}",
                path.display(),
                kind.name(),
                names.join(" or "),
                fitting.join(" or ")
            ))
        }),
        (None, None) => Ok(0),
    }
}

/// Refuses, before any work, a file of `option` whose extension is not one of `allowed` (lower case,
/// without the dot): the one rule and message of every option that writes a file of a given kind.
pub fn check_extension(option: &str, path: &Path, allowed: &[&str]) -> Result<(), Failure> {
    if allowed.contains(&extension(path).as_str()) {
        return Ok(());
    }
    let list: Vec<String> = allowed.iter().map(|e| format!(".{e}")).collect();
    Err(Failure::bad_input(format!(
        "{option} {}: {option} writes {} files only; name one ending in {}",
        path.display(),
        list.join(" or "),
        list.join(" or ")
    )))
}

/// Checks every file of a CSV-writing option (`--patches`, `--csv`, ...): see [`check_extension`].
pub fn check_csv<'a>(
    option: &str,
    paths: impl IntoIterator<Item = &'a Path>,
) -> Result<(), Failure> {
    paths
        .into_iter()
        .try_for_each(|p| check_extension(option, p, &["csv"]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
    enum Two {
        Table,
        Json,
    }

    impl ReportFormat for Two {
        fn kind(self) -> Kind {
            match self {
                Two::Table => Kind::Text,
                Two::Json => Kind::Json,
            }
        }
    }

    fn pick(given: Option<Two>, output: &str) -> Result<Two, String> {
        report_format("test", given, Some(Path::new(output)), "").map_err(|f| f.message)
    }

    #[test]
    fn the_extension_chooses_unless_format_is_given_and_contradictions_are_refused() {
        assert_eq!(pick(None, "r.json"), Ok(Two::Json));
        assert_eq!(pick(None, "R.JSON"), Ok(Two::Json));
        assert_eq!(pick(None, "r.txt"), Ok(Two::Table));
        assert_eq!(pick(None, "r"), Ok(Two::Table));
        assert_eq!(pick(None, "-"), Ok(Two::Table));
        assert_eq!(pick(Some(Two::Json), "-"), Ok(Two::Json));
        assert_eq!(pick(Some(Two::Json), "r.txt"), Ok(Two::Json));
        let clash = pick(Some(Two::Table), "r.json").unwrap_err();
        assert!(
            clash.contains("--format table and -o r.json disagree"),
            "{clash}"
        );
        let unknown = pick(None, "r.csv").unwrap_err();
        assert!(
            unknown.contains("writes its report as table or json only"),
            "{unknown}"
        );
        assert!(check_extension("--csv", Path::new("c.CSV"), &["csv"]).is_ok());
        let wrong = check_extension("--csv", Path::new("c.txt"), &["csv"]).unwrap_err();
        assert!(wrong
            .message
            .contains("--csv c.txt: --csv writes .csv files only"));
    }
}
