//! Small glTF files written for tests.

use std::path::Path;

/// A 1x1 texture of one colour for a test glTF file.
pub struct Texel {
    pub rgb: [u8; 3],
    /// A normal map's `scale`, or `None` for the metallicRoughness texture.
    pub normal_scale: Option<f32>,
}

/// Writes a glTF file with one 2 x 2 quad in z = 0 facing +Z (u along +X, v
/// along -Y) and one metallic-roughness material (`material` is its
/// pbrMetallicRoughness JSON) with `textures` as 1x1 PNGs.
pub fn write_gltf_quad(dir: &Path, material: &str, textures: &[Texel]) {
    let mut bin: Vec<u8> = Vec::new();
    let positions = [
        [-1.0f32, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    for p in positions {
        bin.extend(p.iter().flat_map(|c| c.to_le_bytes()));
    }
    for _ in 0..4 {
        bin.extend([0.0f32, 0.0, 1.0].iter().flat_map(|c| c.to_le_bytes()));
    }
    for uv in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
        bin.extend(uv.iter().flat_map(|c| c.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    std::fs::write(dir.join("quad.bin"), &bin).expect("bin");
    let (mut pbr, mut normal, mut images) = (String::new(), String::new(), Vec::new());
    for (i, t) in textures.iter().enumerate() {
        let [r, g, b] = t.rgb;
        image::RgbaImage::from_pixel(1, 1, image::Rgba([r, g, b, 255]))
            .save(dir.join(format!("t{i}.png")))
            .expect("png");
        images.push(format!(r#"{{ "uri": "t{i}.png" }}"#));
        match t.normal_scale {
            Some(scale) => {
                normal = format!(r#", "normalTexture": {{ "index": {i}, "scale": {scale} }}"#)
            }
            None => pbr = format!(r#", "metallicRoughnessTexture": {{ "index": {i} }}"#),
        }
    }
    let sources: Vec<String> = (0..images.len())
        .map(|i| format!(r#"{{ "source": {i} }}"#))
        .collect();
    let textures = if images.is_empty() {
        String::new()
    } else {
        format!(
            r#""images": [{}], "textures": [{}],"#,
            images.join(", "),
            sources.join(", ")
        )
    };
    let json = format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "scene": 0,
  "scenes": [{{ "nodes": [0] }}],
  "nodes": [{{ "mesh": 0 }}],
  "meshes": [{{ "primitives": [{{ "attributes": {{ "POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2 }}, "indices": 3, "material": 0 }}] }}],
  "materials": [{{ "pbrMetallicRoughness": {{ {material}{pbr} }}{normal} }}],
  {textures}
  "buffers": [{{ "uri": "quad.bin", "byteLength": {len} }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 48 }},
    {{ "buffer": 0, "byteOffset": 48, "byteLength": 48 }},
    {{ "buffer": 0, "byteOffset": 96, "byteLength": 32 }},
    {{ "buffer": 0, "byteOffset": 128, "byteLength": 12 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0] }},
    {{ "bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3" }},
    {{ "bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2" }},
    {{ "bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR" }}
  ]
}}"#,
        len = bin.len()
    );
    std::fs::write(dir.join("quad.gltf"), json).expect("gltf");
}
