//! Hardware acceleration structures (`VK_KHR_acceleration_structure`): the
//! bottom levels over triangle meshes in their own space, and one top level
//! placing them, refitted in place when placements move. Ray queries
//! (`VK_KHR_ray_query`) trace against the top level; the ray tracer's
//! software BVH is the other backend, on devices without these extensions.
//!
//! The structures are created here, sized for the device, and their builds
//! recorded into a command buffer the caller orders: in a frame, the render
//! graph's `BuildAccelerationStructures` pass, whose barriers the compiler
//! derives like any other pass's, building in the scratch buffer the graph
//! declares ([`ScratchSpan`]).

mod scratch;

pub use scratch::{scratch_for, scratch_needed, Scratch, ScratchSpan};

use crate::buffer::Buffer;
use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;
use gpu_allocator::MemoryLocation;
use scratch::scratch_alignment;

/// An acceleration structure and the buffer holding it, destroyed on drop.
pub struct AccelerationStructure<'g> {
    gpu: &'g Gpu,
    /// The structure, for descriptor writes.
    pub handle: vk::AccelerationStructureKHR,
    /// Its device address, as a top level's instances name it.
    pub address: u64,
    storage: Buffer<'g>,
}

impl<'g> AccelerationStructure<'g> {
    fn new(
        gpu: &'g Gpu,
        name: &str,
        kind: vk::AccelerationStructureTypeKHR,
        size: u64,
    ) -> Result<Self, GpuError> {
        let loader = loader(gpu)?;
        let storage = Buffer::new(
            gpu,
            name,
            size,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        let info = vk::AccelerationStructureCreateInfoKHR::default()
            .buffer(storage.buffer)
            .size(size)
            .ty(kind);
        let handle = unsafe { loader.create_acceleration_structure(&info, None) }
            .call("vkCreateAccelerationStructureKHR")?;
        gpu.set_name(handle, name);
        let address = unsafe {
            loader.get_acceleration_structure_device_address(
                &vk::AccelerationStructureDeviceAddressInfoKHR::default()
                    .acceleration_structure(handle),
            )
        };
        Ok(Self {
            gpu,
            handle,
            address,
            storage,
        })
    }

    /// Bytes of device memory it holds.
    pub fn bytes(&self) -> u64 {
        self.storage.size
    }
}

impl Drop for AccelerationStructure<'_> {
    fn drop(&mut self) {
        if let Some(loader) = self.gpu.acceleration() {
            unsafe { loader.destroy_acceleration_structure(self.handle, None) };
        }
    }
}

/// The acceleration-structure entry points, or an error naming the missing
/// extension on a device without it.
fn loader(gpu: &Gpu) -> Result<&ash::khr::acceleration_structure::Device, GpuError> {
    gpu.acceleration().ok_or_else(|| GpuError::Unsupported {
        what: "acceleration structures".into(),
        device: gpu.info().name.clone(),
        needs: "VK_KHR_acceleration_structure and VK_KHR_ray_query".into(),
    })
}

/// The usage the buffers a build reads meshes from need: the renderer's
/// vertex and index buffers carry it on a device with ray queries, so the
/// bottom levels read the geometry already there.
pub const INPUT_USAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::from_raw(
    vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR.as_raw()
        | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS.as_raw(),
);

/// One mesh in its own space, in buffers made with [`INPUT_USAGE`]: vertex
/// positions (three floats at the start of each vertex) and 32-bit indices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mesh {
    /// Device address of its first vertex.
    pub vertices: u64,
    /// Bytes from one vertex to the next.
    pub stride: u64,
    /// The highest index its triangles use.
    pub max_vertex: u32,
    /// Device address of its first index.
    pub indices: u64,
    /// How many triangles: three indices each.
    pub triangles: u32,
}

/// The bottom levels over a scene's meshes, created together and built
/// once by one recorded command ([`Self::record`]).
pub struct BottomLevels<'g> {
    /// One per mesh, in the order given.
    pub levels: Vec<AccelerationStructure<'g>>,
    meshes: Vec<Mesh>,
    /// Each level's scratch, at offsets aligned to the device's minimum.
    scratch_offsets: Vec<u64>,
    /// Bytes of scratch the build needs, all levels together.
    pub scratch_bytes: u64,
    /// Whether the build has been recorded.
    built: bool,
    /// Whether that record is not yet known to have been submitted.
    unsubmitted: bool,
}

/// A placement of a bottom level in the top level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Object-to-world, the top three rows of the matrix, row-major.
    pub transform: [f32; 12],
    /// Which bottom level it places (an index into [`BottomLevels::levels`]).
    pub level: usize,
    /// What ray queries report for its hits as the instance's custom index
    /// (24 bits): the renderer's first triangle of the placement.
    pub custom_index: u32,
}

/// The most a custom index may be: 24 bits.
pub const MAX_CUSTOM_INDEX: u32 = (1 << 24) - 1;

impl<'g> BottomLevels<'g> {
    /// Creates one bottom level per mesh of `meshes` (triangles opaque,
    /// both faces seen, built for fast tracing), sized for the device; the
    /// build is recorded later, by [`Self::record_build`].
    pub fn new(gpu: &'g Gpu, meshes: &[Mesh]) -> Result<Self, GpuError> {
        let loader = loader(gpu)?;
        let align = scratch_alignment(gpu);
        let mut levels = Vec::with_capacity(meshes.len());
        let mut scratch_offsets = Vec::with_capacity(meshes.len());
        let mut scratch_bytes = 0u64;
        for (i, mesh) in meshes.iter().enumerate() {
            let geometry = [bottom_geometry(mesh)];
            let sizes = build_sizes(loader, &bottom_info(&geometry), mesh.triangles);
            levels.push(AccelerationStructure::new(
                gpu,
                &format!("BLAS {i}"),
                vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
                sizes.acceleration_structure_size,
            )?);
            scratch_offsets.push(scratch_bytes);
            scratch_bytes += sizes.build_scratch_size.next_multiple_of(align);
        }
        Ok(Self {
            levels,
            meshes: meshes.to_vec(),
            scratch_offsets,
            scratch_bytes,
            built: false,
            unsubmitted: false,
        })
    }

    /// Records every level's build the first time, one
    /// `vkCmdBuildAccelerationStructuresKHR` with its scratch from `scratch`
    /// (at least [`Self::scratch_bytes`]), then a barrier to the top level's
    /// build, which reads the levels and reuses the scratch; nothing once
    /// built. The caller orders the geometry's writes before it.
    pub fn record(
        &mut self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        scratch: ScratchSpan,
    ) -> Result<(), GpuError> {
        if self.built {
            return Ok(());
        }
        scratch.holds(self.scratch_bytes, "the bottom levels' build")?;
        self.record_build(gpu, cmd, scratch)?;
        between_builds(gpu, cmd);
        self.built = true;
        self.unsubmitted = true;
        Ok(())
    }

    /// Whether the build is recorded and known to have been submitted: its
    /// scratch is no longer in use once that frame has finished.
    pub fn settled(&self) -> bool {
        self.built && !self.unsubmitted
    }

    /// The recorded build was submitted: it counts.
    pub fn submitted(&mut self) {
        self.unsubmitted = false;
    }

    /// The recorded build was never submitted (its frame failed before it):
    /// the next [`Self::record`] records it again.
    pub fn forget_unsubmitted(&mut self) {
        if std::mem::take(&mut self.unsubmitted) {
            self.built = false;
        }
    }

    fn record_build(
        &self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        scratch: ScratchSpan,
    ) -> Result<(), GpuError> {
        let loader = loader(gpu)?;
        if self.levels.is_empty() {
            return Ok(());
        }
        let geometries: Vec<[vk::AccelerationStructureGeometryKHR; 1]> =
            self.meshes.iter().map(|m| [bottom_geometry(m)]).collect();
        let infos: Vec<_> = geometries
            .iter()
            .zip(&self.levels)
            .zip(&self.scratch_offsets)
            .map(|((geometry, level), offset)| {
                bottom_info(geometry)
                    .dst_acceleration_structure(level.handle)
                    .scratch_data(vk::DeviceOrHostAddressKHR {
                        device_address: scratch.address + offset,
                    })
            })
            .collect();
        let ranges: Vec<[vk::AccelerationStructureBuildRangeInfoKHR; 1]> =
            self.meshes
                .iter()
                .map(|m| {
                    [vk::AccelerationStructureBuildRangeInfoKHR::default()
                        .primitive_count(m.triangles)]
                })
                .collect();
        let range_refs: Vec<&[vk::AccelerationStructureBuildRangeInfoKHR]> =
            ranges.iter().map(|r| &r[..]).collect();
        unsafe { loader.cmd_build_acceleration_structures(cmd, &infos, &range_refs) };
        Ok(())
    }

    /// Bytes of device memory the levels hold.
    pub fn bytes(&self) -> u64 {
        self.levels.iter().map(AccelerationStructure::bytes).sum()
    }
}

fn bottom_geometry(mesh: &Mesh) -> vk::AccelerationStructureGeometryKHR<'static> {
    let triangles = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
        .vertex_format(vk::Format::R32G32B32_SFLOAT)
        .vertex_data(vk::DeviceOrHostAddressConstKHR {
            device_address: mesh.vertices,
        })
        .vertex_stride(mesh.stride)
        .max_vertex(mesh.max_vertex)
        .index_type(vk::IndexType::UINT32)
        .index_data(vk::DeviceOrHostAddressConstKHR {
            device_address: mesh.indices,
        });
    vk::AccelerationStructureGeometryKHR::default()
        .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
        .geometry(vk::AccelerationStructureGeometryDataKHR { triangles })
        .flags(vk::GeometryFlagsKHR::OPAQUE)
}

fn bottom_info<'a>(
    geometry: &'a [vk::AccelerationStructureGeometryKHR<'a>],
) -> vk::AccelerationStructureBuildGeometryInfoKHR<'a> {
    vk::AccelerationStructureBuildGeometryInfoKHR::default()
        .ty(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL)
        .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
        .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
        .geometries(geometry)
}

/// Whether the next recorded top-level build starts afresh or refits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TopState {
    /// Created, never built: the next record builds it.
    Unbuilt,
    /// Built for the placements as they are.
    Current,
    /// Placements moved since the last build: the next record refits.
    Moved,
}

/// The top level: placements of bottom levels, built, then refitted in
/// place as placements move, each by a recorded command ([`Self::record`]).
pub struct TopLevel<'g> {
    /// The structure ray queries trace against.
    pub structure: AccelerationStructure<'g>,
    /// The instance records, host-visible: rewritten before a refit.
    instances: Buffer<'g>,
    count: u32,
    /// Bytes of scratch a build or a refit needs.
    pub scratch_bytes: u64,
    state: TopState,
    /// The state before the last recorded build, until it is known to have
    /// been submitted ([`Self::submitted`]).
    unsubmitted: Option<TopState>,
}

impl<'g> TopLevel<'g> {
    /// Creates the top level placing `levels` as `placements` say, sized
    /// for the device, its instance records written; the build is recorded
    /// later, by [`Self::record`].
    pub fn new(
        gpu: &'g Gpu,
        levels: &BottomLevels<'g>,
        placements: &[Placement],
    ) -> Result<Self, GpuError> {
        let loader = loader(gpu)?;
        let count = placements.len() as u32;
        let instances = Buffer::new(
            gpu,
            "TLAS instances",
            (placements.len() * std::mem::size_of::<vk::AccelerationStructureInstanceKHR>()) as u64,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::CpuToGpu,
        )?;
        let geometry = [top_geometry(instances.address())];
        let info = top_info(&geometry, vk::BuildAccelerationStructureModeKHR::BUILD);
        let sizes = build_sizes(loader, &info, count);
        let structure = AccelerationStructure::new(
            gpu,
            "TLAS",
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            sizes.acceleration_structure_size,
        )?;
        let mut top = Self {
            structure,
            instances,
            count,
            scratch_bytes: sizes.build_scratch_size.max(sizes.update_scratch_size),
            state: TopState::Unbuilt,
            unsubmitted: None,
        };
        top.write_instances(levels, placements)?;
        Ok(top)
    }

    /// Moves the placements to `placements` (the same count, each placing
    /// the same level as before): the next [`Self::record`] refits. Call it
    /// between frames, when no build still reads the instance records.
    pub fn place(
        &mut self,
        levels: &BottomLevels<'g>,
        placements: &[Placement],
    ) -> Result<(), GpuError> {
        if placements.len() as u32 != self.count {
            return Err(GpuError::Plan(format!(
                "a top level of {} placements cannot be refitted with {}: it needs a rebuild",
                self.count,
                placements.len()
            )));
        }
        self.write_instances(levels, placements)?;
        if self.state == TopState::Current {
            self.state = TopState::Moved;
        }
        Ok(())
    }

    /// Records the top level's build (the first time) or refit (placements
    /// moved), with its scratch from `scratch`; nothing when it is current.
    /// The caller orders it after the bottom levels' build and the last
    /// reads of the structure, and before the ray queries that read it.
    pub fn record(
        &mut self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        scratch: ScratchSpan,
    ) -> Result<(), GpuError> {
        let mode = match self.state {
            TopState::Current => return Ok(()),
            TopState::Unbuilt => vk::BuildAccelerationStructureModeKHR::BUILD,
            TopState::Moved => vk::BuildAccelerationStructureModeKHR::UPDATE,
        };
        scratch.holds(self.scratch_bytes, "the top level's build")?;
        let loader = loader(gpu)?;
        let geometry = [top_geometry(self.instances.address())];
        let mut info = top_info(&geometry, mode)
            .dst_acceleration_structure(self.structure.handle)
            .scratch_data(vk::DeviceOrHostAddressKHR {
                device_address: scratch.address,
            });
        if mode == vk::BuildAccelerationStructureModeKHR::UPDATE {
            info = info.src_acceleration_structure(self.structure.handle);
        }
        let ranges =
            [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(self.count)];
        unsafe { loader.cmd_build_acceleration_structures(cmd, &[info], &[&ranges]) };
        self.unsubmitted = Some(self.state);
        self.state = TopState::Current;
        Ok(())
    }

    /// The last recorded build was submitted: it counts.
    pub fn submitted(&mut self) {
        self.unsubmitted = None;
    }

    /// The last recorded build was never submitted (its frame failed before
    /// it): the next [`Self::record`] does its work again.
    pub fn forget_unsubmitted(&mut self) {
        if let Some(before) = self.unsubmitted.take() {
            // Never built stays so; a refit (and any move since) refits.
            self.state = if before == TopState::Unbuilt {
                TopState::Unbuilt
            } else {
                TopState::Moved
            };
        }
    }

    fn write_instances(
        &mut self,
        levels: &BottomLevels<'g>,
        placements: &[Placement],
    ) -> Result<(), GpuError> {
        let records: Vec<vk::AccelerationStructureInstanceKHR> = placements
            .iter()
            .map(|p| instance(p, levels))
            .collect::<Result<_, _>>()?;
        let raw = unsafe {
            std::slice::from_raw_parts(
                records.as_ptr().cast::<u8>(),
                std::mem::size_of_val(records.as_slice()),
            )
        };
        self.instances.write(raw)
    }

    /// Bytes of device memory the level and its instances hold.
    pub fn bytes(&self) -> u64 {
        self.structure.bytes() + self.instances.size
    }
}

fn instance(
    placement: &Placement,
    levels: &BottomLevels<'_>,
) -> Result<vk::AccelerationStructureInstanceKHR, GpuError> {
    let level = levels
        .levels
        .get(placement.level)
        .ok_or_else(|| GpuError::Pass {
            pass: "the top level".into(),
            message: format!(
                "a placement names bottom level {} of {}",
                placement.level,
                levels.levels.len()
            ),
        })?;
    let flags = vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE.as_raw() as u8;
    Ok(vk::AccelerationStructureInstanceKHR {
        transform: vk::TransformMatrixKHR {
            matrix: placement.transform,
        },
        instance_custom_index_and_mask: vk::Packed24_8::new(
            placement.custom_index & MAX_CUSTOM_INDEX,
            0xff,
        ),
        instance_shader_binding_table_record_offset_and_flags: vk::Packed24_8::new(0, flags),
        acceleration_structure_reference: vk::AccelerationStructureReferenceKHR {
            device_handle: level.address,
        },
    })
}

fn top_geometry(instances: u64) -> vk::AccelerationStructureGeometryKHR<'static> {
    let data = vk::AccelerationStructureGeometryInstancesDataKHR::default()
        .array_of_pointers(false)
        .data(vk::DeviceOrHostAddressConstKHR {
            device_address: instances,
        });
    vk::AccelerationStructureGeometryKHR::default()
        .geometry_type(vk::GeometryTypeKHR::INSTANCES)
        .geometry(vk::AccelerationStructureGeometryDataKHR { instances: data })
        .flags(vk::GeometryFlagsKHR::OPAQUE)
}

fn top_info<'a>(
    geometry: &'a [vk::AccelerationStructureGeometryKHR<'a>],
    mode: vk::BuildAccelerationStructureModeKHR,
) -> vk::AccelerationStructureBuildGeometryInfoKHR<'a> {
    vk::AccelerationStructureBuildGeometryInfoKHR::default()
        .ty(vk::AccelerationStructureTypeKHR::TOP_LEVEL)
        .flags(
            vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE
                | vk::BuildAccelerationStructureFlagsKHR::ALLOW_UPDATE,
        )
        .mode(mode)
        .geometries(geometry)
}

fn build_sizes(
    loader: &ash::khr::acceleration_structure::Device,
    info: &vk::AccelerationStructureBuildGeometryInfoKHR<'_>,
    primitives: u32,
) -> vk::AccelerationStructureBuildSizesInfoKHR<'static> {
    let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
    unsafe {
        loader.get_acceleration_structure_build_sizes(
            vk::AccelerationStructureBuildTypeKHR::DEVICE,
            info,
            &[primitives],
            &mut sizes,
        )
    };
    sizes
}

/// The barrier between builds: the earlier builds' writes (and their
/// scratch's) made visible to a later build, which reads the levels and
/// reuses the scratch. What comes before and after a frame's build pass is
/// the render graph's to order.
pub fn between_builds(gpu: &Gpu, cmd: vk::CommandBuffer) {
    let barrier = vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR)
        .src_access_mask(vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR)
        .dst_stage_mask(vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR)
        .dst_access_mask(
            vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR
                | vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR,
        );
    let barriers = [barrier];
    let dependency = vk::DependencyInfo::default().memory_barriers(&barriers);
    unsafe { gpu.device().cmd_pipeline_barrier2(cmd, &dependency) };
}
