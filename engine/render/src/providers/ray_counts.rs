//! Rays per pass, the cost model `weft compare` shows beside each pass's
//! time: every pass that traces (`derive: [RayTracing()]`) is compiled with
//! `RAY_COUNT_SLOT`, its slot in one counter buffer of set 1
//! (`ray_counts` in `shaders/include/trace.glsl`), and each BVH walk adds one
//! there. The counters are zeroed before a frame and read after it.

use super::traces;
use weft_graph::plan::PlanPass;
use weft_graph::Diagnostic;

/// How many tracing passes one plan may have: the counter buffer's length.
pub const SLOTS: usize = 256;
/// The define naming a tracing pass's slot.
const SLOT_DEFINE: &str = "RAY_COUNT_SLOT";
/// Bytes of the counter buffer: one 32-bit counter per slot.
pub const BYTES: u64 = (SLOTS * 4) as u64;

/// The rays one pass traced in a frame.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct PassRays {
    /// The pass.
    pub pass: String,
    /// Rays its shaders traced (BVH walks: closest-hit and any-hit alike).
    pub rays: u64,
}

/// Gives each tracing pass of a plan's `passes`, in order, its slot as a
/// define.
pub fn assign_slots<'a>(
    passes: impl IntoIterator<Item = &'a mut PlanPass>,
) -> Result<(), Vec<Diagnostic>> {
    for (slot, pass) in passes.into_iter().filter(|p| traces(p)).enumerate() {
        if slot == SLOTS {
            return Err(vec![Diagnostic::error(
                pass.declared_at.file.clone(),
                pass.declared_at.pos,
                format!(
                    "pass \"{}\" is the plan's {}th pass that traces rays; the ray counters hold {SLOTS}",
                    pass.name,
                    slot + 1
                ),
            )]);
        }
        pass.defines.push(format!("{SLOT_DEFINE}={slot}"));
    }
    Ok(())
}

/// The frame's rays per tracing pass of a plan's `passes`, from the counter
/// buffer's words (`counts`, slot order).
pub fn per_pass<'a>(
    passes: impl IntoIterator<Item = &'a PlanPass>,
    counts: &[u32],
) -> Vec<PassRays> {
    passes
        .into_iter()
        .filter(|p| traces(p))
        .zip(counts)
        .map(|(pass, &rays)| PassRays {
            pass: pass.name.clone(),
            rays: u64::from(rays),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_graph::schema::ProviderDecl;

    fn pass(name: &str, traced: bool) -> PlanPass {
        let mut pass = super::super::tests::pass_with(Vec::new());
        pass.name = name.into();
        if traced {
            pass.derive = vec![ProviderDecl {
                name: "RayTracing".into(),
                args: Default::default(),
            }];
        }
        pass
    }

    #[test]
    fn tracing_passes_get_slots_in_order_and_their_counts_by_name() {
        let mut plan = vec![
            pass("gbuffer", false),
            pass("shadows", true),
            pass("blur", false),
            pass("gi", true),
        ];
        assign_slots(&mut plan).expect("two slots");
        let defines: Vec<&[String]> = plan.iter().map(|p| &p.defines[..]).collect();
        assert_eq!(
            defines,
            [
                &[][..],
                &["RAY_COUNT_SLOT=0".to_string()][..],
                &[][..],
                &["RAY_COUNT_SLOT=1".to_string()][..]
            ]
        );
        assert_eq!(
            per_pass(&plan, &[7, 9, 0]),
            [
                PassRays {
                    pass: "shadows".into(),
                    rays: 7
                },
                PassRays {
                    pass: "gi".into(),
                    rays: 9
                }
            ]
        );
    }

    #[test]
    fn a_plan_with_more_tracing_passes_than_counters_is_refused() {
        let mut plan: Vec<PlanPass> = (0..=SLOTS).map(|i| pass(&format!("p{i}"), true)).collect();
        let errors = assign_slots(&mut plan).expect_err("one too many");
        assert!(
            errors[0].message.contains("pass \"p256\" is the plan's 257th pass that traces rays; the ray counters hold 256"),
            "{}",
            errors[0].message
        );
    }
}
