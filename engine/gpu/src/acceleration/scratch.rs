//! Scratch memory for acceleration-structure builds: where a build works,
//! addressed by device address. In a frame it is a transient buffer of the
//! render graph's (the build pass's `storage_write`), which the compiler
//! places in memory other passes use at other times; [`scratch_needed`]
//! says how large, from the meshes' counts alone, before anything is
//! created. A build outside a frame (`weft bench bvh`) makes its own
//! ([`Scratch`]).

use super::{
    bottom_geometry, bottom_info, build_sizes, loader, top_geometry, top_info, BottomLevels, Mesh,
    TopLevel,
};
use crate::buffer::Buffer;
use crate::context::Gpu;
use crate::error::GpuError;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Scratch a build records into: its first address, aligned to
/// `minAccelerationStructureScratchOffsetAlignment`, and the bytes usable
/// from there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScratchSpan {
    /// The aligned address builds start at.
    pub address: u64,
    /// Bytes usable from `address`.
    pub bytes: u64,
}

impl ScratchSpan {
    /// The usable part of a buffer that starts at device address `address`
    /// and holds `bytes` (made with `SHADER_DEVICE_ADDRESS` usage).
    pub fn within(gpu: &Gpu, address: u64, bytes: u64) -> Self {
        Self::aligned(address, bytes, scratch_alignment(gpu))
    }

    /// The part of `bytes` at `address` that starts on a multiple of `align`.
    fn aligned(address: u64, bytes: u64, align: u64) -> Self {
        let start = address.next_multiple_of(align);
        Self {
            address: start,
            bytes: bytes.saturating_sub(start - address),
        }
    }

    /// An error unless the span holds the `needed` bytes of `what`.
    pub(super) fn holds(&self, needed: u64, what: &str) -> Result<(), GpuError> {
        if self.bytes >= needed {
            return Ok(());
        }
        Err(GpuError::Plan(format!(
            "{what} needs {needed} bytes of scratch, and its scratch buffer holds {} from its \
             aligned start: size it by the scene value the renderer measures \
             (graphs/acceleration.ron)",
            self.bytes
        )))
    }
}

/// Bytes of scratch a frame's builds over `meshes`, placed `placements`
/// times, need: the bottom levels' build (every level at once, each at an
/// aligned offset) or the top level's build or refit, whichever is larger
/// (they run one after the other in the same scratch), plus the alignment
/// a buffer's start may need. Only the meshes' counts matter, not their
/// addresses.
pub fn scratch_needed(gpu: &Gpu, meshes: &[Mesh], placements: u32) -> Result<u64, GpuError> {
    let loader = loader(gpu)?;
    let align = scratch_alignment(gpu);
    let bottom: u64 = meshes
        .iter()
        .map(|mesh| {
            let geometry = [bottom_geometry(mesh)];
            let sizes = build_sizes(loader, &bottom_info(&geometry), mesh.triangles);
            sizes.build_scratch_size.next_multiple_of(align)
        })
        .sum();
    let geometry = [top_geometry(0)];
    let info = top_info(&geometry, vk::BuildAccelerationStructureModeKHR::BUILD);
    let sizes = build_sizes(loader, &info, placements);
    let top = sizes.build_scratch_size.max(sizes.update_scratch_size);
    Ok(both(bottom, top, align))
}

/// Bytes of scratch the builds of `bottom` and `top`, created, need: what
/// [`scratch_needed`] gives for their meshes and placements.
pub fn scratch_for(gpu: &Gpu, bottom: &BottomLevels<'_>, top: &TopLevel<'_>) -> u64 {
    both(
        bottom.scratch_bytes,
        top.scratch_bytes,
        scratch_alignment(gpu),
    )
}

/// The scratch for a bottom-level build and a top-level one in turn, from a
/// buffer start aligned to no more than the device promises.
fn both(bottom: u64, top: u64, align: u64) -> u64 {
    bottom.max(top) + align
}

/// Scratch a build outside a frame owns: a device buffer of its own.
pub struct Scratch<'g> {
    buffer: Buffer<'g>,
    gpu: &'g Gpu,
}

impl<'g> Scratch<'g> {
    /// A scratch buffer of `bytes` (as [`scratch_needed`] counts them).
    pub fn new(gpu: &'g Gpu, bytes: u64) -> Result<Self, GpuError> {
        let buffer = Buffer::new(
            gpu,
            "acceleration-structure scratch",
            bytes.max(1),
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        Ok(Self { buffer, gpu })
    }

    /// Where builds work in it.
    pub fn span(&self) -> ScratchSpan {
        ScratchSpan::within(self.gpu, self.buffer.address(), self.buffer.size)
    }
}

/// `minAccelerationStructureScratchOffsetAlignment`, as the device reported it.
pub(super) fn scratch_alignment(gpu: &Gpu) -> u64 {
    gpu.info().acceleration_scratch_alignment
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_span_starts_aligned_and_loses_the_bytes_before() {
        assert_eq!(
            ScratchSpan::aligned(1000, 4096, 256),
            ScratchSpan {
                address: 1024,
                bytes: 4072
            }
        );
        assert_eq!(ScratchSpan::aligned(1024, 10, 256).bytes, 10);
        assert_eq!(ScratchSpan::aligned(1, 100, 256).bytes, 0);
        let span = ScratchSpan::aligned(0, 100, 128);
        assert!(span.holds(100, "a build").is_ok());
        let refused = span.holds(101, "a build").expect_err("too small");
        assert!(refused
            .to_string()
            .contains("a build needs 101 bytes of scratch, and its scratch buffer holds 100"));
    }
}
