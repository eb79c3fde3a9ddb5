//! The layers import only downwards (geom <- scene <- scenes <- trace <- sample <- measure <- run <-
//! applications <- cli), and the modules inside one layer import each other without cycles.
//!
//! The test reads every `.rs` file under `src/`, works out its module path and the crate-internal modules
//! it uses (`use` trees, `crate::`/`super::`/`self::` paths in code, names bound by `use`, child modules,
//! `scene_complexity::` in the binary) and resolves names re-exported by a module (`pub use`) to the module
//! that defines them. Comments (so intra-doc links), strings and character literals are skipped. A module
//! that a parent declares or re-exports is not a dependency of the parent in the cycle check (a folder's
//! `mod.rs` is its facade).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, lowest first, and the top-level modules of the library in each. A top-level module missing
/// here fails the test: a new module has to be given its place.
const LAYERS: &[(&str, &[&str])] = &[
    ("geom", &["geom"]),
    ("scene", &["scene"]),
    ("scenes", &["scenes"]),
    ("trace", &["trace"]),
    ("sample", &["sample"]),
    ("measure", &["measure"]),
    ("run", &["run"]),
    ("analysis", &["analysis"]),
    (
        "applications",
        &[
            "reproduce",
            "refine",
            "crosscheck",
            "render",
            "report",
            "calibrate",
        ],
    ),
    ("cli", &[]),
];

/// Which crate a module belongs to: the library, or the `scx` binary (`src/main.rs` and `src/cli/`).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Debug)]
enum Krate {
    Lib,
    Bin,
}

/// A module: its crate and its path inside that crate (empty for the crate root).
type Module = (Krate, Vec<String>);

fn module_name(m: &Module) -> String {
    match (m.0, m.1.is_empty()) {
        (Krate::Lib, true) => "crate".to_string(),
        (Krate::Bin, true) => "main".to_string(),
        _ => m.1.join("::"),
    }
}

/// The layer index of a module, or `None` for the library's root (which declares and re-exports
/// everything) or a top-level module missing from `LAYERS`.
fn layer_of(m: &Module) -> Option<usize> {
    if m.0 == Krate::Bin {
        return Some(LAYERS.len() - 1);
    }
    let top = m.1.first()?;
    LAYERS
        .iter()
        .position(|(_, mods)| mods.contains(&top.as_str()))
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Ident(String),
    PathSep,
    Punct(char),
}

/// Tokens with their line numbers; comments, strings, byte strings, raw strings, characters and numbers
/// are dropped (so their contents never look like paths).
fn tokenize(src: &str) -> Vec<(Tok, usize)> {
    let c: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let (mut i, mut line) = (0, 1);
    let skip_to = |from: usize, to: usize, line: &mut usize| {
        *line += c[from..to.min(c.len())]
            .iter()
            .filter(|&&x| x == '\n')
            .count();
        to
    };
    while i < c.len() {
        let ch = c[i];
        let next = c.get(i + 1).copied().unwrap_or('\0');
        if ch == '\n' {
            line += 1;
            i += 1;
        } else if ch.is_whitespace() {
            i += 1;
        } else if ch == '/' && next == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && next == '*' {
            let (mut depth, mut j) = (0usize, i);
            while j < c.len() {
                if c[j] == '/' && c.get(j + 1) == Some(&'*') {
                    depth += 1;
                    j += 2;
                } else if c[j] == '*' && c.get(j + 1) == Some(&'/') {
                    depth -= 1;
                    j += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    j += 1;
                }
            }
            i = skip_to(i, j, &mut line);
        } else if let Some(end) = raw_string_end(&c, i) {
            i = skip_to(i, end, &mut line);
        } else if ch == '"' || (ch == 'b' && next == '"') {
            let mut j = if ch == 'b' { i + 2 } else { i + 1 };
            while j < c.len() && c[j] != '"' {
                j += if c[j] == '\\' { 2 } else { 1 };
            }
            i = skip_to(i, j + 1, &mut line);
        } else if ch == '\'' || (ch == 'b' && next == '\'') {
            let j = if ch == 'b' { i + 1 } else { i };
            if c.get(j + 1) == Some(&'\\') {
                let mut k = j + 2;
                while k < c.len() && c[k] != '\'' {
                    k += 1;
                }
                i = k + 1;
            } else if c.get(j + 2) == Some(&'\'') {
                i = j + 3;
            } else {
                i = j + 1; // a lifetime: its name is read as an identifier, which is harmless
            }
        } else if ch.is_alphanumeric() || ch == '_' {
            let start = i;
            while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                i += 1;
            }
            if !ch.is_ascii_digit() {
                out.push((Tok::Ident(c[start..i].iter().collect()), line));
            }
        } else if ch == ':' && next == ':' {
            out.push((Tok::PathSep, line));
            i += 2;
        } else {
            out.push((Tok::Punct(ch), line));
            i += 1;
        }
    }
    out
}

/// The end of a raw (byte) string starting at `i` (`r"..."`, `r#"..."#`, `br#"..."#`), if one starts there.
fn raw_string_end(c: &[char], i: usize) -> Option<usize> {
    if i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_') {
        return None;
    }
    let mut j = i;
    if c.get(j) == Some(&'b') {
        j += 1;
    }
    if c.get(j) != Some(&'r') {
        return None;
    }
    j += 1;
    let hashes = c[j..].iter().take_while(|&&x| x == '#').count();
    j += hashes;
    if c.get(j) != Some(&'"') {
        return None;
    }
    j += 1;
    while j < c.len() {
        if c[j] == '"'
            && c[j + 1..]
                .iter()
                .take(hashes)
                .filter(|&&x| x == '#')
                .count()
                == hashes
        {
            return Some(j + 1 + hashes);
        }
        j += 1;
    }
    Some(c.len())
}

/// One path found in a file, in the module (possibly an inline `mod`) where it was written.
#[derive(Clone, Debug)]
struct PathUse {
    segments: Vec<String>,
    /// The name the path binds (`use a::b as c` binds `c`, `use a::b` binds `b`), for `use` items.
    binds: Option<String>,
    /// The module the path was written in (the file's module plus inline `mod` blocks).
    scope: Vec<String>,
    line: usize,
    is_use: bool,
    is_pub_use: bool,
}

/// Reads a `use` tree starting at `i` (after `use`), appending each full path to `out`; returns the
/// position after the tree.
fn use_tree(
    toks: &[(Tok, usize)],
    mut i: usize,
    prefix: &[String],
    out: &mut Vec<(Vec<String>, Option<String>)>,
) -> usize {
    let mut segs = prefix.to_vec();
    if toks.get(i).map(|t| &t.0) == Some(&Tok::PathSep) {
        i += 1;
    }
    loop {
        match toks.get(i).map(|t| &t.0) {
            Some(Tok::Ident(name)) => {
                segs.push(name.clone());
                i += 1;
                if toks.get(i).map(|t| &t.0) == Some(&Tok::PathSep) {
                    i += 1;
                    continue;
                }
                let mut bound = segs.last().cloned();
                if let (Some(Tok::Ident(kw)), Some(Tok::Ident(alias))) =
                    (toks.get(i).map(|t| &t.0), toks.get(i + 1).map(|t| &t.0))
                {
                    if kw == "as" {
                        bound = Some(alias.clone());
                        i += 2;
                    }
                }
                if bound.as_deref() == Some("self") {
                    segs.pop();
                    bound = segs.last().cloned();
                }
                if bound.as_deref() == Some("_") {
                    bound = None;
                }
                out.push((segs, bound));
                return i;
            }
            Some(Tok::Punct('*')) => {
                out.push((segs, None));
                return i + 1;
            }
            Some(Tok::Punct('{')) => {
                i += 1;
                loop {
                    match toks.get(i).map(|t| &t.0) {
                        Some(Tok::Punct('}')) => return i + 1,
                        Some(Tok::Punct(',')) => i += 1,
                        None => return i,
                        _ => i = use_tree(toks, i, &segs, out),
                    }
                }
            }
            _ => {
                out.push((segs, None));
                return i;
            }
        }
    }
}

/// Every path in a file that may name a crate-internal module.
fn paths_in(src: &str, file_module: &[String]) -> Vec<PathUse> {
    let toks = tokenize(src);
    let ident = |i: usize| match toks.get(i) {
        Some((Tok::Ident(s), _)) => Some(s.as_str()),
        _ => None,
    };
    let tok = |i: usize| toks.get(i).map(|t| &t.0);
    let mut out = Vec::new();
    let mut inline_mods: Vec<(String, usize)> = Vec::new();
    let mut depth = 0usize;
    let mut pending_mod: Option<String> = None;
    let mut i = 0;
    while i < toks.len() {
        let scope: Vec<String> = file_module
            .iter()
            .cloned()
            .chain(inline_mods.iter().map(|m| m.0.clone()))
            .collect();
        match &toks[i].0 {
            Tok::Punct('{') => {
                depth += 1;
                if let Some(name) = pending_mod.take() {
                    inline_mods.push((name, depth));
                }
                i += 1;
            }
            Tok::Punct('}') => {
                if inline_mods.last().map(|m| m.1) == Some(depth) {
                    inline_mods.pop();
                }
                depth = depth.saturating_sub(1);
                i += 1;
            }
            Tok::Ident(kw) if kw == "mod" && ident(i + 1).is_some() => {
                if tok(i + 2) == Some(&Tok::Punct('{')) {
                    pending_mod = ident(i + 1).map(str::to_string);
                }
                i += 2;
            }
            Tok::Ident(kw) if kw == "use" && (i == 0 || tok(i - 1) != Some(&Tok::PathSep)) => {
                let is_pub = (i >= 1 && ident(i - 1) == Some("pub"))
                    || (i >= 4
                        && ident(i - 4) == Some("pub")
                        && tok(i - 1) == Some(&Tok::Punct(')')));
                let line = toks[i].1;
                let mut trees = Vec::new();
                i = use_tree(&toks, i + 1, &[], &mut trees);
                for (segments, binds) in trees {
                    out.push(PathUse {
                        segments,
                        binds,
                        scope: scope.clone(),
                        line,
                        is_use: true,
                        is_pub_use: is_pub,
                    });
                }
            }
            Tok::Ident(first) if tok(i + 1) == Some(&Tok::PathSep) => {
                let preceded_by_sep = i > 0 && tok(i - 1) == Some(&Tok::PathSep);
                let line = toks[i].1;
                let mut segments = vec![first.clone()];
                i += 1;
                while tok(i) == Some(&Tok::PathSep) {
                    match ident(i + 1) {
                        Some(s) => {
                            segments.push(s.to_string());
                            i += 2;
                        }
                        None => break,
                    }
                }
                if !preceded_by_sep {
                    out.push(PathUse {
                        segments,
                        binds: None,
                        scope: scope.clone(),
                        line,
                        is_use: false,
                        is_pub_use: false,
                    });
                }
            }
            _ => i += 1,
        }
    }
    out
}

/// The module path of a file under `src/` (`a/b.rs` and `a/b/mod.rs` are `a::b`; `lib.rs` and `main.rs`
/// are their crates' roots; `cli/...` belongs to the binary).
fn module_of_file(rel: &Path) -> Module {
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap();
    let stem = last.trim_end_matches(".rs").to_string();
    let krate = if parts.first().map(String::as_str) == Some("cli")
        || (parts.is_empty() && stem == "main")
    {
        Krate::Bin
    } else {
        Krate::Lib
    };
    if !(stem == "mod" || (parts.is_empty() && (stem == "lib" || stem == "main"))) {
        parts.push(stem);
    }
    (krate, parts)
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// One crate-internal import: which module uses which, and where.
#[derive(Clone, Debug)]
struct Edge {
    from: Module,
    to: Module,
    file: String,
    line: usize,
    path: String,
}

struct Resolver {
    modules: BTreeSet<Module>,
    /// Per module, the names it re-exports (`pub use`) and the module that defines each.
    reexports: BTreeMap<Module, BTreeMap<String, Module>>,
    /// Per scope (a file's module or an inline module in it), the names `use` binds to modules.
    bindings: BTreeMap<Module, BTreeMap<String, Module>>,
}

impl Resolver {
    /// The module a path names or takes an item from, if it is crate-internal.
    fn resolve(&self, krate: Krate, scope: &[String], segs: &[String]) -> Option<Module> {
        let first = segs.first()?.as_str();
        let mut rest = &segs[1..];
        let mut base: Module = match first {
            "crate" => (krate, vec![]),
            "scene_complexity" => (Krate::Lib, vec![]),
            "self" => (krate, scope.to_vec()),
            "super" => {
                let mut p = scope.to_vec();
                p.pop()?;
                while rest.first().map(String::as_str) == Some("super") {
                    p.pop()?;
                    rest = &rest[1..];
                }
                (krate, p)
            }
            name => {
                let scope_mod = (krate, scope.to_vec());
                let child = (krate, [scope, &[name.to_string()]].concat());
                if self.modules.contains(&child) {
                    child
                } else {
                    self.bindings.get(&scope_mod)?.get(name)?.clone()
                }
            }
        };
        for seg in rest {
            let child = (
                base.0,
                [base.1.as_slice(), std::slice::from_ref(seg)].concat(),
            );
            if self.modules.contains(&child) {
                base = child;
            } else {
                if let Some(target) = self.reexports.get(&base).and_then(|r| r.get(seg)) {
                    base = target.clone();
                }
                break;
            }
        }
        Some(base)
    }
}

/// Every crate-internal import under `src/`.
fn edges(src_dir: &Path) -> (Vec<Edge>, BTreeSet<Module>) {
    let mut files = Vec::new();
    rust_files(src_dir, &mut files);
    let parsed: Vec<(String, Module, Vec<PathUse>)> = files
        .iter()
        .map(|f| {
            let rel = f.strip_prefix(src_dir).unwrap();
            let module = module_of_file(rel);
            let text = std::fs::read_to_string(f).unwrap();
            let paths = paths_in(&text, &module.1);
            (format!("src/{}", rel.display()), module, paths)
        })
        .collect();
    let mut r = Resolver {
        modules: parsed.iter().map(|p| p.1.clone()).collect(),
        reexports: BTreeMap::new(),
        bindings: BTreeMap::new(),
    };
    // Two passes, so that a name bound or re-exported through another binding also resolves.
    for _ in 0..2 {
        for (_, module, paths) in &parsed {
            for p in paths.iter().filter(|p| p.is_use) {
                let (Some(name), Some(target)) =
                    (&p.binds, r.resolve(module.0, &p.scope, &p.segments))
                else {
                    continue;
                };
                let scope = (module.0, p.scope.clone());
                r.bindings
                    .entry(scope.clone())
                    .or_default()
                    .insert(name.clone(), target.clone());
                if p.is_pub_use {
                    r.reexports
                        .entry(scope)
                        .or_default()
                        .insert(name.clone(), target);
                }
            }
        }
    }
    let mut out = Vec::new();
    for (file, module, paths) in &parsed {
        for p in paths {
            if let Some(to) = r.resolve(module.0, &p.scope, &p.segments) {
                if &to != module {
                    out.push(Edge {
                        from: module.clone(),
                        to,
                        file: file.clone(),
                        line: p.line,
                        path: p.segments.join("::"),
                    });
                }
            }
        }
    }
    (out, r.modules)
}

/// Whether `a` is a proper ancestor of `b` in the same crate (`sample` of `sample::tally`).
fn is_ancestor(a: &Module, b: &Module) -> bool {
    a.0 == b.0 && a.1.len() < b.1.len() && b.1.starts_with(&a.1)
}

/// The layer problems: modules without a layer, imports from a layer above.
fn upward_imports(edges: &[Edge], modules: &BTreeSet<Module>) -> Vec<String> {
    let mut problems = Vec::new();
    for m in modules {
        if layer_of(m).is_none() && !(m.0 == Krate::Lib && m.1.is_empty()) {
            problems.push(format!(
                "{} is in no layer: give its top-level module a place in LAYERS",
                module_name(m)
            ));
        }
    }
    let mut seen = BTreeSet::new();
    for e in edges {
        let (Some(from), Some(to)) = (layer_of(&e.from), layer_of(&e.to)) else {
            continue;
        };
        if to > from && seen.insert((e.from.clone(), e.to.clone())) {
            problems.push(format!(
                "{} (layer {}) imports {} (layer {}): {}:{} `{}`",
                module_name(&e.from),
                LAYERS[from].0,
                module_name(&e.to),
                LAYERS[to].0,
                e.file,
                e.line,
                e.path
            ));
        }
    }
    problems
}

/// The cycles between modules of one layer, each as the sorted names of a strongly connected component.
fn cycles_within_layers(edges: &[Edge]) -> Vec<Vec<String>> {
    let mut graph: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for e in edges {
        let same_layer = layer_of(&e.from).is_some() && layer_of(&e.from) == layer_of(&e.to);
        if same_layer && e.from != e.to && !is_ancestor(&e.from, &e.to) {
            graph
                .entry(e.from.clone())
                .or_default()
                .insert(e.to.clone());
            graph.entry(e.to.clone()).or_default();
        }
    }
    let nodes: Vec<Module> = graph.keys().cloned().collect();
    let reach = |start: &Module| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![start.clone()];
        while let Some(n) = stack.pop() {
            for m in &graph[&n] {
                if seen.insert(m.clone()) {
                    stack.push(m.clone());
                }
            }
        }
        seen
    };
    let reachable: BTreeMap<Module, BTreeSet<Module>> =
        nodes.iter().map(|n| (n.clone(), reach(n))).collect();
    let mut cycles = BTreeSet::new();
    for n in &nodes {
        if !reachable[n].contains(n) {
            continue;
        }
        let component: Vec<String> = nodes
            .iter()
            .filter(|m| reachable[n].contains(*m) && reachable[*m].contains(n))
            .map(module_name)
            .collect();
        cycles.insert(component);
    }
    cycles.into_iter().collect()
}

#[test]
fn layers_import_only_downwards_and_without_cycles() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let (edges, modules) = edges(&src);
    let mut problems = upward_imports(&edges, &modules);
    for cycle in cycles_within_layers(&edges) {
        problems.push(format!("cycle within a layer: {}", cycle.join(" <-> ")));
    }
    assert!(
        problems.is_empty(),
        "the layers (lowest first: {}) must import only downwards, without cycles inside a layer:\n  {}",
        LAYERS.iter().map(|l| l.0).collect::<Vec<_>>().join(" <- "),
        problems.join("\n  ")
    );
}

/// The parser on a small sample: `use` trees, paths in code, `super` in inline modules, and comments,
/// strings and characters that must not count.
#[test]
fn the_import_parser_reads_use_trees_and_paths_but_not_comments_or_strings() {
    let text = r##"
        //! See [`crate::cli::Nothing`] and crate::run::nothing.
        use crate::{scene::{self, Scene}, trace::Tracer as T};
        use super::lines::*;
        /* crate::measure::x /* nested */ crate::run::y */
        fn f() -> char {
            let _ = "crate::run::z";
            let _ = r#"crate::run::w"#;
            let _ = crate::geom::unit(1.0);
            let _: &'static str = "";
            '"'
        }
        mod tests {
            use super::*;
        }
    "##;
    let got: Vec<(String, Vec<String>)> = paths_in(text, &["sample".into(), "tally".into()])
        .into_iter()
        .map(|p| (p.segments.join("::"), p.scope))
        .collect();
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    assert_eq!(
        got,
        vec![
            ("crate::scene".to_string(), s(&["sample", "tally"])),
            ("crate::scene::Scene".to_string(), s(&["sample", "tally"])),
            ("crate::trace::Tracer".to_string(), s(&["sample", "tally"])),
            ("super::lines".to_string(), s(&["sample", "tally"])),
            ("crate::geom::unit".to_string(), s(&["sample", "tally"])),
            ("super".to_string(), s(&["sample", "tally", "tests"])),
        ]
    );
}
