//! Links Debian's static glslang and SPIRV-Tools libraries that
//! `libshaderc_combined.a` needs: Debian builds the combined archive without
//! them, and its `libshaderc.so` crashes when linked dynamically.

const LIB_DIR: &str = "/usr/lib/x86_64-linux-gnu";
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
    println!("cargo:rustc-link-search=native={LIB_DIR}");
    for lib in LIBS {
        println!("cargo:rustc-link-lib=static={lib}");
    }
}
