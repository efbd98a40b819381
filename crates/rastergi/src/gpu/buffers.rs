//! Buffers: creating them, and reading buffers and textures back to the CPU.

use crate::error::{Error, Result};
use crate::gpu::Gpu;

impl Gpu {
    /// A storage buffer initialised with `data`.
    pub fn storage_buffer(&self, label: &str, data: &[u8], extra: wgpu::BufferUsages) -> wgpu::Buffer {
        // Zero-sized bindings are invalid: keep at least 16 bytes.
        let size = (data.len() as u64).max(16).next_multiple_of(4);
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
            mapped_at_creation: true,
        });
        // Not mappable only on a lost device: the buffer is invalid then, and the next wait
        // reports the loss (Gpu::check).
        if let Ok(mut view) = buffer.get_mapped_range_mut(..) {
            view.slice(..data.len()).copy_from_slice(data);
        }
        buffer.unmap();
        buffer
    }

    /// A zero-initialised buffer.
    pub fn zeroed_buffer(&self, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16).next_multiple_of(4),
            usage,
            mapped_at_creation: false,
        })
    }

    /// Copies `size` bytes from the start of `buffer` (which needs COPY_SRC) back to the CPU.
    /// Blocks until the GPU has finished: natively only; a web page awaits
    /// [`read_buffer_async`](Self::read_buffer_async) (see [`block_on`]).
    pub fn read_buffer(&self, buffer: &wgpu::Buffer, size: u64) -> Result<Vec<u8>> {
        block_on(self.read_buffer_async(buffer, size))
    }

    /// [`read_buffer`](Self::read_buffer) as a future. The copy is submitted at once (the
    /// future holds no borrow: it reads the buffer as it is now). Natively the future waits for
    /// the GPU in `device.poll`; in a browser `map_async` answers only once control has
    /// returned to the event loop, so the future is pending until then.
    pub fn read_buffer_async(
        &self,
        buffer: &wgpu::Buffer,
        size: u64,
    ) -> impl std::future::Future<Output = Result<Vec<u8>>> + 'static {
        let staging = self.zeroed_buffer("readback", size, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        let mut enc = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
        enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([enc.finish()]);
        let (tx, rx) = futures_channel::oneshot::channel();
        staging.map_async(wgpu::MapMode::Read, ..size, move |r| {
            let _ = tx.send(r);
        });
        let gpu = self.clone();
        async move {
            // A no-op on WebGPU, where the browser maps the buffer on its own.
            gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(e.to_string()))?;
            let mapped = rx.await;
            gpu.check()?;
            mapped
                .map_err(|_| Error::Gpu("the GPU dropped a read-back before it finished".into()))?
                .map_err(|e| Error::Gpu(format!("mapping a readback buffer failed: {e}")))?;
            let data = staging.get_mapped_range(..size).map_err(|e| Error::Gpu(e.to_string()))?.to_vec();
            staging.unmap();
            Ok(data)
        }
    }

    /// Copies every texel of mip level 0 of `texture` (which needs COPY_SRC) back to the CPU:
    /// `texel_bytes` per texel, rows and layers tightly packed (the copy's row padding dropped).
    pub fn read_texture(&self, texture: &wgpu::Texture, texel_bytes: u32) -> Result<Vec<u8>> {
        let size = texture.size();
        let (w, rows) = (size.width, size.height * size.depth_or_array_layers);
        let tight = (w * texel_bytes) as usize;
        let row = (w * texel_bytes).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = self.zeroed_buffer(
            "texture readback",
            row as u64 * rows as u64,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(size.height),
                },
            },
            size,
        );
        self.queue.submit([enc.finish()]);
        let bytes = self.read_buffer(&buffer, buffer.size())?;
        Ok(bytes.chunks(row as usize).take(rows as usize).flat_map(|r| &r[..tight]).copied().collect())
    }
}

/// Whether a read-back may block until the GPU has finished: not in a web page, where only
/// the asynchronous read-backs work. The balanced photon budget and the photon guide read
/// their measurements back between iterations, so a web page renders without them (the
/// fitted budget, unguided photons).
pub const READ_BACK_BLOCKS: bool = !cfg!(target_arch = "wasm32");

/// Runs a read-back's future to its end. Natively it blocks (the future waits for the GPU in
/// `device.poll`). A browser cannot block: there the answer arrives only after control returns
/// to its event loop, so a future that is not ready at once is an error that names the
/// asynchronous twin to await instead.
pub fn block_on<T>(future: impl std::future::Future<Output = Result<T>>) -> Result<T> {
    #[cfg(not(target_arch = "wasm32"))]
    {
        pollster::block_on(future)
    }
    #[cfg(target_arch = "wasm32")]
    {
        let mut future = std::pin::pin!(future);
        let mut cx = std::task::Context::from_waker(std::task::Waker::noop());
        match future.as_mut().poll(&mut cx) {
            std::task::Poll::Ready(r) => r,
            std::task::Poll::Pending => Err(Error::Gpu(
                "a read-back from the GPU cannot block in a web page; await its asynchronous twin (read_buffer_async, read_state_async, read_display_async)".into(),
            )),
        }
    }
}
