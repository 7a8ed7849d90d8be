//! OBJ/MTL import against the Cornell boxes and the 15-462 models, plus small files written
//! here for the cases the real files lack.

use crate::common;

use common::{asset, short_warnings, temp_dir};
use glam::{Vec2, Vec3, Vec4};
use weft_scene::material::AlphaMode;
use weft_scene::{load_obj, Diagnostics, Location, SceneError};

fn load(path: &std::path::Path) -> (weft_scene::Model, Vec<String>) {
    let mut diag = Diagnostics::default();
    let model = load_obj(path, &Location::file(path), &mut diag).expect("loads");
    (model, short_warnings(&diag.warnings))
}

#[test]
fn cornell_boxes_have_exact_counts() {
    // (file, meshes, triangles, materials, vertices)
    let expected = [
        ("CornellBox-Empty-CO.obj", 6, 12, 6, 24),
        ("CornellBox-Empty-RG.obj", 6, 12, 6, 24),
        ("CornellBox-Empty-Squashed.obj", 6, 12, 7, 24),
        ("CornellBox-Empty-White.obj", 6, 12, 6, 24),
        ("CornellBox-Glossy.obj", 8, 1112, 7, 676),
        ("CornellBox-Mirror.obj", 8, 36, 8, 64),
        ("CornellBox-Original.obj", 8, 36, 8, 64),
        ("CornellBox-Sphere.obj", 8, 2188, 8, 1280),
        ("CornellBox-Water.obj", 9, 7088, 9, 3830),
        ("water.obj", 1, 4900, 1, 2550),
    ];
    for (file, meshes, triangles, materials, vertices) in expected {
        let (model, warnings) = load(&asset(&format!("cornell/{file}")));
        assert_eq!(model.meshes.len(), meshes, "{file} meshes");
        assert_eq!(model.triangle_count(), triangles, "{file} triangles");
        assert_eq!(model.materials.len(), materials, "{file} materials");
        let verts: usize = model.meshes.iter().map(|m| m.positions.len()).sum();
        assert_eq!(verts, vertices, "{file} vertices");
        // The Glossy file names a `light` material its library lacks (see the next test).
        assert_eq!(
            warnings.len(),
            usize::from(file == "CornellBox-Glossy.obj"),
            "{file}: {warnings:?}"
        );
        assert!(model.meshes.iter().all(|m| m.is_consistent()), "{file}");
    }
}

#[test]
fn cornell_original_materials_and_bounds() {
    let (model, _) = load(&asset("cornell/CornellBox-Original.obj"));
    let light = model
        .materials
        .iter()
        .find(|m| m.name == "light")
        .expect("light material");
    assert_eq!(light.emissive, Vec3::new(17.0, 12.0, 4.0));
    assert_eq!(light.base_color, Vec4::new(0.78, 0.78, 0.78, 1.0));
    let left = model
        .materials
        .iter()
        .find(|m| m.name == "leftWall")
        .expect("leftWall");
    assert_eq!(left.base_color, Vec4::new(0.63, 0.065, 0.05, 1.0));
    assert_eq!(left.illum, Some(2));
    assert_eq!(model.bounds.min, Vec3::new(-1.02, 0.0, -1.04));
    assert_eq!(model.bounds.max, Vec3::new(1.0, 1.99, 0.99));
}

#[test]
fn glossy_floor_names_a_material_its_library_lacks() {
    let (model, warnings) = load(&asset("cornell/CornellBox-Glossy-Floor.obj"));
    assert_eq!(model.materials.len(), 7);
    assert_eq!(model.triangle_count(), 1112);
    assert_eq!(
        warnings,
        vec!["CornellBox-Glossy-Floor.obj:3009: usemtl 'light' names no loaded material; default material used"]
    );
    assert_eq!(model.meshes.last().map(|m| m.material), Some(None));
}

#[test]
fn models_462_have_exact_counts() {
    // (file, meshes, triangles, vertices, has uvs)
    let expected = [
        ("bunny.obj", 1, 69451, 34834, false),
        ("checkered_floor.obj", 1, 2, 4, true),
        ("cone.obj", 1, 64, 34, false),
        ("cube.obj", 1, 12, 24, true),
        ("dragon.obj", 1, 100_000, 50_000, false),
        ("sphere.obj", 1, 960, 1984, false),
        ("stone_floor.obj", 1, 2, 4, true),
        ("wall.obj", 1, 2, 4, true),
    ];
    for (file, meshes, triangles, vertices, uvs) in expected {
        let (model, _) = load(&asset(&format!("462/scenes/models/{file}")));
        assert_eq!(model.meshes.len(), meshes, "{file} meshes");
        assert_eq!(model.triangle_count(), triangles, "{file} triangles");
        let verts: usize = model.meshes.iter().map(|m| m.positions.len()).sum();
        assert_eq!(verts, vertices, "{file} vertices");
        assert_eq!(!model.meshes[0].uvs.is_empty(), uvs, "{file} uvs");
    }
}

#[test]
fn textures_resolve_to_absolute_paths() {
    let (model, warnings) = load(&asset("462/scenes/models/cube.obj"));
    assert!(warnings.is_empty(), "{warnings:?}");
    let cube = &model.materials[model.meshes[0].material.expect("material")];
    assert_eq!(cube.name, "cube");
    let tex = cube.textures.base_color.as_ref().expect("map_Kd");
    let weft_scene::material::TextureSource::File(path) = &tex.source else {
        panic!("file texture")
    };
    assert!(path.is_absolute());
    assert!(
        path.ends_with("models/../textures/cube.png"),
        "{}",
        path.display()
    );
    // UVs flip to a top-left origin: OBJ vt 0.375 0.0 becomes (0.375, 1.0).
    assert!(model.meshes[0].uvs.contains(&Vec2::new(0.375, 1.0)));
}

#[test]
fn negative_indices_polygons_missing_normals_and_mtl_quirks() {
    let dir = temp_dir("obj-quirks");
    std::fs::create_dir_all(dir.join("tex")).expect("dir");
    std::fs::write(dir.join("tex/d.png"), b"png").expect("write");
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl a\nKd 0.5 0.25 1\nKs 1 1 1\nKa 0.1 0.1 0.1\nNs 98\nKe 0 1 0\nNi 1.33\nTf 0.9 0.8 0.7\nd 1\nTr 1\nillum 7\n\
         map_Kd tex\\d.png\nmap_bump -bm 0.5 tex/missing.png\nmap_d tex/d.png\n\
         newmtl b\nTr 0.25\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("p.obj"),
        "mtllib m.mtl\nmtllib gone.mtl\no pent\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 1.5 0\nv 0 1 0\n\
         usemtl a\nf -5 -4 -3 -2 -1\no tri\nusemtl b\nf 1 2 3\n",
    )
    .expect("write");
    let (model, warnings) = load(&dir.join("p.obj"));
    assert_eq!(model.meshes.len(), 2);
    assert_eq!(model.meshes[0].triangle_count(), 3);
    assert_eq!(model.meshes[0].normals, vec![Vec3::Z; 5]);
    assert!(model.meshes[0].uvs.is_empty());
    let a = &model.materials[0];
    assert_eq!(a.base_color, Vec4::new(0.5, 0.25, 1.0, 1.0));
    assert_eq!(
        (a.specular, a.ambient, a.emissive),
        (Vec3::ONE, Vec3::splat(0.1), Vec3::Y)
    );
    assert_eq!((a.shininess, a.ior, a.illum), (98.0, 1.33, Some(7)));
    assert_eq!(a.transmission_filter, Vec3::new(0.9, 0.8, 0.7));
    assert!(a.textures.base_color.is_some());
    assert!(a.textures.bump.is_none());
    assert_eq!(a.normal_scale, 0.5);
    assert_eq!(a.alpha_mode, AlphaMode::Mask(0.5));
    let b = &model.materials[1];
    assert_eq!(b.base_color.w, 0.75);
    assert_eq!(b.alpha_mode, AlphaMode::Blend);
    let missing_tex = dir.join("tex/missing.png");
    assert_eq!(
        warnings,
        vec![
            format!(
                "p.obj: material library unusable ({}: missing file {}); default material used",
                dir.join("p.obj").display(),
                dir.join("gone.mtl").display()
            ),
            "m.mtl: material 'a': 'd 1' and 'Tr 1' disagree (d should be 1 - Tr); 'd' is used"
                .to_string(),
            format!(
                "m.mtl: material 'a': texture {} not found; left out",
                missing_tex.display()
            ),
        ]
    );
}

#[test]
fn a_texture_whose_name_differs_in_case_is_found_with_a_warning() {
    let dir = temp_dir("obj-case");
    std::fs::create_dir_all(dir.join("Textures")).expect("dir");
    std::fs::write(dir.join("Textures/Brick.PNG"), b"png").expect("write");
    std::fs::write(dir.join("Textures/twin.png"), b"png").expect("write");
    std::fs::write(dir.join("Textures/TWIN.png"), b"png").expect("write");
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl a\nmap_Kd textures\\brick.png\nnewmtl b\nmap_Kd textures/Twin.png\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("t.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 2\n",
    )
    .expect("write");
    let (model, warnings) = load(&dir.join("t.obj"));
    let tex = model.materials[0]
        .textures
        .base_color
        .as_ref()
        .expect("found");
    let weft_scene::material::TextureSource::File(path) = &tex.source else {
        panic!("file texture")
    };
    assert!(path.ends_with("Textures/Brick.PNG"), "{}", path.display());
    assert!(
        model.materials[1].textures.base_color.is_none(),
        "two files match Twin.png but for case: neither is guessed"
    );
    assert_eq!(
        warnings,
        [
            format!(
                "m.mtl: material 'a': texture {} found as {} (the case differs)",
                dir.join("textures/brick.png").display(),
                dir.join("Textures/Brick.PNG").display()
            ),
            format!(
                "m.mtl: material 'b': texture {} not found; left out",
                dir.join("textures/Twin.png").display()
            ),
        ]
    );
}

#[test]
fn malformed_obj_is_a_located_error() {
    let dir = temp_dir("obj-bad");
    let cases = [
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
            "bad.obj:4: face vertex '4' refers past the 3 defined",
        ),
        (
            "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n",
            "bad.obj:2: 'nan' is not a finite number",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
            "bad.obj:4: face vertex 'x' is malformed",
        ),
        (
            "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n",
            "bad.obj:2: 'inf' is not a finite number",
        ),
        (
            "\u{89}PNG\r\n\u{1a}\n\0\0\0\rIHDR",
            "bad.obj:3: binary data (a NUL byte), not OBJ text",
        ),
        (
            "random words\nv 0 0 0\n",
            "bad.obj: no triangles: the file has no usable 'f' statements (is it an OBJ file?)",
        ),
    ];
    for (text, expected) in cases {
        let path = dir.join("bad.obj");
        std::fs::write(&path, text).expect("write");
        let mut diag = Diagnostics::default();
        let err = load_obj(&path, &Location::file(&path), &mut diag).expect_err(text);
        assert!(matches!(err, SceneError::Model { .. }), "{err:?}");
        let shown = err.to_string();
        let shown = shown.rsplit('/').next().unwrap_or_default();
        assert_eq!(shown, expected);
    }
}

#[test]
fn obj_vertex_colours() {
    let dir = temp_dir("obj-colours");
    let path = dir.join("c.obj");
    std::fs::write(
        &path,
        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n",
    )
    .expect("write");
    let (model, warnings) = load(&path);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(
        model.meshes[0].colors,
        vec![
            Vec4::new(1.0, 0.0, 0.0, 1.0),
            Vec4::new(0.0, 1.0, 0.0, 1.0),
            Vec4::new(0.0, 0.0, 1.0, 1.0)
        ]
    );
}
