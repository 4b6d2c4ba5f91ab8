//! The orientation cue and the scale bar over the view: which side of the patient each
//! edge of the view faces (R/L, A/P, S/I; world space is patient RAS) and a bar of a
//! round number of millimetres at the camera target's depth.

use egui::{Align2, Color32, FontId, Stroke};
use glam::{DMat4, DVec3};

use super::cut_panel::ViewGeometry;

/// The patient axes in world space with the letters of their two ends.
const AXES: [(DVec3, &str, &str); 3] = [
    (DVec3::X, "R", "L"),
    (DVec3::Y, "A", "P"),
    (DVec3::Z, "S", "I"),
];

/// A scale bar aims at this many points long.
const BAR_POINTS: f64 = 100.0;

/// Screen direction (x right, y down; in the view's points) of a short step along `dir`
/// from `at`, or `None` when the step leaves the view frustum's front.
fn screen_step(view: &ViewGeometry, at: DVec3, dir: DVec3) -> Option<egui::Vec2> {
    let vp: DMat4 = view.view_proj.as_dmat4();
    let project = |p: DVec3| {
        let c = vp * p.extend(1.0);
        (c.w > 1e-9).then(|| {
            let ndc = c.truncate() / c.w;
            egui::vec2(
                (ndc.x * 0.5) as f32 * view.rect.width(),
                (ndc.y * 0.5) as f32 * view.rect.height(),
            )
        })
    };
    Some(project(at + dir * 0.01)? - project(at)?)
}

/// The letter at each edge of the view: (right, left, top, bottom). Each edge gets the
/// end of the patient axis that points most nearly towards it on the screen.
pub fn edge_letters(view: &ViewGeometry, target: DVec3) -> [&'static str; 4] {
    let steps: Vec<(egui::Vec2, &str, &str)> = AXES
        .iter()
        .filter_map(|&(dir, pos, neg)| Some((screen_step(view, target, dir)?, pos, neg)))
        .collect();
    // An axis along the line of sight projects to (almost) nothing: it names no edge
    // (normalising its rounding noise would point anywhere).
    let longest = steps.iter().map(|s| s.0.length()).fold(0.0f32, f32::max);
    let steps: Vec<_> = steps
        .into_iter()
        .filter(|s| s.0.length() > 1e-3 * longest)
        .collect();
    let pick = |towards: egui::Vec2| -> &'static str {
        steps
            .iter()
            .map(|&(s, pos, neg)| {
                let d = s.normalized().dot(towards);
                if d >= 0.0 {
                    (d, pos)
                } else {
                    (-d, neg)
                }
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map_or("", |(_, l)| l)
    };
    [
        pick(egui::vec2(1.0, 0.0)),
        pick(egui::vec2(-1.0, 0.0)),
        pick(egui::vec2(0.0, -1.0)),
        pick(egui::vec2(0.0, 1.0)),
    ]
}

/// The largest 1, 2 or 5 × 10^k millimetres not longer than `max_mm`.
pub fn round_length(max_mm: f64) -> f64 {
    if !(max_mm.is_finite() && max_mm > 0.0) {
        return 0.0;
    }
    let decade = 10f64.powf(max_mm.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&l| l <= max_mm)
        .unwrap_or(decade)
}

/// Draws the letters at the view's edges and the scale bar (bottom left), behind the
/// panel.
pub fn draw(ctx: &egui::Context, view: &ViewGeometry) {
    let (target, right, mm_per_unit) = (view.target, view.right, view.mm_per_unit);
    let painter = ctx
        .layer_painter(egui::LayerId::new(
            egui::Order::Background,
            egui::Id::new("orientation"),
        ))
        .with_clip_rect(view.rect);
    let font = FontId::proportional(16.0);
    let colour = Color32::from_rgb(120, 200, 255);
    let r = view.rect;
    let [right_l, left_l, top_l, bottom_l] = edge_letters(view, target);
    for (letter, pos, align) in [
        (
            right_l,
            egui::pos2(r.right() - 6.0, r.center().y),
            Align2::RIGHT_CENTER,
        ),
        (
            left_l,
            egui::pos2(r.left() + 6.0, r.center().y),
            Align2::LEFT_CENTER,
        ),
        (
            top_l,
            egui::pos2(r.center().x, r.top() + 6.0),
            Align2::CENTER_TOP,
        ),
        (
            bottom_l,
            egui::pos2(r.center().x, r.bottom() - 6.0),
            Align2::CENTER_BOTTOM,
        ),
    ] {
        painter.text(pos, align, letter, font.clone(), colour);
    }
    // Points per world unit at the target's depth, along the screen's horizontal.
    let Some(step) = screen_step(view, target, right) else {
        return;
    };
    let points_per_unit = f64::from(step.length()) / 0.01;
    let points_per_mm = points_per_unit / mm_per_unit.max(1e-9);
    let mm = round_length(BAR_POINTS / points_per_mm);
    if mm <= 0.0 {
        return;
    }
    let len = (mm * points_per_mm) as f32;
    let y = r.bottom() - 28.0;
    let x0 = r.left() + 12.0;
    let stroke = Stroke::new(2.0, colour);
    painter.line_segment([egui::pos2(x0, y), egui::pos2(x0 + len, y)], stroke);
    for x in [x0, x0 + len] {
        painter.line_segment([egui::pos2(x, y - 4.0), egui::pos2(x, y + 4.0)], stroke);
    }
    painter.text(
        egui::pos2(x0 + len * 0.5, y - 6.0),
        Align2::CENTER_BOTTOM,
        format!("{mm} mm"),
        FontId::proportional(13.0),
        colour,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use dvr_engine::scene::CameraSpec;
    use glam::Mat4;

    fn view_of(position: DVec3, up: DVec3) -> ViewGeometry {
        let spec = CameraSpec {
            position,
            target: DVec3::ZERO,
            up,
            fov_y_degrees: 40.0,
        };
        let camera = spec.camera();
        let view_proj: Mat4 = camera.view_proj(1.0);
        ViewGeometry {
            view_proj,
            forward: camera.forward().as_dvec3(),
            half: DVec3::splat(0.5),
            rect: egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(200.0, 200.0)),
            target: DVec3::ZERO,
            right: DVec3::X,
            mm_per_unit: 200.0,
        }
    }

    #[test]
    fn an_anterior_view_has_the_patients_right_on_the_left_and_superior_at_the_top() {
        let v = view_of(DVec3::new(0.0, 2.0, 0.0), DVec3::Z);
        assert_eq!(edge_letters(&v, DVec3::ZERO), ["L", "R", "S", "I"]);
    }

    #[test]
    fn a_view_from_the_left_has_anterior_on_the_left() {
        let v = view_of(DVec3::new(-2.0, 0.0, 0.0), DVec3::Z);
        assert_eq!(edge_letters(&v, DVec3::ZERO), ["P", "A", "S", "I"]);
    }

    #[test]
    fn a_view_from_below_with_anterior_up_reads_as_an_axial_slice() {
        let v = view_of(DVec3::new(0.0, 0.0, -2.0), DVec3::Y);
        assert_eq!(edge_letters(&v, DVec3::ZERO), ["L", "R", "A", "P"]);
    }

    #[test]
    fn an_axis_along_the_line_of_sight_names_no_edge_even_off_centre() {
        // The target off the view's centre line (a panned camera): +y still runs into
        // the screen, and must not win an edge through its rounding noise.
        let v = view_of(DVec3::new(0.0, 2.0, 0.0), DVec3::Z);
        for target in [DVec3::ZERO, DVec3::new(1e-7, 0.0, 1e-7)] {
            let letters = edge_letters(&v, target);
            assert!(
                !letters.contains(&"A") && !letters.contains(&"P"),
                "{letters:?}"
            );
        }
    }

    #[test]
    fn scale_bar_lengths_are_round() {
        assert_eq!(round_length(137.0), 100.0);
        assert_eq!(round_length(99.0), 50.0);
        assert_eq!(round_length(3.0), 2.0);
        assert_eq!(round_length(0.7), 0.5);
        assert_eq!(round_length(0.0), 0.0);
        assert_eq!(round_length(f64::NAN), 0.0);
    }
}
