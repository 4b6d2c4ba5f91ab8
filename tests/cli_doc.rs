//! The book's command-line page, `docs/src/cli.md`, is `dvr --help` and every
//! subcommand's `--help`, rendered by this test from the built binary
//! (`common/cli_page.rs` lays the page out and compares it). The test fails when the
//! committed page differs from what the binary says; with `DVR_BLESS=1` it writes the
//! page instead, so it is also the page's one generator:
//!
//! ```sh
//! DVR_BLESS=1 cargo test --test cli_doc
//! ```
//!
//! Needs no Vulkan device: `--help` exits before anything opens one.

mod common;

use common::cli_page::{compare, render, subcommands, PAGE};
use std::process::Command;

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

#[test]
fn cli_page_matches_help() {
    let page = render(help);
    if std::env::var("DVR_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(PAGE, &page).expect("write docs/src/cli.md");
        return;
    }
    let committed = std::fs::read_to_string(PAGE).unwrap_or_default();
    compare(&committed, &page).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn subcommands_are_read_from_the_help() {
    let top = "Usage: dvr [OPTIONS] <COMMAND>\n\nCommands:\n  demo     The main job\n  \
               explore  Open a window:\n           continued\n  help     Print this\n\n\
               Options:\n  -h, --help\n";
    assert_eq!(subcommands(top), ["demo", "explore"]);
}

#[test]
fn a_page_missing_a_command_names_it() {
    let page = "## dvr\n\n## dvr demo\n\n## dvr toy\n";
    let e = compare("## dvr\n\n## dvr demo\n\n## dvr old\n", page).expect_err("differs");
    assert!(e.contains("no section for `dvr toy`"), "{e}");
    assert!(e.contains("a section for `dvr old`"), "{e}");
    let e = compare(
        "## dvr\n\n## dvr demo\nold\n",
        "## dvr\n\n## dvr demo\nnew\n",
    )
    .expect_err("differs");
    assert!(e.contains("first at line 4"), "{e}");
}
