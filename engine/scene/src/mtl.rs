//! MTL materials from tobj into [`Material`], with texture options stripped and texture
//! paths resolved (backslashes included) against the MTL file's folder.

use crate::error::{Diagnostics, Location};
use crate::material::{AlphaMode, Material, Optics, ShadingModel, TextureRef};
use glam::{Vec3, Vec4};
use std::path::{Path, PathBuf};

/// Texture statement options and how many arguments each takes (MTL spec, plus `-bm`).
const OPTIONS: &[(&str, usize)] = &[
    ("-blendu", 1),
    ("-blendv", 1),
    ("-boost", 1),
    ("-cc", 1),
    ("-clamp", 1),
    ("-imfchan", 1),
    ("-mm", 2),
    ("-o", 3),
    ("-s", 3),
    ("-t", 3),
    ("-texres", 1),
    ("-bm", 1),
    ("-type", 1),
];

/// Splits a texture statement's argument into its options and the file name (which may
/// contain spaces); returns the `-bm` multiplier when given.
pub(crate) fn split_texture_options(arg: &str) -> (String, Option<f32>) {
    let words: Vec<&str> = arg.split_whitespace().collect();
    let mut i = 0;
    let mut bump = None;
    while i < words.len() {
        let Some(&(name, count)) = OPTIONS.iter().find(|(o, _)| *o == words[i]) else {
            break;
        };
        if name == "-bm" {
            bump = words
                .get(i + 1)
                .and_then(|w| w.parse::<f32>().ok())
                .filter(|v| v.is_finite());
        }
        // `-o`, `-s` and `-t` allow fewer than three numbers; take only the numeric ones.
        let optional = matches!(name, "-o" | "-s" | "-t");
        let mut taken = 0;
        while taken < count
            && words
                .get(i + 1 + taken)
                .is_some_and(|w| !optional || w.parse::<f32>().is_ok())
        {
            taken += 1;
        }
        i += 1 + taken;
    }
    (words[i.min(words.len())..].join(" "), bump)
}

/// Resolves a texture statement to an existing file, warning (and returning `None`) when it
/// is missing.
fn texture(
    dir: &Path,
    arg: Option<&String>,
    material: &str,
    mtl: &Path,
    diag: &mut Diagnostics,
    sources: &mut Vec<PathBuf>,
) -> Option<TextureRef> {
    let (name, _) = split_texture_options(arg?);
    if name.is_empty() {
        diag.warn(
            Location::file(mtl),
            format!("material '{material}': texture statement without a file name; ignored"),
        );
        return None;
    }
    let named = dir.join(name.replace('\\', "/"));
    sources.push(named.clone());
    let path = if named.is_file() {
        named
    } else if let Some(found) = find_ignoring_case(&named) {
        // MTL files written on case-insensitive file systems (Sponza's among them).
        diag.warn(
            Location::file(mtl),
            format!(
                "material '{material}': texture {} found as {} (the case differs)",
                named.display(),
                found.display()
            ),
        );
        sources.push(found.clone());
        found
    } else {
        diag.warn(
            Location::file(mtl),
            format!(
                "material '{material}': texture {} not found; left out",
                named.display()
            ),
        );
        return None;
    };
    let path = std::path::absolute(&path).unwrap_or(path);
    Some(TextureRef::file(path))
}

/// The file `path` names when its components are matched without regard to
/// ASCII case, if exactly one file matches at each step; for MTL files
/// written where names are case-insensitive.
fn find_ignoring_case(path: &Path) -> Option<PathBuf> {
    let mut found = PathBuf::new();
    for component in path.components() {
        let exact = found.join(component);
        if exact.exists() {
            found = exact;
            continue;
        }
        let wanted = component.as_os_str().to_str()?;
        let mut matches = std::fs::read_dir(if found.as_os_str().is_empty() {
            Path::new(".")
        } else {
            &found
        })
        .ok()?
        .filter_map(|entry| entry.ok())
        .filter(|entry| {
            entry
                .file_name()
                .to_str()
                .is_some_and(|n| n.eq_ignore_ascii_case(wanted))
        });
        let first = matches.next()?;
        if matches.next().is_some() {
            return None;
        }
        found.push(first.file_name());
    }
    found.is_file().then_some(found)
}

/// Clamps a value that must lie in [0, 1], treating NaN as `fallback`.
fn unit(v: f32, fallback: f32) -> f32 {
    if v.is_nan() {
        fallback
    } else {
        v.clamp(0.0, 1.0)
    }
}

/// A colour, or `fallback` when the file gives none.
fn color(c: Option<[f32; 3]>, fallback: Vec3) -> Vec3 {
    c.map(Vec3::from_array).unwrap_or(fallback)
}

/// Statements whose fields tobj cannot take: colours with fewer than three
/// fields (it panics) — `Kd r` is widened to `Kd r r r` as the MTL spec allows,
/// other short or non-numeric ones are blanked — and numeric statements with a
/// NaN, infinite or out-of-range (beyond f32) value, which would make a surface
/// vanish. Returns the text to parse and `(line, warning)` for each blanked line.
/// MTL statements whose fields are numbers.
const NUMERIC_KEYWORDS: [&str; 10] = ["Ka", "Kd", "Ks", "Ke", "Tf", "Ns", "Ni", "d", "Tr", "illum"];

pub(crate) fn sanitize(text: &str) -> (String, Vec<(usize, String)>) {
    let mut out = String::with_capacity(text.len());
    let mut dropped = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let keyword = words.next().unwrap_or_default();
        let fields: Vec<&str> = words.collect();
        let non_finite = fields
            .iter()
            .find(|f| f.parse::<f32>().is_ok_and(|v| !v.is_finite()));
        if let (true, Some(bad)) = (NUMERIC_KEYWORDS.contains(&keyword), non_finite) {
            dropped.push((
                i + 1,
                format!("'{keyword}' value '{bad}' is not a finite 32-bit number; line ignored"),
            ));
        } else if matches!(keyword, "Ka" | "Kd" | "Ks" | "Ke") && fields.len() < 3 {
            let numeric = fields.iter().all(|f| f.parse::<f32>().is_ok());
            match fields.as_slice() {
                [r] if numeric => out.push_str(&format!("{keyword} {r} {r} {r}")),
                _ => dropped.push((
                    i + 1,
                    format!(
                        "'{keyword}' needs 1 or 3 numbers, found {}; line ignored",
                        fields.len()
                    ),
                )),
            }
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    (out, dropped)
}

/// Converts one tobj material read from `mtl`.
/// Every texture path it looks at is added to `sources`.
pub(crate) fn convert(
    m: &tobj::Material,
    mtl: &Path,
    diag: &mut Diagnostics,
    sources: &mut Vec<PathBuf>,
) -> Material {
    let dir = mtl.parent().unwrap_or(Path::new(""));
    let name = m.name.as_str();
    let tr = m
        .unknown_param
        .get("Tr")
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse::<f32>().ok());
    let opacity = match (m.dissolve, tr) {
        (Some(d), Some(t)) => {
            if (d + t - 1.0).abs() > 1e-3 {
                diag.warn(
                    Location::file(mtl),
                    format!("material '{name}': 'd {d}' and 'Tr {t}' disagree (d should be 1 - Tr); 'd' is used"),
                );
            }
            d
        }
        (Some(d), None) => d,
        (None, Some(t)) => 1.0 - t,
        (None, None) => 1.0,
    };
    let opacity = unit(opacity, 1.0);
    let shininess = m
        .shininess
        .filter(|s| s.is_finite())
        .unwrap_or(0.0)
        .max(0.0);
    let kd = color(m.diffuse, Vec3::splat(0.8));
    let ni = m.optical_density.filter(|n| n.is_finite() && *n > 0.0);
    let mut out = Material {
        name: name.to_string(),
        shading: ShadingModel::BlinnPhong,
        base_color: Vec4::new(kd.x, kd.y, kd.z, opacity),
        ambient: color(m.ambient, Vec3::ZERO),
        specular: color(m.specular, Vec3::ZERO),
        shininess,
        emissive: color(m.emissive, Vec3::ZERO),
        ior: ni.unwrap_or(1.5),
        illum: m.illumination_model,
        roughness: (2.0 / (shininess + 2.0)).sqrt(),
        alpha_mode: if opacity < 1.0 {
            AlphaMode::Blend
        } else {
            AlphaMode::Opaque
        },
        ..Material::default()
    };
    let unknown = |key: &str| m.unknown_param.get(key);
    if let Some(tf) = unknown("Tf") {
        let values: Vec<f32> = tf
            .split_whitespace()
            .filter_map(|v| v.parse().ok())
            .collect();
        out.transmission_filter = match values[..] {
            [v] => Vec3::splat(v),
            [r, g, b, ..] => Vec3::new(r, g, b),
            _ => Vec3::ONE,
        }
        .clamp(Vec3::ZERO, Vec3::ONE);
    }
    out.optics = optics(&out, ni, &mut |message| {
        diag.warn(Location::file(mtl), format!("material '{name}': {message}"))
    });
    out.textures.base_color = texture(dir, m.diffuse_texture.as_ref(), name, mtl, diag, sources);
    out.textures.specular = texture(dir, m.specular_texture.as_ref(), name, mtl, diag, sources);
    out.textures.opacity = texture(dir, m.dissolve_texture.as_ref(), name, mtl, diag, sources);
    out.textures.emissive = texture(dir, unknown("map_Ke"), name, mtl, diag, sources);
    out.textures.normal = texture(dir, unknown("norm"), name, mtl, diag, sources);
    if let Some(arg) = &m.normal_texture {
        out.textures.bump = texture(dir, Some(arg), name, mtl, diag, sources);
        if let (_, Some(bm)) = split_texture_options(arg) {
            out.normal_scale = bm;
        }
    }
    if out.textures.opacity.is_some() && out.alpha_mode == AlphaMode::Opaque {
        out.alpha_mode = AlphaMode::Mask(0.5);
    }
    out
}

/// What the path tracer does at an MTL material's surface (`ni`: the `Ni` the
/// file gives), calling `warn` on combinations that could mean two things.
/// `illum 3` is a mirror, `illum 5` a coated diffuse, `illum 4/6/7` glass;
/// any other material with `d < 1` (or `Tr > 0`) and an `Ni` other than 1 is
/// glass over `1 - d` of its surface.
fn optics(out: &Material, ni: Option<f32>, warn: &mut dyn FnMut(String)) -> Optics {
    let opacity = out.base_color.w;
    match out.illum {
        Some(3) => Optics::Mirror,
        Some(5) => Optics::Coated,
        Some(illum @ (4 | 6 | 7)) => {
            match ni {
                None => warn(format!(
                    "glass (illum {illum}) without 'Ni'; index 1.5 assumed"
                )),
                Some(1.0) => warn(format!(
                    "glass (illum {illum}) with 'Ni 1' bends no light and reflects none: invisible in the path tracer"
                )),
                Some(_) => {}
            }
            if opacity < 1.0 {
                warn(format!(
                    "glass (illum {illum}) with opacity {opacity} ('d'/'Tr'): raster graphs blend it, the path tracer ignores 'd' for glass"
                ));
            }
            if out.transmission_filter == Vec3::ZERO {
                warn(format!(
                    "glass (illum {illum}) with 'Tf 0 0 0' lets no light through"
                ));
            }
            Optics::Dielectric {
                fraction: 1.0,
                thin: false,
            }
        }
        _ => match ni {
            Some(n) if opacity < 1.0 && n != 1.0 => {
                warn(format!(
                    "opacity {opacity} ('d'/'Tr') with 'Ni {n}' is read as glass over {:.0}% of the surface in the path tracer, while raster graphs blend it; give 'illum 7' to mean glass or 'Ni 1' to mean coverage only",
                    (1.0 - opacity) * 100.0
                ));
                Optics::Dielectric {
                    fraction: 1.0 - opacity,
                    thin: false,
                }
            }
            _ => Optics::Opaque,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The optics of a material with `illum`, opacity `d`, `Ni` and `Tf`, and the warnings.
    fn optics_of(illum: Option<u8>, d: f32, ni: Option<f32>, tf: f32) -> (Optics, Vec<String>) {
        let m = Material {
            illum,
            base_color: Vec4::new(0.5, 0.5, 0.5, d),
            transmission_filter: Vec3::splat(tf),
            ..Material::default()
        };
        let mut warnings = Vec::new();
        let o = optics(&m, ni, &mut |w| warnings.push(w));
        (o, warnings)
    }

    #[test]
    fn illum_and_dissolve_choose_the_optics() {
        let glass = |fraction| Optics::Dielectric {
            fraction,
            thin: false,
        };
        assert_eq!(optics_of(Some(3), 1.0, None, 1.0), (Optics::Mirror, vec![]));
        assert_eq!(optics_of(Some(5), 1.0, None, 1.0), (Optics::Coated, vec![]));
        assert_eq!(
            optics_of(Some(2), 1.0, Some(1.5), 1.0),
            (Optics::Opaque, vec![])
        );
        for illum in [4, 6, 7] {
            assert_eq!(
                optics_of(Some(illum), 1.0, Some(1.5), 1.0),
                (glass(1.0), vec![])
            );
        }
        assert_eq!(
            optics_of(Some(2), 0.25, Some(1.0), 1.0),
            (Optics::Opaque, vec![])
        );
        assert_eq!(optics_of(None, 0.5, None, 1.0), (Optics::Opaque, vec![]));
        let (o, w) = optics_of(Some(2), 0.25, Some(1.45), 1.0);
        assert_eq!(o, glass(0.75));
        assert_eq!(
            w,
            ["opacity 0.25 ('d'/'Tr') with 'Ni 1.45' is read as glass over 75% of the surface in the path tracer, while raster graphs blend it; give 'illum 7' to mean glass or 'Ni 1' to mean coverage only"]
        );
    }

    #[test]
    fn ambiguous_glass_warns() {
        let warnings = |illum, d, ni, tf| optics_of(Some(illum), d, ni, tf).1;
        assert_eq!(
            warnings(7, 1.0, None, 1.0),
            ["glass (illum 7) without 'Ni'; index 1.5 assumed"]
        );
        assert_eq!(
            warnings(4, 1.0, Some(1.0), 1.0),
            ["glass (illum 4) with 'Ni 1' bends no light and reflects none: invisible in the path tracer"]
        );
        assert_eq!(
            warnings(6, 0.5, Some(1.5), 0.0),
            [
                "glass (illum 6) with opacity 0.5 ('d'/'Tr'): raster graphs blend it, the path tracer ignores 'd' for glass",
                "glass (illum 6) with 'Tf 0 0 0' lets no light through",
            ]
        );
    }

    #[test]
    fn short_colour_statements() {
        let (text, dropped) = sanitize("newmtl a\nKd 0.5\nKs 1 2\nKa\nKe 1 2 3\n");
        assert_eq!(text, "newmtl a\nKd 0.5 0.5 0.5\n\n\nKe 1 2 3\n");
        assert_eq!(
            dropped,
            vec![
                (
                    3,
                    "'Ks' needs 1 or 3 numbers, found 2; line ignored".to_string()
                ),
                (
                    4,
                    "'Ka' needs 1 or 3 numbers, found 0; line ignored".to_string()
                ),
            ]
        );
    }

    #[test]
    fn non_finite_numbers_are_dropped() {
        let (text, dropped) = sanitize("newmtl a\nKd nan 0 0\nKs inf\nNs 1e39\nKe 1 2 3\n");
        assert_eq!(text, "newmtl a\n\n\n\nKe 1 2 3\n");
        let lines: Vec<_> = dropped.iter().map(|(l, m)| format!("{l}: {m}")).collect();
        assert_eq!(
            lines,
            [
                "2: 'Kd' value 'nan' is not a finite 32-bit number; line ignored",
                "3: 'Ks' value 'inf' is not a finite 32-bit number; line ignored",
                "4: 'Ns' value '1e39' is not a finite 32-bit number; line ignored",
            ]
        );
    }

    #[test]
    fn texture_options_are_stripped() {
        assert_eq!(
            split_texture_options("a b.png"),
            ("a b.png".to_string(), None)
        );
        assert_eq!(
            split_texture_options("-bm 0.5 n.png"),
            ("n.png".to_string(), Some(0.5))
        );
        assert_eq!(
            split_texture_options("-s 2 2 -clamp on t.png"),
            ("t.png".to_string(), None)
        );
        assert_eq!(
            split_texture_options("-o 1 2 3 x\\y.png"),
            ("x\\y.png".to_string(), None)
        );
        assert_eq!(split_texture_options("-mm"), (String::new(), None));
    }
}
