//! `weft bench tangents`: the packed vertex tangent frames of real models
//! against the float frames they encode, for both 32-bit encodings
//! (`weft_scene::tangent_frame`), with the UVs' 16-bit quantization error and
//! the vertex buffer's size before and after.

use anyhow::{Context, Result};
use clap::Args;
use glam::Vec2;
use std::path::PathBuf;
use std::process::ExitCode;
use weft_render::{quantize_uv, uv_box, SceneGeometry, VERTEX_BYTES};
use weft_scene::tangent_frame::{self, ErrorSummary, TangentFrame};

/// Arguments of `weft bench tangents`.
#[derive(Args)]
pub struct TangentsArgs {
    /// Scenes or model files (.obj, .gltf, .glb); by default the glTF test
    /// models under ../shared/assets/gltf.
    files: Vec<PathBuf>,
}

/// The models measured when none are named.
const DEFAULT_MODELS: [&str; 4] = [
    "../shared/assets/gltf/bevy/FlightHelmet/FlightHelmet.gltf",
    "../shared/assets/gltf/rise/DamagedHelmet.glb",
    "../shared/assets/gltf/rise/NormalTangentTest.glb",
    "../shared/assets/gltf/rise/NormalTangentMirrorTest.glb",
];

/// Bytes per vertex before packing: position, normal and UV as floats.
const FLOAT_VERTEX_BYTES: u64 = 32;
/// ... and with a float tangent (xyz, handedness) added.
const FLOAT_TANGENT_VERTEX_BYTES: u64 = 48;

/// A scene around `file`: itself when it is a scene, else one instance of the model.
fn scene_of(file: &PathBuf) -> Result<weft_scene::Scene> {
    let is_scene = file.extension().is_some_and(|e| e == "scene");
    if is_scene {
        return weft_scene::load_scene(file).with_context(|| format!("loading {}", file.display()));
    }
    let absolute = std::fs::canonicalize(file).with_context(|| {
        format!(
            "{} not found (run from the repository root)",
            file.display()
        )
    })?;
    let dir = std::env::temp_dir().join(format!("weft-bench-tangents-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("model.scene");
    std::fs::write(
        &path,
        format!("model\n{{\n\tfile \"{}\"\n}}\n", absolute.display()),
    )?;
    let scene = weft_scene::load_scene(&path);
    let _ = std::fs::remove_dir_all(&dir);
    scene.with_context(|| format!("loading {}", file.display()))
}

fn row(name: &str, encoding: &str, s: &ErrorSummary) -> String {
    format!(
        "| {name} | {encoding} | {:.4} / {:.4} | {:.4} / {:.4} | {:.4} / {:.4} |",
        s.mean.normal,
        s.max.normal,
        s.mean.tangent,
        s.max.tangent,
        s.mean.bitangent,
        s.max.bitangent
    )
}

/// Runs `weft bench tangents`.
pub fn run(args: TangentsArgs) -> Result<ExitCode> {
    let files: Vec<PathBuf> = if args.files.is_empty() {
        DEFAULT_MODELS.iter().map(PathBuf::from).collect()
    } else {
        args.files.clone()
    };
    let mut errors = Vec::new();
    let mut sizes = Vec::new();
    for file in &files {
        let scene = scene_of(file)?;
        let name = file.file_name().map_or_else(
            || file.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        // Every vertex of every mesh once (as the vertex buffer holds them).
        let (mut octahedral, mut quaternion) = (ErrorSummary::default(), ErrorSummary::default());
        let (mut vertices, mut with_tangents, mut uv_error) = (0u64, 0u64, 0.0f32);
        for model in &scene.models {
            for mesh in &model.meshes {
                let uv_range = uv_box(&mesh.uvs);
                for (i, normal) in mesh.normals.iter().enumerate() {
                    vertices += 1;
                    let tangent = mesh.tangents.get(i).copied();
                    with_tangents += u64::from(tangent.is_some());
                    let exact = TangentFrame::new(*normal, tangent);
                    let packed = tangent_frame::unpack(tangent_frame::pack(&exact));
                    let smallest =
                        tangent_frame::unpack_quaternion(tangent_frame::pack_quaternion(&exact));
                    let mut e = tangent_frame::frame_error(&exact, &packed);
                    let mut q = tangent_frame::frame_error(&exact, &smallest);
                    if tangent.is_none() {
                        // Without a baked tangent only the normal is used.
                        e.tangent = 0.0;
                        e.bitangent = 0.0;
                        q.tangent = 0.0;
                        q.bitangent = 0.0;
                    }
                    octahedral.add(e);
                    quaternion.add(q);
                    if let Some(uv) = mesh.uvs.get(i).filter(|uv| uv.is_finite()) {
                        let [u, v] = quantize_uv(*uv, uv_range);
                        let back =
                            uv_range.0 + uv_range.1 * Vec2::new(u as f32, v as f32) / 65535.0;
                        uv_error = uv_error.max((back - *uv).abs().max_element());
                    }
                }
            }
        }
        errors.push(row(&name, "octahedral + angle (used)", &octahedral));
        errors.push(row(&name, "smallest-three quaternion", &quaternion));
        let buffer = SceneGeometry::new(&scene).vertices.len() as u64;
        sizes.push(format!(
            "| {name} | {vertices} | {with_tangents} | {:.2e} | {:.2} | {:.2} | {:.2} |",
            uv_error,
            (buffer * FLOAT_VERTEX_BYTES) as f64 / 1048576.0,
            (buffer * FLOAT_TANGENT_VERTEX_BYTES) as f64 / 1048576.0,
            (buffer * u64::from(VERTEX_BYTES)) as f64 / 1048576.0,
        ));
    }
    println!("Angular error of the decoded frame against the float frame, degrees (mean / max); tangent and bitangent over vertices with a baked tangent\n");
    println!("| model | encoding | normal | tangent | bitangent |\n|---|---|---|---|---|");
    for line in &errors {
        println!("{line}");
    }
    println!(
        "\nVertex buffer (light volumes included): {FLOAT_VERTEX_BYTES} bytes per vertex before (no tangent), \
         {FLOAT_TANGENT_VERTEX_BYTES} with a float tangent, {VERTEX_BYTES} packed\n"
    );
    println!("| model | vertices | with baked tangents | max UV error (UV units) | 32 B/vertex (MiB) | 48 B/vertex (MiB) | {VERTEX_BYTES} B/vertex (MiB) |\n|---|---|---|---|---|---|---|");
    for line in &sizes {
        println!("{line}");
    }
    Ok(ExitCode::SUCCESS)
}
