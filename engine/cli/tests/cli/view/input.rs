//! The viewer as a first user meets it (issue 60): a click on the panel
//! lands however slow the frames, a script that did not run is an error, a
//! screenshot that cannot be saved never closes the window, and the live
//! error holds an animated scene still while it accumulates.

use super::{assert_clean, repo, text, Temp, Xvfb};
use crate::harness::finish_within;
use std::process::Output;

/// `weft ARGS` on `x`'s display, failed if it runs past `seconds`: a viewer
/// that never ends fails the test instead of stopping the suite.
fn view_within(x: &Xvfb, args: &[&str], seconds: u64) -> Output {
    finish_within(&mut x.command(args, &repo()), seconds)
}

/// Frames of 900 ms, more than egui's 0.8 s for a press to count as a
/// click: the click still sets the parameter.
#[test]
fn a_click_on_the_panel_lands_when_frames_are_slow() {
    let x = Xvfb::start();
    let out = view_within(
        &x,
        &[
            "view",
            "scenes/cornell.scene",
            "--size",
            "320x180",
            "--panel",
            "--frames",
            "6",
            "--frame-delay-ms",
            "900",
            "--validate",
            "--ui",
            "1:click:param:exposure,2:text:2,3:enter",
        ],
        120,
    );
    assert_clean(&out);
    let stdout = text(&out.stdout);
    assert!(stdout.contains("parameter exposure = 2\n"), "{stdout}");
}

/// A `--ui` step for a frame past `--frames`, or a click still waiting for
/// its widget when the frames run out, fails the command, naming it.
#[test]
fn ui_steps_left_when_the_frames_end_are_an_error() {
    let x = Xvfb::start();
    let out = view_within(
        &x,
        &[
            "view",
            "scenes/cornell.scene",
            "--size",
            "320x180",
            "--panel",
            "--frames",
            "3",
            "--ui",
            "1:click:pause,7:click:live_error",
        ],
        120,
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stdout));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("--ui: 1 step(s) never ran in the 3 frames shown: 7:click:live_error; give more --frames"),
        "{stderr}"
    );
}

/// F12 with a screenshot folder that cannot be written reports it and the
/// viewer goes on to its last frame, exit 0.
#[test]
fn a_screenshot_that_cannot_be_saved_leaves_the_viewer_running() {
    let x = Xvfb::start();
    let tmp = Temp::new("f12-blocked");
    // A file where the screenshot folder should be.
    let blocked = tmp.file("not-a-folder");
    std::fs::write(&blocked, "x").expect("write");
    let out = view_within(
        &x,
        &[
            "view",
            "scenes/cornell.scene",
            "--size",
            "64x36",
            "--frames",
            "5",
            "--screenshot-dir",
            blocked.to_str().expect("utf-8 path"),
            "--press",
            "1:f12",
            "--validate",
        ],
        120,
    );
    assert_clean(&out);
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("error: screenshot not saved:") && stderr.contains("(the viewer goes on)"),
        "{stderr}"
    );
    assert!(
        text(&out.stdout).contains("presented 5 frames"),
        "{}",
        text(&out.stdout)
    );
}

/// The demo animates (swivelling spots); with the live error on, scene
/// time is held, so the reference accumulates past one sample and the
/// viewer says why.
#[test]
fn the_live_error_holds_an_animated_scene_still_while_it_measures() {
    let x = Xvfb::start();
    let out = view_within(
        &x,
        &[
            "view",
            "scenes/demo.scene",
            "--size",
            "48x27",
            "--frames",
            "10",
            "--press",
            "0:l",
            "--reference-spp",
            "4",
            "--validate",
        ],
        120,
    );
    assert_clean(&out);
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("scene time held at 0.000 s while it measures (L again lets it run)"),
        "{stdout}"
    );
    let spp: u64 = stdout
        .lines()
        .find_map(|l| l.strip_prefix("live error: HDR-FLIP "))
        .and_then(|rest| rest.split(" at ").nth(1))
        .and_then(|s| s.trim_end_matches(" spp").parse().ok())
        .unwrap_or_else(|| panic!("no live error line: {stdout}"));
    assert_eq!(spp, 4, "the reference accumulated {spp} spp: {stdout}");
}

/// Text a 32-bit float cannot hold, typed into a parameter's field, leaves
/// the parameter as it was (it once set 1.797e308); a number it can hold is
/// taken.
#[test]
fn a_parameter_field_takes_only_finite_32_bit_numbers() {
    let x = Xvfb::start();
    for (typed, taken) in [
        ("nan", false),
        ("1e39", false),
        ("inf", false),
        ("2.5", true),
    ] {
        let steps = format!("1:click:param:exposure,2:text:{typed},3:enter");
        let out = view_within(
            &x,
            &[
                "view",
                "scenes/cornell.scene",
                "--size",
                "320x180",
                "--panel",
                "--frames",
                "6",
                "--validate",
                "--ui",
                &steps,
            ],
            120,
        );
        assert_clean(&out);
        let stdout = text(&out.stdout);
        assert_eq!(
            stdout.contains("parameter exposure = "),
            taken,
            "{typed}: {stdout}"
        );
        if taken {
            assert!(stdout.contains("parameter exposure = 2.5\n"), "{stdout}");
        }
    }
}
