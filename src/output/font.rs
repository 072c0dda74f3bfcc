//! A 5×7 bitmap font for the few words and numbers the heat maps print on their colour
//! bar (digits, a decimal point, signs, and the lowercase letters of their labels).
//! Characters it lacks are drawn as blanks.

/// Glyph width and height in font pixels; characters are set one pixel apart.
pub const GLYPH: (u32, u32) = (5, 7);

/// Each glyph as seven rows of five columns, `#` for ink.
const GLYPHS: &[(char, [&str; 7])] = &[
    (
        '0',
        [
            " ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### ",
        ],
    ),
    (
        '1',
        [
            "  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### ",
        ],
    ),
    (
        '2',
        [
            " ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####",
        ],
    ),
    (
        '3',
        [
            "#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### ",
        ],
    ),
    (
        '4',
        [
            "   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # ",
        ],
    ),
    (
        '5',
        [
            "#####", "#    ", "#### ", "    #", "    #", "#   #", " ### ",
        ],
    ),
    (
        '6',
        [
            "  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### ",
        ],
    ),
    (
        '7',
        [
            "#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   ",
        ],
    ),
    (
        '8',
        [
            " ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### ",
        ],
    ),
    (
        '9',
        [
            " ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  ",
        ],
    ),
    (
        '.',
        [
            "     ", "     ", "     ", "     ", "     ", " ##  ", " ##  ",
        ],
    ),
    (
        '-',
        [
            "     ", "     ", "     ", " ### ", "     ", "     ", "     ",
        ],
    ),
    (
        '+',
        [
            "     ", "  #  ", "  #  ", "#####", "  #  ", "  #  ", "     ",
        ],
    ),
    (
        '(',
        [
            "   # ", "  #  ", " #   ", " #   ", " #   ", "  #  ", "   # ",
        ],
    ),
    (
        ')',
        [
            " #   ", "  #  ", "   # ", "   # ", "   # ", "  #  ", " #   ",
        ],
    ),
    (
        ',',
        [
            "     ", "     ", "     ", "     ", " ##  ", "  #  ", " #   ",
        ],
    ),
    (
        'a',
        [
            "     ", "     ", " ### ", "    #", " ####", "#   #", " ####",
        ],
    ),
    (
        'c',
        [
            "     ", "     ", " ### ", "#    ", "#    ", "#   #", " ### ",
        ],
    ),
    (
        'd',
        [
            "    #", "    #", " ## #", "#  ##", "#   #", "#   #", " ####",
        ],
    ),
    (
        'e',
        [
            "     ", "     ", " ### ", "#   #", "#####", "#    ", " ### ",
        ],
    ),
    (
        'h',
        [
            "#    ", "#    ", "# ## ", "##  #", "#   #", "#   #", "#   #",
        ],
    ),
    (
        'i',
        [
            "  #  ", "     ", " ##  ", "  #  ", "  #  ", "  #  ", " ### ",
        ],
    ),
    (
        'l',
        [
            " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### ",
        ],
    ),
    (
        'm',
        [
            "     ", "     ", "## # ", "# # #", "# # #", "#   #", "#   #",
        ],
    ),
    (
        'n',
        [
            "     ", "     ", "# ## ", "##  #", "#   #", "#   #", "#   #",
        ],
    ),
    (
        'o',
        [
            "     ", "     ", " ### ", "#   #", "#   #", "#   #", " ### ",
        ],
    ),
    (
        'p',
        [
            "     ", "     ", "#### ", "#   #", "#### ", "#    ", "#    ",
        ],
    ),
    (
        'r',
        [
            "     ", "     ", "# ## ", "##  #", "#    ", "#    ", "#    ",
        ],
    ),
    (
        's',
        [
            "     ", "     ", " ####", "#    ", " ### ", "    #", "#### ",
        ],
    ),
    (
        't',
        [
            " #   ", " #   ", "###  ", " #   ", " #   ", " #  #", "  ## ",
        ],
    ),
    (
        'u',
        [
            "     ", "     ", "#   #", "#   #", "#   #", "#  ##", " ## #",
        ],
    ),
    (
        'x',
        [
            "     ", "     ", "#   #", " # # ", "  #  ", " # # ", "#   #",
        ],
    ),
    (
        'y',
        [
            "     ", "     ", "#   #", "#   #", " ####", "    #", " ### ",
        ],
    ),
];

/// The rows of `c`'s glyph, `None` for a character the font lacks.
fn glyph(c: char) -> Option<&'static [&'static str; 7]> {
    GLYPHS.iter().find(|(g, _)| *g == c).map(|(_, rows)| rows)
}

/// The width of `text` in font pixels at scale 1.
pub fn width(text: &str) -> u32 {
    let n = text.chars().count() as u32;
    if n == 0 { 0 } else { n * (GLYPH.0 + 1) - 1 }
}

/// Call `ink(x, y)` for every inked pixel of `text` set at scale `scale` with its
/// top-left at `(x0, y0)`.
pub fn draw(text: &str, x0: u32, y0: u32, scale: u32, mut ink: impl FnMut(u32, u32)) {
    let s = scale.max(1);
    for (k, c) in text.chars().enumerate() {
        let Some(rows) = glyph(c) else {
            continue;
        };
        let gx = x0 + k as u32 * (GLYPH.0 + 1) * s;
        for (r, row) in rows.iter().enumerate() {
            for (col, b) in row.bytes().enumerate() {
                if b != b'#' {
                    continue;
                }
                for dy in 0..s {
                    for dx in 0..s {
                        ink(gx + col as u32 * s + dx, y0 + r as u32 * s + dy);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_glyph_is_five_by_seven_and_the_labels_are_covered() {
        for (c, rows) in GLYPHS {
            assert!(rows.iter().all(|r| r.len() == 5), "{c}");
            assert!(rows.iter().any(|r| r.contains('#')), "{c} has ink");
        }
        for text in [
            "rays per pixel",
            "time per pixel (ns)",
            "time per pixel (us)",
            "time per pixel (ms)",
            "ray tree depth",
            "0123456789.-+e,",
        ] {
            for c in text.chars().filter(|&c| c != ' ') {
                assert!(glyph(c).is_some(), "{c:?} of {text:?}");
            }
        }
        assert_eq!(width("ab"), 11);
        let mut n = 0;
        draw("1", 0, 0, 2, |_, _| n += 1);
        assert_eq!(n, 4 * 10, "ten inked pixels, each 2×2");
    }
}
