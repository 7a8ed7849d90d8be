//! `weft compare` as a user runs it: every file it promises written, the
//! reference cached and re-rendered when its entry is damaged, validation
//! clean, and bad references reported; what it measures (`measures`) and
//! `weft sweep` (`sweep`).

mod measures;
mod sweep;
mod sweep_folders;

use crate::harness::{command_in, repo};
use std::path::{Path, PathBuf};
use std::process::Output;

fn temp(name: &str) -> PathBuf {
    crate::harness::scratch(&format!("weft-compare-cli-{name}-{}", std::process::id()))
}

/// Runs weft with its user cache in `cache`.
fn weft(args: &[&str], cache: &Path) -> Output {
    command_in(&repo(), args)
        .env("WEFT_CACHE_DIR", cache)
        .output()
        .expect("weft runs")
}

/// The size, reference samples and frames of a quick measurement.
const SMALL: [&str; 6] = ["--size", "48x32", "--spp", "4", "--frames", "1"];

/// Runs weft with its user cache in `cache`, and asserts it succeeded (its
/// stderr shown if not).
fn weft_ok(args: &[&str], cache: &Path) -> Output {
    let run = weft(args, cache);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    run
}

fn report(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("report.json")).expect("report.json");
    serde_json::from_str(&text).expect("report.json is JSON")
}

fn compare(out: &Path, cache: &Path) -> Output {
    let out_arg = out.to_string_lossy().into_owned();
    weft(
        &[
            "compare",
            "scenes/demo.scene",
            "--graphs",
            "graphs/forward.ron,graphs/deferred.ron",
            "--size",
            "48x32",
            "--spp",
            "4",
            "--frames",
            "2",
            "--validate",
            "--out",
            &out_arg,
        ],
        cache,
    )
}

#[test]
fn a_compare_run_writes_every_file_and_caches_its_reference() {
    let cache = temp("cache");
    let out = temp("out");
    let run = compare(&out, &cache);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.contains("validation: 0 errors, 0 warnings"),
        "{stdout}"
    );
    for file in [
        "report.json",
        "report.md",
        "contact_sheet.png",
        "reference.exr",
        "reference.png",
        "forward.png",
        "forward.exr",
        "forward.flip.png",
        "deferred.png",
        "deferred.exr",
        "deferred.flip.png",
    ] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    let first = report(&out);
    assert_eq!(first["reference"]["cached"], false);
    assert_eq!(first["reference"]["spp"], 4);
    let configurations = first["configurations"].as_array().expect("configurations");
    assert_eq!(configurations.len(), 2);
    for c in configurations {
        for key in [
            "graph",
            "features",
            "params",
            "flip",
            "flip_ldr",
            "rmse",
            "rel_mse",
            "psnr",
            "luminance_ratio",
            "frame_ms",
            "passes",
            "transient_bytes",
            "device_bytes",
            "caveats",
        ] {
            assert!(c.get(key).is_some(), "{key} missing in {c}");
        }
        // The graphs' caveats under the demo's features: bloom (on by
        // default), no bounces, unshadowed area lights (the demo has some).
        let caveats: Vec<&str> = c["caveats"]
            .as_array()
            .expect("caveats")
            .iter()
            .filter_map(|n| n.as_str())
            .collect();
        for start in [
            "bloom spreads",
            "direct light and",
            "area lights and emissive",
        ] {
            assert!(
                caveats.iter().any(|n| n.starts_with(start)),
                "{start}: {caveats:?}"
            );
        }
        let flip = c["flip"].as_f64().expect("flip");
        assert!(flip > 0.0 && flip < 1.0, "{flip}");
        // The table's `fastest ms` is the fastest measured frame.
        let fastest = c["frame_spread"]["min"].as_f64().expect("frame_spread.min");
        let name = c["name"].as_str().expect("name");
        let row = stdout
            .lines()
            .find(|l| l.starts_with(&format!("| {name} |")))
            .expect("the configuration's row");
        assert_eq!(
            row.split('|').nth(9).map(str::trim),
            Some(format!("{fastest:.2}").as_str()),
            "{row}"
        );
        let ratio = c["luminance_ratio"].as_f64().expect("luminance_ratio");
        assert!(ratio.is_finite() && ratio > 0.0, "{ratio}");
        let passes = c["passes"].as_array().expect("passes");
        assert!(passes.iter().any(|p| p["name"] == "tonemap"), "{passes:?}");
        assert!(passes
            .iter()
            .all(|p| p["timer"].as_str().is_some_and(|t| !t.is_empty())));
    }
    assert_eq!(configurations[0]["name"], "forward");
    let markdown = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    assert!(markdown.contains("| forward | "), "{markdown}");
    assert!(
        stdout.contains("Caveats: where a configuration differs from the reference by design")
            && markdown.contains(". bloom spreads bright pixels"),
        "{stdout}"
    );

    // The same inputs again: the reference comes from the cache, bit for bit.
    let again = compare(&out, &cache);
    assert!(again.status.success());
    let second = report(&out);
    assert_eq!(second["reference"]["cached"], true);
    assert_eq!(
        second["configurations"][0]["rmse"],
        first["configurations"][0]["rmse"]
    );
    assert_eq!(
        second["reference"]["image"].as_str(),
        Some(out.join("reference.exr").to_string_lossy().as_ref()),
        "the report links to an EXR in the output folder"
    );
    // A damaged entry is rendered again, with a warning.
    let entries: Vec<PathBuf> = std::fs::read_dir(cache.join("references"))
        .expect("the reference cache")
        .map(|e| e.expect("entry").path())
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    let mut bytes = std::fs::read(&entries[0]).expect("entry");
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    std::fs::write(&entries[0], &bytes).expect("damage the entry");
    let third = compare(&out, &cache);
    assert!(third.status.success());
    assert!(
        String::from_utf8_lossy(&third.stderr)
            .contains("is damaged (its checksum does not match its payload); rendered again"),
        "{}",
        String::from_utf8_lossy(&third.stderr)
    );
    assert_eq!(report(&out)["reference"]["cached"], false);
}

#[test]
fn a_reference_image_of_the_wrong_size_or_kind_is_an_error() {
    let cache = temp("bad-cache");
    let out = temp("bad");
    let wrong = out.join("small.exr");
    render_exr("scenes/demo.scene", "8x8", &wrong, &cache);
    let run = |reference: &Path| {
        weft(
            &[
                "compare",
                "scenes/demo.scene",
                "--graphs",
                "graphs/forward.ron",
                "--size",
                "48x32",
                "--reference-image",
                &reference.to_string_lossy(),
                "--out",
                &out.to_string_lossy(),
            ],
            &cache,
        )
    };
    let result = run(&wrong);
    assert!(!result.status.success());
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("is 8x8, but --size asks for 48x32 (images are not resampled)"),
        "{stderr}"
    );
    let junk = out.join("junk.exr");
    std::fs::write(&junk, b"not an image").expect("write");
    let result = run(&junk);
    assert!(!result.status.success());
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("junk.exr: not a readable RGB(A) EXR"),
        "{stderr}"
    );
    let fifo = out.join("fifo.exr");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo");
    assert!(made.success());
    let result = run(&fifo);
    assert!(!result.status.success(), "a FIFO is refused, not waited on");
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("fifo.exr: it is a FIFO, not a regular file"),
        "{stderr}"
    );
}

#[test]
fn a_reference_image_with_non_finite_or_negative_pixels_is_refused() {
    let cache = temp("nan-cache");
    let out = temp("nan");
    for (name, value) in [
        ("nan", f32::NAN),
        ("inf", f32::INFINITY),
        ("negative", -1e30),
    ] {
        let path = out.join(format!("{name}.exr"));
        let mut pixels = vec![[0.5f32, 0.5, 0.5]; 48 * 32];
        pixels[3 * 48 + 5] = [0.5, value, 0.5];
        pixels[10 * 48 + 7] = [value, 0.5, 0.5];
        let image = weft_compare::LinearImage {
            width: 48,
            height: 32,
            pixels,
        };
        image.write_exr(&path).expect("write");
        let result = weft(
            &[
                "compare",
                "scenes/demo.scene",
                "--graphs",
                "graphs/forward.ron",
                "--size",
                "48x32",
                "--reference-image",
                &path.to_string_lossy(),
                "--out",
                &out.to_string_lossy(),
            ],
            &cache,
        );
        assert_eq!(result.status.code(), Some(1), "{name}");
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(
            stderr.contains(&format!(
                "{name}.exr: 2 pixel(s) are not finite, non-negative radiance; the first is at (5, 3)"
            )),
            "{name}: {stderr}"
        );
    }
}

/// Renders `scene` through forward at `size` (`WxH`) into the EXR `path`
/// with weft itself: a linear image to compare against, or a reference.
fn render_exr(scene: &str, size: &str, path: &Path, cache: &Path) {
    weft_ok(
        &[
            "render",
            scene,
            "--size",
            size,
            "--out",
            &path.to_string_lossy(),
        ],
        cache,
    );
}
