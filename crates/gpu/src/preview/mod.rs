//! The previewer's renderer on the GPU: the `render` crate's specification (its crate
//! documentation), step for step, in two passes. A raster pass draws the index of the triangle
//! that covers each pixel centre (`preview_raster.wgsl`): coverage and the depth test are the
//! rasterizer's, whose rules the specification follows. A compute pass then interpolates the
//! vertices at the pixel centre the way the specification does (from the snapped coordinates,
//! where a rasterizer's own interpolation may differ by a fraction of a sub-pixel), shades one
//! frame per dispatch and adds it into an accumulation buffer (`preview_shade.wgsl`, compiled
//! with the files it needs, `crate::wgsl`). The environment behind the
//! mesh, the same in every frame of a camera, is drawn once with the G-buffer and read where no
//! triangle covers a pixel (by the adaptive frames too). [`Renderer::render_frames`]
//! reads back the average of the frames; [`Renderer::accumulate`] keeps adding frames across
//! calls (an interactive view refines as it is shown), and a [`Presenter`] tone maps the running
//! average into a texture, a window's included, exactly as `envmap::tonemap_rgb8` maps pictures.
//! [`View`] names the debug views the shading pass can accumulate instead of the estimate.
//!
//! The CPU renderer `render::render` is the reference: with the same inputs the two images agree
//! to f32 rounding (the CPU shades in f64), apart from the rare sample whose MERL cell, slice or
//! coverage sits on a boundary that rounding crosses. The tests hold it to that. One step is
//! not the CPU's to the letter: a triangle the CPU clips (at the near plane or the guard band) is
//! interpolated at the exact point where the pixel ray meets it, not from the clipped polygon's
//! snapped vertices (the two differ by that snapping, 1/512 pixel).
//!
//! The vertices' projection and snapping (steps 1 and 3) are the CPU's, uploaded with each
//! camera (`render::raster::project` and `snapped`), and the edge functions are exact integers
//! as on the CPU. A GPU that projected for itself may fuse multiply-adds and divide to 2.5 ULP,
//! as Vulkan allows: a coordinate near a rounding tie then snaps one sub-pixel step away, and a
//! small triangle's interpolation moves with it (on an NVIDIA H200, by 4e-4 on a torus of unit size).
//!
//! Everything the shaders read lives in storage buffers (the samples, the mip chain and the
//! prefiltered layers as f32 RGB, the view-layer table) rather than textures: float32 textures
//! need not be filterable, and bilinear weights computed by hand are the CPU's arithmetic. Buffers
//! read together share a binding where they can, so that the estimators' passes bind 8 storage
//! buffers, WebGPU's default per shader stage (`setup.rs`).

use std::cell::{Cell, OnceCell, RefCell};
use std::sync::Arc;

use bytemuck::Pod;
use glam::DVec3;
use render::{Camera, Estimator, Image, Settings};
use wgpu::util::DeviceExt;

use crate::context::check_buffer_fits;
use crate::device::{capture_errors, read_back_with};
use crate::error::GpuError;

pub(crate) mod adaptive;
pub(crate) mod present;
mod setup;
mod tables;
pub(crate) mod uniforms;

pub use adaptive::FrameOptions;
pub use present::Presenter;

pub(crate) use setup::most_storage_buffers;
use setup::{storage_entry, uniform_entry};
use tables::*;
use uniforms::*;

/// Frames recorded into one command buffer: enough to amortize a submission, few enough that no
/// single submission runs for long on a slow adapter.
const FRAMES_PER_SUBMIT: u32 = 16;

/// The G-buffer: the covering triangle's index plus one, 0 where none covers the pixel.
const TRIANGLE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The bandwidths the prediction of adaptive frames reads ([`Renderer::set_bandwidths`]).
#[derive(Debug)]
struct Prediction {
    bandwidths: render::adaptive::Bandwidths,
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
}

/// What [`Renderer::accumulate`] adds up at each pixel: the estimate of the settings' mode, or a
/// debug view of what the estimators read there. Pixels no triangle covers show the environment
/// in every view. The debug views are the same in every frame, so their average is their value
/// (one frame shows them whole).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum View {
    /// The mode's estimate of the radiance: what [`Renderer::render_frames`] renders.
    #[default]
    Shaded,
    /// The interpolated, normalized normal `(x, y, z)` at every covered pixel.
    Normal,
    /// The prefiltered layer that the view-layer table picks for the pixel (whatever the mode):
    /// `(layer, 1, 0)`, `(-1, 1, 0)` where the material has no table, `(0, 0, 0)` where the pixel
    /// has no shading frame (it is black in every mode).
    Layer,
    /// The slice of the baked samples the pixel reads: `(slice, 1, 0)`, or `(0, 0, 0)` where the
    /// pixel has no shading frame.
    Slice,
}

impl View {
    pub const ALL: [View; 4] = [View::Shaded, View::Normal, View::Layer, View::Slice];

    pub fn name(self) -> &'static str {
        match self {
            View::Shaded => "shaded",
            View::Normal => "normals",
            View::Layer => "prefiltered layer",
            View::Slice => "sample slice",
        }
    }

    /// Whether frames after the first change nothing but rounding.
    pub fn is_deterministic(self) -> bool {
        self != View::Shaded
    }

    /// `MODE_*` of the WGSL for this view of a render in `mode`.
    fn mode_index(self, mode: Estimator) -> u32 {
        match self {
            View::Shaded => mode_index(mode),
            View::Normal => MODE_DEBUG_NORMAL,
            View::Layer => MODE_DEBUG_LAYER,
            View::Slice => MODE_DEBUG_SLICE,
        }
    }
}

/// What the accumulation buffer holds: the sum of frames `0 .. frames` of one render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Progress {
    settings: Settings,
    view: View,
    frames: u32,
}

/// The G-buffer read back: the visible surface at every pixel centre as the shading pass sees
/// it, row-major, row 0 at the top, for the tests to hold visibility to `render::raster` on its
/// own, before any shading.
#[derive(Clone, Debug, PartialEq)]
pub struct GBufferReadback {
    pub width: usize,
    pub height: usize,
    /// The index of the triangle that covers the pixel centre, if any.
    pub triangle: Vec<Option<u32>>,
    /// The interpolated world position (0 where not covered).
    pub position: Vec<[f32; 3]>,
    /// The interpolated vertex normal, normalized, or zero where it interpolates to zero (0 where
    /// not covered).
    pub normal: Vec<[f32; 3]>,
}

impl GBufferReadback {
    /// Whether a triangle covers each pixel centre.
    pub fn coverage(&self) -> Vec<bool> {
        self.triangle.iter().map(Option::is_some).collect()
    }
}

/// A scene, a material and its lighting on the GPU, ready to render frames of any
/// [`Settings`].
#[derive(Debug)]
pub struct Renderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    width: u32,
    height: u32,
    camera: Camera,
    n_indices: u32,
    raster_pipeline: wgpu::RenderPipeline,
    /// `VERTEX_FLOATS` per vertex: the clip-space position and the snapped viewport coordinates
    /// with the current camera, the position and the normal (`rasterize` writes it).
    vertex_buffer: wgpu::Buffer,
    mesh: render::Mesh,
    /// What the current camera sees, for adaptive frames ([`Renderer::adaptive_geometry`]):
    /// made at the first adaptive frame after a camera change, for one supersampling.
    geometry: RefCell<Option<Arc<render::adaptive::Geometry>>>,
    raster_group: wgpu::BindGroup,
    triangle_target: wgpu::Texture,
    depth_target: wgpu::Texture,
    shade_pipeline: wgpu::ComputePipeline,
    /// `shade_backdrop`: the environment behind the mesh, drawn with the G-buffer.
    backdrop_pipeline: wgpu::ComputePipeline,
    /// The prediction's inputs, made by [`Renderer::set_bandwidths`].
    prediction: Option<Prediction>,
    /// The adaptive frames' pipelines and group-3 layouts, made at the first that needs them
    /// ([`Renderer::adaptive_pipelines`]).
    adaptive_pipelines: OnceCell<adaptive::Pipelines>,
    /// The adaptive frames' state on the GPU, for the last geometry and settings.
    adaptive: RefCell<Option<adaptive::State>>,
    /// For the limit errors of later uploads.
    adapter_info: wgpu::AdapterInfo,
    table_group: wgpu::BindGroup,
    bake_group: wgpu::BindGroup,
    render_group: wgpu::BindGroup,
    /// The shading module and its layouts, for the pipelines made later.
    shading: setup::Shading,
    shade_uniform: wgpu::Buffer,
    frame_uniform: wgpu::Buffer,
    /// Bytes between the frame slots of `frame_uniform` (the dynamic-offset alignment).
    frame_stride: u64,
    accumulation: wgpu::Buffer,
    /// What `accumulation` holds; `None` when it holds nothing to continue (after a camera change
    /// or a G-buffer read). A `Cell` because reading the G-buffer (`&self`) uses the buffer too.
    progress: Cell<Option<Progress>>,
    /// What settings are checked against.
    n_slices: u32,
    n_vectors: u32,
    n_samples: u32,
    n_levels: u32,
    n_layers: usize,
    view_layers: Vec<f32>,
    /// `render::diffuse_split`: the BRDF's diffuse part the filtered estimators read at the
    /// normal.
    diffuse: [f32; 3],
    maps: MapLayout,
    tables: TableLayout,
}

/// Dropping a renderer waits for the work it submitted. Its passes may still be running on the
/// device's threads (lavapipe compiles a pipeline's shader there when it first runs it: a
/// renderer made and dropped at once leaves its raster and backdrop passes in flight), and a
/// process that exits meanwhile tears the compiler down under them: the GPU test binary crashed
/// after every test had passed, in a lavapipe thread inside LLVM's JIT, about one run in 30 on
/// a busy machine.
impl Drop for Renderer {
    fn drop(&mut self) {
        // A drop has no one to report to; a lost device has no work left to wait for either.
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }
}

impl Renderer {
    /// Pixels of the image: entries of the accumulation buffer.
    fn pixels(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    pub fn width(&self) -> usize {
        self.width as usize
    }

    pub fn height(&self) -> usize {
        self.height as usize
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Looks from `camera` instead: draws the G-buffer again and restarts the accumulation. The
    /// image size stays.
    pub fn set_camera(&mut self, camera: &Camera) -> Result<(), GpuError> {
        self.camera = *camera;
        *self.geometry.get_mut() = None;
        self.restart();
        self.rasterize()
    }

    /// Renders `settings.frames` frames (`f = 0 .. frames`) and reads back their average, with
    /// which pixels a triangle covers. Checks the settings as `render::render` does. Leaves those
    /// frames in the accumulation (a [`Presenter`] shows them, [`Renderer::accumulate`] goes on
    /// from them).
    pub fn render_frames(&mut self, settings: &Settings) -> Result<Image, GpuError> {
        self.check_settings(settings)?;
        self.restart();
        self.accumulate(settings, View::Shaded, settings.frames)?;
        self.accumulated_image()
    }

    /// Adds `frames` frames of the picture `settings` describes (`settings.frames` the frames it
    /// averages when whole, which sets the fis estimator's footprints: `render`'s crate docs) and
    /// of `view` to the accumulation, continuing with the frame after the last one added: calls
    /// of 1 frame each add frames 0, 1, 2, ... and their sum is that of one render of as many
    /// frames. Starts again from frame 0 where the accumulation holds other settings or another
    /// view, or nothing (after [`Renderer::restart`] or a camera change). Checks the settings as
    /// [`Renderer::render_frames`] does. Returns the frames now accumulated. Submits the work
    /// without waiting for it (`wgpu::Device::poll` waits).
    pub fn accumulate(&mut self, settings: &Settings, view: View, frames: u32) -> Result<u32, GpuError> {
        self.check_settings(settings)?;
        let progress = match self.progress.get() {
            Some(p) if (p.settings, p.view) == (*settings, view) => p,
            _ => Progress { settings: *settings, view, frames: 0 },
        };
        let total = progress.frames.checked_add(frames).ok_or_else(|| {
            GpuError::Scene(render::Error::Invalid(format!(
                "{} frames accumulated, {frames} more would overflow the frame index",
                progress.frames
            )))
        })?;
        // Nothing to continue is recorded before the work, so that a failure leaves none.
        self.progress.set(None);
        let shade = self.shade_uniform(view.mode_index(settings.estimator), settings);
        self.shade_frames(&shade, progress.frames, frames, progress.frames == 0)?;
        self.progress.set(Some(Progress { frames: total, ..progress }));
        Ok(total)
    }

    /// Frames in the accumulation: 0 after [`Renderer::restart`] or a camera change.
    pub fn frames_accumulated(&self) -> u32 {
        self.progress.get().map_or(0, |p| p.frames)
    }

    /// The view the accumulation holds, if it holds any frame.
    pub fn accumulated_view(&self) -> Option<View> {
        self.progress.get().map(|p| p.view)
    }

    /// Forgets the accumulation: the next [`Renderer::accumulate`] starts from frame 0.
    pub fn restart(&mut self) {
        self.progress.set(None);
    }

    /// Reads back the average of the accumulated frames, in the units of their [`View`] (linear
    /// radiance for [`View::Shaded`]), with which pixels a triangle covers. Fails with
    /// [`GpuError::Scene`] when no frame has been accumulated.
    pub fn accumulated_image(&self) -> Result<Image, GpuError> {
        let frames = self.frames_accumulated();
        if frames == 0 {
            return Err(GpuError::Scene(render::Error::Invalid("no frame has been accumulated".into())));
        }
        let bytes = 16 * self.pixels();
        let encoder = self.device.create_command_encoder(&Default::default());
        let (rgb, covered) =
            self.submit_and_map(encoder, &[(&self.accumulation, bytes)], &self.readback_buffer(bytes), |sums| {
                let covered = sums.chunks_exact(16).map(|s| f32::from_le_bytes([s[12], s[13], s[14], s[15]]) > 0.0);
                (rgb_of(sums, frames as f32), covered.collect())
            })?;
        Ok(Image { width: self.width(), height: self.height(), rgb, covered })
    }

    /// The visible surface at every pixel centre, as the shading pass interpolates it.
    pub fn gbuffer(&self) -> Result<GBufferReadback, GpuError> {
        // Any valid sample choice: these modes read no sample.
        let settings = Settings { estimator: Estimator::Reference, spp: 1, frames: 1, seed: 0 };
        let positions = self.run_shading(&self.shade_uniform(MODE_GBUFFER_POSITION, &settings))?;
        let normals = self.run_shading(&self.shade_uniform(MODE_GBUFFER_NORMAL, &settings))?;
        Ok(GBufferReadback {
            width: self.width(),
            height: self.height(),
            // The index plus one, exact in f32 up to the 2^24 triangles a mesh may have.
            triangle: positions.iter().map(|p| (p[3] > 0.0).then(|| p[3] as u32 - 1)).collect(),
            position: positions.iter().map(|p| [p[0], p[1], p[2]]).collect(),
            normal: normals.iter().map(|n| [n[0], n[1], n[2]]).collect(),
        })
    }

    /// Runs the shading pass once with `shade` into the cleared accumulation buffer (which then
    /// holds nothing to continue) and reads it back.
    fn run_shading(&self, shade: &ShadeUniform) -> Result<Vec<[f32; 4]>, GpuError> {
        self.progress.set(None);
        self.shade_frames(shade, 0, 1, true)?;
        self.read_accumulation(self.pixels())
    }

    /// Runs the shading pass with `shade` for frames `first .. first + frames`, adding into the
    /// accumulation buffer, cleared first if `clear`.
    fn shade_frames(&self, shade: &ShadeUniform, first: u32, frames: u32, clear: bool) -> Result<(), GpuError> {
        let end = first + frames;
        capture_errors(&self.device, || {
            self.queue.write_buffer(&self.shade_uniform, 0, bytemuck::bytes_of(shade));
            let mut encoder = self.device.create_command_encoder(&Default::default());
            if clear {
                // The sums only: the backdrop behind them is the camera's.
                encoder.clear_buffer(&self.accumulation, 0, Some(16 * self.pixels()));
            }
            let mut first = first;
            while first < end {
                let count = FRAMES_PER_SUBMIT.min(end - first);
                let mut slots = vec![0u8; (self.frame_stride * u64::from(count)) as usize];
                for (i, slot) in slots.chunks_exact_mut(self.frame_stride as usize).enumerate() {
                    let frame = FrameUniform { index: first + i as u32 };
                    slot[..size_of::<FrameUniform>()].copy_from_slice(bytemuck::bytes_of(&frame));
                }
                // Takes effect before the submission below and after the ones before it.
                self.queue.write_buffer(&self.frame_uniform, 0, &slots);
                {
                    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("shade_frame"),
                        timestamp_writes: None,
                    });
                    pass.set_pipeline(&self.shade_pipeline);
                    pass.set_bind_group(0, &self.table_group, &[]);
                    pass.set_bind_group(1, &self.bake_group, &[]);
                    for i in 0..count {
                        pass.set_bind_group(2, &self.render_group, &[(u64::from(i) * self.frame_stride) as u32]);
                        pass.dispatch_workgroups(
                            self.width.div_ceil(SHADE_WORKGROUP),
                            self.height.div_ceil(SHADE_WORKGROUP),
                            1,
                        );
                    }
                }
                self.queue.submit([encoder.finish()]);
                encoder = self.device.create_command_encoder(&Default::default());
                first += count;
            }
            // A clear with no frame after it still has to reach the GPU.
            self.queue.submit([encoder.finish()]);
        })
    }

    /// Uploads the bandwidths the prediction of adaptive frames reads (the environment's and the
    /// bandwidth atlas), replacing any set before; [`Renderer::render_adaptive`] and
    /// [`Renderer::predict_blocks`] need them.
    pub fn set_bandwidths(&mut self, bandwidths: &render::adaptive::Bandwidths) -> Result<(), GpuError> {
        let (environment, atlas) = (&bandwidths.environment, &bandwidths.brdf);
        atlas.check().map_err(|e| render::Error::Invalid(format!("the bandwidth atlas: {e}")))?;
        let texels: Vec<f32> = environment.values().iter().chain(&atlas.data).copied().collect();
        check_buffer_fits(&self.device.limits(), &self.adapter_info, 4 * texels.len() as u64, "the bandwidths")?;
        let predict_layout = &self.adaptive_pipelines()?.predict_layout;
        let prediction = capture_errors(&self.device, || {
            let uniform =
                crate::device::uniform_buffer(&self.device, "preview predict", size_of::<PredictUniform>() as u64);
            let texels = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("preview bandwidths"),
                contents: bytemuck::cast_slice(&texels),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview predict"),
                layout: predict_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: texels.as_entire_binding() },
                ],
            });
            Prediction { bandwidths: bandwidths.clone(), uniform, group }
        })?;
        self.prediction = Some(prediction);
        Ok(())
    }

    /// What the current camera sees, for adaptive frames rendered at `supersample` times an output
    /// image (`render::adaptive::Geometry`): the G-buffer on the CPU with its per-pixel
    /// quantities. Made once per camera, as the raster pass is, and kept for its frames; made
    /// again for another supersampling. The renderer's size must be `supersample` times the
    /// output's.
    pub fn adaptive_geometry(&self, supersample: usize) -> Result<Arc<render::adaptive::Geometry>, GpuError> {
        let ss = supersample as u32;
        if !matches!(supersample, 1 | 2 | 4) || !self.width.is_multiple_of(ss) || !self.height.is_multiple_of(ss) {
            return Err(render::Error::Invalid(format!(
                "the renderer draws {} x {}, which is no output image supersampled {supersample} times (1, 2 or 4)",
                self.width, self.height
            ))
            .into());
        }
        if let Some(geometry) = self.geometry.borrow().as_ref().filter(|g| g.supersample() == supersample) {
            return Ok(Arc::clone(geometry));
        }
        let size = ((self.width / ss) as usize, (self.height / ss) as usize);
        let geometry = Arc::new(render::adaptive::Geometry::new(&self.mesh, &self.camera, size, supersample)?);
        *self.geometry.borrow_mut() = Some(Arc::clone(&geometry));
        Ok(geometry)
    }

    /// Predicts the bandwidth buffer of an adaptive frame at `pixels` (its
    /// `render::adaptive::prediction_pixels`, row-major indices of the renderer's image) as
    /// `render::adaptive` does on the CPU, with `settings`' `n_b`, seed and estimator and the
    /// bandwidths of [`Renderer::set_bandwidths`]: each pixel's image bandwidth (cycles per pixel)
    /// and variance. The curvature is the CPU's G-buffer's ([`Renderer::adaptive_geometry`], as
    /// an adaptive frame's is). A pixel the GPU's raster finds not shadeable (the renderers may
    /// disagree at a few silhouette pixels: crate docs) predicts the bandwidth of a pixel grid's
    /// Nyquist limit, 1/2 cycle per pixel, and variance 0: level 0, shaded at full resolution,
    /// the safe side.
    pub fn predict_blocks(
        &self,
        settings: &render::adaptive::Settings,
        pixels: &[u32],
    ) -> Result<Vec<[f64; 2]>, GpuError> {
        let prediction = self.prediction.as_ref().ok_or_else(no_bandwidths)?;
        let n = self.pixels();
        if pixels.len() as u64 > n {
            return Err(render::Error::Invalid(format!("{} prediction pixels for {n} pixels", pixels.len())).into());
        }
        if let Some(&pixel) = pixels.iter().find(|&&p| u64::from(p) >= n) {
            return Err(render::Error::Invalid(format!("prediction pixel {pixel} is outside {n} pixels")).into());
        }
        if pixels.is_empty() {
            return Ok(Vec::new());
        }
        let geometry = self.adaptive_geometry(1)?;
        capture_errors(&self.device, || self.write_predict_uniform(prediction, settings))?;
        let items = prediction_items(pixels, geometry.pixels());
        let pipeline = &self.adaptive_pipelines()?.predict;
        let values = self.run_items(pipeline, &prediction.group, settings.estimator, settings.seed, &items)?;
        Ok(values.iter().map(|v| if v[0] < 0.0 { [0.5, 0.0] } else { [f64::from(v[0]), f64::from(v[1])] }).collect())
    }

    /// Writes the prediction's uniform for `settings` (`n_b`) and the current camera.
    fn write_predict_uniform(&self, prediction: &Prediction, settings: &render::adaptive::Settings) {
        let (environment, atlas) = (&prediction.bandwidths.environment, &prediction.bandwidths.brdf);
        let uniform = PredictUniform {
            n_b: settings.n_b.min(u32::MAX as usize) as u32,
            env_width: environment.width() as u32,
            env_height: environment.height() as u32,
            lobes_x: atlas.lobes_x as u32,
            lobes_y: atlas.lobes_y as u32,
            tile: atlas.tile as u32,
            radians_per_pixel: (f64::from(self.camera.fov_y()) / f64::from(self.height)) as f32,
            _pad: 0,
        };
        self.queue.write_buffer(&prediction.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Runs an entry that takes a list of items (`predict_blocks`): the items
    /// go in through the accumulation buffer (so it holds nothing to continue afterwards), their
    /// count in the shade uniform's `items`, with `estimator` and `seed`; `group` is group 3. Returns
    /// the first `items.len()` entries the pass leaves. At most a pixel's entry each: the backdrop
    /// follows the sums.
    fn run_items(
        &self,
        pipeline: &wgpu::ComputePipeline,
        group: &wgpu::BindGroup,
        estimator: Estimator,
        seed: u32,
        items: &[[u32; 4]],
    ) -> Result<Vec<[f32; 4]>, GpuError> {
        if items.len() as u64 > self.pixels() {
            return Err(render::Error::Invalid(format!("{} items for {} pixels", items.len(), self.pixels())).into());
        }
        self.progress.set(None);
        let count = items.len() as u32;
        let settings = Settings { estimator, spp: 1, frames: 1, seed };
        let shade = ShadeUniform { items: count, ..self.shade_uniform(mode_index(estimator), &settings) };
        let (x, y) = item_groups(count);
        let encoder = capture_errors(&self.device, || {
            self.queue.write_buffer(&self.shade_uniform, 0, bytemuck::bytes_of(&shade));
            self.queue.write_buffer(&self.frame_uniform, 0, bytemuck::bytes_of(&FrameUniform::default()));
            self.queue.write_buffer(&self.accumulation, 0, bytemuck::cast_slice(items));
            let mut encoder = self.device.create_command_encoder(&Default::default());
            {
                let mut pass = self.begin_pass(&mut encoder);
                pass.set_pipeline(pipeline);
                pass.set_bind_group(3, group, &[]);
                pass.dispatch_workgroups(x, y, 1);
            }
            encoder
        })?;
        let bytes = 16 * u64::from(count);
        self.submit_and_read(encoder, &[(&self.accumulation, bytes)], &self.readback_buffer(bytes))
    }

    /// The accumulation buffer's first `entries` sums, read back.
    fn read_accumulation(&self, entries: u64) -> Result<Vec<[f32; 4]>, GpuError> {
        let bytes = 16 * entries;
        let encoder = self.device.create_command_encoder(&Default::default());
        self.submit_and_read(encoder, &[(&self.accumulation, bytes)], &self.readback_buffer(bytes))
    }

    /// Submits `encoder` with copies of the first bytes of each source, one after another,
    /// into `readback` (a buffer of [`Renderer::readback_buffer`]'s kind, large enough) and
    /// reads them back; nothing to read when there are no bytes.
    fn submit_and_read<T: Pod>(
        &self,
        encoder: wgpu::CommandEncoder,
        sources: &[(&wgpu::Buffer, u64)],
        readback: &wgpu::Buffer,
    ) -> Result<Vec<T>, GpuError> {
        self.submit_and_map(encoder, sources, readback, bytemuck::pod_collect_to_vec)
    }

    /// [`Renderer::submit_and_read`] with `f` of the mapped bytes (`f` of none where there are
    /// no bytes) in place of a copy.
    fn submit_and_map<R>(
        &self,
        mut encoder: wgpu::CommandEncoder,
        sources: &[(&wgpu::Buffer, u64)],
        readback: &wgpu::Buffer,
        f: impl FnOnce(&[u8]) -> R,
    ) -> Result<R, GpuError> {
        let mut bytes = 0;
        capture_errors(&self.device, || {
            for &(source, size) in sources {
                if size > 0 {
                    encoder.copy_buffer_to_buffer(source, 0, readback, bytes, size);
                }
                bytes += size;
            }
            self.queue.submit([encoder.finish()]);
        })?;
        if bytes == 0 {
            return Ok(f(&[]));
        }
        read_back_with(&self.device, readback, bytes, f)
    }

    /// A buffer to map for reading, of `bytes`.
    fn readback_buffer(&self, bytes: u64) -> wgpu::Buffer {
        crate::device::readback_buffer(&self.device, "preview readback", bytes.max(4))
    }

    /// A compute pass with the shading pass's groups 0 to 2 set.
    fn begin_pass<'e>(&self, encoder: &'e mut wgpu::CommandEncoder) -> wgpu::ComputePass<'e> {
        self.begin_timed_pass(encoder, None)
    }

    /// [`Renderer::begin_pass`] with timestamps written at its beginning and end where asked.
    fn begin_timed_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) -> wgpu::ComputePass<'e> {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: None, timestamp_writes });
        self.bind_estimator_groups(&mut pass);
        pass
    }

    /// Binds groups 0 to 2 for an estimator's pass (frame 0's slot of `FrameUniform`).
    fn bind_estimator_groups(&self, pass: &mut wgpu::ComputePass) {
        pass.set_bind_group(0, &self.table_group, &[]);
        pass.set_bind_group(1, &self.bake_group, &[]);
        pass.set_bind_group(2, &self.render_group, &[0]);
    }

    /// Draws the G-buffer with the current camera, and the environment behind the mesh.
    fn rasterize(&self) -> Result<(), GpuError> {
        // The CPU's projection and snapping, which the passes read rather than compute
        // (`preview_geometry.wgsl`).
        let clip = render::raster::project(&self.mesh.positions, self.view_proj());
        let (width, height) = (self.width(), self.height());
        let vertices: Vec<[f32; VERTEX_FLOATS as usize]> =
            (clip.iter().zip(&self.mesh.positions).zip(&self.mesh.normals))
                .map(|((&c, p), n)| {
                    let [x, y] = render::raster::snapped(c, width, height).map_or([0.0; 2], |v| v.map(|s| s as f32));
                    [c.x, c.y, c.z, c.w, x, y, p[0], p[1], p[2], n[0], n[1], n[2]]
                })
                .collect();
        capture_errors(&self.device, || {
            self.queue.write_buffer(&self.vertex_buffer, 0, bytemuck::cast_slice(&vertices));
            let mut encoder = self.device.create_command_encoder(&Default::default());
            {
                let triangle = self.triangle_target.create_view(&Default::default());
                let depth = self.depth_target.create_view(&Default::default());
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("preview raster"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &triangle,
                        depth_slice: None,
                        resolve_target: None,
                        // Zero marks a pixel no triangle covers.
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &depth,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.raster_pipeline);
                pass.set_bind_group(0, &self.raster_group, &[]);
                // Not indexed: the vertex shader reads the indices, and vertex i / 3 is triangle i.
                pass.draw(0..self.n_indices, 0..1);
            }
            // The environment behind the mesh, the same in every frame of this camera: the
            // shading uniform's camera (the frames write theirs again).
            let settings = Settings { estimator: Estimator::Reference, spp: 1, frames: 1, seed: 0 };
            let shade = self.shade_uniform(mode_index(Estimator::Reference), &settings);
            self.queue.write_buffer(&self.shade_uniform, 0, bytemuck::bytes_of(&shade));
            {
                let mut pass = self.begin_pass(&mut encoder);
                pass.set_pipeline(&self.backdrop_pipeline);
                pass.dispatch_workgroups(
                    self.width.div_ceil(SHADE_WORKGROUP),
                    self.height.div_ceil(SHADE_WORKGROUP),
                    1,
                );
            }
            self.queue.submit([encoder.finish()]);
        })
    }

    /// The camera's matrix, with the CPU's aspect in f32 (`render::shade::visibility`).
    fn view_proj(&self) -> glam::Mat4 {
        self.camera.view_proj(self.width as f32 / self.height as f32)
    }

    /// The `ShadeUniform` of a render with `settings` in `MODE_*` `mode`.
    fn shade_uniform(&self, mode: u32, settings: &Settings) -> ShadeUniform {
        let camera = &self.camera;
        // `render::Camera::ray`'s basis, in f64 like the CPU, rounded once.
        let eye = camera.eye().as_dvec3();
        let forward = (camera.target().as_dvec3() - eye).normalize();
        let right = forward.cross(DVec3::Z).normalize();
        let up = right.cross(forward);
        let aspect = f64::from(self.width) / f64::from(self.height);
        let tan_half = (0.5 * f64::from(camera.fov_y())).tan();
        let vec4 = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
        ShadeUniform {
            eye: vec4(eye),
            ray_forward: vec4(forward),
            ray_right: vec4(right * (tan_half * aspect)),
            ray_up: vec4(up * tan_half),
            width: self.width,
            height: self.height,
            seed: settings.seed,
            mode,
            spp: settings.spp,
            n_slices: self.n_slices,
            n_vectors: self.n_vectors,
            n_samples: self.n_samples,
            n_levels: self.n_levels,
            n_view_rows: self.view_layers.len() as u32,
            n_layers: self.n_layers as u32,
            layer_shift: 0,
            maps: self.maps,
            tables: self.tables,
            items: 0,
            filter_samples: settings.filter_samples(),
            diffuse: [self.diffuse[0], self.diffuse[1], self.diffuse[2], 0.0],
        }
    }

    /// The checks of `render::render` on the settings.
    fn check_settings(&self, settings: &Settings) -> Result<(), GpuError> {
        Ok(render::check_settings(settings, self.n_samples as usize, self.n_layers, &self.view_layers)?)
    }
}

/// `predict_blocks`' items: each prediction pixel with its G-buffer curvature in f32 (0 where the
/// CPU's G-buffer finds the pixel not shadeable).
fn prediction_items(at: &[u32], pixels: &[Option<render::adaptive::Pixel>]) -> Vec<[u32; 4]> {
    let curvature = |p: u32| pixels[p as usize].as_ref().map_or(0.0, |px| px.curvature as f32);
    at.iter().map(|&p| [p, curvature(p).to_bits(), 0, 0]).collect()
}

/// The workgroups of a list of `count` items (`shade_blocks`, `predict_blocks`): a power of two of
/// workgroups, taken in bit-reversed order (`item_index` in the WGSL), as `(x, y)`.
fn item_groups(count: u32) -> (u32, u32) {
    workgroups(count.div_ceil(64).next_power_of_two())
}

/// `n` workgroups as `(x, y)`, each within the dispatch limit of a dimension.
fn workgroups(n: u32) -> (u32, u32) {
    (n.min(32768), n.div_ceil(32768))
}

/// The RGB of RGBA `f32` values (little-endian bytes, as a buffer maps), over `divisor`.
fn rgb_of(rgba: &[u8], divisor: f32) -> Vec<f32> {
    let mut rgb = Vec::with_capacity(rgba.len() / 16 * 3);
    for v in rgba.chunks_exact(16) {
        for c in 0..3 {
            rgb.push(f32::from_le_bytes([v[4 * c], v[4 * c + 1], v[4 * c + 2], v[4 * c + 3]]) / divisor);
        }
    }
    rgb
}

fn no_bandwidths() -> GpuError {
    render::Error::Invalid("an adaptive frame's prediction needs the bandwidths: Renderer::set_bandwidths".into())
        .into()
}
