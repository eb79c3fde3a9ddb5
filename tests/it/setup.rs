//! `.ci/setup`'s decision: which Debian packages it finds missing, run with `--dry-run` against fake
//! roots (`SCX_SETUP_ROOT`) laid out as the packages lay out their files. Each case is a machine someone
//! has: the point is that files next to the ones the build uses (libclang-cpp beside libclang, headers
//! without a library, a font `scx` never reads) do not pass for them.

use std::path::Path;
use std::process::Command;

use tempfile::TempDir;

const EMBREE: &str = "libembree-dev";
const LIBCLANG: &str = "libclang-dev";
const FONT: &str = "fonts-dejavu-core";
const VENV: &str = "python3-venv";

/// Debian 12's libembree-dev (Embree 3) with its runtime library.
const EMBREE3_DEB: &[&str] = &[
    "usr/include/embree3/rtcore.h",
    "usr/lib/x86_64-linux-gnu/libembree3.so",
    "usr/lib/x86_64-linux-gnu/libembree3.so.3",
];
/// libclang1-14: the runtime library alone, as other packages pull it in.
const LIBCLANG1_14: &[&str] = &[
    "usr/lib/x86_64-linux-gnu/libclang-14.so.1",
    "usr/lib/llvm-14/lib/libclang.so.1",
    "usr/lib/llvm-14/lib/libclang-14.so.1",
];
/// libclang-common-14-dev: clang's own headers, which libclang needs to parse any C header.
const CLANG_HEADERS_14: &[&str] = &["usr/lib/llvm-14/lib/clang/14.0.6/include/stddef.h"];
/// libclang-14-dev's development names.
const LIBCLANG_DEV_14: &[&str] = &[
    "usr/lib/x86_64-linux-gnu/libclang-14.so",
    "usr/lib/llvm-14/lib/libclang.so",
    "usr/lib/llvm-14/lib/libclang-14.so",
];
/// llvm-14-dev's C++ library of clang (what the Rust image of this project's machines has): not the
/// library bindgen loads.
const LIBCLANG_CPP_14: &[&str] = &[
    "usr/lib/x86_64-linux-gnu/libclang-cpp.so.14",
    "usr/lib/llvm-14/lib/libclang-cpp.so.14",
    "usr/lib/llvm-14/lib/libclang-cpp.so",
];
const DEJAVU: &str = "usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
/// Debian 12's python3-venv: ensurepip (python3.11-venv) and the pip wheel it installs from
/// (python3-pip-whl).
const PYTHON_VENV_DEB: &[&str] = &[
    "usr/lib/python3.11/ensurepip/__init__.py",
    "usr/share/python-wheels/pip-23.0.1-py3-none-any.whl",
];

/// A fake root: empty files at the given paths.
struct Root(TempDir);

impl Root {
    /// A machine with Debian's Python and python3-venv (the README's install of the Python package
    /// needs them), and the files of `groups`.
    fn new(groups: &[&[&str]]) -> Root {
        let root = Root::bare(groups);
        for path in PYTHON_VENV_DEB {
            root.add(path);
        }
        root
    }

    /// A machine with the files of `groups` only.
    fn bare(groups: &[&[&str]]) -> Root {
        let root = Root(tempfile::tempdir().expect("temp dir"));
        for path in groups.iter().flat_map(|g| g.iter()) {
            root.add(path);
        }
        root
    }

    /// Debian 12 with everything installed: Embree 3, libclang 14, the font, python3-venv.
    fn debian12() -> Root {
        Root::new(&[
            EMBREE3_DEB,
            LIBCLANG1_14,
            CLANG_HEADERS_14,
            LIBCLANG_DEV_14,
            &[DEJAVU],
        ])
    }

    fn add(&self, path: &str) -> &Root {
        let file = self.0.path().join(path);
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(&file, b"").unwrap();
        self
    }

    fn remove(&self, paths: &[&str]) -> &Root {
        for path in paths {
            std::fs::remove_file(self.0.path().join(path)).unwrap();
        }
        self
    }

    /// The packages `.ci/setup --dry-run` finds missing, with the given environment (paths in it are
    /// inside the root, as the script reads them).
    fn missing(&self, env: &[(&str, &str)]) -> Vec<String> {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join(".ci/setup");
        let mut cmd = Command::new("bash");
        cmd.arg(&script).arg("--dry-run");
        cmd.env("SCX_SETUP_ROOT", self.0.path());
        for var in ["EMBREE_DIR", "LIBCLANG_PATH", "SCX_FONT"] {
            cmd.env_remove(var);
        }
        cmd.envs(env.iter().copied());
        let out = cmd.output().expect("run bash .ci/setup");
        assert!(
            out.status.success(),
            "{}: {}",
            script.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .map(str::to_string)
            .collect()
    }
}

#[test]
fn an_empty_machine_misses_all_four() {
    assert_eq!(Root::bare(&[]).missing(&[]), [EMBREE, LIBCLANG, FONT, VENV]);
}

#[test]
fn debians_python_without_venv_misses_python3_venv() {
    // Debian's python3 alone (the state of a fresh Debian 12): `python3 -m venv` fails without
    // ensurepip, and ensurepip without pip's wheel.
    let root = Root::debian12();
    root.remove(PYTHON_VENV_DEB);
    assert_eq!(root.missing(&[]), [VENV]);
    root.add(PYTHON_VENV_DEB[0]);
    assert_eq!(root.missing(&[]), [VENV], "ensurepip without the pip wheel");
    root.add(PYTHON_VENV_DEB[1]);
    assert!(root.missing(&[]).is_empty());
}

#[test]
fn a_complete_machine_misses_nothing() {
    assert!(Root::debian12().missing(&[]).is_empty());
}

#[test]
fn libclang_cpp_is_not_libclang() {
    // The machine of issue 14: llvm-14-dev (so libclang-cpp, even clang's headers), no libclang.
    let root = Root::new(&[EMBREE3_DEB, LIBCLANG_CPP_14, CLANG_HEADERS_14, &[DEJAVU]]);
    assert_eq!(root.missing(&[]), [LIBCLANG]);
}

#[test]
fn libclang_counts_by_every_name_bindgen_loads() {
    // The development names, and the runtime's versioned ones (bindgen loads those at run time too).
    for lib in [
        "usr/lib/llvm-14/lib/libclang.so",
        "usr/lib/x86_64-linux-gnu/libclang-14.so",
        "usr/lib/x86_64-linux-gnu/libclang-14.so.1",
        "usr/lib/llvm-14/lib/libclang.so.1",
    ] {
        let root = Root::new(&[EMBREE3_DEB, CLANG_HEADERS_14, &[DEJAVU, lib]]);
        assert!(root.missing(&[]).is_empty(), "{lib}");
    }
}

#[test]
fn libclang_without_clangs_headers_is_not_enough() {
    // libclang1-14 alone: it loads, but cannot parse the Embree headers (no stddef.h).
    let root = Root::new(&[EMBREE3_DEB, LIBCLANG1_14, &[DEJAVU]]);
    assert_eq!(root.missing(&[]), [LIBCLANG]);
}

#[test]
fn another_llvm_version_is_found_in_the_root_not_on_the_host() {
    // Debian 13's LLVM 19: found under the fake root whatever LLVM the machine running the test has.
    let root = Root::new(&[
        &[
            "usr/include/embree4/rtcore.h",
            "usr/lib/x86_64-linux-gnu/libembree4.so",
            "usr/lib/llvm-19/lib/libclang.so",
            "usr/lib/llvm-19/lib/clang/19/include/stddef.h",
        ],
        &[DEJAVU],
    ]);
    assert!(root.missing(&[]).is_empty());
    root.remove(&["usr/lib/llvm-19/lib/libclang.so"]);
    assert_eq!(root.missing(&[]), [LIBCLANG]);
}

#[test]
fn embree_needs_headers_and_library() {
    let headers_only = Root::debian12();
    headers_only.remove(&[
        "usr/lib/x86_64-linux-gnu/libembree3.so",
        "usr/lib/x86_64-linux-gnu/libembree3.so.3",
    ]);
    assert_eq!(headers_only.missing(&[]), [EMBREE]);

    let library_only = Root::debian12();
    library_only.remove(&["usr/include/embree3/rtcore.h"]);
    assert_eq!(library_only.missing(&[]), [EMBREE]);
}

#[test]
fn the_first_prefix_with_headers_is_the_one_that_counts() {
    // build.rs takes /usr/local's Embree 4 headers before /usr's Embree 3: without a libembree4 the
    // link would fail, whatever /usr holds.
    let root = Root::debian12();
    root.add("usr/local/include/embree4/rtcore.h");
    assert_eq!(root.missing(&[]), [EMBREE]);
    root.add("usr/local/lib/libembree4.so");
    assert!(root.missing(&[]).is_empty());
}

#[test]
fn embree_dir_with_a_wheels_suffixed_library() {
    let root = Root::new(&[
        LIBCLANG1_14,
        CLANG_HEADERS_14,
        &[DEJAVU, "opt/embree/include/embree4/rtcore.h"],
    ]);
    let env = [("EMBREE_DIR", "/opt/embree")];
    assert_eq!(root.missing(&env), [EMBREE], "headers alone");
    root.add("opt/embree/lib/libembree4-4aef3270.so.4");
    assert!(root.missing(&env).is_empty(), "with the wheel's library");
    // Without EMBREE_DIR those headers are not looked at.
    assert_eq!(root.missing(&[]), [EMBREE]);
}

#[test]
fn libclang_path_is_the_only_place_looked_at_when_set() {
    let root = Root::debian12();
    assert_eq!(
        root.missing(&[("LIBCLANG_PATH", "/opt/llvm/lib")]),
        [LIBCLANG],
        "an empty LIBCLANG_PATH directory, whatever the system has"
    );
    root.add("opt/llvm/lib/libclang.so.18");
    assert!(root
        .missing(&[("LIBCLANG_PATH", "/opt/llvm/lib")])
        .is_empty());
    assert!(root
        .missing(&[("LIBCLANG_PATH", "/opt/llvm/lib/libclang.so.18")])
        .is_empty());
}

#[test]
fn the_font_is_one_scx_reads() {
    let no_font = Root::new(&[EMBREE3_DEB, LIBCLANG1_14, CLANG_HEADERS_14]);
    assert_eq!(no_font.missing(&[]), [FONT]);
    // A DejaVu file where scx does not look is no font for it.
    no_font.add("usr/share/fonts/dejavu/DejaVuSans.ttf");
    assert_eq!(no_font.missing(&[]), [FONT]);
    assert_eq!(
        no_font.missing(&[("SCX_FONT", "/home/me/absent.ttf")]),
        [FONT]
    );
    no_font.add("home/me/label.ttf");
    assert!(no_font
        .missing(&[("SCX_FONT", "/home/me/label.ttf")])
        .is_empty());
    no_font.add("usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf");
    assert!(no_font.missing(&[]).is_empty());
}
