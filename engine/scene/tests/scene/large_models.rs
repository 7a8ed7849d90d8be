//! The large McGuire models, unzipped into a temporary folder: the Sibenik cathedral completes
//! the 15-462 `sibenik.scene`, and the conference room is the cache benchmark's model.

use crate::common;

use common::{asset, short_warnings, temp_dir, unzip_member};
use weft_scene::{load_scene, SceneReport};

#[test]
fn sibenik_scene_loads_once_its_model_is_in_place() {
    let dir = temp_dir("sibenik");
    std::fs::write(
        dir.join("sibenik.obj"),
        unzip_member(
            &asset("large/mcguire/Sibenik_Cathedral/sibenik.zip"),
            "sibenik.obj",
        ),
    )
    .expect("write obj");
    for file in ["sibenik.scene", "sibenik.mtl"] {
        std::fs::copy(asset(&format!("462/scenes/sibenik/{file}")), dir.join(file)).expect("copy");
    }
    std::fs::create_dir_all(dir.join("textures")).expect("textures dir");
    for png in [
        "KAMEN-stup.png",
        "kamen-bump.png",
        "kamen.png",
        "mramor6x6-bump.png",
        "mramor6x6.png",
    ] {
        std::fs::copy(
            asset(&format!("462/scenes/sibenik/textures/{png}")),
            dir.join("textures").join(png),
        )
        .expect("copy texture");
    }
    let scene = load_scene(&dir.join("sibenik.scene")).expect("sibenik.scene loads");
    let report = SceneReport::of(&scene);
    assert_eq!(
        (report.models.len(), report.meshes, report.triangles),
        (1, 1087, 75_284)
    );
    assert_eq!((report.materials, report.textures), (15, 5));
    let warnings = short_warnings(&scene.warnings);
    assert_eq!(&warnings[..3], &[
        "sibenik.scene:10: property name 'direction:' has a trailing colon; read as 'direction'",
        "sibenik.scene:11: property name 'color:' has a trailing colon; read as 'color'",
        "sibenik.scene:12: property name 'ambient:' has a trailing colon; read as 'ambient'",
    ]);
    // The cathedral's windows are `d` < 1 with `Ni 1.5`: glass by the dissolve rule, with a warning.
    assert_eq!(&warnings[3..], &[
        "sibenik.mtl: material 'staklo': opacity 0.1 ('d'/'Tr') with 'Ni 1.5' is read as glass over 90% of the surface in the path tracer, while raster graphs blend it; give 'illum 7' to mean glass or 'Ni 1' to mean coverage only",
        "sibenik.mtl: material 'staklo_crveno': opacity 0.8 ('d'/'Tr') with 'Ni 1.5' is read as glass over 20% of the surface in the path tracer, while raster graphs blend it; give 'illum 7' to mean glass or 'Ni 1' to mean coverage only",
    ]);
    let glass = scene.models[0]
        .materials
        .iter()
        .find(|m| m.name == "staklo")
        .expect("glass");
    assert_eq!(glass.base_color.w, 0.1);
    assert_eq!(
        glass.optics,
        weft_scene::material::Optics::Dielectric {
            fraction: 0.9,
            thin: false
        }
    );
    // Meshes whose material has a bump map get MikkTSpace tangents; the others get none.
    let model = &scene.models[0];
    let mut with_tangents = 0;
    for mesh in &model.meshes {
        let bumpy = mesh
            .material
            .is_some_and(|m| model.materials[m].textures.bump.is_some());
        let expected = if bumpy { mesh.positions.len() } else { 0 };
        assert_eq!(mesh.tangents.len(), expected, "{}", mesh.name);
        with_tangents += usize::from(bumpy);
    }
    assert_eq!(with_tangents, 412);
    assert!(glass.textures.base_color.is_none());
}

#[test]
fn conference_room_counts() {
    let dir = temp_dir("conference");
    let zip = asset("large/mcguire/Conference_Room/conference.zip");
    std::fs::write(
        dir.join("conference.obj"),
        unzip_member(&zip, "conference.obj"),
    )
    .expect("write obj");
    std::fs::write(
        dir.join("conference.mtl"),
        unzip_member(&zip, "conference.mtl"),
    )
    .expect("write mtl");
    let scene = load_scene(&dir.join("conference.obj")).expect("loads");
    let report = SceneReport::of(&scene);
    assert_eq!(
        (
            report.meshes,
            report.triangles,
            report.materials,
            report.textures
        ),
        (41, 331_179, 35, 0)
    );
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}
