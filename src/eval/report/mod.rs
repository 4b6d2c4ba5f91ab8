//! The eval's reports, written from the results and their scores: `metrics.csv`,
//! `summary.csv`, `baseline.csv` and the text table ([`csv`]), the charts ([`plots`]),
//! the results page ([`html`], its template `page.html`) and each scene's videos
//! ([`videos`]).
//!
//! The eval's fourth layer: it imports the plan, the results and the scores, never the
//! run that made them, so `dvr eval --merge` writes from `result.json` files what one
//! run writes.

pub mod csv;
pub mod html;
pub mod plots;
pub mod videos;

use super::plan::settings::EvalArgs;
use super::results::SceneResult;
use super::scores::overall_summary;
use anyhow::Result;

/// Prints the summary table and where the page is.
pub fn print_summary(args: &EvalArgs, methods: &[String], results: &[SceneResult], seconds: f64) {
    let overall = overall_summary(results, methods);
    print!("{}", csv::summary_table(results, &overall));
    println!(
        "eval: {} scene(s) × {} method(s) in {seconds:.1} s; open {}",
        results.len(),
        methods.len(),
        args.out.join("index.html").display()
    );
}

/// Writes every report of the eval folder from `results`.
pub fn write(
    args: &EvalArgs,
    methods: &[String],
    results: &[SceneResult],
    device: &str,
    seconds: f64,
) -> Result<()> {
    let out = &args.out;
    csv::write_metrics(&out.join("metrics.csv"), results)?;
    csv::write_summary(&out.join("summary.csv"), results)?;
    csv::write_baseline(&out.join("baseline.csv"), results)?;
    let overall = overall_summary(results, methods);
    plots::overall_plot(out, results, &overall)?;
    html::write_page(
        &out.join("index.html"),
        &html::PageInfo {
            args,
            methods,
            device,
            seconds,
        },
        results,
        &overall,
    )
}
