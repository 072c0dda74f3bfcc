//! The NFF lexer: whitespace-separated tokens, `#` comments to the end of the line, and
//! the line and column of every token. Tokens are slices of the source.
//!
//! A lexer may start anywhere a line starts (or at any token), given the line number
//! there, so that the pieces of a file parsed apart number their lines as the whole
//! file does.

use super::number::{Plain, scan_plain};

/// One token: a slice of the source and where it starts.
#[derive(Clone, Copy, Debug)]
pub(super) struct Tok<'a> {
    pub text: &'a str,
    /// Byte offset of the token.
    pub start: usize,
    /// 1-based line.
    pub line: usize,
    /// Byte offset of the start of its line.
    pub line_start: usize,
}

/// Splits the source into tokens, skipping whitespace and `#` comments.
pub(super) struct Lexer<'a> {
    src: &'a str,
    pos: usize,
    line: usize,
    line_start: usize,
    peeked: Option<Tok<'a>>,
    /// The last token handed out by `next`.
    pub last: Option<Tok<'a>>,
}

#[inline]
pub(super) const fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

/// What a byte is to the lexer: part of a token, a blank, a line end or a comment.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Class {
    Token,
    Blank,
    Lf,
    Cr,
    Hash,
}

/// [`Class`] by byte, one look-up instead of a chain of comparisons.
const CLASSES: [Class; 256] = {
    let mut t = [Class::Token; 256];
    let mut b = 0;
    while b < 256 {
        t[b] = match b as u8 {
            b'\n' => Class::Lf,
            b'\r' => Class::Cr,
            b'#' => Class::Hash,
            c if is_space(c) => Class::Blank,
            _ => Class::Token,
        };
        b += 1;
    }
    t
};

impl<'a> Lexer<'a> {
    /// A lexer at the start of `src`.
    pub fn new(src: &'a str) -> Self {
        Self::at(src, 0, 1, 0)
    }

    /// A lexer at byte `pos` of `src`, which is on line `line`, a line that starts at
    /// byte `line_start`. `pos` must be a line start or a token start.
    pub fn at(src: &'a str, pos: usize, line: usize, line_start: usize) -> Self {
        Lexer {
            src,
            pos,
            line,
            line_start,
            peeked: None,
            last: None,
        }
    }

    #[inline(always)]
    fn scan(&mut self) -> Option<Tok<'a>> {
        let b = self.src.as_bytes();
        loop {
            match CLASSES[*b.get(self.pos)? as usize] {
                Class::Token => break,
                Class::Blank => self.pos += 1,
                Class::Lf => {
                    self.pos += 1;
                    self.line += 1;
                    self.line_start = self.pos;
                }
                Class::Cr => {
                    self.pos += 1;
                    // CR LF counts once (at the LF); a lone CR ends a line too.
                    if b.get(self.pos) != Some(&b'\n') {
                        self.line += 1;
                        self.line_start = self.pos;
                    }
                }
                Class::Hash => {
                    while self.pos < b.len() && !matches!(b[self.pos], b'\n' | b'\r') {
                        self.pos += 1;
                    }
                }
            }
        }
        let start = self.pos;
        self.pos += b[start..]
            .iter()
            .position(|&c| CLASSES[c as usize] != Class::Token)
            .unwrap_or(b.len() - start);
        // Token boundaries are ASCII bytes, so they are char boundaries.
        Some(Tok {
            text: &self.src[start..self.pos],
            start,
            line: self.line,
            line_start: self.line_start,
        })
    }

    #[inline(always)]
    pub fn next(&mut self) -> Option<Tok<'a>> {
        let t = match self.peeked.take() {
            Some(t) => Some(t),
            None => self.scan(),
        };
        if t.is_some() {
            self.last = t;
        }
        t
    }

    /// The next token when it is a plain decimal on the same line (after blanks),
    /// read in the same pass, and handed out as [`Lexer::next`] would; `None`, with
    /// nothing consumed, for anything else.
    #[inline(always)]
    pub fn next_plain(&mut self) -> Option<(Tok<'a>, Plain)> {
        if self.peeked.is_some() {
            return None;
        }
        let b = self.src.as_bytes();
        let mut start = self.pos;
        while matches!(b.get(start), Some(b' ' | b'\t')) {
            start += 1;
        }
        let (plain, len) = scan_plain(&b[start..])?;
        self.pos = start + len;
        let tok = Tok {
            text: &self.src[start..self.pos],
            start,
            line: self.line,
            line_start: self.line_start,
        };
        self.last = Some(tok);
        Some((tok, plain))
    }

    #[inline]
    pub fn peek(&mut self) -> Option<Tok<'a>> {
        if self.peeked.is_none() {
            self.peeked = self.scan();
        }
        self.peeked
    }

    /// Bytes of source after the last token handed out.
    pub fn remaining(&self) -> usize {
        let end = self.last.map_or(0, |t| t.start + t.text.len());
        self.src.len() - end
    }

    /// 1-based column of byte `at` on the line starting at `line_start`.
    pub fn col(&self, line_start: usize, at: usize) -> usize {
        col(self.src, line_start, at)
    }
}

/// 1-based column of byte `at` of `src` on the line starting at `line_start`.
pub(super) fn col(src: &str, line_start: usize, at: usize) -> usize {
    src[line_start..at].chars().count() + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(src: &str) -> Vec<(String, usize, usize)> {
        let mut lx = Lexer::new(src);
        let mut v = Vec::new();
        while let Some(t) = lx.next() {
            v.push((t.text.to_string(), t.line, lx.col(t.line_start, t.start)));
        }
        v
    }

    #[test]
    fn lexer_positions_and_comments() {
        let toks = tokens("# header\nv  from\t1 #x\r\n  2\r3\n#end");
        assert_eq!(
            toks,
            vec![
                ("v".into(), 2, 1),
                ("from".into(), 2, 4),
                ("1".into(), 2, 9),
                ("2".into(), 3, 3),
                ("3".into(), 4, 1),
            ]
        );
        // A comment glued to a token ends it; columns count characters, not bytes.
        let toks = tokens("é 1#c\n2");
        assert_eq!(
            toks,
            vec![("é".into(), 1, 1), ("1".into(), 1, 3), ("2".into(), 2, 1)]
        );
        assert!(tokens("  # only a comment").is_empty());
    }

    #[test]
    fn a_lexer_started_at_a_line_numbers_lines_as_the_whole_file() {
        let src = "a\nb c\r\nd";
        let mut lx = Lexer::at(src, 2, 2, 2);
        let t = lx.next().unwrap();
        assert_eq!((t.text, t.line, t.start), ("b", 2, 2));
        lx.next();
        let t = lx.next().unwrap();
        assert_eq!((t.text, t.line, t.line_start), ("d", 3, 7));
        assert_eq!(lx.remaining(), 0);
    }
}
