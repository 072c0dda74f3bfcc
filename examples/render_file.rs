//! Embedding emray: render a scene file with a few options and read an output variable
//! back.
//!
//! ```sh
//! cargo run --release --example render_file -- scenes/spheres.toml
//! ```

use emray::{RenderOptions, render_file};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or("scenes/spheres.toml".into());
    let options = RenderOptions {
        res: Some("160x120".parse()?),
        aov: Some("depth".parse()?),
        ..RenderOptions::default()
    };
    let rendered = render_file(&path, &options)?;
    let (film, aov) = rendered.image().expect("a render makes an image");
    let depth = &aov.expect("depth was asked for").depth;
    let (x, y) = (film.width / 2, film.height / 2);
    let centre = depth[(y * film.width + x) as usize];
    println!(
        "{path}: {}x{}, the ray through the centre meets the scene at distance {centre}, \
         rendered in {:.1} ms on {}",
        film.width, film.height, rendered.report.time_ms.render, rendered.report.backend
    );
    Ok(())
}
