//! Exports of a design: JSON, the channel centreline as CSV, a 1:1 SVG
//! drawing of the body with its channel (for making a mould), and a PNG of
//! the achieved shape over the target.

use super::objective::{Evaluation, Objective};
use super::targets::Quantity;
use super::record::DesignRecord;
use super::DesignError;
use crate::io::FileError;
use crate::model::Routing;
use crate::solver::simulate;
use crate::shape::centreline_from_coefficients;
use std::fmt::Write as _;
use std::path::Path;

/// Refuses an export directory inside a sweep's run directory.
pub fn check_export_dir(dir: &Path) -> Result<(), DesignError> {
    Ok(crate::io::check_outside_run_dir(dir, "the export directory")?)
}

/// A design's export directory being written: each file written
/// atomically, the names kept in the order written, so that what is
/// reported is what was written.
pub(super) struct Export<'a> {
    dir: &'a Path,
    written: Vec<String>,
}

impl<'a> Export<'a> {
    /// Checks `dir` (outside any run directory) and creates it if missing.
    pub(super) fn create(dir: &'a Path) -> Result<Self, DesignError> {
        check_export_dir(dir)?;
        std::fs::create_dir_all(dir).map_err(FileError::on("creating", dir))?;
        Ok(Self { dir, written: Vec::new() })
    }

    /// Writes the file `name`.
    pub(super) fn write(&mut self, name: &str, bytes: &[u8]) -> Result<(), DesignError> {
        let path = self.dir.join(name);
        crate::io::write_atomic(&path, bytes).map_err(FileError::on("writing", &path))?;
        self.written.push(name.to_string());
        Ok(())
    }

    /// Draws the picture `name` by `draw` (given its path).
    pub(super) fn draw(&mut self, name: &str, draw: impl FnOnce(&Path) -> Result<(), DesignError>) -> Result<(), DesignError> {
        draw(&self.dir.join(name))?;
        self.written.push(name.to_string());
        Ok(())
    }

    /// The names of the files written, in order.
    pub(super) fn written(self) -> Vec<String> {
        self.written
    }
}

/// A 1:1 drawing of the straight body (L × 2r) with its channel, in mm
/// (`width="…mm"` with a viewBox in mm, so it prints at true size). The
/// clamp end is on the left; y grows upward as in the model.
pub fn mould_svg(routing: &Routing, radius_mm: f64, channel_diameter_mm: f64, tension_n: f64) -> String {
    let length = routing.length_mm();
    let margin = 10.0;
    let (w, h) = (length + 2.0 * margin, 2.0 * radius_mm + 2.0 * margin + 16.0);
    // Model (s, y) → page (margin + s, margin + r − y).
    let px = |s: f64| margin + s;
    let py = |y: f64| margin + radius_mm - y;
    let mut svg = String::new();
    let _ = writeln!(svg, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}mm" height="{h}mm" viewBox="0 0 {w} {h}" font-family="sans-serif">"#
    );
    let _ = writeln!(svg, "<title>cablemap mould drawing, 1:1, units mm</title>");
    // Body outline.
    let _ = writeln!(
        svg,
        r#"<rect id="body" x="{}" y="{}" width="{length}" height="{}" fill="none" stroke="black" stroke-width="0.2"/>"#,
        px(0.0),
        py(radius_mm),
        2.0 * radius_mm
    );
    // Body axis.
    let _ = writeln!(
        svg,
        r#"<line id="axis" x1="{}" y1="{}" x2="{}" y2="{}" stroke="grey" stroke-width="0.1" stroke-dasharray="2 1"/>"#,
        px(0.0),
        py(0.0),
        px(length),
        py(0.0)
    );
    // Clamp face.
    let _ = writeln!(
        svg,
        r#"<line id="clamp" x1="{0}" y1="{1}" x2="{0}" y2="{2}" stroke="black" stroke-width="0.8"/>"#,
        px(0.0),
        py(radius_mm + 2.0),
        py(-radius_mm - 2.0)
    );
    let points: String =
        routing.channel_samples().iter().map(|(s, y, _)| format!("{:.4},{:.4}", px(*s), py(*y))).collect::<Vec<_>>().join(" ");
    // The channel at its real width, then its centreline.
    let _ = writeln!(
        svg,
        r#"<polyline id="channel" points="{points}" fill="none" stroke="red" stroke-opacity="0.35" stroke-width="{channel_diameter_mm}" stroke-linecap="round"/>"#
    );
    let _ = writeln!(svg, r#"<polyline id="channel-centreline" points="{points}" fill="none" stroke="red" stroke-width="0.1"/>"#);
    for (i, y) in routing.control_points_mm().iter().enumerate() {
        let s = i as f64 * length / 4.0;
        let _ = writeln!(
            svg,
            r#"<circle class="control-point" cx="{:.4}" cy="{:.4}" r="0.35" fill="none" stroke="blue" stroke-width="0.1"/>"#,
            px(s),
            py(*y)
        );
        // Labelled on the side away from the channel, so a mirrored print reads wrong.
        let above = *y < 0.0;
        let _ = writeln!(
            svg,
            r#"<text class="control-point-label" x="{:.4}" y="{:.4}" font-size="1.6" fill="blue" text-anchor="middle">y{i}</text>"#,
            px(s),
            if above { py(*y) - 0.9 } else { py(*y) + 2.2 }
        );
    }
    // Orientation: +y points up the page; the drawing is the cutting plane
    // seen from the mould's open face; the clamp end is on the left.
    let (ax, ay) = (px(length) + 3.0, py(0.0));
    let _ = writeln!(
        svg,
        r#"<g id="orientation"><line x1="{ax}" y1="{ay}" x2="{ax}" y2="{}" stroke="black" stroke-width="0.3"/><path d="M {} {} L {ax} {} L {} {} Z" fill="black"/><text x="{}" y="{}" font-size="2">+y</text></g>"#,
        ay - radius_mm,
        ax - 0.8,
        ay - radius_mm + 1.6,
        ay - radius_mm - 0.2,
        ax + 0.8,
        ay - radius_mm + 1.6,
        ax - 1.4,
        ay + 2.8
    );
    let _ = writeln!(svg, r#"<text id="clamp-label" x="{}" y="{}" font-size="2">CLAMP</text>"#, px(0.0) + 0.5, py(radius_mm) - 1.0);
    // 10 mm scale bar to check the print scale.
    let bar_y = py(-radius_mm) + 6.0;
    let _ = writeln!(
        svg,
        r#"<line id="scale-10mm" x1="{}" y1="{bar_y}" x2="{}" y2="{bar_y}" stroke="black" stroke-width="0.4"/>"#,
        px(0.0),
        px(10.0)
    );
    let ys = routing.control_points_mm().iter().map(|y| format!("{y:.3}")).collect::<Vec<_>>().join(", ");
    // Short lines at 2 mm so the notes stay inside the page at 1:1.
    let notes = [
        "10 mm".to_string(),
        format!("L = {length} mm, r = {radius_mm} mm, channel Ø {channel_diameter_mm} mm; clamp on the left"),
        "seen from mould 1's open face, +y up: mirrored, it bends the other way".to_string(),
        format!("y0..y4 = [{ys}] mm"),
        format!("tension {tension_n:.3} N"),
    ];
    let _ = writeln!(svg, r#"<text x="{}" y="{}" font-size="2">{}</text>"#, px(11.0), bar_y + 0.7, notes[0]);
    for (i, line) in notes[1..].iter().enumerate() {
        let _ = writeln!(svg, r#"<text x="{}" y="{}" font-size="2">{line}</text>"#, px(0.0), bar_y + 3.5 + 2.6 * i as f64);
    }
    svg.push_str("</svg>\n");
    svg
}

/// Writes design.json, channel.csv, mould.svg (the channel drawn
/// `tube_diameter_mm` wide) and shape.png into `dir` (created if missing)
/// and returns the names of the files written, in order, so that what is
/// reported is what was written. mould.svg, a drawing of the uniform
/// cylinder's mould, is left out for a non-uniform body (radius profile,
/// segments, cable anchor); channel.csv then runs over the cable, [0, s_k].
pub fn write_all(
    dir: &Path,
    objective: &Objective,
    eval: &Evaluation,
    record: &DesignRecord,
    tube_diameter_mm: f64,
) -> Result<Vec<String>, DesignError> {
    let mut export = Export::create(dir)?;
    export.write("design.json", record.to_file_text().as_bytes())?;
    let act = &objective.rod;
    let routing = Routing::for_actuator(&eval.routing_mm, act)?;
    export.write("channel.csv", routing.channel_csv().as_bytes())?;
    if act.is_uniform_body() {
        export.write("mould.svg", mould_svg(&routing, act.radius_mm, tube_diameter_mm, eval.tension_n).as_bytes())?;
    }
    export.draw("shape.png", |path| shape_png(path, objective, eval))?;
    Ok(export.written())
}

/// Draws the achieved body over the target: the target tip as a cross and,
/// when the target has curvature coefficients, the target shape. The target
/// states no length or base angle, so its shape is drawn with the achieved
/// design's ℓ and θ_0 (coefficients the target omits are the achieved ones).
pub fn shape_png(path: &Path, objective: &Objective, eval: &Evaluation) -> Result<(), DesignError> {
    let act = &objective.rod;
    let routing = Routing::for_actuator(&eval.routing_mm, act)?;
    let sim = simulate(act, &objective.options, &routing, eval.tension_n, objective.target.order(), objective.length_basis)?;
    let target = &objective.target;
    // Drawing needs the coefficients over the drawn (deformed) length ℓ.
    let target_centreline = target.highest_order().map(|_| {
        let pose = &eval.pose;
        let to_deformed = 1.0 / objective.length_basis.factor_from_deformed(pose.length_mm, act.length_mm);
        let a: Vec<f64> = (0..eval.a.len()).map(|k| to_deformed * target.get(Quantity::BendZ(k)).unwrap_or(eval.a[k])).collect();
        centreline_from_coefficients(&a, pose.length_mm, pose.base_angle_rad, 121)
    });
    let tip = target.get(Quantity::TipX).zip(target.get(Quantity::TipY));
    let title = format!(
        "design: y = [{}] mm, τ = {:.3} N",
        eval.routing_mm.iter().map(|y| format!("{y:.2}")).collect::<Vec<_>>().join(", "),
        eval.tension_n
    );
    crate::plot::draw_design_shape(path, &title, &sim, act, target_centreline.as_deref(), tip)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_csv_follows_the_spline_from_clamp_to_tip() {
        let r = Routing::new(&[1.0, -2.0, 3.0, 0.5, -4.0], 65.0, 5.0).unwrap();
        let csv = r.channel_csv();
        let rows: Vec<Vec<f64>> =
            csv.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
        assert_eq!(rows.first().unwrap()[0], 0.0);
        assert!((rows.last().unwrap()[0] - 65.0).abs() < 1e-9);
        // Clamped spline: interpolates the end control points.
        assert!((rows.first().unwrap()[1] - 1.0).abs() < 1e-9);
        assert!((rows.last().unwrap()[1] + 4.0).abs() < 1e-9);
        assert!(rows.iter().all(|row| row[1].abs() <= 4.0 + 1e-9));
    }

    #[test]
    fn mould_svg_is_true_scale() {
        let r = Routing::new(&[0.0, 1.0, 2.0, 1.0, 0.0], 65.0, 5.0).unwrap();
        let svg = mould_svg(&r, 5.0, 1.0, 1.5);
        assert!(svg.contains(r#"width="85mm""#) && svg.contains(r#"viewBox="0 0 85 46""#), "{svg}");
        assert!(svg.contains(r#"<rect id="body" x="10" y="10" width="65" height="10""#));
        assert_eq!(svg.matches("class=\"control-point\"").count(), 5);
        // Orientation marks: labelled control points, a +y arrow, the clamp end.
        for i in 0..5 {
            assert!(svg.contains(&format!(">y{i}</text>")), "y{i}");
        }
        assert!(svg.contains(r#"<g id="orientation">"#) && svg.contains(">+y</text>") && svg.contains(">CLAMP</text>"));
    }
}
