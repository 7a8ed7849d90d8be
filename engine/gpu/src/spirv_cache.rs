//! The SPIR-V cache: compiled shaders kept on disk so a warm start skips
//! shaderc's compile. An entry is named by a hash of everything the SPIR-V
//! depends on: the preprocessed source (every `#include` expanded, so an
//! edit to any included file changes it), the stage, the defines, the
//! target environment, shaderc's SPIR-V version and this crate's version.
//! An entry carries that hash whole and a checksum of its SPIR-V
//! ([`weft_io::entry`]): a damaged, swapped or foreign entry is rebuilt with a
//! warning, never trusted. The binary chooses the folder once at start (`weft` uses
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

/// The entry kind of SPIR-V in the cache ([`weft_io::entry`]).
const KIND: weft_io::entry::Kind = weft_io::entry::Kind {
    name: "spirv",
    version: 2,
};

/// The largest entry read: a compiled shader is far smaller.
const MAX_ENTRY_BYTES: u64 = 64 << 20;

/// The hash of everything a shader's SPIR-V depends on ([`weft_io::hash`]),
/// over length-prefixed fields. The entry is named after it and stores it
/// whole, so an entry moved onto another's name is noticed.
pub(crate) struct Key(weft_io::hash::Hasher);

impl Key {
    pub(crate) fn new() -> Self {
        let mut key = Self(weft_io::hash::Hasher::new());
        key.field(FORMAT.as_bytes());
        key.field(env!("CARGO_PKG_VERSION").as_bytes());
        let (major, minor) = shaderc::get_spirv_version();
        key.field(&major.to_le_bytes());
        key.field(&minor.to_le_bytes());
        key
    }

    pub(crate) fn field(&mut self, bytes: &[u8]) {
        self.0.field(bytes);
    }

    fn digest(&self) -> u128 {
        self.0.finish()
    }

    fn path(&self, dir: &Path) -> PathBuf {
        dir.join(format!("{}.spv", weft_io::hash::hex(self.digest())))
    }
}

/// The cached SPIR-V for `key`, when there is a sound entry. One that is
/// damaged (truncated, flipped bits, stored for another key, not a regular
/// file) or whose payload is not SPIR-V is reported and ignored; the caller
/// compiles again and [`store`] replaces it.
pub(crate) fn load(key: &Key, shader: &Path) -> Option<Vec<u32>> {
    let dir = dir()?;
    let path = key.path(&dir);
    let damaged = |why: String| {
        warn(format!(
            "the cached SPIR-V of {} ({}) is damaged ({why}); compiled again",
            shader.display(),
            path.display()
        ));
        None
    };
    let bytes =
        match weft_io::entry::read(&path, KIND, &key.digest().to_le_bytes(), MAX_ENTRY_BYTES) {
            Ok(Some(bytes)) => bytes,
            Ok(None) => return None,
            Err(damage) => return damaged(damage.to_string()),
        };
    let words: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        .collect();
    if bytes.len() % 4 != 0 || words.len() < 5 || words[0] != MAGIC {
        return damaged("its payload is not SPIR-V".into());
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
    let bytes: Vec<u8> = spirv.iter().flat_map(|w| w.to_le_bytes()).collect();
    if let Err(e) = weft_io::entry::write(&path, KIND, &key.digest().to_le_bytes(), &bytes) {
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

        // Each kind of damage is compiled again, with one warning naming it,
        // and the entry replaced by a sound one.
        let good = std::fs::read(&entries()[0]).expect("entry");
        let mut flipped = good.clone();
        let last = flipped.len() - 7;
        flipped[last..last + 4].iter_mut().for_each(|b| *b ^= 0xA5);
        type Damage<'a> = &'a dyn Fn(&std::path::Path);
        let damages: [(&str, Damage); 6] = [
            ("its checksum does not match", &|e| {
                std::fs::write(e, &flipped).expect("flip")
            }),
            ("it is truncated", &|e| {
                std::fs::write(e, &good[..good.len() - 9]).expect("cut")
            }),
            ("it is not a weft cache entry", &|e| {
                std::fs::write(e, b"").expect("empty")
            }),
            ("it is not a weft cache entry", &|e| {
                std::fs::write(e, b"not spir-v").expect("junk")
            }),
            ("it is a device", &|e| {
                std::fs::remove_file(e).expect("rm");
                std::os::unix::fs::symlink("/dev/zero", e).expect("link");
            }),
            ("it is a directory", &|e| {
                std::fs::remove_file(e).expect("rm");
                std::fs::create_dir(e).expect("dir");
            }),
        ];
        for (why, damage) in damages {
            let entry = entries()[0].clone();
            damage(&entry);
            let rebuilt = compiler
                .compile_file(&shader, ShaderStage::Compute, &[])
                .expect("compiles");
            assert_eq!(rebuilt.spirv, cold.spirv, "{why}");
            let warnings = super::take_warnings();
            let rebuilt: Vec<_> = warnings
                .iter()
                .filter(|w| w.ends_with("; compiled again"))
                .collect();
            assert!(
                rebuilt.len() == 1 && rebuilt[0].contains("a.comp") && rebuilt[0].contains(why),
                "{why}: {warnings:?}"
            );
            if entry.is_dir() {
                std::fs::remove_dir(&entry).expect("a folder cannot be replaced");
                compiler
                    .compile_file(&shader, ShaderStage::Compute, &[])
                    .expect("compiles");
                super::take_warnings();
            }
            assert_eq!(
                std::fs::read(&entry).expect("entry"),
                good,
                "{why}: rewritten"
            );
        }

        // An entry copied onto another key's name is stored for another input.
        std::fs::write(&include, "const float VALUE = 3.0;\n").expect("write");
        let other = compiler
            .compile_file(&shader, ShaderStage::Compute, &[])
            .expect("compiles");
        let other_entry = entries()
            .into_iter()
            .find(|e| std::fs::read(e).ok() != Some(good.clone()))
            .expect("second entry");
        std::fs::write(&include, "const float VALUE = 1.0;\n").expect("write");
        std::fs::copy(
            &other_entry,
            entries()
                .into_iter()
                .find(|e| *e != other_entry)
                .expect("first"),
        )
        .expect("swap");
        let served = compiler
            .compile_file(&shader, ShaderStage::Compute, &[])
            .expect("compiles");
        assert_eq!(served.spirv, cold.spirv, "never the other shader's SPIR-V");
        assert_ne!(other.spirv, cold.spirv);
        let warnings = super::take_warnings();
        assert!(
            warnings
                .iter()
                .any(|w| w.contains("stored for another input")),
            "{warnings:?}"
        );
        std::fs::remove_file(&other_entry).expect("rm");

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
