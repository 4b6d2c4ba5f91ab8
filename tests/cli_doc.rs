//! The book's command-line page, `docs/src/cli.md`, is `dvr --help` and every
//! subcommand's `--help`, rendered by this test from the built binary. The test fails
//! when the committed page differs from what the binary says; with `DVR_BLESS=1` it
//! writes the page instead, so it is also the page's one generator:
//!
//! ```sh
//! DVR_BLESS=1 cargo test --test cli_doc
//! ```
//!
//! Needs no Vulkan device: `--help` exits before anything opens one.

use std::path::Path;
use std::process::Command;

const PAGE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/src/cli.md");

/// `dvr [SUBCOMMAND] --help`, as a user's terminal would show it (no colour: not a tty).
fn help(sub: Option<&str>) -> String {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_dvr"));
    cmd.args(sub).arg("--help").env_remove("DVR_LOG");
    let out = cmd.output().expect("dvr runs");
    assert!(
        out.status.success(),
        "dvr {} --help failed: {}",
        sub.unwrap_or(""),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("help is UTF-8")
}

/// The subcommands the top-level help lists under `Commands:`, `help` left out.
fn subcommands(top: &str) -> Vec<String> {
    top.lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter(|l| l.starts_with("  ") && !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|name| name != "help")
        .collect()
}

fn render() -> String {
    let top = help(None);
    let subs = subcommands(&top);
    assert!(
        subs.len() >= 8,
        "expected the eight commands in `dvr --help`, found {subs:?}"
    );
    let mut page = String::from(
        "# The command line\n\n\
         <!-- Generated from `dvr --help` by tests/cli_doc.rs: do not edit. \
         `DVR_BLESS=1 cargo test --test cli_doc` rewrites it. -->\n\n\
         Every command's `--help`, as the binary prints it. What the commands are for is in \
         [Getting started](getting-started.md#commands); exit statuses and environment \
         variables are there too.\n\n\
         Commands:",
    );
    for s in &subs {
        page.push_str(&format!(" [`{s}`](#dvr-{s})"));
        page.push(if s == subs.last().unwrap() { '.' } else { ',' });
    }
    page.push_str("\n\n## dvr\n\n```text\n");
    page.push_str(&top);
    page.push_str("```\n");
    for s in &subs {
        page.push_str(&format!("\n## dvr {s}\n\n```text\n"));
        page.push_str(&help(Some(s)));
        page.push_str("```\n");
    }
    page
}

#[test]
fn cli_page_matches_help() {
    let page = render();
    if std::env::var("DVR_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(PAGE, &page).expect("write docs/src/cli.md");
        return;
    }
    let committed = std::fs::read_to_string(Path::new(PAGE)).unwrap_or_default();
    if committed != page {
        let line = committed
            .lines()
            .zip(page.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| committed.lines().count().min(page.lines().count()));
        panic!(
            "docs/src/cli.md differs from `dvr --help` (first at line {}): \
             run `DVR_BLESS=1 cargo test --test cli_doc` and commit the page",
            line + 1
        );
    }
}

#[test]
fn subcommands_are_read_from_the_help() {
    let top = "Usage: dvr [OPTIONS] <COMMAND>\n\nCommands:\n  demo     The main job\n  \
               explore  Open a window:\n           continued\n  help     Print this\n\n\
               Options:\n  -h, --help\n";
    assert_eq!(subcommands(top), ["demo", "explore"]);
}
