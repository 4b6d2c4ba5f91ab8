//! Compiles every compute shader in a folder to SPIR-V at build time.
//!
//! `#include "x.glsl"` resolves against the shader folder's `include/` subfolder, so
//! the bindings, structs and helpers shared by passes are written once. The output is
//! one `.spv` per shader plus a generated Rust file that embeds them by name.

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

/// One compiled shader: its stem (`path_trace` for `path_trace.comp`) and the SPIR-V path.
pub struct Compiled {
    pub name: String,
    pub spv: PathBuf,
}

/// Compiles `src_dir/*.comp` into `out_dir`, returning the list, or a message naming the
/// shader and glslang's diagnostics.
pub fn compile_dir(src_dir: &Path, out_dir: &Path) -> Result<Vec<Compiled>, String> {
    let include_dir = src_dir.join("include");
    let compiler = shaderc::Compiler::new().map_err(|e| format!("shaderc: {e}"))?;
    let mut options = shaderc::CompileOptions::new().map_err(|e| format!("shaderc: {e}"))?;
    options.set_target_env(
        shaderc::TargetEnv::Vulkan,
        shaderc::EnvVersion::Vulkan1_3 as u32,
    );
    options.set_target_spirv(shaderc::SpirvVersion::V1_6);
    options.set_source_language(shaderc::SourceLanguage::GLSL);
    options.set_optimization_level(shaderc::OptimizationLevel::Performance);
    options.set_generate_debug_info(); // keeps OpName, which pipeline reflection binds by
    options.set_warnings_as_errors();
    let inc = include_dir.clone();
    // Shaders and includes are named relative to the shader folder: the SPIR-V's debug
    // strings hold these names, and an absolute path would make the same source compile
    // to different bytes in each checkout (eval's reference cache keys on the bytes).
    options.set_include_callback(move |requested, _ty, requester, _depth| {
        let path = inc.join(requested);
        let content = fs::read_to_string(&path).map_err(|e| {
            format!(
                "{requester}: cannot include {requested} ({}): {e}",
                path.display()
            )
        })?;
        Ok(shaderc::ResolvedInclude {
            resolved_name: format!("include/{requested}"),
            content,
        })
    });

    let mut entries: Vec<PathBuf> = fs::read_dir(src_dir)
        .map_err(|e| format!("{}: {e}", src_dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "comp"))
        .collect();
    entries.sort();

    let mut out = Vec::new();
    for path in entries {
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .ok_or_else(|| format!("{}: shader name is not UTF-8", path.display()))?
            .to_string();
        let source = fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let file_name = format!("{name}.comp");
        let artifact = compiler
            .compile_into_spirv(
                &source,
                shaderc::ShaderKind::Compute,
                &file_name,
                "main",
                Some(&options),
            )
            .map_err(|e| format!("{}:\n{e}", path.display()))?;
        let spv = out_dir.join(format!("{name}.spv"));
        fs::write(&spv, artifact.as_binary_u8()).map_err(|e| format!("{}: {e}", spv.display()))?;
        out.push(Compiled { name, spv });
    }
    Ok(out)
}

/// Rust source embedding the compiled shaders: `pub static SHADERS: &[(&str, &[u8])]`.
pub fn embed_rs(compiled: &[Compiled]) -> String {
    let mut s =
        String::from("/// Every compute shader, compiled at build time: (name, SPIR-V bytes).\n");
    s.push_str("pub static SHADERS: &[(&str, &[u8])] = &[\n");
    for c in compiled {
        let _ = writeln!(
            s,
            "    ({:?}, include_bytes!({:?})),",
            c.name,
            c.spv.display().to_string()
        );
    }
    s.push_str("];\n");
    s
}

/// Emits `cargo:rerun-if-changed` for the shader folder and everything in it.
pub fn rerun_if_changed(src_dir: &Path) {
    println!("cargo:rerun-if-changed={}", src_dir.display());
    for dir in [src_dir.to_path_buf(), src_dir.join("include")] {
        if let Ok(rd) = fs::read_dir(&dir) {
            for e in rd.flatten() {
                println!("cargo:rerun-if-changed={}", e.path().display());
            }
        }
    }
}
