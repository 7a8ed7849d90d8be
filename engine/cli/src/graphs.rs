//! The graphs a command renders, each loaded and resolved once and then kept:
//! the typed feature toggles are checked against the loaded graph, and the
//! same value is compiled for every scene, size and feature set.

use anyhow::{bail, Result};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use weft_graph::schema::ParamValue;
use weft_graph::Prepared;
use weft_render::RenderSettings;

/// Refuses feature toggles typed on the command line that `graph` does not
/// know (a typo would otherwise be ignored silently).
pub fn check_features(graph: &Prepared, toggles: &[String]) -> Result<()> {
    match graph.unknown_features(toggles).as_slice() {
        [] => Ok(()),
        unknown => bail!("--features: {}", unknown.join("\n")),
    }
}

/// The graph `settings` names, loaded once (an error lists every problem at
/// its file and line), with `settings.features` checked against it.
pub fn load_checked(settings: &RenderSettings) -> Result<Prepared> {
    let graph = weft_render::load_graph(settings)?;
    check_features(&graph, &settings.features)?;
    Ok(graph)
}

/// Graphs loaded by file and parameters, for commands that render several
/// configurations of the same files (compare, sweep).
#[derive(Default)]
pub struct Loaded {
    graphs: BTreeMap<(PathBuf, String), Arc<Prepared>>,
}

impl Loaded {
    /// The graph `settings` names with its parameters, loaded on first use.
    pub fn get(&mut self, settings: &RenderSettings) -> Result<Arc<Prepared>> {
        let key = (settings.graph.clone(), params_key(&settings.params));
        if let Some(graph) = self.graphs.get(&key) {
            check_features(graph, &settings.features)?;
            return Ok(Arc::clone(graph));
        }
        let graph = Arc::new(load_checked(settings)?);
        self.graphs.insert(key, Arc::clone(&graph));
        Ok(graph)
    }
}

/// Parameters as one comparable text (values have no total order).
fn params_key(params: &BTreeMap<String, ParamValue>) -> String {
    format!("{params:?}")
}

/// A graph path as the command line gives it, found on weft's search path
/// (`$WEFT_HOME`, the install's share folder, the current folder:
/// [`weft_io::home`]); a path found nowhere stays as given, and loading it
/// says where it was looked for.
pub(crate) fn graph_path(text: &str) -> Result<PathBuf, String> {
    let given = PathBuf::from(text);
    Ok(weft_io::home::locate(&given).unwrap_or(given))
}
