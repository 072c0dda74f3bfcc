//! Malformed input: truncated files, binary garbage, NaN, huge counts and sizes, deep
//! nesting, unreadable files. Every case exits with status 1, prints one line naming
//! the file, and writes no output (nor a temporary file).

mod common;
use common::emray;

const CAMERA: &str = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 8 8\n";

/// Deterministic random bytes: no text format.
fn garbage(n: usize, seed: u64) -> Vec<u8> {
    let mut rng = emray::math::Rng::new(seed);
    (0..n).map(|_| (rng.next_u32() >> 24) as u8).collect()
}

fn nested_csg(depth: usize) -> String {
    let mut s = String::from("{ type = \"sphere\", center = [0, 0, 0], radius = 1 }");
    for _ in 0..depth {
        s = format!(
            "{{ type = \"union\", children = [{s}, {{ type = \"sphere\", center = [1, 0, 0], radius = 1 }}] }}"
        );
    }
    format!(
        "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\nresolution = [8, 8]\n\
         [[objects]]\ntype = \"group\"\nchildren = [{s}]\n"
    )
}

/// A chain of `depth` defines, each an instance of the next, the last a sphere.
fn nested_defines(depth: usize) -> String {
    let mut s = nested_csg(0);
    for i in 0..depth {
        let child = if i + 1 == depth {
            "{ type = \"sphere\", center = [0, 0, 0], radius = 1 }".to_string()
        } else {
            format!("{{ type = \"instance\", of = \"d{}\" }}", i + 1)
        };
        s += &format!("[define.d{i}]\ntype = \"group\"\nchildren = [{child}]\n");
    }
    s + "[[objects]]\ntype = \"instance\"\nof = \"d0\"\n"
}

/// The corpus: (file name, contents); `None` makes a directory (unreadable as a file).
fn corpus() -> Vec<(&'static str, Option<Vec<u8>>)> {
    let t = |s: String| Some(s.into_bytes());
    vec![
        (
            "truncated.nff",
            t(format!("{CAMERA}s 0 0 0 1\np 3\n0 0 0\n1 0")),
        ),
        ("truncated-view.nff", t("v\nfrom 0 0 5\nat 0 0".into())),
        ("garbage.nff", Some(garbage(3000, 1))),
        ("garbage.obj", Some(garbage(3000, 2))),
        ("garbage.toml", Some(garbage(3000, 3))),
        ("nul.nff", Some(vec![0; 64])),
        ("nan.nff", t(format!("{CAMERA}s 0 0 NaN 1\n"))),
        ("inf.nff", t(format!("{CAMERA}s 0 0 1e39 1\n"))),
        ("nan-radius.nff", t(format!("{CAMERA}s 0 0 0 nan\n"))),
        (
            "huge-count.nff",
            t(format!("{CAMERA}p 4000000000\n0 0 0\n")),
        ),
        ("huge-res.nff", t(CAMERA.replace("8 8", "100000 100000"))),
        ("zero-res.nff", t(CAMERA.replace("8 8", "0 8"))),
        ("huge-pixels.nff", t(CAMERA.replace("8 8", "60000 60000"))),
        ("truncated.obj", t("v 0 0 0\nv 1 0".into())),
        (
            "nan.obj",
            t("v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".into()),
        ),
        (
            "huge-index.obj",
            t("v 0 0 0\nv 1 0 0\nf 1 2 4000000000\n".into()),
        ),
        ("no-faces.obj", t("v 0 0 0\n".into())),
        (
            "truncated.toml",
            t("[camera]\nfrom = [0, 0, 5]\nat = [0, 0".into()),
        ),
        (
            "nan.toml",
            t(nested_csg(0).replace("radius = 1 }]", "radius = nan }]")),
        ),
        (
            "huge-res.toml",
            t(nested_csg(0).replace("[8, 8]", "[100000, 100000]")),
        ),
        ("deep-csg.toml", t(nested_csg(300))),
        ("deep-defines.toml", t(nested_defines(3000))),
        (
            "deep-arrays.toml",
            t(format!("a = {}{}\n", "[".repeat(20000), "]".repeat(20000))),
        ),
        (
            "missing-include.toml",
            t(nested_csg(0).replace(
                "children = [",
                "children = [{ type = \"include\", file = \"nowhere.obj\" }, ",
            )),
        ),
        ("packed.nff.gz", Some(GZIP.to_vec())),
        ("utf16.toml", Some(utf16(&nested_csg(0)))),
        ("directory.nff", None),
    ]
}

/// The first bytes of a gzip file.
const GZIP: &[u8] = b"\x1F\x8B\x08\x00\x00\x00\x00\x00\x00\x03";

/// `text` as UTF-16 with its byte-order mark (little-endian, as Windows writes it).
fn utf16(text: &str) -> Vec<u8> {
    std::iter::once(0xFEFF_u16)
        .chain(text.encode_utf16())
        .flat_map(u16::to_le_bytes)
        .collect()
}

/// Compressed files (whatever their name) and UTF-16 text are refused in one line that
/// says what they are, for every format.
#[test]
fn compressed_and_utf16_inputs_say_what_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: [(&str, Vec<u8>, &str); 5] = [
        (
            "a.nff.gz",
            GZIP.to_vec(),
            "is gzip-compressed: decompress it first (gunzip a.nff.gz)",
        ),
        (
            "b.obj",
            GZIP.to_vec(),
            "is gzip-compressed: decompress it first (mv b.obj b.obj.gz && gunzip b.obj.gz)",
        ),
        ("c.toml", GZIP.to_vec(), "is gzip-compressed"),
        ("d.nff", utf16(CAMERA), "is UTF-16 text: save it as UTF-8"),
        (
            "e.toml",
            utf16(&nested_csg(0)),
            "is UTF-16 text: save it as UTF-8",
        ),
    ];
    for (name, bytes, message) in &cases {
        std::fs::write(d.join(name), bytes).unwrap();
        let o = emray(d, &["render", "-q", name, "-o", "out.png"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{name}: {err}");
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(
            err.starts_with(&format!("emray: error: {name}: the file ")) && err.contains(message),
            "{name}: {err}"
        );
    }
}

#[test]
fn every_malformed_file_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases = corpus();
    for (name, data) in &cases {
        match data {
            Some(bytes) => std::fs::write(d.join(name), bytes).unwrap(),
            None => std::fs::create_dir(d.join(name)).unwrap(),
        }
    }
    let before = std::fs::read_dir(d).unwrap().count();
    for (name, _) in &cases {
        for out in ["out.png", "out.exr"] {
            let o = emray(d, &["render", "-q", name, "-o", out]);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(1), "{name}: {err}");
            assert_eq!(err.lines().count(), 1, "{name}: {err}");
            assert!(
                err.starts_with(&format!("emray: error: {name}")),
                "{name}: {err}"
            );
            assert_eq!(
                std::fs::read_dir(d).unwrap().count(),
                before,
                "{name}: output left"
            );
        }
    }
    // The same corpus as one batch: every job fails, each reported, nothing written.
    let mut args = vec![
        "batch",
        "-q",
        "-o",
        "{stem}-{index}.png",
        "--report",
        "r.json",
    ];
    args.extend(cases.iter().map(|(n, _)| *n));
    let o = emray(d, &args);
    assert_eq!(o.status.code(), Some(1));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("r.json")).unwrap()).unwrap();
    assert_eq!(r["failed"].as_u64(), Some(cases.len() as u64));
    for (job, (name, _)) in r["jobs"].as_array().unwrap().iter().zip(&cases) {
        assert!(job["error"].as_str().unwrap().starts_with(name), "{job}");
    }
    assert!(
        !std::fs::read_dir(d).unwrap().any(|e| e
            .unwrap()
            .file_name()
            .to_string_lossy()
            .ends_with(".png"))
    );
}

/// A generated database over the memory limit is refused after being counted, before
/// any of it is generated: 48 million spheres are not built to find out.
#[test]
fn a_database_over_the_memory_limit_is_refused_before_it_is_generated() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = emray(
        d,
        &[
            "render",
            "spd:balls?size=8",
            "--max-memory",
            "1G",
            "-o",
            "o.png",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("spd:balls?size=8: rendering 512x512 with 48427563 primitives")
            && err.contains("--max-memory"),
        "{err}"
    );
    assert!(!d.join("o.png").exists());
}

#[test]
fn memory_limit_refuses_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.nff"), format!("{CAMERA}s 0 0 0 1\n")).unwrap();
    let o = emray(
        d,
        &[
            "render",
            "s.nff",
            "--res",
            "16000x16000",
            "--max-memory",
            "64M",
            "-o",
            "o.png",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("s.nff: rendering 16000x16000") && err.contains("--max-memory"),
        "{err}"
    );
    assert!(!d.join("o.png").exists());
    let o = emray(
        d,
        &[
            "batch",
            "s.nff",
            "--res",
            "16000x16000",
            "--max-memory",
            "64M",
        ],
    );
    assert_eq!(o.status.code(), Some(1));
    let o = emray(
        d,
        &["render", "s.nff", "--max-memory", "lots", "-o", "o.png"],
    );
    assert_eq!(o.status.code(), Some(2));
    let o = emray(
        d,
        &[
            "render",
            "-q",
            "s.nff",
            "--max-memory",
            "64M",
            "-o",
            "o.png",
        ],
    );
    assert!(o.status.success());
}
