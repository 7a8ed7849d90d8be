//! Environment maps: the light from every direction a scene's rays leave by,
//! an equirectangular HDR image oriented exactly as Mitsuba 3's `envmap`
//! emitter with an identity `to_world` (scenes/FORMAT.md, "environment"), so
//! a Mitsuba render of the same scene is its reference. The file is read
//! through weft's one capped reader and decoded (OpenEXR or Radiance HDR);
//! non-finite texels are refused with their position, negative ones clamped
//! to 0 with one warning that counts them.

use crate::error::{Diagnostics, Location, SceneError};
use crate::source::read_capped;
use std::path::PathBuf;

/// The largest environment file read.
pub const MAX_ENVIRONMENT_BYTES: u64 = 512 << 20;
/// The most texels an environment map may have (an 8192×4096 map).
pub const MAX_ENVIRONMENT_TEXELS: u64 = 8192 * 4096;

/// An `environment` block as written: which file, how bright, how turned.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentDesc {
    /// The equirectangular map, resolved against the scene file.
    pub file: PathBuf,
    /// The `file` line (or the scene, for `--environment`).
    pub at: Location,
    /// Multiplies every texel (Mitsuba's `scale`).
    pub intensity: f32,
    /// Degrees the map is turned about +y (Mitsuba's `to_world` rotation
    /// about [0, 1, 0]).
    pub rotation_deg: f32,
}

/// A loaded environment map: linear RGB radiance, rows from the top (+y).
#[derive(Debug, Clone, PartialEq)]
pub struct Environment {
    /// The map's file.
    pub file: PathBuf,
    /// Multiplies every texel.
    pub intensity: f32,
    /// Degrees turned about +y.
    pub rotation_deg: f32,
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Radiance, `width * height` texels, row by row from the top; finite and
    /// at least 0.
    pub texels: Vec<[f32; 3]>,
}

/// Reads and checks the map `desc` names.
pub fn load_environment(
    desc: &EnvironmentDesc,
    diag: &mut Diagnostics,
) -> Result<Environment, SceneError> {
    let bytes = read_capped(&desc.file, &desc.at, MAX_ENVIRONMENT_BYTES)?;
    let error = |message: String| SceneError::Model {
        at: Location::file(&desc.file),
        message,
    };
    let format = image::guess_format(&bytes)
        .ok()
        .filter(|f| matches!(f, image::ImageFormat::OpenExr | image::ImageFormat::Hdr))
        .ok_or_else(|| {
            error("not an OpenEXR or Radiance HDR file (an environment map is an equirectangular HDR image)".into())
        })?;
    let reader = image::ImageReader::with_format(std::io::Cursor::new(&bytes), format);
    let (width, height) = reader.into_dimensions().map_err(|e| error(e.to_string()))?;
    if u64::from(width) * u64::from(height) > MAX_ENVIRONMENT_TEXELS || width < 2 || height < 2 {
        return Err(error(format!(
            "the map is {width}x{height}; environment maps are from 2x2 to {MAX_ENVIRONMENT_TEXELS} texels"
        )));
    }
    let mut reader = image::ImageReader::with_format(std::io::Cursor::new(&bytes), format);
    reader.limits(limits_for(width, height));
    let image = reader
        .decode()
        .map_err(|e| error(e.to_string()))?
        .into_rgb32f();
    let mut texels: Vec<[f32; 3]> = image.pixels().map(|p| p.0).collect();
    let clamped = sanitize(&mut texels, width).map_err(|(x, y, value)| {
        error(format!(
            "texel ({x}, {y}) is {value:?}: environment radiance must be finite"
        ))
    })?;
    if clamped > 0 {
        diag.warn(
            Location::file(&desc.file),
            format!("{clamped} texel(s) have negative channels; clamped to 0"),
        );
    }
    Ok(Environment {
        file: desc.file.clone(),
        intensity: desc.intensity,
        rotation_deg: desc.rotation_deg,
        width,
        height,
        texels,
    })
}

/// Decoder limits that fit one `width`×`height` float image (with the
/// decoder's RGBA copy).
fn limits_for(width: u32, height: u32) -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(u64::from(width) * u64::from(height) * 16 * 3);
    limits
}

/// Clamps negative channels to 0 and returns how many texels had one; the
/// first non-finite texel (column, row, value) is an error.
pub fn sanitize(texels: &mut [[f32; 3]], width: u32) -> Result<usize, (u32, u32, [f32; 3])> {
    let width = width.max(1) as usize;
    let mut clamped = 0;
    for (i, texel) in texels.iter_mut().enumerate() {
        if texel.iter().any(|c| !c.is_finite()) {
            return Err(((i % width) as u32, (i / width) as u32, *texel));
        }
        if texel.iter().any(|c| *c < 0.0) {
            clamped += 1;
            *texel = texel.map(|c| c.max(0.0));
        }
    }
    Ok(clamped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_channels_are_clamped_and_counted() {
        let mut texels = [[1.0, -2.0, 3.0], [0.5, 0.5, 0.5], [-0.0, -1e-9, 4.0]];
        assert_eq!(sanitize(&mut texels, 3), Ok(2));
        assert_eq!(texels, [[1.0, 0.0, 3.0], [0.5, 0.5, 0.5], [-0.0, 0.0, 4.0]]);
    }

    #[test]
    fn the_first_non_finite_texel_is_refused_with_its_position() {
        let mut texels = [
            [0.0; 3],
            [0.0; 3],
            [0.0; 3],
            [1.0, f32::NAN, 0.0],
            [f32::INFINITY; 3],
        ];
        let (x, y, value) = sanitize(&mut texels, 2).expect_err("NaN");
        assert_eq!((x, y), (1, 1));
        assert!(value[1].is_nan());
    }

    fn write_exr(name: &str, width: u32, height: u32, texels: &[[f32; 3]]) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("weft-env-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join(name);
        let bytes = weft_io::exr::encode_rgb(width, height, texels).expect("encode");
        std::fs::write(&path, bytes).expect("write");
        path
    }

    fn desc(file: PathBuf) -> EnvironmentDesc {
        EnvironmentDesc {
            at: Location::file(&file),
            file,
            intensity: 2.0,
            rotation_deg: 30.0,
        }
    }

    #[test]
    fn reads_an_exr_map_row_by_row_from_the_top() {
        let texels: Vec<[f32; 3]> = (0..8).map(|i| [i as f32, -(i as f32), 1e4]).collect();
        let path = write_exr("rows.exr", 4, 2, &texels);
        let mut diag = Diagnostics::default();
        let env = load_environment(&desc(path.clone()), &mut diag).expect("loads");
        assert_eq!((env.width, env.height), (4, 2));
        assert_eq!(env.texels[5], [5.0, 0.0, 1e4]);
        assert_eq!((env.intensity, env.rotation_deg), (2.0, 30.0));
        assert_eq!(diag.warnings.len(), 1);
        assert_eq!(
            diag.warnings[0].to_string(),
            format!(
                "{}: warning: 7 texel(s) have negative channels; clamped to 0",
                path.display()
            )
        );
    }

    #[test]
    fn refuses_nan_with_its_position_and_files_that_are_not_hdr_images() {
        let mut texels = vec![[0.25f32; 3]; 8];
        texels[6] = [0.0, 0.0, f32::NAN];
        let path = write_exr("nan.exr", 4, 2, &texels);
        let error =
            load_environment(&desc(path.clone()), &mut Diagnostics::default()).expect_err("NaN");
        assert_eq!(
            error.to_string(),
            format!(
                "{}: texel (2, 1) is [0.0, 0.0, NaN]: environment radiance must be finite",
                path.display()
            )
        );
        let text = path.with_extension("txt");
        std::fs::write(&text, "not an image").expect("write");
        let error = load_environment(&desc(text), &mut Diagnostics::default()).expect_err("text");
        assert!(
            error
                .to_string()
                .contains("not an OpenEXR or Radiance HDR file"),
            "{error}"
        );
    }
}
