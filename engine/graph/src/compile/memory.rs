//! Step 5, memory: transient images and buffers whose lifetimes do not
//! overlap share memory. Each is placed at the lowest aligned offset that does
//! not collide with any resource alive at the same time (largest first),
//! inside one block.

use crate::id::{IdVec, ResourceId};
use crate::plan::{
    BufferDesc, ImageDesc, MemoryBlock, MemoryPlan, Placement, PlanResource, Residency,
    ResourceDesc,
};

/// Places every transient image and buffer of `resources` (setting its
/// `placement`) with the device's memory requirements; returns the memory
/// plan. (Acceleration structures are the scene's memory, never transient.)
pub(crate) fn alias(
    resources: &mut IdVec<ResourceId, PlanResource>,
    requirements: &dyn Fn(&ResourceDesc) -> MemoryRequirements,
) -> MemoryPlan {
    let transient: Vec<(ResourceId, Transient)> = resources
        .iter_enumerated()
        .filter(|(_, r)| r.residency == Residency::Transient)
        .map(|(i, r)| {
            (
                i,
                Transient {
                    requirements: requirements(&r.desc),
                    lifetime: (r.lifetime.0.index(), r.lifetime.1.index()),
                },
            )
        })
        .collect();
    let requests: Vec<Transient> = transient.iter().map(|(_, t)| *t).collect();
    let (memory, placements) = place(&requests);
    for ((i, _), placement) in transient.iter().zip(placements) {
        resources[*i].placement = Some(placement);
    }
    memory
}

/// Size and alignment of a resource's memory, as `vkGetImageMemoryRequirements`
/// or `vkGetBufferMemoryRequirements` reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryRequirements {
    pub size: u64,
    pub alignment: u64,
}

/// Requirements when no device is at hand: an image's tightly packed texels
/// over the mip chain, layers and samples, a buffer's bytes, each rounded up
/// to 64 KiB pages with 64 KiB alignment, as discrete GPUs commonly report
/// for optimally tiled images (and so that no buffer shares a page of
/// `bufferImageGranularity` with an image).
pub fn estimate_requirements(desc: &ResourceDesc) -> MemoryRequirements {
    match desc {
        ResourceDesc::Image(image) => estimate_image(image),
        ResourceDesc::Buffer(buffer) => estimate_buffer(buffer),
        ResourceDesc::AccelerationStructure => MemoryRequirements {
            size: 0,
            alignment: 1,
        },
    }
}

/// The page [`estimate_requirements`] rounds to.
const PAGE: u64 = 64 * 1024;

fn estimate_buffer(desc: &BufferDesc) -> MemoryRequirements {
    MemoryRequirements {
        size: desc.size.max(1).div_ceil(PAGE) * PAGE,
        alignment: PAGE,
    }
}

fn estimate_image(desc: &ImageDesc) -> MemoryRequirements {
    let mut texels = 0u64;
    for mip in 0..desc.mips {
        let w = (desc.extent.width >> mip).max(1) as u64;
        let h = (desc.extent.height >> mip).max(1) as u64;
        texels += w * h;
    }
    let bytes = texels * desc.texel_bytes as u64 * desc.layers as u64 * desc.samples as u64;
    MemoryRequirements {
        size: bytes.div_ceil(PAGE) * PAGE,
        alignment: PAGE,
    }
}

/// A resource to place: its requirements and the first and last pass that use it.
#[derive(Debug, Clone, Copy)]
pub struct Transient {
    pub requirements: MemoryRequirements,
    pub lifetime: (usize, usize),
}

fn overlaps(a: (usize, usize), b: (usize, usize)) -> bool {
    a.0 <= b.1 && b.0 <= a.1
}

/// Places transient resources; returns a placement per input, in input order.
pub fn place(resources: &[Transient]) -> (MemoryPlan, Vec<Placement>) {
    let mut by_size: Vec<usize> = (0..resources.len()).collect();
    by_size.sort_by_key(|&i| {
        (
            std::cmp::Reverse(resources[i].requirements.size),
            resources[i].lifetime.0,
            i,
        )
    });
    let mut placements = vec![
        Placement {
            block: 0,
            offset: 0,
            size: 0
        };
        resources.len()
    ];
    // Placed resources as (offset, end, lifetime), kept sorted by offset.
    let mut placed: Vec<(u64, u64, (usize, usize))> = Vec::with_capacity(resources.len());
    let mut block_size = 0u64;
    let mut block_alignment = 1u64;
    for &i in &by_size {
        let req = resources[i].requirements;
        let align = req.alignment.max(1);
        let mut offset = 0u64;
        let lifetime = resources[i].lifetime;
        for &(start, end, other) in &placed {
            if !overlaps(lifetime, other) {
                continue;
            }
            if offset + req.size <= start {
                break;
            }
            offset = offset.max(end.div_ceil(align) * align);
        }
        placements[i] = Placement {
            block: 0,
            offset,
            size: req.size,
        };
        let at = placed.partition_point(|p| p.0 <= offset);
        placed.insert(at, (offset, offset + req.size, lifetime));
        block_size = block_size.max(offset + req.size);
        block_alignment = block_alignment.max(align);
    }
    let unaliased = resources.iter().map(|t| t.requirements.size).sum();
    let blocks = if resources.is_empty() {
        Vec::new()
    } else {
        vec![MemoryBlock {
            size: block_size,
            alignment: block_alignment,
        }]
    };
    (
        MemoryPlan {
            blocks,
            transient_bytes: block_size,
            transient_bytes_unaliased: unaliased,
        },
        placements,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(size: u64, alignment: u64, first: usize, last: usize) -> Transient {
        Transient {
            requirements: MemoryRequirements { size, alignment },
            lifetime: (first, last),
        }
    }

    #[test]
    fn disjoint_lifetimes_share_memory_and_overlapping_ones_do_not() {
        let (plan, p) = place(&[t(100, 1, 0, 1), t(100, 1, 2, 3), t(50, 1, 1, 2)]);
        assert_eq!(p[0].offset, 0);
        assert_eq!(p[1].offset, 0);
        assert_eq!(p[2].offset, 100);
        assert_eq!(plan.transient_bytes, 150);
        assert_eq!(plan.transient_bytes_unaliased, 250);
    }

    #[test]
    fn offsets_respect_alignment() {
        let (plan, p) = place(&[t(1000, 1, 0, 5), t(10, 256, 0, 5)]);
        assert_eq!(p[1].offset, 1024);
        assert_eq!(plan.blocks[0].size, 1034);
        assert_eq!(plan.blocks[0].alignment, 256);
    }

    #[test]
    fn gaps_between_live_images_are_reused() {
        // a [0,100) and c [200,300) live throughout; b ended; d fits in b's gap.
        let (_, p) = place(&[
            t(100, 1, 0, 9),
            t(100, 1, 0, 1),
            t(100, 1, 0, 9),
            t(90, 1, 5, 9),
        ]);
        assert_eq!((p[0].offset, p[1].offset, p[2].offset), (0, 100, 200));
        assert_eq!(p[3].offset, 100);
    }

    #[test]
    fn estimate_counts_mips_layers_and_rounds_to_pages() {
        let desc = ImageDesc {
            format: "R8G8B8A8_UNORM".into(),
            format_raw: 37,
            aspect: crate::vk::Aspect::Color,
            extent: crate::plan::Extent {
                width: 256,
                height: 256,
            },
            mips: 2,
            layers: 3,
            samples: 1,
            usage: crate::vk::ImageUsage::SAMPLED,
            texel_bytes: 4,
        };
        let req = estimate_requirements(&ResourceDesc::Image(desc));
        assert_eq!(req.size, (256 * 256 + 128 * 128) * 4 * 3);
        assert_eq!(req.alignment, 65536);
        let buffer = ResourceDesc::Buffer(BufferDesc {
            size: 65537,
            usage: crate::vk::BufferUsage::STORAGE,
        });
        assert_eq!(
            estimate_requirements(&buffer),
            MemoryRequirements {
                size: 2 * 65536,
                alignment: 65536
            }
        );
    }
}
