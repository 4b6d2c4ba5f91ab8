//! The book's command-line page, `docs/src/cli.md`: `dvr --help` and every subcommand's
//! `--help`, from whatever gives the help text (the built binary in `tests/cli_doc.rs`,
//! a parser in this process in `tests/plugins.rs`), and the check that the committed page
//! is that page.

/// The committed page.
pub const PAGE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/src/cli.md");

/// What regenerates the page, as every mismatch says.
const BLESS: &str = "run `DVR_BLESS=1 cargo test --test cli_doc` and commit the page";

/// The subcommands the top-level help lists under `Commands:`, `help` left out.
pub fn subcommands(top: &str) -> Vec<String> {
    top.lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter(|l| l.starts_with("  ") && !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|name| name != "help")
        .collect()
}

/// The page for the help `help` gives: `help(None)` is `dvr --help`, `help(Some(s))`
/// is `dvr s --help` for every command the top level lists.
pub fn render(help: impl Fn(Option<&str>) -> String) -> String {
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

/// The commands a page has a section for (`## dvr <command>`).
fn sections(page: &str) -> Vec<&str> {
    page.lines()
        .filter_map(|l| l.strip_prefix("## dvr "))
        .collect()
}

/// `Ok` when the committed page is `page`. Otherwise what differs: each command with no
/// section in the committed page, and each section of a command the help no longer
/// lists, else the first line that differs.
pub fn compare(committed: &str, page: &str) -> Result<(), String> {
    if committed == page {
        return Ok(());
    }
    let (old, new) = (sections(committed), sections(page));
    let mut problems: Vec<String> = new
        .iter()
        .filter(|c| !old.contains(c))
        .map(|c| format!("no section for `dvr {c}`"))
        .collect();
    problems.extend(
        old.iter()
            .filter(|c| !new.contains(c))
            .map(|c| format!("a section for `dvr {c}`, which `dvr --help` does not list")),
    );
    if problems.is_empty() {
        let line = committed
            .lines()
            .zip(page.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| committed.lines().count().min(page.lines().count()));
        return Err(format!(
            "docs/src/cli.md differs from `dvr --help` (first at line {}): {BLESS}",
            line + 1
        ));
    }
    Err(format!(
        "docs/src/cli.md has {}: {BLESS}",
        problems.join(", and ")
    ))
}
