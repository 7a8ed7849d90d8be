//! glTF import against the sample files in `../shared/assets/gltf`: counts, node transforms,
//! materials with their extensions, punctual lights and cameras, tangents.

use crate::common;

use common::asset;
use glam::{Vec3, Vec4};
use weft_scene::camera::CameraOrigin;
use weft_scene::material::{AlphaMode, Optics, ShadingModel, TextureSource};
use weft_scene::{load_scene, Light};

#[test]
fn sample_files_have_exact_counts() {
    // (file, meshes, triangles, materials, distinct textures, lights, cameras from the file)
    let expected = [
        ("bevy/FlightHelmet/FlightHelmet.gltf", 6, 94722, 6, 15, 0, 0),
        ("renderling/EmissiveStrengthTest.glb", 6, 90, 6, 1, 0, 0),
        ("renderling/four_spotlights.glb", 0, 0, 0, 0, 4, 0),
        ("renderling/light_tiling_test.glb", 6, 2330, 6, 0, 1, 1),
        ("renderling/shadow_mapping_points.glb", 10, 120, 2, 0, 4, 1),
        ("renderling/shadow_mapping_sanity.gltf", 6, 2192, 5, 0, 1, 1),
        ("renderling/shadow_mapping_spots.glb", 3, 1042, 3, 0, 2, 1),
        ("renderling/spot_lights.glb", 1, 12, 1, 0, 2, 1),
        ("renderling/spot_one.glb", 5, 528, 2, 0, 1, 1),
        ("rise/AlphaBlendModeTest.glb", 9, 61, 6, 4, 0, 0),
        ("rise/AttenuationTest.glb", 23, 292, 18, 3, 0, 0),
        ("rise/Box.glb", 1, 12, 1, 0, 0, 0),
        ("rise/BoxTextured.glb", 1, 12, 1, 1, 0, 0),
        ("rise/DamagedHelmet.glb", 1, 15452, 1, 5, 0, 0),
        ("rise/DispersionTest.glb", 27, 51827, 27, 2, 0, 0),
        ("rise/MultiUVTest.glb", 1, 12, 1, 2, 0, 1),
        ("rise/NormalTangentMirrorTest.glb", 1, 5240, 1, 3, 0, 0),
        ("rise/NormalTangentTest.glb", 1, 7774, 1, 3, 0, 0),
        ("rise/OrientationTest.glb", 13, 524, 7, 0, 0, 0),
        ("rise/TransmissionTest.glb", 22, 128775, 14, 9, 0, 1),
        ("rise/VertexColorTest.glb", 2, 36, 2, 2, 0, 0),
    ];
    for (file, meshes, triangles, materials, textures, lights, cameras) in expected {
        let scene =
            load_scene(&asset(&format!("gltf/{file}"))).unwrap_or_else(|e| panic!("{file}: {e}"));
        let report = weft_scene::SceneReport::of(&scene);
        assert_eq!(report.meshes, meshes, "{file} meshes");
        assert_eq!(report.triangles, triangles, "{file} triangles");
        assert_eq!(report.materials, materials, "{file} materials");
        assert_eq!(report.textures, textures, "{file} textures");
        assert_eq!(scene.lights.len(), lights, "{file} lights");
        let from_file = scene
            .cameras
            .iter()
            .filter(|c| c.origin == CameraOrigin::Gltf)
            .count();
        assert_eq!(from_file, cameras, "{file} cameras");
        assert_eq!(
            scene.cameras.len(),
            cameras.max(1),
            "{file}: a default camera when the file has none"
        );
        assert!(scene.warnings.is_empty(), "{file}: {:?}", scene.warnings);
        for model in &scene.models {
            assert!(model
                .materials
                .iter()
                .all(|m| m.shading == ShadingModel::MetallicRoughness));
            assert!(model.meshes.iter().all(|m| m.is_consistent()), "{file}");
        }
    }
}

#[test]
fn emissive_strength_scales_the_emissive_factor() {
    let scene = load_scene(&asset("gltf/renderling/EmissiveStrengthTest.glb")).expect("loads");
    let mats = &scene.models[0].materials;
    let emit = |name: &str| mats.iter().find(|m| m.name == name).map(|m| m.emissive);
    assert_eq!(emit("Emit1"), Some(Vec3::new(0.1, 0.5, 0.9)));
    assert_eq!(emit("Emit4"), Some(Vec3::new(0.1, 0.5, 0.9) * 4.0));
    assert_eq!(emit("Emit16"), Some(Vec3::new(0.1, 0.5, 0.9) * 16.0));
}

#[test]
fn transmission_and_volume_extensions() {
    let scene = load_scene(&asset("gltf/rise/AttenuationTest.glb")).expect("loads");
    let mats = &scene.models[0].materials;
    let m = mats
        .iter()
        .find(|m| m.name == "R5_Attenuation_0.25")
        .expect("material");
    assert_eq!(
        (m.transmission, m.thickness, m.attenuation_distance),
        (1.0, 1.0, Some(4.0))
    );
    assert_eq!(m.attenuation_color, Vec3::new(0.1, 0.5, 0.9));
    // σ = -ln(c) / d: over 4 units the volume keeps (0.1, 0.5, 0.9).
    let kept = (-m.absorption * 4.0).exp();
    assert!(
        (kept - Vec3::new(0.1, 0.5, 0.9)).abs().max_element() < 1e-6,
        "{kept}"
    );
    let solid = Optics::Dielectric {
        fraction: 1.0,
        thin: false,
    };
    assert_eq!(m.optics, solid);
    // Without KHR_materials_volume a transmissive material is thin-walled.
    let sample = mats
        .iter()
        .find(|m| m.name == "R1_Sample_1.0")
        .expect("material");
    assert_eq!(
        (sample.optics, sample.absorption),
        (
            Optics::Dielectric {
                fraction: 1.0,
                thin: true
            },
            Vec3::ZERO
        )
    );
    let t = mats
        .iter()
        .find(|m| m.name == "R3_ThicknessTex_Mat")
        .expect("material");
    assert_eq!(t.thickness, 2.0);
    assert!(t.textures.thickness.is_some());
    let plain = mats
        .iter()
        .find(|m| m.name == "LabelMaterial")
        .expect("material");
    assert_eq!(
        (plain.transmission, plain.attenuation_distance, plain.optics),
        (0.0, None, Optics::Opaque)
    );

    let scene = load_scene(&asset("gltf/rise/TransmissionTest.glb")).expect("loads");
    let mats = &scene.models[0].materials;
    let m = mats
        .iter()
        .find(|m| m.name == "GreenMaskRough")
        .expect("material");
    assert_eq!(
        (m.transmission, m.roughness, m.alpha_mode),
        (1.0, 0.32, AlphaMode::Mask(0.5))
    );
    assert!(m.double_sided);
    assert_eq!(scene.cameras[0].name, "render_camera");
}

#[test]
fn punctual_lights_become_scene_lights() {
    let scene = load_scene(&asset("gltf/renderling/spot_lights.glb")).expect("loads");
    let Light::Spot(spot) = &scene.lights[1] else {
        panic!("spot")
    };
    assert!((spot.angle - 5.2).abs() < 1e-4, "{}", spot.angle);
    assert!((spot.inner_angle.unwrap_or(0.0) - 4.42).abs() < 1e-4);
    assert!(spot.direction.distance(Vec3::NEG_X) < 1e-5);
    assert!(
        spot.position
            .distance(Vec3::new(4.283_793, -0.005_799, 0.000_309))
            < 1e-4
    );
    assert_eq!(spot.attenuation, weft_scene::Attenuation::INVERSE_SQUARE);
    let cam = &scene.cameras[0];
    assert_eq!(
        (cam.name.as_str(), cam.near, cam.far),
        ("Camera", 0.1, 100.0)
    );
    assert!((cam.fov_y - 0.399_596_5).abs() < 1e-6);

    // Photometric intensities in Blender's convention: the file's 54351.41 cd spots
    // (Blender's 1000 W, exported as W x 683 / 4 pi) get colour I / (683 pi), 25.33.
    let scene = load_scene(&asset("gltf/renderling/shadow_mapping_spots.glb")).expect("loads");
    let Light::Spot(spot) = &scene.lights[0] else {
        panic!("spot")
    };
    let expected = 54_351.413 / (683.0 * std::f32::consts::PI);
    assert!(
        (spot.color - Vec3::splat(expected)).abs().max_element() < 1e-3,
        "{}",
        spot.color
    );
    assert!((expected - 1000.0 / (4.0 * std::f32::consts::PI * std::f32::consts::PI)).abs() < 1e-3);

    let scene = load_scene(&asset("gltf/renderling/four_spotlights.glb")).expect("loads");
    let directions: Vec<Vec3> = scene
        .lights
        .iter()
        .map(|l| match l {
            Light::Spot(s) => s.direction.round(),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(directions, vec![Vec3::NEG_Y, Vec3::Y, Vec3::X, Vec3::NEG_Z]);

    let scene = load_scene(&asset("gltf/renderling/shadow_mapping_points.glb")).expect("loads");
    for light in &scene.lights {
        let Light::Point(p) = light else {
            panic!("point")
        };
        assert_eq!(p.radius_source, weft_scene::light::RadiusSource::Derived);
        assert!((p.position.y - 0.237_934_6).abs() < 1e-5);
        assert!((p.position.x.abs() - 1.5).abs() < 1e-5 && (p.position.z.abs() - 1.5).abs() < 1e-5);
    }
}

#[test]
fn normal_maps_get_tangents_and_textures_resolve() {
    let scene = load_scene(&asset("gltf/bevy/FlightHelmet/FlightHelmet.gltf")).expect("loads");
    let model = &scene.models[0];
    for mesh in &model.meshes {
        assert_eq!(mesh.tangents.len(), mesh.positions.len(), "{}", mesh.name);
        assert!(mesh.tangents.iter().all(|t| t.w.abs() == 1.0));
    }
    let lenses = model
        .materials
        .iter()
        .find(|m| m.name == "LensesMat")
        .expect("material");
    assert_eq!(lenses.alpha_mode, AlphaMode::Blend);
    let Some(TextureSource::File(path)) = lenses.textures.normal.as_ref().map(|t| t.source.clone())
    else {
        panic!("normal map file")
    };
    assert!(path.is_absolute() && path.ends_with("FlightHelmet_Materials_LensesMat_Normal.png"));

    let scene = load_scene(&asset("gltf/rise/DamagedHelmet.glb")).expect("loads");
    let m = &scene.models[0].materials[0];
    assert_eq!((m.metallic, m.roughness, m.emissive), (1.0, 1.0, Vec3::ONE));
    assert_eq!(m.base_color, Vec4::ONE);
    let Some(TextureSource::Embedded {
        mime_type, bytes, ..
    }) = m.textures.base_color.as_ref().map(|t| &t.source)
    else {
        panic!("embedded base colour")
    };
    assert_eq!(mime_type, "image/jpeg");
    assert_eq!(&bytes[..3], &[0xFF, 0xD8, 0xFF]);
    assert_eq!(scene.models[0].meshes[0].tangents.len(), 14556);
}

#[test]
fn node_transforms_are_baked_into_vertices() {
    let scene = load_scene(&asset("gltf/rise/OrientationTest.glb")).expect("loads");
    let b = scene.bounds;
    assert!(
        (b.max.x - 5.330_651).abs() < 1e-4 && (b.min.y + 5.330_651).abs() < 1e-4,
        "{b:?}"
    );
    let scene = load_scene(&asset("gltf/renderling/light_tiling_test.glb")).expect("loads");
    let base = scene.models[0]
        .materials
        .iter()
        .find(|m| m.name == "base.020")
        .expect("material");
    assert_eq!(base.ior, 1.45, "KHR_materials_ior");
    let Light::Sun(sun) = &scene.lights[0] else {
        panic!("sun")
    };
    assert!(
        sun.direction
            .distance(Vec3::new(0.344_933, -0.763_707, 0.545_686))
            < 1e-5
    );
}

#[test]
fn second_uv_set_and_vertex_colours() {
    let scene = load_scene(&asset("gltf/rise/MultiUVTest.glb")).expect("loads");
    let model = &scene.models[0];
    let mesh = &model.meshes[0];
    assert_eq!(
        (mesh.uvs.len(), mesh.uvs1.len()),
        (mesh.positions.len(), mesh.positions.len())
    );
    assert_ne!(mesh.uvs, mesh.uvs1);
    let coords: Vec<u32> = model.materials[0]
        .textures
        .iter()
        .map(|t| t.tex_coord)
        .collect();
    assert!(coords.contains(&1), "{coords:?}");

    let scene = load_scene(&asset("gltf/rise/VertexColorTest.glb")).expect("loads");
    let with_colors: Vec<usize> = scene.models[0]
        .meshes
        .iter()
        .map(|m| m.colors.len())
        .collect();
    assert!(with_colors.iter().any(|&n| n > 0), "{with_colors:?}");
    for mesh in &scene.models[0].meshes {
        assert!(mesh.colors.is_empty() || mesh.colors.len() == mesh.positions.len());
    }
}

/// A one-triangle glTF whose POSITION accessor has `position_type`, indices
/// of `index_type` (a component type), and `asset` as its asset object.
pub(crate) fn triangle_gltf(asset: &str, position_type: &str, index_type: u32) -> String {
    // 3 float VEC3 positions (36 bytes), then 3 u32 indices (12 bytes).
    let mut bytes: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    bytes.extend([0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    let data = base64(&bytes);
    format!(
        r#"{{"asset":{asset},"buffers":[{{"uri":"data:application/octet-stream;base64,{data}","byteLength":48}}],
"bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":12}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"{position_type}","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":{index_type},"count":3,"type":"SCALAR"}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#
    )
}

pub(crate) fn base64(bytes: &[u8]) -> String {
    const TABLE: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(TABLE[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[test]
fn accessor_types_and_the_asset_version_are_held_to_the_specification() {
    let dir = common::temp_dir("gltf-spec");
    let load = |name: &str, text: String| {
        let path = dir.join(name);
        std::fs::write(&path, text).expect("write");
        load_scene(&path)
            .map(|s| s.triangle_count())
            .map_err(|e| e.to_string())
    };
    let version = r#"{"version":"2.0"}"#;
    assert_eq!(
        load("good.gltf", triangle_gltf(version, "VEC3", 5125)),
        Ok(1)
    );
    let error =
        load("vec2.gltf", triangle_gltf(version, "VEC2", 5125)).expect_err("VEC2 positions");
    assert!(
        error.contains("attribute POSITION is accessor 0 of F32 Vec2; the glTF 2.0 specification allows float VEC3"),
        "{error}"
    );
    let error =
        load("signed.gltf", triangle_gltf(version, "VEC3", 5122)).expect_err("signed indices");
    assert!(
        error.contains("indices are accessor 1 of I16 Scalar; the glTF 2.0 specification allows unsigned SCALAR integers"),
        "{error}"
    );
    let error = load(
        "v3.gltf",
        triangle_gltf(r#"{"version":"3.0"}"#, "VEC3", 5125),
    )
    .expect_err("glTF 3");
    assert!(
        error.contains("asset.version is \"3.0\"; weft reads glTF 2.x"),
        "{error}"
    );
    let error = load(
        "min.gltf",
        triangle_gltf(r#"{"version":"2.0","minVersion":"3.0"}"#, "VEC3", 5125),
    )
    .expect_err("minVersion 3");
    assert!(error.contains("asset.minVersion is \"3.0\""), "{error}");
}
