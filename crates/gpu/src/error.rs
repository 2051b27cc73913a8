//! Why GPU work failed, split by who can fix it: the machine (no adapter, too small an adapter)
//! or the GPU and its driver at run time.

/// An error from [`crate::Gpu`], [`crate::MerlLookup`], [`crate::preview::Renderer`] or
/// [`crate::preview::Presenter`]. Messages
/// are lower case and say what to do where something can be done.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter on any backend: the machine has no GPU driver, not even a software one.
    #[error(
        "no GPU adapter found: on Debian/Ubuntu install the software Vulkan driver with \
         'apt-get install mesa-vulkan-drivers libvulkan1' (lavapipe), and leave WGPU_BACKEND unset"
    )]
    NoAdapter,
    /// Adapters exist, but none can present to the window's surface (`Gpu::for_surface`).
    #[error("no GPU adapter can present to the window (adapters found: {adapters})")]
    NoPresentAdapter { adapters: String },
    /// The adapter cannot hold a buffer or a texture as large as the work needs. `have` and `need`
    /// are in the limit's unit: bytes for buffers, texels for a texture's side.
    #[error("adapter {adapter}: {limit} is {have}, {what} needs {need}")]
    AdapterLimit { adapter: String, limit: &'static str, have: u64, need: u64, what: &'static str },
    #[error("adapter {adapter}: requesting a device: {error}")]
    RequestDevice { adapter: String, error: wgpu::RequestDeviceError },
    /// The previewer's inputs are inconsistent or beyond its limits: the scene, material,
    /// lighting or settings that `render::render` rejects, with its error.
    #[error(transparent)]
    Scene(#[from] render::Error),
    /// Validation, out-of-memory or internal error reported by wgpu while creating or running work.
    #[error("wgpu: {0}")]
    Wgpu(wgpu::Error),
    #[error("waiting for the GPU: {0}")]
    Poll(#[from] wgpu::PollError),
    #[error("reading results back from the GPU: {0}")]
    Readback(String),
    /// A window's surface could not be made, configured or drawn into (`surface::WindowSurface`).
    #[error("{0}")]
    Surface(String),
    /// `preview::Presenter` draws 8-bit RGBA or BGRA targets (plain or sRGB) only.
    #[error("the presenter draws into 8-bit RGBA or BGRA targets, not {0:?}")]
    TargetFormat(wgpu::TextureFormat),
}
