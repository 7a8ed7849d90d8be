//! Pipeline-statistics queries around each pass (with GPU timestamps):
//! primitives, vertex and fragment shader invocations, compute invocations,
//! so a benchmark can confirm how much work a pass really did.

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;
use weft_graph::plan::Plan;

/// The statistics collected, in the order Vulkan writes them (bit order).
const FLAGS: vk::QueryPipelineStatisticFlags = vk::QueryPipelineStatisticFlags::from_raw(
    vk::QueryPipelineStatisticFlags::INPUT_ASSEMBLY_PRIMITIVES.as_raw()
        | vk::QueryPipelineStatisticFlags::VERTEX_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::CLIPPING_PRIMITIVES.as_raw()
        | vk::QueryPipelineStatisticFlags::FRAGMENT_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::COMPUTE_SHADER_INVOCATIONS.as_raw(),
);
/// Values per query.
const VALUES: usize = 5;

/// What one pass made the device do.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct PassStatistics {
    /// The pass name.
    pub pass: String,
    /// Primitives assembled (triangles drawn).
    pub input_primitives: u64,
    /// Vertex shader invocations.
    pub vertex_invocations: u64,
    /// Primitives that left clipping.
    pub clipped_primitives: u64,
    /// Fragment shader invocations (implementations may count helper lanes).
    pub fragment_invocations: u64,
    /// Compute shader invocations.
    pub compute_invocations: u64,
}

/// One pipeline-statistics query per pass.
pub(crate) struct StatisticsPool<'g> {
    gpu: &'g Gpu,
    pool: vk::QueryPool,
    count: u32,
}

impl<'g> StatisticsPool<'g> {
    /// Queries in the pool.
    pub(crate) fn count(&self) -> u32 {
        self.count
    }

    /// A pool with one query per pass.
    pub(crate) fn new(gpu: &'g Gpu, count: u32) -> Result<Self, GpuError> {
        let count = count.max(1);
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::PIPELINE_STATISTICS)
            .query_count(count)
            .pipeline_statistics(FLAGS);
        let pool =
            unsafe { gpu.device().create_query_pool(&info, None) }.call("vkCreateQueryPool")?;
        Ok(Self { gpu, pool, count })
    }

    /// Resets every query; recorded once at the start of the frame.
    pub(crate) fn reset(&self, cmd: vk::CommandBuffer) {
        unsafe {
            self.gpu
                .device()
                .cmd_reset_query_pool(cmd, self.pool, 0, self.count)
        };
    }

    /// Starts counting for a pass (outside any render pass).
    pub(crate) fn begin(&self, cmd: vk::CommandBuffer, pass: u32) {
        unsafe {
            self.gpu
                .device()
                .cmd_begin_query(cmd, self.pool, pass, vk::QueryControlFlags::empty())
        };
    }

    /// Stops counting for a pass.
    pub(crate) fn end(&self, cmd: vk::CommandBuffer, pass: u32) {
        unsafe { self.gpu.device().cmd_end_query(cmd, self.pool, pass) };
    }

    /// The statistics of every pass, after the frame has completed.
    pub(crate) fn read(&self, plan: &Plan) -> Result<Vec<PassStatistics>, GpuError> {
        // One element per query: ash derives the query count and stride from it.
        let mut values = vec![[0u64; VALUES]; self.count as usize];
        unsafe {
            self.gpu.device().get_query_pool_results(
                self.pool,
                0,
                &mut values,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .call("vkGetQueryPoolResults")?;
        Ok(plan
            .passes
            .iter()
            .zip(&values)
            .map(|(pass, v)| PassStatistics {
                pass: pass.name.clone(),
                input_primitives: v[0],
                vertex_invocations: v[1],
                clipped_primitives: v[2],
                fragment_invocations: v[3],
                compute_invocations: v[4],
            })
            .collect())
    }
}

impl Drop for StatisticsPool<'_> {
    fn drop(&mut self) {
        unsafe { self.gpu.device().destroy_query_pool(self.pool, None) };
    }
}
