//! Damaged or swapped cache entries: the uncached image, with a warning.

use super::*;

/// Renders `scene` with forward at 24x16 using `cache` as the user cache.
fn render_with_cache(scene: &str, cache: &Path, png: &Path) -> Output {
    finish_within(
        command_in(
            &repo(),
            &[
                "render",
                scene,
                "--size",
                "24x16",
                "--out",
                &png.to_string_lossy(),
            ],
        )
        .env("WEFT_CACHE_DIR", cache),
        300,
    )
}

#[test]
fn damaged_or_swapped_cache_entries_give_the_uncached_image_with_a_warning() {
    let dir = temp("cache-damage");
    let cache = dir.join("cache");
    let clean = dir.join("clean.png");
    let out = command_in(
        &repo(),
        &[
            "render",
            "scenes/demo.scene",
            "--size",
            "24x16",
            "--no-cache",
            "--out",
            &clean.to_string_lossy(),
        ],
    )
    .output()
    .expect("weft runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let reference = std::fs::read(&clean).expect("png");
    let png = dir.join("cached.png");
    assert!(render_with_cache("scenes/demo.scene", &cache, &png)
        .status
        .success());
    let entries = |sub: &str| -> Vec<PathBuf> {
        let mut found: Vec<PathBuf> = std::fs::read_dir(cache.join(sub))
            .map(|d| d.map(|e| e.expect("entry").path()).collect())
            .unwrap_or_default();
        found.sort();
        found
    };
    let spirv = entries("spirv");
    let models = entries("models");
    assert!(
        !spirv.is_empty() && !models.is_empty(),
        "{spirv:?} {models:?}"
    );
    // Four bytes flipped in every SPIR-V entry, every model entry truncated.
    for entry in &spirv {
        let mut bytes = std::fs::read(entry).expect("entry");
        let at = bytes.len() / 2;
        bytes[at..at + 4].iter_mut().for_each(|b| *b ^= 0x5A);
        std::fs::write(entry, bytes).expect("damage");
    }
    for entry in &models {
        let bytes = std::fs::read(entry).expect("entry");
        std::fs::write(entry, &bytes[..bytes.len() / 2]).expect("truncate");
    }
    let out = render_with_cache("scenes/demo.scene", &cache, &png);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("is damaged (its checksum does not match its payload); compiled again"),
        "{err}"
    );
    assert!(err.contains("is damaged (it is truncated"), "{err}");
    assert_eq!(
        std::fs::read(&png).expect("png"),
        reference,
        "the same image as without a cache"
    );
    // Rewritten: the next run is clean.
    let out = render_with_cache("scenes/demo.scene", &cache, &png);
    assert!(!stderr(&out).contains("damaged"), "{}", stderr(&out));
    // Every SPIR-V entry replaced by a link to a device: no hang, same image.
    for entry in entries("spirv") {
        std::fs::remove_file(&entry).expect("rm");
        std::os::unix::fs::symlink("/dev/zero", &entry).expect("link");
    }
    let out = render_with_cache("scenes/demo.scene", &cache, &png);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("is damaged (it is a device); compiled again"),
        "{err}"
    );
    assert_eq!(std::fs::read(&png).expect("png"), reference);
    // Two model entries swapped: each model still renders as itself.
    let swap_scene = dir.join("two.scene");
    let models_dir = repo().join("scenes/models");
    std::fs::write(
        &swap_scene,
        format!(
            "model\n{{\n\tfile \"{}\"\n}}\n\nmodel\n{{\n\tfile \"{}\"\n\tposition 0 1 0\n}}\n\ncamera \"c\"\n{{\n\tposition 0 2 6\n\ttarget 0 0.5 0\n}}\n\nsunlight\n{{\n\tdirection -0.3 -1 -0.4\n\tcolor 1 1 1\n}}\n",
            models_dir.join("floor.obj").display(),
            models_dir.join("glass_sphere.obj").display()
        ),
    )
    .expect("scene");
    let swap = swap_scene.to_string_lossy().into_owned();
    let first = dir.join("first.png");
    assert!(render_with_cache(&swap, &cache, &first).status.success());
    let named = |stem: &str| {
        entries("models")
            .into_iter()
            .find(|e| {
                e.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with(stem))
            })
            .expect("entry")
    };
    let (floor, sphere) = (named("floor.obj-"), named("glass_sphere.obj-"));
    let (floor_bytes, sphere_bytes) = (
        std::fs::read(&floor).expect("e"),
        std::fs::read(&sphere).expect("e"),
    );
    std::fs::write(&floor, &sphere_bytes).expect("swap");
    std::fs::write(&sphere, &floor_bytes).expect("swap");
    let swapped = dir.join("swapped.png");
    let out = render_with_cache(&swap, &cache, &swapped);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("(it was stored for another input); imported again"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(&swapped).expect("png"),
        std::fs::read(&first).expect("png")
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// A damaged BVH entry is built again with the warning docs/performance.md
/// promises (it was built again silently: the warnings were taken before
/// the path tracer built its data), and the image is the uncached one.
#[test]
fn a_damaged_bvh_entry_is_built_again_with_a_warning() {
    let dir = temp("bvh-damage");
    let cache = dir.join("cache");
    let render = |out: &Path| {
        command_in(
            &repo(),
            &[
                "render",
                "scenes/cornell.scene",
                "--graph",
                "graphs/pathtrace.ron",
                "--size",
                "16x16",
                "--spp",
                "2",
                "--out",
                &out.to_string_lossy(),
            ],
        )
        .env("WEFT_CACHE_DIR", &cache)
        .output()
        .expect("weft runs")
    };
    let first = dir.join("first.png");
    assert!(render(&first).status.success());
    let bvh: Vec<PathBuf> = std::fs::read_dir(&cache)
        .expect("cache")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "weftbvh"))
        .collect();
    assert_eq!(bvh.len(), 1, "{bvh:?}");
    let mut bytes = std::fs::read(&bvh[0]).expect("entry");
    let at = bytes.len() / 2;
    bytes[at..at + 4].iter_mut().for_each(|b| *b ^= 0x5A);
    std::fs::write(&bvh[0], bytes).expect("damage");
    let again = dir.join("again.png");
    let out = render(&again);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains(&format!(
            "warning: the BVH cache entry {} is damaged (its checksum does not match its payload); built again",
            bvh[0].display()
        )),
        "{err}"
    );
    assert_eq!(
        std::fs::read(&again).expect("png"),
        std::fs::read(&first).expect("png")
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}
