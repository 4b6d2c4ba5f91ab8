//! ours' fixed constants live in one place per language: the shaders' in
//! `shaders/glsl/include/ours_constants.glsl` (a few in the shader they belong to, as
//! `const` declarations), the Rust side's beside [`super::OursParams`] (`LAG_RADIUS`,
//! [`super::ATROUS_LEVELS`], [`super::prior::PRIOR_STRIDE`]). The test here reads ours'
//! shaders and fails on any numeric literal outside a named declaration that is not
//! structural (0–3, the channel count among them, and the Catmull-Rom weights' halves),
//! so a number that changes the output cannot enter without a name.

/// The shaders ours runs, and the includes only ours reads.
const SOURCES: [(&str, &str); 13] = [
    (
        "ours_gradient.comp",
        include_str!("../../../../shaders/glsl/ours_gradient.comp"),
    ),
    (
        "ours_gradient_pool.comp",
        include_str!("../../../../shaders/glsl/ours_gradient_pool.comp"),
    ),
    (
        "ours_guide.comp",
        include_str!("../../../../shaders/glsl/ours_guide.comp"),
    ),
    (
        "ours_lag.comp",
        include_str!("../../../../shaders/glsl/ours_lag.comp"),
    ),
    (
        "ours_noise.comp",
        include_str!("../../../../shaders/glsl/ours_noise.comp"),
    ),
    (
        "ours_prior.comp",
        include_str!("../../../../shaders/glsl/ours_prior.comp"),
    ),
    (
        "ours_prior_fit.comp",
        include_str!("../../../../shaders/glsl/ours_prior_fit.comp"),
    ),
    (
        "ours_prior_sums.comp",
        include_str!("../../../../shaders/glsl/ours_prior_sums.comp"),
    ),
    (
        "ours_update.comp",
        include_str!("../../../../shaders/glsl/ours_update.comp"),
    ),
    (
        "variance_atrous.comp",
        include_str!("../../../../shaders/glsl/variance_atrous.comp"),
    ),
    (
        "include/ours_change.glsl",
        include_str!("../../../../shaders/glsl/include/ours_change.glsl"),
    ),
    (
        "include/ours_prior.glsl",
        include_str!("../../../../shaders/glsl/include/ours_prior.glsl"),
    ),
    (
        "include/ours_constants.glsl",
        include_str!("../../../../shaders/glsl/include/ours_constants.glsl"),
    ),
];

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
    fn every_output_changing_number_in_ours_shaders_is_named() {
        let mut unnamed = Vec::new();
        for (file, src) in SOURCES {
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
