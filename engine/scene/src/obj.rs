//! OBJ import through tobj: triangulated, one index per vertex, normals computed when
//! missing, UVs flipped to a top-left origin, errors located by line.

use crate::bounds::Aabb;
use crate::error::{Diagnostics, Location, SceneError, Warning};
use crate::material::Material;
use crate::mesh::{compute_normals, Mesh};
use crate::model::Model;
use crate::mtl;
use crate::source::{read_capped, MAX_MODEL_BYTES};
use glam::{Vec2, Vec3};
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Loads an OBJ file and its material libraries; `asked_at` is where the file was named.
pub fn load_obj(
    path: &Path,
    asked_at: &Location,
    diag: &mut Diagnostics,
) -> Result<Model, SceneError> {
    let bytes = read_capped(path, asked_at, MAX_MODEL_BYTES)?;
    if let Some(nul) = bytes.iter().position(|&b| b == 0) {
        let line = 1 + bytes[..nul].iter().filter(|&&b| b == b'\n').count();
        return Err(SceneError::Model {
            at: Location::line(path, line),
            message: "binary data (a NUL byte), not OBJ text".into(),
        });
    }
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    // Each library read, with how many materials it added (tobj appends them in order).
    let libraries: RefCell<Vec<(PathBuf, usize)>> = RefCell::new(Vec::new());
    let mtl_warnings: RefCell<Vec<Warning>> = RefCell::new(Vec::new());
    let looked_at: RefCell<Vec<PathBuf>> = RefCell::new(vec![path.to_path_buf()]);
    let loader = |name: &Path| -> tobj::MTLLoadResult {
        let file = dir.join(name.to_string_lossy().replace('\\', "/"));
        looked_at.borrow_mut().push(file.clone());
        match load_mtl_text(&file, path, &mut mtl_warnings.borrow_mut()) {
            Some(parsed) => {
                libraries.borrow_mut().push((file, parsed.0.len()));
                Ok(parsed)
            }
            None => Ok((Vec::new(), HashMap::new())),
        }
    };
    // Exporters write comments in legacy encodings; read those bytes as U+FFFD, not as an error.
    let text = String::from_utf8_lossy(&bytes);
    let result = tobj::load_obj_buf(&mut text.as_bytes(), &options, loader);
    diag.warnings.extend(mtl_warnings.into_inner());
    let (models, materials) = result.map_err(|e| locate_obj_error(path, &bytes, &e.to_string()))?;
    let materials = materials.unwrap_or_default();
    let mut sources = looked_at.into_inner();
    let libraries: Vec<PathBuf> = libraries
        .into_inner()
        .into_iter()
        .flat_map(|(file, count)| std::iter::repeat_n(file, count))
        .collect();
    let materials: Vec<Material> = materials
        .iter()
        .enumerate()
        .map(|(i, m)| {
            mtl::convert(
                m,
                libraries.get(i).map_or(path, PathBuf::as_path),
                diag,
                &mut sources,
            )
        })
        .collect();
    // Only a mesh without a material, while materials exist, can come from an unknown usemtl:
    // scan the text for names only then.
    if !materials.is_empty() && models.iter().any(|m| m.mesh.material_id.is_none()) {
        warn_unknown_usemtl(path, &bytes, &materials, diag);
    }
    let mut meshes = Vec::with_capacity(models.len());
    for m in models {
        if let Some(mesh) = convert_mesh(m, materials.len(), path, &bytes, diag)? {
            meshes.push(mesh);
        }
    }
    if meshes.is_empty() {
        return Err(SceneError::Model {
            at: Location::file(path),
            message: "no triangles: the file has no usable 'f' statements (is it an OBJ file?)"
                .into(),
        });
    }
    let mut model = Model {
        path: path.to_path_buf(),
        meshes,
        materials,
        lights: Vec::new(),
        cameras: Vec::new(),
        bounds: Aabb::EMPTY,
        sources,
    };
    model.update_bounds();
    Ok(model)
}

/// Reads and parses one MTL file; a missing or broken library is a warning for the OBJ.
fn load_mtl_text(
    file: &Path,
    obj: &Path,
    warnings: &mut Vec<Warning>,
) -> Option<(Vec<tobj::Material>, HashMap<String, usize>)> {
    let bytes = match read_capped(file, &Location::file(obj), MAX_MODEL_BYTES) {
        Ok(bytes) => bytes,
        Err(e) => {
            warnings.push(Warning {
                at: Location::file(obj),
                message: format!("material library unusable ({e}); default material used"),
            });
            return None;
        }
    };
    let (text, dropped) = mtl::sanitize(&String::from_utf8_lossy(&bytes));
    warnings.extend(dropped.into_iter().map(|(line, message)| Warning {
        at: Location::line(file, line),
        message,
    }));
    match tobj::load_mtl_buf(&mut text.as_bytes()) {
        Ok(parsed) => Some(parsed),
        Err(e) => {
            warnings.push(Warning {
                at: Location {
                    file: file.to_path_buf(),
                    line: locate_mtl_error(text.as_bytes()),
                    column: None,
                },
                message: format!("material library does not parse ({e}); default material used"),
            });
            None
        }
    }
}

/// The first MTL line tobj rejects on its own, found by parsing lines one at a time.
fn locate_mtl_error(bytes: &[u8]) -> Option<usize> {
    let text = String::from_utf8_lossy(bytes);
    text.lines().enumerate().find_map(|(i, line)| {
        let probe = format!("newmtl probe\n{line}\n");
        tobj::load_mtl_buf(&mut probe.as_bytes())
            .is_err()
            .then_some(i + 1)
    })
}

/// Warns, once per name at its first line, about `usemtl` names no library defines (tobj
/// silently gives those faces no material).
fn warn_unknown_usemtl(path: &Path, bytes: &[u8], materials: &[Material], diag: &mut Diagnostics) {
    let mut reported: Vec<&str> = Vec::new();
    let text = String::from_utf8_lossy(bytes);
    for (i, line) in text.lines().enumerate() {
        let Some(name) = line
            .trim_start()
            .strip_prefix("usemtl")
            .filter(|rest| rest.starts_with(char::is_whitespace))
        else {
            continue;
        };
        let name = name.trim();
        if name.is_empty() || materials.iter().any(|m| m.name == name) || reported.contains(&name) {
            continue;
        }
        diag.warn(
            Location::line(path, i + 1),
            format!("usemtl '{name}' names no loaded material; default material used"),
        );
        reported.push(name);
    }
}

/// Turns one tobj model into a mesh; `None` when it has no triangles.
fn convert_mesh(
    m: tobj::Model,
    material_count: usize,
    path: &Path,
    bytes: &[u8],
    diag: &mut Diagnostics,
) -> Result<Option<Mesh>, SceneError> {
    let mesh = m.mesh;
    if mesh.indices.is_empty() {
        return Ok(None);
    }
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    if !finite(&mesh.positions) || !finite(&mesh.normals) || !finite(&mesh.texcoords) {
        return Err(locate_obj_error(path, bytes, "a number is NaN or infinite"));
    }
    let positions: Vec<Vec3> = mesh
        .positions
        .chunks_exact(3)
        .map(Vec3::from_slice)
        .collect();
    if mesh.indices.iter().any(|&i| i as usize >= positions.len()) {
        return Err(locate_obj_error(
            path,
            bytes,
            "a face index is out of range",
        ));
    }
    let normals = if mesh.normals.len() == mesh.positions.len() {
        mesh.normals
            .chunks_exact(3)
            .map(|n| Vec3::from_slice(n).try_normalize().unwrap_or(Vec3::Y))
            .collect()
    } else {
        compute_normals(&positions, &mesh.indices)
    };
    let uvs = if mesh.texcoords.len() / 2 == positions.len() {
        mesh.texcoords
            .chunks_exact(2)
            .map(|t| Vec2::new(t[0], 1.0 - t[1]))
            .collect()
    } else {
        Vec::new()
    };
    let colors = if mesh.vertex_color.len() == mesh.positions.len() {
        mesh.vertex_color
            .chunks_exact(3)
            .map(|c| Vec3::from_slice(c).extend(1.0))
            .collect()
    } else {
        Vec::new()
    };
    let material = match mesh.material_id {
        Some(id) if id < material_count => Some(id),
        Some(_) => {
            diag.warn(
                Location::file(path),
                format!(
                    "mesh '{}' uses a material that was not loaded; default material used",
                    m.name
                ),
            );
            None
        }
        None => None,
    };
    let bounds = Aabb::from_points(&positions);
    Ok(Some(Mesh {
        name: m.name,
        positions,
        normals,
        uvs,
        uvs1: Vec::new(),
        colors,
        tangents: Vec::new(),
        indices: mesh.indices,
        material,
        bounds,
    }))
}

/// Finds the first OBJ line that is malformed (bad or non-finite number, face index out of
/// range) so tobj's unlocated error can name a line; falls back to the whole file.
fn locate_obj_error(path: &Path, bytes: &[u8], what: &str) -> SceneError {
    let text = String::from_utf8_lossy(bytes);
    let mut counts = [0usize; 3]; // v, vt, vn
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let problem = match words.next() {
            Some(kind @ ("v" | "vt" | "vn")) => {
                let slot = match kind {
                    "v" => 0,
                    "vt" => 1,
                    _ => 2,
                };
                counts[slot] += 1;
                let needed = if kind == "vt" { 1 } else { 3 };
                let nums: Vec<&str> = words.collect();
                if nums.len() < needed {
                    Some(format!("'{kind}' needs {needed} numbers"))
                } else {
                    nums.iter()
                        .find(|w| !w.parse::<f32>().is_ok_and(f32::is_finite))
                        .map(|w| format!("'{w}' is not a finite number"))
                }
            }
            Some("f") => face_problem(words, &counts),
            _ => None,
        };
        if let Some(message) = problem {
            return SceneError::Model {
                at: Location::line(path, i + 1),
                message,
            };
        }
    }
    SceneError::Model {
        at: Location::file(path),
        message: format!("OBJ does not parse: {what}"),
    }
}

/// What is wrong with a face's vertex references, given how many of each vertex kind precede it.
fn face_problem<'a>(words: impl Iterator<Item = &'a str>, counts: &[usize; 3]) -> Option<String> {
    let corners: Vec<&str> = words.collect();
    if corners.len() < 3 {
        return Some("a face needs at least 3 vertices".to_string());
    }
    for corner in corners {
        for (slot, part) in corner.split('/').enumerate().take(3) {
            if part.is_empty() && slot > 0 {
                continue;
            }
            let Ok(index) = part.parse::<i64>() else {
                return Some(format!("face vertex '{corner}' is malformed"));
            };
            let count = counts[slot] as i64;
            let valid = (index > 0 && index <= count) || (index < 0 && -index <= count);
            if !valid {
                return Some(format!(
                    "face vertex '{corner}' refers past the {count} defined"
                ));
            }
        }
    }
    None
}
