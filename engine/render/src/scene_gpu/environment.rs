//! The scene's environment map on the device: its texels and the path
//! tracer's sampling table as texel buffers (`environment_texels`,
//! `environment_table`: shaders/include/environment.glsl,
//! shaders/pathtrace/environment_sampling.glsl), and the `Frame` block's
//! environment fields. A scene without a map gets one black texel and an
//! empty table, so every shader binds the same layout.

use crate::environment::{irradiance_sh, EnvironmentTable};
use crate::environment_prefilter::prefiltered;
use crate::gpu_types::bytes_of;
use glam::{UVec4, Vec4};
use weft_gpu::buffer::{TexelBuffer, TexelFormat};
use weft_gpu::{Gpu, GpuError};
use weft_scene::environment::Environment;

/// The `Frame` block's environment fields (`GpuFrame`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameEnvironment {
    /// Intensity, cos and sin of the rotation about +y, 1 when the table
    /// can be sampled (0: a black map, or none).
    pub params: Vec4,
    /// Width, height, 1 when the scene has a map, 0.
    pub size: UVec4,
    /// The irradiance's nine spherical-harmonic coefficients (rgb), as
    /// [`irradiance_sh`] scales them.
    pub sh: [Vec4; 9],
}

/// The map's texel buffers and the fields the `Frame` block carries.
pub struct EnvironmentBuffers<'g> {
    /// RGB radiance as f32 bits, one `uvec4` per texel, rows from the top:
    /// the map, then its prefiltered levels ([`prefiltered`]).
    pub texels: TexelBuffer<'g>,
    /// [`EnvironmentTable::records`].
    pub table: TexelBuffer<'g>,
    /// What the `Frame` block says of the map.
    pub frame: FrameEnvironment,
}

impl<'g> EnvironmentBuffers<'g> {
    /// Turns the map to `rotation_deg` about +y (the viewer's panel): the
    /// `Frame` block's next upload carries it; nothing else depends on it.
    pub fn turn(&mut self, rotation_deg: f32) {
        let r = rotation_deg.to_radians();
        (self.frame.params.y, self.frame.params.z) = (r.cos(), r.sin());
    }

    /// Uploads `environment`'s map and table (one black texel without one).
    pub fn new(gpu: &'g Gpu, environment: Option<&Environment>) -> Result<Self, GpuError> {
        let words = |texels: &[[f32; 3]]| -> Vec<[u32; 4]> {
            texels
                .iter()
                .map(|t| [t[0].to_bits(), t[1].to_bits(), t[2].to_bits(), 0])
                .collect()
        };
        let (texels, table, frame) = match environment {
            Some(env) => {
                let table = EnvironmentTable::build(env);
                let rotation = env.rotation_deg.to_radians();
                let frame = FrameEnvironment {
                    params: Vec4::new(
                        env.intensity,
                        rotation.cos(),
                        rotation.sin(),
                        f32::from(u8::from(table.sampled)),
                    ),
                    size: UVec4::new(env.width, env.height, 1, 0),
                    sh: irradiance_sh(env).map(|c| c.extend(0.0)),
                };
                let mut texels = words(&env.texels);
                texels.extend(words(&prefiltered(env)));
                (texels, table.records, frame)
            }
            None => (
                vec![[0; 4]],
                vec![[0; 4]],
                FrameEnvironment {
                    params: Vec4::new(0.0, 1.0, 0.0, 0.0),
                    size: UVec4::new(1, 1, 0, 0),
                    sh: [Vec4::ZERO; 9],
                },
            ),
        };
        let upload = |name: &str, records: &[[u32; 4]]| {
            TexelBuffer::device_local(gpu, name, bytes_of(records), TexelFormat::Words4)
        };
        Ok(Self {
            texels: upload("the environment map", &texels)?,
            table: upload("the environment's sampling table", &table)?,
            frame,
        })
    }
}
