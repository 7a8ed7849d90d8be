//! The scene vocabulary the renderer hands graphs (`weft_graph::vocabulary`):
//! the features [`crate::scene_features`] sets, the mesh filters of
//! `draw: Meshes(..)`, the lights `draw: LightVolumes(..)` draws volumes of,
//! and the shading models a define's `draws:` groups mesh draws by. Each name
//! is the Rust name of what the renderer does with it, so adding one is an
//! entry here and the code that handles it; `weft graph check` holds every
//! graph to [`VOCABULARY`] with located errors.

use weft_graph::schema::{Draw, SceneTerm};
use weft_graph::vocabulary::{SceneFeature, SceneValue, SceneVocabulary};

/// What the renderer offers graphs.
pub const VOCABULARY: SceneVocabulary = SceneVocabulary {
    features: SCENE_FEATURES,
    values: SCENE_VALUES,
    mesh_filters: MeshFilter::NAMES,
    light_volumes: LightVolume::NAMES,
    shading_models: ShadingModelName::NAMES,
};

/// The features scenes set, each with when (the viewer's panel shows them
/// read-only with the reason).
pub const SCENE_FEATURES: &[SceneFeature] = &[
    SceneFeature {
        name: "shadow_casters",
        reason: "a placed mesh casts shadows and a sun, point light, cone spot, area light or emissive mesh casts them",
    },
    SceneFeature {
        name: "emissive",
        reason: "a placed mesh glows",
    },
    SceneFeature {
        name: "transparent",
        reason: "a placed mesh blends",
    },
    SceneFeature {
        name: "suns",
        reason: "the scene has a sun",
    },
    SceneFeature {
        name: "point_lights",
        reason: "the scene has a point light",
    },
    SceneFeature {
        name: "spot_lights",
        reason: "the scene has a spot light",
    },
    SceneFeature {
        name: "area_lights",
        reason: "the scene has an area light or emissive geometry that lights raster passes",
    },
    SceneFeature {
        name: "rect_lights",
        reason: "the scene has a rectangle or emissive-polygon light",
    },
    SceneFeature {
        name: "disc_lights",
        reason: "the scene has a disc light",
    },
    SceneFeature {
        name: "punctual_lights",
        reason: "the scene has a sun, point or spot light",
    },
    SceneFeature {
        name: "glossy",
        reason: "a Blinn-Phong material has a specular lobe",
    },
    SceneFeature {
        name: "dielectrics",
        reason: "a material is glass",
    },
    SceneFeature {
        name: "mirrors",
        reason: "a material is a mirror (MTL illum 3)",
    },
    SceneFeature {
        name: "coated",
        reason: "a material has a Fresnel coat (MTL illum 5)",
    },
    SceneFeature {
        name: "metallic_roughness",
        reason: "a glTF material is placed",
    },
    SceneFeature {
        name: "specular_lobes",
        reason: "a material is glossy, a mirror, coated, glass or glTF (lobes rt_specular traces)",
    },
    SceneFeature {
        name: "blinn_phong",
        reason: "a material shades with Blinn-Phong",
    },
    SceneFeature {
        name: "emission_occlusion_maps",
        reason: "a material has an emissive or occlusion texture",
    },
    SceneFeature {
        name: "normal_maps",
        reason: "a material has a normal texture",
    },
    SceneFeature {
        name: "textures",
        reason: "a material has a texture",
    },
    SceneFeature {
        name: "environment",
        reason: "the scene has an environment map",
    },
];

/// The scene value a plan that traces in hardware sizes the scratch of its
/// structures' builds by (`crate::structure_scratch_bytes`).
pub const STRUCTURE_SCRATCH_BYTES: &str = "structure_scratch_bytes";

/// The numbers the renderer measures of each scene for graphs' buffer sizes.
pub const SCENE_VALUES: &[SceneValue] = &[SceneValue {
    name: STRUCTURE_SCRATCH_BYTES,
    meaning: "bytes the builds of the scene's acceleration structures work in (0 when the plan \
              traces in software)",
}];

/// Declares a closed set of names graphs may write, as an enum whose
/// variants are the names, with the list and the lookup.
macro_rules! scene_terms {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident),+ $(,)? }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum $name { $($(#[$vdoc])* $variant),+ }

        impl $name {
            /// Every name, as graphs write them.
            pub const NAMES: &'static [&'static str] = &[$(stringify!($variant)),+];

            /// What a graph's name stands for, if it names one.
            pub fn named(term: &SceneTerm) -> Option<Self> {
                match term.0.as_str() {
                    $(stringify!($variant) => Some(Self::$variant),)+
                    _ => None,
                }
            }

            /// The name graphs write.
            pub fn name(self) -> &'static str {
                match self {
                    $(Self::$variant => stringify!($variant),)+
                }
            }
        }
    };
}

scene_terms! {
    /// Which scene meshes a raster pass draws (`draw: Meshes(Opaque)`).
    MeshFilter {
        /// Every mesh; a pass that blends draws transparent ones after the
        /// rest, farthest first.
        All,
        /// Meshes that do not blend.
        Opaque,
        /// Meshes that blend.
        Transparent,
        /// Meshes that glow.
        Emissive,
        /// Meshes that cast shadows and, in a shadow-atlas pass, the area
        /// lights' panels (opaque, as the path tracer's are).
        ShadowCasters,
    }
}

scene_terms! {
    /// Lights a raster pass draws proxy volumes of (`draw: LightVolumes(Point)`).
    LightVolume {
        /// A sphere per point light.
        Point,
        /// A cone per spot light narrow enough for one, else a sphere.
        Spot,
        /// Each area light's own outline (its panel: a rectangle or a disc),
        /// so a pass can draw what camera rays see of them.
        Area,
    }
}

scene_terms! {
    /// The shading models mesh draws are grouped by (a define's `draws:`).
    ShadingModelName {
        /// MTL materials: diffuse, specular and shininess (mirrors and coats too).
        BlinnPhong,
        /// glTF materials: base colour, metallic and roughness.
        MetallicRoughness,
    }
}

impl ShadingModelName {
    /// The name of a material's shading model.
    pub fn of(model: weft_scene::material::ShadingModel) -> Self {
        match model {
            weft_scene::material::ShadingModel::BlinnPhong => Self::BlinnPhong,
            weft_scene::material::ShadingModel::MetallicRoughness => Self::MetallicRoughness,
        }
    }
}

/// What a raster pass draws, in the renderer's terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneDraw {
    /// Scene meshes through a filter.
    Meshes(MeshFilter),
    /// One proxy volume per light of a kind.
    LightVolumes(LightVolume),
    /// One triangle covering the target (drawn by the executor).
    FullscreenTriangle,
}

impl SceneDraw {
    /// What `draw` stands for; `Err` names a term outside [`VOCABULARY`]
    /// (which `weft graph check` and every compile refuse first).
    pub fn of(draw: &Draw) -> Result<Self, String> {
        let unknown = |what: &str, term: &SceneTerm| format!("unknown {what} `{}`", term.0);
        match draw {
            Draw::Meshes(t) => MeshFilter::named(t)
                .map(SceneDraw::Meshes)
                .ok_or_else(|| unknown("mesh filter", t)),
            Draw::LightVolumes(t) => LightVolume::named(t)
                .map(SceneDraw::LightVolumes)
                .ok_or_else(|| unknown("light kind", t)),
            Draw::FullscreenTriangle => Ok(SceneDraw::FullscreenTriangle),
        }
    }
}

/// Why [`crate::scene_features`] sets `name`, in a phrase a user reads
/// beside it (the viewer's panel shows scene features read-only with this);
/// `None` for a name it never sets.
pub fn scene_feature_reason(name: &str) -> Option<&'static str> {
    SCENE_FEATURES
        .iter()
        .find(|f| f.name == name)
        .map(|f| f.reason)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_name_stands_for_its_value_and_back() {
        for name in MeshFilter::NAMES {
            let filter = MeshFilter::named(&SceneTerm(name.to_string())).expect("named");
            assert_eq!(filter.name(), *name);
        }
        assert_eq!(LightVolume::NAMES, ["Point", "Spot", "Area"]);
        assert_eq!(
            SceneDraw::of(&Draw::LightVolumes(SceneTerm("Spot".into()))),
            Ok(SceneDraw::LightVolumes(LightVolume::Spot))
        );
        assert_eq!(
            SceneDraw::of(&Draw::Meshes(SceneTerm("Opaqe".into()))),
            Err("unknown mesh filter `Opaqe`".to_string())
        );
        assert_eq!(
            ShadingModelName::of(weft_scene::material::ShadingModel::MetallicRoughness).name(),
            "MetallicRoughness"
        );
    }

    #[test]
    fn every_scene_feature_is_named_once_with_a_reason() {
        let mut names: Vec<&str> = SCENE_FEATURES.iter().map(|f| f.name).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), SCENE_FEATURES.len());
        assert!(SCENE_FEATURES.iter().all(|f| !f.reason.is_empty()));
        assert_eq!(scene_feature_reason("suns"), Some("the scene has a sun"));
        assert_eq!(scene_feature_reason("bloom"), None);
    }

    #[test]
    fn the_renderer_compiles_no_graph_with_a_name_it_does_not_hold() {
        let text = r#"Graph(
    resources: [Image(name: "ldr", format: R8G8B8A8_SRGB)],
    passes: [
        Pass(name: "volumes", kind: Raster, shaders: (vertex: "v.vert", fragment: "v.frag"),
             color: [(image: "ldr", load: Clear([0.0, 0.0, 0.0, 1.0]))],
             draw: LightVolumes(Sun)),
    ],
    output: "ldr",
)"#;
        let root = std::path::Path::new("/t/g.ron");
        let graph = weft_graph::load_with(root, &|_: &std::path::Path| Ok(text.to_string()));
        let prepared = weft_graph::Prepared::new(graph).expect("the graph alone is valid");
        let errors = crate::providers::compile(&prepared, &weft_graph::CompileOptions::default())
            .expect_err("refused");
        let messages: Vec<(&str, Option<&str>)> = errors
            .iter()
            .map(|d| (d.message.as_str(), d.hint.as_deref()))
            .collect();
        assert_eq!(
            messages,
            [(
                "unknown light kind `Sun`",
                Some("scenes offer: Point, Spot, Area")
            )]
        );
    }
}
