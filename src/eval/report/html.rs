//! `DIR/index.html`: a static results page that works from `file://` with no server.
//! The page ([`page.html`](./page.html)) is a template; the results go into it as JSON
//! in a `<script type="application/json">` element (no fetch, which file:// forbids),
//! and images and plots are linked by relative path.
//!
//! The page reads its state from the address (`#scene=0&frame=2&a=ours&b=reference&
//! view=wipe&split=30&flip=1&zoom=4&x=10&y=20`) and writes it back to the address, to
//! `<body data-…>` and to the title, and counts image loads on `<body>`
//! (`data-loaded`, `data-failed`, `data-pending`), so a headless browser can check it.

use super::plots::{colour_hex, method_colour, scene_plot_stems, METRIC_PLOTS, OVERALL_PLOT_STEM};
use crate::eval::plan::settings::{EvalArgs, EXPOSURE, GPU_WARMUP_FRAMES, RECOVERY_TOLERANCE_DB};
use crate::eval::results::{MetricRow, SceneResult};
use crate::eval::scores::{mean_curve, overall_recovery_text, scene_summary, Overall, Recovery};
use anyhow::Result;
use serde_json::{json, Value};
use std::path::Path;

const TEMPLATE: &str = include_str!("page.html");

pub struct PageInfo<'a> {
    pub args: &'a EvalArgs,
    pub methods: &'a [String],
    pub device: &'a str,
    pub seconds: f64,
}

fn recovery_json(r: Recovery) -> Value {
    match r {
        Recovery::NotApplicable => Value::Null,
        Recovery::Frames(n) => json!(n),
        Recovery::Never => json!("never"),
    }
}

fn scene_json(r: &SceneResult) -> Value {
    let metrics: serde_json::Map<String, Value> = r
        .methods
        .iter()
        .map(|m| {
            let rows = r.series(m);
            let col = |f: &dyn Fn(&MetricRow) -> Option<f64>| -> Value {
                rows.iter().map(|x| f(x)).collect::<Vec<_>>().into()
            };
            (
                m.clone(),
                json!({
                    "psnr": col(&|x| Some(x.psnr)),
                    "ssim": col(&|x| Some(x.ssim)),
                    "flip": col(&|x| Some(x.flip)),
                    "temporal_error": col(&|x| x.temporal_error),
                    "gpu_ms": col(&|x| Some(x.gpu_ms)),
                }),
            )
        })
        .collect();
    let summary: Vec<Value> = scene_summary(r)
        .into_iter()
        .map(|s| {
            json!({
                "method": s.method, "psnr": s.psnr, "ssim": s.ssim, "flip": s.flip,
                "temporal_error": s.temporal_error, "gpu_ms": s.gpu_ms,
                "recovery": recovery_json(s.recovery),
            })
        })
        .collect();
    let titles = METRIC_PLOTS
        .iter()
        .map(|(_, label)| label.to_string())
        .chain(std::iter::once("speed vs accuracy".to_string()));
    let plots: Vec<Value> = scene_plot_stems(&r.dir)
        .into_iter()
        .zip(titles)
        .map(|(stem, title)| json!({ "title": title, "src": format!("{stem}.svg") }))
        .collect();
    json!({
        "name": r.name,
        "dir": r.dir,
        "frames": r.frames,
        "spp": r.spp,
        "event_frame": r.event_frame,
        "path_trace_ms_per_spp": r.path_trace_ms_per_spp,
        "volume": r.volume,
        "methods": r.methods,
        "metrics": metrics,
        "summary": summary,
        "baseline": mean_curve(&r.baseline)
            .into_iter()
            .map(|(spp, ms, psnr)| json!({ "spp": spp, "gpu_ms": ms, "psnr": psnr }))
            .collect::<Vec<_>>(),
        "plots": plots,
    })
}

/// The page's data: everything the script shows.
pub fn page_data(info: &PageInfo, results: &[SceneResult], overall: &[Overall]) -> Value {
    let (width, height) = info.args.size;
    let scenes: Vec<Value> = results
        .iter()
        .map(|r| {
            let mut v = scene_json(r);
            v["width"] = json!(width);
            v["height"] = json!(height);
            v
        })
        .collect();
    json!({
        "device": info.device,
        "seconds": info.seconds,
        "note": info.args.note,
        "video": info.args.video.video,
        "video_fps": info.args.video.video_fps,
        "settings": {
            "width": width,
            "height": height,
            "spp": results.first().map(|r| r.spp),
            "ref_spp": info.args.ref_spp,
            "motion": info.args.render.motion.name(),
            "exposure": EXPOSURE,
            "warmup_frames": GPU_WARMUP_FRAMES,
            "recovery_tolerance_db": RECOVERY_TOLERANCE_DB,
        },
        "methods": info.methods.iter().map(|m| json!({
            "name": m, "colour": colour_hex(method_colour(m)),
        })).collect::<Vec<_>>(),
        "overall": overall.iter().map(|o| json!({
            "method": o.method, "scenes": o.scenes, "psnr": o.psnr, "ssim": o.ssim,
            "flip": o.flip, "temporal_error": o.temporal_error, "gpu_ms": o.gpu_ms,
            "recovery": overall_recovery_text(o.recovery),
        })).collect::<Vec<_>>(),
        "overall_plot": format!("{OVERALL_PLOT_STEM}.svg"),
        "scenes": scenes,
    })
}

/// JSON that is safe inside a `<script>` element: no `</script>` or `<!--` can close
/// or confuse it (`<` only appears inside strings, where `\u003c` means the same).
fn script_safe_json(v: &Value) -> String {
    v.to_string().replace('<', "\\u003c")
}

pub fn page(info: &PageInfo, results: &[SceneResult], overall: &[Overall]) -> String {
    TEMPLATE.replace(
        "__DATA__",
        &script_safe_json(&page_data(info, results, overall)),
    )
}

pub fn write_page(
    path: &Path,
    info: &PageInfo,
    results: &[SceneResult],
    overall: &[Overall],
) -> Result<()> {
    crate::output::write_text(path, &page(info, results, overall))
}

#[cfg(test)]
mod tests {
    use super::super::csv::tests::result;
    use super::*;
    use crate::eval::scores::overall_summary;
    use clap::Parser;

    #[derive(Parser)]
    struct Wrap {
        #[command(flatten)]
        args: EvalArgs,
    }

    #[test]
    fn data_is_inlined_and_script_safe() {
        let args = Wrap::parse_from(["x", "--size", "32x16", "--ref-spp", "64"]).args;
        let mut r = result("cloud/tf-jump", 6, Some(3));
        r.name = "evil</script><!--".into();
        let results = [r];
        let methods = results[0].methods.clone();
        let overall = overall_summary(&results, &methods);
        let info = PageInfo {
            args: &args,
            methods: &methods,
            device: "llvmpipe",
            seconds: 1.0,
        };
        let html = page(&info, &results, &overall);
        assert_eq!(
            html.matches("</script>").count(),
            2,
            "only the page's own scripts close"
        );
        assert!(!html.contains("__DATA__"));
        assert!(!html.contains("fetch("), "file:// pages cannot fetch");
        let start = html.find("id=\"data\">").unwrap() + "id=\"data\">".len();
        let end = start + html[start..].find("</script>").unwrap();
        let data: Value = serde_json::from_str(&html[start..end]).unwrap();
        assert_eq!(data["scenes"][0]["name"], "evil</script><!--");
        assert_eq!(data["scenes"][0]["width"], 32);
        assert_eq!(data["scenes"][0]["event_frame"], 3);
        assert_eq!(
            data["scenes"][0]["metrics"]["ours"]["psnr"]
                .as_array()
                .unwrap()
                .len(),
            6
        );
        assert_eq!(
            data["scenes"][0]["metrics"]["ours"]["temporal_error"][0],
            Value::Null
        );
        assert_eq!(data["scenes"][0]["summary"][1]["recovery"], 2);
        assert_eq!(data["settings"]["ref_spp"], 64);
        assert_eq!(data["settings"]["exposure"], 1.0);
        assert_eq!(data["methods"][1]["colour"], "#d62728");
        assert!(data["scenes"][0]["plots"][0]["src"]
            .as_str()
            .unwrap()
            .ends_with("/plots/psnr.svg"));
    }

    /// Scene names come from scene files: every place the page's script puts a data
    /// string into HTML escapes it (the JSON itself is script-safe, see above).
    #[test]
    fn the_script_escapes_every_data_string_it_puts_into_html() {
        assert!(TEMPLATE.contains("function esc(v)"));
        for used in [
            "${esc(s.name)}",
            "${esc(m)}",
            "${esc(r.method)}",
            "${esc(text)}",
            "${esc(DATA.device)}",
        ] {
            assert!(TEMPLATE.contains(used), "{used}");
        }
        for raw in [
            ">${s.name}</option>",
            "</span>${r.method}</td>",
            "device ${DATA.device}",
            ">${m}</option>",
        ] {
            assert!(!TEMPLATE.contains(raw), "{raw} unescaped");
        }
    }
}
