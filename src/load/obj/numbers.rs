//! The numbers of the element statements `v`, `vt` and `vn`: their `f32` values (a
//! vertex divided by its weight `w`, the components of a vertex colour counted), and
//! the first problem with them as the error message will show it.
//!
//! A number that does not parse, or a weight of 0, makes the file unreadable wherever
//! it is ([`Numbers::fatal`]). Other problems (`nan`, `inf`, a number too large for
//! `f32` or for emray's range) matter only for elements that faces use, but the error
//! then names the first problem in the file.

use super::located::{Located, comment_hint, show};
use crate::scene::range;

/// The kinds of element statement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Element {
    /// `v x y z [w | r g b]`.
    Vertex,
    /// `vt u v [w]`.
    Texture,
    /// `vn x y z`.
    Normal,
}

const XYZ: [&str; 3] = ["x", "y", "z"];
const UV: [&str; 2] = ["u", "v"];

impl Element {
    fn what(self) -> &'static str {
        match self {
            Element::Vertex => "vertex",
            Element::Texture => "texture",
            Element::Normal => "normal",
        }
    }

    fn names(self) -> &'static [&'static str] {
        match self {
            Element::Texture => &UV,
            _ => &XYZ,
        }
    }
}

/// What the numbers of one statement give.
#[derive(Debug, PartialEq)]
pub(super) struct Numbers {
    /// x y z (a vertex's divided by its weight), u v (and 0), or the normal's x y z.
    pub values: [f32; 3],
    /// The same in double precision (a vertex's position in the world).
    pub exact: [f64; 3],
    /// Components of a vertex colour `r g b` read, up to the first that is no number.
    pub colours: usize,
    /// The first problem with the statement's numbers.
    pub bad: Option<Located>,
    /// A number that does not parse, or a weight of 0.
    pub fatal: bool,
}

/// Read the numbers of an element statement: `toks` are the words after its keyword
/// (all of them, or at least the first seven), `n` how many words there are.
pub(super) fn read(kind: Element, ln: usize, line: &str, toks: &[&str], n: usize) -> Numbers {
    let mut out = Numbers {
        values: [0.0; 3],
        exact: [0.0; 3],
        colours: 0,
        bad: None,
        fatal: false,
    };
    let err = |tok: Option<&str>, message: String| Located::at_token(ln, line, tok, message);
    let what = kind.what();
    for (k, name) in kind.names().iter().enumerate() {
        let Some(&tok) = toks.get(k) else {
            out.fatal = true;
            let message = format!("expected {what} {name}, found the end of the line");
            out.bad.get_or_insert_with(|| err(None, message));
            return out;
        };
        // Read in double precision; f32 judges what is finite, as the renderer holds it.
        match tok.parse::<f64>() {
            Ok(x) => {
                let v = x as f32;
                out.values[k] = v;
                out.exact[k] = x;
                if out.bad.is_none() {
                    out.bad = check_value(kind, name, v, tok).map(|m| err(Some(tok), m));
                }
            }
            Err(_) => {
                out.fatal = true;
                let message = format!(
                    "expected {what} {name}, found {}{}",
                    show(tok),
                    comment_hint(tok)
                );
                out.bad.get_or_insert_with(|| err(Some(tok), message));
            }
        }
    }
    if kind == Element::Vertex {
        match (n, toks.get(3)) {
            (4, Some(&w)) => weight(&mut out, w, &err),
            (6, _) => out.colours = colour_components(toks.get(3..6).unwrap_or_default()),
            _ => {}
        }
    }
    out
}

/// The problem with a coordinate's value `v` (read from `tok`), if any.
fn check_value(kind: Element, name: &str, v: f32, tok: &str) -> Option<String> {
    if !v.is_finite() {
        return (kind != Element::Texture).then(|| {
            format!(
                "{} {name} {} is not a finite number",
                kind.what(),
                show(tok)
            )
        });
    }
    if kind == Element::Vertex {
        return out_of_range(|| format!("vertex {name}"), v);
    }
    None
}

/// The message for a coordinate beyond emray's range, if `v` is; `what` names it.
fn out_of_range(what: impl FnOnce() -> String, v: f32) -> Option<String> {
    if v.abs() <= range::MAX_COORDINATE {
        return None;
    }
    range::check_coordinate(&what(), v)
        .err()
        .map(|e| e.to_string())
}

/// A vertex's weight `w`: the coordinates are divided by it.
fn weight(out: &mut Numbers, w_tok: &str, err: &impl Fn(Option<&str>, String) -> Located) {
    let w64 = match w_tok.parse::<f64>() {
        Ok(w) => w,
        Err(_) => {
            out.fatal = true;
            let message = format!(
                "expected vertex weight w, found {}{}",
                show(w_tok),
                comment_hint(w_tok)
            );
            out.bad.get_or_insert_with(|| err(Some(w_tok), message));
            return;
        }
    };
    let w = w64 as f32;
    if w == 0.0 {
        out.fatal = true;
        out.bad
            .get_or_insert_with(|| err(Some(w_tok), "vertex weight w is 0".into()));
        return;
    }
    if out.bad.is_none() {
        out.bad = weight_problem(out.values, w, w_tok).map(|m| err(Some(w_tok), m));
    }
    for c in &mut out.values {
        *c /= w;
    }
    for c in &mut out.exact {
        *c /= w64;
    }
}

/// The problem with dividing `xyz` by the weight `w` (not 0), if any.
fn weight_problem(xyz: [f32; 3], w: f32, w_tok: &str) -> Option<String> {
    if !w.is_finite() {
        return Some(format!(
            "vertex weight w {} is not a finite number",
            show(w_tok)
        ));
    }
    if xyz.iter().any(|c| !(c / w).is_finite()) {
        return Some(format!(
            "vertex coordinates divided by the weight w = {} are not finite",
            show(w_tok)
        ));
    }
    xyz.iter()
        .zip(XYZ)
        .find_map(|(c, name)| out_of_range(|| format!("vertex {name} / w ="), c / w))
}

/// How many of the colour components `r g b` are numbers, up to the first that is not.
fn colour_components(rgb: &[&str]) -> usize {
    rgb.iter().take_while(|t| t.parse::<f32>().is_ok()).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_line(line: &str) -> Numbers {
        let mut words = line.split_whitespace();
        let kind = match words.next() {
            Some("v") => Element::Vertex,
            Some("vt") => Element::Texture,
            _ => Element::Normal,
        };
        let toks: Vec<&str> = words.collect();
        read(kind, 1, line, &toks, toks.len())
    }

    #[test]
    fn values_and_weights() {
        let n = read_line("v 2 4 6 2");
        assert_eq!((n.values, n.bad, n.fatal), ([1.0, 2.0, 3.0], None, false));
        let n = read_line("v 0 0 0 1 0.5 x");
        assert_eq!((n.colours, n.bad, n.fatal), (2, None, false));
        let n = read_line("vt 0.25 0.5 1");
        assert_eq!(n.values, [0.25, 0.5, 0.0]);
    }

    #[test]
    fn bad_numbers() {
        let bad = |line: &str| read_line(line).bad.unwrap();
        let e = bad("v 1e8 0 0 1e-31");
        assert!(e.message.contains("divided by the weight"), "{}", e.message);
        let e = bad("v 1 2 3 w");
        assert_eq!((e.line, e.col), (1, 9));
        assert!(read_line("v 1 2 3 w").fatal);
        let n = read_line("v 1 0 0 -0");
        assert!(n.fatal && n.bad.unwrap().message.contains("weight w is 0"));
        let e = bad("v 2e9 0 0");
        assert!(e.message.contains("outside the range"), "{}", e.message);
        let e = bad("vn 0 nan 0");
        assert_eq!(e.message, "normal y 'nan' is not a finite number");
        // vt only needs numbers.
        assert!(read_line("vt inf 0").bad.is_none());
        // Colours are not looked at.
        assert!(read_line("v 0 0 0 red green blue").bad.is_none());
        // The first problem of the line is kept, and a later unparsable number is fatal.
        let n = read_line("v inf y 0");
        assert!(n.fatal && n.bad.unwrap().message.contains("vertex x"));
    }
}
