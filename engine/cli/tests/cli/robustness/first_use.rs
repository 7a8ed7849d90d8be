//! weft as a new user first meets it (issue 60): from a folder that is not
//! the repository, installed under a prefix, and with its output going to
//! a log instead of a terminal.

use super::*;

/// The folder `tools/install PREFIX BINARY` lays out, with this build's
/// binary: `PREFIX/bin/weft` and the graphs and shaders under
/// `PREFIX/share/weft`.
fn installed(name: &str) -> PathBuf {
    let prefix = temp(name);
    let status = Command::new("bash")
        .arg(repo().join("tools/install"))
        .arg(&prefix)
        .arg(env!("CARGO_BIN_EXE_weft"))
        .status()
        .expect("tools/install runs");
    assert!(status.success());
    prefix
}

/// The installed weft renders a scene given by its full path from an empty
/// folder, its default graph found in the install's share folder; WEFT_HOME
/// points an uninstalled binary at a checkout; a graph found nowhere says
/// where it was looked for.
#[test]
fn weft_renders_from_any_folder_installed_or_pointed_at_its_tree() {
    let prefix = installed("install");
    assert!(prefix.join("share/weft/graphs/forward.ron").is_file());
    assert!(prefix.join("share/weft/shaders/forward.frag").is_file());
    let elsewhere = temp("elsewhere");
    let scene = repo().join("scenes/cornell.scene");
    let png = elsewhere.join("c.png");
    let run = |command: &mut Command| finish_within(command, 120);
    let mut installed_weft = Command::new(prefix.join("bin/weft"));
    installed_weft
        .current_dir(&elsewhere)
        .env_remove("WEFT_HOME")
        .env("WEFT_CACHE_DIR", crate::harness::user_cache())
        .args([
            "render",
            &scene.to_string_lossy(),
            "--size",
            "16x16",
            "--out",
            &png.to_string_lossy(),
        ]);
    let out = run(&mut installed_weft);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("share/weft/graphs/forward.ron"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(png.is_file());
    // The build's own binary, not installed: found through WEFT_HOME.
    let mut pointed = command_in(&elsewhere, &["graph", "check", "graphs/deferred.ron"]);
    pointed.env("WEFT_HOME", repo());
    let out = run(&mut pointed);
    assert!(out.status.success(), "{}", stderr(&out));
    // Nowhere: the message names the places looked in, not include paths.
    let mut lost = command_in(&elsewhere, &["graph", "check", "graphs/forward.ron"]);
    lost.env_remove("WEFT_HOME");
    let out = run(&mut lost);
    let err = format!("{}{}", String::from_utf8_lossy(&out.stdout), stderr(&out));
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot read graph file: no such file; looked in $WEFT_HOME (unset)")
            && err.contains("graphs/forward.ron (the current folder)")
            && err.contains("set WEFT_HOME")
            && !err.contains("include paths"),
        "{err}"
    );
    std::fs::remove_dir_all(&prefix).expect("clean up");
    std::fs::remove_dir_all(&elsewhere).expect("clean up");
}

/// With stderr a file, a progressive render prints progress lines (samples,
/// rate, time left) instead of a bar no one sees.
#[test]
fn long_work_reports_progress_in_a_log() {
    let dir = temp("progress-log");
    let exr = dir.join("ref.exr");
    let out = weft_within(
        &repo(),
        &[
            "render",
            "scenes/cornell.scene",
            "--graph",
            "graphs/pathtrace.ron",
            "--size",
            "32x32",
            "--spp",
            "100000",
            "--time-limit",
            "3",
            "--out",
            &exr.to_string_lossy(),
        ],
        300,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("render: frame "))
        .collect();
    assert!(!lines.is_empty(), "no progress lines: {err}");
    assert!(
        lines[0].contains("/100000 (")
            && lines[0].contains(" spp, ")
            && lines[0].contains("frame/s")
            && lines[0].contains(", ETA "),
        "{err}"
    );
    assert!(
        err.lines()
            .any(|l| l.starts_with("render: done, ") && l.contains(" frames in 3.")),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}
