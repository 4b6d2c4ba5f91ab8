//! The channels of a multi-channel medium and the time of a series in the side panel:
//! per channel a colour swatch, a visible switch and the choice of which channel the
//! TF editor edits (over that channel's histogram and window); a time slider with
//! play/pause and a speed in time points per second.

use super::tf_editor;
use super::ui::{Model, UiState};
use egui::RichText;
use std::time::Instant;

/// Playback state of a series (not part of the model: only the time it sets is).
pub struct Playback {
    pub times: usize,
    pub playing: bool,
    /// Time points per second.
    pub speed: f64,
    last: Option<Instant>,
}

impl Playback {
    pub fn new(times: usize) -> Self {
        Self {
            times,
            playing: false,
            speed: 4.0,
            last: None,
        }
    }

    /// Advances `time` by the wall-clock time since the last call while playing,
    /// wrapping past the last time point to the first.
    pub fn tick(&mut self, time: &mut f64) {
        let now = Instant::now();
        let dt = self
            .last
            .replace(now)
            .map_or(0.0, |t| (now - t).as_secs_f64());
        if !self.playing || self.times < 2 {
            return;
        }
        let span = (self.times - 1) as f64;
        *time = (*time + dt * self.speed).rem_euclid(span.max(f64::MIN_POSITIVE));
    }
}

/// The channels panel (shown when the medium has channels): returns nothing, edits the
/// model; the TF editor below it edits the selected channel.
pub fn channels(ui: &mut egui::Ui, state: &mut UiState, model: &mut Model) {
    for (i, c) in model.channels.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            ui.color_edit_button_rgb(&mut c.colour);
            ui.checkbox(&mut c.visible, "");
            let label = RichText::new(&c.name).small();
            if ui
                .selectable_label(state.channel == i, label)
                .on_hover_text("edit this channel's transfer function")
                .clicked()
            {
                state.channel = i;
                state.tf_editor.selected = None;
                state.tf_editor.dragging = None;
            }
        });
    }
    let i = state.channel.min(model.channels.len().saturating_sub(1));
    if let Some(c) = model.channels.get_mut(i) {
        let empty = Vec::new();
        let histogram = state.channel_histograms.get(i).unwrap_or(&empty);
        tf_editor::show(ui, &mut state.tf_editor, &mut c.tf, histogram, c.window);
    }
}

/// The time slider, play/pause and speed (shown for a series of several time points).
pub fn time(ui: &mut egui::Ui, playback: &mut Playback, time: &mut f64) {
    let last = (playback.times.max(1) - 1) as f64;
    ui.add(egui::Slider::new(time, 0.0..=last).text("time point"));
    ui.horizontal(|ui| {
        let label = if playback.playing {
            "⏸ pause"
        } else {
            "▶ play"
        };
        if ui.button(label).clicked() {
            playback.playing = !playback.playing;
        }
        ui.add(
            egui::DragValue::new(&mut playback.speed)
                .range(0.1..=60.0)
                .speed(0.1)
                .suffix(" /s"),
        );
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn playback_wraps_past_the_last_time_point_and_holds_when_paused() {
        let mut p = Playback::new(24);
        let mut t = 22.5;
        p.tick(&mut t);
        std::thread::sleep(std::time::Duration::from_millis(30));
        p.tick(&mut t);
        assert_eq!(t, 22.5, "paused");
        p.playing = true;
        p.speed = 100.0;
        std::thread::sleep(std::time::Duration::from_millis(20));
        p.tick(&mut t);
        assert!((0.0..23.0).contains(&t) && t != 22.5, "{t}");
    }
}
