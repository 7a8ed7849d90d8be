//! Rules for the scene's acceleration structures: a
//! `BuildAccelerationStructures` pass writes one, in one buffer of
//! scratch, and does nothing else, and other passes only read one, through
//! ray queries (`storage_read`).

use super::{
    pass_path, resource_path, rules::access_path, Ir, IrKind, IrPass, IrResource, Resolver, Usage,
};
use crate::id::{IdVec, IrResourceId};
use crate::schema::{PassDecl, PassKind};
use crate::spans::Seg;

impl Resolver<'_> {
    /// A build pass declares one acceleration structure in `storage_write`,
    /// with one buffer for its scratch, and nothing the executor
    /// would ignore: no shaders, attachments, other reads or writes, copy
    /// endpoints, draws or dispatches.
    pub(super) fn check_build_pass(
        &mut self,
        pass: &IrPass,
        decl: &PassDecl,
        resources: &IdVec<IrResourceId, IrResource>,
    ) {
        let (source, index) = (pass.source, pass.index);
        let name = &pass.name;
        let declared: [(&'static str, bool); 9] = [
            ("shaders", decl.shaders != Default::default()),
            ("color", !decl.color.is_empty()),
            ("depth", decl.depth.is_some()),
            ("sampled", !decl.sampled.is_empty()),
            ("storage_read", !decl.storage_read.is_empty()),
            ("src", decl.src.is_some() || decl.dst.is_some()),
            ("draw", decl.draw.is_some()),
            ("dispatch", decl.dispatch.is_some()),
            ("repeat", decl.repeat.is_some()),
        ];
        for (field, present) in declared {
            if present {
                self.error(
                    source,
                    &pass_path(index, &[Seg::Field(field)]),
                    format!(
                        "BuildAccelerationStructures pass \"{name}\" takes no `{field}`: it builds \
                         the acceleration structure it names in `storage_write`, and nothing else"
                    ),
                );
            }
        }
        let written: Vec<Option<&IrKind>> = pass
            .accesses
            .iter()
            .filter(|a| a.usage == Usage::StorageWrite)
            .map(|a| resources.get(a.resource).map(|r| &r.kind))
            .collect();
        let count = |f: fn(&IrKind) -> bool| written.iter().flatten().filter(|k| f(k)).count();
        let structures = count(|k| matches!(k, IrKind::AccelerationStructure));
        let buffers = count(|k| matches!(k, IrKind::Buffer { .. }));
        if structures + buffers < written.iter().flatten().count() || buffers != 1 {
            self.error(
                source,
                &pass_path(index, &[Seg::Field("storage_write")]),
                format!(
                    "BuildAccelerationStructures pass \"{name}\" writes its acceleration \
                     structure and one `Buffer`, the scratch it builds in"
                ),
            )
            .hint = Some(
                "size the scratch by the scene value the renderer measures for builds, as \
                 graphs/acceleration.ron does"
                    .into(),
            );
        }
        if pass
            .accesses
            .iter()
            .any(|a| a.usage == Usage::StorageWrite && !a.conditions.is_empty())
        {
            self.error(
                source,
                &pass_path(index, &[Seg::Field("storage_write")]),
                format!(
                    "BuildAccelerationStructures pass \"{name}\" writes its structure and scratch \
                     whenever it runs: its writes take no `enabled_if`"
                ),
            )
            .hint = Some("give the pass `enabled_if` instead".into());
        }
        if structures != 1 {
            self.error(
                source,
                &pass_path(index, &[Seg::Field("storage_write")]),
                format!(
                    "BuildAccelerationStructures pass \"{name}\" needs exactly one \
                     `AccelerationStructure` resource in `storage_write`"
                ),
            )
            .hint = Some(
                "declare `AccelerationStructure(name: \"scene_structures\")` in `resources` and \
                 write it here"
                    .into(),
            );
        }
    }

    /// The scene has one set of structures, built once a frame: a graph
    /// declares at most one `AccelerationStructure` and one build pass.
    fn check_one_structure(&mut self, ir: &Ir) {
        let declared: Vec<&IrResource> = ir
            .resources
            .iter()
            .filter(|r| matches!(r.kind, IrKind::AccelerationStructure))
            .collect();
        if let [first, second, ..] = declared[..] {
            self.error(
                second.source,
                &resource_path(second.index, &[Seg::Field("name")]),
                format!(
                    "acceleration structures \"{}\" and \"{}\": the scene has one, which one \
                     BuildAccelerationStructures pass builds",
                    first.name, second.name
                ),
            );
        }
        let builds: Vec<&IrPass> = ir
            .passes
            .iter()
            .filter(|p| p.kind == PassKind::BuildAccelerationStructures)
            .collect();
        if let [first, second, ..] = builds[..] {
            self.error(
                second.source,
                &pass_path(second.index, &[Seg::Field("kind")]),
                format!(
                    "passes \"{}\" and \"{}\" both build acceleration structures: the scene's are \
                     built once a frame, by one pass",
                    first.name, second.name
                ),
            );
        }
    }

    /// Every use of an acceleration structure is a build pass's write or a
    /// ray-query read (`storage_read`) in a pass that runs shaders, and
    /// there is one structure, built by one pass.
    pub(super) fn check_structure_uses(&mut self, ir: &Ir) {
        self.check_one_structure(ir);
        for pass in &ir.passes {
            for access in &pass.accesses {
                let resource = &ir.resources[access.resource];
                if !matches!(resource.kind, IrKind::AccelerationStructure) {
                    continue;
                }
                let build = pass.kind == PassKind::BuildAccelerationStructures;
                let fine = match access.usage {
                    Usage::StorageWrite => build,
                    Usage::StorageRead => matches!(
                        pass.kind,
                        PassKind::Compute | PassKind::Raster | PassKind::Fullscreen
                    ),
                    _ => false,
                };
                if !fine {
                    self.error(
                        pass.source,
                        &access_path(pass.index, access),
                        format!(
                            "pass \"{}\" uses acceleration structure \"{}\" as {}: shaders read \
                             one through ray queries (`storage_read`), and only a \
                             BuildAccelerationStructures pass writes one",
                            pass.name,
                            resource.name,
                            super::rules::usage_name(&access.usage)
                        ),
                    );
                }
            }
        }
    }
}
