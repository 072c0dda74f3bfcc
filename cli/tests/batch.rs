//! `emray batch`, shards, `render --tile/--crop` and `emray merge`, through the binary.

use emray::output::read_exr;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn emray(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_emray"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run emray")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A small scene: two spheres (one mirror, one glass) over a polygon floor, 2 lights.
fn scene(res: &str, shift: f32) -> String {
    format!(
        "v\nfrom 0 1 6\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution {res}\n\
         b 0.2 0.3 0.5\nl 4 6 5\nl -4 5 3 1 0.9 0.8\n\
         f 1 0.5 0.3 0.7 0.3 20 0 1\ns {shift} 0 0 1\n\
         f 0.9 0.9 1 0.1 0.2 40 0.8 1.5\ns 1.3 0.2 1 0.6\n\
         f 0.8 0.8 0.8 1 0 0 0 1\np 4\n-4 -1 -4\n-4 -1 4\n4 -1 4\n4 -1 -4\n"
    )
}

fn write_scenes(dir: &Path, n: usize) -> Vec<String> {
    (0..n)
        .map(|i| {
            let name = format!("s{i:02}.nff");
            std::fs::write(dir.join(&name), scene("12 10", i as f32 * 0.1 - 0.5)).unwrap();
            name
        })
        .collect()
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_failing_job_in_the_middle_fails_alone() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut scenes = write_scenes(d, 2);
    std::fs::write(d.join("bad.nff"), "v\nfrom 0 0 5\nat 0 0 0\ns 0 0 nan 1\n").unwrap();
    scenes.insert(1, "bad.nff".into());
    let mut args = vec!["batch", "-q", "-o", "out/{stem}.png", "--report", "r.json"];
    args.extend(scenes.iter().map(String::as_str));
    let o = emray(d, &args);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("bad.nff:"), "{}", stderr(&o));
    assert_eq!(files(&d.join("out")), ["s00.png", "s01.png"]);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("r.json")).unwrap()).unwrap();
    assert_eq!(r["total"], 3);
    assert_eq!(r["ok"], 2);
    assert_eq!(r["failed"], 1);
    let jobs = r["jobs"].as_array().unwrap();
    let statuses: Vec<&str> = jobs.iter().map(|j| j["status"].as_str().unwrap()).collect();
    assert_eq!(statuses, ["ok", "failed", "ok"]);
    let err = jobs[1]["error"].as_str().unwrap();
    assert!(err.starts_with("bad.nff:"), "{err}");
    assert!(jobs[0]["stats"]["rays"]["eye"].as_u64().unwrap() == 120);
    assert!(jobs[2]["stats"]["time_ms"]["render"].as_f64().unwrap() >= 0.0);
}

#[test]
fn a_killed_batch_resumes_to_a_clean_runs_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scenes = write_scenes(d, 12);
    let mut args = vec!["batch", "-q", "-t", "1", "--spp", "4"];
    args.extend(scenes.iter().map(String::as_str));
    // The clean run.
    let o = emray(d, &[&args[..], &["-o", "clean/{stem}.png"]].concat());
    args.extend(["-o", "out/{stem}.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Killed (SIGKILL) once the first image is out, in the middle of the batch.
    let mut child = Command::new(env!("CARGO_BIN_EXE_emray"))
        .current_dir(d)
        .args(&args)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !d.join("out/s00.png").exists() && t0.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done_before = files(&d.join("out")).len();
    // Leftovers a kill can leave: a stale temporary file, and (from some other tool)
    // a truncated image under an output name, which a resume must not trust.
    std::fs::write(d.join("out/.s03.png.k3Xq9ZpA.tmp"), b"partial").unwrap();
    std::fs::write(d.join("out/s05.png"), b"\x89PNG\r\n\x1a\n").unwrap();
    let o = emray(
        d,
        &[&args[..], &["--skip-existing", "--report", "r.json"]].concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("r.json")).unwrap()).unwrap();
    assert!(r["skipped"].as_u64().unwrap() >= 1);
    assert!(r["ok"].as_u64().unwrap() >= 1, "s05 was redone");
    let clean = files(&d.join("clean"));
    assert_eq!(clean.len(), 12);
    assert_eq!(files(&d.join("out")), clean, "no temporary files remain");
    for f in &clean {
        assert_eq!(
            std::fs::read(d.join("out").join(f)).unwrap(),
            std::fs::read(d.join("clean").join(f)).unwrap(),
            "{f} (killed after {done_before} images)"
        );
    }
}

#[cfg(unix)]
#[test]
fn ctrl_c_stops_after_writing_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Three jobs that finish, then one whose scene is a named pipe nobody writes: its
    // load blocks, so the batch is surely still running when the signal arrives,
    // whatever the machine's speed.
    let mut scenes = write_scenes(d, 8);
    let fifo = Command::new("mkfifo").arg(d.join("blocked.nff")).status();
    if !fifo.is_ok_and(|s| s.success()) {
        eprintln!("skipped: mkfifo is not available");
        return;
    }
    scenes.insert(3, "blocked.nff".into());
    let mut args = vec!["batch", "-q", "-t", "1", "--report", "r.json"];
    args.extend(scenes.iter().map(String::as_str));
    let mut child = Command::new(env!("CARGO_BIN_EXE_emray"))
        .current_dir(d)
        .args(&args)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let pngs = || files(d).iter().filter(|f| f.ends_with(".png")).count();
    let t0 = Instant::now();
    while pngs() < 3 && t0.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(pngs(), 3, "the first three jobs finish");
    // SIGINT, as Ctrl-C sends it; sent from here, as no `kill` program need be installed.
    let pid = nix::unistd::Pid::from_raw(child.id().try_into().unwrap());
    nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGINT).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("r.json")).unwrap()).unwrap();
    assert_eq!(r["interrupted"], true);
    assert_eq!(r["ok"].as_u64(), Some(3));
    // Exactly the finished jobs left images, and no temporary file is left.
    assert_eq!(pngs(), 3);
    assert!(!files(d).iter().any(|f| f.ends_with(".tmp")));
}

/// This shard's job names, from `batch --list`.
fn shard_names(d: &Path, scenes: &[String], shard: &str) -> Vec<String> {
    let mut args = vec!["batch", "--list", "-o", "{stem}.png", "--shard", shard];
    args.extend(scenes.iter().map(String::as_str));
    let o = emray(d, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    String::from_utf8(o.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split('\t').next().unwrap().to_string())
        .collect()
}

#[test]
fn shards_cover_every_job_exactly_once() {
    let dir = tempfile::tempdir().unwrap();
    let scenes: Vec<String> = (0..23).map(|i| format!("scene{i}.nff")).collect();
    let mut reversed = scenes.clone();
    reversed.reverse();
    for n in 1..=8u32 {
        let mut seen: Vec<String> = Vec::new();
        for i in 0..n {
            let names = shard_names(dir.path(), &scenes, &format!("{i}/{n}"));
            let mut again = shard_names(dir.path(), &reversed, &format!("{i}/{n}"));
            again.reverse();
            assert_eq!(names, again, "shard {i}/{n} depends on the order");
            seen.extend(names);
        }
        seen.sort();
        let mut all: Vec<String> = scenes.iter().map(|s| s.replace(".nff", ".png")).collect();
        all.sort();
        assert_eq!(seen, all, "N = {n}");
    }
}

fn backends() -> Vec<&'static str> {
    if cfg!(feature = "embree") {
        vec!["embree", "bvh"]
    } else {
        vec!["bvh"]
    }
}

#[test]
fn tiles_merge_bit_identical_to_the_full_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.nff"), scene("23 19", 0.0)).unwrap();
    for backend in backends() {
        for (mode, counts) in [
            (&["--spp", "3"][..], &[1, 2, 3, 7][..]),
            (&["--spd", "--res", "17x13"][..], &[2, 7][..]),
            (&["--aa", "adaptive"][..], &[3][..]),
        ] {
            let base = [&["render", "-q", "t.nff", "--backend", backend][..], mode].concat();
            let o = emray(d, &[&base[..], &["-o", "full.exr"]].concat());
            assert!(o.status.success(), "{}", stderr(&o));
            let (full, _) = read_exr(&d.join("full.exr")).unwrap();
            for &n in counts {
                let mut parts: Vec<String> = Vec::new();
                for i in 0..n {
                    let p = format!("part{i}.exr");
                    let tile = format!("{i}/{n}");
                    let o = emray(d, &[&base[..], &["--band", &tile, "-o", &p]].concat());
                    assert!(o.status.success(), "{}", stderr(&o));
                    parts.push(p);
                }
                // Merged in any order.
                parts.reverse();
                let mut args = vec!["merge", "-o", "merged.exr"];
                args.extend(parts.iter().map(String::as_str));
                let o = emray(d, &args);
                assert!(o.status.success(), "{}", stderr(&o));
                let (merged, _) = read_exr(&d.join("merged.exr")).unwrap();
                assert_eq!((merged.width, merged.height), (full.width, full.height));
                let same =
                    merged.pixels.iter().zip(&full.pixels).all(|(a, b)| {
                        a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits)
                    });
                assert!(same, "{backend} {mode:?} N = {n}");
            }
        }
    }
}

#[test]
fn merge_refuses_parts_that_do_not_make_one_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.nff"), scene("16 12", 0.0)).unwrap();
    let part = |extra: &[&str], out: &str| {
        let o = emray(
            d,
            &[
                &["render", "-q", "t.nff", "--backend", "bvh"][..],
                extra,
                &["-o", out],
            ]
            .concat(),
        );
        assert!(o.status.success(), "{}", stderr(&o));
    };
    part(&["--crop", "0,16,0,5"], "a.exr");
    part(&["--crop", "0,16,5,12"], "b.exr");
    part(&["--crop", "0,16,4,12"], "overlap.exr");
    part(&["--crop", "0,16,5,12", "--spp", "2"], "other.exr");
    let merge = |parts: &[&str]| emray(d, &[&["merge", "-o", "m.png"][..], parts].concat());
    assert!(merge(&["a.exr", "b.exr"]).status.success());
    std::fs::remove_file(d.join("m.png")).unwrap();
    for (parts, why) in [
        (&["a.exr"][..], "uncovered"),
        (&["a.exr", "overlap.exr"][..], "overlap"),
        (&["a.exr", "other.exr"][..], "other settings"),
    ] {
        let o = merge(parts);
        assert_eq!(o.status.code(), Some(1));
        assert!(stderr(&o).contains(why), "{why}: {}", stderr(&o));
        assert!(!d.join("m.png").exists());
    }
    // Bad regions and outputs are refused before rendering.
    let o = emray(
        d,
        &["render", "t.nff", "--crop", "0,17,0,12", "-o", "c.exr"],
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("not inside"), "{}", stderr(&o));
    let o = emray(d, &["render", "t.nff", "--tile", "0/2", "-o", "c.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!d.join("c.exr").exists() && !d.join("c.png").exists());
}

#[test]
fn manifest_jobs_with_defaults_and_gnu_parallel_shards() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scenes = write_scenes(d, 6);
    let mut manifest = String::from("output = \"{stem}-{backend}.png\"\nbackend = \"bvh\"\n");
    for s in &scenes {
        manifest += &format!("[[job]]\nscene = \"{s}\"\n");
    }
    manifest +=
        "[[job]]\nname = \"big\"\nscene = \"s00.nff\"\nres = \"20x8\"\noutput = \"big.exr\"\n";
    std::fs::create_dir(d.join("one")).unwrap();
    std::fs::create_dir(d.join("four")).unwrap();
    std::fs::write(
        d.join("one/jobs.toml"),
        manifest.replace("scene = \"", "scene = \"../"),
    )
    .unwrap();
    std::fs::write(
        d.join("four/jobs.toml"),
        manifest.replace("scene = \"", "scene = \"../"),
    )
    .unwrap();
    let o = emray(d, &["batch", "-q", "-m", "one/jobs.toml"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let one: Vec<String> = files(&d.join("one"))
        .into_iter()
        .filter(|f| f != "jobs.toml")
        .collect();
    assert_eq!(one.len(), 7, "{one:?}");
    assert!(one.contains(&"s03-bvh.png".to_string()) && one.contains(&"big.exr".to_string()));
    let (big, _) = read_exr(&d.join("one/big.exr")).unwrap();
    assert_eq!((big.width, big.height), (20, 8));
    if Command::new("parallel").arg("--version").output().is_err() {
        eprintln!("skipped the GNU parallel part: `parallel` is not installed");
        return;
    }
    let exe = env!("CARGO_BIN_EXE_emray");
    let o = Command::new("parallel")
        .current_dir(d)
        .args([
            "--will-cite",
            "-j",
            "4",
            exe,
            "batch",
            "-q",
            "-t",
            "1",
            "-m",
            "four/jobs.toml",
        ])
        .args([
            "--shard",
            "{}/4",
            "--report",
            "four/r{}.json",
            ":::",
            "0",
            "1",
            "2",
            "3",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let mut total = 0;
    for i in 0..4 {
        let r: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(d.join(format!("four/r{i}.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(r["shard"], format!("{i}/4"));
        total += r["ok"].as_u64().unwrap();
    }
    assert_eq!(total, 7);
    for f in &one {
        assert_eq!(
            std::fs::read(d.join("one").join(f)).unwrap(),
            std::fs::read(d.join("four").join(f)).unwrap(),
            "{f}"
        );
    }
}
