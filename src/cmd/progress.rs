//! Progress bars on a terminal: the tiles of one render.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

/// Bars are drawn unless `quiet`, and only on a terminal.
fn shown(quiet: bool) -> bool {
    !quiet && std::io::stderr().is_terminal()
}

/// A bar in `template`'s shape.
fn bar(len: u64, template: &str) -> ProgressBar {
    let b = ProgressBar::new(len);
    b.set_style(
        ProgressStyle::with_template(template)
            .expect("static template")
            .progress_chars("=> "),
    );
    b
}

/// The tiles of one render.
pub struct TileBar(Option<ProgressBar>);

impl TileBar {
    /// A bar named `name` (none when `quiet` or not on a terminal).
    pub fn new(name: &str, quiet: bool) -> Self {
        TileBar(shown(quiet).then(|| {
            let b = bar(
                0,
                "{msg} [{bar:40}] {pos}/{len} tiles {elapsed_precise} eta {eta}",
            );
            b.set_message(name.to_string());
            b
        }))
    }

    /// `done` of `total` tiles are rendered.
    pub fn set(&self, done: usize, total: usize) {
        if let Some(b) = &self.0 {
            b.set_length(total as u64);
            b.set_position(done as u64);
        }
    }

    /// The render is done: clear the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}
