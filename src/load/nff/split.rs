//! Cutting an NFF file into stretches that can be parsed apart.
//!
//! A stretch starts at a line whose first token is an entity keyword: there, as far as
//! the text shows, one entity ends and the next begins (an entity's numbers may run
//! over several lines, but a keyword on its own line is no number). The guess is
//! checked when the stretches are joined: each stretch must end just where the next
//! one's first token starts (see `super::parse_in_stretches`).

use super::lexer::is_space;

/// The entity keywords.
const KEYWORDS: [&[u8]; 8] = [b"v", b"b", b"l", b"f", b"c", b"s", b"p", b"pp"];

/// Where the stretches start: at 0, then at the first line that starts an entity at
/// least `target` bytes after the last start.
pub(super) fn cut(src: &str, target: usize) -> Vec<usize> {
    let b = src.as_bytes();
    let mut starts = vec![0];
    let mut from = target.max(1);
    while from < b.len() {
        match next_entity_line(b, from) {
            Some(start) => {
                starts.push(start);
                from = start + target.max(1);
            }
            None => break,
        }
    }
    starts
}

/// The first line start at or after byte `from`'s line's end whose first token is an
/// entity keyword.
fn next_entity_line(b: &[u8], mut from: usize) -> Option<usize> {
    loop {
        let start = line_after(b, from)?;
        if starts_entity(&b[start..]) {
            return Some(start);
        }
        from = start;
    }
}

/// The start of the line after the one byte `from` is on (`None` at the last line).
fn line_after(b: &[u8], from: usize) -> Option<usize> {
    let end = from + b[from..].iter().position(|&c| c == b'\n' || c == b'\r')?;
    match (b[end], b.get(end + 1)) {
        (b'\r', Some(b'\n')) => Some(end + 2),
        _ => Some(end + 1),
    }
    .filter(|&s| s < b.len())
}

/// Whether `line`'s first token (after blanks) is an entity keyword.
fn starts_entity(line: &[u8]) -> bool {
    let Some(start) = line.iter().position(|&c| c != b' ' && c != b'\t') else {
        return false;
    };
    let rest = &line[start..];
    let len = rest
        .iter()
        .position(|&c| is_space(c) || c == b'#')
        .unwrap_or(rest.len());
    KEYWORDS.contains(&&rest[..len])
}

/// How many bytes of `bytes` are `byte` (counted in byte-wide lanes, 255 at a time,
/// which the compiler vectorises).
fn count(bytes: &[u8], byte: u8) -> usize {
    bytes
        .chunks(255)
        .map(|c| c.iter().fold(0u8, |n, &x| n + u8::from(x == byte)) as usize)
        .sum()
}

/// The line breaks in `b[from..to]` (a LF, or a CR that no LF follows), as the lexer
/// counts them.
pub(super) fn line_breaks(b: &[u8], from: usize, to: usize) -> usize {
    let part = &b[from..to];
    let lf = count(part, b'\n');
    if !part.contains(&b'\r') {
        return lf;
    }
    let lone_cr = (from..to)
        .filter(|&i| b[i] == b'\r' && b.get(i + 1) != Some(&b'\n'))
        .count();
    lf + lone_cr
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretches_start_at_lines_that_start_entities() {
        let src = "v\nfrom 0 0 0\ns 1 2 3 4\n  p 3\n1 2 3\r\n1 2 3\n\tpp 1\nsx 1\nf 1 1";
        let starts = cut(src, 1);
        let heads: Vec<&str> = starts.iter().map(|&s| &src[s..s + 2]).collect();
        assert_eq!(heads, ["v\n", "s ", "  ", "\tp", "f "]);
        assert_eq!(cut(src, 1000), [0]);
        assert_eq!(cut("", 1), [0]);
    }

    #[test]
    fn line_breaks_count_crlf_once_and_lone_cr() {
        let b = b"a\r\nb\rc\nd\r";
        assert_eq!(line_breaks(b, 0, b.len()), 4);
        assert_eq!(line_breaks(b, 3, 6), 1);
        assert_eq!(line_breaks(b, 0, 0), 0);
    }
}
