//! What the executor can record, checked when a plan is compiled rather than
//! met at render: a `Copy` between images copies texel for texel, so both
//! must be one size at the output size compiled for (a `Blit` scales); a
//! copy or blit joins two images or two buffers, never one of each; an
//! indirect dispatch's buffer holds every record its repeats read. `weft
//! graph check` compiles at two output sizes, so a size rule that agrees at
//! one only (an `Absolute` size beside an output-relative one) is refused
//! before a render meets it.

use crate::diagnostic::Diagnostic;
use crate::id::{IdVec, PassId, ResourceId};
use crate::plan::{Extent, PlanPass, PlanResource, ResourceDesc};
use crate::resolve::INDIRECT_RECORD_BYTES;
use crate::schema::PassKind;

/// An error for each pass among `passes` the executor could not record.
pub(super) fn check(
    passes: &IdVec<PassId, PlanPass>,
    resources: &IdVec<ResourceId, PlanResource>,
    output: Extent,
) -> Result<(), Vec<Diagnostic>> {
    let errors: Vec<Diagnostic> = passes
        .iter()
        .filter_map(|pass| {
            refusal(pass, resources, output).map(|message| {
                Diagnostic::error(pass.declared_at.file.clone(), pass.declared_at.pos, message)
            })
        })
        .collect();
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors)
    }
}

/// Why `pass` cannot be recorded, if it cannot.
fn refusal(
    pass: &PlanPass,
    resources: &IdVec<ResourceId, PlanResource>,
    output: Extent,
) -> Option<String> {
    if let Some(indirect) = pass.indirect {
        let ResourceDesc::Buffer(buffer) = &resources[indirect.buffer].desc else {
            return None;
        };
        let end = u64::from(pass.repeat.max(1) - 1) * u64::from(indirect.stride)
            + u64::from(INDIRECT_RECORD_BYTES);
        return (end > buffer.size).then(|| {
            format!(
                "pass \"{}\": its {} indirect dispatch(es) read up to byte {end} of `{}`, which has {} bytes",
                pass.name,
                pass.repeat.max(1),
                resources[indirect.buffer].name,
                buffer.size
            )
        });
    }
    let (src, dst) = pass.transfer?;
    let (s, d) = (&resources[src], &resources[dst]);
    match (&s.desc, &d.desc) {
        (ResourceDesc::Image(si), ResourceDesc::Image(di))
            if pass.kind == PassKind::Copy && si.extent != di.extent =>
        {
            Some(format!(
                "copy pass \"{}\": `{}` is {}x{} and `{}` {}x{} at output size {}x{}; a copy needs equal sizes (a Blit scales)",
                pass.name,
                s.name,
                si.extent.width,
                si.extent.height,
                d.name,
                di.extent.width,
                di.extent.height,
                output.width,
                output.height
            ))
        }
        (ResourceDesc::Image(_), ResourceDesc::Image(_))
        | (ResourceDesc::Buffer(_), ResourceDesc::Buffer(_)) => None,
        _ => Some(format!(
            "pass \"{}\" copies between `{}` and `{}`, an image and a buffer; a copy joins two images or two buffers",
            pass.name, s.name, d.name
        )),
    }
}

#[cfg(test)]
mod tests {
    use crate::compile::fixture::resolved;
    use crate::compile::{compile_ir, CompileOptions};
    use crate::plan::Extent;

    /// Compiles `text` at `extent`, reading `kept` back when the graph has it.
    fn compiled(text: &str, extent: Extent) -> Result<crate::plan::Plan, Vec<crate::Diagnostic>> {
        let (graph, ir) = resolved(text);
        let options = CompileOptions {
            extent,
            readback: if text.contains("\"kept\"") {
                vec!["kept".into()]
            } else {
                Vec::new()
            },
            readback_asked: true,
            ..CompileOptions::default()
        };
        compile_ir(&graph, &ir, &options)
    }

    /// The message of the one error compiling `text` at `extent` gives.
    fn refused(text: &str, extent: Extent) -> String {
        let errors = compiled(text, extent).expect_err("refused");
        assert_eq!(errors.len(), 1, "{errors:#?}");
        errors[0].message.clone()
    }

    const HD: Extent = Extent {
        width: 1280,
        height: 720,
    };

    /// `out` drawn, then copied into `kept`, declared `kept`.
    fn copy_into(kept: &str) -> String {
        format!(
            r#"Graph(
            output: "out",
            resources: [
                Image(name: "out", format: R8G8B8A8_UNORM),
                {kept}
            ],
            passes: [
                Pass(name: "draw", kind: Fullscreen, shaders: (fragment: "a.frag"), color: [(image: "out")]),
                Pass(name: "keep", kind: Copy, src: "out", dst: "kept"),
            ],
        )"#
        )
    }

    #[test]
    fn copies_need_equal_sizes_and_one_kind_of_resource() {
        assert_eq!(
            refused(
                &copy_into(r#"Image(name: "kept", format: R8G8B8A8_UNORM, size: Absolute(64, 64)),"#),
                HD
            ),
            "copy pass \"keep\": `out` is 1280x720 and `kept` 64x64 at output size 1280x720; a copy needs equal sizes (a Blit scales)"
        );
        // Equal at one output size only: refused at another.
        let same_at_hd =
            copy_into(r#"Image(name: "kept", format: R8G8B8A8_UNORM, size: Absolute(1280, 720)),"#);
        assert!(compiled(&same_at_hd, HD).is_ok());
        let odd = Extent {
            width: 997,
            height: 541,
        };
        assert!(refused(&same_at_hd, odd)
            .starts_with("copy pass \"keep\": `out` is 997x541 and `kept` 1280x720"));
        let into_buffer = r#"Graph(
            output: "out",
            resources: [
                Image(name: "drawn", format: R8G8B8A8_UNORM),
                Buffer(name: "bytes", size: "64"),
                Image(name: "out", format: R8G8B8A8_UNORM),
            ],
            passes: [
                Pass(name: "draw", kind: Fullscreen, shaders: (fragment: "a.frag"), color: [(image: "drawn")]),
                Pass(name: "keep", kind: Copy, src: "drawn", dst: "bytes"),
                Pass(name: "use", kind: Compute, shaders: (compute: "u.comp"),
                     storage_read: ["bytes"], storage_write: ["out"], dispatch: Output(8, 8)),
            ],
        )"#;
        assert_eq!(
            refused(into_buffer, HD),
            "pass \"keep\" copies between `drawn` and `bytes`, an image and a buffer; a copy joins two images or two buffers"
        );
    }

    #[test]
    fn an_indirect_dispatch_reads_within_its_buffer() {
        let text = |size: u32| {
            format!(
                r#"Graph(
                output: "out",
                resources: [
                    Image(name: "out", format: R8G8B8A8_UNORM),
                    Buffer(name: "counts", size: "{size}"),
                ],
                passes: [
                    Pass(name: "count", kind: Compute, shaders: (compute: "c.comp"),
                         storage_write: ["counts"], dispatch: Groups(1, 1, 1)),
                    Pass(name: "work", kind: Compute, shaders: (compute: "w.comp"),
                         storage_read: ["counts"], storage_write: ["out"],
                         dispatch: Indirect("counts", 16), repeat: 4),
                ],
            )"#
            )
        };
        // Four records 16 bytes apart: the last ends at byte 3 * 16 + 12.
        assert_eq!(
            refused(&text(48), HD),
            "pass \"work\": its 4 indirect dispatch(es) read up to byte 60 of `counts`, which has 48 bytes"
        );
        assert!(compiled(&text(60), HD).is_ok());
    }
}
