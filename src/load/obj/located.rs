//! Places in a file and how messages show them: problems at a line and column, the
//! column of a token, and tokens quoted for a message.

use crate::load::LoadError;
use std::path::Path;

/// A problem at a place in a file; line 0 means the whole file.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Located {
    pub line: usize,
    pub col: usize,
    pub message: String,
}

impl Located {
    /// At `tok`, a slice of `line` (line number `ln`), or just after the line's last
    /// token when there is none.
    pub fn at_token(ln: usize, line: &str, tok: Option<&str>, message: String) -> Self {
        Located {
            line: ln,
            col: tok.map_or_else(|| col_end(line), |t| col_of(line, t)),
            message,
        }
    }

    /// A problem with the whole file.
    pub fn whole_file(message: String) -> Self {
        Located {
            line: 0,
            col: 0,
            message,
        }
    }

    pub fn at(self, path: &Path) -> LoadError {
        LoadError {
            path: path.to_path_buf(),
            line: self.line,
            col: self.col,
            message: self.message,
        }
    }
}

/// An error about the whole file at `path`.
pub(super) fn whole_file(path: &Path, message: String) -> LoadError {
    Located::whole_file(message).at(path)
}

/// 1-based column (in characters) of `tok`, a slice of `line`.
pub(super) fn col_of(line: &str, tok: &str) -> usize {
    let off = (tok.as_ptr() as usize).saturating_sub(line.as_ptr() as usize);
    line.get(..off).map_or(1, |s| s.chars().count() + 1)
}

/// 1-based column just after the last token of `line`.
pub(super) fn col_end(line: &str) -> usize {
    line.trim_end().chars().count() + 1
}

/// A token for a message: quoted, and shortened if long.
pub(super) fn show(t: &str) -> String {
    const MAX: usize = 40;
    if t.chars().count() <= MAX {
        format!("'{t}'")
    } else {
        let head: String = t.chars().take(MAX).collect();
        format!("'{head}…'")
    }
}

/// A hint for a token that starts a comment after a statement.
pub(super) fn comment_hint(tok: &str) -> &'static str {
    if tok.starts_with('#') {
        " (comments must be on a line of their own)"
    } else {
        ""
    }
}

/// `noun` with its indefinite article.
pub(super) fn article(noun: &str) -> String {
    if noun.starts_with(['a', 'e', 'i', 'o', 'u']) {
        format!("an {noun}")
    } else {
        format!("a {noun}")
    }
}

/// The name a statement gives: the rest of the line after its first space, trimmed
/// (`usemtl`, `mtllib`: a name may contain spaces).
pub(super) fn name_after_space(line: &str) -> &str {
    line.split_once(' ').unwrap_or_default().1.trim()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_characters() {
        let line = "g é x";
        let x = line.split_whitespace().nth(2).unwrap();
        assert_eq!(col_of(line, x), 5);
        assert_eq!(col_end("f 1 2  "), 6);
    }

    #[test]
    fn names_are_the_rest_after_the_first_space() {
        assert_eq!(name_after_space("usemtl  a b \r"), "a b");
        assert_eq!(name_after_space("usemtl\tx"), "");
        // A leading space is the first space.
        assert_eq!(name_after_space(" mtllib a.mtl"), "mtllib a.mtl");
    }

    #[test]
    fn long_tokens_are_shortened() {
        assert_eq!(show("ab"), "'ab'");
        assert!(show(&"x".repeat(50)).ends_with("…'"));
    }
}
