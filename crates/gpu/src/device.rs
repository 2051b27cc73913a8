//! Helpers around a wgpu device that the whole crate uses: its errors captured as
//! [`GpuError`]s, buffers made, and buffers mapped and read back.

use std::sync::mpsc;

use bytemuck::Pod;

use crate::error::GpuError;

/// A buffer of `size` bytes for `usage`, not mapped at creation.
pub(crate) fn buffer(device: &wgpu::Device, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
}

/// A buffer of `size` bytes that a copy fills and the host maps to read ([`read_back`]).
pub(crate) fn readback_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    buffer(device, label, size, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST)
}

/// A uniform buffer of `size` bytes that the queue writes.
pub(crate) fn uniform_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    buffer(device, label, size, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST)
}

/// Maps the first `bytes` of `buffer`, waits for the GPU, and copies them out.
pub(crate) fn read_back<T: Pod>(device: &wgpu::Device, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<T>, GpuError> {
    // Copies through an aligned vector: the mapped bytes carry no alignment promise.
    read_back_with(device, buffer, bytes, bytemuck::pod_collect_to_vec)
}

/// `f` of the first `bytes` of `buffer` (`MAP_READ`), mapped once the device is done with it:
/// a reader that converts as it copies reads the bytes once.
pub(crate) fn read_back_with<R>(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    bytes: u64,
    f: impl FnOnce(&[u8]) -> R,
) -> Result<R, GpuError> {
    let slice = buffer.slice(..bytes);
    let (sender, receiver) = mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        // The receiver outlives the poll below; a send can only fail if it has panicked.
        let _ = sender.send(result);
    });
    device.poll(wgpu::PollType::wait_indefinitely())?;
    receiver
        .recv()
        .map_err(|_| GpuError::Readback("the map callback did not run".into()))?
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let values = {
        let view = slice.get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?;
        f(&view)
    };
    buffer.unmap();
    Ok(values)
}

/// Runs `f` with wgpu's errors captured, so that a validation or out-of-memory error becomes a
/// [`GpuError`] instead of wgpu's default of panicking.
pub(crate) fn capture_errors<T>(device: &wgpu::Device, f: impl FnOnce() -> T) -> Result<T, GpuError> {
    let scopes = [wgpu::ErrorFilter::Validation, wgpu::ErrorFilter::OutOfMemory, wgpu::ErrorFilter::Internal]
        .map(|filter| device.push_error_scope(filter));
    let value = f();
    // Scopes pop innermost first.
    let errors: Vec<Option<wgpu::Error>> =
        scopes.into_iter().rev().map(|scope| pollster::block_on(scope.pop())).collect();
    match errors.into_iter().flatten().next() {
        Some(error) => Err(GpuError::Wgpu(error)),
        None => Ok(value),
    }
}
