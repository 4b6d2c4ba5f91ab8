//! The transfer-function editor: control points over the volume's density histogram.
//! Drag a point to move it (density across, opacity up), click to select it and edit
//! its colours below, double-click empty space to add a point, right-click a point to
//! remove it (two remain at least). Presets come from `assets/transfer/`; a TF can be
//! saved to and loaded from TOML (`TransferFunction::to_toml`).
//!
//! The geometry (point ↔ pixel, picking, moving with neighbours' order kept) is plain
//! functions with unit tests; [`show`] only wires them to egui.

use dvr_engine::files::Durability::Renamed;
use dvr_engine::transfer::{ControlPoint, TransferFunction};
use egui::{Color32, Pos2, Rect, Sense, Stroke};

/// Smallest density gap kept between neighbouring points (densities must increase).
const MIN_GAP: f32 = 1e-3;
/// Pick radius in points.
const PICK_RADIUS: f32 = 8.0;

pub struct TfEditor {
    pub selected: Option<usize>,
    /// The control point under a drag (a drag held counts as the view moving).
    pub dragging: Option<usize>,
    presets: Vec<String>,
    pub path: String,
    pub message: String,
}

impl TfEditor {
    pub fn new() -> Self {
        Self {
            selected: None,
            dragging: None,
            presets: TransferFunction::preset_names().unwrap_or_default(),
            path: "tf.toml".into(),
            message: String::new(),
        }
    }
}

/// Screen position of a control point in `rect`.
pub fn to_screen(rect: Rect, density: f32, opacity: f32) -> Pos2 {
    egui::pos2(
        rect.left() + density * rect.width(),
        rect.bottom() - opacity * rect.height(),
    )
}

/// (density, opacity) under a screen position, clamped to [0, 1].
pub fn from_screen(rect: Rect, p: Pos2) -> (f32, f32) {
    (
        ((p.x - rect.left()) / rect.width()).clamp(0.0, 1.0),
        ((rect.bottom() - p.y) / rect.height()).clamp(0.0, 1.0),
    )
}

/// The point nearest to `p` within the pick radius.
pub fn pick(tf: &TransferFunction, rect: Rect, p: Pos2) -> Option<usize> {
    tf.points
        .iter()
        .enumerate()
        .map(|(i, c)| (i, to_screen(rect, c.density, c.opacity).distance(p)))
        .filter(|(_, d)| *d <= PICK_RADIUS)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// Moves point `i` to (density, opacity), keeping it strictly between its neighbours.
pub fn move_point(tf: &mut TransferFunction, i: usize, density: f32, opacity: f32) {
    let lo = if i == 0 {
        0.0
    } else {
        tf.points[i - 1].density + MIN_GAP
    };
    let hi = tf.points.get(i + 1).map_or(1.0, |n| n.density - MIN_GAP);
    let p = &mut tf.points[i];
    p.density = density.clamp(lo, hi.max(lo));
    p.opacity = opacity.clamp(0.0, 1.0);
}

/// Adds a point at `density` with the TF's current colours there and `opacity`;
/// returns its index, or None where it would crowd a neighbour.
pub fn add_point(tf: &mut TransferFunction, density: f32, opacity: f32) -> Option<usize> {
    if tf
        .points
        .iter()
        .any(|p| (p.density - density).abs() < MIN_GAP)
    {
        return None;
    }
    let mut point: ControlPoint = tf.sample(density);
    point.opacity = opacity.clamp(0.0, 1.0);
    let i = tf.points.partition_point(|p| p.density < density);
    tf.points.insert(i, point);
    Some(i)
}

/// Removes point `i` unless only two remain.
pub fn remove_point(tf: &mut TransferFunction, i: usize) -> bool {
    if tf.points.len() <= 2 || i >= tf.points.len() {
        return false;
    }
    tf.points.remove(i);
    true
}

/// The data value at normalised density `d` through `window`, as the axis shows it.
pub fn axis_label(window: [f32; 2], d: f32) -> String {
    let v = window[0] + d * (window[1] - window[0]);
    let span = (window[1] - window[0]).abs();
    if span >= 100.0 {
        format!("{v:.0}")
    } else if span >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.3}")
    }
}

fn colour32(c: [f32; 3], alpha: f32) -> Color32 {
    let u = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    Color32::from_rgba_unmultiplied(u(c[0]), u(c[1]), u(c[2]), u(alpha))
}

fn rgb_edit(ui: &mut egui::Ui, label: &str, c: &mut [f32; 3]) {
    ui.horizontal(|ui| {
        ui.label(label);
        ui.color_edit_button_rgb(c);
    });
}

/// The editor widget.
/// The editor over the histogram; `window` (the data values at density 0 and 1) labels
/// its axis in the volume's data units (Hounsfield for a CT).
pub fn show(
    ui: &mut egui::Ui,
    ed: &mut TfEditor,
    tf: &mut TransferFunction,
    histogram: &[f32],
    window: [f32; 2],
) {
    let width = ui.available_width();
    let (rect, response) =
        ui.allocate_exact_size(egui::vec2(width, 130.0), Sense::click_and_drag());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_gray(18));
    // Histogram.
    let bins = histogram.len().max(1) as f32;
    for (i, h) in histogram.iter().enumerate() {
        let x0 = rect.left() + rect.width() * i as f32 / bins;
        let x1 = rect.left() + rect.width() * (i + 1) as f32 / bins;
        let bar = Rect::from_min_max(
            egui::pos2(x0, rect.bottom() - h * rect.height()),
            egui::pos2(x1, rect.bottom()),
        );
        painter.rect_filled(bar, 0.0, Color32::from_gray(60));
    }
    // Interaction first, so this frame draws the edited TF.
    let pointer = response.interact_pointer_pos();
    if response.drag_started() {
        ed.dragging = pointer.and_then(|p| pick(tf, rect, p));
        if ed.dragging.is_some() {
            ed.selected = ed.dragging;
        }
    }
    if response.dragged() {
        if let (Some(i), Some(p)) = (ed.dragging, pointer) {
            let (d, o) = from_screen(rect, p);
            move_point(tf, i, d, o);
        }
    }
    if response.drag_stopped() {
        ed.dragging = None;
    }
    if response.double_clicked() {
        if let Some(p) = pointer {
            if pick(tf, rect, p).is_none() {
                let (d, o) = from_screen(rect, p);
                if let Some(i) = add_point(tf, d, o) {
                    ed.selected = Some(i);
                }
            }
        }
    } else if response.clicked() {
        ed.selected = pointer.and_then(|p| pick(tf, rect, p));
    }
    if response.secondary_clicked() {
        if let Some(i) = pointer.and_then(|p| pick(tf, rect, p)) {
            if remove_point(tf, i) {
                ed.selected = None;
            }
        }
    }
    // Opacity curve and points.
    let line: Vec<Pos2> = tf
        .points
        .iter()
        .map(|p| to_screen(rect, p.density, p.opacity))
        .collect();
    let mut curve = Vec::with_capacity(line.len() + 2);
    curve.push(egui::pos2(rect.left(), line[0].y));
    curve.extend(line.iter().copied());
    curve.push(egui::pos2(rect.right(), line[line.len() - 1].y));
    painter.add(egui::Shape::line(curve, Stroke::new(1.5, Color32::WHITE)));
    for (i, p) in tf.points.iter().enumerate() {
        let at = to_screen(rect, p.density, p.opacity);
        let stroke = if ed.selected == Some(i) {
            Stroke::new(2.0, Color32::YELLOW)
        } else {
            Stroke::new(1.0, Color32::WHITE)
        };
        painter.circle(at, 5.0, colour32(p.diffuse, 1.0), stroke);
    }
    // Colour strip: diffuse colour weighted by opacity.
    let (strip, _) = ui.allocate_exact_size(egui::vec2(width, 10.0), Sense::hover());
    let steps = 64;
    for k in 0..steps {
        let d = (k as f32 + 0.5) / steps as f32;
        let s = tf.sample(d);
        let r = Rect::from_min_max(
            egui::pos2(
                strip.left() + strip.width() * k as f32 / steps as f32,
                strip.top(),
            ),
            egui::pos2(
                strip.left() + strip.width() * (k + 1) as f32 / steps as f32,
                strip.bottom(),
            ),
        );
        ui.painter().rect_filled(
            r,
            0.0,
            colour32(s.diffuse.map(|c| c * s.opacity.sqrt()), 1.0),
        );
    }
    // The axis, in data units.
    let (axis, _) = ui.allocate_exact_size(egui::vec2(width, 14.0), Sense::hover());
    for (k, align) in [
        (0.0, egui::Align2::LEFT_TOP),
        (0.5, egui::Align2::CENTER_TOP),
        (1.0, egui::Align2::RIGHT_TOP),
    ] {
        ui.painter().text(
            egui::pos2(axis.left() + axis.width() * k, axis.top()),
            align,
            axis_label(window, k),
            egui::FontId::proportional(11.0),
            Color32::from_gray(170),
        );
    }
    // The selected point's properties.
    if let Some(i) = ed.selected.filter(|&i| i < tf.points.len()) {
        let p = &mut tf.points[i];
        ui.label(format!("point {i}: density {:.3}", p.density));
        let mut opacity = p.opacity;
        ui.add(egui::Slider::new(&mut opacity, 0.0..=1.0).text("opacity"));
        let density = p.density;
        rgb_edit(ui, "diffuse", &mut p.diffuse);
        rgb_edit(ui, "specular", &mut p.specular);
        ui.add(egui::Slider::new(&mut p.roughness, 0.0..=1.0).text("roughness"));
        rgb_edit(ui, "emissive", &mut p.emissive);
        move_point(tf, i, density, opacity);
    }
    // Presets and files.
    ui.horizontal(|ui| {
        egui::ComboBox::from_id_salt("preset")
            .selected_text(tf.name.as_str())
            .show_ui(ui, |ui| {
                for name in &ed.presets {
                    if ui.selectable_label(*name == tf.name, name).clicked() {
                        match TransferFunction::preset(name) {
                            Ok(p) => {
                                *tf = p;
                                ed.selected = None;
                            }
                            Err(e) => ed.message = e.to_string(),
                        }
                    }
                }
            });
    });
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(&mut ed.path).desired_width(150.0));
        if ui.button("save").clicked() {
            let (path, text) = (std::path::Path::new(&ed.path), tf.to_toml());
            ed.message = match dvr_engine::files::write_atomic(path, text.as_bytes(), Renamed) {
                Ok(()) => format!("saved {}", ed.path),
                Err(e) => format!("{}: {e}", ed.path),
            };
        }
        if ui.button("load").clicked() {
            match TransferFunction::load(&ed.path) {
                Ok(loaded) => {
                    *tf = loaded;
                    ed.selected = None;
                    ed.message = format!("loaded {}", ed.path);
                }
                Err(e) => ed.message = e.to_string(),
            }
        }
    });
    if !ed.message.is_empty() {
        ui.label(egui::RichText::new(ed.message.as_str()).small());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tf() -> TransferFunction {
        TransferFunction {
            name: "t".into(),
            units: Default::default(),
            points: vec![
                ControlPoint::new(0.2, 0.0, [1.0, 0.0, 0.0]),
                ControlPoint::new(0.5, 0.5, [0.0, 1.0, 0.0]),
                ControlPoint::new(0.8, 1.0, [0.0, 0.0, 1.0]),
            ],
        }
    }

    fn rect() -> Rect {
        Rect::from_min_size(egui::pos2(10.0, 20.0), egui::vec2(200.0, 100.0))
    }

    #[test]
    fn the_axis_is_labelled_in_data_units() {
        assert_eq!(axis_label([-1024.0, 3071.0], 0.0), "-1024");
        assert_eq!(axis_label([-1024.0, 3071.0], 1.0), "3071");
        assert_eq!(axis_label([0.0, 1.0], 0.5), "0.5");
        assert_eq!(axis_label([0.0, 0.5], 0.5), "0.250");
        assert_eq!(axis_label([0.0, 10.0], 0.25), "2.5");
    }

    #[test]
    fn screen_mapping_round_trips_and_picks_the_nearest_point() {
        let r = rect();
        let p = to_screen(r, 0.5, 0.5);
        assert_eq!(p, egui::pos2(110.0, 70.0));
        let (d, o) = from_screen(r, p);
        assert!((d - 0.5).abs() < 1e-6 && (o - 0.5).abs() < 1e-6);
        assert_eq!(pick(&tf(), r, p + egui::vec2(3.0, -3.0)), Some(1));
        assert_eq!(pick(&tf(), r, egui::pos2(60.0, 30.0)), None);
    }

    #[test]
    fn moving_keeps_densities_increasing_and_values_in_range() {
        let mut t = tf();
        move_point(&mut t, 1, 0.95, 1.7);
        assert!(t.points[1].density < t.points[2].density);
        assert_eq!(t.points[1].opacity, 1.0);
        move_point(&mut t, 1, 0.0, -1.0);
        assert!(t.points[1].density > t.points[0].density);
        assert_eq!(t.points[1].opacity, 0.0);
        move_point(&mut t, 0, -5.0, 0.3);
        assert_eq!(t.points[0].density, 0.0);
        t.validate().expect("still a valid TF");
    }

    #[test]
    fn add_and_remove_keep_the_tf_valid() {
        let mut t = tf();
        let i = add_point(&mut t, 0.65, 0.9).expect("added");
        assert_eq!(i, 2);
        assert_eq!(t.points.len(), 4);
        // The new point takes the colour the TF had there.
        let g = t.points[2].diffuse;
        assert!(g[1] > 0.0 && g[2] > 0.0);
        assert_eq!(add_point(&mut t, 0.65, 0.1), None, "too close to a point");
        t.validate().expect("valid after add");
        assert!(remove_point(&mut t, 0));
        assert!(remove_point(&mut t, 0));
        assert!(!remove_point(&mut t, 0), "two points remain");
        t.validate().expect("valid after removes");
    }
}
