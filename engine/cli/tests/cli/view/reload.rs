//! Hot reload in `weft view`: a shader edit is picked up while viewing and a
//! broken one keeps the last good version, and a slow reload is prepared
//! while frames keep being presented.

use super::{load, Xvfb};
use crate::harness::repo;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

/// How long a reload may take before the test gives up (lavapipe under load).
const REPLY: Duration = Duration::from_secs(60);

/// A copy of the graphs and shaders, so edits never touch the repository.
struct Copy(PathBuf);

impl Copy {
    fn new(name: &str) -> Self {
        let dir = crate::harness::scratch_path(&format!("weft-view-{name}-{}", std::process::id()));
        for folder in ["graphs", "shaders"] {
            copy_dir(&repo().join(folder), &dir.join(folder));
        }
        Self(dir)
    }
}

impl Drop for Copy {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("create copy folder");
    for entry in std::fs::read_dir(from).expect("read folder") {
        let entry = entry.expect("folder entry");
        let target = to.join(entry.file_name());
        if entry.path().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).expect("copy file");
        }
    }
}

/// Waits for a line of `lines` that satisfies `wanted`.
fn wait_for(lines: &Receiver<String>, wanted: impl Fn(&str) -> bool, what: &str) -> String {
    let deadline = Instant::now() + REPLY;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match lines.recv_timeout(left) {
            Ok(line) if wanted(&line) => return line,
            Ok(_) => {}
            Err(_) => panic!("no {what} within {REPLY:?}"),
        }
    }
}

/// Lines a pipe carries, read on a thread.
fn lines(pipe: impl Read + Send + 'static) -> Receiver<String> {
    let (send, receive) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(pipe).lines().map_while(Result::ok) {
            if send.send(line).is_err() {
                break;
            }
        }
    });
    receive
}

/// `weft view` with `args` in `dir`, its output read line by line, once it
/// has listed the graph's features (its first frame is up).
fn view(x: &Xvfb, dir: &Path, args: &[&str]) -> (Child, Receiver<String>, Receiver<String>) {
    let mut child = x
        .command(args, dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("weft starts");
    let stdout = lines(child.stdout.take().expect("stdout"));
    let stderr = lines(child.stderr.take().expect("stderr"));
    wait_for(&stdout, |l| l.starts_with("graph "), "features line");
    (child, stdout, stderr)
}

/// Stops the viewer as a user's SIGTERM would: it exits cleanly (writing its
/// screenshot) with no validation message left on stderr.
fn stop(mut child: Child, stderr: &Receiver<String>) {
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(killed.success());
    let status = child.wait().expect("weft exits");
    let rest: Vec<String> = stderr.try_iter().collect();
    assert!(status.success(), "{status:?}; stderr: {rest:?}");
    assert!(rest.iter().all(|l| !l.contains("validation")), "{rest:?}");
}

#[test]
fn shader_edits_reload_while_viewing_and_a_broken_one_keeps_the_last_good() {
    const TONEMAP: &str = "shaders/tonemap.frag";
    const OUT: &str = "color = vec4(c / (1.0 + c), 1.0);";
    let x = Xvfb::start();
    let copy = Copy::new("reload");
    let shot = copy.0.join("last.png");
    let scene = repo().join("scenes/demo.scene");
    let (child, stdout, stderr) = view(
        &x,
        &copy.0,
        &[
            "view",
            scene.to_str().expect("utf-8 path"),
            "--size",
            "64x36",
            "--validate",
            "--screenshot-on-exit",
            shot.to_str().expect("utf-8 path"),
        ],
    );
    let tonemap = copy.0.join(TONEMAP);
    let original = std::fs::read_to_string(&tonemap).expect("read shader");
    assert!(original.contains(OUT));

    let saved = Instant::now();
    std::fs::write(
        &tonemap,
        original.replace(OUT, "color = vec4(1.0, 0.0, 0.0, 1.0);"),
    )
    .expect("edit shader");
    let line = wait_for(&stdout, |l| l.starts_with("reloaded "), "reload line");
    eprintln!(
        "edit to shown: {:.1} ms ({line})",
        saved.elapsed().as_secs_f64() * 1e3
    );
    assert!(line.contains("tonemap.frag"), "{line}");

    let broken_line = original.lines().count() + 1;
    std::fs::write(&tonemap, format!("{original}this is not glsl\n")).expect("break shader");
    let error = wait_for(&stderr, |l| l.starts_with("error: "), "error line");
    assert!(
        error.contains(&format!("tonemap.frag:{broken_line}: "))
            && error.ends_with("(kept last good)"),
        "{error}"
    );

    stop(child, &stderr);
    let image = load(&shot);
    assert_eq!(image.dimensions(), (64, 36));
    assert!(
        image.pixels().all(|p| p.0 == [255, 0, 0, 255]),
        "the red version is still shown after the broken edit"
    );
}

/// A reload whose preparation takes 1.5 s (the hidden `--prepare-delay-ms`) is
/// prepared on the worker: frames keep being presented meanwhile, none of them
/// as long as the delay, and the edit still goes live.
#[test]
fn a_slow_reload_is_prepared_while_frames_keep_being_presented() {
    const TONEMAP: &str = "shaders/tonemap.frag";
    const OUT: &str = "color = vec4(c / (1.0 + c), 1.0);";
    const DELAY_MS: f64 = 1500.0;
    let x = Xvfb::start();
    let copy = Copy::new("slow");
    std::fs::create_dir_all(copy.0.join("scenes")).expect("scenes folder");
    std::fs::write(
        copy.0.join("scenes/quad.obj"),
        "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nvn 0 1 0\nf 1//1 3//1 2//1\nf 1//1 4//1 3//1\n",
    )
    .expect("write model");
    std::fs::write(
        copy.0.join("scenes/tiny.scene"),
        "model\n{\n\tfile \"quad.obj\"\n}\ncamera\n{\n\tposition 0 3 5\n\ttarget 0 0 0\n}\n\
         sunlight\n{\n\tdirection -0.3 -1 -0.4\n\tcolor 0.3 0.3 0.3\n}\n",
    )
    .expect("write scene");
    let shot = copy.0.join("last.png");
    let (child, stdout, stderr) = view(
        &x,
        &copy.0,
        &[
            "view",
            "scenes/tiny.scene",
            "--size",
            "64x36",
            "--validate",
            "--prepare-delay-ms",
            "1500",
            "--screenshot-on-exit",
            shot.to_str().expect("utf-8 path"),
        ],
    );
    let tonemap = copy.0.join(TONEMAP);
    let original = std::fs::read_to_string(&tonemap).expect("read shader");
    std::fs::write(
        &tonemap,
        original.replace(OUT, "color = vec4(1.0, 0.0, 0.0, 1.0);"),
    )
    .expect("edit shader");
    let line = wait_for(&stdout, |l| l.starts_with("reloaded "), "reload line");
    let number_before = |marker: &str| -> f64 {
        let head = &line[..line
            .find(marker)
            .unwrap_or_else(|| panic!("{marker}: {line}"))];
        let word = head.split_whitespace().last().expect("a number");
        word.parse().unwrap_or_else(|_| panic!("{word}: {line}"))
    };
    let prepare_ms = number_before(" ms; ");
    let frames = number_before(" frames presented");
    let longest = line
        .split("the longest ")
        .nth(1)
        .and_then(|rest| rest.split(" ms").next())
        .and_then(|n| n.parse::<f64>().ok())
        .unwrap_or_else(|| panic!("longest: {line}"));
    eprintln!("{line}");
    assert!(prepare_ms >= DELAY_MS, "{line}");
    assert!(frames > 0.0, "{line}");
    assert!(longest < DELAY_MS, "{line}");

    stop(child, &stderr);
    assert!(
        load(&shot).pixels().all(|p| p.0 == [255, 0, 0, 255]),
        "the edit is live"
    );
}
