//! Every `emray` command the documentation shows runs as a user who has just cloned
//! the repository would run it: in a scratch folder holding a copy of what the
//! repository gives them (its scenes and its sample batch manifest), section by section
//! (a section's commands may use what the ones before them wrote), each through
//! `bash` as written (pipes and redirections included), with this build's `emray`
//! first on the `PATH`. Each must exit with status 0.
//!
//! Commands that take much more than a second (benchmarks, studies, the stress suite,
//! radiosity, large renders) or need what another program writes are only parsed, by
//! the binary's own test; [`PARSE_ONLY`] lists them with why, and an entry that matches
//! no documented command fails the test, so the list cannot go stale. Commands that
//! need a feature this build lacks (`embree`, `quality`) are skipped.
//!
//! The sample manifest docs/batch.md shows is the repository's `jobs.toml`, which its
//! commands run.

#[path = "../src/cmd/docs_scan.rs"]
#[allow(dead_code)]
mod docs_scan;

use docs_scan::Documented;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The documented commands that are only parsed, each picked out by a piece of its
/// text, with why. Times are a release build's on two cores.
const PARSE_ONLY: &[(&str, &str)] = &[
    ("emray bench", "a benchmark: minutes"),
    (
        "emray study",
        "a reference render and a sweep of settings: minutes",
    ),
    ("emray stress", "the stress suite: minutes"),
    (
        "--gi radiosity",
        "a radiosity solution: seconds to a minute",
    ),
    (
        "emray radiosity",
        "a radiosity solution: seconds to a minute",
    ),
    (
        "emray batch scenes/*.toml",
        "every scene file of the repository: about 8 s",
    ),
    (
        "emray batch spd:balls",
        "the SPD suite in --spd mode: about 11 s",
    ),
    (
        "emray merge parts/",
        "merges the bands the Slurm job array above renders",
    ),
    (
        "spd:balls?size=7",
        "4.8 million spheres: 45 s and gigabytes",
    ),
    (
        "spd:balls?size=8",
        "counts 48 million spheres, then is refused (exits 1, as documented)",
    ),
    (
        "render balls7.nff",
        "5.4 million spheres from the 228 MB file `emray gen balls -s 7` writes: seconds \
         and gigabytes",
    ),
    (
        "scenes/ice-cube.toml -o",
        "depth 10, 19 million rays: about 6 s",
    ),
    (
        "vase.obj",
        "needs the files the texture_assets example writes",
    ),
    (
        "large.obj",
        "needs the files the texture_assets example writes",
    ),
    (
        "circle.nff",
        "needs the file the big_polygon example writes",
    ),
    (
        "emray view",
        "serves its page until Ctrl-C (cli/tests/view.rs drives it)",
    ),
];

/// What the scratch folder holds of the repository: the files of these that git
/// tracks (what a clone has; the texture example's output, say, is left out), or all
/// of them when the repository is not a git checkout.
const COPIED: &[&str] = &["scenes", "jobs.toml"];

/// Longest a command may take before it counts as failed.
const TIMEOUT: Duration = Duration::from_secs(300);

#[test]
fn every_documented_command_runs() {
    let all = docs_scan::documented();
    let stale: Vec<&str> = PARSE_ONLY
        .iter()
        .map(|(piece, _)| *piece)
        .filter(|piece| !all.iter().any(|c| c.line.contains(piece)))
        .collect();
    assert!(
        stale.is_empty(),
        "PARSE_ONLY entries match no documented command: {stale:?}"
    );
    let sections = Mutex::new(sections(all.into_iter().filter(runnable).collect()));
    let ran = Mutex::new(0usize);
    let failures = Mutex::new(Vec::new());
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get().min(4));
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                while let Some(section) = sections.lock().unwrap().pop() {
                    let (count, failed) = run_section(&section);
                    *ran.lock().unwrap() += count;
                    failures.lock().unwrap().extend(failed);
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    let ran = ran.into_inner().unwrap();
    // The README alone shows a dozen that run: finding few means the scanner broke.
    assert!(ran >= 30, "only {ran} documented commands ran");
}

#[test]
fn the_manifest_docs_batch_shows_is_jobs_toml() {
    let doc = std::fs::read_to_string(docs_scan::root().join("docs/batch.md")).unwrap();
    let file = std::fs::read_to_string(docs_scan::root().join("jobs.toml")).unwrap();
    let block: Vec<&str> = doc
        .lines()
        .skip_while(|l| l.trim() != "```toml")
        .skip(1)
        .take_while(|l| l.trim() != "```")
        .map(str::trim)
        .collect();
    let lines: Vec<&str> = file.lines().map(str::trim).collect();
    assert_eq!(
        block, lines,
        "docs/batch.md's first toml block is not jobs.toml"
    );
}

/// Whether `cmd` is to be run here: not listed as parse-only, and its features built.
fn runnable(cmd: &Documented) -> bool {
    let listed = PARSE_ONLY.iter().any(|(piece, _)| cmd.line.contains(piece));
    let embree = cmd.line.contains("embree");
    let quality = cmd.line.starts_with("emray compare") || cmd.line.starts_with("emray study");
    !listed && (cfg!(feature = "embree") || !embree) && (cfg!(feature = "quality") || !quality)
}

/// The commands grouped by section, in the order of the documents.
fn sections(commands: Vec<Documented>) -> Vec<Vec<Documented>> {
    let mut out: Vec<Vec<Documented>> = Vec::new();
    for cmd in commands {
        match out.last_mut() {
            Some(last) if last[0].section == cmd.section => last.push(cmd),
            _ => out.push(vec![cmd]),
        }
    }
    out
}

/// Run one section's commands in order in a scratch folder of its own: how many ran,
/// and a message for each that failed.
fn run_section(section: &[Documented]) -> (usize, Vec<String>) {
    let dir = tempfile::tempdir().expect("a scratch folder");
    let root = docs_scan::root();
    match tracked() {
        Some(files) => {
            for f in files {
                let to = dir.path().join(&f);
                std::fs::create_dir_all(to.parent().expect("a folder")).expect("a folder");
                std::fs::copy(root.join(&f), to).expect("a copy");
            }
        }
        None => {
            for name in COPIED.iter().filter(|n| root.join(n).exists()) {
                copy(&root.join(name), &dir.path().join(name));
            }
        }
    }
    let mut failures = Vec::new();
    for cmd in section {
        let start = Instant::now();
        let result = run(dir.path(), &cmd.line);
        // Shown with --nocapture: what each command costs in this build.
        println!(
            "{:>7.0} ms  {}",
            start.elapsed().as_secs_f64() * 1e3,
            cmd.place
        );
        if let Err(e) = result {
            failures.push(format!("{}: `{}`: {e}", cmd.place, cmd.line));
        }
    }
    (section.len(), failures)
}

/// Run `line` with `bash` in `dir`; the reason it failed, if it did.
fn run(dir: &Path, line: &str) -> Result<(), String> {
    let exe = Path::new(env!("CARGO_BIN_EXE_emray"));
    let bin = exe.parent().expect("the binary's folder");
    let path = std::env::var_os("PATH").unwrap_or_default();
    let path = std::env::join_paths(
        std::iter::once(bin.to_path_buf()).chain(std::env::split_paths(&path)),
    )
    .expect("a PATH");
    let out = |name: &str| std::fs::File::create(dir.join(name)).expect("an output file");
    let mut child = Command::new("bash")
        .args(["-o", "pipefail", "-c", line])
        .current_dir(dir)
        .env("PATH", path)
        .stdin(Stdio::null())
        .stdout(out(".stdout"))
        .stderr(out(".stderr"))
        .spawn()
        .map_err(|e| format!("cannot start bash: {e}"))?;
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            break status;
        }
        if start.elapsed() > TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("still running after {} s", TIMEOUT.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    if status.success() {
        return Ok(());
    }
    let stderr = std::fs::read_to_string(dir.join(".stderr")).unwrap_or_default();
    let tail: Vec<&str> = stderr.lines().rev().take(5).collect();
    let tail: Vec<&str> = tail.into_iter().rev().collect();
    Err(format!("{status}\n{}", tail.join("\n")))
}

/// The files of [`COPIED`] that git tracks, relative to the root; `None` without git.
fn tracked() -> Option<Vec<std::path::PathBuf>> {
    let out = Command::new("git")
        .arg("-C")
        .arg(docs_scan::root())
        .args(["ls-files", "-z", "--"])
        .args(COPIED)
        .stderr(Stdio::null())
        .output()
        .ok()?;
    if !out.status.success() || out.stdout.is_empty() {
        return None;
    }
    let text = String::from_utf8(out.stdout).ok()?;
    Some(
        text.split('\0')
            .filter(|f| !f.is_empty())
            .map(Into::into)
            .collect(),
    )
}

/// Copy a file, or a folder and everything in it.
fn copy(from: &Path, to: &Path) {
    if from.is_dir() {
        std::fs::create_dir_all(to).expect("a folder");
        for entry in std::fs::read_dir(from).expect("a readable folder") {
            let entry = entry.expect("a folder entry");
            copy(&entry.path(), &to.join(entry.file_name()));
        }
    } else {
        std::fs::copy(from, to).expect("a copy");
    }
}
