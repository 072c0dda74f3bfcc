//! Atomic writes: every output file is written to a temporary file beside it
//! (`.NAME.XXXXXXXX.tmp`, in the same folder so that the rename is atomic), then renamed
//! over the target, so a failed or interrupted write never leaves a truncated file under
//! the target's name. The file gets the permissions the process's umask gives any new
//! file. Temporary files are registered while they exist, so that a process told to stop
//! can remove them ([`super::pending`]). Also the check made before any work goes into a file
//! ([`prepare`]), and the removal of temporary files a killed process left
//! ([`remove_stale_temps`]).

use super::OutputError;
use super::pending::PendingFile;
use std::fs;
use std::path::Path;

/// The folder `path` goes in (`.` for a bare file name).
pub(super) fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// A new temporary file beside `path`, named `.NAME.XXXXXXXX.tmp`, with the permissions
/// of any new file (see [`new_file_permissions`]), registered as a write in progress
/// (see [`super::pending`]); deleted when dropped unless persisted.
fn temp_beside(path: &Path) -> std::io::Result<PendingFile> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder
        .prefix(&prefix)
        .suffix(TEMP_SUFFIX)
        .rand_bytes(TEMP_RAND);
    if let Some(p) = new_file_permissions() {
        builder.permissions(p);
    }
    PendingFile::create(|| builder.tempfile_in(folder_of(path)))
}

/// The mode a temporary file is created with, which the rename keeps: read and write
/// for everyone, less what the process's umask takes away, as any program creating a
/// file gets (0644 under umask 022, 0600 under 077). The system applies the umask when
/// it creates the file, so it is never read or changed here (changing it to read it
/// would race with other threads creating files). `tempfile`'s own default, 0600
/// whatever the umask, would leave images on a shared folder unreadable to others.
#[cfg(unix)]
fn new_file_permissions() -> Option<fs::Permissions> {
    use std::os::unix::fs::PermissionsExt;
    Some(fs::Permissions::from_mode(0o666))
}

/// Elsewhere a new file gets the system's defaults.
#[cfg(not(unix))]
fn new_file_permissions() -> Option<fs::Permissions> {
    None
}

/// Create the folder `path` goes in, and the folders above it, if missing: the one
/// way every command makes its outputs' folders.
pub fn create_folder(path: &Path) -> Result<(), OutputError> {
    let folder = folder_of(path);
    fs::create_dir_all(folder).map_err(|e| OutputError::Write {
        path: path.to_path_buf(),
        message: match not_a_folder(folder) {
            Some(f) => format!("{} is not a folder", f.display()),
            None => e.to_string(),
        },
    })
}

/// The nearest of `folder` and the folders above it that exists, if it is not a folder
/// (a file where a folder should be, which the system reports as "File exists").
fn not_a_folder(folder: &Path) -> Option<&Path> {
    folder
        .ancestors()
        .find(|a| a.exists())
        .filter(|a| !a.is_dir())
}

/// Make sure `path` can be written before any work goes into it: create its folder if
/// missing, and create (then remove) a temporary file there, as the final write will.
pub fn prepare(path: &Path) -> Result<(), OutputError> {
    let err = |message: String| OutputError::Write {
        path: path.to_path_buf(),
        message,
    };
    create_folder(path)?;
    if path.is_dir() {
        return Err(err("it is a folder".into()));
    }
    temp_beside(path).map_err(|e| err(os_message(&e)))?;
    Ok(())
}

/// Make sure `path`, a file that records are appended to (`--stats-json`), can be
/// written before any work goes into it: as [`prepare`], and if it exists, open it for
/// appending.
pub fn prepare_append(path: &Path) -> Result<(), OutputError> {
    prepare(path)?;
    if path.exists() {
        fs::OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| OutputError::Write {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
    }
    Ok(())
}

/// What an I/O error says, without the temporary file's name that `tempfile` appends
/// ("... at path \"dir/.x.png.AbCd1234.tmp\""): the message names the target instead.
fn os_message(e: &std::io::Error) -> String {
    let text = e.to_string();
    match text.rfind(" at path \"") {
        Some(at) => text[..at].to_string(),
        None => text,
    }
}

/// Write `path` through a temporary file beside it (`.NAME.XXXXXX.tmp`, so that the
/// rename is atomic) that `write` fills, then a rename, creating its folder if missing;
/// on failure the temporary file is removed and the target left as it was.
pub(crate) fn write_atomic(
    path: &Path,
    write: impl FnOnce(fs::File) -> Result<(), String>,
) -> Result<(), OutputError> {
    let err = |message: String| OutputError::Write {
        path: path.to_path_buf(),
        message,
    };
    create_folder(path)?;
    // Dropping an unpersisted temporary file deletes it.
    let tmp = temp_beside(path).map_err(|e| err(os_message(&e)))?;
    let file = tmp.reopen().map_err(|e| err(e.to_string()))?;
    write(file).map_err(err)?;
    tmp.persist(path).map_err(|e| err(e.to_string()))?;
    Ok(())
}

/// Temporary files end in this.
const TEMP_SUFFIX: &str = ".tmp";
/// Random characters in a temporary file's name.
const TEMP_RAND: usize = 8;

/// Remove temporary files that an earlier, killed process left for `path` (their
/// names are `.NAME.XXXXXXXX.tmp`, see `write_atomic`; older versions put their
/// process id there); returns how many went.
pub fn remove_stale_temps(path: &Path) -> usize {
    let (Some(dir), Some(name)) = (path.parent(), path.file_name()) else {
        return 0;
    };
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let prefix = format!(".{}.", name.to_string_lossy());
    let Ok(entries) = fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for e in entries.flatten() {
        let n = e.file_name().to_string_lossy().into_owned();
        let stale = n
            .strip_prefix(&prefix)
            .and_then(|rest| rest.strip_suffix(TEMP_SUFFIX))
            .is_some_and(|r| !r.is_empty() && r.bytes().all(|b| b.is_ascii_alphanumeric()));
        if stale && fs::remove_file(e.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}
