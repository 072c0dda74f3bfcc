//! The library's top-level modules form a layered graph (docs/architecture.md): each
//! may import only from the modules below it. This test reads `src/` and fails on any
//! `crate::MODULE` reference (in a `use` or a path) that goes against the layers, naming
//! the file and line, so that an import cycle cannot creep back in. Unit tests (a
//! `#[cfg(test)] mod` at the end of a file, or a `tests.rs` file) are not part of the
//! graph: they may build a scene with a loader or render it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Every top-level module of the library with the modules it may import, lowest layer
/// first. Keep in step with docs/architecture.md.
const LAYERS: &[(&str, &[&str])] = &[
    ("math", &[]),
    ("geometry", &["math"]),
    ("scene", &["math", "geometry"]),
    ("spd", &["math", "geometry"]),
    ("load", &["math", "geometry", "scene"]),
    ("accel", &["math", "geometry", "scene"]),
    ("render", &["math", "geometry", "scene", "accel"]),
    (
        "radiosity",
        &["math", "geometry", "scene", "accel", "render"],
    ),
    ("output", &["math", "render"]),
    (
        "job",
        &[
            "math",
            "geometry",
            "scene",
            "spd",
            "load",
            "accel",
            "render",
            "radiosity",
            "output",
        ],
    ),
    (
        "batch",
        &[
            "math",
            "geometry",
            "scene",
            "spd",
            "load",
            "accel",
            "render",
            "radiosity",
            "output",
            "job",
        ],
    ),
    (
        "bench",
        &[
            "math", "geometry", "scene", "spd", "load", "accel", "render", "output", "job",
        ],
    ),
    (
        "accuracy",
        &[
            "math", "geometry", "scene", "spd", "load", "accel", "render", "output", "job",
        ],
    ),
];

/// The documentation of the layers: its table must list the same modules with the same
/// imports as [`LAYERS`], so that the docs cannot drift from what this test enforces.
const ARCHITECTURE: &str = "docs/architecture.md";

/// Files under `dir`, recursively, that end in `.rs`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

/// The top-level modules a line of code names as `crate::MODULE` (in paths and in
/// `use crate::{a::…, b}` groups spread over the lines that follow), comments removed.
fn crate_modules(code: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    let all: Vec<&str> = code.lines().collect();
    // Unit tests start at a `#[cfg(test)]` followed by a `mod`: stop there.
    let end = (0..all.len())
        .find(|&i| {
            all[i].trim() == "#[cfg(test)]"
                && all[i + 1..]
                    .iter()
                    .find(|l| !l.trim().is_empty())
                    .is_some_and(|l| l.trim_start().starts_with("mod "))
        })
        .unwrap_or(all.len());
    let lines = &all[..end];
    let strip = |l: &str| l.split("//").next().unwrap_or("").to_string();
    for (i, line) in lines.iter().enumerate() {
        let line = strip(line);
        let mut rest = line.as_str();
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            if let Some(group) = rest.strip_prefix('{') {
                // A use group: gather the text up to its closing brace.
                let mut text = group.to_string();
                let mut j = i;
                while text.matches('{').count() >= text.matches('}').count() {
                    j += 1;
                    match lines.get(j) {
                        Some(l) => text.push_str(&strip(l)),
                        None => break,
                    }
                }
                let mut depth = 0;
                let mut item = String::new();
                for c in text.chars() {
                    match c {
                        '{' => depth += 1,
                        '}' if depth == 0 => break,
                        '}' => depth -= 1,
                        ',' if depth == 0 => {
                            found.push((i + 1, first_segment(&item)));
                            item.clear();
                            continue;
                        }
                        _ => {}
                    }
                    item.push(c);
                }
                found.push((i + 1, first_segment(&item)));
                break;
            }
            found.push((i + 1, first_segment(rest)));
        }
    }
    found.retain(|(_, m)| !m.is_empty());
    found
}

fn first_segment(path: &str) -> String {
    path.trim()
        .chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect()
}

#[test]
fn top_level_modules_import_only_the_layers_below() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let allowed: BTreeMap<&str, &[&str]> = LAYERS.iter().copied().collect();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut violations = Vec::new();
    let mut modules_seen = std::collections::BTreeSet::new();
    for file in &files {
        let rel = file.strip_prefix(&src).expect("under src");
        let top = rel.components().next().expect("a component");
        let top = top.as_os_str().to_string_lossy();
        let module = top.trim_end_matches(".rs").to_string();
        // The binary (main.rs and its cmd/ modules) may use anything; lib.rs declares.
        if matches!(module.as_str(), "main" | "cmd" | "lib") || file.ends_with("tests.rs") {
            continue;
        }
        modules_seen.insert(module.clone());
        let Some(may) = allowed.get(module.as_str()) else {
            violations.push(format!(
                "{}: top-level module `{module}` is not in the layer table of tests/layering.rs",
                rel.display()
            ));
            continue;
        };
        let code = std::fs::read_to_string(file).expect("read a source file");
        for (line, used) in crate_modules(&code) {
            if used == module || may.contains(&used.as_str()) {
                continue;
            }
            // Re-exports at the crate root (`crate::Scene`) are not modules.
            if used.starts_with(|c: char| c.is_ascii_uppercase()) {
                violations.push(format!(
                    "src/{}:{line}: `{module}` uses a crate-root re-export `crate::{used}`; \
                     name its module instead",
                    rel.display()
                ));
                continue;
            }
            violations.push(format!(
                "src/{}:{line}: `{module}` imports `crate::{used}`, which is not below it \
                 (it may import: {})",
                rel.display(),
                if may.is_empty() {
                    "nothing".to_string()
                } else {
                    may.join(", ")
                }
            ));
        }
    }
    assert!(violations.is_empty(), "{}", violations.join("\n"));
    for (module, _) in LAYERS {
        assert!(
            modules_seen.contains(*module),
            "the layer table names `{module}`, which src/ no longer has"
        );
    }
}

#[test]
fn the_scanner_sees_paths_and_use_groups() {
    let code = "use crate::math::Vec3;\nuse crate::{\n    accel::Hit,\n    scene::{Scene, Light},\n};\n// crate::render in a comment\nlet x = crate::geometry::Kind::Sphere;\n#[cfg(test)]\n\nmod tests {\n    use crate::load::nff;\n}\n";
    let got: Vec<String> = crate_modules(code).into_iter().map(|(_, m)| m).collect();
    assert_eq!(got, ["math", "accel", "scene", "geometry"]);
}

/// The rows of the "| module | may import |" table in docs/architecture.md, as
/// (module, what it may import as written there).
fn documented_layers(doc: &str) -> Vec<(String, String)> {
    doc.lines()
        .skip_while(|l| !l.starts_with("| module | may import |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cells: Vec<&str> = l.trim_matches('|').split('|').map(str::trim).collect();
            (cells[0].trim_matches('`').to_string(), cells[1].to_string())
        })
        .collect()
}

/// Expand a documented cell ("math, geometry", "—", "all of the above but radiosity,
/// run") into the module names it stands for, given the modules documented above it.
fn expand(cell: &str, above: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for part in cell.split(", ") {
        if part == "—" {
            continue;
        } else if part == "all of the above" {
            out.extend(above.iter().cloned());
        } else if let Some(but) = part.strip_prefix("all of the above but ") {
            out.extend(above.iter().filter(|m| *m != but).cloned());
        } else {
            out.push(part.to_string());
        }
    }
    out
}

#[test]
fn the_architecture_doc_lists_the_same_layers() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(ARCHITECTURE);
    let doc = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{ARCHITECTURE}: {e}"));
    let rows = documented_layers(&doc);
    assert_eq!(
        rows.len(),
        LAYERS.len(),
        "{ARCHITECTURE}: the layer table's rows"
    );
    // "all of the above" means the modules of the rows above that are not drivers.
    let stages = ["job", "batch", "bench", "accuracy"];
    let mut above: Vec<String> = Vec::new();
    for ((module, cell), (want_module, want)) in rows.iter().zip(LAYERS) {
        assert_eq!(
            module, want_module,
            "{ARCHITECTURE}: the layer table's order"
        );
        let mut got = expand(cell, &above);
        let mut want: Vec<String> = want.iter().map(|m| m.to_string()).collect();
        got.sort();
        want.sort();
        assert_eq!(got, want, "{ARCHITECTURE}: what `{module}` may import");
        if !stages.contains(&module.as_str()) {
            above.push(module.clone());
        }
    }
}
