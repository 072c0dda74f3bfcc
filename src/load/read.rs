//! Reading a whole file into memory, a large one in parallel: its chunks are read by
//! the worker threads at once, each into its own part of the buffer, so that the
//! copying from the page cache and the faulting-in of the buffer's pages, which take a
//! large scene file longer than a thread can parse it, are shared.

use rayon::prelude::*;
use std::io;
use std::path::Path;

/// Files smaller than this are read in one call.
const PARALLEL_FROM: u64 = 16 << 20;
/// The chunks a large file is read in.
const CHUNK: usize = 4 << 20;

/// The bytes of the file at `path`, as [`std::fs::read`] gives them.
///
/// # Errors
/// As [`std::fs::read`].
pub(super) fn read(path: &Path) -> io::Result<Vec<u8>> {
    let len = std::fs::metadata(path)?.len();
    if len < PARALLEL_FROM || rayon::current_num_threads() < 2 {
        return std::fs::read(path);
    }
    // A file that changes while it is read (or a platform without positioned reads) is
    // read again in one call, which says what is wrong if anything is.
    read_in_chunks(path, len).or_else(|_| std::fs::read(path))
}

/// The file's `len` bytes, read in [`CHUNK`]s in parallel; an error if it no longer
/// has `len` bytes.
#[cfg(unix)]
fn read_in_chunks(path: &Path, len: u64) -> io::Result<Vec<u8>> {
    use std::os::unix::fs::FileExt;
    let file = std::fs::File::open(path)?;
    let len = usize::try_from(len).map_err(|_| io::Error::from(io::ErrorKind::OutOfMemory))?;
    let mut bytes = vec![0; len];
    bytes
        .par_chunks_mut(CHUNK)
        .enumerate()
        .try_for_each(|(k, chunk)| file.read_exact_at(chunk, (k * CHUNK) as u64))?;
    if file.read_at(&mut [0], len as u64)? > 0 {
        return Err(io::Error::other("the file grew while it was read"));
    }
    Ok(bytes)
}

#[cfg(not(unix))]
fn read_in_chunks(path: &Path, _len: u64) -> io::Result<Vec<u8>> {
    std::fs::read(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_large_file_reads_as_one_call_reads_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big");
        let bytes: Vec<u8> = (0..(PARALLEL_FROM as usize + CHUNK / 3))
            .map(|i| (i * 7 % 251) as u8)
            .collect();
        std::fs::write(&path, &bytes).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        assert!(pool.install(|| read(&path).unwrap()) == bytes);
        assert!(read_in_chunks(&path, bytes.len() as u64 - 1).is_err());
        assert!(read(&dir.path().join("missing")).is_err());
    }
}
