//! ours' fixed constants each have one home: the shaders' in
//! `shaders/glsl/include/ours_constants.glsl` (a few in the shader they belong to, as
//! `const` declarations), the Rust side's beside [`super::OursParams`] (`LAG_RADIUS`,
//! [`super::ATROUS_LEVELS`], [`super::prior::PRIOR_STRIDE`]). The tests here read every
//! shader and include ours' passes read (the path tracer's shared code that its gradient
//! pass re-traces with, the reprojection, the à-trous it shares with the paper's models)
//! and ours' Rust, and fail
//! - on a numeric literal outside a named declaration that is not structural (0–4, halves,
//!   an index), in any of those shaders: a number that changes the output cannot enter
//!   without a name;
//! - on a name given a value in two places (a shader and the Rust, or two shaders);
//! - on a name of ours' own (its shaders and includes, the shared à-trous, its Rust) with
//!   no row in the denoisers page's tables, and on a row that names nothing.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// ours' Rust: its module (but this file, whose tables are the test's) and the shared
/// à-trous module it runs, as (file, source).
fn rust_sources() -> Vec<(String, String)> {
    let denoise = root().join("engine/src/denoise");
    let mut files: Vec<PathBuf> = std::fs::read_dir(denoise.join("ours"))
        .expect("ours' module folder")
        .map(|e| e.expect("a folder entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .filter(|p| !p.ends_with("constants.rs"))
        .collect();
    files.push(denoise.join("variance_atrous.rs"));
    files.sort();
    let name = |p: &Path| p.strip_prefix(root()).unwrap_or(p).display().to_string();
    files.iter().map(|p| (name(p), read(p))).collect()
}

/// The shaders ours' Rust builds pipelines from (`ctx.pipeline("name"`), and every
/// include they read, transitively, as (path under shaders/glsl, source).
fn shader_sources(rust: &[(String, String)]) -> Vec<(String, String)> {
    let glsl = root().join("shaders/glsl");
    let mut todo: Vec<String> = Vec::new();
    for (_, src) in rust {
        for piece in src.split("pipeline(").skip(1) {
            let piece = piece.trim_start();
            if let Some(rest) = piece.strip_prefix('"') {
                let name = rest.split('"').next().unwrap_or_default();
                if !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                    todo.push(format!("{name}.comp"));
                }
            }
        }
    }
    let mut out: Vec<(String, String)> = Vec::new();
    while let Some(file) = todo.pop() {
        if out.iter().any(|(f, _)| *f == file) {
            continue;
        }
        let src = read(&glsl.join(&file));
        for line in src.lines() {
            if let Some(inc) = line.trim().strip_prefix("#include") {
                todo.push(format!("include/{}", inc.trim().trim_matches('"')));
            }
        }
        out.push((file, src));
    }
    out.sort();
    out
}

/// Whether a shader is ours' own (its passes and includes, and the à-trous it shares
/// with the paper's models) rather than code it shares with the path tracer.
fn own_shader(file: &str) -> bool {
    let name = file.trim_start_matches("include/");
    name.starts_with("ours_") || name.starts_with("variance_atrous")
}

/// File-scope constants given a value: GLSL's `const T NAME = …` (a specialisation
/// constant is the engine's to set, so its default is no home) and Rust's numeric
/// `const NAME: T = …` whose value has a literal (one read from a shader's text names its
/// home there). Each as (name, where).
fn declarations(file: &str, src: &str) -> Vec<(String, String)> {
    let rust = file.ends_with(".rs");
    let mut out = Vec::new();
    let lines: Vec<&str> = src.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        // Indented declarations are locals (`const int D = PRIOR_FEATURES;`) or the
        // tests' own tables.
        if line.starts_with(' ') {
            continue;
        }
        // The whole statement: a value may continue on the next lines.
        let end = (i..lines.len())
            .find(|&j| lines[j].contains(';'))
            .unwrap_or(i);
        let statement = lines[i..=end].join(" ");
        let decl = statement
            .trim_start_matches("pub ")
            .trim_start_matches("pub(crate) ")
            .trim_start_matches("pub(super) ");
        let Some(rest) = decl.strip_prefix("const ") else {
            continue;
        };
        let name = if rust {
            let Some((name, rest)) = rest.split_once(':') else {
                continue;
            };
            let Some((ty, value)) = rest.split_once('=') else {
                continue;
            };
            let numeric = ["u32", "i32", "f32", "u64", "f64", "usize"].contains(&ty.trim());
            if !numeric || !value.chars().any(|c| c.is_ascii_digit()) {
                continue;
            }
            name.trim()
        } else {
            let Some((head, _)) = rest.split_once('=') else {
                continue;
            };
            let name = head.split_whitespace().nth(1).unwrap_or_default();
            name.split('[').next().unwrap_or_default()
        };
        out.push((name.to_string(), format!("{file}:{}", i + 1)));
    }
    out
}

/// The names in the first column of ours' two tables on the denoisers page (the knobs,
/// after "**Its parameters**", and the fixed constants, after "**Fixed constants.**"),
/// each a backticked word.
fn table_names() -> Vec<String> {
    let page = read(&root().join("docs/src/denoisers.md"));
    let mut names = Vec::new();
    let (mut armed, mut in_table) = (false, false);
    for line in page.lines() {
        if line.contains("**Its parameters**") || line.contains("**Fixed constants.**") {
            armed = true;
            continue;
        }
        if !armed {
            continue;
        }
        if !line.starts_with('|') {
            if in_table {
                (armed, in_table) = (false, false);
            }
            continue;
        }
        in_table = true;
        let cell = line[1..].split(" | ").next().unwrap_or_default();
        for (i, piece) in cell.split('`').enumerate() {
            if i % 2 == 1 {
                names.push(piece.to_string());
            }
        }
    }
    assert!(
        names.len() > 20,
        "the denoisers page's two tables were not found"
    );
    names
}

/// Numbers that are structure, not choices: the mean over three channels, halves (a
/// pixel's centre, the Catmull-Rom weights), and small integers (indices, the four
/// channels of a texel, the Catmull-Rom's four taps). An integer inside `[…]` is an
/// index. A loop over a window written with a literal radius (`for (int d = -2; …`) is
/// a choice, whatever its size.
const STRUCTURAL_FLOATS: [f64; 7] = [0.0, 1.0, 2.0, 3.0, 0.5, 1.5, 2.5];
const STRUCTURAL_INTS: [i64; 5] = [0, 1, 2, 3, 4];

/// The source without comments, declarations that name a value (`const …`, a
/// specialisation constant's default) and the lines that are not code (`#version`,
/// `#include`, `layout(…) in;`, bindings).
fn code_lines(src: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut in_block = false;
    for (i, line) in src.lines().enumerate() {
        let mut code = String::new();
        let mut rest = line;
        loop {
            if in_block {
                match rest.find("*/") {
                    Some(e) => {
                        rest = &rest[e + 2..];
                        in_block = false;
                    }
                    None => break,
                }
            } else {
                let line_comment = rest.find("//");
                let block = rest.find("/*");
                match (line_comment, block) {
                    (Some(l), b) if b.is_none_or(|b| l < b) => {
                        code.push_str(&rest[..l]);
                        break;
                    }
                    (_, Some(b)) => {
                        code.push_str(&rest[..b]);
                        rest = &rest[b + 2..];
                        in_block = true;
                    }
                    _ => {
                        code.push_str(rest);
                        break;
                    }
                }
            }
        }
        let t = code.trim();
        let named = t.starts_with("const ") || t.starts_with("layout(") || t.starts_with('#');
        if !t.is_empty() && !named {
            out.push((i + 1, t.to_string()));
        }
    }
    out
}

/// The numeric literals of a line of code (not parts of names such as `vec3` or
/// `fit_r_hi`), each with whether it is negated (`-2`) and inside brackets (`beta[4]`).
fn literals(line: &str) -> Vec<(String, bool, bool)> {
    let b = line.as_bytes();
    let mut out = Vec::new();
    let mut depth = 0i32;
    let mut i = 0;
    while i < b.len() {
        let starts =
            b[i].is_ascii_digit() || (b[i] == b'.' && i + 1 < b.len() && b[i + 1].is_ascii_digit());
        let in_name = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if starts && !in_name {
            let s = i;
            // A minus after an operand subtracts (`D - 1`); otherwise it negates (`-2`).
            let before = line[..s].trim_end();
            let negated = before.strip_suffix('-').is_some_and(|b| {
                !b.trim_end().ends_with(|c: char| {
                    c.is_ascii_alphanumeric() || c == '_' || c == ')' || c == ']'
                })
            });
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'.') {
                i += 1;
                // An exponent's sign belongs to the literal.
                if i < b.len() && (b[i] == b'-' || b[i] == b'+') && matches!(b[i - 1], b'e' | b'E')
                {
                    i += 1;
                }
            }
            out.push((line[s..i].to_string(), negated, depth > 0));
        } else {
            match b[i] {
                b'[' => depth += 1,
                b']' => depth -= 1,
                _ => {}
            }
            i += 1;
        }
    }
    out
}

/// Whether a literal is structure (see [`STRUCTURAL_FLOATS`]).
fn structural(lit: &str, negated: bool, indexing: bool, in_loop_header: bool) -> bool {
    let digits = lit.trim_end_matches(['u', 'U']);
    if let Ok(v) = digits.parse::<i64>() {
        if in_loop_header && negated {
            return false;
        }
        return indexing || STRUCTURAL_INTS.contains(&v);
    }
    let v: Option<f64> = lit.trim_end_matches(['f', 'F']).parse().ok();
    v.is_some_and(|v| STRUCTURAL_FLOATS.contains(&v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_output_changing_number_in_the_shaders_ours_reads_is_named() {
        let shaders = shader_sources(&rust_sources());
        for must in [
            "ours_update.comp",
            "include/path.glsl",
            "include/reproject.glsl",
        ] {
            assert!(
                shaders.iter().any(|(f, _)| f == must),
                "the scan misses {must}"
            );
        }
        let mut unnamed = Vec::new();
        for (file, src) in &shaders {
            for (line, code) in code_lines(src) {
                let header = code.starts_with("for ") || code.starts_with("for(");
                for (lit, negated, indexing) in literals(&code) {
                    if !structural(&lit, negated, indexing, header) {
                        unnamed.push(format!("{file}:{line}: {lit} in `{code}`"));
                    }
                }
            }
        }
        assert!(
            unnamed.is_empty(),
            "unnamed constants:\n{}",
            unnamed.join("\n")
        );
    }

    #[test]
    fn every_constant_has_one_home_and_a_row() {
        let rust = rust_sources();
        let shaders = shader_sources(&rust);
        let mut homes: BTreeMap<String, Vec<String>> = BTreeMap::new();
        let mut own: Vec<String> = Vec::new();
        for (file, src) in shaders.iter().chain(&rust) {
            let mine = file.ends_with(".rs") || own_shader(file);
            for (name, at) in declarations(file, src) {
                if mine {
                    own.push(name.clone());
                }
                homes.entry(name).or_default().push(at);
            }
        }
        let twice: Vec<String> = homes
            .iter()
            .filter(|(_, at)| at.len() > 1)
            .map(|(name, at)| format!("{name}: {}", at.join(", ")))
            .collect();
        assert!(
            twice.is_empty(),
            "given a value twice:\n{}",
            twice.join("\n")
        );
        let rows = table_names();
        let mut missing: Vec<&String> = own.iter().filter(|n| !rows.contains(n)).collect();
        missing.dedup();
        assert!(
            missing.is_empty(),
            "no row in docs/src/denoisers.md: {missing:?}"
        );
        // The knobs' rows name OursParams' fields.
        let knobs: Vec<&str> = super::super::OVERRIDABLE.iter().map(|o| o.0).collect();
        let stale: Vec<&String> = rows
            .iter()
            .filter(|n| !homes.contains_key(*n) && !knobs.contains(&n.as_str()))
            .collect();
        assert!(stale.is_empty(), "rows that name no constant: {stale:?}");
    }

    #[test]
    fn declarations_are_found_in_both_languages() {
        let glsl = "const float A = 1e-3;\nlayout(constant_id = 0) const int S = 4;\n    const int D = A;\nconst float B3[3] = float[](1.0, 2.0, 3.0);";
        let names: Vec<String> = declarations("x.glsl", glsl)
            .into_iter()
            .map(|d| d.0)
            .collect();
        assert_eq!(names, ["A", "B3"]);
        let rust = "pub const N: u32 = 4;\nconst F: u32 = glsl_int(SRC, \"F\");\nconst T: [&str; 2] = [\"a\", \"b\"];";
        let names: Vec<String> = declarations("x.rs", rust)
            .into_iter()
            .map(|d| d.0)
            .collect();
        assert_eq!(names, ["N"]);
    }

    #[test]
    fn the_scan_sees_literals_and_skips_names_and_comments() {
        let src = "float a = x * 25.0; // 7.0 here is a comment\nconst float K = 9.0;\n\
                   vec3 v = vec3(1e-6, 2u, 0.5) /* 4.0 */ + fit_r_hi[5];\n\
                   for (int d = -2; d <= 2; ++d) { k = D - 1;";
        let lines = code_lines(src);
        assert_eq!(lines.len(), 3);
        let lits = |i: usize| -> Vec<(String, bool, bool)> { literals(&lines[i].1) };
        assert_eq!(lits(0), vec![("25.0".into(), false, false)]);
        let second: Vec<String> = lits(1).into_iter().map(|l| l.0).collect();
        assert_eq!(second, vec!["1e-6", "2u", "0.5", "5"]);
        assert!(!structural("25.0", false, false, false));
        assert!(!structural("1e-6", false, false, false));
        assert!(structural("2u", false, false, false) && structural("0.5", false, false, false));
        assert!(structural("5", false, true, false), "an index");
        // A window's literal radius is caught in a loop header, however small.
        let header: Vec<bool> = lits(2)
            .into_iter()
            .map(|(l, neg, idx)| structural(&l, neg, idx, true))
            .collect();
        assert_eq!(header, vec![false, true, true]);
    }
}
