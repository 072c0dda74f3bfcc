//! The text of an input file. Every file emray reads as text comes through here: NFF,
//! OBJ and MTL files, TOML scenes and batch manifests, and the NFF and OBJ files a
//! scene includes; so every format sees the same text for the same bytes.
//!
//! - A UTF-8 byte-order mark (EF BB BF) at the start is skipped: some editors write
//!   one, and it is no part of the first statement. Lines and columns count from the
//!   character after it.
//! - A gzip-compressed file (one that starts with the gzip magic 1F 8B, whatever its
//!   name: the SPD distributes its files as `.nff.gz`) is refused with the command that
//!   decompresses it.
//! - A UTF-16 or UTF-32 byte-order mark is refused: such text is not UTF-8.
//!
//! Bytes that are not UTF-8 elsewhere in the file are each format's business: NFF, OBJ
//! and MTL replace them ([`lossy`]), TOML refuses them.

use super::LoadError;
use std::borrow::Cow;
use std::path::Path;

/// The UTF-8 byte-order mark.
const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";
/// The first two bytes of every gzip file.
const GZIP_MAGIC: &[u8] = b"\x1F\x8B";
/// The byte-order marks of encodings emray does not read, UTF-32 before UTF-16 (the
/// little-endian UTF-32 mark starts with the UTF-16 one).
const OTHER_BOMS: [(&[u8], &str); 4] = [
    (b"\xFF\xFE\x00\x00", "UTF-32"),
    (b"\x00\x00\xFE\xFF", "UTF-32"),
    (b"\xFF\xFE", "UTF-16"),
    (b"\xFE\xFF", "UTF-16"),
];

/// The bytes of the file at `path` that are its text: all of them but a leading UTF-8
/// byte-order mark.
///
/// # Errors
/// `path: …` for a gzip-compressed file or one with a UTF-16 or UTF-32 byte-order mark.
fn body<'b>(bytes: &'b [u8], path: &Path) -> Result<&'b [u8], LoadError> {
    if bytes.starts_with(GZIP_MAGIC) {
        return Err(whole_file(path, gzip_message(path)));
    }
    if let Some((_, name)) = OTHER_BOMS.iter().find(|(bom, _)| bytes.starts_with(bom)) {
        return Err(whole_file(
            path,
            format!("the file is {name} text: save it as UTF-8"),
        ));
    }
    Ok(bytes.strip_prefix(UTF8_BOM).unwrap_or(bytes))
}

/// The text of `bytes`, read from the file at `path` ([`body`]), with every byte
/// sequence that is not UTF-8 replaced by U+FFFD, which leaves line numbers intact.
///
/// # Errors
/// As [`body`].
pub(crate) fn lossy<'b>(bytes: &'b [u8], path: &Path) -> Result<Cow<'b, str>, LoadError> {
    body(bytes, path).map(String::from_utf8_lossy)
}

/// Read the file at `path` as text ([`lossy`]).
///
/// # Errors
/// As [`read_body`].
pub(crate) fn read_lossy(path: &Path) -> Result<String, LoadError> {
    let bytes = read_body(path)?;
    Ok(String::from_utf8(bytes)
        .unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned()))
}

/// The [`body`] of the file at `path`.
///
/// # Errors
/// `path: cannot read: …` when the file cannot be read, else as [`body`].
pub(crate) fn read_body(path: &Path) -> Result<Vec<u8>, LoadError> {
    let mut bytes =
        super::read::read(path).map_err(|e| whole_file(path, format!("cannot read: {e}")))?;
    let skip = bytes.len() - body(&bytes, path)?.len();
    bytes.drain(..skip);
    Ok(bytes)
}

/// What to do with a gzip-compressed file: `gunzip` it (renamed first when its name
/// does not end in `.gz`, which `gunzip` requires).
fn gzip_message(path: &Path) -> String {
    let p = path.display();
    let gz = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
    let command = if gz {
        format!("gunzip {p}")
    } else {
        format!("mv {p} {p}.gz && gunzip {p}.gz")
    };
    format!("the file is gzip-compressed: decompress it first ({command})")
}

fn whole_file(path: &Path, message: String) -> LoadError {
    LoadError {
        path: path.to_path_buf(),
        line: 0,
        col: 0,
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(bytes: &[u8]) -> Result<String, String> {
        lossy(bytes, Path::new("f.nff"))
            .map(Cow::into_owned)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn a_utf8_byte_order_mark_is_skipped_once() {
        assert_eq!(text(b"\xEF\xBB\xBFv 1").unwrap(), "v 1");
        assert_eq!(text(b"v 1").unwrap(), "v 1");
        assert_eq!(text(b"").unwrap(), "");
        // Only at the start, and only one.
        assert_eq!(text(b"\xEF\xBB\xBF\xEF\xBB\xBFv").unwrap(), "\u{feff}v");
        assert_eq!(text(b"v\xEF\xBB\xBF").unwrap(), "v\u{feff}");
    }

    #[test]
    fn gzip_is_refused_with_the_command_that_decompresses_it() {
        let gz = b"\x1F\x8B\x08\x00\x00\x00\x00\x00";
        let e = lossy(gz, Path::new("d/scene.nff.gz")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "d/scene.nff.gz: the file is gzip-compressed: decompress it first \
             (gunzip d/scene.nff.gz)"
        );
        let e = lossy(gz, Path::new("scene.nff")).unwrap_err();
        assert!(
            e.message
                .ends_with("(mv scene.nff scene.nff.gz && gunzip scene.nff.gz)"),
            "{e}"
        );
    }

    #[test]
    fn utf16_and_utf32_are_refused() {
        for (bytes, name) in [
            (&b"\xFF\xFEv\x00"[..], "UTF-16"),
            (b"\xFE\xFF\x00v", "UTF-16"),
            (b"\xFF\xFE\x00\x00v\x00\x00\x00", "UTF-32"),
            (b"\x00\x00\xFE\xFF\x00\x00\x00v", "UTF-32"),
        ] {
            assert_eq!(
                text(bytes).unwrap_err(),
                format!("f.nff: the file is {name} text: save it as UTF-8")
            );
        }
    }

    #[test]
    fn other_bytes_are_replaced_in_place() {
        assert_eq!(text(b"a\xFFb\nc").unwrap(), "a\u{fffd}b\nc");
    }
}
