//! One picture of every SPD database at its default size (the picture in docs/nff.md):
//! `cargo run --release --example contact_sheet -- docs/spd.png [TILE]`.

use emray::accel::Backend;
use emray::render::RenderSettings;
use emray::render::color::{Encoding, to_rgb8};
use emray::spd::Database;
use std::path::Path;

fn main() {
    let mut args = std::env::args().skip(1);
    let out = args.next().unwrap_or_else(|| "spd.png".into());
    let tile: u32 = args.next().map_or(256, |t| t.parse().expect("tile size"));
    let cols = 4u32;
    let rows = (Database::ALL.len() as u32).div_ceil(cols);
    let mut sheet = image::RgbImage::new(cols * tile, rows * tile);
    for (k, db) in Database::ALL.into_iter().enumerate() {
        let size = db.default_size();
        let scene = emray::load::nff::parse_str(&db.generate(size), Path::new(db.name()))
            .expect("generated NFF parses");
        let mut s = RenderSettings::for_scene(&scene);
        s.width = tile;
        s.height = tile;
        let (film, report) = emray::job::render_scene(
            db.name(),
            &scene,
            Backend::default_available(),
            &s,
            0.0,
            None,
        )
        .expect("render");
        eprintln!(
            "{:<9} size {size:>2}  {:>8.0} ms",
            db.name(),
            report.time_ms.render
        );
        let px = to_rgb8(&film, Encoding::Srgb);
        let (x0, y0) = ((k as u32 % cols) * tile, (k as u32 / cols) * tile);
        for j in 0..tile {
            for i in 0..tile {
                let o = ((j * tile + i) * 3) as usize;
                sheet.put_pixel(x0 + i, y0 + j, image::Rgb([px[o], px[o + 1], px[o + 2]]));
            }
        }
    }
    sheet.save(&out).expect("write the sheet");
    eprintln!("wrote {out}");
}
