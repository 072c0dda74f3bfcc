//! Build script: with the `embree` feature, find Intel Embree (4, else 3), generate its
//! bindings with bindgen from the installed header into `OUT_DIR`, and tell rustc which
//! API it got (`cfg(embree4)` or `cfg(embree3)`). Without the feature it does nothing.
//!
//! Search order:
//! 1. `EMBREE_DIR` (`include/` and `lib/` under it), `EMBREE_INCLUDE_DIR`, `EMBREE_LIB_DIR`;
//! 2. pkg-config `embree4`, then `embree3` (through the `pkg-config` crate, which runs
//!    the `pkg-config` program when it is installed and honours `PKG_CONFIG_PATH`);
//! 3. the compiler's default include directories, for `embree4/rtcore.h` then
//!    `embree3/rtcore.h`.
//!
//! Whichever route found it, a library directory the dynamic loader does not search by
//! default (anything but `/lib`, `/usr/lib` and their `lib64` and multiarch
//! subdirectories) is also written into the binaries' run path, so that they start
//! without `LD_LIBRARY_PATH`.

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    // The cfgs the Embree backend is compiled under; declared even when the feature is off
    // so that `check-cfg` knows them in every configuration.
    println!("cargo::rustc-check-cfg=cfg(embree3)");
    println!("cargo::rustc-check-cfg=cfg(embree4)");
    println!("cargo::rustc-check-cfg=cfg(embree_instance_array)");

    #[cfg(feature = "embree")]
    embree::run();
}

#[cfg(feature = "embree")]
mod embree {
    use std::env;
    use std::fmt::Write as _;
    use std::path::{Path, PathBuf};

    /// Environment variables that steer the search.
    const ENV_VARS: [&str; 3] = ["EMBREE_DIR", "EMBREE_INCLUDE_DIR", "EMBREE_LIB_DIR"];

    /// Embree's two API generations. The header directory and the library name follow it.
    #[derive(Clone, Copy, PartialEq, Eq, Debug)]
    enum Api {
        Embree4,
        Embree3,
    }

    impl Api {
        const NEWEST_FIRST: [Api; 2] = [Api::Embree4, Api::Embree3];

        /// Directory under the include dir, library name, cfg name.
        fn name(self) -> &'static str {
            match self {
                Api::Embree4 => "embree4",
                Api::Embree3 => "embree3",
            }
        }
    }

    /// What was found.
    struct Found {
        api: Api,
        /// Directory that holds `embreeN/rtcore.h`.
        include_dir: PathBuf,
        /// Where the library is, when known (system locations need none).
        lib_dir: Option<PathBuf>,
        /// How it was found, for messages.
        how: String,
    }

    pub fn run() {
        for var in ENV_VARS {
            println!("cargo::rerun-if-env-changed={var}");
        }
        for var in [
            "PKG_CONFIG",
            "PKG_CONFIG_PATH",
            "PKG_CONFIG_LIBDIR",
            "PKG_CONFIG_SYSROOT_DIR",
            "LIBCLANG_PATH",
            "BINDGEN_EXTRA_CLANG_ARGS",
        ] {
            println!("cargo::rerun-if-env-changed={var}");
        }

        let mut searched = Vec::new();
        let found = find(&mut searched).unwrap_or_else(|| fail_not_found(&searched));
        let header = found.include_dir.join(found.api.name()).join("rtcore.h");
        println!(
            "cargo::rerun-if-changed={}",
            found.include_dir.join(found.api.name()).display()
        );

        println!("cargo::rustc-cfg={}", found.api.name());
        println!("cargo::rustc-link-lib={}", found.api.name());
        if let Some(lib) = &found.lib_dir {
            println!("cargo::rustc-link-search=native={}", lib.display());
            let unix = env::var("CARGO_CFG_TARGET_FAMILY").is_ok_and(|f| f == "unix");
            if unix && !is_loader_default(lib) {
                println!("cargo::rustc-link-arg=-Wl,-rpath,{}", lib.display());
                // For the binaries of the packages that depend on this one (the
                // `emray` command): `DEP_EMBREE_RPATH` in their build scripts.
                println!("cargo::metadata=rpath={}", lib.display());
            }
        }
        let version = header_version(&found.include_dir.join(found.api.name()));
        println!(
            "cargo::rustc-env=EMRAY_EMBREE_HEADER_VERSION={}",
            version.as_deref().unwrap_or("unknown")
        );

        let bindings = generate(&header, &found);
        // Embree 4.3+ built with instance arrays adds `instPrimID` to the hit and the
        // ray-query context; the backend initialises it when present.
        if bindings.contains("instPrimID") {
            println!("cargo::rustc-cfg=embree_instance_array");
        }
        let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"))
            .join("embree_bindings.rs");
        if let Err(e) = std::fs::write(&out, bindings) {
            fail(&format!("cannot write {}: {e}", out.display()));
        }
    }

    /// The header in `include_dir`, newest API first.
    fn header_in(include_dir: &Path) -> Option<Api> {
        Api::NEWEST_FIRST
            .into_iter()
            .find(|api| include_dir.join(api.name()).join("rtcore.h").is_file())
    }

    fn env_path(var: &str) -> Option<PathBuf> {
        env::var_os(var)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    }

    fn find(searched: &mut Vec<String>) -> Option<Found> {
        // 1. Explicit locations. A location given by the user that holds no Embree is an
        //    error, not something to fall back from silently.
        let dir = env_path("EMBREE_DIR");
        let include =
            env_path("EMBREE_INCLUDE_DIR").or_else(|| dir.as_ref().map(|d| d.join("include")));
        let lib = env_path("EMBREE_LIB_DIR").or_else(|| {
            dir.as_ref().and_then(|d| {
                ["lib", "lib64"]
                    .iter()
                    .map(|l| d.join(l))
                    .find(|l| l.is_dir())
            })
        });
        if let Some(include) = include {
            let Some(api) = header_in(&include) else {
                fail(&format!(
                    "{} = {} holds neither embree4/rtcore.h nor embree3/rtcore.h.\n\
                     Point it at the directory that contains the embree4/ or embree3/ header folder.",
                    if env_path("EMBREE_INCLUDE_DIR").is_some() {
                        "EMBREE_INCLUDE_DIR"
                    } else {
                        "EMBREE_DIR/include (from EMBREE_DIR)"
                    },
                    include.display()
                ));
            };
            return Some(Found {
                api,
                include_dir: include,
                lib_dir: lib,
                how: "EMBREE_DIR / EMBREE_INCLUDE_DIR".into(),
            });
        }

        // 2. pkg-config. It leaves out -I for system directories, so also look in the
        //    default ones for the header of the version pkg-config reported.
        for api in Api::NEWEST_FIRST {
            searched.push(format!("pkg-config {}", api.name()));
            if let Some((includes, libs)) = pkg_config(api.name()) {
                let dirs = includes.into_iter().chain(default_include_dirs());
                for dir in dirs {
                    if dir.join(api.name()).join("rtcore.h").is_file() {
                        return Some(Found {
                            api,
                            include_dir: dir,
                            lib_dir: lib.clone().or_else(|| libs.into_iter().next()),
                            how: format!("pkg-config {}", api.name()),
                        });
                    }
                }
            }
        }

        // 3. The compiler's default include directories.
        for api in Api::NEWEST_FIRST {
            for dir in default_include_dirs() {
                searched.push(format!("{}/{}/rtcore.h", dir.display(), api.name()));
                if dir.join(api.name()).join("rtcore.h").is_file() {
                    let lib_dir = lib.clone().or_else(|| sibling_lib_dir(&dir, api));
                    return Some(Found {
                        api,
                        include_dir: dir,
                        lib_dir,
                        how: "default include path".into(),
                    });
                }
            }
        }
        None
    }

    /// Include and library directories pkg-config gives for `name`, or `None` when it
    /// does not know `name` (or is not installed). The link lines are written by
    /// [`run`], the same way for every route.
    fn pkg_config(name: &str) -> Option<(Vec<PathBuf>, Vec<PathBuf>)> {
        let lib = pkg_config::Config::new()
            .cargo_metadata(false)
            .env_metadata(false)
            .probe(name)
            .ok()?;
        Some((lib.include_paths, lib.link_paths))
    }

    /// Whether the dynamic loader searches `dir` without being told: the system library
    /// directories (glibc's built-in list, with Debian's multiarch ones).
    fn is_loader_default(dir: &Path) -> bool {
        let mut defaults = vec![
            PathBuf::from("/lib"),
            PathBuf::from("/lib64"),
            PathBuf::from("/usr/lib"),
            PathBuf::from("/usr/lib64"),
        ];
        if let Some(triple) = multiarch() {
            defaults.push(PathBuf::from(format!("/lib/{triple}")));
            defaults.push(PathBuf::from(format!("/usr/lib/{triple}")));
        }
        let dir = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
        defaults
            .iter()
            .any(|d| d.canonicalize().is_ok_and(|d| d == dir) || *d == dir)
    }

    /// The usual compiler include directories, including the Debian multiarch one.
    fn default_include_dirs() -> Vec<PathBuf> {
        let mut dirs = vec![
            PathBuf::from("/usr/local/include"),
            PathBuf::from("/usr/include"),
        ];
        if let Some(triple) = multiarch() {
            dirs.insert(1, PathBuf::from(format!("/usr/local/include/{triple}")));
            dirs.push(PathBuf::from(format!("/usr/include/{triple}")));
        }
        dirs.push(PathBuf::from("/opt/homebrew/include"));
        dirs
    }

    /// Debian's multiarch triple for the target (`x86_64-linux-gnu`), if it has one.
    fn multiarch() -> Option<String> {
        let arch = env::var("CARGO_CFG_TARGET_ARCH").ok()?;
        let os = env::var("CARGO_CFG_TARGET_OS").ok()?;
        let env_ = env::var("CARGO_CFG_TARGET_ENV").unwrap_or_default();
        if os != "linux" {
            return None;
        }
        let arch = match arch.as_str() {
            "x86" => "i386",
            "arm" => "arm",
            other => other,
        };
        let abi = if env_.is_empty() {
            "gnu".to_string()
        } else {
            env_
        };
        Some(format!("{arch}-linux-{abi}"))
    }

    /// For a header under `<prefix>/include`, the `<prefix>/lib*` directory that holds the
    /// library, when it is not a directory the linker searches anyway.
    fn sibling_lib_dir(include_dir: &Path, api: Api) -> Option<PathBuf> {
        let prefix = include_dir.parent()?;
        if prefix == Path::new("/usr") {
            return None;
        }
        let mut candidates = vec![prefix.join("lib"), prefix.join("lib64")];
        if let Some(triple) = multiarch() {
            candidates.insert(1, prefix.join("lib").join(triple));
        }
        candidates.into_iter().find(|dir| {
            std::fs::read_dir(dir).is_ok_and(|entries| {
                entries.flatten().any(|e| {
                    e.file_name()
                        .to_string_lossy()
                        .starts_with(&format!("lib{}.", api.name()))
                })
            })
        })
    }

    /// `RTC_VERSION_STRING` from `rtcore_config.h`.
    fn header_version(header_dir: &Path) -> Option<String> {
        let text = std::fs::read_to_string(header_dir.join("rtcore_config.h")).ok()?;
        text.lines().find_map(|line| {
            let rest = line.trim().strip_prefix("#define RTC_VERSION_STRING")?;
            Some(rest.trim().trim_matches('"').to_string())
        })
    }

    /// Run bindgen over the installed header. A missing libclang or a header that does not
    /// parse ends the build with one message, not bindgen's panic and backtrace.
    fn generate(header: &Path, found: &Found) -> String {
        let builder = bindgen::Builder::default()
            .header(header.to_string_lossy())
            .clang_arg(format!("-I{}", found.include_dir.display()))
            .rust_target(bindgen::RustTarget::stable(85, 0).expect("1.85 is a stable Rust"))
            // Edition 2024: `unsafe extern "C"` blocks.
            .rust_edition(bindgen::RustEdition::Edition2024)
            .allowlist_function("rtc.*")
            .allowlist_type("RTC.*")
            .allowlist_var("RTC.*")
            // C enums arrive as newtypes over their integer: any value Embree hands back
            // is valid, unlike a Rust enum (where an unknown value is undefined behaviour).
            .default_enum_style(bindgen::EnumVariation::NewType {
                is_bitfield: false,
                is_global: false,
            })
            .bitfield_enum("RTC.*Flags")
            .derive_default(true)
            .derive_debug(true)
            .generate_comments(false)
            .layout_tests(true)
            .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()));

        // bindgen panics when it cannot load libclang; keep its message but not the panic
        // report, and say what to install.
        let previous_hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(|_| {}));
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| builder.generate()));
        std::panic::set_hook(previous_hook);

        match result {
            Ok(Ok(bindings)) => bindings.to_string(),
            Ok(Err(e)) => fail(&format!(
                "bindgen could not process {} (found via {}): {e}\n\
                 If libclang is missing or broken: apt-get install libclang-dev \
                 (or set LIBCLANG_PATH to the directory holding libclang.so).",
                header.display(),
                found.how
            )),
            Err(payload) => {
                let detail = payload
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| payload.downcast_ref::<&str>().copied())
                    .unwrap_or("bindgen panicked");
                fail(&format!(
                    "bindgen needs libclang to read the Embree header {} and could not use it.\n\
                     Install it:   apt-get install libclang-dev\n\
                     (or set LIBCLANG_PATH to the directory holding libclang.so), or build the \
                     pure-Rust backend only:   cargo build --no-default-features\n\
                     bindgen said: {detail}",
                    header.display()
                ))
            }
        }
    }

    fn fail_not_found(searched: &[String]) -> ! {
        let mut msg = String::from(
            "Intel Embree was not found (needed by the default `embree` feature).\n\nSearched:\n",
        );
        for var in ENV_VARS {
            match env::var_os(var) {
                Some(v) => {
                    let _ = writeln!(msg, "  ${var} = {}", PathBuf::from(v).display());
                }
                None => {
                    let _ = writeln!(msg, "  ${var}: not set");
                }
            }
        }
        for s in searched {
            let _ = writeln!(msg, "  {s}");
        }
        msg.push_str(
            "\nFix one of:\n\
             \x20 - install it (Debian/Ubuntu):   apt-get install libembree-dev libclang-dev\n\
             \x20 - point the build at an install: EMBREE_DIR=<prefix> (with include/ and lib/), or\n\
             \x20   EMBREE_INCLUDE_DIR=<dir holding embree4/ or embree3/> and EMBREE_LIB_DIR=<dir>\n\
             \x20 - build only the pure-Rust BVH backend:   cargo build --no-default-features",
        );
        fail(&msg)
    }

    /// Stop the build with one message.
    fn fail(msg: &str) -> ! {
        eprintln!("\nerror: emray build: {msg}\n");
        std::process::exit(1)
    }
}
