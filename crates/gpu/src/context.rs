//! A wgpu device for compute and offscreen work, on whatever adapter the machine has: a real GPU,
//! or lavapipe (Mesa's software Vulkan driver) in CI. Headless by default; [`Gpu::for_surface`]
//! picks an adapter that can also present to a window the caller made (the crate knows no
//! windowing library).

use crate::device::capture_errors;
use crate::error::GpuError;
use crate::merl_lookup::table_bytes;

/// An adapter, its device and its queue. Created once per process (a device on lavapipe takes
/// tens of milliseconds, a MERL table upload more); share it by reference.
#[derive(Debug)]
pub struct Gpu {
    adapter: wgpu::Adapter,
    info: wgpu::AdapterInfo,
    device: wgpu::Device,
    queue: wgpu::Queue,
}

impl Gpu {
    /// Opens the preferred adapter: Vulkan first (the backend CI runs on, through lavapipe), then
    /// a real GPU before a software one. `WGPU_BACKEND` and the other wgpu variables are honoured.
    ///
    /// The device asks for what the tools' passes need (wgpu's downlevel defaults, raised to the
    /// most storage buffers a previewer pass binds and to the adapter's sizes), and fails with
    /// [`GpuError::AdapterLimit`] if the adapter cannot bind a whole MERL table of the largest
    /// size (360 cells in `phi_d`, 35 MB as f32).
    pub fn new() -> Result<Gpu, GpuError> {
        pollster::block_on(Gpu::new_async())
    }

    async fn new_async() -> Result<Gpu, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Gpu::open(&instance, None, &|limits| limits).await
    }

    /// Opens the preferred adapter among `backends` as [`Gpu::new`] does (`WGPU_BACKEND` aside),
    /// with the limits it would ask for passed through `cap`: the GPU tests run the previewer on
    /// Mesa's GL (`wgpu::Backends::GL`) and stand in for a smaller adapter by lowering a limit.
    pub fn with_backends(
        backends: wgpu::Backends,
        cap: &dyn Fn(wgpu::Limits) -> wgpu::Limits,
    ) -> Result<Gpu, GpuError> {
        let descriptor =
            wgpu::InstanceDescriptor { backends, ..wgpu::InstanceDescriptor::new_without_display_handle_from_env() };
        pollster::block_on(Gpu::open(&wgpu::Instance::new(descriptor), None, cap))
    }

    /// Opens the preferred adapter of `instance` among those that can present to `surface` (a
    /// window's), by the same preference and with the same checks as [`Gpu::new`]. The instance
    /// must be the one the surface was created with. Fails with [`GpuError::NoPresentAdapter`]
    /// where adapters exist but none can present to the surface.
    pub fn for_surface(instance: &wgpu::Instance, surface: &wgpu::Surface<'_>) -> Result<Gpu, GpuError> {
        pollster::block_on(Gpu::open(instance, Some(surface), &|limits| limits))
    }

    async fn open(
        instance: &wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
        cap: &dyn Fn(wgpu::Limits) -> wgpu::Limits,
    ) -> Result<Gpu, GpuError> {
        let adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
        let found: Vec<String> = adapters.iter().map(|a| describe(&a.get_info())).collect();
        let need = table_bytes(merl::Dims::MERL_FULL_PHI);
        let adapter = adapters
            .into_iter()
            .filter(|a| surface.is_none_or(|s| a.is_surface_supported(s)))
            .max_by_key(|a| {
                let fits = check_buffer_fits(&a.limits(), &a.get_info(), need, "").is_ok();
                (fits, preference(&a.get_info()))
            })
            .ok_or_else(|| match (surface, found.is_empty()) {
                (Some(_), false) => GpuError::NoPresentAdapter { adapters: found.join(", ") },
                _ => GpuError::NoAdapter,
            })?;
        let info = adapter.get_info();
        let limits = cap(required_limits(&adapter.limits()));
        check_buffer_fits(&limits, &info, need, "a MERL table of 90 x 90 x 360 cells")?;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("gpu"),
                // Timestamps where the adapter has them: the adaptive frame's stages
                // (`preview::Renderer::render_adaptive`).
                required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
                required_limits: limits,
                ..Default::default()
            })
            .await
            .map_err(|error| GpuError::RequestDevice { adapter: describe(&info), error })?;
        Ok(Gpu { adapter, info, device, queue })
    }

    /// Configures `surface` (of the instance this device was opened from) for this device, with
    /// wgpu's validation errors (a surface whose window has gone, a configuration it does not
    /// support) returned as [`GpuError::Wgpu`] rather than wgpu's default of panicking.
    pub fn configure_surface(
        &self,
        surface: &wgpu::Surface<'_>,
        config: &wgpu::SurfaceConfiguration,
    ) -> Result<(), GpuError> {
        capture_errors(&self.device, || surface.configure(&self.device, config))
    }

    /// The adapter the device was opened on (for a surface's capabilities).
    pub fn adapter(&self) -> &wgpu::Adapter {
        &self.adapter
    }

    /// Name, backend and driver of the adapter, for tools and CI logs to say what ran.
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// One line naming the adapter, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu, Mesa
    /// 22.3.6)`.
    pub fn adapter_summary(&self) -> String {
        describe(&self.info)
    }

    pub fn device(&self) -> &wgpu::Device {
        &self.device
    }

    pub fn queue(&self) -> &wgpu::Queue {
        &self.queue
    }

    /// Waits until the work submitted so far has finished.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(())
    }

    /// The limits the device was created with (the adapter's own).
    pub fn limits(&self) -> wgpu::Limits {
        self.device.limits()
    }
}

pub(crate) fn describe(info: &wgpu::AdapterInfo) -> String {
    let driver = [info.driver.as_str(), info.driver_info.as_str()]
        .into_iter()
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join(" ");
    let mut s = format!("{} ({:?}, {:?}", info.name, info.backend, info.device_type);
    if !driver.is_empty() {
        s.push_str(", ");
        s.push_str(&driver);
    }
    s.push(')');
    s
}

/// Larger is better.
fn preference(info: &wgpu::AdapterInfo) -> (bool, u8) {
    let kind = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 4,
        wgpu::DeviceType::IntegratedGpu => 3,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 1,
        wgpu::DeviceType::Other => 0,
    };
    (info.backend == wgpu::Backend::Vulkan, kind)
}

/// The limits a device asks of `adapter`: wgpu's downlevel defaults (what Mesa's GL and WebGPU's
/// compute-capable adapters offer), raised to what the passes need where it is more, and to the
/// adapter's own for the sizes that follow the work (buffers, the image's side, dispatches): the
/// most storage buffers a previewer pass binds per shader stage
/// ([`crate::preview::most_storage_buffers`]), fewer where the adapter has fewer (the modes that
/// need more then fail with the limit, and the others run).
pub(crate) fn required_limits(adapter: &wgpu::Limits) -> wgpu::Limits {
    wgpu::Limits {
        max_storage_buffers_per_shader_stage: crate::preview::most_storage_buffers(),
        max_storage_buffer_binding_size: adapter.max_storage_buffer_binding_size,
        max_buffer_size: adapter.max_buffer_size,
        max_texture_dimension_2d: adapter.max_texture_dimension_2d,
        max_compute_workgroups_per_dimension: adapter.max_compute_workgroups_per_dimension,
        ..wgpu::Limits::downlevel_defaults()
    }
    .or_worse_values_from(adapter)
}

/// Whether one buffer of `bytes` can be created and bound whole as a storage buffer.
pub(crate) fn check_buffer_fits(
    limits: &wgpu::Limits,
    info: &wgpu::AdapterInfo,
    bytes: u64,
    what: &'static str,
) -> Result<(), GpuError> {
    let checks = [
        ("max_storage_buffer_binding_size", limits.max_storage_buffer_binding_size),
        ("max_buffer_size", limits.max_buffer_size),
    ];
    for (limit, have) in checks {
        if have < bytes {
            return Err(GpuError::AdapterLimit { adapter: describe(info), limit, have, need: bytes, what });
        }
    }
    Ok(())
}
