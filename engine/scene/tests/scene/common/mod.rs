//! Helpers shared by the integration tests: asset paths and warning text.

use std::path::{Path, PathBuf};

/// A file under `../shared/assets` (read in place, never copied).
pub fn asset(rel: &str) -> PathBuf {
    Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/assets"
    ))
    .join(rel)
}

/// A file under the repository's `scenes/`.
pub fn repo_scene(rel: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes")).join(rel)
}

/// Warnings as `basename:line: message`, so expectations do not depend on the checkout path.
pub fn short_warnings(warnings: &[weft_scene::Warning]) -> Vec<String> {
    warnings
        .iter()
        .map(|w| {
            let name =
                w.at.file
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default();
            match w.at.line {
                Some(l) => format!("{name}:{l}: {}", w.message),
                None => format!("{name}: {}", w.message),
            }
        })
        .collect()
}

/// A fresh empty folder under the system temp folder, unique to this test,
/// removed with everything in it when dropped (the large-model tests copy
/// tens of megabytes into theirs).
pub struct TempDir(PathBuf);

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Creates the test's `TempDir`.
pub fn temp_dir(name: &str) -> TempDir {
    let dir = std::env::temp_dir().join(format!("weft-scene-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    TempDir(dir)
}

/// The bytes of `member` inside the zip archive `zip` (stored or deflated), read through the
/// archive's central directory; panics with a message when the archive is not as expected.
pub fn unzip_member(zip: &Path, member: &str) -> Vec<u8> {
    let data = std::fs::read(zip).expect("read zip");
    let u16_at = |o: usize| u16::from_le_bytes([data[o], data[o + 1]]) as usize;
    let u32_at =
        |o: usize| u32::from_le_bytes([data[o], data[o + 1], data[o + 2], data[o + 3]]) as usize;
    let eocd = (0..data.len() - 21)
        .rev()
        .find(|&o| u32_at(o) == 0x0605_4b50)
        .expect("end of central directory");
    let (count, mut at) = (u16_at(eocd + 10), u32_at(eocd + 16));
    for _ in 0..count {
        assert_eq!(u32_at(at), 0x0201_4b50, "central directory entry");
        let (method, size) = (u16_at(at + 10), u32_at(at + 20));
        let (name_len, extra_len, comment_len) =
            (u16_at(at + 28), u16_at(at + 30), u16_at(at + 32));
        let name = String::from_utf8_lossy(&data[at + 46..at + 46 + name_len]);
        if name == member {
            let local = u32_at(at + 42);
            let start = local + 30 + u16_at(local + 26) + u16_at(local + 28);
            let raw = &data[start..start + size];
            return match method {
                0 => raw.to_vec(),
                8 => miniz_oxide::inflate::decompress_to_vec(raw).expect("inflate"),
                other => panic!("zip method {other}"),
            };
        }
        at += 46 + name_len + extra_len + comment_len;
    }
    panic!("{member} not in {}", zip.display())
}

/// Cases per fuzzing property: `default` under `make test`, `WEFT_FUZZ_CASES`
/// under `make fuzz` (see docs/fuzzing.md).
pub fn fuzz_cases(default: u32) -> u32 {
    std::env::var("WEFT_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}
