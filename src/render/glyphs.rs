//! A tiny built-in bitmap font for the labels of image legends: digits and the few letters
//! numbers and their units need (`.`, `-`, `+`, `k`, `W`, `/`, `m`, `lux`, `N` for north, and
//! `E`, `U`, `a`, `v`, `i`, `n` for the grid's figures, `%` and `h` for the annual metrics),
//! 5 pixels high. Enough to label a
//! colour scale without a font file or a text-rendering crate.

/// The rows of a glyph, top to bottom, `#` for ink; `None` for characters it lacks.
fn glyph(c: char) -> Option<[&'static str; 5]> {
    Some(match c {
        '0' => ["###", "#.#", "#.#", "#.#", "###"],
        '1' => [".#.", "##.", ".#.", ".#.", "###"],
        '2' => ["###", "..#", "###", "#..", "###"],
        '3' => ["###", "..#", "###", "..#", "###"],
        '4' => ["#.#", "#.#", "###", "..#", "..#"],
        '5' => ["###", "#..", "###", "..#", "###"],
        '6' => ["###", "#..", "###", "#.#", "###"],
        '7' => ["###", "..#", "..#", "..#", "..#"],
        '8' => ["###", "#.#", "###", "#.#", "###"],
        '9' => ["###", "#.#", "###", "..#", "###"],
        '.' => [".", ".", ".", ".", "#"],
        '-' => ["...", "...", "###", "...", "..."],
        'k' => ["#..", "#.#", "##.", "#.#", "#.#"],
        'W' => ["#...#", "#...#", "#.#.#", "#.#.#", ".#.#."],
        '/' => ["..#", "..#", ".#.", "#..", "#.."],
        'm' => [".....", "####.", "#.#.#", "#.#.#", "#.#.#"],
        // For the grid's plan (src/grid): "lux", "+3.0 m", the north marker.
        'l' => ["#.", "#.", "#.", "#.", ".#"],
        'u' => ["...", "#.#", "#.#", "#.#", "###"],
        'x' => ["...", "#.#", ".#.", ".#.", "#.#"],
        '+' => ["...", ".#.", "###", ".#.", "..."],
        'N' => ["#...#", "##..#", "#.#.#", "#..##", "#...#"],
        // The grid's figures: "Eav 540 lx U0 0.15 Emin/Emax 0.05".
        'E' => ["###", "#..", "##.", "#..", "###"],
        'U' => ["#.#", "#.#", "#.#", "#.#", "###"],
        'a' => ["...", "##.", "..#", "###", "###"],
        'v' => ["...", "#.#", "#.#", "#.#", ".#."],
        'i' => ["#", ".", "#", "#", "#"],
        'n' => ["...", "##.", "#.#", "#.#", "#.#"],
        // The annual metrics' plans (src/annual): "%" of occupied hours, "h" of sun.
        '%' => ["##..#", "##.#.", "..#..", ".#.##", "#..##"],
        'h' => ["#..", "#..", "##.", "#.#", "#.#"],
        ' ' => ["..", "..", "..", "..", ".."],
        _ => return None,
    })
}

/// Glyph height in font pixels.
pub const HEIGHT: u32 = 5;

/// Width of `text` in font pixels (one pixel between glyphs; unknown characters are skipped).
pub fn width(text: &str) -> u32 {
    let ws: Vec<u32> = text
        .chars()
        .filter_map(glyph)
        .map(|g| g[0].len() as u32)
        .collect();
    ws.iter().sum::<u32>() + ws.len().saturating_sub(1) as u32
}

/// Draws `text` into `img` with its top-left corner at (x, y), each font pixel `scale` image
/// pixels wide; whatever falls outside the image is clipped.
pub fn draw(img: &mut image::RgbImage, x: i64, y: i64, scale: u32, text: &str, ink: [u8; 3]) {
    let s = scale.max(1) as i64;
    let mut cx = x;
    for g in text.chars().filter_map(glyph) {
        for (r, row) in g.iter().enumerate() {
            for (c, ch) in row.bytes().enumerate() {
                if ch != b'#' {
                    continue;
                }
                for dy in 0..s {
                    for dx in 0..s {
                        let (px, py) = (cx + c as i64 * s + dx, y + r as i64 * s + dy);
                        if px >= 0
                            && py >= 0
                            && (px as u32) < img.width()
                            && (py as u32) < img.height()
                        {
                            img.put_pixel(px as u32, py as u32, image::Rgb(ink));
                        }
                    }
                }
            }
        }
        cx += (g[0].len() as i64 + 1) * s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glyphs_are_rectangular() {
        for c in "0123456789.-kW/m lux+NEUavin%h".chars() {
            let g = glyph(c).unwrap();
            assert!(g.iter().all(|r| r.len() == g[0].len()), "{c}");
        }
    }

    #[test]
    fn drawing_clips_and_inks() {
        let mut img = image::RgbImage::new(20, 8);
        draw(&mut img, -2, 1, 1, "10", [255, 255, 255]);
        assert!(img.pixels().any(|p| p.0 == [255, 255, 255]));
        assert_eq!(width("10"), 7);
    }
}
