//! Preview pictures of the moulds: the print plate from above (colour =
//! height) and the assembled mould's cross-section at mid-length.

use super::canvas::{png_backend, register_fonts, PlotError, FONT};
use crate::mould::MouldSet;
use plotters::prelude::*;
use std::path::Path;

/// Draws mould `number` (1 or 2) to `path`.
pub fn draw_mould(path: &Path, set: &MouldSet, number: u8) -> Result<(), PlotError> {
    register_fonts();
    let err = |e: &dyn std::fmt::Display| PlotError::new(path, e);
    let m = &set.moulds;
    let kinds = MouldSet::kinds(number);
    let (_, placed) = set.plate(number);
    let root = png_backend(path, (1400, 1100))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (top, bottom) = root.split_vertically(620);
    // The section at true aspect on the left, notes on the right.
    let (bottom, notes) = bottom.split_horizontally(820);
    let [x0, x1] = m.x_range_mm();
    let yh = m.y_half_mm();
    let y_top = placed.last().map_or(yh, |p| p.offset_mm[1] + yh);
    let names: Vec<String> = kinds.iter().map(|k| format!("{} ({})", k.name(), k.letter())).collect();
    let mut plan = ChartBuilder::on(&top)
        .caption(
            format!("mould {number}: {} as printed, seen from above (darker = lower); clamp end left", names.join(" and ")),
            (FONT, 22),
        )
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(50)
        .build_cartesian_2d(x0 - 2.0..x1 + 2.0, -yh - 2.0..y_top + 2.0)
        .map_err(|e| err(&e))?;
    plan.configure_mesh().x_desc("x (mm)").y_desc("y on the plate (mm)").label_style((FONT, 14)).draw().map_err(|e| err(&e))?;
    // 0.25 mm cells, or larger ones on a large mould: no more cells than
    // the picture has pixels (about 1400 across, 300 per part down).
    let cell = (0.25f64).max((x1 - x0) / 1400.0).max(2.0 * yh / 300.0);
    let (zlo, zhi) = (-(m.radius_mm() + 0.5), 1.6);
    for p in &placed {
        let nx = ((x1 - x0) / cell).ceil() as usize;
        let ny = ((2.0 * yh) / cell).ceil() as usize;
        let cells = (0..nx).flat_map(|i| (0..ny).map(move |j| (i, j))).map(|(i, j)| {
            let (x, y) = (x0 + (i as f64 + 0.5) * cell, -yh + (j as f64 + 0.5) * cell);
            let z = m.height_mm(p.part, x, y);
            let t = ((z - zlo) / (zhi - zlo)).clamp(0.0, 1.0);
            let shade = (60.0 + 190.0 * t) as u8;
            let y0 = y - cell / 2.0 + p.offset_mm[1];
            Rectangle::new([(x - cell / 2.0, y0), (x + cell / 2.0, y0 + cell)], RGBColor(shade / 2, shade / 2 + 20, shade).filled())
        });
        plan.draw_series(cells).map_err(|e| err(&e))?;
    }
    // Section of the assembled mould at mid-length.
    let x_mid = m.length_mm() / 2.0;
    let w = m.params().wall_mm;
    let zb = m.radius_mm() + w;
    let mut sec = ChartBuilder::on(&bottom)
        .caption(format!("assembled, section at x = {x_mid:.1} mm seen from the tip (cutting plane z = 0)"), (FONT, 20))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(50)
        .build_cartesian_2d(-yh - 1.0..yh + 1.0, -zb - 1.0..zb + 1.0)
        .map_err(|e| err(&e))?;
    sec.configure_mesh().x_desc("y (mm)").y_desc("z (mm)").label_style((FONT, 14)).draw().map_err(|e| err(&e))?;
    let colours = [RGBColor(90, 110, 170), RGBColor(200, 140, 60)];
    for (kind, colour) in kinds.iter().zip(colours) {
        let s = kind.frame_sign();
        // Back face of the part in the assembly frame.
        let back = s * m.z_bottom_mm(*kind);
        // Seen from the tip (looking towards −x) +y is to the right.
        let mut poly: Vec<(f64, f64)> = m.section_mm(*kind, x_mid);
        poly.sort_by(|a, b| a.0.total_cmp(&b.0));
        poly.push((poly.last().map_or(yh, |p| p.0), back));
        poly.push((poly[0].0, back));
        sec.draw_series(std::iter::once(Polygon::new(poly.clone(), colour.mix(0.6).filled())))
            .map_err(|e| err(&e))?
            .label(format!("{} ({})", kind.name(), kind.letter()))
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], colour.filled()));
    }
    let rho = m.params().tube_diameter_mm / 2.0;
    let circle = |cx: f64, r: f64| (0..=72).map(move |k| {
        let a = k as f64 * std::f64::consts::TAU / 72.0;
        (cx + r * a.cos(), r * a.sin())
    });
    sec.draw_series(std::iter::once(PathElement::new(circle(0.0, m.radius_mm()).collect::<Vec<_>>(), BLACK.stroke_width(1))))
        .map_err(|e| err(&e))?
        .label("body outline (r)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], BLACK));
    let one = m.channels().len() == 1;
    let tube_label = match (number, one) {
        (1, true) => "channel (the lid's protrusion)",
        (1, false) => "channels (the lid's protrusions)",
        (_, true) => "PTFE tube in the groove",
        (_, false) => "PTFE tubes in the grooves",
    };
    let ycs: Vec<f64> = (0..m.channels().len()).map(|k| m.channel_y_mm(k, x_mid)).collect();
    let label = match ycs.as_slice() {
        [yc] => format!("{tube_label}, y_c = {yc:.2} mm"),
        several => format!("{tube_label}, y_c = {} mm (cables 1..{})", several.iter().map(|y| format!("{y:.2}")).collect::<Vec<_>>().join(", "), several.len()),
    };
    sec.draw_series(ycs.iter().map(|yc| PathElement::new(circle(*yc, rho).collect::<Vec<_>>(), RED.stroke_width(2))))
        .map_err(|e| err(&e))?
        .label(label)
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], RED));
    sec.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 14))
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(|e| err(&e))?;
    let cl = m.params().clearance_mm;
    let lines = if number == 1 {
        vec![
            "Mould 1 (first casting): tray T + lid 1.".to_string(),
            "Lay the lid on the tray mating faces together,".to_string(),
            "pins in holes (they fit one way only).".to_string(),
            "Stand it on the tip end and pour silicone".to_string(),
            "into the opening at the clamp end (CL).".to_string(),
            "The lid's protrusion leaves the groove.".to_string(),
        ]
    } else {
        vec![
            "Mould 2 (second casting): tray T + cover 2.".to_string(),
            "Leave the half body in the tray, lay the".to_string(),
            "PTFE tube in its groove (out through the".to_string(),
            "notch at the tip and the clamp-end opening),".to_string(),
            "close with the cover and pour at CL.".to_string(),
            "Pull the tube out after curing.".to_string(),
        ]
    };
    let mut all = lines;
    all.push(String::new());
    all.push(format!("L = {} mm, r = {} mm, clamp block {} mm", m.length_mm(), m.radius_mm(), m.params().clamp_mm));
    all.push(format!("tube Ø {} mm, clearance {cl} mm, wall {} mm", m.params().tube_diameter_mm, m.params().wall_mm));
    for (k, c) in m.channels().iter().enumerate() {
        let ys = c.control_points_mm().iter().map(|y| format!("{y:.2}")).collect::<Vec<_>>().join(", ");
        all.push(if m.channels().len() == 1 { format!("y0..y4 = [{ys}] mm") } else { format!("cable {}: y0..y4 = [{ys}] mm", k + 1) });
    }
    all.push("Marks: 'CL' = clamp end, arrow + '+Y' = +y side;".to_string());
    all.push("text reading backwards = mirrored print.".to_string());
    for (i, line) in all.iter().enumerate() {
        notes.draw(&Text::new(line.clone(), (20, 40 + 26 * i as i32), (FONT, 18))).map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
