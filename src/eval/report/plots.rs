//! The charts of an eval, each written as SVG (for the page) and PNG (for slides):
//! per scene, PSNR / SSIM / FLIP / temporal error vs frame with one line per method;
//! per scene and over all scenes, mean GPU ms per frame (log x) vs mean PSNR with the
//! accumulation baseline curve.
//!
//! Text is drawn with the font [`crate::font`] registers.

use crate::eval::results::SceneResult;
use crate::eval::scores::{mean_curve, scene_summary, Overall};
use anyhow::{anyhow, Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

const SIZE: (u32, u32) = (640, 400);

/// Colours of the registry's rows, in its order (`dvr_engine::denoise::DENOISERS`):
/// grey for the noisy input, red for ours, the rest a categorical palette.
const PALETTE: [RGBColor; 21] = [
    RGBColor(127, 127, 127),
    RGBColor(31, 119, 180),
    RGBColor(227, 119, 194),
    RGBColor(140, 86, 75),
    RGBColor(214, 39, 40),
    RGBColor(174, 199, 232),
    RGBColor(152, 223, 138),
    RGBColor(197, 176, 213),
    RGBColor(196, 156, 148),
    RGBColor(255, 152, 150),
    RGBColor(23, 190, 207),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(188, 189, 34),
    RGBColor(219, 219, 141),
    RGBColor(158, 218, 229),
    RGBColor(247, 182, 210),
    RGBColor(255, 187, 120),
    RGBColor(199, 199, 199),
    RGBColor(57, 59, 121),
];

/// A method's colour, the same in every chart and on the page: by its row in the
/// registry, so no name is listed here.
pub fn method_colour(method: &str) -> RGBColor {
    let row = dvr_engine::denoise::DENOISERS
        .iter()
        .position(|d| d.name == method)
        .unwrap_or_else(|| {
            // Not a registry name (a label from outside): a stable pick by name.
            method
                .bytes()
                .fold(0usize, |h, b| h.wrapping_mul(31).wrapping_add(b.into()))
        });
    PALETTE[row % PALETTE.len()]
}

pub fn colour_hex(c: RGBColor) -> String {
    format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2)
}

/// Something that can draw itself on any plotters backend.
pub(crate) trait Chart {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>>;
}

/// Writes `chart` as `<stem>.svg` and `<stem>.png`.
pub(crate) fn save(chart: &impl Chart, stem: &Path) -> Result<()> {
    if let Some(dir) = stem.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let svg_path = stem.with_extension("svg");
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        chart
            .draw(&root)
            .and_then(|_| root.present())
            .map_err(|e| anyhow!("drawing {}: {e}", svg_path.display()))?;
    }
    crate::output::write_text(&svg_path, &svg)?;

    let png_path = stem.with_extension("png");
    let mut pixels = vec![0u8; SIZE.0 as usize * SIZE.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
        chart
            .draw(&root)
            .and_then(|_| root.present())
            .map_err(|e| anyhow!("drawing {}: {e}", png_path.display()))?;
    }
    crate::output::write_rgb8_png(&png_path, SIZE.0, SIZE.1, &pixels)
}

/// `(lo, hi)` of the finite values, padded by 5 % (and widened when flat).
fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1e-3)
    };
    (lo - pad, hi + pad)
}

/// One metric vs frame, a line per method.
struct MetricPlot {
    title: String,
    y_label: &'static str,
    frames: u32,
    /// (method, [(frame, value)])
    series: Vec<(String, Vec<(u32, f64)>)>,
    /// A vertical marker at the sudden change.
    event: Option<u32>,
}

impl Chart for MetricPlot {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let (y0, y1) = padded_range(self.series.iter().flat_map(|s| s.1.iter().map(|p| p.1)));
        let x1 = self.frames.max(2) as i32 - 1;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(64)
            .build_cartesian_2d(0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_labels((x1 as usize + 1).min(12))
            .x_desc("frame")
            .y_desc(self.y_label)
            .light_line_style(RGBColor(242, 242, 242))
            .draw()?;
        if let Some(e) = self.event {
            let x = e as i32;
            chart.draw_series(DashedLineSeries::new(
                vec![(x, y0), (x, y1)],
                6,
                4,
                BLACK.mix(0.5).stroke_width(1),
            ))?;
            chart.draw_series(std::iter::once(Text::new(
                "change",
                (x, y1),
                ("sans-serif", 13).into_font().color(&BLACK.mix(0.7)),
            )))?;
        }
        for (method, points) in &self.series {
            let c = method_colour(method);
            let finite: Vec<(i32, f64)> = points
                .iter()
                .filter(|p| p.1.is_finite())
                .map(|&(f, v)| (f as i32, v))
                .collect();
            chart
                .draw_series(LineSeries::new(finite.clone(), c.stroke_width(2)))?
                .label(method.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
                });
            if finite.len() <= 24 {
                chart.draw_series(finite.iter().map(|&p| Circle::new(p, 2, c.filled())))?;
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .position(SeriesLabelPosition::LowerRight)
            .label_font(("sans-serif", 13))
            .draw()?;
        Ok(())
    }
}

/// (method, GPU ms, PSNR)
type MethodPoint = (String, f64, f64);

/// Mean GPU ms per frame vs mean PSNR per method, with the accumulation curve.
struct SpeedPlot {
    title: String,
    methods: Vec<MethodPoint>,
    /// (spp, ms, psnr)
    baseline: Vec<(u32, f64, f64)>,
}

impl Chart for SpeedPlot {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let ok = |ms: f64, psnr: f64| ms.is_finite() && ms > 0.0 && psnr.is_finite();
        let methods: Vec<&MethodPoint> = self.methods.iter().filter(|m| ok(m.1, m.2)).collect();
        let baseline: Vec<&(u32, f64, f64)> =
            self.baseline.iter().filter(|b| ok(b.1, b.2)).collect();
        let xs = methods
            .iter()
            .map(|m| m.1)
            .chain(baseline.iter().map(|b| b.1));
        let (mut x0, mut x1) = xs.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        if !x0.is_finite() {
            (x0, x1) = (1.0, 10.0);
        }
        let (x0, x1) = (x0 / 1.6, x1 * 1.6);
        let (y0, y1) = padded_range(
            methods
                .iter()
                .map(|m| m.2)
                .chain(baseline.iter().map(|b| b.2)),
        );
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(64)
            .build_cartesian_2d((x0..x1).log_scale(), y0..y1)?;
        chart
            .configure_mesh()
            .x_desc("GPU ms per frame (log)")
            .y_desc("PSNR (dB)")
            .light_line_style(RGBColor(242, 242, 242))
            .draw()?;
        if !baseline.is_empty() {
            let grey = RGBColor(90, 90, 90);
            chart.draw_series(LineSeries::new(
                baseline.iter().map(|b| (b.1, b.2)),
                grey.stroke_width(1),
            ))?;
            chart.draw_series(baseline.iter().map(|b| {
                EmptyElement::at((b.1, b.2))
                    + Circle::new((0, 0), 2, grey.filled())
                    + Text::new(
                        format!("{} spp", b.0),
                        (4, 2),
                        ("sans-serif", 11).into_font().color(&grey),
                    )
            }))?;
            if let Some(first) = baseline.first() {
                chart.draw_series(std::iter::once(
                    EmptyElement::at((first.1, first.2))
                        + Text::new(
                            "accumulation",
                            (4, -16),
                            ("sans-serif", 12).into_font().color(&grey),
                        ),
                ))?;
            }
        }
        // Points are labelled to their right (a legend box would hide some of them).
        // Labels of nearby points are laid out top to bottom without overlapping, with a
        // leader line when a label had to move away from its point.
        let mut points: Vec<(&MethodPoint, (i32, i32))> = methods
            .iter()
            .map(|m| (*m, chart.backend_coord(&(m.1, m.2))))
            .collect();
        points.sort_by_key(|(_, (_, py))| *py);
        let mut placed: Vec<(i32, i32)> = Vec::new();
        for ((method, ms, psnr), (px, py)) in points {
            let c = method_colour(method);
            let mut top = py - 7;
            for &(x, y) in &placed {
                if (x - px).abs() < 90 {
                    top = top.max(y + 13);
                }
            }
            placed.push((px, top));
            let dy = top - py;
            let leader = if dy > 4 {
                vec![(4, 2), (10, dy + 7)]
            } else {
                Vec::new()
            };
            chart.draw_series(std::iter::once(
                EmptyElement::at((*ms, *psnr))
                    + Circle::new((0, 0), 5, c.filled())
                    + PathElement::new(leader, c.stroke_width(1))
                    + Text::new(
                        method.clone(),
                        (11, dy),
                        ("sans-serif", 13).into_font().color(&c),
                    ),
            ))?;
        }
        Ok(())
    }
}

/// The metrics plotted against frames: (CSV column, axis label).
pub const METRIC_PLOTS: [(&str, &str); 4] = [
    ("psnr", "PSNR (dB)"),
    ("ssim", "SSIM"),
    ("flip", "FLIP (mean error)"),
    ("temporal_error", "temporal error"),
];

/// Plot files of a scene relative to the eval folder, without extension: the four
/// metric plots, then the speed-vs-accuracy chart.
pub fn scene_plot_stems(scene_dir: &str) -> Vec<String> {
    METRIC_PLOTS
        .iter()
        .map(|(m, _)| format!("{scene_dir}/plots/{m}"))
        .chain(std::iter::once(format!("{scene_dir}/plots/speed_accuracy")))
        .collect()
}

pub const OVERALL_PLOT_STEM: &str = "plots/speed_accuracy";

pub fn scene_plots(out: &Path, r: &SceneResult) -> Result<()> {
    let stems = scene_plot_stems(&r.dir);
    for ((metric, label), stem) in METRIC_PLOTS.iter().zip(&stems) {
        let series = r
            .methods
            .iter()
            .map(|m| {
                let points = r
                    .series(m)
                    .iter()
                    .filter_map(|x| {
                        let v = match *metric {
                            "psnr" => Some(x.psnr),
                            "ssim" => Some(x.ssim),
                            "flip" => Some(x.flip),
                            _ => x.temporal_error,
                        };
                        v.map(|v| (x.frame, v))
                    })
                    .collect();
                (m.clone(), points)
            })
            .collect();
        let plot = MetricPlot {
            title: format!("{} — {label}", r.name),
            y_label: label,
            frames: r.frames,
            series,
            event: r.event_frame,
        };
        save(&plot, &out.join(stem))?;
    }
    let speed = SpeedPlot {
        title: format!("{} — speed vs accuracy", r.name),
        methods: scene_summary(r)
            .into_iter()
            .map(|s| (s.method, s.gpu_ms, s.psnr))
            .collect(),
        baseline: mean_curve(&r.baseline),
    };
    save(&speed, &out.join(&stems[4]))
}

pub fn overall_plot(out: &Path, results: &[SceneResult], overall: &[Overall]) -> Result<()> {
    let points: Vec<_> = results
        .iter()
        .flat_map(|r| r.baseline.iter().cloned())
        .collect();
    let plot = SpeedPlot {
        title: format!("all scenes ({}) — speed vs accuracy", results.len()),
        methods: overall
            .iter()
            .map(|o| (o.method.clone(), o.gpu_ms, o.psnr))
            .collect(),
        baseline: mean_curve(&points),
    };
    save(&plot, &out.join(OVERALL_PLOT_STEM))
}

#[cfg(test)]
mod tests {
    use super::super::csv::tests::result;
    use super::*;
    use crate::eval::scores::overall_summary;

    #[test]
    fn every_denoiser_has_its_own_colour() {
        let rows = dvr_engine::denoise::DENOISERS;
        assert!(rows.len() <= PALETTE.len(), "add colours for the new rows");
        for (i, d) in rows.iter().enumerate() {
            let c = method_colour(d.name);
            assert!(
                rows[..i].iter().all(|e| method_colour(e.name) != c),
                "{} shares a colour",
                d.name
            );
        }
        assert_eq!(method_colour("ours"), RGBColor(214, 39, 40), "ours is red");
    }

    #[test]
    fn plots_are_written_as_svg_and_png() {
        crate::font::init_font().expect("a font (install fonts-dejavu-core)");
        let tmp = tempfile::tempdir().unwrap();
        let r = result("cloud/tf-jump", 8, Some(4));
        scene_plots(tmp.path(), &r).unwrap();
        let methods = r.methods.clone();
        let results = [r];
        overall_plot(tmp.path(), &results, &overall_summary(&results, &methods)).unwrap();
        for stem in scene_plot_stems("cloud_tf-jump")
            .iter()
            .map(String::as_str)
            .chain([OVERALL_PLOT_STEM])
        {
            let svg = std::fs::read_to_string(tmp.path().join(format!("{stem}.svg"))).unwrap();
            assert!(svg.contains("<svg") && svg.contains("ours"), "{stem}.svg");
            let png = image::open(tmp.path().join(format!("{stem}.png"))).unwrap();
            assert_eq!((png.width(), png.height()), SIZE);
            // Not blank: the lines of a method's colour are there.
            let rgb = png.to_rgb8();
            let red = method_colour("ours");
            assert!(
                rgb.pixels().any(|p| p.0 == [red.0, red.1, red.2]),
                "{stem}.png has no line in the colour of `ours`"
            );
        }
    }

    #[test]
    fn ranges_are_padded_and_never_empty() {
        assert_eq!(padded_range([1.0, 3.0].into_iter()), (0.9, 3.1));
        assert_eq!(padded_range([f64::NAN].into_iter()), (0.0, 1.0));
        let (lo, hi) = padded_range([2.0, 2.0].into_iter());
        assert!(lo < 2.0 && hi > 2.0);
    }
}
