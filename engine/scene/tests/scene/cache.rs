//! The model cache gives back exactly what a fresh import gives, for OBJ and glTF scenes.

use crate::common;

use common::{asset, repo_scene, temp_dir};
use weft_scene::cache::cache_file_for;
use weft_scene::{load_scene, load_scene_with, LoadOptions};

#[test]
fn cached_loads_equal_fresh_loads() {
    let cache = temp_dir("cache-equal");
    let options = LoadOptions {
        cache_dir: Some(cache.to_path_buf()),
        ..LoadOptions::default()
    };
    for file in [
        repo_scene("demo.scene"),
        repo_scene("gltf.scene"),
        asset("gltf/bevy/FlightHelmet/FlightHelmet.gltf"),
        asset("cornell/CornellBox-Glossy-Floor.obj"),
    ] {
        let fresh = load_scene(&file).expect("fresh");
        let writing = load_scene_with(&file, &options).expect("first cached load");
        let reading = load_scene_with(&file, &options).expect("second cached load");
        assert_eq!(writing, fresh, "{}", file.display());
        assert_eq!(reading, fresh, "{}", file.display());
        for model in &fresh.models {
            assert!(
                cache_file_for(&cache, &model.path).is_file(),
                "{}",
                model.path.display()
            );
        }
    }
}
