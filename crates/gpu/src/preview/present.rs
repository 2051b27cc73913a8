//! The present pass (`preview_present.wgsl`): a [`Renderer`]'s running average, tone mapped like
//! `envmap::tonemap_rgb8`, drawn into a window's surface texture or an offscreen texture, and
//! the read-back of such a texture as 8-bit RGB (a screenshot).

use bytemuck::{Pod, Zeroable};

use super::{Renderer, View, storage_entry, uniform_entry};
use crate::context::Gpu;
use crate::device::{capture_errors, read_back};
use crate::error::GpuError;

/// Entries of the palette (`palette` in the WGSL).
const PALETTE_SIZE: usize = 256;

/// Rows of a texture copied into a buffer start at multiples of this many bytes.
const ROW_ALIGNMENT: u32 = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;

/// `Present` of the WGSL.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct PresentUniform {
    pub(crate) image_size: [u32; 2],
    pub(crate) frames: u32,
    pub(crate) view: u32,
    pub(crate) exposure: f32,
    pub(crate) srgb_target: u32,
    pub(crate) n_indices: u32,
    pub(crate) _pad: u32,
    pub(crate) origin: [f32; 2],
    pub(crate) scale: f32,
    pub(crate) _pad2: f32,
}

/// `VIEW_*` of the WGSL.
fn view_index(view: View) -> u32 {
    match view {
        View::Shaded => 0,
        View::Normal => 1,
        View::Layer => 2,
        View::Slice => 3,
    }
}

/// Draws what a [`Renderer`] has accumulated into textures of one format: radiance tone mapped
/// exactly as `envmap::tonemap_rgb8` maps pictures (exposure `2^ev`, Reinhard's `x / (1 + x)`
/// per channel, the sRGB transfer function; an sRGB target's own encoding is used, not applied
/// twice), the debug views in false colour (the WGSL's documentation has the colours). The image
/// keeps its aspect ratio and is centred in the target, scaled by nearest pixel; at the image's
/// own size it is drawn pixel for pixel. Must be made on the renderer's [`Gpu`].
#[derive(Debug)]
pub struct Presenter {
    device: wgpu::Device,
    queue: wgpu::Queue,
    format: wgpu::TextureFormat,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    palette: wgpu::Buffer,
}

impl Presenter {
    /// The pass for targets of `format`: `Rgba8Unorm`, `Bgra8Unorm` or their sRGB variants
    /// (every surface offers one of these), otherwise [`GpuError::TargetFormat`].
    pub fn new(gpu: &Gpu, format: wgpu::TextureFormat) -> Result<Presenter, GpuError> {
        use wgpu::TextureFormat as F;
        if !matches!(format, F::Rgba8Unorm | F::Rgba8UnormSrgb | F::Bgra8Unorm | F::Bgra8UnormSrgb) {
            return Err(GpuError::TargetFormat(format));
        }
        let device = gpu.device().clone();
        let queue = gpu.queue().clone();
        capture_errors(&device, || {
            let fragment = wgpu::ShaderStages::FRAGMENT;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("preview present"),
                entries: &[
                    uniform_entry(0, fragment, false),
                    uniform_entry(1, fragment, false),
                    storage_entry(2, fragment, true),
                ],
            });
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("preview_present.wgsl"),
                source: wgpu::ShaderSource::Wgsl(crate::wgsl::PREVIEW_PRESENT.source.into()),
            });
            let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("preview present"),
                layout: Some(&device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("preview present"),
                    bind_group_layouts: &[Some(&layout)],
                    immediate_size: 0,
                })),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("present_vertex"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("present_fragment"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            });
            let uniform = crate::device::uniform_buffer(&device, "preview present", size_of::<PresentUniform>() as u64);
            let colours: Vec<[f32; 4]> = (0..PALETTE_SIZE)
                .map(|i| {
                    let [r, g, b] = picture::colormap::viridis(i as f64 / (PALETTE_SIZE - 1) as f64);
                    [f32::from(r) / 255.0, f32::from(g) / 255.0, f32::from(b) / 255.0, 1.0]
                })
                .collect();
            let palette = wgpu::util::DeviceExt::create_buffer_init(
                &device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some("preview palette"),
                    contents: bytemuck::cast_slice(&colours),
                    usage: wgpu::BufferUsages::UNIFORM,
                },
            );
            Presenter { device: device.clone(), queue: queue.clone(), format, pipeline, layout, uniform, palette }
        })
    }

    /// The format of the targets this pass draws.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Draws the average of what `renderer` has accumulated (the background where it holds no
    /// frame) into `target`, a view of a texture of [`Presenter::format`] and `size` (width,
    /// height) with `RENDER_ATTACHMENT` usage, at exposure `exposure_ev` stops. Submits the work.
    pub fn draw(
        &self,
        renderer: &Renderer,
        target: &wgpu::TextureView,
        size: (u32, u32),
        exposure_ev: f32,
    ) -> Result<(), GpuError> {
        let (width, height) = (renderer.width, renderer.height);
        let view = renderer.accumulated_view().unwrap_or_default();
        let n_indices = match view {
            View::Layer => renderer.n_layers as u32,
            View::Slice => renderer.n_slices,
            View::Shaded | View::Normal => 0,
        };
        // Whole target pixels for the origin, so that at scale 1 image pixels are target pixels.
        let scale = (size.0 as f32 / width as f32).min(size.1 as f32 / height as f32);
        let origin = [
            ((size.0 as f32 - scale * width as f32) / 2.0).floor(),
            ((size.1 as f32 - scale * height as f32) / 2.0).floor(),
        ];
        let uniform = PresentUniform {
            image_size: [width, height],
            frames: renderer.frames_accumulated(),
            view: view_index(view),
            // In f64 like `tonemap_rgb8`, rounded once.
            exposure: f64::from(exposure_ev).exp2() as f32,
            srgb_target: self.format.is_srgb().into(),
            n_indices,
            _pad: 0,
            origin,
            scale,
            _pad2: 0.0,
        };
        capture_errors(&self.device, || {
            self.queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
            let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview present"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: self.uniform.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: self.palette.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: renderer.accumulation.as_entire_binding() },
                ],
            });
            let mut encoder = self.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("preview present"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: target,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.draw(0..3, 0..1);
            }
            self.queue.submit([encoder.finish()]);
        })
    }

    /// [`Presenter::draw`] into a new offscreen texture of `size`, read back as 8-bit RGB
    /// (row-major, row 0 at the top): the picture a window of that size shows.
    pub fn draw_rgb8(&self, renderer: &Renderer, size: (u32, u32), exposure_ev: f32) -> Result<Vec<u8>, GpuError> {
        let texture = capture_errors(&self.device, || {
            self.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("preview present offscreen"),
                size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: self.format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        })?;
        self.draw(renderer, &texture.create_view(&Default::default()), size, exposure_ev)?;
        self.read_rgb8(&texture)
    }

    /// Reads a 2D texture of [`Presenter::format`] with `COPY_SRC` usage (a surface texture
    /// configured with it, or an offscreen one) back as 8-bit RGB, row-major, row 0 at the top:
    /// the bytes the target holds (sRGB-encoded either way).
    pub fn read_rgb8(&self, texture: &wgpu::Texture) -> Result<Vec<u8>, GpuError> {
        if texture.format() != self.format {
            return Err(GpuError::TargetFormat(texture.format()));
        }
        let (width, height) = (texture.width(), texture.height());
        let row_bytes = (4 * width).next_multiple_of(ROW_ALIGNMENT);
        let bytes = u64::from(row_bytes) * u64::from(height);
        let readback = capture_errors(&self.device, || {
            let buffer = crate::device::readback_buffer(&self.device, "preview present readback", bytes);
            let mut encoder = self.device.create_command_encoder(&Default::default());
            encoder.copy_texture_to_buffer(
                texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row_bytes),
                        rows_per_image: Some(height),
                    },
                },
                texture.size(),
            );
            self.queue.submit([encoder.finish()]);
            buffer
        })?;
        let padded: Vec<u8> = read_back(&self.device, &readback, bytes)?;
        let bgra = matches!(self.format, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb);
        let mut rgb = Vec::with_capacity(3 * width as usize * height as usize);
        for row in padded.chunks_exact(row_bytes as usize) {
            for texel in row[..4 * width as usize].chunks_exact(4) {
                if bgra {
                    rgb.extend_from_slice(&[texel[2], texel[1], texel[0]]);
                } else {
                    rgb.extend_from_slice(&texel[..3]);
                }
            }
        }
        Ok(rgb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn view_indices_match_the_shader() {
        let views =
            [("SHADED", View::Shaded), ("NORMAL", View::Normal), ("LAYER", View::Layer), ("SLICE", View::Slice)];
        for (name, view) in views {
            let decl = format!("const VIEW_{name}: u32 = {}u;", view_index(view));
            assert!(crate::wgsl::PREVIEW_PRESENT.source.contains(&decl), "the WGSL does not declare `{decl}`");
        }
    }

    #[test]
    fn palette_size_matches_the_shader() {
        let decl = format!("array<vec4<f32>, {PALETTE_SIZE}>");
        assert!(crate::wgsl::PREVIEW_PRESENT.source.contains(&decl), "the WGSL does not declare `{decl}`");
    }
}
