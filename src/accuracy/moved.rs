//! NFF scenes moved and scaled as a whole, for the invariance checks of `emray stress`
//! and `tests/stability.rs`: the same scene far from the origin, or a thousand times
//! larger or smaller, must render the same picture.
//!
//! [`move_nff`] rewrites NFF text entity by entity with every point mapped by
//! `p ↦ scale·p + shift` and every length (radii, `hither`) multiplied by `scale`, in
//! double precision, written with the shortest decimal that reads back as the same
//! `f64` (so nothing is lost that an `f64` reader could keep). Directions (`up`, vertex
//! normals), angles, colours, materials and the resolution are copied as they are.
//! Comments are dropped.

use crate::math::DVec3;

/// Why an NFF text could not be moved: it is not well-formed NFF. (The loader gives
/// the precise `file:line:col`; this tool runs on scenes that load.)
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("cannot move this NFF text: {0}")]
pub struct MoveError(String);

/// `src`, an NFF scene, with every point `p` moved to `scale·p + shift` and every
/// length scaled by `scale` (a similarity: the picture stays the same).
///
/// # Errors
/// An entity the NFF format does not have, or too few numbers after one.
pub fn move_nff(src: &str, scale: f64, shift: DVec3) -> Result<String, MoveError> {
    let mut w = Writer {
        tokens: tokens(src).peekable(),
        out: String::with_capacity(src.len() * 2),
        scale,
        shift,
    };
    while let Some(t) = w.tokens.next() {
        w.entity(t)?;
    }
    Ok(w.out)
}

/// The whitespace-separated tokens of NFF text, `#` comments left out.
fn tokens(src: &str) -> impl Iterator<Item = &str> {
    src.lines()
        .flat_map(|line| line.split('#').next().unwrap_or("").split_whitespace())
}

/// Whether a token is a number (and not the keyword of the next entity).
fn is_number(t: &str) -> bool {
    t.parse::<f64>().is_ok()
}

struct Writer<'a, I: Iterator<Item = &'a str>> {
    tokens: std::iter::Peekable<I>,
    out: String,
    scale: f64,
    shift: DVec3,
}

impl<'a, I: Iterator<Item = &'a str>> Writer<'a, I> {
    /// Copy one entity, starting at its keyword `kw`.
    fn entity(&mut self, kw: &str) -> Result<(), MoveError> {
        match kw {
            "v" => self.viewpoint(),
            "b" => self.line("b", &[Arg::Copy(3)]),
            "l" => {
                self.line("l", &[Arg::Point])?;
                // The colour is optional.
                if self.tokens.peek().is_some_and(|t| is_number(t)) {
                    self.out.pop();
                    self.copy(3)?;
                    self.out.push('\n');
                }
                Ok(())
            }
            "f" => self.line("f", &[Arg::Copy(8)]),
            "c" => self.line("c", &[Arg::Point, Arg::Length, Arg::Point, Arg::Length]),
            "s" => self.line("s", &[Arg::Point, Arg::Length]),
            "p" => self.polygon("p", &[Arg::Point]),
            "pp" => self.polygon("pp", &[Arg::Point, Arg::Copy(3)]),
            other => Err(MoveError(format!("unknown entity '{other}'"))),
        }
    }

    fn viewpoint(&mut self) -> Result<(), MoveError> {
        self.out.push_str("v\n");
        for (kw, args) in [
            ("from", &[Arg::Point][..]),
            ("at", &[Arg::Point]),
            ("up", &[Arg::Copy(3)]),
            ("angle", &[Arg::Copy(1)]),
            ("hither", &[Arg::Length]),
            ("resolution", &[Arg::Copy(2)]),
        ] {
            match self.tokens.next() {
                Some(t) if t == kw => self.line(kw, args)?,
                other => return Err(MoveError(format!("expected '{kw}', found {other:?}"))),
            }
        }
        Ok(())
    }

    /// `p`/`pp`: the vertex count, then each vertex's arguments on a line.
    fn polygon(&mut self, kw: &str, vertex: &[Arg]) -> Result<(), MoveError> {
        let n = self.next()?;
        let count: u64 = n
            .parse::<f64>()
            .ok()
            .filter(|v| v.fract() == 0.0 && *v >= 0.0)
            .map(|v| v as u64)
            .ok_or_else(|| MoveError(format!("bad vertex count '{n}'")))?;
        self.out.push_str(&format!("{kw} {n}\n"));
        for _ in 0..count {
            let start = self.out.len();
            self.args(vertex)?;
            // A vertex line starts with its first number, not a space.
            self.out.remove(start);
            self.out.push('\n');
        }
        Ok(())
    }

    /// `kw` and its arguments on one line.
    fn line(&mut self, kw: &str, args: &[Arg]) -> Result<(), MoveError> {
        self.out.push_str(kw);
        self.args(args)?;
        self.out.push('\n');
        Ok(())
    }

    fn args(&mut self, args: &[Arg]) -> Result<(), MoveError> {
        for a in args {
            match *a {
                Arg::Copy(n) => self.copy(n)?,
                Arg::Point => {
                    let p = DVec3::new(self.num()?, self.num()?, self.num()?);
                    let q = p * self.scale + self.shift;
                    for c in q.to_array() {
                        self.out.push_str(&format!(" {c:?}"));
                    }
                }
                Arg::Length => {
                    let l = self.num()? * self.scale;
                    self.out.push_str(&format!(" {l:?}"));
                }
            }
        }
        Ok(())
    }

    /// Copy `n` tokens as they are.
    fn copy(&mut self, n: usize) -> Result<(), MoveError> {
        for _ in 0..n {
            let t = self.next()?;
            self.out.push(' ');
            self.out.push_str(t);
        }
        Ok(())
    }

    fn next(&mut self) -> Result<&'a str, MoveError> {
        self.tokens
            .next()
            .ok_or_else(|| MoveError("unexpected end of text".into()))
    }

    fn num(&mut self) -> Result<f64, MoveError> {
        let t = self.next()?;
        t.parse()
            .map_err(|_| MoveError(format!("expected a number, found '{t}'")))
    }
}

/// What an entity's arguments are.
#[derive(Clone, Copy)]
enum Arg {
    /// This many tokens copied unchanged.
    Copy(usize),
    /// Three coordinates of a point: moved.
    Point,
    /// One length: scaled.
    Length,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::nff::parse_str;
    use std::path::Path;

    const SCENE: &str = "v\nfrom 0 -5 1 # eye\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.5\n\
        resolution 8 6\nb 0.1 0.2 0.3\nl 1 2 3\nl 4 5 6 0.5 0.5 0.5\nf 1 0 0 0.5 0.5 3 0 1\n\
        c 0 0 0 1 0 0 2 0.5\ns 1 1 1 0.25\np 3\n0 0 0\n1 0 0\n0 1 0\n\
        pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n";

    #[test]
    fn the_identity_keeps_the_scene() {
        let moved = move_nff(SCENE, 1.0, DVec3::ZERO).unwrap();
        let a = parse_str(SCENE, Path::new("a")).unwrap();
        let b = parse_str(&moved, Path::new("b")).unwrap();
        assert_eq!(a.camera, b.camera);
        assert_eq!(a.lights, b.lights);
        assert_eq!(a.materials, b.materials);
        assert_eq!(a.geometry.prim_count(), b.geometry.prim_count());
    }

    #[test]
    fn points_move_lengths_scale_directions_stay() {
        let moved = move_nff(SCENE, 2.0, DVec3::new(1000.0, -1000.0, 0.5)).unwrap();
        let lines: Vec<&str> = moved.lines().collect();
        assert_eq!(lines[1], "from 1000.0 -1010.0 2.5");
        assert_eq!(lines[3], "up 0 0 1");
        assert_eq!(lines[4], "angle 40");
        assert_eq!(lines[5], "hither 1.0");
        assert_eq!(lines[8], "l 1002.0 -996.0 6.5");
        assert_eq!(lines[9], "l 1008.0 -990.0 12.5 0.5 0.5 0.5");
        assert_eq!(lines[11], "c 1000.0 -1000.0 0.5 2.0 1000.0 -1000.0 4.5 1.0");
        assert_eq!(lines[12], "s 1002.0 -998.0 2.5 0.5");
        assert_eq!(lines[17], "pp 3");
        assert_eq!(lines[18], "1000.0 -1000.0 0.5 0 0 1");
        parse_str(&moved, Path::new("moved")).unwrap();
    }

    #[test]
    fn full_precision_round_trips() {
        let src = "s 0.1 0.2 0.3 0.7\n";
        let moved = move_nff(src, 1.0, DVec3::splat(1e6)).unwrap();
        let nums: Vec<f64> = moved
            .split_whitespace()
            .skip(1)
            .map(|t| t.parse().unwrap())
            .collect();
        assert_eq!(nums, vec![0.1 + 1e6, 0.2 + 1e6, 0.3 + 1e6, 0.7]);
    }

    #[test]
    fn malformed_text_is_an_error() {
        assert!(move_nff("q 1 2 3", 1.0, DVec3::ZERO).is_err());
        assert!(move_nff("s 1 2", 1.0, DVec3::ZERO).is_err());
        assert!(move_nff("p x", 1.0, DVec3::ZERO).is_err());
        assert!(move_nff("v\nat 0 0 0", 1.0, DVec3::ZERO).is_err());
    }
}
