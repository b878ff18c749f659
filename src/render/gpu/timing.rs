//! Frame timing: warm-up and timed frames over the same resources, read from GPU timestamp
//! queries around each pass where the adapter has them, else from the host's wall clock.

use super::resources::FrameResources;
use super::GpuBackend;
use crate::render::{plan::RenderPlan, Clock, Timing, View};
use std::time::Instant;

impl GpuBackend {
    /// `warmup` untimed and `repeats` timed frames over the same resources.
    pub(super) fn time_frames(
        &mut self,
        r: &FrameResources,
        view: View,
        plan: &RenderPlan,
        warmup: u32,
        repeats: u32,
    ) -> anyhow::Result<Timing> {
        let (mut seconds, mut primary_seconds) = (Vec::new(), Vec::new());
        for i in 0..warmup + repeats {
            let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
            let mut encoder = self.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, r, view, plan);
            let start = Instant::now();
            self.submit(encoder, scope)?;
            let wall = start.elapsed().as_secs_f64();
            let passes = self.frame_seconds(r)?;
            if i >= warmup {
                seconds.push(passes.map_or(wall, |p| p.0));
                primary_seconds.extend(passes.map(|p| p.1));
            }
        }
        Ok(Timing {
            seconds,
            primary_seconds,
            clock: if self.timestamps {
                Clock::GpuTimestamp
            } else {
                Clock::WallClock
            },
        })
    }

    /// (whole frame, primary pass) seconds from the timestamps around each pass.
    fn frame_seconds(&self, r: &FrameResources) -> anyhow::Result<Option<(f64, f64)>> {
        let Some((set, resolve)) = &r.queries else {
            return Ok(None);
        };
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.resolve_query_set(set, 0..set_count(resolve), resolve, 0);
        self.submit(encoder, self.device.push_error_scope(wgpu::ErrorFilter::Validation))?;
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&self.read(resolve, resolve.size())?);
        let (first, last) = (ticks[0], ticks[ticks.len() - 1]);
        let period = self.queue.get_timestamp_period() as f64;
        let seconds = |a: u64, b: u64| b.saturating_sub(a) as f64 * period * 1e-9;
        Ok(Some((seconds(first, last), seconds(ticks[0], ticks[1]))))
    }
}

/// Timestamps a resolve buffer holds.
fn set_count(resolve: &wgpu::Buffer) -> u32 {
    (resolve.size() / 8) as u32
}
