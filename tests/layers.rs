//! The application's layers import only downward (OVERVIEW.md, "Layers of the
//! application"): every `crate::<module>` path in `src/` names a module of a lower layer
//! (or its own), and inside `dvr eval` every `crate::eval::<layer>` or `super::<layer>`
//! path names a lower eval layer. And the engine's GPU-free crates (`engine/volume`,
//! `engine/scene`, `engine/metrics`) name no Vulkan crate among their dependencies, so
//! they keep building and testing without a Vulkan loader. Reads the sources and
//! manifests as text; needs no GPU.

use std::path::{Path, PathBuf};

/// Top-level modules of `src/` by layer: a module may import only lower layers.
const APP_LAYERS: &[(&str, u32)] = &[
    ("main", 6),
    ("lib", 6),
    ("cli", 5),
    ("bench", 4),
    ("capture", 3),
    ("demo", 3),
    ("eval", 2),
    ("explore", 2),
    ("info", 1),
    ("setup", 1),
    ("shard", 1),
    ("video", 1),
    ("logger", 1),
    ("args", 0),
    ("output", 0),
    ("font", 0),
    ("progress", 0),
    ("profile", 0),
];

/// `dvr eval`'s layers: plan → references, results → run, scores → report → the command.
const EVAL_LAYERS: &[(&str, u32)] = &[
    ("plan", 0),
    ("references", 1),
    ("results", 1),
    ("run", 2),
    ("scores", 2),
    ("report", 3),
    ("mod", 4),
    ("farm", 4),
];

fn layer(table: &[(&str, u32)], name: &str) -> Option<u32> {
    table.iter().find(|(n, _)| *n == name).map(|&(_, l)| l)
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("read src") {
        let p = entry.expect("entry").path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Each `<prefix><name>` in `text` (a path segment after the prefix).
fn named_after<'a>(text: &'a str, prefix: &str) -> Vec<&'a str> {
    text.match_indices(prefix)
        .filter_map(|(i, _)| {
            let rest = &text[i + prefix.len()..];
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            (end > 0).then(|| &rest[..end])
        })
        .collect()
}

/// The upward imports of one file, as "file: path" lines.
fn upward(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).expect("under src");
    let parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    let text = std::fs::read_to_string(file).expect("read source");
    let mut bad = Vec::new();
    let own = parts[0].as_str();
    let own_layer = layer(APP_LAYERS, own).unwrap_or_else(|| panic!("{own} has no layer"));
    for target in named_after(&text, "crate::") {
        if target == own {
            continue;
        }
        match layer(APP_LAYERS, target) {
            Some(l) if l < own_layer => {}
            _ => bad.push(format!("{}: crate::{target}", rel.display())),
        }
    }
    if own == "eval" {
        // The eval layer this file is in: eval/<layer>.rs or eval/<layer>/...
        let sub = parts.get(1).map_or("mod", String::as_str);
        let mine = layer(EVAL_LAYERS, sub).unwrap_or(4);
        let mut targets = named_after(&text, "crate::eval::");
        // `super::` reaches eval's layers from eval/<layer>.rs and eval/<layer>/mod.rs.
        if parts.len() == 2 || (parts.len() == 3 && parts[2] == "mod") {
            targets.extend(named_after(&text, "super::"));
        }
        for target in targets {
            if let Some(l) = layer(EVAL_LAYERS, target) {
                if target != sub && l >= mine {
                    bad.push(format!("{}: eval layer {target}", rel.display()));
                }
            }
        }
    }
    bad
}

#[test]
fn the_application_imports_only_downward() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(files.len() > 40, "found {} files under src/", files.len());
    let bad: Vec<String> = files.iter().flat_map(|f| upward(&src, f)).collect();
    assert!(bad.is_empty(), "upward imports:\n{}", bad.join("\n"));
}

#[test]
fn the_checker_sees_an_upward_import() {
    // A file of the bottom layer naming the eval command, as profile once did.
    let dir = tempfile::tempdir().expect("tempdir");
    let src = dir.path();
    std::fs::create_dir_all(src.join("profile")).expect("mkdir");
    std::fs::create_dir_all(src.join("eval/plan")).expect("mkdir");
    let bad_file = src.join("profile/methods.rs");
    std::fs::write(&bad_file, "use crate::eval::run::method_gpu_ms;\n").expect("write");
    assert_eq!(
        upward(src, &bad_file),
        vec!["profile/methods.rs: crate::eval"]
    );
    let plan = src.join("eval/plan/mod.rs");
    std::fs::write(
        &plan,
        "use super::run::x;\nuse crate::profile::WARMUP_FRAMES;\n",
    )
    .expect("write");
    assert_eq!(upward(src, &plan), vec!["eval/plan/mod.rs: eval layer run"]);
}

/// The engine's crates that build and test without a Vulkan loader.
const GPU_FREE_CRATES: &[&str] = &["engine/volume", "engine/scene", "engine/metrics"];

/// Crates that need Vulkan (or the engine that does) at build or test time.
const VULKAN_CRATES: &[&str] = &[
    "ash",
    "ash-window",
    "gpu-allocator",
    "shaderc",
    "glsl-build",
    "dvr-engine",
];

/// The Vulkan crates a manifest's dependency sections (normal, dev and build) name.
fn vulkan_dependencies(manifest: &str) -> Vec<String> {
    let mut section = "";
    let mut found = Vec::new();
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            section = line;
            continue;
        }
        if !section.ends_with("dependencies]") {
            continue;
        }
        let name = line
            .split(|c: char| c == '=' || c == '.' || c.is_whitespace())
            .next()
            .unwrap_or("");
        if VULKAN_CRATES.contains(&name) {
            found.push(format!("{section} {name}"));
        }
    }
    found
}

#[test]
fn the_gpu_free_crates_name_no_vulkan_crate() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let workspace = std::fs::read_to_string(root.join("Cargo.toml")).expect("read Cargo.toml");
    for krate in GPU_FREE_CRATES {
        assert!(
            workspace.contains(&format!("\"{krate}\"")),
            "{krate} is not a workspace member"
        );
        let manifest = std::fs::read_to_string(root.join(krate).join("Cargo.toml"))
            .unwrap_or_else(|e| panic!("{krate}/Cargo.toml: {e}"));
        let bad = vulkan_dependencies(&manifest);
        assert!(bad.is_empty(), "{krate}/Cargo.toml: {}", bad.join(", "));
    }
}

#[test]
fn the_checker_sees_a_vulkan_dependency() {
    let manifest = "[package]\nname = \"x\"\n\n[dependencies]\nglam.workspace = true\n\
                    ash.workspace = true\n\n[dev-dependencies]\n\
                    dvr-engine = { path = \"..\" }\n";
    assert_eq!(
        vulkan_dependencies(manifest),
        vec!["[dependencies] ash", "[dev-dependencies] dvr-engine"]
    );
}
