//! Times the loading of scene files (NFF, OBJ, TOML, `spd:NAME[?size=N]`), for the
//! loading measurements of docs/performance.md:
//! `cargo run --release --example load_time -- [-t THREADS] REPS SCENE...`.
//!
//! Each repetition loads every scene once, in the order given, so that the runs of
//! different scenes (or of two builds started side by side) are interleaved on a busy
//! machine. Prints every run's time, then per scene the median, the spread and, for a
//! file, its megabytes per second (10⁶ bytes) at the median.

use std::path::Path;
use std::time::Instant;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut threads = 0;
    if args.first().is_some_and(|a| a == "-t") && args.len() > 1 {
        threads = args[1].parse().expect("THREADS is a whole number");
        args.drain(..2);
    }
    let Some((reps, scenes)) = args.split_first().filter(|(_, s)| !s.is_empty()) else {
        eprintln!("usage: load_time [-t THREADS] REPS SCENE...");
        std::process::exit(2);
    };
    let reps: usize = reps.parse().expect("REPS is a whole number");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let mut times = vec![Vec::new(); scenes.len()];
    for rep in 0..reps {
        for (scene, t) in scenes.iter().zip(&mut times) {
            let t0 = Instant::now();
            let loaded = pool.install(|| emray::job::load_scene(scene));
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            if let Err(e) = loaded {
                eprintln!("{e}");
                std::process::exit(1);
            }
            println!("rep {rep} {scene}: {ms:.1} ms");
            t.push(ms);
        }
    }
    for (scene, t) in scenes.iter().zip(&mut times) {
        t.sort_by(f64::total_cmp);
        let median = t[t.len() / 2];
        let rate = std::fs::metadata(Path::new(scene))
            .map(|m| format!(", {:.0} MB/s", m.len() as f64 / 1e3 / median))
            .unwrap_or_default();
        println!(
            "{scene}: median {median:.1} ms (min {:.1}, max {:.1}){rate}",
            t[0],
            t[t.len() - 1]
        );
    }
}
