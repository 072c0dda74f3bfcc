//! The files every command writes, through the binary: the permissions they get, the
//! folders made for them, the check made before any work that each can be written, no
//! temporary file left by a signal, and their names from the shared templates.

use std::path::Path;
#[cfg(unix)]
use std::process::{Command, Output};

mod common;
use common::{emray, stderr};

const SCENE: &str = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 30\nhither 1\nresolution 40 30\n\
                     b 0.1 0.2 0.3\nl 3 3 10\nf 1 0 0 1 0 0 0 1\ns 0 0 0 2\n";

/// Run the `emray` binary with `args` in `dir` under the shell's `umask`.
#[cfg(unix)]
fn emray_under_umask(dir: &Path, umask: &str, args: &[&str]) -> Output {
    Command::new("sh")
        .current_dir(dir)
        .arg("-c")
        .arg(format!("umask {umask} && exec \"$@\""))
        .arg("sh")
        .arg(env!("CARGO_BIN_EXE_emray"))
        .args(args)
        .output()
        .expect("run sh")
}

/// Every file under `dir` but `except`, with its permission bits.
#[cfg(unix)]
fn modes(dir: &Path, except: &[&str]) -> Vec<(String, u32)> {
    use std::os::unix::fs::PermissionsExt;
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().into_owned();
        let meta = e.metadata().unwrap();
        if meta.is_dir() {
            for (sub, mode) in modes(&e.path(), except) {
                out.push((format!("{name}/{sub}"), mode));
            }
        } else if !except.contains(&name.as_str()) {
            out.push((name, meta.permissions().mode() & 0o777));
        }
    }
    out.sort();
    out
}

#[cfg(unix)]
#[test]
fn every_output_gets_the_mode_the_umask_gives_a_new_file() {
    let mut commands: Vec<Vec<&str>> = vec![
        vec!["render", "a.nff", "-o", "a.png"],
        vec![
            "render",
            "a.nff",
            "-o",
            "aov.exr",
            "--aov",
            "depth,id",
            "--heatmap",
            "rays",
            "heat.png",
            "--stats-json",
            "stats.jsonl",
        ],
        vec![
            "render", "a.nff", "--tile", "0/2", "--aov", "id", "-o", "p0.exr",
        ],
        vec![
            "render", "a.nff", "--tile", "1/2", "--aov", "id", "-o", "p1.exr",
        ],
        vec!["merge", "p0.exr", "p1.exr", "-o", "merged.exr"],
        vec!["gen", "tetra", "-s", "1", "-o", "t.nff"],
        vec![
            "batch",
            "a.nff",
            "-o",
            "batch/{stem}.png",
            "--report",
            "r.json",
        ],
    ];
    if cfg!(feature = "quality") {
        commands.push(vec!["compare", "a.png", "a.png", "--diff", "diff.png"]);
        commands.push(vec![
            "study",
            "a.nff",
            "--out",
            "study",
            "--res",
            "8x6",
            "--reference-strata",
            "1",
        ]);
    }
    for (umask, mode) in [("022", 0o644), ("077", 0o600)] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.nff"), SCENE).unwrap();
        for args in &commands {
            let o = emray_under_umask(d, umask, args);
            assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        }
        let found = modes(d, &["a.nff"]);
        for name in [
            "a.png",
            "aov.exr",
            "aov.exr.ids.json",
            "heat.png",
            "stats.jsonl",
            "merged.exr",
            "merged.exr.ids.json",
            "t.nff",
            "batch/a.png",
            "r.json",
        ] {
            assert!(found.iter().any(|(n, _)| n == name), "{name}: {found:?}");
        }
        let wrong: Vec<String> = found
            .iter()
            .filter(|(_, m)| *m != mode)
            .map(|(n, m)| format!("{n} {m:o}"))
            .collect();
        assert!(wrong.is_empty(), "umask {umask}: want {mode:o}: {wrong:?}");
    }
}

/// The Cornell box of `scenes/`, whose light is an emitting polygon.
fn cornell_box() -> String {
    format!("{}/scenes/cornell-box.toml", common::repo().display())
}

#[test]
fn every_command_creates_a_missing_output_folder() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.nff"), SCENE).unwrap();
    let cornell = cornell_box();
    let mut commands: Vec<Vec<&str>> = vec![
        vec!["gen", "tetra", "-s", "1", "-o", "gen/t.nff"],
        vec![
            "render",
            "a.nff",
            "-o",
            "render/a.exr",
            "--aov",
            "id",
            "--heatmap",
            "rays",
            "heat/a.png",
            "--stats-json",
            "stats/s.jsonl",
        ],
        vec!["render", "a.nff", "--tile", "0/1", "-o", "part.exr"],
        vec!["merge", "part.exr", "-o", "merge/m.png"],
        vec![
            "batch",
            "a.nff",
            "-o",
            "batch/{stem}.png",
            "--report",
            "report/r.json",
        ],
        vec![
            "radiosity",
            &cornell,
            "--patch-size",
            "300",
            "--res",
            "8x8",
            "--spp",
            "1",
            "-o",
            "rad/c.png",
            "--ply",
            "ply/c.ply",
            "--stats-json",
            "radstats/s.jsonl",
        ],
    ];
    if cfg!(feature = "quality") {
        commands.push(vec![
            "compare",
            "part.exr",
            "part.exr",
            "--diff",
            "diff/d.png",
        ]);
    }
    for args in &commands {
        let o = emray(d, args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    }
    for file in [
        "gen/t.nff",
        "render/a.exr",
        "render/a.exr.ids.json",
        "heat/a.png",
        "stats/s.jsonl",
        "merge/m.png",
        "batch/a.png",
        "report/r.json",
        "rad/c.png",
        "ply/c.ply",
        "radstats/s.jsonl",
    ] {
        assert!(d.join(file).is_file(), "{file}");
    }
    if cfg!(feature = "quality") {
        assert!(d.join("diff/d.png").is_file());
    }
}

/// The temporary files in `dir` (`.NAME.XXXXXXXX.tmp`), with their sizes.
#[cfg(unix)]
fn temporary_files(dir: &Path) -> Vec<(String, u64)> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| {
            let e = e.ok()?;
            let name = e.file_name().to_string_lossy().into_owned();
            let size = e.metadata().ok()?.len();
            name.ends_with(".tmp").then_some((name, size))
        })
        .collect()
}

#[cfg(unix)]
#[test]
fn a_signal_during_a_long_write_leaves_no_temporary_file() {
    use nix::sys::signal::{Signal, kill};
    use std::process::Stdio;
    use std::time::{Duration, Instant};
    for signal in [Signal::SIGINT, Signal::SIGTERM] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.nff"), SCENE).unwrap();
        // Every output variable of a million pixels: an EXR of some 30 MB, which takes
        // a while to compress and write.
        let mut child = Command::new(env!("CARGO_BIN_EXE_emray"))
            .current_dir(d)
            .args(["render", "a.nff", "--res", "1024x1024", "--aov", "all"])
            .args(["-o", "big.exr", "-q"])
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // The write has begun once its temporary file holds something (the check of
        // the output before the render leaves an empty one for a moment).
        let t0 = Instant::now();
        let writing = || temporary_files(d).iter().any(|(_, size)| *size > 0);
        while !writing() && t0.elapsed() < Duration::from_secs(120) {
            assert!(child.try_wait().unwrap().is_none(), "ended before writing");
            std::thread::sleep(Duration::from_millis(1));
        }
        let pid = nix::unistd::Pid::from_raw(child.id().try_into().unwrap());
        kill(pid, signal).unwrap();
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(130), "{signal}: {}", stderr(&o));
        assert_eq!(temporary_files(d), [], "{signal}");
    }
}

/// One command whose output cannot be written: its arguments, the file the message
/// names, the exit status, and files it must not have written.
struct Unwritable {
    args: Vec<String>,
    names: &'static str,
    status: i32,
    absent: &'static [&'static str],
}

fn unwritable(args: &str, names: &'static str, absent: &'static [&'static str]) -> Unwritable {
    Unwritable {
        args: args.split(' ').map(String::from).collect(),
        names,
        status: 1,
        absent,
    }
}

/// A folder for one case of [`an_unwritable_output_is_refused_before_any_work`]: the
/// scene `a.nff`, the image `ref.png`, a regular file `file` where a folder would have
/// to be, and a folder where the ids file of `taken.exr` would go.
fn unwritable_fixture(png: &[u8]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.nff"), SCENE).unwrap();
    std::fs::write(d.join("ref.png"), png).unwrap();
    std::fs::write(d.join("file"), "").unwrap();
    std::fs::create_dir(d.join("taken.exr.ids.json")).unwrap();
    dir
}

#[test]
fn an_unwritable_output_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.nff"), SCENE).unwrap();
    let o = emray(dir.path(), &["render", "a.nff", "-o", "ref.png", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let png = std::fs::read(dir.path().join("ref.png")).unwrap();
    let cornell = cornell_box();
    let bench = "bench nope.nff --reps 1 --res 8x8 --backend bvh -t 1 --no-raw --no-peer";
    let mut cases = vec![
        unwritable(
            "render a.nff -o a.png --stats --stats-json file/s.jsonl",
            "file/s.jsonl",
            &["a.png"],
        ),
        // Checked before the scene is read.
        unwritable(
            "render nope.nff -o a.png --stats-json file/s.jsonl",
            "file/s.jsonl",
            &[],
        ),
        unwritable(
            "render a.nff -o a.png --stats --heatmap rays file/h.png",
            "file/h.png",
            &["a.png"],
        ),
        unwritable("render a.nff -o file/a.exr --aov depth", "file/a.exr", &[]),
        unwritable(
            "render a.nff -o taken.exr --stats --aov id",
            "taken.exr.ids.json",
            &["taken.exr"],
        ),
        unwritable(
            "batch a.nff -o b.png --report file/r.json",
            "file/r.json",
            &["b.png"],
        ),
        unwritable(
            "batch a.nff -o file/{stem}.png --report r.json",
            "file/a.png",
            &["r.json"],
        ),
        unwritable(
            "radiosity nope.toml -o rad.png --ply file/c.ply",
            "file/c.ply",
            &[],
        ),
        unwritable(
            &format!(
                "radiosity {cornell} --patch-size 300 --res 8x8 -o rad.png --stats-json file/s.jsonl"
            ),
            "file/s.jsonl",
            &["rad.png"],
        ),
        unwritable("merge nope.exr -o file/m.png", "file/m.png", &[]),
        unwritable(&format!("{bench} --csv file/b.csv"), "file/b.csv", &[]),
        unwritable(&format!("{bench} --json file/b.json"), "file/b.json", &[]),
        unwritable("gen tetra -o file/t.nff", "file/t.nff", &[]),
    ];
    if cfg!(feature = "quality") {
        cases.push(unwritable(
            "study nope.nff --out file/st",
            "file/st/study.csv",
            &[],
        ));
        cases.push(Unwritable {
            status: 2,
            ..unwritable(
                "compare ref.png ref.png --diff file/d.png",
                "file/d.png",
                &[],
            )
        });
    }
    for case in &cases {
        let dir = unwritable_fixture(&png);
        let d = dir.path();
        let args: Vec<&str> = case.args.iter().map(String::as_str).collect();
        let o = emray(d, &args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(case.status), "{args:?}: {e}");
        let wanted = format!("emray: error: {}: cannot write", case.names);
        assert!(e.starts_with(&wanted), "{args:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{args:?}: one line: {e}");
        assert_eq!(String::from_utf8_lossy(&o.stdout), "", "{args:?}: no work");
        for f in case.absent {
            assert!(!d.join(f).exists(), "{args:?}: {f} was written");
        }
    }
}

/// The files in `dir`, sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn render_and_batch_name_outputs_with_the_same_templates() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.nff"), SCENE).unwrap();
    std::fs::write(d.join("b.nff"), SCENE).unwrap();
    let template = "{stem}-{backend}-{spp}-{index}";
    let o = emray(
        d,
        &[
            "render",
            "a.nff",
            "b.nff",
            "--backend",
            "bvh",
            "--spp",
            "2",
            "-o",
            &format!("render/{template}.png"),
            "--heatmap",
            "rays",
            &format!("render/{template}-rays.png"),
            "-q",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = emray(
        d,
        &[
            "batch",
            "a.nff",
            "b.nff",
            "--backend",
            "bvh",
            "--spp",
            "2",
            "-o",
            &format!("batch/{template}.png"),
            "-q",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        files(&d.join("render")),
        [
            "a-bvh-2-0-rays.png",
            "a-bvh-2-0.png",
            "b-bvh-2-1-rays.png",
            "b-bvh-2-1.png"
        ]
    );
    assert_eq!(files(&d.join("batch")), ["a-bvh-2-0.png", "b-bvh-2-1.png"]);
}

#[test]
fn unknown_placeholders_are_refused_listing_the_known_ones() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.nff"), SCENE).unwrap();
    let known = "(one of {stem}, {backend}, {index}, {spp})";
    for (args, wanted) in [
        (
            vec!["render", "a.nff", "-o", "{foo}.png"],
            format!("output template '{{foo}}.png': unknown placeholder '{{foo}}' {known}"),
        ),
        (
            vec!["render", "a.nff", "-o", "{stem.png"],
            "output template '{stem.png': '{' without '}'".to_string(),
        ),
        (
            vec!["render", "a.nff", "--heatmap", "rays", "{stem}-{what}.png"],
            format!(
                "output template '{{stem}}-{{what}}.png': unknown placeholder '{{what}}' {known}"
            ),
        ),
        (
            vec!["batch", "a.nff", "-o", "{foo}.png"],
            format!("output template '{{foo}}.png': unknown placeholder '{{foo}}' {known}"),
        ),
        (
            vec!["batch", "a.nff", "--report", "r-{index}.json"],
            "report name 'r-{index}.json': unknown placeholder '{index}' (one of {shard})"
                .to_string(),
        ),
    ] {
        let o = emray(d, &args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert_eq!(e.trim_end(), format!("emray: error: {wanted}"), "{args:?}");
    }
    assert_eq!(files(d), ["a.nff"], "nothing is written");
}
