//! Camera bookmarks: poses saved while flying, kept as a `.scene` file of
//! `camera` blocks (`demo-1a2b3c4d.bookmarks.scene` for `demo.scene`) in the
//! user's data folder, never in the scene's (a repository's working tree),
//! unless `--bookmarks FILE` names one; a bookmark can be pasted into the
//! scene itself.

use anyhow::{Context, Result};
use glam::{DVec3, Quat, Vec3};
use std::path::{Path, PathBuf};
use weft_scene::{scene_desc_from_str, Camera, Diagnostics};

/// One saved pose, in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Bookmark {
    /// `bookmark N`.
    pub name: String,
    /// World position.
    pub world: DVec3,
    /// Where it looks (no roll).
    pub orientation: Quat,
}

impl Bookmark {
    /// The position relative to a scene's `origin` (the coordinates the viewer flies in).
    pub fn position(&self, origin: DVec3) -> Vec3 {
        (self.world - origin).as_vec3()
    }
}

/// The bookmarks file for `scene`: in `data` (the user's data folder,
/// `~/.local/share` by XDG's rule) under `weft/bookmarks`, named by the
/// scene's stem and a hash of its full path, so scenes of one name in
/// different folders keep their own; beside the scene only when there is no
/// data folder.
pub fn file_for(scene: &Path, data: Option<PathBuf>) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
    let Some(data) = data else {
        return scene.with_file_name(format!("{stem}.bookmarks.scene"));
    };
    let full = scene.canonicalize().unwrap_or_else(|_| scene.to_path_buf());
    let mut hasher = weft_io::hash::Hasher::new();
    hasher.field(full.to_string_lossy().as_bytes());
    let hash = weft_io::hash::hex(hasher.finish());
    data.join("weft").join("bookmarks").join(format!(
        "{stem}-{}.bookmarks.scene",
        &hash[..8.min(hash.len())]
    ))
}

/// The bookmarks saved in `path`; none when it does not exist. An unreadable
/// or malformed file is an error naming it (it is never overwritten unread).
pub fn load(path: &Path) -> Result<Vec<Bookmark>> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let text = weft_io::read_text(path, weft_io::MAX_TEXT_BYTES)
        .with_context(|| format!("reading bookmarks {}", path.display()))?;
    let mut diagnostics = Diagnostics::default();
    let desc = scene_desc_from_str(&text, path, &mut diagnostics)
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("reading bookmarks {}", path.display()))?;
    Ok(desc
        .cameras
        .iter()
        .map(|c| Bookmark {
            name: c.name.clone(),
            world: desc.origin + c.position.as_dvec3(),
            orientation: c.orientation,
        })
        .collect())
}

/// Writes `bookmarks` to `path` as `camera` blocks with `lens`'s field of
/// view and clip distances.
pub fn save(path: &Path, bookmarks: &[Bookmark], lens: &Camera) -> Result<()> {
    let text: String = bookmarks
        .iter()
        .map(|b| {
            super::camera_block::camera_block(&b.name, lens, b.world, Vec3::ZERO, b.orientation)
        })
        .collect();
    weft_io::write_output(path, text.as_bytes())
        .with_context(|| format!("writing bookmarks {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bookmarks_go_to_the_data_folder_named_by_scene_and_path() {
        let data = Some(PathBuf::from("/data"));
        let demo = file_for(Path::new("scenes/demo.scene"), data.clone());
        assert_eq!(demo.parent(), Some(Path::new("/data/weft/bookmarks")));
        let name = demo.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            name.starts_with("demo-") && name.ends_with(".bookmarks.scene"),
            "{name}"
        );
        // Another folder's demo.scene keeps its own file.
        assert_ne!(file_for(Path::new("other/demo.scene"), data), demo);
        // Without a data folder, beside the scene.
        assert_eq!(
            file_for(Path::new("scenes/demo.scene"), None),
            PathBuf::from("scenes/demo.bookmarks.scene")
        );
    }

    #[test]
    fn saved_bookmarks_read_back_in_world_coordinates() {
        let dir = std::env::temp_dir().join(format!("weft-bookmarks-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("far.bookmarks.scene");
        let marks = vec![
            Bookmark {
                name: "bookmark 1".into(),
                world: DVec3::new(1e7, 2.0, -2048.5),
                orientation: Quat::from_rotation_y(0.5) * Quat::from_rotation_x(-0.25),
            },
            Bookmark {
                name: "bookmark 2".into(),
                world: DVec3::new(-1.0, 0.5, 3.0),
                orientation: Quat::IDENTITY,
            },
        ];
        let lens = weft_scene::camera::default_camera(&weft_scene::Aabb::EMPTY);
        save(&path, &marks, &lens).unwrap();
        let read = load(&path).unwrap();
        assert_eq!(read.len(), 2);
        for (r, m) in read.iter().zip(&marks) {
            assert_eq!(r.name, m.name);
            assert!((r.world - m.world).length() < 1e-5, "{r:?} vs {m:?}");
            let (a, b) = (r.orientation * Vec3::NEG_Z, m.orientation * Vec3::NEG_Z);
            assert!(a.dot(b) > 1.0 - 1e-6, "{a} vs {b}");
        }
        let origin = DVec3::new(1e7, 0.0, -2048.0);
        assert_eq!(read[0].position(origin), Vec3::new(0.0, 2.0, -0.5));
        assert!(load(&dir.join("none.bookmarks.scene")).unwrap().is_empty());
        std::fs::write(&path, "camera \"x\" { position 1 2 }").unwrap();
        let err = format!("{:#}", load(&path).unwrap_err());
        assert!(err.contains("far.bookmarks.scene"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
