//! GPU pass timings (`--profile`): a timestamp at the beginning and end of every pass, read back
//! in batches and summed per pass label.
//!
//! A pass's time is `(end − begin) · period` where `period` is the queue's timestamp period
//! in nanoseconds per tick. Timestamps bracket the GPU's execution of the pass, so the sum
//! over the labels is the GPU time of the work; the gap to the wall-clock time is submission,
//! synchronisation and CPU work. On adapters without `TIMESTAMP_QUERY` there is no profiler
//! and callers print wall-clock time only.

use std::sync::{Arc, Mutex};

use crate::error::{Error, Result};

/// Timestamp queries in the set: begin and end of up to half as many passes between reads.
const CAPACITY: u32 = 2048;

/// Collects per-pass GPU times. Cloning is cheap: clones share the query set and the sums.
#[derive(Clone)]
pub struct Profiler(Arc<Inner>);

struct Inner {
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Nanoseconds per timestamp tick.
    period: f32,
    state: Mutex<State>,
}

#[derive(Default)]
struct State {
    /// Label of each begin/end pair written since the last read, in query order.
    pending: Vec<&'static str>,
    /// Sum of times per label, in order of first appearance.
    totals: Vec<PassTime>,
    /// Passes not timed because the query set was full.
    dropped: u64,
}

/// The summed GPU time of one pass label.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTime {
    pub label: &'static str,
    /// Passes with this label.
    pub count: u64,
    /// Their total GPU time, in seconds.
    pub seconds: f64,
}

impl std::fmt::Debug for Profiler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Profiler")
    }
}

impl Profiler {
    /// A profiler on `device`, or `None` if it was opened without `TIMESTAMP_QUERY`.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Profiler> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let query_set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: CAPACITY,
        });
        let bytes = CAPACITY as u64 * 8;
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp resolve"),
            size: bytes,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let period = queue.get_timestamp_period();
        // Natively `Inner` is Send and Sync; wgpu's WebGPU handles are neither (one thread).
        #[cfg_attr(target_arch = "wasm32", allow(clippy::arc_with_non_send_sync))]
        Some(Profiler(Arc::new(Inner { query_set, resolve, readback, period, state: Mutex::default() })))
    }

    /// Reserves the begin/end query pair of one pass labelled `label`.
    fn pair(&self, label: &'static str) -> Option<u32> {
        let mut s = self.0.state.lock().expect("profiler state");
        if 2 * (s.pending.len() as u32 + 1) > CAPACITY {
            s.dropped += 1;
            return None;
        }
        s.pending.push(label);
        Some(2 * (s.pending.len() as u32 - 1))
    }

    /// Timestamp writes for a compute pass labelled `label`.
    pub fn compute(&self, label: &'static str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.pair(label).map(|i| wgpu::ComputePassTimestampWrites {
            query_set: &self.0.query_set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        })
    }

    /// Timestamp writes for a render pass labelled `label`.
    pub fn render(&self, label: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.pair(label).map(|i| wgpu::RenderPassTimestampWrites {
            query_set: &self.0.query_set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        })
    }

    /// Whether the query set is more than half used (time to [`collect`](Self::collect)).
    pub fn half_full(&self) -> bool {
        let s = self.0.state.lock().expect("profiler state");
        4 * s.pending.len() as u32 >= CAPACITY
    }

    /// Reads the timestamps of the submitted passes back and adds them to the sums. Blocks
    /// until the GPU has finished the work submitted so far.
    pub fn collect(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<()> {
        let mut s = self.0.state.lock().expect("profiler state");
        let n = 2 * s.pending.len() as u32;
        if n == 0 {
            return Ok(());
        }
        let inner = &self.0;
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("timestamps") });
        enc.resolve_query_set(&inner.query_set, 0..n, &inner.resolve, 0);
        enc.copy_buffer_to_buffer(&inner.resolve, 0, &inner.readback, 0, n as u64 * 8);
        queue.submit([enc.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        let bytes = n as u64 * 8;
        inner.readback.map_async(wgpu::MapMode::Read, ..bytes, move |r| {
            let _ = tx.send(r);
        });
        device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(e.to_string()))?;
        rx.recv()
            .map_err(|e| Error::Gpu(e.to_string()))?
            .map_err(|e| Error::Gpu(format!("mapping the timestamp buffer failed: {e}")))?;
        let ticks: Vec<u64> = {
            let view = inner.readback.get_mapped_range(..bytes).map_err(|e| Error::Gpu(e.to_string()))?;
            bytemuck::cast_slice(&view).to_vec()
        };
        inner.readback.unmap();
        let pending = std::mem::take(&mut s.pending);
        for (k, label) in pending.into_iter().enumerate() {
            let dt = ticks[2 * k + 1].saturating_sub(ticks[2 * k]) as f64 * inner.period as f64 * 1e-9;
            match s.totals.iter_mut().find(|t| t.label == label) {
                Some(t) => {
                    t.count += 1;
                    t.seconds += dt;
                }
                None => s.totals.push(PassTime { label, count: 1, seconds: dt }),
            }
        }
        Ok(())
    }

    /// Collects outstanding timestamps and returns the sums per label (first appearance first)
    /// and the number of passes that were not timed.
    pub fn report(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<(Vec<PassTime>, u64)> {
        self.collect(device, queue)?;
        let s = self.0.state.lock().expect("profiler state");
        Ok((s.totals.clone(), s.dropped))
    }

    /// Forgets the sums (e.g. after warm-up iterations).
    pub fn clear(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<()> {
        self.collect(device, queue)?;
        let mut s = self.0.state.lock().expect("profiler state");
        s.totals.clear();
        s.dropped = 0;
        Ok(())
    }
}

/// A table of pass times: label, passes, total ms, ms per `per` (e.g. iterations), share.
pub fn table(times: &[PassTime], per: u64, per_name: &str) -> String {
    use std::fmt::Write as _;
    let total: f64 = times.iter().map(|t| t.seconds).sum();
    let per = per.max(1) as f64;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<22} {:>8} {:>11} {:>13} {:>7}",
        "pass",
        "passes",
        "total ms",
        format!("ms/{per_name}"),
        "share"
    );
    for t in times {
        let _ = writeln!(
            s,
            "{:<22} {:>8} {:>11.2} {:>13.3} {:>6.1}%",
            t.label,
            t.count,
            1e3 * t.seconds,
            1e3 * t.seconds / per,
            100.0 * t.seconds / total.max(1e-30)
        );
    }
    let _ =
        write!(s, "{:<22} {:>8} {:>11.2} {:>13.3} {:>6.1}%", "GPU total", "", 1e3 * total, 1e3 * total / per, 100.0);
    s
}

/// Begins a compute pass labelled `label`, timed when `profiler` is given.
pub fn compute_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    profiler: Option<&Profiler>,
    label: &'static str,
) -> wgpu::ComputePass<'e> {
    let timestamp_writes = profiler.and_then(|p| p.compute(label));
    enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes })
}

/// A render pass into `color` with its operations and, where given, a depth target cleared to
/// 0 (reversed Z: the nearest surface has the largest depth) and discarded after the pass;
/// timed under `label` where `profiler` is given.
pub fn render_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    profiler: Option<&Profiler>,
    label: &'static str,
    (color, ops): (&wgpu::TextureView, wgpu::Operations<wgpu::Color>),
    depth: Option<&wgpu::TextureView>,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
            depth_slice: None,
            resolve_target: None,
            ops,
        })],
        depth_stencil_attachment: depth.map(|view| wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Discard }),
            stencil_ops: None,
        }),
        timestamp_writes: profiler.and_then(|p| p.render(label)),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}
