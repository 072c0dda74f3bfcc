//! The `emray` command: exit codes, messages, and no output left behind on error.

use std::path::Path;
use std::process::Command;

mod common;
use common::{emray, stderr};

const SCENE: &str = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 30\nhither 1\nresolution 40 30\n\
                     b 0.1 0.2 0.3\nl 3 3 10\nf 1 0 0 1 0 0 0 1\ns 0 0 0 2\n";

#[test]
fn renders_a_scene_to_png_with_stats() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.nff"), SCENE).unwrap();
    let o = emray(
        dir.path(),
        &[
            "render",
            "a.nff",
            "-o",
            "out.png",
            "--backend",
            "bvh",
            "--stats",
            "--stats-json",
            "s.jsonl",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(dir.path().join("out.png")).unwrap();
    assert_eq!((img.width(), img.height()), (40, 30));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("Mrays/s") && out.contains("1 spheres"),
        "{out}"
    );
    let json: serde_json::Value = serde_json::from_str(
        std::fs::read_to_string(dir.path().join("s.jsonl"))
            .unwrap()
            .trim(),
    )
    .unwrap();
    for key in [
        "scene",
        "backend",
        "width",
        "height",
        "threads",
        "spp",
        "prims",
        "time_ms",
        "rays",
        "mrays_per_s",
    ] {
        assert!(json.get(key).is_some(), "missing {key}: {json}");
    }
    assert_eq!(json["prims"]["spheres"], 1);
    assert_eq!(json["rays"]["eye"], 40 * 30);
    assert_eq!(json["backend"], "bvh");
    if cfg!(target_os = "linux") {
        // At least the image's buffers: more than a megabyte, less than the machine.
        let peak = json["peak_resident_bytes"].as_u64().unwrap();
        assert!((1 << 20..1 << 40).contains(&peak), "{json}");
        assert!(out.contains("; peak resident "), "{out}");
    }
}

#[test]
fn res_and_exr_output() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.nff"), SCENE).unwrap();
    let o = emray(
        dir.path(),
        &["render", "a.nff", "-o", "x.exr", "--res", "16x8", "-q"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let meta = exr::meta::MetaData::read_from_file(dir.path().join("x.exr"), false).unwrap();
    let size = meta.headers[0].layer_size;
    assert_eq!((size.width(), size.height()), (16, 8));
}

#[test]
fn missing_file_is_an_input_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let o = emray(dir.path(), &["render", "nope.nff", "-o", "out.png"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("nope.nff") && e.contains("cannot read"), "{e}");
    assert_eq!(e.lines().count(), 1, "one line, no backtrace: {e}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn malformed_scene_reports_path_line_col() {
    let dir = tempfile::tempdir().unwrap();
    let bad = SCENE.replace("s 0 0 0 2", "s 0 0 zero 2");
    std::fs::write(dir.path().join("bad.nff"), bad).unwrap();
    let o = emray(dir.path(), &["render", "bad.nff", "-o", "out.png"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("bad.nff:11:7:"), "{e}");
    assert!(!dir.path().join("out.png").exists());
}

#[test]
fn usage_errors_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.nff"), SCENE).unwrap();
    for args in [
        vec!["render", "a.nff", "--res", "0x10"],
        vec!["render", "a.nff", "--res", "1000000x1000000"],
        vec!["render", "a.nff", "--backend", "optix"],
        vec!["render", "a.nff", "--spp", "0"],
        vec!["render", "--bogus", "a.nff"],
        vec!["render"],
        vec!["render", "a.nff", "a.nff", "-o", "one.png"],
        vec!["render", "a.nff", "-o", "out.jpg"],
        vec!["render", "a.nff", "--reference", "--spd"],
        vec!["render", "a.nff", "--bailout=-1"],
        vec!["render", "a.nff", "--tile", "0/2", "-o", "part.png"],
        vec!["render", "a.nff", "--tile", "4/4", "-o", "part.exr"],
        vec!["render", "a.nff", "--crop", "5,1,0,9", "-o", "part.exr"],
    ] {
        let o = emray(dir.path(), &args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).is_empty());
    }
    // Nothing was written by any of them.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn several_scenes_with_a_template_and_a_failure() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.nff"), SCENE).unwrap();
    std::fs::write(dir.path().join("b.nff"), "v\nfrom 0 0 1\n").unwrap();
    let o = emray(
        dir.path(),
        &["render", "a.nff", "b.nff", "-o", "{stem}-out.png", "-q"],
    );
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("b.nff:"), "{e}");
    assert!(dir.path().join("a-out.png").exists());
    assert!(!dir.path().join("b-out.png").exists());
}

#[test]
fn no_arguments_renders_the_default_scene() {
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_emray"))
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(dir.path().join("emray.png")).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (640, 480));
    // Not a flat image: many distinct colours.
    let mut colours: Vec<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    colours.sort();
    colours.dedup();
    assert!(colours.len() > 1000, "{} colours", colours.len());
}

#[test]
fn gen_writes_nff_that_renders() {
    let dir = tempfile::tempdir().unwrap();
    let o = emray(dir.path(), &["gen", "tetra", "-s", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    let scene = emray::load::nff::parse_str(&text, Path::new("tetra")).unwrap();
    assert_eq!(scene.geometry.triangles.len(), 16, "4^2 triangles");
    let o = emray(dir.path(), &["gen", "tetra", "-s", "2", "-o", "t.nff"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(dir.path().join("t.nff")).unwrap(),
        text
    );
    let o = emray(
        dir.path(),
        &["render", "spd:tetra?size=2", "--res", "32x32", "-q"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.path().join("tetra_s2.png").exists());
}

#[test]
fn gen_refuses_bad_databases_and_sizes() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        vec!["gen", "nope"],
        vec!["gen", "balls", "-s", "0"],
        vec!["gen", "balls", "-s", "1000"],
        vec!["render", "spd:balls?size=1000"],
        vec!["render", "spd:nope"],
    ] {
        let o = emray(dir.path(), &args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("emray: error:"), "{}", stderr(&o));
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn input_errors_exit_1_with_one_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.nff"), SCENE).unwrap();
    for (args, wanted) in [
        (
            vec!["render", "a.nff", "--crop", "0,50,0,10", "-o", "x.exr"],
            "emray: error: a.nff: crop 0,50,0,10 is not inside the 40x30 image",
        ),
        (
            vec!["render", "a.nff", "--band", "0/31", "-o", "x.exr"],
            "emray: error: a.nff: --band leaves no rows for this part of a 30-row image",
        ),
        (
            vec!["render", "a.nff", "--max-memory", "1K"],
            "over the memory limit of 0.0 MiB (--max-memory)",
        ),
        (
            vec!["batch", "--manifest", "missing.toml"],
            "emray: error: missing.toml: cannot read",
        ),
        (
            vec!["merge", "nope.exr", "-o", "m.png"],
            "emray: error: nope.exr: ",
        ),
        (
            vec!["radiosity", "nope.toml"],
            "emray: error: nope.toml: cannot read",
        ),
        (
            vec!["gen", "tetra", "-o", "a.nff/t.nff"],
            "emray: error: a.nff/t.nff: cannot write",
        ),
    ] {
        let o = emray(dir.path(), &args);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(wanted), "{args:?}: {e}");
        assert_eq!(
            e.lines().count(),
            1,
            "{args:?}: one line, no backtrace: {e}"
        );
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn batch_usage_errors_exit_2_before_any_job() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.nff"), SCENE).unwrap();
    for (args, wanted) in [
        (vec!["batch"], "give scene files, globs or --manifest FILE"),
        (
            vec!["batch", "nomatch*.nff"],
            "glob 'nomatch*.nff' matches no file",
        ),
        (
            vec!["batch", "a.nff", "-o", "{colour}.png"],
            "unknown placeholder '{colour}' (one of {stem}, {backend}, {index}, {spp})",
        ),
        (
            vec!["batch", "a.nff", "a.nff", "-o", "same.png"],
            "2 scenes but one output file 'same.png'",
        ),
        (vec!["batch", "spd:nope"], "unknown database 'nope'"),
    ] {
        let o = emray(dir.path(), &args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.starts_with("emray: error: ") && e.contains(wanted),
            "{args:?}: {e}"
        );
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn an_out_of_range_band_is_called_a_band_and_a_shard_a_shard() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.nff"), SCENE).unwrap();
    let o = emray(
        dir.path(),
        &["render", "a.nff", "--tile", "4/4", "-o", "x.exr"],
    );
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("band '4/4': need 0 <= I < N"), "{e}");
    assert!(!e.contains("shard"), "{e}");
    let o = emray(dir.path(), &["batch", "a.nff", "--shard", "4/4"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("shard '4/4': need 0 <= I < N"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn help_names_every_scene_format_and_counts_parts_from_zero() {
    let dir = tempfile::tempdir().unwrap();
    let help = |args: &[&str]| String::from_utf8(emray(dir.path(), args).stdout).unwrap();
    let render = help(&["render", "--help"]);
    assert!(
        render.contains("Scene files: NFF, TOML (`.toml`), OBJ (`.obj`), or `spd:NAME[?size=N]`"),
        "{render}"
    );
    assert!(
        render.contains("horizontal bands of rows (I counts from 0: 0 ≤ I < N)"),
        "{render}"
    );
    let batch = help(&["batch", "--help"]);
    assert!(
        batch.contains("Run only shard I of N (I counts from 0: 0 ≤ I < N)"),
        "{batch}"
    );
}

#[test]
fn a_missing_output_folder_is_created() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.nff"), SCENE).unwrap();
    let o = emray(
        dir.path(),
        &["render", "s.nff", "-o", "new/deeper/s.png", "-q"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.path().join("new/deeper/s.png").is_file());
}

#[test]
fn an_unwritable_output_fails_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.nff"), SCENE).unwrap();
    // A regular file where the output's folder should be: no folder can be made there.
    std::fs::write(dir.path().join("file"), "").unwrap();
    let o = emray(
        dir.path(),
        &["render", "s.nff", "-o", "file/s.png", "--stats"],
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("file/s.png: cannot write"), "{err}");
    assert!(
        !err.contains(".tmp"),
        "the message names the target, not a temporary file: {err}"
    );
    // Nothing was rendered: the statistics a render prints are absent.
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(!out.contains("rays") && !err.contains("rays"), "{out}{err}");
}

#[test]
fn two_scenes_writing_one_file_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    for d in ["a", "b"] {
        std::fs::create_dir(dir.path().join(d)).unwrap();
        std::fs::write(dir.path().join(d).join("s.nff"), SCENE).unwrap();
    }
    let o = emray(
        dir.path(),
        &["render", "a/s.nff", "b/s.nff", "-o", "out/{stem}.png"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("would both write"), "{}", stderr(&o));
    assert!(!dir.path().join("out").exists(), "nothing is written");
}

#[test]
fn a_closed_standard_output_ends_quietly() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    // The teapot's NFF is far larger than a pipe's buffer: emray is still writing
    // when the reader goes away, as with `emray gen teapot | head -1`.
    let mut child = Command::new(env!("CARGO_BIN_EXE_emray"))
        .current_dir(dir.path())
        .args(["gen", "teapot"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run emray");
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.starts_with('b') || first.starts_with('v'), "{first}");
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(stderr(&o), "", "nothing printed on a closed pipe");
}

/// The options `--help` lists under the heading `heading` (up to the next heading).
fn options_under(help: &str, heading: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut inside = false;
    for line in help.lines() {
        if !line.starts_with(' ') && line.ends_with(':') {
            inside = line == format!("{heading}:");
            continue;
        }
        let item = line.trim_start();
        if inside && item.starts_with('-') {
            let long = item.split([' ', ',', '=']).find(|w| w.starts_with("--"));
            out.extend(long.map(String::from));
        }
    }
    out
}

#[test]
fn help_lists_the_radiosity_options_alone_under_radiosity() {
    let dir = tempfile::tempdir().unwrap();
    let radiosity = [
        "--gi",
        "--patch-size",
        "--ff-samples",
        "--vis-samples",
        "--solver",
        "--form-factors",
        "--hemicube-res",
        "--subdiv-threshold",
        "--min-patch-size",
        "--subdiv-passes",
        "--epsilon",
        "--max-iterations",
    ];
    for command in ["render", "explain", "radiosity"] {
        let o = emray(dir.path(), &[command, "--help"]);
        let help = String::from_utf8(o.stdout).unwrap();
        assert_eq!(
            options_under(&help, "Radiosity"),
            radiosity,
            "emray {command} --help:\n{help}"
        );
        let headings = [
            ("Image", "--area-samples"),
            ("Output", "--aov"),
            ("Output", "--heatmap"),
        ];
        for (heading, other) in headings
            .into_iter()
            .chain([("Backend", "--embree-quality")])
        {
            let under = options_under(&help, heading);
            assert!(
                under.iter().any(|o| o == other),
                "{command}: {other} under {heading}"
            );
        }
    }
}

#[test]
fn every_command_takes_quiet_and_verbose() {
    let dir = tempfile::tempdir().unwrap();
    let commands = [
        "render",
        "gen",
        "batch",
        "merge",
        "bench",
        "compare",
        "stress",
        "study",
        "radiosity",
        "explain",
    ];
    for command in commands {
        let o = emray(dir.path(), &[command, "--help"]);
        let help = String::from_utf8(o.stdout).unwrap();
        for option in ["-q, --quiet", "-v, --verbose"] {
            assert!(help.contains(option), "emray {command} --help: {option}");
        }
    }
    // Taken, not refused as a usage error: the scene is what is missing.
    let o = emray(dir.path(), &["radiosity", "-q", "-vv", "nope.toml"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("nope.toml: cannot read"),
        "{}",
        stderr(&o)
    );
}

/// A scene with no objects renders the background, with a warning naming the file; a
/// scene with one does not warn.
#[test]
fn a_scene_without_objects_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let view = SCENE.split("b 0.1").next().unwrap();
    std::fs::write(dir.path().join("empty.nff"), format!("{view}l 3 3 10\n")).unwrap();
    std::fs::write(
        dir.path().join("empty.toml"),
        "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nresolution = [8, 8]\n\
         [[lights]]\nposition = [0, 5, 5]\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("full.nff"), SCENE).unwrap();
    for name in ["empty.nff", "empty.toml"] {
        let o = emray(dir.path(), &["render", name, "-o", "out.png"]);
        let err = stderr(&o);
        assert!(o.status.success(), "{name}: {err}");
        assert!(
            err.contains(&format!(
                "{name}: scene has no objects: the image will be the background only"
            )),
            "{name}: {err}"
        );
    }
    let o = emray(dir.path(), &["render", "full.nff", "-o", "out.png"]);
    assert!(
        o.status.success() && stderr(&o).is_empty(),
        "{}",
        stderr(&o)
    );
}

/// `command` run through `bash` on `script`'s terminal (util-linux) in `dir`; `None`,
/// with a note, where `script` is missing.
fn on_a_terminal(command: &str, dir: &std::path::Path) -> Option<std::process::Output> {
    let run = Command::new("script")
        .args(["-qec", command, "/dev/null"])
        .current_dir(dir)
        .output();
    if run.is_err() {
        eprintln!("skipped: no `script` to give the render a terminal");
    }
    run.ok()
}

/// On a terminal the progress bar names each phase before the tiles count: a long
/// load or build is never a silent wait. The terminal is `script`'s (util-linux); the
/// test is skipped where it is missing.
#[test]
fn the_progress_bar_names_the_phases_on_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.nff"), SCENE).unwrap();
    let command = format!(
        "'{}' render a.nff -o out.png --res 64x48",
        env!("CARGO_BIN_EXE_emray")
    );
    let Some(o) = on_a_terminal(&command, dir.path()) else {
        return;
    };
    assert!(o.status.success(), "{}", stderr(&o));
    let screen = String::from_utf8_lossy(&o.stdout);
    assert!(screen.contains("a.nff: loading …"), "{screen:?}");
    assert!(screen.contains("a.nff: loading 100% …"), "{screen:?}");
    assert!(dir.path().join("out.png").exists());
}

/// A load shows how far it has come, in a render's bar and a batch job's: a generated
/// database of 66 000 spheres tells its first share when 16 384 are made, long before
/// the end.
#[test]
fn the_progress_bar_shows_the_share_loaded() {
    for command in ["render", "batch"] {
        shares_loaded_on_the_bar(command);
    }
}

/// `emray COMMAND` of a generated database on a terminal shows a share below 100 %,
/// then larger ones up to 100 %.
fn shares_loaded_on_the_bar(command: &str) {
    let dir = tempfile::tempdir().unwrap();
    let command = format!(
        "'{}' {command} 'spd:balls?size=5' -o out.png --res 8x8",
        env!("CARGO_BIN_EXE_emray")
    );
    let Some(o) = on_a_terminal(&command, dir.path()) else {
        return;
    };
    assert!(o.status.success(), "{}", stderr(&o));
    let screen = String::from_utf8_lossy(&o.stdout);
    let shares: Vec<u32> = screen
        .split(": loading ")
        .skip(1)
        .filter_map(|s| s.split('%').next()?.parse().ok())
        .collect();
    assert!(shares.iter().any(|&p| p < 100), "{screen:?}");
    assert!(shares.windows(2).all(|w| w[0] <= w[1]), "{shares:?}");
    assert_eq!(shares.last(), Some(&100), "{screen:?}");
}
