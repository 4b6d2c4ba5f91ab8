//! The labels of a label map in the side panel: a search box (a parcellation has a
//! hundred labels), show all / hide all, and per label a colour swatch, a visible switch
//! and an opacity; below them what the last click picked (the label and the intensity
//! under the cursor).

use super::ui::{Model, UiState};
use egui::RichText;

/// Rows the list shows before it scrolls.
const VISIBLE_ROWS: f32 = 12.0;

pub fn labels(ui: &mut egui::Ui, state: &mut UiState, model: &mut Model) {
    ui.horizontal(|ui| {
        ui.add(
            egui::TextEdit::singleline(&mut state.label_search)
                .hint_text("search labels")
                .desired_width(140.0),
        );
        if ui.small_button("show all").clicked() {
            model.labels.iter_mut().for_each(|l| l.visible = true);
        }
        if ui.small_button("hide all").clicked() {
            model.labels.iter_mut().for_each(|l| l.visible = false);
        }
    });
    let needle = state.label_search.to_lowercase();
    let row = ui.spacing().interact_size.y + ui.spacing().item_spacing.y;
    egui::ScrollArea::vertical()
        .max_height(row * VISIBLE_ROWS)
        .show(ui, |ui| {
            for l in model
                .labels
                .iter_mut()
                .filter(|l| needle.is_empty() || l.name.to_lowercase().contains(&needle))
            {
                ui.horizontal(|ui| {
                    ui.color_edit_button_rgb(&mut l.colour);
                    ui.checkbox(&mut l.visible, "");
                    ui.add(
                        egui::DragValue::new(&mut l.opacity)
                            .range(0.0..=1.0)
                            .speed(0.01)
                            .fixed_decimals(2),
                    )
                    .on_hover_text("opacity");
                    ui.label(RichText::new(format!("{} {}", l.value, l.name)).small());
                });
            }
        });
    if let Some(p) = &state.pick {
        ui.label(RichText::new(p).small());
    } else {
        ui.label(
            RichText::new("click the view to pick a label")
                .small()
                .weak(),
        );
    }
}
