//! Debian's libshaderc_combined.a holds only shaderc's own objects, and the shared
//! libshaderc.so leaves glslang symbols undefined for rust-lld. Link glslang and
//! SPIRV-Tools from their static archives instead (packages libshaderc-dev, glslang-dev,
//! spirv-tools; building shaderc from source takes well over 15 minutes on 2 cores). The
//! directives propagate to every binary that links this crate, build scripts included.
fn main() {
    let dir = std::env::var("DVR_GLSLANG_LIB_DIR")
        .unwrap_or_else(|_| "/usr/lib/x86_64-linux-gnu".to_string());
    println!("cargo:rerun-if-env-changed=DVR_GLSLANG_LIB_DIR");
    println!("cargo:rustc-link-search=native={dir}");
    for lib in [
        "glslang",
        "MachineIndependent",
        "GenericCodeGen",
        "OSDependent",
        "OGLCompiler",
        "SPIRV",
        "glslang-default-resource-limits",
        "HLSL",
        "SPIRV-Tools-opt",
        "SPIRV-Tools",
    ] {
        println!("cargo:rustc-link-lib=static={lib}");
    }
    println!("cargo:rustc-link-lib=dylib=stdc++");
}
