//! Random damage to random cache entries never changes the image.

use super::*;
use weft_scene::rng::Rng;

/// The cache as a property: random damage to random entries (SPIR-V, models,
/// the path tracer's BVH) in rounds; every render exits 0 and writes the
/// image a `--no-cache` render writes, byte for byte.
#[test]
fn random_damage_to_random_cache_entries_never_changes_the_image() {
    let dir = temp("cache-property");
    let cache = dir.join("cache");
    let render = |graph: &str, out: &Path, cached: bool| {
        let mut args = vec![
            "render",
            "scenes/demo.scene",
            "--graph",
            graph,
            "--size",
            "24x16",
            "--out",
        ];
        let out = out.to_string_lossy().into_owned();
        args.push(&out);
        if !cached {
            args.push("--no-cache");
        }
        finish_within(
            command_in(&repo(), &args).env("WEFT_CACHE_DIR", &cache),
            300,
        )
    };
    let graphs = ["graphs/forward.ron", "graphs/pathtrace.ron"];
    let mut clean = Vec::new();
    for graph in graphs {
        let png = dir.join("clean.png");
        let out = render(graph, &png, false);
        assert!(out.status.success(), "{}", stderr(&out));
        clean.push(std::fs::read(&png).expect("png"));
        assert!(render(graph, &dir.join("warm.png"), true).status.success());
    }
    let entries = || -> Vec<PathBuf> {
        let mut found = Vec::new();
        for sub in ["spirv", "models", ""] {
            if let Ok(read) = std::fs::read_dir(cache.join(sub)) {
                found.extend(
                    read.map(|e| e.expect("entry").path())
                        .filter(|p| p.is_file() || p.is_symlink()),
                );
            }
        }
        found.sort();
        found
    };
    let mut rng = Rng::new(0x000C_AC4E);
    for round in 0..6 {
        let all = entries();
        assert!(all.len() > 3, "{all:?}");
        let mut damaged = Vec::new();
        for _ in 0..1 + rng.below(3) {
            let entry = &all[rng.below(all.len())];
            let bytes = std::fs::read(entry).unwrap_or_default();
            let kind = rng.below(6);
            let _ = std::fs::remove_file(entry);
            match kind {
                0 => std::fs::write(entry, &bytes[..rng.below(bytes.len().max(1))])
                    .expect("truncate"),
                1 => {
                    let mut flipped = bytes.clone();
                    for _ in 0..1 + rng.below(8) {
                        let at = rng.below(flipped.len().max(1));
                        if let Some(b) = flipped.get_mut(at) {
                            *b ^= 1 << rng.below(8);
                        }
                    }
                    std::fs::write(entry, flipped).expect("flip");
                }
                2 => {
                    let noise: Vec<u8> =
                        (0..rng.below(256)).map(|_| rng.next_u64() as u8).collect();
                    std::fs::write(entry, noise).expect("replace");
                }
                3 => {
                    let other = std::fs::read(&all[rng.below(all.len())]).unwrap_or_default();
                    std::fs::write(entry, other).expect("swap");
                }
                4 => std::os::unix::fs::symlink("/dev/zero", entry).expect("link"),
                _ => std::fs::create_dir(entry).expect("folder"),
            }
            damaged.push(format!("{} ({kind})", entry.display()));
        }
        for (graph, clean) in graphs.iter().zip(&clean) {
            let png = dir.join(format!("round{round}.png"));
            let out = render(graph, &png, true);
            let err = stderr(&out);
            assert!(
                out.status.success(),
                "round {round} {graph} after {damaged:?}: {err}"
            );
            assert_eq!(
                &std::fs::read(&png).expect("png"),
                clean,
                "round {round} {graph} after {damaged:?}: {err}"
            );
        }
        // A folder left in an entry's place cannot be replaced by a rename (the
        // render warns and goes on uncached); clear it so later rounds cache again.
        for sub in ["spirv", "models", ""] {
            for entry in std::fs::read_dir(cache.join(sub)).expect("cache folder") {
                let path = entry.expect("entry").path();
                let is_entry = path.extension().is_some_and(|e| {
                    ["spv", "weftcache", "weftbvh"].contains(&e.to_str().unwrap_or(""))
                });
                if is_entry && path.is_dir() && !path.is_symlink() {
                    std::fs::remove_dir_all(&path).expect("rm folder");
                }
            }
        }
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}
