//! How long a render or a batch has left, from the time spent and the share of the work
//! done, shown once enough of it is done to say.
//!
//! indicatif's own estimate follows the recent rate of steps, which the first tiles of
//! a render fool: a band of sky finishes in a blink and the estimate reads a second or
//! two for a render ten times longer. Time spent × left ÷ done averages over the whole
//! render so far instead.

use indicatif::ProgressState;
use std::fmt::Write;
use std::time::{Duration, Instant};

/// The time left after `elapsed` for `done` of `total` steps, when at least
/// `min_done` are done (none before: too few to say).
pub fn eta(elapsed: Duration, done: u64, total: u64, min_done: u64) -> Option<Duration> {
    if done < min_done.max(1) || done >= total {
        return None;
    }
    Some(elapsed.mul_f64((total - done) as f64 / done as f64))
}

/// The tiles a render must finish before its estimate shows: a few, and 2% of them.
pub fn min_tiles(total: u64) -> u64 {
    (total / 50).max(4)
}

/// `8s`, `1m 12s`, `2h 05m`: a duration as the bars show it, rounded up to a second.
pub fn short(d: Duration) -> String {
    let s = d.as_secs() + u64::from(d.subsec_nanos() > 0);
    match s {
        0..60 => format!("{s}s"),
        60..3600 => format!("{}m {:02}s", s / 60, s % 60),
        _ => format!("{}h {:02}m", s / 3600, s % 3600 / 60),
    }
}

/// A bar's time left, measured from `start`: ` eta 8s` once `min_done(len)` steps are
/// done, nothing before.
pub fn key(
    start: Instant,
    min_done: fn(u64) -> u64,
) -> impl Fn(&ProgressState, &mut dyn Write) + Clone + Send + Sync + 'static {
    move |state: &ProgressState, w: &mut dyn Write| {
        let total = state.len().unwrap_or(0);
        if let Some(left) = eta(start.elapsed(), state.pos(), total, min_done(total)) {
            let _ = write!(w, " eta {}", short(left));
        }
    }
}

/// The jobs a batch must finish before its estimate shows: one.
pub fn min_jobs(_total: u64) -> u64 {
    1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_is_time_spent_times_left_over_done() {
        let s = Duration::from_secs;
        // A quarter done in 2.5 s: 7.5 s left.
        let ms = Duration::from_millis;
        assert_eq!(eta(ms(2500), 25, 100, 4), Some(ms(7500)));
        // Too few tiles done to say, or nothing left.
        assert_eq!(eta(s(1), 3, 100, 4), None);
        assert_eq!(eta(s(1), 0, 100, 0), None);
        assert_eq!(eta(s(9), 100, 100, 4), None);
        assert_eq!(min_tiles(100), 4);
        assert_eq!(min_tiles(1200), 24);
    }

    #[test]
    fn durations_read_short() {
        assert_eq!(short(Duration::from_millis(7200)), "8s");
        assert_eq!(short(Duration::from_secs(72)), "1m 12s");
        assert_eq!(short(Duration::from_secs(7500)), "2h 05m");
    }
}
