//! Per-pass timings: GPU timestamps around each pass, or host wall time of
//! each pass submitted alone (profiling mode), labelled with which they are.

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;
use weft_graph::plan::Plan;
use weft_graph::schema::PassKind;

/// How per-pass times are measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TimingMode {
    /// No timing.
    #[default]
    Off,
    /// GPU timestamps around each pass, one submission per frame.
    GpuTimestamps,
    /// CPU wall time of each pass submitted and waited for on its own
    /// (profiling mode: slower frames, but honest figures where timestamps
    /// are not, like compute on lavapipe).
    CpuPerPass,
}

/// What a timing figure measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum TimingSource {
    /// Difference of GPU timestamps around the pass.
    GpuTimestamp,
    /// Host wall time from submitting the pass alone to its fence signalling.
    CpuWall,
}

/// The time one pass took.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PassTiming {
    /// The pass name.
    pub pass: String,
    /// Its kind, so compute figures can be judged (lavapipe timestamps).
    pub kind: PassKind,
    /// How the figure was measured.
    pub source: TimingSource,
    /// Milliseconds.
    pub ms: f64,
}

impl TimingSource {
    /// How the figure is labelled in tables.
    pub fn label(self) -> &'static str {
        match self {
            Self::GpuTimestamp => "gpu timestamp",
            Self::CpuWall => "cpu wall (submit+wait)",
        }
    }
}

/// A table of per-pass times with a total, one pass per line.
pub fn format_timings(timings: &[PassTiming]) -> String {
    let width = timings
        .iter()
        .map(|t| t.pass.len())
        .max()
        .unwrap_or(4)
        .max(5);
    let mut out = format!(
        "{:<width$}  {:<10}  {:>9}  measured by\n",
        "pass", "kind", "ms"
    );
    for t in timings {
        out.push_str(&format!(
            "{:<width$}  {:<10}  {:>9.3}  {}\n",
            t.pass,
            format!("{:?}", t.kind),
            t.ms,
            t.source.label()
        ));
    }
    let total: f64 = timings.iter().map(|t| t.ms).sum();
    out.push_str(&format!(
        "{:<width$}  {:<10}  {:>9.3}\n",
        "total", "", total
    ));
    out
}

/// Timestamp queries around every pass.
pub(crate) struct QueryPool<'g> {
    gpu: &'g Gpu,
    pub(crate) pool: vk::QueryPool,
    pub(crate) count: u32,
}

impl<'g> QueryPool<'g> {
    pub(crate) fn new(gpu: &'g Gpu, count: u32) -> Result<Self, GpuError> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(count.max(1));
        let pool =
            unsafe { gpu.device().create_query_pool(&info, None) }.call("vkCreateQueryPool")?;
        Ok(Self {
            gpu,
            pool,
            count: count.max(1),
        })
    }

    pub(crate) fn write(
        &self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        query: u32,
        stage: vk::PipelineStageFlags2,
    ) {
        unsafe {
            gpu.device()
                .cmd_write_timestamp2(cmd, stage, self.pool, query)
        };
    }

    pub(crate) fn timings(&self, gpu: &Gpu, plan: &Plan) -> Result<Vec<PassTiming>, GpuError> {
        let mut ticks = vec![0u64; self.count as usize];
        unsafe {
            gpu.device().get_query_pool_results(
                self.pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .call("vkGetQueryPoolResults")?;
        let period = f64::from(gpu.info().timestamp_period);
        Ok(plan
            .passes
            .iter()
            .enumerate()
            .map(|(i, pass)| PassTiming {
                pass: pass.name.clone(),
                kind: pass.kind,
                source: TimingSource::GpuTimestamp,
                ms: ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64 * period / 1e6,
            })
            .collect())
    }
}

impl Drop for QueryPool<'_> {
    fn drop(&mut self) {
        unsafe { self.gpu.device().destroy_query_pool(self.pool, None) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_a_labelled_table() {
        let timings = [
            PassTiming {
                pass: "tonemap".into(),
                kind: PassKind::Fullscreen,
                source: TimingSource::GpuTimestamp,
                ms: 1.25,
            },
            PassTiming {
                pass: "blur".into(),
                kind: PassKind::Compute,
                source: TimingSource::CpuWall,
                ms: 0.5,
            },
        ];
        assert_eq!(
            format_timings(&timings),
            "pass     kind               ms  measured by\n\
             tonemap  Fullscreen      1.250  gpu timestamp\n\
             blur     Compute         0.500  cpu wall (submit+wait)\n\
             total                    1.750\n"
        );
    }
}
