//! The one way these tests run `weft`: the built binary, in a given folder, with
//! a user cache of this test process's own (`WEFT_CACHE_DIR`) and an empty XDG
//! config (no pictures folder for screenshots), so results never depend on what
//! the user's `~/.cache/weft` or `~/.config/user-dirs.dirs` hold.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
pub use weft_testkit::scratch::{scratch, scratch_path};

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// This process's user cache folder, empty when first asked for.
pub fn user_cache() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| scratch(&format!("weft-cli-cache-{}", std::process::id())))
}

/// `weft ARGS` run in `dir`, not yet started; `.env("WEFT_CACHE_DIR", ..)` may replace the cache.
pub fn command_in(dir: &Path, args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_weft"));
    command
        .args(args)
        .current_dir(dir)
        .env("WEFT_CACHE_DIR", user_cache())
        .env("XDG_CONFIG_HOME", user_cache().join("xdg-config"))
        .env("XDG_DATA_HOME", user_cache().join("xdg-data"));
    command
}

/// Runs `weft ARGS` in the repository and waits for it.
pub fn weft(args: &[&str]) -> Output {
    command_in(&repo(), args).output().expect("weft runs")
}

/// Runs `command`, killing it (and failing the test) after `seconds`.
pub fn finish_within(command: &mut Command, seconds: u64) -> Output {
    let mut child = command
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("weft runs");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(seconds);
    while child.try_wait().expect("wait").is_none() {
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            let out = child.wait_with_output().expect("output");
            panic!(
                "{command:?} still ran after {seconds} s: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().expect("output")
}
