//! Vertex colours must be on every vertex or on none: which vertices have one, as far
//! as the first that differs from the file's first vertex.
//!
//! A stretch of the file notes its own first vertex and the first that differs from
//! it; joined in file order, the notes give the file's first vertex and its first
//! mismatch, the same as noting every vertex of the file in turn.

use super::located::Located;

/// Whether a vertex has a colour, and where its keyword is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct ColourNote {
    pub has_colour: bool,
    pub line: usize,
    pub col: usize,
}

/// The vertices of a file, or of a stretch of it, as far as colours go.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Colours {
    /// The first vertex.
    first: Option<ColourNote>,
    /// The first vertex whose colour is present where the first vertex's is not, or
    /// the other way round.
    mismatch: Option<ColourNote>,
}

impl Colours {
    /// Note the next vertex.
    pub fn note(&mut self, v: ColourNote) {
        match self.first {
            None => self.first = Some(v),
            Some(first) if first.has_colour != v.has_colour && self.mismatch.is_none() => {
                self.mismatch = Some(v);
            }
            Some(_) => {}
        }
    }

    /// Note the vertices of the stretch that follows.
    pub fn join(&mut self, next: Colours) {
        if let Some(first) = next.first {
            self.note(first);
        }
        if self.mismatch.is_none() {
            self.mismatch = next.mismatch;
        }
    }

    /// The first mismatch, as the error that reports it.
    pub fn mismatch(&self) -> Option<Located> {
        let (first, v) = (self.first?, self.mismatch?);
        let (this, that) = if v.has_colour {
            ("has a colour", "has none")
        } else {
            ("has no colour", "has one")
        };
        Some(Located {
            line: v.line,
            col: v.col,
            message: format!(
                "this vertex {this} but the first one (line {}) {that}: vertex colours \
                 must be on every vertex or on none",
                first.line
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn notes(colours: &[bool]) -> Vec<ColourNote> {
        let note = |(k, &has_colour): (usize, &bool)| ColourNote {
            has_colour,
            line: k + 1,
            col: 1,
        };
        colours.iter().enumerate().map(note).collect()
    }

    #[test]
    fn stretches_joined_note_what_the_whole_file_notes() {
        let cases: [&[bool]; 5] = [
            &[true, true, false, true],
            &[false, false, false, true],
            &[true, true],
            &[false, true, false],
            &[],
        ];
        for case in cases {
            let all = notes(case);
            let mut whole = Colours::default();
            all.iter().for_each(|&v| whole.note(v));
            for cut in 0..=all.len() {
                let (a, b) = all.split_at(cut);
                let mut first = Colours::default();
                a.iter().for_each(|&v| first.note(v));
                let mut second = Colours::default();
                b.iter().for_each(|&v| second.note(v));
                first.join(second);
                assert_eq!(first, whole, "{case:?} cut at {cut}");
            }
        }
        let mut c = Colours::default();
        notes(&[false, true]).into_iter().for_each(|v| c.note(v));
        let m = c.mismatch().unwrap();
        assert_eq!((m.line, m.col), (2, 1));
        assert!(
            m.message.contains("first one (line 1) has none"),
            "{}",
            m.message
        );
    }
}
