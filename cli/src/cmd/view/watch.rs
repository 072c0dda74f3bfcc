//! The scene file watched: its modification time and size polled every
//! [`INTERVAL`] (no dependency, every platform); a change re-renders.

use std::path::Path;
use std::time::{Duration, SystemTime};

/// How often the scene file is looked at.
pub const INTERVAL: Duration = Duration::from_millis(300);

/// What tells one version of a file from another (`None`: no such file, as for an
/// `spd:` scene).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stamp(Option<(SystemTime, u64)>);

impl Stamp {
    /// `path`'s stamp now.
    pub fn of(path: &Path) -> Stamp {
        Stamp(
            std::fs::metadata(path)
                .ok()
                .and_then(|m| Some((m.modified().ok()?, m.len()))),
        )
    }
}

/// Poll `path` until `stop` says so, calling `changed` each time its stamp changes.
pub fn watch(path: &Path, stop: impl Fn() -> bool, changed: impl Fn()) {
    let mut last = Stamp::of(path);
    while !stop() {
        std::thread::sleep(INTERVAL);
        let now = Stamp::of(path);
        if now != last {
            last = now;
            changed();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_write_changes_the_stamp() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("s.nff");
        let missing = Stamp::of(&f);
        assert_eq!(missing, Stamp(None));
        std::fs::write(&f, "a").unwrap();
        let one = Stamp::of(&f);
        assert_ne!(one, missing);
        std::fs::write(&f, "ab").unwrap();
        assert_ne!(Stamp::of(&f), one);
    }
}
