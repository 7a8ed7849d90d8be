//! Links Debian's static glslang and SPIRV-Tools libraries that
//! `libshaderc_combined.a` needs: Debian builds the combined archive without
//! them, and its `libshaderc.so` crashes when linked dynamically. The
//! packages are libshaderc-dev, glslang-dev and spirv-tools (tools/setup).

use std::path::Path;

const LIBS: &[&str] = &[
    "SPIRV",
    "glslang",
    "MachineIndependent",
    "OSDependent",
    "GenericCodeGen",
    "OGLCompiler",
    "SPIRV-Tools-opt",
    "SPIRV-Tools",
];

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let arch = std::env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_else(|_| "x86_64".into());
    let debian_arch = if arch == "x86" { "i386" } else { arch.as_str() };
    let dir = format!("/usr/lib/{debian_arch}-linux-gnu");
    let missing: Vec<String> = ["shaderc_combined"]
        .iter()
        .chain(LIBS)
        .map(|l| format!("{dir}/lib{l}.a"))
        .filter(|p| !Path::new(p).is_file())
        .collect();
    if !missing.is_empty() {
        panic!(
            "weft-gpu links shaderc statically but {} missing; run tools/setup (libshaderc-dev, glslang-dev, spirv-tools)",
            missing.join(", ")
        );
    }
    println!("cargo:rustc-link-search=native={dir}");
    for lib in LIBS {
        println!("cargo:rustc-link-lib=static={lib}");
    }
}
