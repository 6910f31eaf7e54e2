//! GPU time of repeated dispatches from timestamp queries: one submission
//! holds every repetition, each bracketed by two timestamps and separated
//! from the next by a barrier, so the numbers are device time only (no
//! submission, fence or host wake-up in them).

use super::context::Shared;
use super::error::{vk_err, Error, Result};
use ash::vk;

/// Records `repeats` dispatches (`dispatch` records one; `bind` runs once
/// first; `before` before each one, outside its timestamps) and returns
/// each one's device time in nanoseconds. `stage` is the shader stage the
/// dispatches run in, for the barrier between them.
pub(crate) fn timed_dispatches(
    shared: &Shared,
    repeats: u32,
    stage: vk::PipelineStageFlags,
    bind: impl Fn(vk::CommandBuffer),
    before: impl Fn(vk::CommandBuffer),
    dispatch: impl Fn(vk::CommandBuffer),
) -> Result<Vec<f64>> {
    let ts = shared.timestamps;
    if ts.valid_bits == 0 {
        return Err(Error::Invalid(
            "the queue writes no timestamps (timestampValidBits is 0)".into(),
        ));
    }
    if repeats == 0 {
        return Ok(Vec::new());
    }
    let count = 2 * repeats;
    let info = vk::QueryPoolCreateInfo::default()
        .query_type(vk::QueryType::TIMESTAMP)
        .query_count(count);
    // SAFETY: valid device.
    let pool = unsafe { shared.device.create_query_pool(&info, None) }
        .map_err(vk_err("vkCreateQueryPool"))?;
    let d = &shared.device;
    let submitted = shared.submit("timed dispatches", |cmd| {
        // SAFETY: cmd is recording; the pool lives until after the wait.
        unsafe {
            d.cmd_reset_query_pool(cmd, pool, 0, count);
            bind(cmd);
            // Each dispatch rewrites the image: without a barrier they could
            // overlap and the brackets would not time one dispatch each.
            let barrier = vk::MemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::SHADER_WRITE)
                .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
            for i in 0..repeats {
                if i > 0 {
                    d.cmd_pipeline_barrier(
                        cmd,
                        stage,
                        stage,
                        vk::DependencyFlags::empty(),
                        &[barrier],
                        &[],
                        &[],
                    );
                }
                before(cmd);
                d.cmd_write_timestamp(cmd, vk::PipelineStageFlags::TOP_OF_PIPE, pool, 2 * i);
                dispatch(cmd);
                d.cmd_write_timestamp(cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, pool, 2 * i + 1);
            }
        }
    });
    let result = submitted.and_then(|_| {
        let mut ticks = vec![0u64; count as usize];
        // SAFETY: the submission finished; every query was written.
        unsafe {
            d.get_query_pool_results(
                pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .map_err(vk_err("vkGetQueryPoolResults"))?;
        Ok(durations(&ticks, ts.valid_bits, ts.period_ns))
    });
    if !shared.hung() {
        // SAFETY: the submission using the pool is done.
        unsafe { d.destroy_query_pool(pool, None) };
    }
    result
}

/// Pairs of (start, end) ticks to nanoseconds; the counter keeps only
/// `valid_bits` and may wrap once between the two.
fn durations(ticks: &[u64], valid_bits: u32, period_ns: f32) -> Vec<f64> {
    let mask = if valid_bits >= 64 {
        u64::MAX
    } else {
        (1u64 << valid_bits) - 1
    };
    ticks
        .chunks_exact(2)
        .map(|p| ((p[1] & mask).wrapping_sub(p[0] & mask) & mask) as f64 * f64::from(period_ns))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::durations;

    #[test]
    fn ticks_become_nanoseconds_across_a_wrap() {
        assert_eq!(durations(&[10, 30, 5, 6], 64, 1.0), [20.0, 1.0]);
        // A 32-bit counter wrapping between the two timestamps.
        assert_eq!(durations(&[0xFFFF_FFF0, 0x10], 32, 2.0), [64.0]);
        // Bits above the valid ones are ignored.
        assert_eq!(durations(&[1 << 40 | 3, 7], 32, 0.5), [2.0]);
    }
}
