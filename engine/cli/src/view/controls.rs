//! What the viewer's keys switch between, apart from the window: the graphs
//! beside the one being viewed, the features a graph can toggle, and the title
//! line that reports them with frame and pass times or the last reload error.

use std::path::{Path, PathBuf};
use weft_gpu::PassTiming;
use winit::keyboard::KeyCode;

/// The number keys that toggle features, in order: alone for the first nine,
/// with Shift for the next nine.
pub const FEATURE_KEYS: [KeyCode; 9] = [
    KeyCode::Digit1,
    KeyCode::Digit2,
    KeyCode::Digit3,
    KeyCode::Digit4,
    KeyCode::Digit5,
    KeyCode::Digit6,
    KeyCode::Digit7,
    KeyCode::Digit8,
    KeyCode::Digit9,
];

/// What a key press asks for (movement and look keys are read while held instead).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Esc: end after this frame.
    Quit,
    /// F12: save what the window shows.
    Screenshot,
    /// Space: stop or resume scene time.
    Pause,
    /// R: back to the scene camera.
    ResetCamera,
    /// G (+1) or Shift+G (-1): another graph from the graph's folder.
    Graph(isize),
    /// 1-9, then Shift+1-9: toggle the graph's feature with this index.
    Feature(usize),
    /// C: print the flown camera as a `.scene` `camera` block.
    PrintCamera,
    /// F1: show or hide the panel.
    Panel,
    /// L: start or stop the live error against the reference.
    LiveError,
    /// B: save the camera as the next bookmark (in the bookmarks file).
    SaveBookmark,
}

/// The action of a key pressed with or without Shift.
pub fn action(code: KeyCode, shift: bool) -> Option<Action> {
    match code {
        KeyCode::Escape => Some(Action::Quit),
        KeyCode::F12 => Some(Action::Screenshot),
        KeyCode::Space => Some(Action::Pause),
        KeyCode::KeyR => Some(Action::ResetCamera),
        KeyCode::KeyC => Some(Action::PrintCamera),
        KeyCode::F1 => Some(Action::Panel),
        KeyCode::KeyL => Some(Action::LiveError),
        KeyCode::KeyB => Some(Action::SaveBookmark),
        KeyCode::KeyG => Some(Action::Graph(if shift { -1 } else { 1 })),
        _ => FEATURE_KEYS
            .iter()
            .position(|&k| k == code)
            .map(|i| Action::Feature(if shift { FEATURE_KEYS.len() + i } else { i })),
    }
}

/// The key that toggles the feature at `index`: `1`-`9`, then `Shift+1`-`Shift+9`;
/// `None` past those.
pub fn feature_key(index: usize) -> Option<String> {
    let keys = FEATURE_KEYS.len();
    match index {
        i if i < keys => Some(format!("{}", i + 1)),
        i if i < 2 * keys => Some(format!("Shift+{}", i - keys + 1)),
        _ => None,
    }
}

/// Parses one `--press` entry, `FRAME:KEY`: the key is pressed before frame
/// FRAME (counted from 0) renders. KEY is `g`, `G` (Shift+G), `1`-`9`,
/// `shift+1`-`shift+9`, `f1`, `f12`, `space`, `r`, `c`, `l`, `b` or `esc`.
pub fn parse_press(text: &str) -> Result<(u32, Action), String> {
    let (frame, key) = split_frame(text, "KEY")?;
    let (code, shift) = match key.trim() {
        "g" => (KeyCode::KeyG, false),
        "G" => (KeyCode::KeyG, true),
        "f12" | "F12" => (KeyCode::F12, false),
        "f1" | "F1" => (KeyCode::F1, false),
        "l" => (KeyCode::KeyL, false),
        "b" => (KeyCode::KeyB, false),
        "space" => (KeyCode::Space, false),
        "r" => (KeyCode::KeyR, false),
        "c" => (KeyCode::KeyC, false),
        "esc" => (KeyCode::Escape, false),
        other => {
            let (digit, shift) = match other.strip_prefix("shift+") {
                Some(digit) => (digit, true),
                None => (other, false),
            };
            match digit.parse::<usize>() {
                Ok(n @ 1..=9) => (FEATURE_KEYS[n - 1], shift),
                _ => {
                    return Err(format!(
                    "unknown key \"{other}\" (use g, G, 1-9, shift+1-9, f1, f12, space, r, c, l, b or esc)"
                ))
                }
            }
        }
    };
    let action = action(code, shift).ok_or_else(|| format!("no action for \"{key}\""))?;
    Ok((frame, action))
}

/// A scripted entry `FRAME:REST` (`--press`, `--ui`): the frame number and
/// the rest; `what` names the rest in the error.
pub fn split_frame<'t>(text: &'t str, what: &str) -> Result<(u32, &'t str), String> {
    let (frame, rest) = text
        .split_once(':')
        .ok_or_else(|| format!("expected FRAME:{what}, found \"{text}\""))?;
    let frame = frame
        .trim()
        .parse::<u32>()
        .map_err(|_| format!("\"{frame}\" is not a frame number"))?;
    Ok((frame, rest))
}

/// The features a user of `graph` can switch (names in its conditions and
/// its defaults): the graph's own first (bloom, debug views, a depth
/// prepass), then those a scene switches on by what it has (`shadow_casters`,
/// `textures`, ...), each group sorted; number keys 1 to 9 toggle them in this
/// order, so they reach the graph's own choices before the scene's.
pub fn graph_features(graph: &weft_graph::Prepared) -> Vec<String> {
    let mut names = weft_graph::feature_names(graph.ir());
    names.extend(graph.graph().default_features.iter().cloned());
    // The renderer's own, on exactly when passes trace in hardware.
    names.remove(weft_render::RAY_QUERY_FEATURE);
    let (scene, own): (Vec<String>, Vec<String>) = names
        .into_iter()
        .partition(|n| weft_render::scene_feature_reason(n).is_some());
    own.into_iter().chain(scene).collect()
}

/// The requested toggles with `name` flipped: any earlier toggle of it is
/// dropped and `!name` or `name` added, so it holds over scene and graph defaults.
pub fn toggle(requested: &[String], name: &str, on_now: bool) -> Vec<String> {
    let mut next: Vec<String> = requested
        .iter()
        .filter(|f| f.trim_start_matches('!') != name)
        .cloned()
        .collect();
    next.push(if on_now {
        format!("!{name}")
    } else {
        name.to_string()
    });
    next
}

/// The graphs to cycle through: the `.ron` files in `graph`'s folder that
/// compile on their own (not fragments), sorted, always including `graph`.
pub fn sibling_graphs(graph: &Path) -> Vec<PathBuf> {
    let dir = graph
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut graphs: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .filter(|p| weft_graph::Prepared::new(weft_graph::load(p)).is_ok())
        .collect();
    if !graphs.iter().any(|g| same_file(g, graph)) {
        graphs.push(graph.to_path_buf());
    }
    graphs.sort();
    graphs
}

/// Whether two paths name one file.
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// The graph `step` places after `current` in `graphs`, wrapping around.
pub fn cycle(graphs: &[PathBuf], current: &Path, step: isize) -> Option<PathBuf> {
    let n = graphs.len() as isize;
    if n == 0 {
        return None;
    }
    let at = graphs
        .iter()
        .position(|g| same_file(g, current))
        .unwrap_or(0) as isize;
    graphs.get((at + step).rem_euclid(n) as usize).cloned()
}

/// What the title shows.
pub struct Status<'a> {
    /// The graph file.
    pub graph: &'a Path,
    /// Features on in the live plan.
    pub features: &'a [String],
    /// Mean wall milliseconds per frame (render and present).
    pub frame_ms: f64,
    /// The last frame's per-pass times.
    pub timings: &'a [PassTiming],
    /// The last refused reload, shown until one succeeds.
    pub error: Option<&'a str>,
    /// Samples per pixel accumulated, for a progressive graph.
    pub samples: Option<u64>,
    /// Whether the progressive image has started over frame after frame
    /// with the camera still: the scene animates ([`RestartWatch`]).
    pub animating: bool,
}

/// What the title says while [`RestartWatch::animating`].
pub const ANIMATING: &str = "restarts every frame: the scene animates; Space pauses time";

/// Frames in a row a progressive image must start over, the camera still and
/// scene time running, before the viewer says the scene's animation is why.
const RESTARTS_TO_SAY: u32 = 3;

/// Watches a progressive graph's image start over: when it does frame after
/// frame although the camera stands still and scene time runs, the scene
/// animates and the image cannot converge until time is paused (Space).
#[derive(Debug, Default)]
pub struct RestartWatch {
    in_a_row: u32,
}

impl RestartWatch {
    /// Notes one frame: whether its image started over, whether the camera
    /// moved for it, whether scene time ran.
    pub fn observe(&mut self, restarted: bool, camera_moved: bool, time_runs: bool) {
        self.in_a_row = if restarted && !camera_moved && time_runs {
            self.in_a_row.saturating_add(1)
        } else {
            0
        };
    }

    /// Whether the frames seen say the scene's animation restarts the image.
    pub fn animating(&self) -> bool {
        self.in_a_row >= RESTARTS_TO_SAY
    }

    /// Whether the last frame is the one that made it so (say it once).
    pub fn just_began(&self) -> bool {
        self.in_a_row == RESTARTS_TO_SAY
    }
}

/// The window title: graph, features, frame time and per-pass times, or the
/// reload error in front of them.
pub fn title(status: &Status) -> String {
    let graph = status
        .graph
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let fps = if status.frame_ms > 0.0 {
        1000.0 / status.frame_ms
    } else {
        0.0
    };
    let mut line = format!(
        "weft view: {graph} [{}] {:.1} ms ({fps:.0} fps)",
        status.features.join(" "),
        status.frame_ms
    );
    if let Some(samples) = status.samples {
        line.push_str(&format!(" {samples} spp"));
        if status.animating {
            line.push_str(&format!(" ({ANIMATING})"));
        }
    }
    if !status.timings.is_empty() {
        let passes: Vec<String> = status
            .timings
            .iter()
            .map(|t| format!("{} {:.2}", t.pass, t.ms))
            .collect();
        line.push_str(&format!(" | {}", passes.join(", ")));
    }
    match status.error {
        Some(error) => format!("ERROR {error} (kept last good) | {line}"),
        None => line,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_gpu::TimingSource;
    use weft_graph::schema::PassKind;

    fn graphs_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../graphs")
    }

    #[test]
    fn keys_map_to_actions_and_press_scripts_parse() {
        assert_eq!(action(KeyCode::KeyG, false), Some(Action::Graph(1)));
        assert_eq!(action(KeyCode::KeyG, true), Some(Action::Graph(-1)));
        assert_eq!(action(KeyCode::Digit1, false), Some(Action::Feature(0)));
        assert_eq!(action(KeyCode::Digit9, true), Some(Action::Feature(17)));
        assert_eq!(action(KeyCode::F12, false), Some(Action::Screenshot));
        assert_eq!(action(KeyCode::KeyW, false), None);
        assert_eq!(parse_press("3:G"), Ok((3, Action::Graph(-1))));
        assert_eq!(parse_press("0:2"), Ok((0, Action::Feature(1))));
        assert_eq!(parse_press("4:shift+1"), Ok((4, Action::Feature(9))));
        assert_eq!(parse_press("4:shift+9"), Ok((4, Action::Feature(17))));
        assert_eq!(parse_press("5:c"), Ok((5, Action::PrintCamera)));
        assert!(parse_press("1:shift+0").is_err());
        assert_eq!(action(KeyCode::Digit3, true), Some(Action::Feature(11)));
        assert_eq!(feature_key(0).as_deref(), Some("1"));
        assert_eq!(feature_key(8).as_deref(), Some("9"));
        assert_eq!(feature_key(9).as_deref(), Some("Shift+1"));
        assert_eq!(feature_key(17).as_deref(), Some("Shift+9"));
        assert_eq!(feature_key(18), None);
        assert_eq!(parse_press(" 7 : f12 "), Ok((7, Action::Screenshot)));
        assert_eq!(parse_press("1:esc"), Ok((1, Action::Quit)));
        assert_eq!(parse_press("2:f1"), Ok((2, Action::Panel)));
        assert_eq!(parse_press("2:l"), Ok((2, Action::LiveError)));
        assert_eq!(parse_press("2:b"), Ok((2, Action::SaveBookmark)));
        assert!(parse_press("1:0").is_err());
        assert!(parse_press("x:g").is_err());
        assert!(parse_press("g").is_err());
    }

    #[test]
    fn toggling_replaces_earlier_toggles_of_the_same_feature() {
        let requested = vec!["bloom".to_string(), "!shadow_casters".to_string()];
        assert_eq!(
            toggle(&requested, "shadow_casters", false),
            vec!["bloom".to_string(), "shadow_casters".to_string()]
        );
        assert_eq!(
            toggle(&requested, "bloom", true),
            vec!["!shadow_casters".to_string(), "!bloom".to_string()]
        );
        assert_eq!(toggle(&[], "x", false), vec!["x".to_string()]);
    }

    #[test]
    fn features_of_the_shipped_forward_graph() {
        let loaded = weft_graph::load(&graphs_dir().join("forward.ron"));
        let names = graph_features(&weft_graph::Prepared::new(loaded).expect("loads"));
        for expected in ["bloom", "depth_prepass", "shadow_casters"] {
            assert!(
                names.iter().any(|n| n == expected),
                "{expected} in {names:?}"
            );
        }
        assert!(
            !names.iter().any(|n| n.starts_with("bench")),
            "no bench feature is offered: {names:?}"
        );
        // The graph's own features first, then the scene's, each sorted.
        let own = names
            .iter()
            .take_while(|n| weft_render::scene_feature_reason(n).is_none())
            .count();
        assert!(own >= 2, "bloom and depth_prepass come first: {names:?}");
        assert!(names[own..]
            .iter()
            .all(|n| weft_render::scene_feature_reason(n).is_some()));
        assert!(
            names[..own].is_sorted() && names[own..].is_sorted(),
            "{names:?}"
        );
        assert!(names[..own].iter().any(|n| n == "bloom"), "{names:?}");
        assert!(
            names[own..].iter().any(|n| n == "shadow_casters"),
            "{names:?}"
        );
    }

    #[test]
    fn graphs_cycle_in_name_order_and_wrap() {
        let forward = graphs_dir().join("forward.ron");
        let graphs = sibling_graphs(&forward);
        let names: Vec<String> = graphs
            .iter()
            .map(|g| g.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        for expected in ["deferred.ron", "forward.ron"] {
            assert!(
                names.iter().any(|n| n == expected),
                "{expected} in {names:?}"
            );
        }
        let next = cycle(&graphs, &forward, 1).unwrap();
        let at = graphs.iter().position(|g| *g == forward).unwrap();
        assert_eq!(next, graphs[(at + 1) % graphs.len()]);
        assert_eq!(cycle(&graphs, &next, -1).unwrap(), forward);
        assert_eq!(
            cycle(&graphs, &forward, graphs.len() as isize).unwrap(),
            forward
        );
        assert_eq!(cycle(&[], &forward, 1), None);
    }

    #[test]
    fn title_shows_graph_features_times_and_errors() {
        let timings = [PassTiming {
            pass: "forward".into(),
            kind: PassKind::Raster,
            source: TimingSource::GpuTimestamp,
            ms: 1.234,
        }];
        let features = ["bloom".to_string(), "shadow_casters".to_string()];
        let mut status = Status {
            graph: Path::new("graphs/forward.ron"),
            features: &features,
            frame_ms: 20.0,
            timings: &timings,
            error: None,
            samples: None,
            animating: false,
        };
        assert_eq!(
            title(&status),
            "weft view: forward.ron [bloom shadow_casters] 20.0 ms (50 fps) | forward 1.23"
        );
        status.samples = Some(48);
        assert_eq!(
            title(&status),
            "weft view: forward.ron [bloom shadow_casters] 20.0 ms (50 fps) 48 spp | forward 1.23"
        );
        status.animating = true;
        assert_eq!(
            title(&status),
            "weft view: forward.ron [bloom shadow_casters] 20.0 ms (50 fps) 48 spp \
             (restarts every frame: the scene animates; Space pauses time) | forward 1.23"
        );
        status.samples = None;
        status.error = Some("graphs/forward.ron:3: unknown pass kind");
        assert!(title(&status)
            .starts_with("ERROR graphs/forward.ron:3: unknown pass kind (kept last good) | weft view: forward.ron"));
    }

    #[test]
    fn restarts_with_the_camera_still_and_time_running_mean_the_scene_animates() {
        let mut watch = RestartWatch::default();
        for _ in 0..2 {
            watch.observe(true, false, true);
        }
        assert!(
            !watch.animating(),
            "two restarts could be an edit or a reload"
        );
        watch.observe(true, false, true);
        assert!(watch.animating() && watch.just_began());
        watch.observe(true, false, true);
        assert!(watch.animating() && !watch.just_began());
        // Flying restarts the image for a reason the user knows.
        watch.observe(true, true, true);
        assert!(!watch.animating());
        // Paused, a restart has another cause (an edit); converging ends it.
        for _ in 0..5 {
            watch.observe(true, false, false);
        }
        assert!(!watch.animating());
        for _ in 0..3 {
            watch.observe(true, false, true);
        }
        watch.observe(false, false, true);
        assert!(!watch.animating());
    }
}
