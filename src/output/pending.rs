//! The temporary files being written, process-wide, so that a process told to stop can
//! remove them before it ends: [`abandon_writes`] removes every one and refuses new
//! ones. The library handles no signal; the binary's Ctrl-C handler calls it.
//!
//! A temporary file is created and registered under one lock, and leaves the register
//! only once it is renamed into place or removed, so a file is never on disk unregistered
//! while its write is in progress.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};
use tempfile::NamedTempFile;

/// The temporary files of writes in progress, by a number of their own.
struct Register {
    files: Vec<(u64, PathBuf)>,
    next: u64,
    /// Set by [`abandon_writes`]: no new temporary file.
    abandoned: bool,
}

static REGISTER: Mutex<Register> = Mutex::new(Register {
    files: Vec::new(),
    next: 0,
    abandoned: false,
});

/// The register, even if a thread panicked holding it (its list stays valid).
fn register() -> MutexGuard<'static, Register> {
    REGISTER.lock().unwrap_or_else(|e| e.into_inner())
}

/// A registered temporary file: removed, then unregistered, when dropped, unless
/// [`persist`](Self::persist)ed.
pub(super) struct PendingFile {
    // Fields drop in this order: the file is removed before it leaves the register.
    file: NamedTempFile,
    entry: Entry,
}

/// A file's place in the register, given up when dropped.
struct Entry(u64);

impl Drop for Entry {
    fn drop(&mut self) {
        register().files.retain(|(id, _)| *id != self.0);
    }
}

impl PendingFile {
    /// Create a temporary file with `create` and register it; refused once writes are
    /// abandoned.
    pub(super) fn create(create: impl FnOnce() -> io::Result<NamedTempFile>) -> io::Result<Self> {
        let mut r = register();
        if r.abandoned {
            return Err(io::Error::new(
                io::ErrorKind::Interrupted,
                "interrupted: no more files are written",
            ));
        }
        let file = create()?;
        let id = r.next;
        r.next += 1;
        r.files.push((id, file.path().to_path_buf()));
        Ok(PendingFile {
            file,
            entry: Entry(id),
        })
    }

    /// A second handle to the file, to write through.
    pub(super) fn reopen(&self) -> io::Result<fs::File> {
        self.file.reopen()
    }

    /// Rename the file to `path`, then unregister it (after the rename, or after a
    /// failed rename's temporary file is removed).
    pub(super) fn persist(self, path: &Path) -> io::Result<()> {
        let PendingFile { file, entry } = self;
        let renamed = file.persist(path).map(drop).map_err(|e| e.error);
        drop(entry);
        renamed
    }
}

/// Stop every write: remove the temporary files of writes in progress and refuse new
/// ones, for a process about to end (on Ctrl-C, say). Returns how many were removed.
/// Writes in progress then fail; files already renamed into place stay whole.
pub fn abandon_writes() -> usize {
    let mut r = register();
    r.abandoned = true;
    r.files
        .iter()
        .filter(|(_, path)| fs::remove_file(path).is_ok())
        .count()
}
