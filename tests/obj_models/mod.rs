//! OBJ models the integration tests share: hand-written models, well-formed and not,
//! a grid generator, random mutations of a model, and how a load is compared. Each
//! test file that needs them declares `mod obj_models;`.
#![allow(dead_code)]

use emray::load::LoadError;
use emray::load::obj::ObjData;
use std::fmt::Write as _;

/// The library the models name.
pub const MTL: &str = "newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\nnewmtl c\nKd 0 0 1\n";

pub const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// A grid of `n` × `n` quads with texture coordinates and normals, its faces written
/// with relative indices after each row's vertices (they reach back across rows).
pub fn grid(n: usize, colours: bool) -> String {
    let mut s = String::from("mtllib m.mtl\no grid\ns 1\n");
    let row = n + 1;
    for j in 0..=n {
        for i in 0..=n {
            let c = if colours { " 0.5 0.25 1" } else { "" };
            writeln!(s, "v {i} {j} {}{c}\nvt {} {}", (i * j) % 3, i, j).unwrap();
        }
        writeln!(s, "vn 0 0 1").unwrap();
        if j == 0 {
            continue;
        }
        writeln!(s, "usemtl {}", ["a", "b", "c"][j % 3]).unwrap();
        for i in 0..n {
            // Vertex i of this row is -(row - i); of the row before, -(2 row - i).
            let (a, b) = (2 * row - i, 2 * row - i - 1);
            let (c, d) = (row - i - 1, row - i);
            writeln!(s, "f -{a}/-{a}/-1 -{b}/-{b}/-1 -{c}/-{c}/-1 -{d}/-{d}/-1").unwrap();
        }
    }
    s
}

/// Models, well-formed and not.
pub fn models() -> Vec<String> {
    let mut m = vec![
        grid(3, false),
        grid(2, true),
        format!("# forward references within a run\nf 1 2 3\nf -1 2 3\n{TRI}g next\nf 3 2 1\n"),
        format!("f 1 2 3\ng x\n{TRI}"),
        format!("usemtl a\nf 1 2 3\nusemtl b\n{TRI}mtllib m.mtl\nusemtl c\nf 1 2 3\n"),
        format!("mtllib m.mtl\nusemtl a\nf 1 2 3\nusemtl a\n{TRI}usemtl zz\nf 1 2 3\n"),
        format!("{TRI}vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nf 1//1 2//1 3//1\nf 1/1 2/1 3/1\n"),
        format!("f 1/1/1 2/1/1 3/1/1\ng\nvt 0 0\nvn 0 0 1\n{TRI}f 1/1/1 2/1/1 3/1/1\n"),
        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n".into(),
        "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nf 1 2 3\n".into(),
        "v 0 0 0\nv 1 0 0 1 1 1\nv 0 1 0\nf 1 2 3\n".into(),
        "v 0 0 0 r g b\nv 1 0 0 1 1 1\nv 0 1 0 1 1 1\nf 1 2 3\n".into(),
        "v 0 0 0 1 1 1\nv 1 0 0 1 1 1\nf 1 2 3\nv 0 1 0\n".into(),
        format!("s 1\n{TRI}f 1 2 3\ns off\nf 1 3 2\ns 2\no a\nf 3 2 1\ns\ng b c\nf 1 2 3\n"),
        format!("\u{feff}{TRI}f 1 2 3\n"),
        format!(
            "{}f 1 2 3\r\n\r\n# comment\r\nf 3 2 1",
            TRI.replace('\n', "\r\n")
        ),
        format!("\n\n  # indented comment\n\t{TRI}  f 1 2 3  \nl 1 2\nl\n\n"),
        format!("g é\n{TRI}f 1 2 é\n"),
        format!("{TRI}v 0 0 1 2\nv 1 1 1 0.5\nf -1 -2 -3 1\nvt inf 0\nf 1/1 2/1 3/1\n"),
        format!("{TRI}vn nan 0 0\nvn 0 0 1\nf 1 2//2 3//2\n"),
        format!("{TRI}v 1e10 0 0\nf 1 2 4\n"),
        format!("{TRI}v 0 0 zero\nf 1 2 3\nf 1 2 0\n"),
        format!("{TRI}f 1 2 3\nv 0 0 inf\nf 1 2 -5\n"),
        format!("{TRI}f 1 2 3\nf 1 2 9\nv 0 0 x\n"),
        format!("{TRI}f 1 2 0\n"),
        format!("{TRI}f 1 2 -4\n"),
        format!("{TRI}f 1 2 3/1/1/1\n"),
        format!("{TRI}f 1 2 3 # a comment\n"),
        format!("{TRI}usemtl\nf 1 2 3\n"),
        format!("{TRI}f\n"),
        format!("{TRI}f 1 2 x\n"),
        format!("{TRI}f 1 2 /3\n"),
        format!("{TRI}v 1 2\n"),
        format!("{TRI}v 1 2 3 4 5\n"),
        format!("{TRI}v 1 2 3 0\nf 1 2 3\n"),
        format!("{TRI}vt 1\n"),
        format!("{TRI}vn 1 2\n"),
        format!("f 7 1 1\nf 1 1 1/9\nf 1/1 1/1 1/1\n{TRI}vt 0 0\n"),
        format!("{TRI}f 1 2 3\ng\nf 1 2 99999999999999999999999\n"),
    ];
    m.push(m.concat());
    m
}

/// A deterministic random number generator (xorshift64*).
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    pub fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len())]
    }
}

/// Words a mutation puts in place of another.
pub const WORDS: [&str; 20] = [
    "0", "1", "2", "-1", "-2", "-9", "7", "x", "nan", "inf", "1e39", "1/1/1", "2//1", "1/2",
    "-1/-1/-1", "1/1/1/1", "#", "usemtl", "g", "é",
];

/// Statements a mutation inserts.
pub const STATEMENTS: [&str; 16] = [
    "v 0 0 0",
    "v 1 2 3 0.5 0.5 0.5",
    "vt 0.5 0.5",
    "vn 0 1 0",
    "f 1 2 3",
    "f -1 -2 -3",
    "f 1/1/1 2/2/2 3/3/3",
    "g",
    "o thing",
    "usemtl a",
    "usemtl b",
    "usemtl nope",
    "s 1",
    "s off",
    "mtllib m.mtl",
    "# comment",
];

/// `src` with one random change: a line dropped, doubled, swapped or inserted, a word
/// replaced, a line break made CRLF, or a character dropped.
pub fn mutate(src: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = src.split('\n').map(String::from).collect();
    let k = rng.below(lines.len());
    match rng.below(7) {
        0 => drop(lines.remove(k)),
        1 => lines.insert(k, lines[k].clone()),
        2 => {
            let j = rng.below(lines.len());
            lines.swap(k, j);
        }
        3 => lines.insert(k, rng.pick(&STATEMENTS).to_string()),
        4 => {
            let words: Vec<&str> = lines[k].split(' ').collect();
            let w = rng.below(words.len());
            let mut words: Vec<String> = words.iter().map(|s| s.to_string()).collect();
            words[w] = rng.pick(&WORDS).to_string();
            lines[k] = words.join(" ");
        }
        5 => lines[k].push('\r'),
        _ => {
            let chars: Vec<char> = lines[k].chars().collect();
            if !chars.is_empty() {
                let c = rng.below(chars.len());
                lines[k] = chars
                    .iter()
                    .enumerate()
                    .filter(|&(i, _)| i != c)
                    .map(|(_, c)| c)
                    .collect();
            }
        }
    }
    lines.join("\n")
}

/// The model or error as compared: its `Debug` form, where NaN equals NaN and -0 is not
/// 0 (the triangles' origins do not show: compare them with `same_origins`).
pub fn shown(r: &Result<ObjData, LoadError>) -> String {
    match r {
        Ok(d) => format!("{d:?}"),
        Err(e) => format!("{e:?}: {e}"),
    }
}

/// A folder with the library the models name, `m.mtl`.
pub fn library_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.mtl"), MTL).unwrap();
    dir
}
