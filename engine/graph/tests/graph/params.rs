//! Graph parameters as a user sets them: top-level names, fragments'
//! parameters by their qualified names, a graph built on another passing
//! its own on, and every value held to its declared type and range.

use crate::support::repo_root;
use weft_graph::CompileOptions;

#[test]
fn top_level_parameters_can_be_set_when_loading() {
    use std::collections::BTreeMap;
    use weft_graph::schema::ParamValue;
    let path = repo_root().join("graphs/forward.ron");
    let set =
        |name: &str, value: f64| BTreeMap::from([(name.to_string(), ParamValue::Number(value))]);
    let graph = weft_graph::load_with_params(&path, set("exposure", 2.5));
    let options = CompileOptions {
        features: graph.features::<&str>(&[]),
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&graph, &options).expect("compiles");
    let tonemap = plan
        .passes
        .iter()
        .find(|p| p.name == "tonemap")
        .expect("tonemap pass");
    assert_eq!(tonemap.params["exposure"], ParamValue::Number(2.5));

    let misspelt = weft_graph::load_with_params(&path, set("exposur", 2.5));
    let errors: Vec<_> = misspelt
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .collect();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(
        errors[0].message,
        "unknown parameter \"exposur\" for \"forward.ron\""
    );
    assert_eq!(
        errors[0].hint.as_deref(),
        Some("did you mean \"exposure\"?")
    );
    assert!(errors[0].file.ends_with("forward.ron"));
}

/// `fragment.name` reaches a parameter of the include whose file stem is
/// `fragment` (`--param shadows.pcf_radius=3`); a qualifier naming no
/// include, or a name the fragment lacks, is an error with the nearest name.
#[test]
fn fragment_parameters_are_set_by_qualified_names() {
    use std::collections::BTreeMap;
    use weft_graph::schema::ParamValue;
    let path = repo_root().join("graphs/forward.ron");
    let set =
        |name: &str, value: f64| BTreeMap::from([(name.to_string(), ParamValue::Number(value))]);
    let graph = weft_graph::load_with_params(&path, set("bloom.threshold", 4.0));
    assert!(
        graph.diagnostics.iter().all(|d| !d.is_error()),
        "{:?}",
        graph.diagnostics
    );
    let options = CompileOptions {
        features: graph.features(&["bloom"]),
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&graph, &options).expect("compiles");
    let bright = plan
        .passes
        .iter()
        .find(|p| p.name == "bloom_bright")
        .expect("bloom_bright pass");
    assert_eq!(bright.params["threshold"], ParamValue::Number(4.0));

    let errors = |name: &str| {
        weft_graph::load_with_params(&path, set(name, 1.0))
            .diagnostics
            .into_iter()
            .filter(|d| d.is_error())
            .map(|d| (d.message, d.hint))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        errors("blom.threshold"),
        [(
            "parameter \"blom.threshold\": \"forward.ron\" includes no fragment \"blom\""
                .to_string(),
            Some("did you mean \"bloom\"?".to_string())
        )]
    );
    assert_eq!(
        errors("shadows.pcf_radus"),
        [(
            "unknown parameter \"pcf_radus\" for \"shadows.ron\"".to_string(),
            Some("did you mean \"pcf_radius\"?".to_string())
        )]
    );
}

/// A graph built on a whole graph (hybrid.ron on deferred.ron) passes on
/// what it does not take itself: the built-on graph's parameters by name
/// (`exposure`), its fragments' as `fragment.name` (`gi.rays`), and
/// `settable` lists them so; a name or qualifier neither graph knows is an
/// error at the built-on graph, with the nearest name.
#[test]
fn a_graph_built_on_another_passes_its_parameters_on() {
    use std::collections::BTreeMap;
    use weft_graph::schema::ParamValue;
    let path = repo_root().join("graphs/hybrid.ron");
    let set = |pairs: &[(&str, f64)]| {
        pairs
            .iter()
            .map(|(n, v)| (n.to_string(), ParamValue::Number(*v)))
            .collect::<BTreeMap<_, _>>()
    };
    let graph = weft_graph::load_with_params(&path, set(&[("gi.rays", 4.0), ("exposure", 2.0)]));
    assert!(
        graph.diagnostics.iter().all(|d| !d.is_error()),
        "{:?}",
        graph.diagnostics
    );
    let settable = graph.settable_params();
    for name in [
        "exposure",
        "gi.rays",
        "rt_specular.max_depth",
        "shadows.resolution",
    ] {
        assert!(settable.contains(name), "{name} in {settable:?}");
    }
    let options = CompileOptions {
        features: graph.features(&["!denoise"]),
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&graph, &options).expect("compiles");
    let param = |pass: &str, name: &str| {
        plan.passes
            .iter()
            .find(|p| p.name == pass)
            .unwrap_or_else(|| panic!("pass {pass}"))
            .params[name]
            .clone()
    };
    assert_eq!(param("gi", "rays"), ParamValue::Number(4.0));
    assert_eq!(param("tonemap", "exposure"), ParamValue::Number(2.0));

    let errors = |name: &str| {
        weft_graph::load_with_params(&path, set(&[(name, 1.0)]))
            .diagnostics
            .into_iter()
            .filter(|d| d.is_error())
            .map(|d| (d.file.file_name().map(|f| f.to_owned()), d.message, d.hint))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        errors("exposur"),
        [(
            Some("deferred.ron".into()),
            "unknown parameter \"exposur\" for \"deferred.ron\"".to_string(),
            Some("did you mean \"exposure\"?".to_string())
        )]
    );
    assert_eq!(
        errors("gii.rays"),
        [(
            Some("deferred.ron".into()),
            "parameter \"gii.rays\": \"deferred.ron\" includes no fragment \"gii\"".to_string(),
            Some("did you mean \"gi\"?".to_string())
        )]
    );
}

#[test]
fn parameter_values_are_held_to_their_declared_type_and_range() {
    use std::collections::BTreeMap;
    use weft_graph::schema::ParamValue;
    let dir = std::env::temp_dir().join(format!("weft-param-ranges-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(
        dir.join("frag.ron"),
        "Graph(\n    fragment: true,\n    params: { \"radius\": 2 },\n    param_ranges: { \"radius\": (integer: true, min: 0, max: 7) },\n)\n",
    )
    .expect("write");
    let root = dir.join("g.ron");
    std::fs::write(
        &root,
        "Graph(\n    include: [(file: \"frag.ron\", params: { \"radius\": 9 })],\n    params: {\n        \"depth\": 8,\n        \"mode\": 0,\n        \"gain\": 1.0,\n    },\n    param_ranges: {\n        \"depth\": (integer: true, min: 1),\n        \"mode\": (one_of: [0, 1, 2]),\n        \"missing\": (min: 0),\n    },\n    output: \"x\",\n)\n",
    )
    .expect("write");
    let errors = |overrides: BTreeMap<String, ParamValue>| -> Vec<String> {
        weft_graph::load_with_params(&root, overrides)
            .diagnostics
            .iter()
            .filter(|d| d.is_error())
            .map(|d| {
                format!(
                    "{}:{}: {}",
                    d.file.file_name().unwrap().to_string_lossy(),
                    d.pos.line,
                    d.message
                )
            })
            .collect()
    };
    let base = errors(BTreeMap::new());
    assert_eq!(
        base,
        [
            "g.ron:11: `param_ranges` names \"missing\", which `params` does not declare",
            "g.ron:2: parameter \"radius\" set to 9: it must be at most 7",
        ]
    );
    let set = |name: &str, value: ParamValue| BTreeMap::from([(name.to_string(), value)]);
    for (name, value, expected) in [
        (
            "depth",
            ParamValue::Number(-1.0),
            "g.ron:4: parameter \"depth\" set to -1: it must be at least 1",
        ),
        (
            "depth",
            ParamValue::Number(2.5),
            "g.ron:4: parameter \"depth\" set to 2.5: it must be a whole number",
        ),
        (
            "mode",
            ParamValue::Number(99.0),
            "g.ron:5: parameter \"mode\" set to 99: it must be one of 0, 1, 2",
        ),
        (
            "gain",
            ParamValue::Bool(true),
            "g.ron:6: parameter \"gain\" set to true: it must be a number, like its default",
        ),
    ] {
        let found = errors(set(name, value));
        assert!(
            found.iter().any(|e| e == expected),
            "{expected}\n{found:#?}"
        );
        assert_eq!(found.len(), base.len() + 1, "{found:#?}");
    }
    assert_eq!(
        errors(set("mode", ParamValue::Number(2.0))),
        base,
        "in range"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}
