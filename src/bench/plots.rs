//! The benchmark's chart per profiled size: each denoiser's own GPU ms per frame as a
//! bar (with the shared path-tracing passes as the first bar for scale), labelled with
//! the time and its passes' share of the measured peak bandwidth.

use crate::eval::report::plots::{method_colour, save, Chart};
use crate::profile::methods::{method_rows, shared_ms};
use crate::profile::Profile;
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// (label, ms, % of peak, colour)
type Bar = (String, f64, Option<f64>, RGBColor);

struct MethodBars {
    title: String,
    bars: Vec<Bar>,
}

impl Chart for MethodBars {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let max = self.bars.iter().map(|b| b.1).fold(0.0f64, f64::max);
        // Room on the right for the labels.
        let x1 = if max > 0.0 { max * 1.6 } else { 1.0 };
        let n = self.bars.len().max(1) as i32;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(8)
            .build_cartesian_2d(0.0..x1, 0..n)?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(1)
            .y_label_formatter(&|_| String::new())
            .x_desc("GPU ms per frame")
            .light_line_style(RGBColor(242, 242, 242))
            .draw()?;
        for (i, (label, ms, peak, colour)) in self.bars.iter().enumerate() {
            // First bar at the top.
            let y = n - 1 - i as i32;
            chart.draw_series(std::iter::once(Rectangle::new(
                [(0.0, y), (*ms, y + 1)],
                colour.mix(0.8).filled(),
            )))?;
            let text = match peak {
                Some(p) => format!("{label}  {ms:.3} ms  ({p:.0}% of peak)"),
                None => format!("{label}  {ms:.3} ms"),
            };
            chart.draw_series(std::iter::once(
                EmptyElement::at((*ms, y + 1))
                    + Text::new(text, (4, 2), ("sans-serif", 12).into_font()),
            ))?;
        }
        Ok(())
    }
}

/// Writes `<stem>.svg` and `<stem>.png` for one profile.
pub fn pass_chart(p: &Profile, stem: &Path) -> Result<()> {
    let mut bars: Vec<Bar> = vec![(
        "shared (path trace, motion)".into(),
        shared_ms(p),
        None,
        RGBColor(90, 90, 90),
    )];
    // Each method with the passes it needs (features, guides), as it would run alone.
    bars.extend(method_rows(p).into_iter().map(|r| {
        let colour = method_colour(&r.method);
        (r.method, r.cost_ms, r.percent_of_peak, colour)
    }));
    let chart = MethodBars {
        title: format!(
            "{} {}x{}: GPU time per denoiser, with the features it needs",
            p.run.device, p.run.width, p.run.height
        ),
        bars,
    };
    save(&chart, stem)
}
