//! The pixel font of the orientation marks engraved in each part's mating
//! face ("CL", "+Y", the arrows and the part's letter): glyph tables and
//! the rectangles a text's pixels cover.

/// Pixel size of the marks, mm.
pub(super) const PIXEL_MM: f64 = 0.8;

/// The pixel font of the marks (rows top to bottom, '#' engraved; 3 wide,
/// the arrows 5). No two pixels touch only at a corner, so the engraving
/// stays 2-manifold.
pub(super) fn glyph(c: char) -> &'static [&'static str] {
    match c {
        'C' => &["###", "#..", "#..", "#..", "###"],
        'L' => &["#..", "#..", "#..", "#..", "###"],
        'T' => &["###", ".#.", ".#.", ".#.", ".#."],
        'Y' => &["#.#", "#.#", "###", ".#.", ".#."],
        '+' => &["...", ".#.", "###", ".#.", "..."],
        '1' => &["##.", ".#.", ".#.", ".#.", "###"],
        '2' => &["###", "..#", "###", "#..", "###"],
        '^' => &["..#..", ".###.", "#####", "..#..", "..#.."],
        'v' => &["..#..", "..#..", "#####", ".###.", "..#.."],
        _ => &["...", "...", "...", "...", "..."],
    }
}

/// Width of `text` in the mark font, mm.
pub(super) fn text_width_mm(text: &str) -> f64 {
    text.chars().map(|c| (glyph(c)[0].len() + 1) as f64 * PIXEL_MM).sum::<f64>() - PIXEL_MM
}

/// Pixel rectangles ([x0, x1], [y0, y1]) of `text` from `x_left`, centred on
/// `y_centre`, read left to right with the glyphs' tops towards +y.
pub(super) fn text_pixels(text: &str, x_left: f64, y_centre: f64) -> Vec<([f64; 2], [f64; 2])> {
    let p = PIXEL_MM;
    let top = y_centre + 2.5 * p;
    let mut out = Vec::new();
    let mut x = x_left;
    for c in text.chars() {
        for (row, line) in glyph(c).iter().enumerate() {
            // Runs of pixels in a row become one rectangle.
            let cells: Vec<bool> = line.chars().map(|ch| ch == '#').collect();
            let mut k = 0;
            while k < cells.len() {
                if cells[k] {
                    let start = k;
                    while k < cells.len() && cells[k] {
                        k += 1;
                    }
                    out.push(([x + start as f64 * p, x + k as f64 * p], [top - (row + 1) as f64 * p, top - row as f64 * p]));
                } else {
                    k += 1;
                }
            }
        }
        x += (glyph(c)[0].len() + 1) as f64 * p;
    }
    out
}

