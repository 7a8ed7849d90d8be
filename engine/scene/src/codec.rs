//! The cache encoding of every model type (meshes, materials, lights, cameras, warnings).

use crate::binio::{bin_struct, Bin, Reader, Writer};
use crate::bounds::Aabb;
use crate::camera::{Camera, CameraKey, CameraOrigin};
use crate::error::{Location, Warning};
use crate::light::{
    AreaLight, AreaShape, Attenuation, Light, PointLight, RadiusSource, SpotLight, SunLight,
    SunMotion, Swivel,
};
use crate::material::{
    AlphaMode, Material, MaterialTextures, ShadingModel, TextureRef, TextureSource,
};
use crate::mesh::Mesh;
use crate::model::Model;

bin_struct!(Aabb { min, max });
bin_struct!(Mesh {
    name,
    positions,
    normals,
    uvs,
    uvs1,
    colors,
    tangents,
    indices,
    material,
    bounds
});
bin_struct!(TextureRef { source, tex_coord });
bin_struct!(MaterialTextures {
    base_color,
    specular,
    normal,
    bump,
    opacity,
    metallic_roughness,
    emissive,
    occlusion,
    transmission,
    thickness,
});
bin_struct!(Material {
    name,
    shading,
    base_color,
    ambient,
    specular,
    shininess,
    emissive,
    ior,
    illum,
    metallic,
    roughness,
    transmission,
    thickness,
    attenuation_distance,
    attenuation_color,
    alpha_mode,
    double_sided,
    normal_scale,
    textures,
});
bin_struct!(Attenuation {
    constant,
    linear,
    quadratic
});
bin_struct!(SunMotion {
    axis,
    degrees_per_second
});
bin_struct!(SunLight {
    direction,
    color,
    ambient,
    motion
});
bin_struct!(Swivel { from, to, period });
bin_struct!(SpotLight {
    position,
    direction,
    color,
    exponent,
    angle,
    inner_angle,
    length,
    attenuation,
    swivel
});
bin_struct!(PointLight {
    position,
    color,
    velocity,
    amplitude,
    attenuation,
    radius,
    radius_source
});
bin_struct!(AreaLight {
    shape,
    position,
    orientation,
    emission,
    two_sided
});
bin_struct!(CameraKey {
    time,
    position,
    orientation
});
bin_struct!(Camera {
    name,
    position,
    orientation,
    fov_y,
    near,
    far,
    path,
    origin
});
bin_struct!(Location { file, line });
bin_struct!(Warning { at, message });
bin_struct!(Model {
    path,
    meshes,
    materials,
    lights,
    cameras,
    bounds,
    sources
});

/// Implements [`Bin`] for a field-less enum as a one-byte tag.
macro_rules! bin_tag {
    ($t:ty { $($variant:ident = $tag:expr),* $(,)? }) => {
        impl Bin for $t {
            fn write(&self, w: &mut Writer) {
                let tag: u8 = match self { $( <$t>::$variant => $tag, )* };
                tag.write(w);
            }
            fn read(r: &mut Reader<'_>) -> Option<Self> {
                match u8::read(r)? {
                    $( $tag => Some(<$t>::$variant), )*
                    _ => None,
                }
            }
        }
    };
}
bin_tag!(ShadingModel { BlinnPhong = 0, MetallicRoughness = 1 });
bin_tag!(RadiusSource { Given = 0, Derived = 1, Range = 2 });
bin_tag!(CameraOrigin { Scene = 0, Gltf = 1, Default = 2 });

impl Bin for AlphaMode {
    fn write(&self, w: &mut Writer) {
        match self {
            AlphaMode::Opaque => 0u8.write(w),
            AlphaMode::Mask(cutoff) => {
                1u8.write(w);
                cutoff.write(w);
            }
            AlphaMode::Blend => 2u8.write(w),
        }
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        match u8::read(r)? {
            0 => Some(AlphaMode::Opaque),
            1 => Some(AlphaMode::Mask(f32::read(r)?)),
            2 => Some(AlphaMode::Blend),
            _ => None,
        }
    }
}

impl Bin for TextureSource {
    fn write(&self, w: &mut Writer) {
        match self {
            TextureSource::File(path) => {
                0u8.write(w);
                path.write(w);
            }
            TextureSource::Embedded {
                id,
                mime_type,
                bytes,
            } => {
                1u8.write(w);
                id.write(w);
                mime_type.write(w);
                bytes.write(w);
            }
        }
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        match u8::read(r)? {
            0 => Some(TextureSource::File(Bin::read(r)?)),
            1 => Some(TextureSource::Embedded {
                id: Bin::read(r)?,
                mime_type: Bin::read(r)?,
                bytes: Bin::read(r)?,
            }),
            _ => None,
        }
    }
}

impl Bin for AreaShape {
    fn write(&self, w: &mut Writer) {
        match self {
            AreaShape::Rect { width, height } => {
                0u8.write(w);
                width.write(w);
                height.write(w);
            }
            AreaShape::Disc { radius } => {
                1u8.write(w);
                radius.write(w);
            }
        }
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        match u8::read(r)? {
            0 => Some(AreaShape::Rect {
                width: Bin::read(r)?,
                height: Bin::read(r)?,
            }),
            1 => Some(AreaShape::Disc {
                radius: Bin::read(r)?,
            }),
            _ => None,
        }
    }
}

impl Bin for Light {
    fn write(&self, w: &mut Writer) {
        match self {
            Light::Sun(l) => {
                0u8.write(w);
                l.write(w);
            }
            Light::Spot(l) => {
                1u8.write(w);
                l.write(w);
            }
            Light::Point(l) => {
                2u8.write(w);
                l.write(w);
            }
            Light::Area(l) => {
                3u8.write(w);
                l.write(w);
            }
        }
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        match u8::read(r)? {
            0 => Some(Light::Sun(Bin::read(r)?)),
            1 => Some(Light::Spot(Bin::read(r)?)),
            2 => Some(Light::Point(Bin::read(r)?)),
            3 => Some(Light::Area(Bin::read(r)?)),
            _ => None,
        }
    }
}
