//! The panel's cut section (clip planes: add, remove, switch, flip, drag the offset,
//! align to the view; the crop box: switch and six sliders) and the outline of the
//! cut drawn over the view (each enabled plane where it meets the volume's box, the
//! crop box's edges).

use dvr_engine::scene::{ClipPlane, CropBox, CropUnits, Cut, MAX_CLIP_PLANES};
use egui::{Color32, RichText};
use glam::{DMat4, DVec3, Mat4};

/// What the cut section and the outline need of the view this frame.
#[derive(Clone, Copy, Debug)]
pub struct ViewGeometry {
    /// World → clip of the shown view.
    pub view_proj: Mat4,
    /// Unit direction the camera looks.
    pub forward: DVec3,
    /// Half the volume's box, world units.
    pub half: DVec3,
    /// The shown view's rectangle, in points.
    pub rect: egui::Rect,
    /// The camera's target and unit right vector, world space (the scale bar's depth
    /// and direction).
    pub target: DVec3,
    pub right: DVec3,
    /// The volume's millimetres per world unit.
    pub mm_per_unit: f64,
}

/// Where a plane is along its normal from the volume's centre, in world units.
fn offset(p: &ClipPlane) -> f64 {
    p.normal.normalize_or(DVec3::Z).dot(p.point)
}

/// A plane through the centre facing away from the camera: it removes the half of the
/// volume nearer the viewer.
pub fn plane_facing(forward: DVec3) -> ClipPlane {
    ClipPlane {
        point: DVec3::ZERO,
        normal: forward,
        enabled: true,
    }
}

/// The cut section; `locked` while recording (a scene cannot add or remove planes).
pub fn show(ui: &mut egui::Ui, cut: &mut Cut, view: Option<&ViewGeometry>, locked: bool) {
    let reach = view.map_or(0.9, |v| v.half.length());
    let mut remove = None;
    for (i, p) in cut.planes.iter_mut().enumerate() {
        ui.push_id(("clip", i), |ui| {
            ui.horizontal(|ui| {
                ui.checkbox(&mut p.enabled, format!("plane {i}"));
                if ui.small_button("flip").clicked() {
                    *p = p.flipped();
                }
                if let Some(v) = view {
                    if ui
                        .small_button("align")
                        .on_hover_text("face the view, keeping the offset")
                        .clicked()
                    {
                        let d = offset(p);
                        p.normal = v.forward;
                        p.point = v.forward * d;
                    }
                }
                ui.add_enabled_ui(!locked, |ui| {
                    if ui.small_button("remove").clicked() {
                        remove = Some(i);
                    }
                });
            });
            let mut d = offset(p);
            if ui
                .add(egui::Slider::new(&mut d, -reach..=reach).text("offset"))
                .changed()
            {
                let n = p.normal.normalize_or(DVec3::Z);
                p.point += n * (d - offset(p));
            }
        });
    }
    if let Some(i) = remove {
        cut.planes.remove(i);
    }
    ui.add_enabled_ui(!locked && cut.planes.len() < MAX_CLIP_PLANES, |ui| {
        if ui
            .button("add plane")
            .on_hover_text("through the centre, facing the view")
            .clicked()
        {
            let forward = view.map_or(DVec3::Z, |v| v.forward);
            cut.planes.push(plane_facing(forward));
        }
    });
    ui.separator();
    let mut on = cut.crop.is_some_and(|c| c.enabled);
    if ui.checkbox(&mut on, "crop box").changed() {
        match &mut cut.crop {
            Some(c) => c.enabled = on,
            None => cut.crop = Some(full_box()),
        }
    }
    if let Some(c) = cut.crop.as_mut().filter(|c| c.enabled) {
        if c.units == CropUnits::Voxels {
            ui.label(RichText::new("corners in voxels (from the scene)").small());
        } else {
            for (axis, i) in [("x", 0), ("y", 1), ("z", 2)] {
                ui.horizontal(|ui| {
                    let (mut lo, mut hi) = (c.min[i], c.max[i]);
                    ui.add(egui::Slider::new(&mut lo, -0.5..=0.5).text(format!("{axis} min")));
                    ui.add(egui::Slider::new(&mut hi, -0.5..=0.5).text("max"));
                    c.min[i] = lo.min(hi);
                    c.max[i] = hi.max(lo);
                });
            }
        }
    }
    if cut.active() {
        ui.label(RichText::new("C switches every cut off and on").small());
    }
}

/// The crop box that crops nothing.
pub fn full_box() -> CropBox {
    CropBox {
        min: DVec3::splat(-0.5),
        max: DVec3::splat(0.5),
        units: CropUnits::Box,
        enabled: true,
    }
}

/// The 12 edges of the box `lo`..`hi`.
fn box_edges(lo: DVec3, hi: DVec3) -> Vec<[DVec3; 2]> {
    let corner = |i: u32| {
        DVec3::new(
            if i & 1 != 0 { hi.x } else { lo.x },
            if i & 2 != 0 { hi.y } else { lo.y },
            if i & 4 != 0 { hi.z } else { lo.z },
        )
    };
    let mut edges = Vec::new();
    for i in 0..8u32 {
        for bit in [1, 2, 4] {
            if i & bit == 0 {
                edges.push([corner(i), corner(i | bit)]);
            }
        }
    }
    edges
}

/// The polygon where `plane` meets the box `lo`..`hi` (empty when it misses it), in
/// order around the plane.
fn plane_polygon(plane: &ClipPlane, lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    let (n, w) = plane.equation();
    let mut points: Vec<DVec3> = box_edges(lo, hi)
        .into_iter()
        .filter_map(|[a, b]| {
            let (sa, sb) = (n.dot(a) + w, n.dot(b) + w);
            (sa * sb <= 0.0 && sa != sb).then(|| a + (b - a) * (sa / (sa - sb)))
        })
        .collect();
    if points.len() < 3 {
        return Vec::new();
    }
    let centre = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    points.sort_by(|a, b| {
        let angle = |p: &DVec3| (p - centre).dot(v).atan2((p - centre).dot(u));
        angle(a).total_cmp(&angle(b))
    });
    points
}

/// Line segments outlining the cut in world space: each enabled plane's polygon in the
/// volume's box (within the crop box when there is one), and the crop box's edges.
pub fn outline(cut: &Cut, half: DVec3) -> Vec<[DVec3; 2]> {
    let mut lines = Vec::new();
    let (mut lo, mut hi) = (-half, half);
    if let Some(c) = cut.crop.filter(|c| c.enabled && c.units == CropUnits::Box) {
        lo = c.min * 2.0 * half;
        hi = c.max * 2.0 * half;
        lines.extend(box_edges(lo, hi));
    }
    for p in cut.planes.iter().filter(|p| p.enabled) {
        let poly = plane_polygon(p, lo, hi);
        for i in 0..poly.len() {
            lines.push([poly[i], poly[(i + 1) % poly.len()]]);
        }
    }
    lines
}

/// Draws the outline over the view (behind the panel, in front of the frame).
pub fn draw_outline(ctx: &egui::Context, cut: &Cut, view: &ViewGeometry) {
    let lines = outline(cut, view.half);
    if lines.is_empty() {
        return;
    }
    let painter = ctx
        .layer_painter(egui::LayerId::new(
            egui::Order::Background,
            egui::Id::new("cut-outline"),
        ))
        .with_clip_rect(view.rect);
    let vp = view.view_proj.as_dmat4();
    let to_screen = |p: DVec3| -> Option<egui::Pos2> {
        let clip = DMat4::mul_vec4(&vp, p.extend(1.0));
        (clip.w > 1e-6).then(|| {
            let ndc = clip.truncate() / clip.w;
            let r = view.rect;
            egui::pos2(
                r.min.x + (ndc.x as f32 * 0.5 + 0.5) * r.width(),
                r.min.y + (ndc.y as f32 * 0.5 + 0.5) * r.height(),
            )
        })
    };
    let stroke = egui::Stroke::new(1.5, Color32::from_rgb(255, 200, 60));
    for [a, b] in lines {
        if let (Some(a), Some(b)) = (to_screen(a), to_screen(b)) {
            painter.line_segment([a, b], stroke);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_through_the_centre_cuts_the_box_in_a_square() {
        let p = ClipPlane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
            enabled: true,
        };
        let poly = plane_polygon(&p, DVec3::splat(-0.5), DVec3::splat(0.5));
        assert_eq!(poly.len(), 4);
        assert!(poly
            .iter()
            .all(|q| q.z.abs() < 1e-12 && (q.x.abs() - 0.5).abs() < 1e-12));
        // A plane clear of the box draws nothing.
        let clear = ClipPlane {
            point: DVec3::new(0.0, 0.0, 0.9),
            ..p
        };
        assert!(plane_polygon(&clear, DVec3::splat(-0.5), DVec3::splat(0.5)).is_empty());
        let cut = Cut {
            planes: vec![p],
            crop: Some(full_box()),
        };
        assert_eq!(outline(&cut, DVec3::splat(0.5)).len(), 12 + 4);
    }
}
