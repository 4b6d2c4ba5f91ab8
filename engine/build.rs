//! Compiles `shaders/glsl/*.comp` to SPIR-V with shaderc (glslang) at build time and
//! embeds them, so a shader error is a build error and the binary needs no shader files.
use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets this"));
    let src = manifest.join("../shaders/glsl");
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets this"));
    glsl_build::rerun_if_changed(&src);
    match glsl_build::compile_dir(&src, &out) {
        Ok(compiled) => {
            std::fs::write(out.join("shaders.rs"), glsl_build::embed_rs(&compiled))
                .expect("write shaders.rs into OUT_DIR");
        }
        Err(e) => {
            eprintln!("{e}");
            panic!("shader compilation failed (see above)");
        }
    }
}
