//! A window's surface for the previewer: made on the display the window is on, with a device
//! that can present to it, configured for [`crate::preview::Presenter`]'s formats, and kept
//! usable across resizes and lost surfaces. The window is the caller's (any type with
//! raw-window-handle's window and display handles, e.g. a winit window behind an `Arc`): the
//! crate knows no windowing library.
//!
//! The surface format is a plain 8-bit one where the adapter offers one, so that the present pass
//! writes the picture's sRGB-encoded bytes itself and the window shows the picture's bytes; an
//! sRGB-only surface encodes in hardware, within one 8-bit step of them. The present mode is FIFO,
//! the one every surface supports (lavapipe presents to Xvfb with it).

use std::sync::Arc;

use crate::Gpu;
use crate::error::GpuError;
use crate::preview::{Presenter, Renderer};

/// Redraws in a row that may get no surface texture (timeouts, a surface reconfigured or made
/// again) before [`WindowSurface::acquire`] gives up: a resize takes one or two; a surface that
/// stays lost would otherwise redraw forever.
pub const MAX_SKIPPED: u32 = 100;

/// The display windows are on (the instance their surfaces are made with).
#[derive(Debug)]
pub struct Display {
    instance: wgpu::Instance,
}

impl Display {
    /// The display `handle` names (winit's `EventLoop::owned_display_handle`); only GLES uses
    /// it, Vulkan ignores it. The wgpu environment variables (`WGPU_BACKEND`, ...) are honoured.
    pub fn new(handle: impl wgpu::rwh::HasDisplayHandle + std::fmt::Debug + Send + Sync + 'static) -> Display {
        let descriptor = wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(handle));
        Display { instance: wgpu::Instance::new(descriptor) }
    }
}

/// A window's configured surface.
pub struct WindowSurface {
    instance: wgpu::Instance,
    /// Makes the window's surface again (after it was lost).
    remake: Remake,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// Acquisitions in a row that gave no texture.
    skipped: u32,
}

type Remake = Box<dyn Fn(&wgpu::Instance) -> Result<wgpu::Surface<'static>, wgpu::CreateSurfaceError>>;

/// One texture of the surface to draw into and present.
#[derive(Debug)]
pub struct SurfaceFrame {
    texture: wgpu::SurfaceTexture,
    readable: bool,
}

impl std::fmt::Debug for WindowSurface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WindowSurface").field("config", &self.config).field("skipped", &self.skipped).finish()
    }
}

impl WindowSurface {
    /// The surface of `window` (`size`: its inner size in pixels) on `display`, and a device that
    /// can present to it (`Gpu::for_surface`). With `readable` the surface is asked to be
    /// readable too, where it can be (screenshots then read what the window shows).
    pub fn new<W: wgpu::rwh::HasWindowHandle + wgpu::rwh::HasDisplayHandle + Send + Sync + 'static>(
        display: &Display,
        window: Arc<W>,
        size: (u32, u32),
        readable: bool,
    ) -> Result<(WindowSurface, Gpu), GpuError> {
        let instance = display.instance.clone();
        let remake: Remake = Box::new(move |instance| instance.create_surface(window.clone()));
        let surface =
            remake(&instance).map_err(|e| GpuError::Surface(format!("creating the window's surface: {e}")))?;
        let gpu = Gpu::for_surface(&instance, &surface)?;
        let caps = surface.get_capabilities(gpu.adapter());
        let format = surface_format(&caps.formats).ok_or_else(|| {
            GpuError::Surface(format!(
                "the window's surface offers none of the 8-bit RGBA or BGRA formats the previewer draws: {:?}",
                caps.formats
            ))
        })?;
        let usage = if readable && caps.usages.contains(wgpu::TextureUsages::COPY_SRC) {
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC
        } else {
            wgpu::TextureUsages::RENDER_ATTACHMENT
        };
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            color_space: Default::default(),
            width: size.0.max(1),
            height: size.1.max(1),
            present_mode: wgpu::PresentMode::Fifo,
            desired_maximum_frame_latency: 2,
            alpha_mode: if caps.alpha_modes.contains(&wgpu::CompositeAlphaMode::Opaque) {
                wgpu::CompositeAlphaMode::Opaque
            } else {
                wgpu::CompositeAlphaMode::Auto
            },
            view_formats: vec![],
        };
        gpu.configure_surface(&surface, &config)?;
        Ok((WindowSurface { instance, remake, surface, config, skipped: 0 }, gpu))
    }

    /// The surface's texture format (what a [`Presenter`] for it is made with).
    pub fn format(&self) -> wgpu::TextureFormat {
        self.config.format
    }

    /// Whether screenshots read the surface itself (else they draw the same picture offscreen).
    pub fn readable(&self) -> bool {
        self.config.usage.contains(wgpu::TextureUsages::COPY_SRC)
    }

    /// A description for logs: the format, and where a screenshot is read from.
    pub fn describe(&self) -> String {
        let read = if self.readable() { "the surface" } else { "an offscreen copy" };
        format!("surface {:?}, screenshots read from {read}", self.config.format)
    }

    /// Configures the surface for a new size. A minimized window reports 0 x 0, which no surface
    /// takes: the last size is kept; returns whether the size changed.
    pub fn resize(&mut self, gpu: &Gpu, size: (u32, u32)) -> Result<bool, GpuError> {
        if size.0 == 0 || size.1 == 0 {
            return Ok(false);
        }
        self.config.width = size.0;
        self.config.height = size.1;
        gpu.configure_surface(&self.surface, &self.config)?;
        Ok(true)
    }

    /// The surface's next texture, or `None` where this redraw has to be skipped; configures an
    /// outdated surface again (for the size the last resize gave, not asked of the window, which
    /// cannot answer once it is gone), makes a lost one again, and gives up after
    /// [`MAX_SKIPPED`] skips in a row.
    pub fn acquire(&mut self, gpu: &Gpu) -> Result<Option<SurfaceFrame>, GpuError> {
        let texture = self.try_acquire(gpu)?;
        self.skipped = if texture.is_some() { 0 } else { self.skipped + 1 };
        if self.skipped > MAX_SKIPPED {
            return Err(GpuError::Surface(format!(
                "the window's surface gave no texture to draw into {MAX_SKIPPED} times in a row"
            )));
        }
        let readable = self.readable();
        Ok(texture.map(|texture| SurfaceFrame { texture, readable }))
    }

    fn try_acquire(&mut self, gpu: &Gpu) -> Result<Option<wgpu::SurfaceTexture>, GpuError> {
        use wgpu::CurrentSurfaceTexture as Current;
        match self.surface.get_current_texture() {
            Current::Success(texture) => Ok(Some(texture)),
            Current::Timeout | Current::Occluded => Ok(None),
            // The surface changed (a resize under way): the texture must go before configuring.
            Current::Suboptimal(texture) => {
                drop(texture);
                gpu.configure_surface(&self.surface, &self.config)?;
                Ok(None)
            }
            Current::Outdated => {
                gpu.configure_surface(&self.surface, &self.config)?;
                Ok(None)
            }
            Current::Lost => {
                self.surface = (self.remake)(&self.instance)
                    .map_err(|e| GpuError::Surface(format!("creating the window's surface again: {e}")))?;
                gpu.configure_surface(&self.surface, &self.config)?;
                Ok(None)
            }
            Current::Validation => Err(GpuError::Surface("the window's surface reported a validation error".into())),
        }
    }
}

impl SurfaceFrame {
    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.texture.texture.width(), self.texture.texture.height())
    }

    /// Draws what `renderer` has accumulated into the frame at `exposure_ev` stops.
    pub fn draw(&self, presenter: &Presenter, renderer: &Renderer, exposure_ev: f32) -> Result<(), GpuError> {
        let view = self.texture.texture.create_view(&Default::default());
        presenter.draw(renderer, &view, self.size(), exposure_ev)
    }

    /// What the frame shows, 8-bit RGB: read from the surface where it is readable, else the
    /// same picture drawn offscreen.
    pub fn read_rgb8(&self, presenter: &Presenter, renderer: &Renderer, exposure_ev: f32) -> Result<Vec<u8>, GpuError> {
        match self.readable {
            true => presenter.read_rgb8(&self.texture.texture),
            false => presenter.draw_rgb8(renderer, self.size(), exposure_ev),
        }
    }

    /// Shows the frame in the window.
    pub fn present(self, gpu: &Gpu) {
        gpu.queue().present(self.texture);
    }
}

/// The surface format to draw: a plain 8-bit one where offered, into which the present pass
/// writes the picture's sRGB-encoded bytes itself; else an sRGB one, which encodes in hardware.
pub fn surface_format(offered: &[wgpu::TextureFormat]) -> Option<wgpu::TextureFormat> {
    use wgpu::TextureFormat as F;
    [F::Bgra8Unorm, F::Rgba8Unorm, F::Bgra8UnormSrgb, F::Rgba8UnormSrgb].into_iter().find(|f| offered.contains(f))
}

#[cfg(test)]
mod tests {
    use super::surface_format;

    #[test]
    fn a_plain_surface_format_is_preferred_to_an_srgb_one() {
        use wgpu::TextureFormat as F;
        assert_eq!(surface_format(&[F::Bgra8UnormSrgb, F::Bgra8Unorm]), Some(F::Bgra8Unorm));
        assert_eq!(surface_format(&[F::Rgba16Float, F::Rgba8UnormSrgb]), Some(F::Rgba8UnormSrgb));
        assert_eq!(surface_format(&[F::Rgb10a2Unorm]), None);
    }
}
