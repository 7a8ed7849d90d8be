//! Bad input as an adversary gives it: devices and FIFOs where files belong,
//! system files as includes, oversized textures, damaged and swapped cache
//! entries, files outside a scene's folder, stray commas. Each is a clean,
//! located error or a warning and a right image: never a hang, a crash or a
//! silently wrong result. Every child runs under a deadline, so a hang fails
//! the test instead of stopping the suite.

use crate::harness::{command_in, finish_within, repo};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

mod bounds;
mod cache;
mod damage;
mod first_use;
mod inputs;

/// `weft ARGS` in `dir`, killed (and the test failed) after `seconds`.
fn weft_within(dir: &Path, args: &[&str], seconds: u64) -> Output {
    finish_within(&mut command_in(dir, args), seconds)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A fresh temporary folder for one test.
fn temp(name: &str) -> PathBuf {
    crate::harness::scratch(&format!("weft-robust-{name}-{}", std::process::id()))
}

fn mkfifo(path: &Path) {
    let made = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo");
    assert!(made.success());
}

#[test]
fn devices_and_fifos_named_as_graphs_are_refused_at_once() {
    let dir = temp("graph-devices");
    let fifo = dir.join("g.ron");
    mkfifo(&fifo);
    let fifo = fifo.to_string_lossy().into_owned();
    for graph in ["/dev/zero", fifo.as_str()] {
        for args in [
            vec!["graph", "check", graph],
            vec!["graph", "check", "--shaders", graph],
            vec!["graph", "dot", graph],
            vec![
                "render",
                "scenes/demo.scene",
                "--graph",
                graph,
                "--size",
                "8x8",
            ],
        ] {
            let out = weft_within(&repo(), &args, 60);
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
            assert!(
                err.contains("is a device, not a regular file")
                    || err.contains("is a FIFO, not a regular file"),
                "{args:?}: {err}"
            );
        }
    }
    // An include of a device, and of a system file whose content must not be
    // echoed (it would print the environment).
    for (include, expected) in [
        ("/dev/zero", "it is a device, not a regular file"),
        (
            "/proc/self/environ",
            "RON syntax error (the file is outside the graph's folder, so its content is not shown)",
        ),
    ] {
        let graph = dir.join("inc.ron");
        std::fs::write(
            &graph,
            format!("Graph(\n    include: [(file: \"{include}\")],\n    output: \"x\",\n)\n"),
        )
        .expect("write");
        let out = command_in(&repo(), &["graph", "check", &graph.to_string_lossy()])
            .env("WEFT_SECRET_FOR_TEST", "do-not-print-me")
            .stdin(Stdio::null())
            .output()
            .expect("weft runs");
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{include}: {err}");
        assert!(err.contains(expected), "{include}: {err}");
        assert!(!err.contains("do-not-print-me"), "{include} echoed: {err}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn devices_and_fifos_named_as_scenes_print_their_error_and_end() {
    let dir = temp("scene-devices");
    let fifo = dir.join("s.scene");
    mkfifo(&fifo);
    for scene in [Path::new("/dev/zero"), fifo.as_path()] {
        let out = weft_within(&repo(), &["scene", "check", &scene.to_string_lossy()], 30);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{scene:?}: {err}");
        assert!(err.contains("not a regular file"), "{scene:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// A quad with a texture `width` x `height`, lit head-on, in `dir`.
fn textured_quad(dir: &Path, width: u32, height: u32) -> PathBuf {
    image::RgbaImage::from_pixel(width, height, image::Rgba([200, 120, 40, 255]))
        .save(dir.join("wide.png"))
        .expect("png");
    std::fs::write(
        dir.join("quad.mtl"),
        "newmtl m\nKd 1 1 1\nmap_Kd wide.png\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\nusemtl m\nf 1/1/1 4/4/1 3/3/1 2/2/1\n",
    )
    .expect("obj");
    let scene = dir.join("quad.scene");
    std::fs::write(
        &scene,
        "model\n{\n\tfile \"quad.obj\"\n}\n\ncamera \"main\"\n{\n\tposition 0 3 0.01\n\ttarget 0 0 0\n}\n\nsunlight\n{\n\tdirection 0 -1 0\n\tcolor 1 1 1\n}\n",
    )
    .expect("scene");
    scene
}

#[test]
fn textures_over_the_device_limit_are_downscaled_with_a_warning() {
    let dir = temp("wide-texture");
    let scene = textured_quad(&dir, 65536, 1);
    let check = weft_within(&repo(), &["scene", "check", &scene.to_string_lossy()], 60);
    let text = String::from_utf8_lossy(&check.stdout);
    assert!(check.status.success(), "{}", stderr(&check));
    assert!(
        text.contains("texture is 65536x1, over 16384 texels per side (maxImageDimension2D): it is downscaled to 16384x1 before upload"),
        "{text}"
    );
    for graph in ["graphs/forward.ron", "graphs/pathtrace.ron"] {
        let png = dir.join("out.png");
        let out = weft_within(
            &repo(),
            &[
                "render",
                &scene.to_string_lossy(),
                "--graph",
                graph,
                "--size",
                "16x16",
                "--validate",
                "--out",
                &png.to_string_lossy(),
            ],
            300,
        );
        let err = stderr(&out);
        assert!(out.status.success(), "{graph}: {err}");
        if graph.ends_with("forward.ron") {
            assert!(
                err.contains("is 65536x1, over the device's maxImageDimension2D of 16384: downscaled to 16384x1"),
                "{graph}: {err}"
            );
        }
        let image = image::open(&png).expect("png").to_rgba8();
        let centre = image.get_pixel(8, 8);
        assert!(
            centre[0] > centre[1] && centre[1] > centre[2],
            "{graph}: textured, not white: {centre:?}"
        );
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// A valid 11600x11600 texture (513 MiB of RGBA8, within the device's
/// 16384 a side): `scene check` accepts it and `render` decodes and draws it
/// (the image decoder's default 512 MiB limit once dropped it there).
#[test]
fn a_large_valid_texture_is_checked_and_drawn_alike() {
    let dir = temp("full-texture");
    let scene = textured_quad(&dir, 11600, 11600);
    let check = weft_within(&repo(), &["scene", "check", &scene.to_string_lossy()], 120);
    let report = String::from_utf8_lossy(&check.stdout).into_owned();
    assert!(check.status.success(), "{}", stderr(&check));
    assert!(
        !report.contains("wide.png"),
        "no warning about the texture: {report}"
    );
    let png = dir.join("out.png");
    let out = weft_within(
        &repo(),
        &[
            "render",
            &scene.to_string_lossy(),
            "--size",
            "16x16",
            "--out",
            &png.to_string_lossy(),
        ],
        300,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("warning"), "{err}");
    let centre = *image::open(&png).expect("png").to_rgba8().get_pixel(8, 8);
    assert!(
        centre[0] > centre[1] && centre[1] > centre[2],
        "textured, not white: {centre:?}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}
