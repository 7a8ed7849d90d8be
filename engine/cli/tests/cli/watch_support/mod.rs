//! A `weft render --watch` child for tests: a private copy of the forward graph,
//! the shaders and a tiny scene in a temporary folder (the repository's files are
//! never edited), the child's stdout read line by line, edits made the ways
//! editors make them, and the output image decoded.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use crate::harness::command_in;

/// How long one reload may take before a test gives up (lavapipe under load).
pub const REPLY: Duration = Duration::from_secs(60);

/// A floor quad with a small slanted triangle on it.
const QUAD_OBJ: &str = "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nv -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0 1 0\nvn 0 1 0\nvn 0 0.5 -0.86\nf 1//1 3//1 2//1\nf 1//1 4//1 3//1\nf 5//2 7//2 6//2\n";

/// The tiny scene: the quad, a camera above it and a dim sun.
pub const SCENE: &str = "model\n{\n\tfile \"quad.obj\"\n}\n\ncamera \"main\"\n{\n\tposition 0 3 5\n\ttarget 0 0 0\n}\n\nsunlight\n{\n\tdirection -0.3 -1 -0.4\n\tcolor 0.3 0.3 0.3\n\tambient 0.05\n}\n";

/// Held by each test so they run one at a time: parallel lavapipe renders on a
/// 2-core machine would distort the latencies measured and slow every reload.
static SERIAL: Mutex<()> = Mutex::new(());

/// Takes the one-test-at-a-time lock (a failed test does not block the others).
pub fn serial() -> MutexGuard<'static, ()> {
    SERIAL
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
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

/// A temporary folder with `graphs/`, `shaders/`, `scenes/tiny.scene` and `out/`.
pub struct Fixture {
    /// The folder; removed on drop.
    pub dir: PathBuf,
}

impl Fixture {
    /// Copies the graphs and shaders and writes the scene, under a name unique to the test.
    pub fn new(name: &str) -> Self {
        let dir =
            crate::harness::scratch_path(&format!("weft-watch-{name}-{}", std::process::id()));
        copy_dir(&repo().join("graphs"), &dir.join("graphs"));
        copy_dir(&repo().join("shaders"), &dir.join("shaders"));
        std::fs::create_dir_all(dir.join("scenes")).expect("scenes folder");
        std::fs::create_dir_all(dir.join("out")).expect("out folder");
        std::fs::write(dir.join("scenes/quad.obj"), QUAD_OBJ).expect("write obj");
        std::fs::write(dir.join("scenes/tiny.scene"), SCENE).expect("write scene");
        Self { dir }
    }

    /// A file in the fixture.
    pub fn path(&self, relative: &str) -> PathBuf {
        self.dir.join(relative)
    }

    /// The file's text.
    pub fn read(&self, relative: &str) -> String {
        std::fs::read_to_string(self.path(relative)).expect("read fixture file")
    }

    /// Saves like editors that write a temporary file and rename it over the original.
    pub fn save_by_rename(&self, relative: &str, text: &str) {
        let path = self.path(relative);
        let tmp = path.with_extension("swp~");
        std::fs::write(&tmp, text).expect("write temp");
        std::fs::rename(&tmp, &path).expect("rename over");
    }

    /// Saves like editors that truncate the file and write it again in place.
    pub fn save_in_place(&self, relative: &str, text: &str) {
        std::fs::write(self.path(relative), text).expect("write in place");
    }

    /// The output image's RGBA8 pixels.
    pub fn pixels(&self) -> Vec<u8> {
        image::open(self.path("out/live.png"))
            .expect("decode output")
            .to_rgba8()
            .into_raw()
    }
}

impl Drop for Fixture {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Mean of the red, green and blue channels over all pixels (0..=255).
pub fn brightness(pixels: &[u8]) -> f64 {
    let rgb: Vec<f64> = pixels
        .chunks_exact(4)
        .flat_map(|p| p[..3].iter().map(|&c| f64::from(c)))
        .collect();
    rgb.iter().sum::<f64>() / rgb.len().max(1) as f64
}

/// A running `weft render --watch`.
pub struct Watch {
    child: Child,
    lines: Receiver<String>,
    stderr: Arc<Mutex<String>>,
}

impl Watch {
    /// Starts the child on the fixture (64x36, forward graph, `extra` arguments) and
    /// waits for its first image.
    pub fn start(fixture: &Fixture, extra: &[&str]) -> Self {
        let mut watch = Self::spawn(fixture, extra);
        let first = watch.line();
        assert!(first.starts_with("wrote out/live.png"), "{first}");
        watch
    }

    /// Starts the child on the fixture without waiting for anything.
    pub fn spawn(fixture: &Fixture, extra: &[&str]) -> Self {
        let mut child = command_in(
            &fixture.dir,
            &[
                "render",
                "scenes/tiny.scene",
                "--graph",
                "graphs/forward.ron",
                "--size",
                "64x36",
                "--out",
                "out/live.png",
                "--watch",
            ],
        )
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("weft starts");
        let (send, lines) = channel();
        let stdout = child.stdout.take().expect("stdout");
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if send.send(line).is_err() {
                    break;
                }
            }
        });
        let stderr = Arc::new(Mutex::new(String::new()));
        let collected = Arc::clone(&stderr);
        let mut pipe = child.stderr.take().expect("stderr");
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = pipe.read(&mut buf) {
                if n == 0 {
                    break;
                }
                if let Ok(mut text) = collected.lock() {
                    text.push_str(&String::from_utf8_lossy(&buf[..n]));
                }
            }
        });
        Self {
            child,
            lines,
            stderr,
        }
    }

    /// The next line the child prints.
    pub fn line(&mut self) -> String {
        match self.lines.recv_timeout(REPLY) {
            Ok(line) => line,
            Err(_) => panic!(
                "no line from weft within {REPLY:?}; stderr:\n{}",
                self.stderr()
            ),
        }
    }

    /// The next line, and when it arrived.
    pub fn timed_line(&mut self) -> (String, Instant) {
        let line = self.line();
        (line, Instant::now())
    }

    /// Everything the child wrote to stderr so far.
    pub fn stderr(&self) -> String {
        self.stderr.lock().map(|t| t.clone()).unwrap_or_default()
    }

    /// The child's process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// The child's resident memory in KiB, from /proc.
    pub fn rss_kib(&self) -> u64 {
        let status =
            std::fs::read_to_string(format!("/proc/{}/status", self.pid())).expect("child status");
        status
            .lines()
            .find_map(|l| l.strip_prefix("VmRSS:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
            .expect("VmRSS line")
    }

    /// Sends SIGTERM and waits for the child to exit.
    pub fn terminate(self) -> ExitStatus {
        self.signal("-TERM")
    }

    /// Sends SIGINT (Ctrl-C) and waits for the child to exit.
    pub fn interrupt(self) -> ExitStatus {
        self.signal("-INT")
    }

    fn signal(mut self, signal: &str) -> ExitStatus {
        let killed = Command::new("kill")
            .args([signal, &self.pid().to_string()])
            .status()
            .expect("kill runs");
        assert!(killed.success());
        self.child.wait().expect("child exits")
    }
}

impl Drop for Watch {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The milliseconds in a `reloaded ... (frame X ms)` line.
pub fn frame_ms(line: &str) -> f64 {
    line.rsplit_once("(frame ")
        .and_then(|(_, rest)| rest.strip_suffix(" ms)"))
        .and_then(|ms| ms.parse().ok())
        .unwrap_or_else(|| panic!("no frame time in {line:?}"))
}
