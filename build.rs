//! Build script. With the `embree` feature: finds Embree 4 or 3, compiles the C shim in `ffi/`, generates
//! its bindings from the installed Embree headers, links Embree and sets `cfg(embree_v3)` or
//! `cfg(embree_v4)`. Without the feature it does nothing, so such builds need neither Embree nor libclang.

fn main() {
    // Declared in every build so that `cfg(embree_v3)` / `cfg(embree_v4)` never warn as unknown.
    println!("cargo::rustc-check-cfg=cfg(embree_v3)");
    println!("cargo::rustc-check-cfg=cfg(embree_v4)");
    println!("cargo:rerun-if-changed=build.rs");
    #[cfg(feature = "embree")]
    if std::env::var_os("CARGO_FEATURE_EMBREE").is_some() {
        embree::build();
    }
}

#[cfg(feature = "embree")]
mod embree {
    use std::env;
    use std::panic;
    use std::path::{Path, PathBuf};

    const SHIM_HEADER: &str = "ffi/scx_embree.h";
    const SHIM_SOURCE: &str = "ffi/scx_embree.c";
    const REMEDY: &str =
        "install it with 'apt-get install libembree-dev libclang-dev', set EMBREE_DIR, \
                          or build with --no-default-features";

    /// The Embree installation the build uses.
    struct Embree {
        /// 3 or 4.
        major: u32,
        /// The directory holding `embree{major}/rtcore.h`.
        include: PathBuf,
        /// The library, when found in the prefix.
        library: Option<Library>,
        /// Where the library was looked for (for the warning when it was not found).
        looked_in: Vec<PathBuf>,
    }

    /// A library file found under a prefix.
    struct Library {
        dir: PathBuf,
        /// `Some(file name)` when the linker cannot find it as `-lembree{major}`: a versioned name without
        /// the development symlink (`libembree3.so.3`) or a Python wheel's suffixed one
        /// (`libembree4-4aef3270.so.4`). It is then linked by its exact name.
        verbatim: Option<String>,
    }

    pub fn build() {
        println!("cargo:rerun-if-env-changed=EMBREE_DIR");
        println!("cargo:rerun-if-changed={SHIM_HEADER}");
        println!("cargo:rerun-if-changed={SHIM_SOURCE}");
        let embree = find_embree().unwrap_or_else(|message| stop(&message));
        compile_shim(&embree);
        generate_bindings(&embree).unwrap_or_else(|message| stop(&message));
        link(&embree);
        println!("cargo:rustc-cfg=embree_v{}", embree.major);
    }

    /// Ends the build with one line that says what to do (a panic would bury it in a backtrace).
    fn stop(message: &str) -> ! {
        eprintln!("error: {message}");
        std::process::exit(1);
    }

    /// Installation prefixes in order of preference: an explicit `EMBREE_DIR` first, then a local install,
    /// then the distribution's.
    fn prefixes() -> Vec<PathBuf> {
        let mut prefixes = Vec::new();
        if let Some(dir) = env::var_os("EMBREE_DIR").filter(|d| !d.is_empty()) {
            prefixes.push(PathBuf::from(dir));
        }
        prefixes.push("/usr/local".into());
        prefixes.push("/usr".into());
        prefixes
    }

    /// The first prefix with Embree 4 or Embree 3 headers (4 preferred within a prefix).
    fn find_embree() -> Result<Embree, String> {
        let prefixes = prefixes();
        for prefix in &prefixes {
            let include = prefix.join("include");
            for major in [4, 3] {
                if include.join(format!("embree{major}/rtcore.h")).is_file() {
                    let looked_in = lib_dirs(prefix);
                    let library = find_library(&looked_in, major);
                    return Ok(Embree {
                        major,
                        include,
                        library,
                        looked_in,
                    });
                }
            }
        }
        let looked: Vec<String> = prefixes
            .iter()
            .map(|p| p.join("include").display().to_string())
            .collect();
        Err(format!(
            "Embree not found (looked for embree4/rtcore.h and embree3/rtcore.h under {}): {REMEDY}",
            looked.join(", ")
        ))
    }

    /// The directories of a prefix that may hold the library.
    fn lib_dirs(prefix: &Path) -> Vec<PathBuf> {
        let mut dirs = vec![prefix.join("lib"), prefix.join("lib64")];
        if let Some(multiarch) = multiarch() {
            dirs.push(prefix.join("lib").join(multiarch));
        }
        dirs
    }

    /// `libembree{major}` in the first of `dirs` that holds it, by preference: the name `-lembree{major}`
    /// finds (`libembree4.so`, `libembree4.dylib`, `embree4.lib`), then a versioned one
    /// (`libembree4.so.4`), then a wheel's suffixed one (`libembree4-<hash>.so.4`); within a kind, the
    /// first in name order, so the choice does not depend on the directory's listing order.
    fn find_library(dirs: &[PathBuf], major: u32) -> Option<Library> {
        let plain = [
            format!("libembree{major}.so"),
            format!("libembree{major}.dylib"),
            format!("embree{major}.lib"),
        ];
        let versioned = format!("libembree{major}.so.");
        let versioned_mac = format!("libembree{major}.");
        let suffixed = format!("libembree{major}-");
        let rank = |name: &str| -> Option<u8> {
            if plain.iter().any(|p| p == name) {
                Some(0)
            } else if name.starts_with(&versioned)
                || (name.starts_with(&versioned_mac) && name.ends_with(".dylib"))
            {
                Some(1)
            } else if name.starts_with(&suffixed)
                && (name.contains(".so") || name.ends_with(".dylib"))
            {
                Some(2)
            } else {
                None
            }
        };
        dirs.iter().find_map(|dir| {
            let mut names: Vec<(u8, String)> = dir
                .read_dir()
                .ok()?
                .flatten()
                .filter_map(|e| {
                    let name = e.file_name().into_string().ok()?;
                    Some((rank(&name)?, name))
                })
                .collect();
            names.sort();
            let (rank, name) = names.into_iter().next()?;
            Some(Library {
                dir: dir.clone(),
                verbatim: (rank > 0).then_some(name),
            })
        })
    }

    /// Debian's multiarch directory name for the target (`x86_64-linux-gnu`).
    fn multiarch() -> Option<String> {
        let arch = env::var("CARGO_CFG_TARGET_ARCH").ok()?;
        let os = env::var("CARGO_CFG_TARGET_OS").ok()?;
        let target_env = env::var("CARGO_CFG_TARGET_ENV").unwrap_or_default();
        (os == "linux").then(|| format!("{arch}-linux-{target_env}"))
    }

    fn compile_shim(embree: &Embree) {
        cc::Build::new()
            .file(SHIM_SOURCE)
            .include("ffi")
            .include(&embree.include)
            .define("SCX_EMBREE_MAJOR", embree.major.to_string().as_str())
            .flag_if_supported("-std=c11")
            // The watertight test needs each product rounded on its own: no fused multiply-adds.
            .flag_if_supported("-ffp-contract=off")
            .warnings(true)
            .extra_warnings(true)
            .compile("scx_embree");
    }

    /// Runs bindgen over the shim's header against the installed Embree headers.
    fn generate_bindings(embree: &Embree) -> Result<(), String> {
        let builder = bindgen::Builder::default()
            .header(SHIM_HEADER)
            .clang_arg(format!("-I{}", embree.include.display()))
            .clang_arg(format!("-DSCX_EMBREE_MAJOR={}", embree.major))
            .allowlist_function("scx_.*")
            .allowlist_type("scx_.*")
            .allowlist_type("RTCRay|RTCHit|RTCRayHit|RTCRayHit4|RTCRayHit8|RTCRayHit16")
            .allowlist_type("RTCIntersectContext|RTCRayQueryContext|RTCIntersectArguments")
            .allowlist_type("RTCError")
            .allowlist_var(
                "RTC_VERSION|RTC_VERSION_MAJOR|RTC_VERSION_MINOR|RTC_VERSION_PATCH|SCX_.*",
            )
            .default_macro_constant_type(bindgen::MacroTypeVariation::Signed)
            .derive_default(true)
            .prepend_enum_name(false)
            .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()));
        let bindings = run_bindgen(builder)?;
        let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"))
            .join("embree_bindings.rs");
        bindings
            .write_to_file(&out)
            .map_err(|e| format!("cannot write {}: {e}", out.display()))
    }

    /// Generates bindings, turning bindgen's panic on a missing libclang into one line.
    fn run_bindgen(builder: bindgen::Builder) -> Result<bindgen::Bindings, String> {
        let default_hook = panic::take_hook();
        panic::set_hook(Box::new(|_| {}));
        let result = panic::catch_unwind(panic::AssertUnwindSafe(|| builder.generate()));
        panic::set_hook(default_hook);
        match result {
            Ok(Ok(bindings)) => Ok(bindings),
            Ok(Err(e)) => Err(format!("bindgen failed on {SHIM_HEADER}: {e}")),
            Err(payload) => {
                let message = payload
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| payload.downcast_ref::<&str>().copied())
                    .unwrap_or("unknown panic");
                let first_line = message.lines().next().unwrap_or(message);
                if message.contains("libclang") {
                    Err(format!(
                        "libclang not found, bindgen needs it to read the Embree headers ({first_line}): \
                         install it with 'apt-get install libclang-dev', set LIBCLANG_PATH, \
                         or build with --no-default-features"
                    ))
                } else {
                    Err(format!("bindgen failed on {SHIM_HEADER}: {first_line}"))
                }
            }
        }
    }

    fn link(embree: &Embree) {
        let major = embree.major;
        let Some(library) = &embree.library else {
            let looked: Vec<String> = embree
                .looked_in
                .iter()
                .map(|d| d.display().to_string())
                .collect();
            println!(
                "cargo:warning=libembree{major} not found in {} (looked for libembree{major}.so, \
                 libembree{major}.so.N and libembree{major}-*.so*); leaving -lembree{major} to the linker's search path",
                looked.join(", ")
            );
            println!("cargo:rustc-link-lib=embree{major}");
            return;
        };
        let dir = &library.dir;
        println!("cargo:rustc-link-search=native={}", dir.display());
        // Outside the system directories the loader needs telling where the library is.
        let system = dir.starts_with("/usr/lib") || dir.starts_with("/lib");
        if !system && env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
            println!("cargo:rustc-link-arg=-Wl,-rpath,{}", dir.display());
        }
        match &library.verbatim {
            // `-l:NAME` for the linker: the exact file, found through the search path above. Unlike a
            // link argument, a link-lib also reaches the crates that depend on this one.
            Some(name) => println!("cargo:rustc-link-lib=dylib:+verbatim={name}"),
            None => println!("cargo:rustc-link-lib=embree{major}"),
        }
    }
}
