//! The README and the guide under `docs/`: every relative Markdown link (`[text](path)`,
//! `[text](path#anchor)`, `[text](#anchor)`, images too) points to a file of the repository that exists, and
//! every anchor into a Markdown file to one of its headings, by GitHub's slugs. The README stays a front door
//! of at most 400 lines and the guide has at least 3 pages, all listed in its index (issue 26's acceptance
//! numbers).
//!
//! What counts as Markdown here is what these pages use: ATX headings (`## Title`), inline links, fenced
//! code blocks (whose contents are not prose, so neither links nor headings) and code spans (skipped).
//! Setext headings, reference-style links and HTML anchors are not recognised; indented code blocks are
//! read as prose, so a command shown in one must not look like a link (fence it instead). Links with a
//! scheme (`https:`, `mailto:`) are not followed. Only std: a slug and a link pattern need no parser.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Component, Path, PathBuf};

/// The issue's acceptance numbers.
const README_MAX_LINES: usize = 400;
const MIN_GUIDE_PAGES: usize = 3;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The guide's pages: every `docs/*.md` but its index, sorted.
fn guide_pages() -> Vec<PathBuf> {
    let mut pages: Vec<PathBuf> = fs::read_dir(root().join("docs"))
        .expect("docs/ exists")
        .map(|entry| entry.expect("a readable docs/ entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .filter(|p| p.file_name().is_some_and(|n| n != "README.md"))
        .collect();
    pages.sort();
    pages
}

/// The documents whose links are checked: the README, the guide's index and its pages.
fn documents() -> Vec<PathBuf> {
    let mut docs = vec![root().join("README.md"), root().join("docs/README.md")];
    docs.extend(guide_pages());
    docs
}

fn read(path: &Path) -> String {
    fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Whether a line opens or closes a fenced code block (up to 3 spaces, then ``` or ~~~), and with which
/// fence character and length.
fn fence(line: &str) -> Option<(char, usize)> {
    let trimmed = line.trim_start_matches(' ');
    if line.len() - trimmed.len() > 3 {
        return None;
    }
    let c = trimmed.chars().next()?;
    if c != '`' && c != '~' {
        return None;
    }
    let n = trimmed.chars().take_while(|&x| x == c).count();
    (n >= 3).then_some((c, n))
}

/// The text with every fenced code block blanked out (its lines kept, empty), so that line numbers stay
/// those of the file.
fn without_fenced_code(text: &str) -> Vec<String> {
    let mut open: Option<(char, usize)> = None;
    text.lines()
        .map(|line| match (open, fence(line)) {
            (None, Some(f)) => {
                open = Some(f);
                String::new()
            }
            (Some((c, n)), Some((c2, n2))) if c == c2 && n2 >= n && line.trim().len() == n2 => {
                open = None;
                String::new()
            }
            (Some(_), _) => String::new(),
            (None, None) => line.to_string(),
        })
        .collect()
}

/// The text with its code spans blanked out (backtick runs of equal length and everything between them,
/// across lines within a paragraph), newlines kept so that offsets still give line numbers.
fn without_code_spans(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out = chars.clone();
    let run_at = |i: usize| chars[i..].iter().take_while(|&&c| c == '`').count();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] != '`' {
            i += 1;
            continue;
        }
        let n = run_at(i);
        // The closing run: the next run of exactly n backticks before a blank line (a paragraph's end).
        let mut j = i + n;
        let mut close = None;
        while j < chars.len() {
            if chars[j] == '\n'
                && chars[j + 1..]
                    .iter()
                    .take_while(|&&c| c != '\n')
                    .all(|c| c.is_whitespace())
            {
                break;
            }
            if chars[j] == '`' {
                let m = run_at(j);
                if m == n {
                    close = Some(j + m);
                    break;
                }
                j += m;
            } else {
                j += 1;
            }
        }
        match close {
            Some(end) => {
                for c in &mut out[i..end] {
                    if *c != '\n' {
                        *c = ' ';
                    }
                }
                i = end;
            }
            None => i += n, // an unmatched run is literal text
        }
    }
    out.into_iter().collect()
}

/// The prose of a Markdown text, code removed, with the file's line structure.
fn prose(text: &str) -> String {
    without_code_spans(&without_fenced_code(text).join("\n"))
}

/// The inline links of a text (images included): (line number from 1, destination).
fn links(text: &str) -> Vec<(usize, String)> {
    let prose = prose(text);
    let mut found = Vec::new();
    let bytes = prose.as_bytes();
    let mut search = 0;
    while let Some(k) = prose[search..].find("](") {
        let at = search + k;
        search = at + 2;
        // `]` must close a `[` of the same paragraph; a `\]` is literal.
        if at > 0 && bytes[at - 1] == b'\\' {
            continue;
        }
        let before = &prose[..at];
        let paragraph_start = before.rfind("\n\n").map_or(0, |p| p + 2);
        if !before[paragraph_start..].contains('[') {
            continue;
        }
        // The destination: `<...>`, or up to whitespace or the `)` that balances the `(`.
        let rest = &prose[at + 2..];
        let destination = if let Some(inner) = rest.strip_prefix('<') {
            inner.split('>').next().unwrap_or("").to_string()
        } else {
            let mut depth = 0usize;
            let mut end = rest.len();
            for (i, c) in rest.char_indices() {
                match c {
                    '(' => depth += 1,
                    ')' if depth == 0 => {
                        end = i;
                        break;
                    }
                    ')' => depth -= 1,
                    c if c.is_whitespace() => {
                        end = i;
                        break;
                    }
                    _ => {}
                }
            }
            rest[..end].to_string()
        };
        let line = prose[..at].matches('\n').count() + 1;
        found.push((line, destination));
    }
    found
}

/// GitHub's anchor for a heading's text: inline links reduced to their text, lower case, spaces to `-`,
/// every character but letters, digits, `-` and `_` dropped (so code spans' backticks, `:`, `.`, `'`,
/// `(`, `|` and the like vanish).
fn slug(heading: &str) -> String {
    let mut text = String::new();
    let mut rest = heading;
    // `[text](url)` -> `text`.
    while let Some(open) = rest.find('[') {
        let Some(mid) = rest[open..].find("](").map(|m| open + m) else {
            break;
        };
        let Some(close) = rest[mid..].find(')').map(|c| mid + c) else {
            break;
        };
        text.push_str(&rest[..open]);
        text.push_str(&rest[open + 1..mid]);
        rest = &rest[close + 1..];
    }
    text.push_str(rest);
    text.chars()
        .flat_map(char::to_lowercase)
        .filter_map(|c| match c {
            ' ' => Some('-'),
            '-' | '_' => Some(c),
            c if c.is_alphanumeric() => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a Markdown text's ATX headings, repeated ones numbered as GitHub does (`x`, `x-1`, ...).
fn anchors(text: &str) -> Vec<String> {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut out = Vec::new();
    for line in without_fenced_code(text) {
        let trimmed = line.trim_start_matches(' ');
        if line.len() - trimmed.len() > 3 {
            continue;
        }
        let hashes = trimmed.chars().take_while(|&c| c == '#').count();
        if !(1..=6).contains(&hashes) {
            continue;
        }
        let after = &trimmed[hashes..];
        if !(after.is_empty() || after.starts_with(' ') || after.starts_with('\t')) {
            continue;
        }
        // A closing sequence of `#`s after a space is not part of the heading.
        let mut title = after.trim();
        let unclosed = title.trim_end_matches('#');
        if unclosed.is_empty() || unclosed.ends_with(' ') {
            title = unclosed.trim_end();
        }
        let base = slug(title);
        let n = seen.entry(base.clone()).or_insert(0);
        out.push(if *n == 0 {
            base.clone()
        } else {
            format!("{base}-{n}")
        });
        *n += 1;
    }
    out
}

/// `path` with `.` and `..` resolved lexically (the targets need not exist).
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// `%20` and the like, as a browser decodes a link.
fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let hex = |b: u8| (b as char).to_digit(16);
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let (Some(hi), Some(lo)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push((hi * 16 + lo) as u8);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// What is wrong with the relative links of one document (whose text is `text`), one sentence each.
fn link_errors(doc: &Path, text: &str) -> Vec<String> {
    let root = normalise(&root());
    let name = doc.strip_prefix(&root).unwrap_or(doc).display().to_string();
    let dir = doc.parent().expect("a document is in a folder");
    let mut errors = Vec::new();
    for (line, destination) in links(text) {
        let at = format!("{name}:{line}: ({destination})");
        if destination.is_empty() {
            errors.push(format!("{at}: an empty link"));
            continue;
        }
        if destination.contains("://") || destination.starts_with("mailto:") {
            continue;
        }
        let (path, anchor) = match destination.split_once('#') {
            Some((p, a)) => (p, Some(a)),
            None => (destination.as_str(), None),
        };
        let target = if path.is_empty() {
            doc.to_path_buf()
        } else if path.starts_with('/') {
            errors.push(format!(
                "{at}: an absolute path (GitHub resolves it against the site, not the repository)"
            ));
            continue;
        } else {
            normalise(&dir.join(percent_decode(path)))
        };
        if !target.starts_with(&root) {
            errors.push(format!("{at}: leaves the repository"));
            continue;
        }
        if !target.exists() {
            errors.push(format!(
                "{at}: {} does not exist",
                target.strip_prefix(&root).unwrap_or(&target).display()
            ));
            continue;
        }
        let Some(anchor) = anchor else { continue };
        if !target
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("md"))
        {
            continue; // anchors into source files (`#L10`) are GitHub's, not headings
        }
        let target_text = if target == doc {
            text.to_string()
        } else {
            read(&target)
        };
        if !anchors(&target_text).iter().any(|a| a == anchor) {
            errors.push(format!(
                "{at}: no heading of {} has the anchor #{anchor}",
                target.strip_prefix(&root).unwrap_or(&target).display()
            ));
        }
    }
    errors
}

#[test]
fn every_relative_link_of_the_readme_and_the_guide_points_to_an_existing_file_and_heading() {
    let mut errors = Vec::new();
    let mut count = 0;
    for doc in documents() {
        let doc = normalise(&doc);
        let text = read(&doc);
        count += links(&text).len();
        errors.extend(link_errors(&doc, &text));
    }
    assert!(
        count > 50,
        "only {count} links found: is the link pattern still right?"
    );
    assert!(errors.is_empty(), "broken links:\n{}", errors.join("\n"));
}

#[test]
fn the_readme_stays_a_front_door_of_at_most_400_lines() {
    let lines = read(&root().join("README.md")).lines().count();
    assert!(
        lines <= README_MAX_LINES,
        "README.md has {lines} lines, more than {README_MAX_LINES}: move the detail into a page under docs/"
    );
}

#[test]
fn the_guide_has_at_least_three_pages_all_listed_in_its_index() {
    let pages = guide_pages();
    assert!(
        pages.len() >= MIN_GUIDE_PAGES,
        "docs/ has {} guide pages, fewer than {MIN_GUIDE_PAGES}",
        pages.len()
    );
    let index = read(&root().join("docs/README.md"));
    let linked: Vec<String> = links(&index)
        .into_iter()
        .map(|(_, d)| d.split('#').next().unwrap_or("").to_string())
        .collect();
    for page in pages {
        let name = page.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            linked.contains(&name),
            "docs/README.md does not link to docs/{name}"
        );
    }
}

#[test]
fn slugs_are_githubs() {
    for (heading, anchor) in [
        ("Reading the reliability verdict", "reading-the-reliability-verdict"),
        ("Open scenes and `--enclose`", "open-scenes-and---enclose"),
        ("Do the paper's findings hold?", "do-the-papers-findings-hold"),
        ("How I_s^c is shared out", "how-i_sc-is-shared-out"),
        (
            "Table 1: fig. 2, 512 cubes: random (a) and clustered (b, c) placements (`@fig2:a|b|c`)",
            "table-1-fig-2-512-cubes-random-a-and-clustered-b-c-placements-fig2abc",
        ),
        ("See [the guide](docs/README.md) first", "see-the-guide-first"),
        ("Über 2 Wände", "über-2-wände"),
    ] {
        assert_eq!(slug(heading), anchor, "{heading}");
    }
    let text = "# A\n\n## A\n\n```\n# not a heading\n```\n\n### B ###\n    #### indented code\n#no space\n";
    assert_eq!(anchors(text), ["a", "a-1", "b"]);
}

#[test]
fn links_in_code_are_not_links_and_broken_ones_are_caught() {
    let text = "See [a](docs/README.md \"title\") and ![b](docs/cornell8_radiosity.png).\n\
                `[not](a-link.md)` and\n\n```\n[nor](this.md)\n```\n\
                [c](<docs/design.md#determinism>), [d](https://example.org/x.md).\n";
    let found: Vec<String> = links(text).into_iter().map(|(_, d)| d).collect();
    assert_eq!(
        found,
        [
            "docs/README.md",
            "docs/cornell8_radiosity.png",
            "docs/design.md#determinism",
            "https://example.org/x.md"
        ]
    );
    let readme = root().join("README.md");
    assert!(
        link_errors(&readme, text).is_empty(),
        "{:?}",
        link_errors(&readme, text)
    );

    let broken = "[a](docs/no-such-page.md), [b](docs/design.md#no-such-heading), [c](#nowhere), \
                  [d](../../outside.md), [e](/README.md)\n# Here\n";
    let errors = link_errors(&readme, broken);
    assert_eq!(errors.len(), 5, "{errors:#?}");
}
