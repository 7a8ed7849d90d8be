//! The SPIR-V cache: compiled shaders kept on disk so a warm start skips
//! shaderc's compile. An entry is named by a hash of everything the SPIR-V
//! depends on: the preprocessed source (every `#include` expanded, so an
//! edit to any included file changes it), the stage, the defines, the
//! target environment, shaderc's SPIR-V version and this crate's version.
//! An entry that is not valid SPIR-V is rebuilt with a warning, never
//! trusted. The binary chooses the folder once at start (`weft` uses
//! `$WEFT_CACHE_DIR/spirv`, else `$XDG_CACHE_HOME/weft/spirv` or
//! `~/.cache/weft/spirv`, and `--no-cache` turns it off); by default nothing
//! is cached.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

/// The SPIR-V magic number, the first word of every module.
const MAGIC: u32 = 0x0723_0203;

/// Bumped when what a key covers changes.
const FORMAT: &str = "weft spirv 1";

struct State {
    dir: Option<PathBuf>,
    warnings: Vec<String>,
}

fn state() -> &'static Mutex<State> {
    static STATE: OnceLock<Mutex<State>> = OnceLock::new();
    STATE.get_or_init(|| {
        Mutex::new(State {
            dir: None,
            warnings: Vec::new(),
        })
    })
}

/// Sets the folder compiled shaders are cached in (`None`: no caching).
pub fn set_dir(dir: Option<PathBuf>) {
    if let Ok(mut s) = state().lock() {
        s.dir = dir;
    }
}

/// The folder in use, if any.
pub fn dir() -> Option<PathBuf> {
    state().lock().ok().and_then(|s| s.dir.clone())
}

/// Warnings about entries that were rebuilt, since the last call.
pub fn take_warnings() -> Vec<String> {
    state()
        .lock()
        .map(|mut s| std::mem::take(&mut s.warnings))
        .unwrap_or_default()
}

fn warn(message: String) {
    if let Ok(mut s) = state().lock() {
        s.warnings.push(message);
    }
}

/// 64-bit FNV-1a over length-prefixed fields.
pub(crate) struct Key(u64);

impl Key {
    pub(crate) fn new() -> Self {
        let mut key = Self(0xcbf2_9ce4_8422_2325);
        key.field(FORMAT.as_bytes());
        key.field(env!("CARGO_PKG_VERSION").as_bytes());
        let (major, minor) = shaderc::get_spirv_version();
        key.field(&major.to_le_bytes());
        key.field(&minor.to_le_bytes());
        key
    }

    pub(crate) fn field(&mut self, bytes: &[u8]) {
        for &b in (bytes.len() as u64).to_le_bytes().iter().chain(bytes) {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn path(&self, dir: &Path) -> PathBuf {
        dir.join(format!("{:016x}.spv", self.0))
    }
}

/// The cached SPIR-V for `key`, when there is a valid entry. A damaged one
/// (not whole words, or not starting with SPIR-V's magic number) is
/// reported and ignored.
pub(crate) fn load(key: &Key, shader: &Path) -> Option<Vec<u32>> {
    let dir = dir()?;
    let path = key.path(&dir);
    let bytes = std::fs::read(&path).ok()?;
    let words: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        .collect();
    if bytes.len() % 4 != 0 || words.len() < 5 || words[0] != MAGIC {
        warn(format!(
            "the cached SPIR-V of {} ({}) is damaged; compiled again",
            shader.display(),
            path.display()
        ));
        return None;
    }
    Some(words)
}

/// Stores `spirv` for `key`, written aside and renamed into place. A cache
/// that cannot be written is reported once per entry and otherwise ignored.
pub(crate) fn store(key: &Key, spirv: &[u32]) {
    let Some(dir) = dir() else {
        return;
    };
    let path = key.path(&dir);
    let partial = path.with_extension(format!("partial{}", std::process::id()));
    let bytes: Vec<u8> = spirv.iter().flat_map(|w| w.to_le_bytes()).collect();
    let written = std::fs::create_dir_all(&dir)
        .and_then(|()| std::fs::write(&partial, &bytes))
        .and_then(|()| std::fs::rename(&partial, &path));
    if let Err(e) = written {
        warn(format!(
            "cannot write the SPIR-V cache {}: {e}",
            path.display()
        ));
    }
}

#[cfg(test)]
mod tests {
    use crate::shader::{ShaderCompiler, ShaderStage};

    /// One test owns the process-wide folder, so the steps run in order.
    #[test]
    fn entries_are_reused_rebuilt_when_damaged_and_keyed_by_includes() {
        let dir = std::env::temp_dir().join(format!("weft-spirv-cache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        let shader = dir.join("a.comp");
        let include = dir.join("value.glsl");
        std::fs::write(&include, "const float VALUE = 1.0;\n").expect("write");
        std::fs::write(
            &shader,
            "#version 450\n#include \"value.glsl\"\nlayout(local_size_x = 1) in;\n\
             layout(set = 0, binding = 0) buffer B { float v; } b;\nvoid main() { b.v = VALUE; }\n",
        )
        .expect("write");
        let cache = dir.join("cache");
        super::set_dir(Some(cache.clone()));
        let compiler = ShaderCompiler::new(Vec::new()).expect("compiler");
        let entries = || {
            std::fs::read_dir(&cache)
                .map(|d| {
                    d.filter_map(Result::ok)
                        .map(|e| e.path())
                        .collect::<Vec<_>>()
                })
                .unwrap_or_default()
        };
        let cold = compiler
            .compile_file(&shader, ShaderStage::Compute, &[])
            .expect("compiles");
        assert_eq!(entries().len(), 1);
        let warm = compiler
            .compile_file(&shader, ShaderStage::Compute, &[])
            .expect("from the cache");
        assert_eq!(warm, cold, "same SPIR-V and the same dependencies");
        assert!(warm.dependencies.contains(&include));

        // A damaged entry is compiled again, with a warning, and replaced.
        std::fs::write(&entries()[0], b"not spir-v").expect("damage");
        let rebuilt = compiler
            .compile_file(&shader, ShaderStage::Compute, &[])
            .expect("compiles");
        assert_eq!(rebuilt.spirv, cold.spirv);
        let warnings = super::take_warnings();
        assert!(
            warnings
                .iter()
                .any(|w| w.contains("a.comp") && w.ends_with("is damaged; compiled again")),
            "{warnings:?}"
        );
        assert_eq!(
            std::fs::read(&entries()[0]).expect("entry").len(),
            cold.spirv.len() * 4
        );

        // Editing an included file, or a define, makes another entry.
        std::fs::write(&include, "const float VALUE = 2.0;\n").expect("write");
        let edited = compiler
            .compile_file(&shader, ShaderStage::Compute, &[])
            .expect("compiles");
        assert_ne!(edited.spirv, cold.spirv);
        compiler
            .compile_file(&shader, ShaderStage::Compute, &["EXTRA".to_string()])
            .expect("compiles");
        assert_eq!(entries().len(), 3);
        super::set_dir(None);
    }
}
