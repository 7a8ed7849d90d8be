//! Hardware acceleration structures (`VK_KHR_acceleration_structure`): the
//! bottom levels over triangle meshes in their own space, and one top level
//! placing them, refitted in place when placements move. Ray queries
//! (`VK_KHR_ray_query`) trace against the top level; the ray tracer's
//! software BVH is the other backend, on devices without these extensions.
//!
//! Each build is recorded into one command buffer and followed by a barrier
//! from the build's writes (`ACCELERATION_STRUCTURE_BUILD`) to every later
//! read, builds of the top level and shaders' ray queries alike.

use crate::buffer::Buffer;
use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::time::{Duration, Instant};

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

/// The bottom levels over a scene's meshes, built together.
pub struct BottomLevels<'g> {
    /// One per mesh, in the order given.
    pub levels: Vec<AccelerationStructure<'g>>,
    /// How long the build took: recording, submission and the wait.
    pub build_time: Duration,
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

/// Builds one bottom level per mesh of `meshes` (triangles opaque, both
/// faces seen, built for fast tracing), in one command buffer.
pub fn build_bottom_levels<'g>(
    gpu: &'g Gpu,
    meshes: &[Mesh],
) -> Result<BottomLevels<'g>, GpuError> {
    let loader = loader(gpu)?;
    let start = Instant::now();
    let geometries: Vec<_> = meshes
        .iter()
        .map(|mesh| {
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
        })
        .collect();
    let counts: Vec<u32> = meshes.iter().map(|m| m.triangles).collect();
    let mut levels = Vec::with_capacity(meshes.len());
    let mut scratch_offsets = Vec::with_capacity(meshes.len());
    let mut scratch_size = 0u64;
    let align = scratch_alignment(gpu);
    for (i, geometry) in geometries.iter().enumerate() {
        let info = bottom_info(std::slice::from_ref(geometry));
        let sizes = build_sizes(loader, &info, counts[i]);
        levels.push(AccelerationStructure::new(
            gpu,
            &format!("BLAS {i}"),
            vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
            sizes.acceleration_structure_size,
        )?);
        scratch_offsets.push(scratch_size);
        scratch_size += sizes.build_scratch_size.next_multiple_of(align);
    }
    let scratch = scratch_buffer(gpu, "BLAS scratch", scratch_size + align)?;
    let scratch_base = scratch.address().next_multiple_of(align);
    let infos: Vec<_> = geometries
        .iter()
        .zip(&levels)
        .zip(&scratch_offsets)
        .map(|((geometry, level), offset)| {
            bottom_info(std::slice::from_ref(geometry))
                .dst_acceleration_structure(level.handle)
                .scratch_data(vk::DeviceOrHostAddressKHR {
                    device_address: scratch_base + offset,
                })
        })
        .collect();
    let ranges: Vec<[vk::AccelerationStructureBuildRangeInfoKHR; 1]> = counts
        .iter()
        .map(|&n| [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(n)])
        .collect();
    let range_refs: Vec<&[vk::AccelerationStructureBuildRangeInfoKHR]> =
        ranges.iter().map(|r| &r[..]).collect();
    if !infos.is_empty() {
        gpu.one_shot(|cmd| {
            unsafe { loader.cmd_build_acceleration_structures(cmd, &infos, &range_refs) };
            built(gpu, cmd);
            Ok(())
        })?;
    }
    Ok(BottomLevels {
        levels,
        build_time: start.elapsed(),
    })
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

/// The top level: placements of bottom levels, rebuilt or refitted in
/// place as placements move.
pub struct TopLevel<'g> {
    gpu: &'g Gpu,
    /// The structure ray queries trace against.
    pub structure: AccelerationStructure<'g>,
    /// The instance records, host-visible: rewritten before a refit.
    instances: Buffer<'g>,
    scratch: Buffer<'g>,
    count: u32,
    /// How long the last build or refit took on the device.
    pub last_time: Duration,
}

impl<'g> TopLevel<'g> {
    /// Builds the top level placing `levels` as `placements` say.
    pub fn build(
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
        let align = scratch_alignment(gpu);
        let scratch = scratch_buffer(
            gpu,
            "TLAS scratch",
            sizes.build_scratch_size.max(sizes.update_scratch_size) + align,
        )?;
        let mut top = Self {
            gpu,
            structure,
            instances,
            scratch,
            count,
            last_time: Duration::ZERO,
        };
        top.record(
            levels,
            placements,
            vk::BuildAccelerationStructureModeKHR::BUILD,
        )?;
        Ok(top)
    }

    /// Moves the placements to `placements` (the same count, each placing
    /// the same level as before) and refits the top level in place.
    pub fn refit(
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
        self.record(
            levels,
            placements,
            vk::BuildAccelerationStructureModeKHR::UPDATE,
        )
    }

    fn record(
        &mut self,
        levels: &BottomLevels<'g>,
        placements: &[Placement],
        mode: vk::BuildAccelerationStructureModeKHR,
    ) -> Result<(), GpuError> {
        let start = Instant::now();
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
        self.instances.write(raw)?;
        let loader = loader(self.gpu)?;
        let geometry = [top_geometry(self.instances.address())];
        let align = scratch_alignment(self.gpu);
        let mut info = top_info(&geometry, mode)
            .dst_acceleration_structure(self.structure.handle)
            .scratch_data(vk::DeviceOrHostAddressKHR {
                device_address: self.scratch.address().next_multiple_of(align),
            });
        if mode == vk::BuildAccelerationStructureModeKHR::UPDATE {
            info = info.src_acceleration_structure(self.structure.handle);
        }
        let ranges =
            [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(self.count)];
        self.gpu.one_shot(|cmd| {
            // Earlier traces and builds read the structure a refit rewrites.
            before_build(self.gpu, cmd);
            unsafe { loader.cmd_build_acceleration_structures(cmd, &[info], &[&ranges]) };
            built(self.gpu, cmd);
            Ok(())
        })?;
        self.last_time = start.elapsed();
        Ok(())
    }

    /// Bytes of device memory the level, its instances and scratch hold.
    pub fn bytes(&self) -> u64 {
        self.structure.bytes() + self.instances.size + self.scratch.size
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

/// `minAccelerationStructureScratchOffsetAlignment`.
fn scratch_alignment(gpu: &Gpu) -> u64 {
    let mut structures = vk::PhysicalDeviceAccelerationStructurePropertiesKHR::default();
    let mut properties = vk::PhysicalDeviceProperties2::default().push_next(&mut structures);
    unsafe {
        gpu.instance()
            .get_physical_device_properties2(gpu.physical_device(), &mut properties)
    };
    u64::from(
        structures
            .min_acceleration_structure_scratch_offset_alignment
            .max(1),
    )
}

fn scratch_buffer<'g>(gpu: &'g Gpu, name: &str, size: u64) -> Result<Buffer<'g>, GpuError> {
    Buffer::new(
        gpu,
        name,
        size,
        vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
        MemoryLocation::GpuOnly,
    )
}

/// The barrier before a build that rewrites a structure earlier commands
/// read or wrote: every earlier access, then the build.
fn before_build(gpu: &Gpu, cmd: vk::CommandBuffer) {
    let barrier = vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
        .src_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR)
        .dst_access_mask(
            vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR
                | vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR,
        );
    let barriers = [barrier];
    let dependency = vk::DependencyInfo::default().memory_barriers(&barriers);
    unsafe { gpu.device().cmd_pipeline_barrier2(cmd, &dependency) };
}

/// The barrier after a build: its writes made visible to later builds (a
/// top level reading its bottom levels) and to every shader's ray queries.
fn built(gpu: &Gpu, cmd: vk::CommandBuffer) {
    let barrier = vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR)
        .src_access_mask(vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR)
        .dst_stage_mask(
            vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR
                | vk::PipelineStageFlags2::ALL_COMMANDS,
        )
        .dst_access_mask(
            vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR | vk::AccessFlags2::MEMORY_READ,
        );
    let barriers = [barrier];
    let dependency = vk::DependencyInfo::default().memory_barriers(&barriers);
    unsafe { gpu.device().cmd_pipeline_barrier2(cmd, &dependency) };
}
