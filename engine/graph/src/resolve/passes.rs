//! Resolving pass declarations: accesses, shaders, dispatch and fixed-function state.

use super::{
    pass_path, IrAccess, IrDispatch, IrPass, IrResource, Resolver, Usage, INDIRECT_RECORD_BYTES,
    MAX_REPEAT, MAX_WORKGROUP_COUNT,
};
use crate::id::{IdVec, IrResourceId};
use crate::load::Located;
use crate::plan::ShaderFiles;
use crate::schema::{
    Dispatch, Draw, ParamValue, PassDecl, PassKind, ProviderDecl, RasterState, ReadDecl,
};
use crate::spans::Seg;
use std::collections::BTreeMap;

impl Resolver<'_> {
    /// `values` with `"$param"` references replaced by the declaring file's
    /// parameters; unknown references and non-finite numbers are errors at the
    /// value (`at` is the map's path; `keyed`: a map, else a struct's fields).
    pub(super) fn resolve_values(
        &mut self,
        source: usize,
        at: &[Seg],
        keyed: bool,
        values: &BTreeMap<String, ParamValue>,
    ) -> BTreeMap<String, ParamValue> {
        let mut resolved = BTreeMap::new();
        for (name, value) in values {
            let mut path = at.to_vec();
            path.push(if keyed {
                Seg::Key(name)
            } else {
                Seg::Field(name)
            });
            match crate::load::resolve_value(&self.graph.sources[source].params, value) {
                Ok(v) => {
                    if let Some(bad) = crate::load::non_finite(&v) {
                        self.error(source, &path, crate::load::not_f32(name, bad));
                    }
                    resolved.insert(name.clone(), v);
                }
                Err(missing) => {
                    let names: Vec<&str> = self.graph.sources[source]
                        .params
                        .keys()
                        .map(String::as_str)
                        .collect();
                    let hint = crate::diagnostic::nearest(&missing, names)
                        .map(|n| format!("did you mean \"${n}\"?"));
                    self.error(source, &path, format!("unknown parameter \"${missing}\""))
                        .hint = hint;
                }
            }
        }
        resolved
    }

    /// Every condition of the pass (its own, its reads', its defines') is
    /// well formed; a malformed one is reported at the pass's `enabled_if`
    /// when it is the pass's own, else at the pass.
    fn check_conditions(&mut self, pass: &IrPass) {
        let own = pass.enabled_if.iter().map(|c| (c, true));
        let others = pass
            .accesses
            .iter()
            .flat_map(|a| a.conditions.iter())
            .chain(pass.defines.iter().flat_map(|d| d.enabled_if.iter()))
            .map(|c| (c, false));
        let problems: Vec<(String, bool)> = own
            .chain(others)
            .filter_map(|(c, is_own)| crate::condition::malformed(c).map(|m| (m, is_own)))
            .collect();
        for (problem, is_own) in problems {
            let field = if is_own { "enabled_if" } else { "name" };
            self.error(
                pass.source,
                &pass_path(pass.index, &[Seg::Field(field)]),
                problem,
            );
        }
    }

    pub(super) fn resolve_pass(
        &mut self,
        p: &Located<PassDecl>,
        resources: &IdVec<IrResourceId, IrResource>,
    ) -> IrPass {
        let (source, index) = (p.source, p.index);
        let decl = &p.item;
        let mut accesses = self.resolve_attachments(p);
        let read_lists: [(&'static str, &Vec<ReadDecl>, Usage); 3] = [
            ("sampled", &decl.sampled, Usage::Sampled),
            ("storage_read", &decl.storage_read, Usage::StorageRead),
            ("storage_write", &decl.storage_write, Usage::StorageWrite),
        ];
        for (field, list, usage) in read_lists {
            for (i, read) in list.iter().enumerate() {
                let mut path = pass_path(index, &[Seg::Field(field), Seg::Index(i)]);
                if matches!(read, ReadDecl::Conditional(_)) {
                    path.push(Seg::Field("name"));
                }
                if let Some(r) = self.lookup(source, &path, read.name()) {
                    accesses.push(IrAccess {
                        resource: r,
                        usage: usage.clone(),
                        conditions: read.conditions().to_vec(),
                        field,
                        item: Some(i),
                    });
                }
            }
        }
        for (field, name, usage) in [
            ("src", &decl.src, Usage::TransferSrc),
            ("dst", &decl.dst, Usage::TransferDst),
        ] {
            if let Some(name) = name {
                let path = pass_path(index, &[Seg::Field(field)]);
                if let Some(r) = self.lookup(source, &path, name) {
                    accesses.push(IrAccess {
                        resource: r,
                        usage,
                        conditions: Vec::new(),
                        field,
                        item: None,
                    });
                }
            }
        }
        let mut after = Vec::new();
        for (i, name) in decl.after.iter().enumerate() {
            match self.pass_index.get(name.as_str()) {
                Some(&target) => after.push(target),
                // A fragment checked alone may order itself after its
                // includer's passes, as it may read its includer's resources.
                None if self.graph.is_fragment => {}
                None => {
                    let names: Vec<&str> = self
                        .graph
                        .passes
                        .iter()
                        .map(|p| p.item.name.as_str())
                        .collect();
                    let hint = crate::diagnostic::nearest(name, names)
                        .map(|n| format!("did you mean \"{n}\"?"));
                    self.error(
                        source,
                        &pass_path(index, &[Seg::Field("after"), Seg::Index(i)]),
                        format!("unknown pass \"{name}\""),
                    )
                    .hint = hint;
                }
            }
        }
        let params = self.resolve_values(
            source,
            &pass_path(index, &[Seg::Field("params")]),
            true,
            &decl.params,
        );
        let derive = decl
            .derive
            .iter()
            .enumerate()
            .map(|(k, call)| ProviderDecl {
                name: call.name.clone(),
                args: self.resolve_values(
                    source,
                    &pass_path(index, &[Seg::Field("derive"), Seg::Index(k)]),
                    false,
                    &call.args,
                ),
            })
            .collect();
        self.check_dispatch(source, index, decl.dispatch.as_ref());
        let dispatch = match &decl.dispatch {
            None => None,
            Some(Dispatch::Output(x, y)) => Some(IrDispatch::Output(*x, *y)),
            Some(Dispatch::Groups(x, y, z)) => Some(IrDispatch::Groups(*x, *y, *z)),
            Some(Dispatch::Image(name, x, y)) => self
                .lookup(source, &pass_path(index, &[Seg::Field("dispatch")]), name)
                .map(|r| IrDispatch::Image(r, *x, *y)),
            Some(Dispatch::Indirect(name, stride)) => self
                .lookup(source, &pass_path(index, &[Seg::Field("dispatch")]), name)
                .map(|r| {
                    // The dispatch itself reads the buffer, so it is ordered
                    // and synchronized after whatever wrote the counts.
                    accesses.push(IrAccess {
                        resource: r,
                        usage: Usage::IndirectRead,
                        conditions: Vec::new(),
                        field: "dispatch",
                        item: None,
                    });
                    IrDispatch::Indirect(r, *stride)
                }),
        };
        let repeat = match &decl.repeat {
            None => 1,
            Some(dim) => self.count(
                source,
                &pass_path(index, &[Seg::Field("repeat")]),
                dim,
                "repeat",
                MAX_REPEAT,
            ),
        };
        let dir = self.graph.sources[source]
            .file
            .parent()
            .map(|d| d.to_path_buf())
            .unwrap_or_default();
        let shaders = ShaderFiles {
            vertex: decl.shaders.vertex.as_ref().map(|s| dir.join(s)),
            fragment: decl.shaders.fragment.as_ref().map(|s| dir.join(s)),
            compute: decl.shaders.compute.as_ref().map(|s| dir.join(s)),
        };
        let pass = IrPass {
            name: decl.name.clone(),
            source,
            index,
            kind: decl.kind,
            shaders,
            draw: decl.draw.clone(),
            dispatch,
            repeat,
            params,
            derive,
            accesses,
            after,
            enabled_if: decl.enabled_if.clone(),
            raster: self.raster_state(source, index, decl),
            defines: self.check_defines(source, index, decl),
        };
        self.check_pass_shape(&pass, decl, resources);
        self.check_conditions(&pass);
        let bits = pass.variant_bits();
        if bits > super::ir::MAX_VARIANT_BITS {
            self.error(
                source,
                &pass_path(index, &[Seg::Field("name")]),
                format!(
                    "pass \"{}\" has shader defines decided by {bits} features: up to {} variants, more than the {} a pass may have",
                    pass.name,
                    super::ir::variant_count(bits),
                    super::ir::variant_count(super::ir::MAX_VARIANT_BITS)
                ),
            )
            .hint = Some("key defines that always go together to one feature, or split the pass".into());
        }
        pass
    }

    /// The pass's defines: those of the define sets it names, in order, then
    /// its own, each a preprocessor name the engine does not own. A set's
    /// `draws` holds only in a pass that draws meshes; a name given twice
    /// must mean the same define.
    fn check_defines(
        &mut self,
        source: usize,
        index: usize,
        decl: &PassDecl,
    ) -> Vec<crate::schema::DefineDecl> {
        let meshes = matches!(decl.draw, Some(Draw::Meshes(_)));
        let mut defines: Vec<crate::schema::DefineDecl> = Vec::new();
        for (k, set) in decl.define_sets.iter().enumerate() {
            let found = self
                .graph
                .define_sets
                .iter()
                .find(|(_, name, _)| name == set);
            match found {
                Some((_, _, list)) => {
                    for d in list {
                        let define = crate::schema::DefineDecl {
                            draws: d.draws.clone().filter(|_| meshes),
                            ..d.clone()
                        };
                        let name = define.name.clone();
                        if define.value.is_some() {
                            let path =
                                pass_path(index, &[Seg::Field("define_sets"), Seg::Index(k)]);
                            self.error(
                                source,
                                &path,
                                format!("define set \"{set}\" gives \"{name}\" a value; a define with a value belongs to the pass's own `defines`"),
                            );
                        }
                        if !add_define(&mut defines, define) {
                            let path =
                                pass_path(index, &[Seg::Field("define_sets"), Seg::Index(k)]);
                            self.error(
                                source,
                                &path,
                                format!("define set \"{set}\" gives \"{name}\" other conditions than an earlier set"),
                            );
                        }
                    }
                }
                None => {
                    let names: Vec<&str> = self
                        .graph
                        .define_sets
                        .iter()
                        .map(|(_, name, _)| name.as_str())
                        .collect();
                    let path = pass_path(index, &[Seg::Field("define_sets"), Seg::Index(k)]);
                    self.error(source, &path, format!("unknown define set \"{set}\""))
                        .hint = crate::diagnostic::nearest(set, names.iter().copied())
                        .map(|n| format!("did you mean \"{n}\"?"))
                        .or_else(|| {
                            Some(format!(
                                "this graph's define sets: {}",
                                if names.is_empty() {
                                    "none".into()
                                } else {
                                    names.join(", ")
                                }
                            ))
                        });
                }
            }
        }
        for (k, define) in decl.defines.iter().enumerate() {
            let name = &define.name;
            let path = pass_path(
                index,
                &[Seg::Field("defines"), Seg::Index(k), Seg::Field("name")],
            );
            if let Some((message, hint)) = define_name_problem(name) {
                self.error(source, &path, message).hint = hint;
            }
            if define.draws.is_some() && !meshes {
                let path = pass_path(
                    index,
                    &[Seg::Field("defines"), Seg::Index(k), Seg::Field("draws")],
                );
                self.error(
                    source,
                    &path,
                    format!(
                        "define \"{name}\": `draws` groups a pass's mesh draws by shading model, and pass `{}` draws no meshes",
                        decl.name
                    ),
                )
                .hint = Some("remove `draws`, or give the pass `draw: Meshes(...)`".into());
            }
            let define = crate::schema::DefineDecl {
                value: define
                    .value
                    .as_ref()
                    .and_then(|value| self.define_value(source, (index, k), name, value)),
                ..define.clone()
            };
            if !add_define(&mut defines, define) {
                self.error(
                    source,
                    &path,
                    format!("define \"{name}\" is also in one of the pass's define sets, under other conditions"),
                )
                .hint = Some("give it once: in the set, or in the pass".into());
            }
        }
        defines
    }

    /// A define's value as a whole number, its `$parameter` resolved; `None`
    /// after reporting one that is not a whole number or names no parameter.
    fn define_value(
        &mut self,
        source: usize,
        (index, k): (usize, usize),
        name: &str,
        value: &ParamValue,
    ) -> Option<ParamValue> {
        let path = pass_path(
            index,
            &[Seg::Field("defines"), Seg::Index(k), Seg::Field("value")],
        );
        match crate::load::resolve_value(&self.graph.sources[source].params, value) {
            Ok(ParamValue::Number(n))
                if n.fract() == 0.0 && (f64::from(i32::MIN)..=f64::from(i32::MAX)).contains(&n) =>
            {
                Some(ParamValue::Number(n))
            }
            Ok(other) => {
                self.error(
                    source,
                    &path,
                    format!(
                        "define \"{name}\": its value must be a whole number from {} to {} (a GLSL int), found {}",
                        i32::MIN,
                        i32::MAX,
                        crate::load::value_text(&other)
                    ),
                );
                None
            }
            Err(missing) => {
                self.error(
                    source,
                    &path,
                    format!("define \"{name}\": unknown parameter \"${missing}\""),
                );
                None
            }
        }
    }

    /// A pass's declared fixed-function state, with bias parameters resolved;
    /// only raster passes have it, and depth state needs a depth attachment.
    pub(super) fn raster_state(
        &mut self,
        source: usize,
        index: usize,
        decl: &PassDecl,
    ) -> RasterState {
        let Some(raster) = &decl.raster else {
            return RasterState::default();
        };
        let at = |field| pass_path(index, &[Seg::Field("raster"), Seg::Field(field)]);
        if decl.kind != PassKind::Raster {
            self.error(
                source,
                &pass_path(index, &[Seg::Field("raster")]),
                format!(
                    "a {:?} pass has no raster state (only Raster passes draw triangles with it)",
                    decl.kind
                ),
            );
        }
        let depth_field = if raster.depth_compare.is_some() {
            Some("depth_compare")
        } else if raster.depth_bias.is_some() {
            Some("depth_bias")
        } else if raster.depth_clamp == Some(true) {
            Some("depth_clamp")
        } else {
            None
        };
        if let (Some(field), None) = (depth_field, &decl.depth) {
            self.error(
                source,
                &at(field),
                format!("`{field}` needs a depth attachment, and the pass has none"),
            );
        }
        let depth_bias = raster.depth_bias.as_ref().map(|(c, s)| {
            let path = at("depth_bias");
            let constant = self.dim(source, &path, c, "a depth bias").unwrap_or(0.0);
            let slope = self.dim(source, &path, s, "a depth bias").unwrap_or(0.0);
            (constant, slope)
        });
        RasterState {
            depth_compare: raster.depth_compare,
            depth_bias,
            cull: raster.cull.unwrap_or_default(),
            depth_clamp: raster.depth_clamp.unwrap_or(false),
        }
    }

    /// Work-group sizes of at least 1; fixed group counts within the count
    /// every Vulkan device supports.
    pub(super) fn check_dispatch(
        &mut self,
        source: usize,
        index: usize,
        dispatch: Option<&Dispatch>,
    ) {
        let at = pass_path(index, &[Seg::Field("dispatch")]);
        let (values, what, max) = match dispatch {
            None => return,
            Some(Dispatch::Output(x, y) | Dispatch::Image(_, x, y)) => {
                (vec![*x, *y], "work-group sizes", u32::MAX)
            }
            Some(Dispatch::Groups(x, y, z)) => {
                (vec![*x, *y, *z], "group counts", MAX_WORKGROUP_COUNT)
            }
            Some(Dispatch::Indirect(_, stride)) => {
                if *stride < INDIRECT_RECORD_BYTES || stride % 4 != 0 {
                    self.error(
                        source,
                        &at,
                        format!(
                            "an indirect dispatch's stride must be a multiple of 4 of at least \
                             {INDIRECT_RECORD_BYTES} bytes (three u32 group counts), found {stride}"
                        ),
                    );
                }
                return;
            }
        };
        if let Some(bad) = values.iter().find(|v| !(1..=max).contains(*v)) {
            let range = if max == u32::MAX {
                "at least 1".to_string()
            } else {
                format!("from 1 to {max}")
            };
            self.error(source, &at, format!("{what} must be {range}, found {bad}"));
        }
    }
}

/// Adds `define` to `defines` unless the same define is there; false when a
/// define of its name is there under other conditions.
fn add_define(
    defines: &mut Vec<crate::schema::DefineDecl>,
    define: crate::schema::DefineDecl,
) -> bool {
    match defines.iter().find(|d| d.name == define.name) {
        Some(same) => *same == define,
        None => {
            defines.push(define);
            true
        }
    }
}

/// Why `name` cannot be a declared define, with a hint: not a preprocessor
/// name, or one of the engine's `HAS_` names.
pub(super) fn define_name_problem(name: &str) -> Option<(String, Option<String>)> {
    let valid = name.starts_with(|c: char| c.is_ascii_uppercase() || c == '_')
        && name
            .chars()
            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_');
    if !valid {
        Some((
            format!("define \"{name}\" is not a preprocessor name: use capitals, digits and underscores"),
            None,
        ))
    } else if name.starts_with("HAS_") {
        Some((
            format!(
                "define \"{name}\": names starting HAS_ are the engine's, for conditional reads"
            ),
            Some("choose another prefix, e.g. SCENE_".into()),
        ))
    } else {
        None
    }
}
