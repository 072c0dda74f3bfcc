//! How far a load has come: [`LoadProgress`], which the loaders advance as they read
//! (bytes of a file, primitives of a generated database) and which tells a watcher
//! `(done, total)` a few dozen times a second at most, so that a long load shows a
//! percentage instead of a silent wait.
//!
//! Advancing is cheap (an atomic add, and a clock read) and is done per chunk of
//! input, never per line or per entity. What the watcher is told never goes back,
//! whichever threads advance, and ends with `(total, total)` once the load is done
//! ([`LoadProgress::finish`]).

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// The least time between two reports by default: at most 25 a second.
pub const REPORT_INTERVAL: Duration = Duration::from_millis(40);

/// What a watcher is told: `(done, total)`, in the loader's units.
pub type Tell<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// The progress of one load (see the module documentation).
pub struct LoadProgress<'a> {
    tell: Option<Tell<'a>>,
    interval: Duration,
    start: Instant,
    total: AtomicU64,
    done: AtomicU64,
    /// The last report: when (since `start`) and its `done`.
    told: Mutex<(Duration, u64)>,
}

impl<'a> LoadProgress<'a> {
    /// Progress told to `tell`, at most once per [`REPORT_INTERVAL`].
    pub fn new(tell: Tell<'a>) -> Self {
        Self::with(Some(tell))
    }

    /// Progress that nobody watches: advancing it does nothing.
    pub fn silent() -> Self {
        Self::with(None)
    }

    fn with(tell: Option<Tell<'a>>) -> Self {
        LoadProgress {
            tell,
            interval: REPORT_INTERVAL,
            start: Instant::now(),
            total: AtomicU64::new(0),
            done: AtomicU64::new(0),
            told: Mutex::new((Duration::ZERO, 0)),
        }
    }

    /// The same, told at most once per `interval` (zero: at every advance).
    pub fn every(mut self, interval: Duration) -> Self {
        self.interval = interval;
        self
    }

    /// Whether anybody is told (a loader may skip the work of counting when not).
    pub fn is_watched(&self) -> bool {
        self.tell.is_some()
    }

    /// The load has `total` units to do in all.
    pub fn expect(&self, total: u64) {
        self.total.store(total, Ordering::Relaxed);
    }

    /// The total set by [`LoadProgress::expect`] (0 before).
    pub fn total(&self) -> u64 {
        self.total.load(Ordering::Relaxed)
    }

    /// `n` more units are done: tell the watcher if the last report is old enough and
    /// no other thread is telling it now.
    pub fn advance(&self, n: u64) {
        let Some(tell) = self.tell else {
            return;
        };
        self.done.fetch_add(n, Ordering::Relaxed);
        let now = self.start.elapsed();
        let Ok(mut told) = self.told.try_lock() else {
            return;
        };
        if now.saturating_sub(told.0) < self.interval && told.1 > 0 {
            return;
        }
        let total = self.total();
        let done = self.done.load(Ordering::Relaxed).min(total);
        if done > told.1 && done < total {
            tell(done, total);
            *told = (now, done);
        }
    }

    /// The load is done: tell `(total, total)`, once.
    pub fn finish(&self) {
        let Some(tell) = self.tell else {
            return;
        };
        let total = self.total();
        let mut told = self.told.lock().unwrap_or_else(|e| e.into_inner());
        if total > 0 && told.1 < total {
            tell(total, total);
            *told = (self.start.elapsed(), total);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reports(interval: Duration, steps: &[u64], total: u64) -> Vec<(u64, u64)> {
        let seen = Mutex::new(Vec::new());
        let tell = |d, t| seen.lock().unwrap().push((d, t));
        let p = LoadProgress::new(&tell).every(interval);
        p.expect(total);
        for &n in steps {
            p.advance(n);
        }
        p.finish();
        p.finish();
        seen.into_inner().unwrap()
    }

    #[test]
    fn every_advance_is_told_without_an_interval_and_the_end_once() {
        let r = reports(Duration::ZERO, &[3, 0, 4, 3], 10);
        assert_eq!(r, [(3, 10), (7, 10), (10, 10)]);
    }

    #[test]
    fn reports_are_throttled_but_the_end_is_told() {
        let r = reports(Duration::from_secs(3600), &[1; 100], 100);
        assert_eq!(r, [(1, 100), (100, 100)]);
    }

    #[test]
    fn done_never_passes_the_total_nor_goes_back() {
        let r = reports(Duration::ZERO, &[5, 20], 10);
        assert_eq!(r, [(5, 10), (10, 10)]);
        let seen = Mutex::new(Vec::new());
        let tell = |d, _| seen.lock().unwrap().push(d);
        let p = LoadProgress::new(&tell).every(Duration::ZERO);
        p.expect(1 << 20);
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| (0..1000).for_each(|_| p.advance(1)));
            }
        });
        p.finish();
        let seen = seen.into_inner().unwrap();
        assert!(seen.windows(2).all(|w| w[0] < w[1]), "{seen:?}");
        assert_eq!(seen.last(), Some(&(1 << 20)));
    }

    #[test]
    fn nothing_is_told_when_nobody_watches_or_nothing_is_expected() {
        let p = LoadProgress::silent();
        p.expect(5);
        p.advance(5);
        p.finish();
        assert!(!p.is_watched());
        assert_eq!(reports(Duration::ZERO, &[1], 0), []);
    }
}
