//! The scene vocabulary, as the graph sees it: the names a graph uses for
//! what scenes hold — the features the engine sets from a scene, the numbers
//! it measures of one (`scene_values`, for buffer sizes), the mesh filters of
//! `draw: Meshes(..)`, the light kinds of `draw: LightVolumes(..)` and the
//! shading models of a define's `draws:`. This crate knows none of
//! them: the renderer hands its [`SceneVocabulary`] in, as it hands its
//! providers, and [`check_vocabulary`] holds a graph to it with located
//! errors and the nearest name as a hint.

use crate::diagnostic::{nearest, Diagnostic};
use crate::load::LoadedGraph;
use crate::resolve::{feature_names, resolve, Ir};
use crate::schema::{Draw, SceneTerm};
use crate::spans::Seg;
use std::collections::BTreeSet;

/// The names scenes give graphs, as the renderer registers them.
#[derive(Debug, Clone, Copy)]
pub struct SceneVocabulary {
    /// Features the engine sets from what a scene holds: a graph may test
    /// them in a caveat or the camera jitter without a pass of its own
    /// doing so.
    pub features: &'static [SceneFeature],
    /// Numbers the renderer measures of each scene, which a graph declares
    /// in `scene_values` to size buffers by.
    pub values: &'static [SceneValue],
    /// What `draw: Meshes(..)` may select.
    pub mesh_filters: &'static [&'static str],
    /// The lights `draw: LightVolumes(..)` may draw volumes of.
    pub light_volumes: &'static [&'static str],
    /// The shading models a define's `draws:` may name.
    pub shading_models: &'static [&'static str],
}

/// A feature the engine sets from a scene, and when.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneFeature {
    /// The name conditions test (`"suns"`).
    pub name: &'static str,
    /// When a scene sets it, for panels and messages ("the scene has a sun").
    pub reason: &'static str,
}

/// A number the renderer measures of each scene, and what it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneValue {
    /// The name size expressions use (`"structure_scratch_bytes"`).
    pub name: &'static str,
    /// What it measures, for messages and docs.
    pub meaning: &'static str,
}

/// Every use of a scene name the vocabulary does not hold: a scene value, a
/// mesh filter, a light kind, a shading model, and (outside fragments, whose features may
/// be their includer's) a caveat's or the jitter's feature that neither the
/// graph nor scenes set.
pub fn check_vocabulary(graph: &LoadedGraph, vocabulary: &SceneVocabulary) -> Vec<Diagnostic> {
    let (ir, _) = resolve(graph);
    check_vocabulary_resolved(graph, &ir, vocabulary)
}

/// [`check_vocabulary`] of a graph already resolved (a [`crate::Prepared`]'s
/// `ir`), as the renderer checks each graph it compiles.
pub fn check_vocabulary_resolved(
    graph: &LoadedGraph,
    ir: &Ir,
    vocabulary: &SceneVocabulary,
) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    for pass in &graph.passes {
        let mut term = |path: &[Seg], used: &SceneTerm, what: &str, known: &[&str]| {
            if known.contains(&used.0.as_str()) {
                return;
            }
            let mut at = vec![Seg::Field("passes"), Seg::Index(pass.index)];
            at.extend_from_slice(path);
            let (file, pos) = graph.locate(pass.source, &at);
            diags.push(unknown(file, pos, &used.0, what, known));
        };
        match &pass.item.draw {
            Some(Draw::Meshes(filter)) => term(
                &[Seg::Field("draw")],
                filter,
                "mesh filter",
                vocabulary.mesh_filters,
            ),
            Some(Draw::LightVolumes(kind)) => term(
                &[Seg::Field("draw")],
                kind,
                "light kind",
                vocabulary.light_volumes,
            ),
            _ => {}
        }
        for (k, define) in pass.item.defines.iter().enumerate() {
            if let Some(model) = &define.draws {
                let path = [Seg::Field("defines"), Seg::Index(k), Seg::Field("draws")];
                term(&path, model, "shading model", vocabulary.shading_models);
            }
        }
    }
    for (source, name, defines) in &graph.define_sets {
        for (k, define) in defines.iter().enumerate() {
            let Some(model) = &define.draws else { continue };
            if !vocabulary.shading_models.contains(&model.0.as_str()) {
                let path = [
                    Seg::Field("define_sets"),
                    Seg::Key(name),
                    Seg::Index(k),
                    Seg::Field("draws"),
                ];
                let (file, pos) = graph.locate(*source, &path);
                let known = vocabulary.shading_models;
                diags.push(unknown(file, pos, &model.0, "shading model", known));
            }
        }
    }
    let values: Vec<&str> = vocabulary.values.iter().map(|v| v.name).collect();
    for (k, (source, name)) in graph.scene_values.iter().enumerate() {
        if !values.contains(&name.as_str()) {
            let index = graph.scene_values[..k]
                .iter()
                .filter(|(s, _)| s == source)
                .count();
            let path = [Seg::Field("scene_values"), Seg::Index(index)];
            let (file, pos) = graph.locate(*source, &path);
            let mut d = unknown(file, pos, name, "scene value", &values);
            if nearest(name, values.iter().copied()).is_none() {
                let offered: Vec<String> = vocabulary
                    .values
                    .iter()
                    .map(|v| format!("{} ({})", v.name, v.meaning))
                    .collect();
                d.hint = Some(format!("scenes offer: {}", offered.join("; ")));
            }
            diags.push(d);
        }
    }
    if !graph.is_fragment {
        diags.extend(unknown_features(graph, ir, vocabulary));
    }
    diags
}

/// An error for `used`, a name of `what` outside `known`.
fn unknown(
    file: std::path::PathBuf,
    pos: weft_diagnostic::Pos,
    used: &str,
    what: &str,
    known: &[&str],
) -> Diagnostic {
    let d = Diagnostic::error(file, pos, format!("unknown {what} `{used}`"));
    match nearest(used, known.iter().copied()) {
        Some(n) => d.with_hint(format!("did you mean `{n}`?")),
        None => d.with_hint(format!("scenes offer: {}", known.join(", "))),
    }
}

/// Caveat and jitter conditions that name a feature neither the graph (its
/// passes' conditions, its defaults) nor scenes set: a misspelt one would
/// never show its caveat or never jitter.
fn unknown_features(graph: &LoadedGraph, ir: &Ir, vocabulary: &SceneVocabulary) -> Vec<Diagnostic> {
    let mut known: BTreeSet<String> = feature_names(ir);
    known.extend(graph.default_features.iter().cloned());
    known.extend(vocabulary.features.iter().map(|f| f.name.to_string()));
    let caveats = graph
        .caveats
        .iter()
        .map(|(source, c)| (*source, "caveats", "caveat", &c.enabled_if));
    let jitter = graph
        .jitter
        .iter()
        .map(|(source, j)| (*source, "jitter", "jitter", &j.enabled_if));
    let mut seen: Vec<(usize, &str)> = Vec::new();
    let mut diags = Vec::new();
    for (source, field, what, conditions) in caveats.chain(jitter) {
        let index = seen.iter().filter(|s| **s == (source, field)).count();
        seen.push((source, field));
        let path = [
            Seg::Field(field),
            Seg::Index(index),
            Seg::Field("enabled_if"),
        ];
        for condition in conditions {
            let names = crate::condition::names(condition);
            for feature in names.into_iter().filter(|f| !f.is_empty()) {
                if known.contains(feature) {
                    continue;
                }
                let (file, pos) = graph.locate(source, &path);
                let d = Diagnostic::error(
                    file,
                    pos,
                    format!("{what} condition \"{condition}\" names a feature neither this graph nor scenes set"),
                );
                diags.push(match nearest(feature, known.iter().map(String::as_str)) {
                    Some(n) => d.with_hint(format!("did you mean \"{n}\"?")),
                    None => d,
                });
            }
        }
    }
    diags
}
