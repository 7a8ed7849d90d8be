//! The human-readable plan printed by `weft graph plan`: pass order, culled passes,
//! barriers and render-pass ops, and memory. Snapshot tests diff this text, so any
//! change in synchronization shows in review.

use crate::plan::{Barrier, Plan, Residency, ResourceDesc};
use crate::vk::flag_names;
use std::fmt::Write;

fn mib(bytes: u64) -> String {
    format!("{:.2} MiB", bytes as f64 / (1024.0 * 1024.0))
}

fn barrier_line(plan: &Plan, b: &Barrier) -> String {
    let name = &plan.resources[b.resource].name;
    let layouts = match b.layouts {
        Some((old, new)) if old != new => format!(" {} -> {}", old.vk_name(), new.vk_name()),
        Some((same, _)) => format!(" {} (no transition)", same.vk_name()),
        None => String::new(),
    };
    format!(
        "{name}: {}/{} -> {}/{}{layouts}",
        flag_names(b.src_stage),
        flag_names(b.src_access),
        flag_names(b.dst_stage),
        flag_names(b.dst_access)
    )
}

/// Renders a plan as indented text.
pub fn render(plan: &Plan) -> String {
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(
        w,
        "plan \"{}\" at {}x{}, features [{}]",
        plan.name,
        plan.extent.width,
        plan.extent.height,
        plan.features.join(", ")
    );
    if !plan.scene_values.is_empty() {
        let values: Vec<String> = plan
            .scene_values
            .iter()
            .map(|(name, value)| format!("{name} = {value}"))
            .collect();
        let _ = writeln!(
            w,
            "scene values (0 where not measured): {}",
            values.join(", ")
        );
    }
    if plan.camera_jitter {
        let _ = writeln!(
            w,
            "camera jittered each frame by a sub-pixel Halton (2, 3) offset"
        );
    }
    let _ = writeln!(w, "\nresources:");
    for r in &plan.resources {
        let what = match &r.desc {
            ResourceDesc::Image(i) => format!(
                "image {} {}x{}{}{}{} usage {}",
                i.format,
                i.extent.width,
                i.extent.height,
                if i.mips > 1 {
                    format!(" mips {}", i.mips)
                } else {
                    String::new()
                },
                if i.layers > 1 {
                    format!(" layers {}", i.layers)
                } else {
                    String::new()
                },
                if i.samples > 1 {
                    format!(" x{} samples", i.samples)
                } else {
                    String::new()
                },
                flag_names(i.usage)
            ),
            ResourceDesc::Buffer(b) => {
                format!("buffer {} bytes usage {}", b.size, flag_names(b.usage))
            }
            ResourceDesc::AccelerationStructure => {
                "acceleration structures (the scene's memory)".to_string()
            }
        };
        let residency = match r.residency {
            Residency::Transient => match r.placement {
                Some(p) => format!("transient @{}+{}", p.offset, p.size),
                None => "transient".to_string(),
            },
            Residency::History => "history".to_string(),
            Residency::Output => "output".to_string(),
        };
        let _ = writeln!(
            w,
            "  {}: {what}; {residency}; passes {}..{}",
            r.name, r.lifetime.0, r.lifetime.1
        );
    }
    let _ = writeln!(w, "\npasses:");
    for (i, p) in plan.passes.iter().enumerate() {
        let _ = writeln!(w, "  {i}. {} ({:?})", p.name, p.kind);
        for b in &p.barriers {
            let _ = writeln!(w, "     barrier {}", barrier_line(plan, b));
        }
        if let Some(rp) = &p.render_pass {
            for (i, a) in rp.attachments.iter().enumerate() {
                // A resolve target says which attachment it resolves.
                let resolves = rp
                    .resolve
                    .iter()
                    .position(|&t| t == Some(i))
                    .map(|k| {
                        let from = &plan.resources[rp.attachments[rp.color[k]].resource].name;
                        format!(" (resolves {from})")
                    })
                    .unwrap_or_default();
                let _ = writeln!(
                    w,
                    "     attachment {}: load {:?} store {:?}{} layout {}{resolves}",
                    plan.resources[a.resource].name,
                    a.load,
                    a.store,
                    if a.read_only { " read-only" } else { "" },
                    a.layout.vk_name()
                );
            }
        }
        if let Some(d) = p.dispatch {
            let _ = writeln!(w, "     dispatch {}x{}x{}", d[0], d[1], d[2]);
        }
        if let Some(d) = p.indirect {
            let _ = writeln!(
                w,
                "     dispatch indirect from {}, a record each {} bytes",
                plan.resources[d.buffer].name, d.stride
            );
        }
        if p.repeat > 1 {
            let _ = writeln!(w, "     repeat {} times, between them:", p.repeat);
            for b in &p.repeat_barriers {
                let _ = writeln!(w, "       barrier {}", barrier_line(plan, b));
            }
        }
        if p.variants > 1 || !p.defines.is_empty() {
            // Variants are 2^features; the cap is 2^MAX_VARIANT_BITS.
            let features = p.variants.trailing_zeros();
            let _ = writeln!(
                w,
                "     defines {} (variant key; 1 of up to {} variants: {features} of the {} features a pass may depend on)",
                if p.defines.is_empty() {
                    "none".to_string()
                } else {
                    p.defines.join(" ")
                },
                p.variants,
                crate::resolve::MAX_VARIANT_BITS
            );
        }
        if p.groups_by_model() {
            let mut groups: Vec<String> = Vec::new();
            for (model, define) in &p.model_defines {
                let label = model.clone();
                let prefix = format!("{label} +");
                match groups.iter_mut().find(|g| g.starts_with(&prefix)) {
                    Some(g) => g.push_str(&format!(" {define}")),
                    None => groups.push(format!("{label} +{define}")),
                }
            }
            let _ = writeln!(
                w,
                "     mesh draws grouped by shading model, one variant each: {}",
                groups.join(", ")
            );
        }
    }
    if !plan.epilogue.is_empty() {
        let _ = writeln!(w, "\nepilogue:");
        for b in &plan.epilogue {
            let _ = writeln!(w, "     barrier {}", barrier_line(plan, b));
        }
    }
    if !plan.culled.is_empty() {
        let _ = writeln!(w, "\nculled:");
        for c in &plan.culled {
            let _ = writeln!(w, "  {}: {}", c.name, c.reason);
        }
    }
    let m = &plan.memory;
    let saved = if m.transient_bytes_unaliased > 0 {
        100.0 * (1.0 - m.transient_bytes as f64 / m.transient_bytes_unaliased as f64)
    } else {
        0.0
    };
    let _ = writeln!(
        w,
        "\ntransient memory: {} aliased, {} unaliased ({saved:.1}% saved)",
        mib(m.transient_bytes),
        mib(m.transient_bytes_unaliased)
    );
    out
}
