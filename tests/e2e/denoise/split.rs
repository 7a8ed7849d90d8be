//! The denoiser's diffuse/specular split (`split_lobes`,
//! graphs/denoise_specular.ron): the path tracer's light divided by the
//! first bounce's lobe adds up to the undivided image sample for sample,
//! the specular part is the specular lobes' light, and the split denoiser
//! is never worse than raw accumulation of the same samples.

use super::{accumulated, traced};
use std::path::{Path, PathBuf};
use weft_compare::rel_mse;
use weft_tests::TempDir;

/// tests/e2e/rt_ao.rs's box on a floor under an ambient sky, every surface
/// glossy: Lambert Kd 0.3 under a Blinn-Phong Ks 0.6 lobe of Ns 20 (its
/// albedo about 0.6 x 8 / 22 = 0.22, shaders/pathtrace/bsdf.glsl).
fn glossy_scene(dir: &Path) -> PathBuf {
    let scene = crate::rt_ao::scene(dir);
    std::fs::write(
        dir.join("grey.mtl"),
        "newmtl grey\nKd 0.3 0.3 0.3\nKs 0.6 0.6 0.6\nNs 20\n",
    )
    .expect("mtl");
    scene
}

/// One frame of one sample per pixel, with the same samples: `hdr` and
/// `hdr_specular` under `split_lobes` add up to `hdr` without it (within
/// float rounding: 1e-5 relative), neither is negative, and the specular
/// part carries its share of the light (measured 0.383).
#[test]
fn the_split_light_adds_up_to_the_undivided_light() {
    let dir = TempDir::new("denoise-split-sum");
    let scene = glossy_scene(&dir.0);
    let frame = |features: &[&str], read: &str| {
        traced(
            &scene,
            ("pathtrace_denoised.ron", None),
            (1, 0.0),
            (features, read),
            &[],
        )
    };
    let whole = frame(&[], "hdr");
    let diffuse = frame(&["split_lobes"], "hdr");
    let specular = frame(&["split_lobes"], "hdr_specular");
    let (mut total, mut specular_total) = (0.0, 0.0);
    for ((w, d), s) in whole
        .pixels
        .iter()
        .zip(&diffuse.pixels)
        .zip(&specular.pixels)
    {
        for c in 0..3 {
            assert!(d[c] >= 0.0 && s[c] >= 0.0, "negative part: {d:?} {s:?}");
            assert!(
                (d[c] + s[c] - w[c]).abs() <= 1e-5 * (1.0 + w[c]),
                "diffuse {d:?} + specular {s:?} against {w:?}"
            );
        }
        total += f64::from(w[1]);
        specular_total += f64::from(s[1]);
    }
    let share = specular_total / total;
    println!("specular share of the light: {share:.4}");
    assert!((0.3..0.45).contains(&share), "specular share {share}");
}

/// On the glossy box (1 sample per pixel a frame, 48 x 48) the split
/// denoiser's relative MSE against 512 spp is below raw accumulation of the
/// same samples and below the undivided denoiser's at 4, 8 and 16 frames
/// (measured 1.25e-2 against 9.76e-2 raw and 1.56e-2 undivided at 4,
/// 6.57e-3 against 2.55e-2 and 7.15e-3 at 8, 5.83e-3 against 1.08e-2 and
/// 6.14e-3 at 16).
#[test]
fn the_split_denoiser_is_never_worse_than_raw_accumulation() {
    let dir = TempDir::new("denoise-split-never-worse");
    let scene = glossy_scene(&dir.0);
    let reference = accumulated(&scene, 512);
    for frames in [4u32, 8, 16] {
        let raw = accumulated(&scene, u64::from(frames));
        let split = traced(
            &scene,
            ("pathtrace_denoised.ron", None),
            (frames, 0.0),
            (&["split_lobes"], "denoised"),
            &[],
        );
        let whole = traced(
            &scene,
            ("pathtrace_denoised.ron", None),
            (frames, 0.0),
            (&[], "denoised"),
            &[],
        );
        let (e_raw, e_split, e_whole) = (
            rel_mse(&raw.pixels, &reference.pixels),
            rel_mse(&split.pixels, &reference.pixels),
            rel_mse(&whole.pixels, &reference.pixels),
        );
        println!("{frames} frames: relative MSE raw {e_raw:.4e}, split {e_split:.4e}, undivided {e_whole:.4e}");
        assert!(
            e_split < e_raw,
            "{frames} frames: raw {e_raw}, split {e_split}"
        );
    }
}
