//! Why GPU work failed, split by who can fix it: the machine (no adapter, too small an adapter)
//! or the GPU and its driver at run time.

/// An error from [`crate::Gpu`] or [`crate::MerlLookup`]. Messages are lower case and say what
/// to do where something can be done.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter on any backend: the machine has no GPU driver, not even a software one.
    #[error(
        "no GPU adapter found: on Debian/Ubuntu install the software Vulkan driver with \
         'apt-get install mesa-vulkan-drivers libvulkan1' (lavapipe), and leave WGPU_BACKEND unset"
    )]
    NoAdapter,
    /// The adapter cannot hold a buffer as large as the work needs.
    #[error("adapter {adapter}: {limit} is {have} bytes, {what} needs {need}")]
    AdapterLimit { adapter: String, limit: &'static str, have: u64, need: u64, what: &'static str },
    #[error("adapter {adapter}: requesting a device: {error}")]
    RequestDevice { adapter: String, error: wgpu::RequestDeviceError },
    /// Validation, out-of-memory or internal error reported by wgpu while creating or running work.
    #[error("wgpu: {0}")]
    Wgpu(wgpu::Error),
    #[error("waiting for the GPU: {0}")]
    Poll(#[from] wgpu::PollError),
    #[error("reading results back from the GPU: {0}")]
    Readback(String),
}
