//! An adaptive frame (`render::adaptive`) on the GPU, whole: the camera's G-buffer records are
//! uploaded once (from `render::adaptive::Geometry`, the CPU's, so that both renderers plan
//! from the same surfaces), and each frame then runs as one submission, one wait:
//!
//! 1. the prediction at the prediction pixels (`predict_blocks`), the levels of the bandwidth
//!    buffer, the min and max pyramids and the plan of every block (`preview_adaptive.wgsl`),
//!    which counts the shaded blocks per level and per chunk of [`CHUNK`] candidates;
//! 2. their samples (`adaptive_allocate`, one invocation: `render::adaptive::area_allocation`
//!    from the counts per level, in integers, so the CPU's samples exactly), and the list of
//!    shaded blocks in the plan's order, by a prefix sum over the chunks and the candidates
//!    (`adaptive_offsets`, `adaptive_list`), each with its samples and its parts of at most
//!    [`PART`] samples in `shade_blocks`' items;
//! 3. the parts (`shade_blocks`, dispatched with the counts the allocation left: an indirect
//!    dispatch, and the count copied into the shading uniform), their sums put in place, the
//!    up-sampling level by level from the top, and the output image, which comes back with the
//!    control words (the counts, the samples, the status).
//!
//! That is the area allocation, the previewer's default, wherever the budget fits 32 bits and
//! `max_spp` 2^16. The variance and the standard-deviation allocations weight every block by
//! its own variance, which needs a sort by share rather than counts: there the list comes back
//! after step 2's prefix sum, the host allocates with `render::adaptive::allocation` and lays
//! out the parts ([`parts`]), and step 3 is a second submission.
//!
//! The plan is the CPU's in `f32`: the weights agree to `f32` rounding, and the decisions
//! (valid, shaded, rescued, up-sampled) are the same wherever no weight or sum sits within
//! rounding of a threshold (`render::adaptive::MIN_WEIGHT`, `rescue_below`) and no lobe
//! sharpness row boundary is crossed; eq. 11's levels are exact comparisons with powers of two,
//! which give the CPU's levels for the same `f32` bandwidths. The tests hold a frame's plan to
//! the CPU's from the same predictions. The frame's buffers (predictions, pyramid, plan) stay on
//! the GPU unless [`FrameOptions::details`] asks for them.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use render::adaptive::{Action, Adaptive, Allocation, Details, Geometry, Level, Plan, Prediction, Timings};
use render::{Image, Lighting, Material};

use super::{Renderer, no_bandwidths};
use crate::context::check_buffer_fits;
use crate::error::GpuError;
use crate::merl_lookup::capture_errors;

/// `AdaptivePass` of `preview_adaptive.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct AdaptivePass {
    pub(crate) level: u32,
    pub(crate) top: u32,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) out_width: u32,
    pub(crate) out_height: u32,
    pub(crate) ss: u32,
    pub(crate) count: u32,
    pub(crate) level_table: u32,
    pub(crate) sharpness: u32,
    pub(crate) n_rows: u32,
    pub(crate) oracle: u32,
    pub(crate) depth_sigma: f32,
    pub(crate) rescue_below: f32,
    pub(crate) candidates: u32,
    pub(crate) budget: u32,
    pub(crate) max_spp: u32,
    pub(crate) capacity: u32,
    pub(crate) allocate: u32,
    pub(crate) _pad: u32,
}

/// `NONE` of the WGSL: a render pixel without a prediction (not shadeable).
const NONE: u32 = u32::MAX;

/// The WGSL's control words (`preview_adaptive.wgsl`): shaded blocks in all, the status, the
/// samples given, `shade_blocks`' items, the indirect dispatches' workgroups, shaded blocks
/// per level, the allocation's per level, then from `CONTROL_CHUNKS` one per chunk of [`CHUNK`]
/// candidates (the plan's counts); all are cleared each frame, the first `CONTROL_CHUNKS` read
/// back.
const CONTROL_SHADED: u32 = 0;
const CONTROL_STATUS: u32 = 1;
const CONTROL_SAMPLES: u32 = 2;
const CONTROL_PARTS: u32 = 3;
const CONTROL_ARGS: u32 = 4;
const CONTROL_COUNTS: u32 = 16;
const CONTROL_CHUNKS: u32 = 96;
/// Levels the control words have room for (`MAX_LEVELS`): a render up to 65535 pixels a side.
const MAX_LEVELS: usize = 16;
/// Candidates per workgroup of the list's prefix sums (`CHUNK`: 64 invocations of `RUN` 4).
const CHUNK: u32 = 256;

/// What an adaptive frame on the GPU may take besides its settings.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameOptions<'a> {
    /// The image bandwidth of every render pixel (cycles per pixel, row-major) instead of the
    /// prediction's, as `render::adaptive::Hooks::oracle`: uploaded with the frame.
    pub oracle: Option<&'a [f64]>,
    /// Read the frame's buffers back into [`Adaptive::details`] (after the frame's timings).
    pub details: bool,
}

/// The frame's state on the GPU for one geometry (camera and supersampling), prediction level
/// and pyramid top: `preview_adaptive.wgsl`'s state.
#[derive(Debug)]
pub(super) struct State {
    geometry: Arc<Geometry>,
    /// The prediction level and the pyramid's top.
    key: (usize, usize),
    /// `(width, height, first block)` per level.
    levels: Vec<(u32, u32, u32)>,
    blocks: u32,
    /// Blocks that hold a shadeable pixel, per level (`preview_adaptive.wgsl`'s candidates).
    candidates_per_level: Vec<u32>,
    /// The pass uniform with the tables' offsets (the per-pass fields zero).
    base: AdaptivePass,
    /// The prediction pixels (`render::adaptive::prediction_pixels`), as `predict_blocks`'
    /// items.
    items: wgpu::Buffer,
    n_items: u32,
    /// Shadeable render pixels, and output pixels a triangle covers.
    shadeable: usize,
    covered_output: u64,
    buffers: Buffers,
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
    /// For the frame's read-backs (the control words, the list, the image), kept from frame to
    /// frame.
    readback: wgpu::Buffer,
    /// The workgroups of `shade_blocks` and of `adaptive_scatter` where the GPU allocates,
    /// copied from the control words: an indirect dispatch's buffer may not be bound beside it.
    indirect: wgpu::Buffer,
    /// Where the adapter has timestamp queries: the one-submission frame's stages.
    clock: Option<Clock>,
}

/// Four timestamps of a one-submission frame (the starts of its three passes: the prediction; the
/// pyramids, the plan, the samples and the list; the shading, up-sampling and output; and the end
/// of the last), and the buffer they resolve into.
#[derive(Debug)]
struct Clock {
    set: wgpu::QuerySet,
    resolved: wgpu::Buffer,
}

/// Bytes of [`Clock`]'s timestamps.
const CLOCK_BYTES: u64 = 4 * 8;

/// The buffers of `preview_adaptive.wgsl`'s state, in its binding order (3 to 12).
#[derive(Debug)]
struct Buffers {
    records_surface: wgpu::Buffer,
    records_lobe: wgpu::Buffer,
    bandwidths: wgpu::Buffer,
    levels: wgpu::Buffer,
    parents: wgpu::Buffer,
    weights: wgpu::Buffer,
    values: wgpu::Buffer,
    list: wgpu::Buffer,
    tables: wgpu::Buffer,
    control: wgpu::Buffer,
}

impl Buffers {
    fn in_binding_order(&self) -> [&wgpu::Buffer; 10] {
        [
            &self.records_surface,
            &self.records_lobe,
            &self.bandwidths,
            &self.levels,
            &self.parents,
            &self.weights,
            &self.values,
            &self.list,
            &self.tables,
            &self.control,
        ]
    }
}

/// Slots of the pass uniform: levels, `top` reductions, plan, scatter, `top` up-samplings,
/// output.
fn slots(top: usize) -> u64 {
    2 * top as u64 + 4
}

/// The samples of one part of a shaded block, at most (`shade_blocks`): a block's samples run in
/// parts side by side, since one invocation that takes a coarse block's hundreds of samples one
/// after another would hold the whole frame up.
const PART: u32 = 16;

/// `shade_blocks`' items for the shaded blocks of `list` (in the plan's order) with their
/// `samples`: each block's samples in parts of `PART` (or, where that would make more items
/// than the accumulation buffer's `capacity` entries, of the least power of two that does not);
/// and the list's entries for `adaptive_scatter`: the block's index among every level's blocks,
/// its first part, the number of parts, its samples. `adaptive_allocate` and `adaptive_list`
/// lay out the same where the GPU allocates.
fn parts(
    list: &[[u32; 4]],
    samples: &[u32],
    levels: &[(u32, u32, u32)],
    capacity: usize,
) -> (Vec<[u32; 4]>, Vec<[u32; 4]>) {
    let count = |part: u32| samples.iter().map(|&n| n.div_ceil(part) as usize).sum::<usize>();
    let mut part = PART;
    while count(part) > capacity && part < u32::MAX / 2 {
        part *= 2;
    }
    let mut items = Vec::with_capacity(count(part));
    let mut targets = Vec::with_capacity(list.len());
    for (e, &n) in list.iter().zip(samples) {
        let first = items.len() as u32;
        for start in (0..n).step_by(part as usize) {
            items.push([e[3], n, start, part.min(n - start)]);
        }
        targets.push([levels[e[0] as usize].2 + e[1], first, items.len() as u32 - first, n]);
    }
    (items, targets)
}

/// Dispatches one of the adaptive passes in `(x, y)` workgroups, with the pass uniform's slot at
/// byte `offset`.
fn dispatch(
    cpass: &mut wgpu::ComputePass,
    pipeline: &wgpu::ComputePipeline,
    state: &State,
    offset: u64,
    (x, y): (u32, u32),
) {
    cpass.set_pipeline(pipeline);
    cpass.set_bind_group(3, &state.group, &[offset as u32]);
    cpass.dispatch_workgroups(x, y, 1);
}

/// Bytes between the pass uniform's slots: its size rounded up to the dynamic-offset alignment.
fn slot_stride(alignment: u64) -> u64 {
    (size_of::<AdaptivePass>() as u64).div_ceil(alignment) * alignment
}

/// Workgroups of 64 for `count` items, as `(x, y)` within the dispatch limits.
fn groups(count: u32) -> (u32, u32) {
    super::workgroups(count.div_ceil(64).max(1))
}

impl Renderer {
    /// The state for `geometry` and `settings`, made and uploaded when the geometry, the
    /// prediction level or the top changed since the last frame.
    fn adaptive_state(
        &self,
        geometry: &Arc<Geometry>,
        settings: &render::adaptive::Settings,
        material: &Material,
        lighting: &Lighting,
    ) -> Result<(), GpuError> {
        let (width, height) = geometry.render_size();
        let top = render::adaptive::top_level(width, height, settings.max_level);
        let l = settings.prediction_level(top);
        // The geometry is one supersampling's: it and these two fix the state.
        let key = (l, top);
        if let Some(state) = self.adaptive.borrow().as_ref()
            && Arc::ptr_eq(&state.geometry, geometry)
            && state.key == key
        {
            return Ok(());
        }
        let pixels = geometry.pixels();
        let shadeable: Vec<bool> = pixels.iter().map(Option::is_some).collect();
        let (at, of_pixel) = render::adaptive::prediction_pixels(&shadeable, (width, height), l);
        let mut levels = Vec::with_capacity(top + 1);
        let (mut w, mut h, mut blocks) = (width as u32, height as u32, 0u32);
        for _ in 0..=top {
            levels.push((w, h, blocks));
            blocks += w * h;
            (w, h) = (w.div_ceil(2), h.div_ceil(2));
        }
        if levels.len() > MAX_LEVELS {
            return Err(render::Error::Invalid(format!(
                "an adaptive frame of {width} x {height} render pixels has {} levels: at most {MAX_LEVELS}",
                levels.len()
            ))
            .into());
        }
        // The lobe weight's sharpness per view row, as `render::adaptive::render_with` reads it
        // (`check_settings` holds the rows in range where the lobe weight is on).
        let sharpness: Vec<f32> = match lighting.exponents.is_empty() {
            true => vec![0.0; material.view_layers.len()],
            false => {
                material.view_layers.iter().map(|&x| render::layer_exponent(&lighting.exponents, x) as f32).collect()
            }
        };
        let p = (width * height) as u32;
        // The candidates: blocks that hold a shadeable pixel, level by level.
        let mut any_shadeable: Vec<bool> = shadeable.clone();
        let mut candidates: Vec<u32> = (0..p).filter(|&i| shadeable[i as usize]).collect();
        let mut candidates_per_level = vec![candidates.len() as u32];
        for k in 1..levels.len() {
            let ((w, h, first), (cw, ch, _)) = (levels[k], levels[k - 1]);
            let child = &any_shadeable;
            let mine: Vec<bool> = (0..w * h)
                .map(|b| {
                    let (bx, by) = (b % w, b / w);
                    (0..4).any(|j| {
                        let (cx, cy) = (2 * bx + j % 2, 2 * by + j / 2);
                        cx < cw && cy < ch && child[(cy * cw + cx) as usize]
                    })
                })
                .collect();
            let before = candidates.len();
            candidates.extend((0..w * h).filter(|&b| mine[b as usize]).map(|b| first + b));
            candidates_per_level.push((candidates.len() - before) as u32);
            any_shadeable = mine;
        }
        let n_candidates = candidates.len() as u32;
        let candidates_at = 4 * (levels.len() as u32 + 1);
        let sharpness_at = candidates_at + n_candidates;
        let limits = self.device.limits();
        // The largest of the buffers: a vec4 per block.
        let fits = |bytes: u64| check_buffer_fits(&limits, &self.adapter_info, bytes, "an adaptive frame's buffers");
        fits(16 * u64::from(blocks))?;
        fits(16 * u64::from(p))?;
        let base = AdaptivePass {
            top: top as u32,
            width: width as u32,
            height: height as u32,
            out_width: geometry.size().0 as u32,
            out_height: geometry.size().1 as u32,
            ss: settings.supersample as u32,
            level_table: 0,
            sharpness: sharpness_at,
            n_rows: sharpness.len() as u32,
            candidates: candidates_at,
            capacity: p,
            ..Default::default()
        };
        let (mut surface, mut lobe) = (vec![[0f32; 4]; p as usize], vec![[0u32; 4]; p as usize]);
        for (i, (s, l)) in surface.iter_mut().zip(&mut lobe).enumerate() {
            let f = |v: f64| (v as f32).to_bits();
            match &pixels[i] {
                Some(px) => {
                    let [nx, ny] = px.screen_normal;
                    *s = [px.depth, px.cos_o, nx, ny].map(|v| v as f32);
                    *l = [f(px.mirror.x), f(px.mirror.y), f(px.mirror.z), of_pixel[i]];
                }
                None => {
                    // The WGSL's output tells covered pixels without a shading frame by a depth
                    // of 0: a shaded pixel's is positive.
                    s[0] = if geometry.covers(i) { 0.0 } else { -1.0 };
                    l[3] = NONE;
                }
            }
        }
        let mut first_candidate = 0;
        let mut table: Vec<u32> = Vec::with_capacity(4 * (levels.len() + 1));
        for (&(w, h, first), &n) in levels.iter().zip(&candidates_per_level) {
            table.extend([w, h, first, first_candidate]);
            first_candidate += n;
        }
        table.extend([0, 0, blocks, first_candidate]);
        table.extend(&candidates);
        table.extend(sharpness.iter().map(|v| v.to_bits()));
        // Every block not a candidate: min level -1, skipped, for every frame of the geometry.
        let idle: Vec<u32> = [u32::MAX, 0, 0, 0].repeat(blocks as usize);
        let items = super::prediction_items(&at, pixels);
        let state = capture_errors(&self.device, || {
            use wgpu::BufferUsages as U;
            use wgpu::util::DeviceExt;
            let init = |label: &str, contents: &[u8]| {
                self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: U::STORAGE | U::COPY_SRC | U::COPY_DST,
                })
            };
            let empty = |label: &str, bytes: u64| {
                self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes.max(16),
                    usage: U::STORAGE | U::COPY_SRC | U::COPY_DST,
                    mapped_at_creation: false,
                })
            };
            let buffers = Buffers {
                records_surface: init("adaptive records", bytemuck::cast_slice(&surface)),
                records_lobe: init("adaptive records", bytemuck::cast_slice(&lobe)),
                bandwidths: empty("adaptive bandwidths", 4 * u64::from(p)),
                levels: init("adaptive levels", bytemuck::cast_slice(&idle)),
                parents: empty("adaptive parents", 16 * u64::from(blocks)),
                weights: empty("adaptive weights", 16 * u64::from(blocks)),
                values: empty("adaptive values", 16 * u64::from(blocks)),
                list: empty("adaptive list", 16 * u64::from(blocks)),
                tables: init("adaptive tables", bytemuck::cast_slice(&table)),
                control: empty("adaptive control", 4 * u64::from(CONTROL_CHUNKS + n_candidates.div_ceil(CHUNK))),
            };
            let items_buffer = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("adaptive prediction pixels"),
                contents: bytemuck::cast_slice(if items.is_empty() { &[[0u32; 4]][..] } else { &items }),
                usage: wgpu::BufferUsages::COPY_SRC,
            });
            let uniform = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("adaptive passes"),
                size: slot_stride(self.frame_stride) * slots(top),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut entries = vec![wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &uniform,
                    offset: 0,
                    size: wgpu::BufferSize::new(size_of::<AdaptivePass>() as u64),
                }),
            }];
            for (binding, buffer) in (3..).zip(buffers.in_binding_order()) {
                entries.push(wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() });
            }
            let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("adaptive"),
                layout: &self.adaptive_layout,
                entries: &entries,
            });
            let out_pixels = (geometry.size().0 * geometry.size().1) as u64;
            let readback = self.readback_buffer(
                (16 * u64::from(blocks)).max(16 * out_pixels + 4 * u64::from(CONTROL_CHUNKS) + CLOCK_BYTES),
            );
            let clock = self.device.features().contains(wgpu::Features::TIMESTAMP_QUERY).then(|| Clock {
                set: self.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("adaptive stages"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 4,
                }),
                resolved: self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("adaptive stages"),
                    size: CLOCK_BYTES,
                    usage: U::QUERY_RESOLVE | U::COPY_SRC,
                    mapped_at_creation: false,
                }),
            });
            let indirect = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("adaptive indirect dispatches"),
                size: 24,
                usage: U::INDIRECT | U::COPY_DST,
                mapped_at_creation: false,
            });
            State {
                readback,
                indirect,
                clock,
                geometry: Arc::clone(geometry),
                key,
                levels,
                blocks,
                candidates_per_level,
                base,
                items: items_buffer,
                n_items: at.len() as u32,
                shadeable: shadeable.iter().filter(|&&s| s).count(),
                covered_output: geometry.output_coverage().iter().filter(|&&c| c).count() as u64,
                buffers,
                uniform,
                group,
            }
        })?;
        *self.adaptive.borrow_mut() = Some(state);
        Ok(())
    }

    /// One adaptive frame (`render::adaptive`, `brdf-preview --mode adaptive`) of the renderer's
    /// mesh and camera, its output image `supersample` times smaller than the renderer's, with
    /// the bandwidths of [`Renderer::set_bandwidths`], on the GPU whole (module docs): the same
    /// frame as `render::adaptive::render_with` computes on the CPU, to `f32` rounding. The
    /// G-buffer is the camera's ([`Renderer::adaptive_geometry`], made once per camera). The
    /// timings ([`Timings`]): in one submission (the area allocation) its steps on the GPU's
    /// clock where the adapter has one; in two, `predict_ms` the first's wall time (prediction,
    /// pyramids, plan and the list of shaded blocks read back), `plan_ms` the host's allocation,
    /// `shade_ms` the second's (shading, up-sampling, output and its read-back).
    pub fn render_adaptive(
        &self,
        material: &Material,
        lighting: &Lighting,
        settings: &render::adaptive::Settings,
        options: FrameOptions,
    ) -> Result<Adaptive, GpuError> {
        let prediction = self.prediction.as_ref().ok_or_else(no_bandwidths)?;
        let settings = &render::adaptive::check_settings(settings, material, lighting)?;
        let geometry = self.adaptive_geometry(settings.supersample)?;
        let (width, height) = geometry.render_size();
        if let Some(oracle) = options.oracle
            && oracle.len() != width * height
        {
            return Err(render::Error::Invalid(format!(
                "an oracle of {} values for {width} x {height} render pixels",
                oracle.len()
            ))
            .into());
        }
        self.adaptive_state(&geometry, settings, material, lighting)?;
        let borrowed = self.adaptive.borrow();
        let state = borrowed.as_ref().expect("made above");
        let top = state.levels.len() - 1;
        let (out_width, out_height) = geometry.size();
        let clock = std::time::Instant::now();
        let lap = || clock.elapsed().as_secs_f64() * 1e3;

        // The frame's samples: on the GPU under the area allocation, where 32-bit words hold the
        // budget and 64-bit sums of shifts its products (module docs); otherwise on the host.
        let budget = u64::from(settings.spp) * state.covered_output;
        let on_gpu =
            settings.allocation == Allocation::Area && budget <= u64::from(u32::MAX) && settings.max_spp <= 1 << 16;
        let stride = slot_stride(self.frame_stride);
        let base = AdaptivePass {
            depth_sigma: settings.depth_sigma as f32,
            rescue_below: settings.rescue_below as f32,
            n_rows: if settings.lobe_weight { state.base.n_rows } else { 0 },
            oracle: u32::from(options.oracle.is_some()),
            budget: budget.min(u64::from(u32::MAX)) as u32,
            max_spp: settings.max_spp,
            allocate: u32::from(on_gpu),
            ..state.base
        };
        let (levels_slot, plan_slot, scatter_slot) = (0, 1 + top as u64, 2 + top as u64);
        let output_slot = scatter_slot + 1 + top as u64;
        let candidates: u32 = state.candidates_per_level.iter().sum();
        let chunks = candidates.div_ceil(CHUNK).max(1);
        let out_pixels = (out_width * out_height) as u64;
        let pipelines = &self.adaptive_pipelines;
        // The shading uniform of the frame's passes with `items` items (the prediction's, then
        // `shade_blocks`' parts): the estimator, the seed, the pre-convolved estimator's layers.
        let shade_uniform = |items: u32| super::ShadeUniform {
            layer_shift: settings.layer_shift,
            ..self.shade_uniform(
                super::mode_index(settings.mode),
                &render::Settings { mode: settings.mode, spp: items, frames: 1, seed: settings.seed },
            )
        };
        // The shaded blocks' parts (`shade_blocks`), their estimates in place, the up-sampling
        // and the output: `Some(count)` dispatches a known count, `None` the counts
        // `adaptive_allocate` left in the indirect buffer.
        let shading = |cpass: &mut wgpu::ComputePass, parts: Option<u32>, shaded: Option<u32>| {
            cpass.set_pipeline(&self.blocks_pipeline);
            match parts {
                Some(0) => {}
                Some(n) => {
                    let (x, y) = super::item_groups(n);
                    cpass.dispatch_workgroups(x, y, 1);
                }
                None => cpass.dispatch_workgroups_indirect(&state.indirect, 0),
            }
            match shaded {
                Some(n) => dispatch(cpass, &pipelines.scatter, state, scatter_slot * stride, groups(n)),
                None => {
                    cpass.set_pipeline(&pipelines.scatter);
                    cpass.set_bind_group(3, &state.group, &[(scatter_slot * stride) as u32]);
                    cpass.dispatch_workgroups_indirect(&state.indirect, 12);
                }
            }
            for k in (0..top).rev() {
                let slot = scatter_slot + 1 + k as u64;
                dispatch(cpass, &pipelines.upsample, state, slot * stride, groups(state.candidates_per_level[k]));
            }
            dispatch(cpass, &pipelines.output, state, output_slot * stride, groups(out_pixels as u32));
        };

        // Submission 1: prediction, levels, pyramids, plan, the list of shaded blocks in the
        // plan's order; on the GPU also the samples and all of submission 2.
        let control_bytes = 4 * u64::from(CONTROL_CHUNKS);
        let read = capture_errors(&self.device, || {
            self.progress.set(None);
            self.write_predict_uniform(prediction, settings);
            self.queue.write_buffer(&self.shade_uniform, 0, bytemuck::bytes_of(&shade_uniform(state.n_items)));
            self.queue.write_buffer(&self.frame_uniform, 0, &[0u8; 16]);
            if let Some(oracle) = options.oracle {
                let values: Vec<f32> = oracle.iter().map(|&b| b as f32).collect();
                self.queue.write_buffer(&state.buffers.bandwidths, 0, bytemuck::cast_slice(&values));
            }
            // The pass uniform's slots, written at once.
            let mut uniform = vec![0u8; (stride * slots(top)) as usize];
            let mut pass = |slot: u64, fields: AdaptivePass| {
                uniform[(slot * stride) as usize..][..size_of::<AdaptivePass>()]
                    .copy_from_slice(bytemuck::bytes_of(&fields));
            };
            pass(levels_slot, base);
            for k in 1..=top {
                pass(k as u64, AdaptivePass { level: k as u32, ..base });
            }
            pass(plan_slot, AdaptivePass { count: candidates, ..base });
            for slot in scatter_slot..=output_slot {
                let level = (slot - scatter_slot).saturating_sub(1) as u32;
                pass(slot, AdaptivePass { level, ..base });
            }
            self.queue.write_buffer(&state.uniform, 0, &uniform);
            let mut encoder = self.device.create_command_encoder(&Default::default());
            // Every word, the chunks' too: the plan adds to them.
            encoder.clear_buffer(&state.buffers.control, 0, None);
            encoder.copy_buffer_to_buffer(&state.items, 0, &self.accumulation, 0, 16 * u64::from(state.n_items));
            // The one-submission frame's passes start with timestamps where the adapter has them.
            let stamp = |start: u32, end: Option<u32>| {
                let clock = state.clock.as_ref().filter(|_| on_gpu)?;
                Some(wgpu::ComputePassTimestampWrites {
                    query_set: &clock.set,
                    beginning_of_pass_write_index: Some(start),
                    end_of_pass_write_index: end,
                })
            };
            {
                let mut cpass = self.begin_timed_pass(&mut encoder, stamp(0, None));
                if state.n_items > 0 {
                    cpass.set_pipeline(&self.predict_pipeline);
                    cpass.set_bind_group(3, &prediction.group, &[]);
                    let (x, y) = super::item_groups(state.n_items);
                    cpass.dispatch_workgroups(x, y, 1);
                }
                if on_gpu {
                    drop(cpass);
                    cpass = self.begin_timed_pass(&mut encoder, stamp(1, None));
                }
                let run = |cpass: &mut wgpu::ComputePass, pipeline, slot: u64, groups| {
                    dispatch(cpass, pipeline, state, slot * stride, groups)
                };
                let per_level = &state.candidates_per_level;
                run(&mut cpass, &pipelines.levels, levels_slot, groups(per_level[0]));
                for (k, &n) in per_level.iter().enumerate().skip(1) {
                    run(&mut cpass, &pipelines.reduce, k as u64, groups(n));
                }
                run(&mut cpass, &pipelines.plan, plan_slot, groups(candidates));
                if on_gpu {
                    run(&mut cpass, &pipelines.allocate, plan_slot, (1, 1));
                }
                run(&mut cpass, &pipelines.offsets, plan_slot, (1, 1));
                run(&mut cpass, &pipelines.list, plan_slot, super::workgroups(chunks));
            }
            if on_gpu {
                let spp_at = std::mem::offset_of!(super::ShadeUniform, spp) as u64;
                encoder.copy_buffer_to_buffer(
                    &state.buffers.control,
                    4 * u64::from(CONTROL_PARTS),
                    &self.shade_uniform,
                    spp_at,
                    4,
                );
                encoder.copy_buffer_to_buffer(
                    &state.buffers.control,
                    4 * u64::from(CONTROL_ARGS),
                    &state.indirect,
                    0,
                    24,
                );
                shading(&mut self.begin_timed_pass(&mut encoder, stamp(2, Some(3))), None, None);
                if let Some(clock) = state.clock.as_ref() {
                    encoder.resolve_query_set(&clock.set, 0..4, &clock.resolved, 0);
                }
            }
            encoder
        })
        .and_then(|encoder| {
            let image = if on_gpu { 16 * out_pixels } else { 0 };
            let stamps = match &state.clock {
                Some(clock) if on_gpu => (&clock.resolved, CLOCK_BYTES),
                _ => (&state.buffers.control, 0),
            };
            let sources = [(&self.accumulation, image), (&state.buffers.control, control_bytes), stamps];
            // The image's RGB, the control words, the timestamps.
            self.submit_and_map(encoder, &sources, &state.readback, |bytes| {
                let (image, rest) = bytes.split_at(image as usize);
                let words: Vec<u32> = bytemuck::pod_collect_to_vec(rest);
                let (control, stamps) = words.split_at(CONTROL_CHUNKS as usize);
                (super::rgb_of(image, 1.0), control.to_vec(), stamps.to_vec())
            })
        })?;
        let predict_ms = lap();
        let (image_rgb, control, stamps) = read;
        let n_shaded = control[CONTROL_SHADED as usize];
        let counts = &control[CONTROL_COUNTS as usize..][..=top];
        let shaded_per_level: Vec<usize> = counts.iter().map(|&n| n as usize).collect();
        if control[CONTROL_STATUS as usize] != 0 {
            render::adaptive::check_budget(u64::from(n_shaded), budget)?;
        }

        let (rgb, samples, plan_ms) = if on_gpu {
            (image_rgb, u64::from(control[CONTROL_SAMPLES as usize]), predict_ms)
        } else {
            // The host: the samples, then submission 2: shading, estimates in place,
            // up-sampling, output.
            let encoder = self.device.create_command_encoder(&Default::default());
            let shaded: Vec<u32> =
                self.submit_and_read(encoder, &[(&state.buffers.list, 16 * u64::from(n_shaded))], &state.readback)?;
            let list: Vec<[u32; 4]> = shaded.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
            let blocks_in: Vec<(usize, f64)> =
                list.iter().map(|e| (e[0] as usize, f64::from(f32::from_bits(e[2])))).collect();
            let samples = render::adaptive::allocation(&blocks_in, budget, settings)?;
            let (items, targets) = parts(&list, &samples, &state.levels, width * height);
            let plan_ms = lap();
            let rgb = capture_errors(&self.device, || {
                let shade = shade_uniform(items.len() as u32);
                self.queue.write_buffer(&self.shade_uniform, 0, bytemuck::bytes_of(&shade));
                if !items.is_empty() {
                    self.queue.write_buffer(&self.accumulation, 0, bytemuck::cast_slice(&items));
                    self.queue.write_buffer(&state.buffers.list, 0, bytemuck::cast_slice(&targets));
                }
                let mut encoder = self.device.create_command_encoder(&Default::default());
                shading(&mut self.begin_pass(&mut encoder), Some(items.len() as u32), Some(n_shaded));
                encoder
            })
            .and_then(|encoder| {
                let sources = [(&self.accumulation, 16 * out_pixels)];
                self.submit_and_map(encoder, &sources, &state.readback, |rgba| super::rgb_of(rgba, 1.0))
            })?;
            (rgb, samples.iter().map(|&n| u64::from(n)).sum(), plan_ms)
        };
        let shade_ms = lap();
        let image = Image { width: out_width, height: out_height, rgb, covered: geometry.output_coverage().to_vec() };
        let details = if options.details { Some(self.adaptive_details(state, n_shaded, budget)?) } else { None };
        Ok(Adaptive {
            image,
            width,
            height,
            shadeable: state.shadeable,
            shaded_per_level,
            samples,
            budget,
            timings: if on_gpu {
                // The stages on the GPU's clock; without one, all of it is the shading's.
                let ticks: Vec<u64> = stamps.chunks_exact(2).map(|w| u64::from(w[0]) | u64::from(w[1]) << 32).collect();
                let period_ms = f64::from(self.queue.get_timestamp_period()) * 1e-6;
                let ms = |a: usize, b: usize| ticks[b].saturating_sub(ticks[a]) as f64 * period_ms;
                let (predict_ms, plan_ms, stages_ms) =
                    if ticks.len() == 4 { (ms(0, 1), ms(1, 2), ms(2, 3)) } else { (0.0, 0.0, shade_ms) };
                Timings {
                    gbuffer_ms: geometry.millis(),
                    predict_ms,
                    plan_ms,
                    shade_ms: stages_ms,
                    total_ms: shade_ms,
                    submissions: 1,
                    gpu_clock: ticks.len() == 4,
                }
            } else {
                Timings {
                    gbuffer_ms: geometry.millis(),
                    predict_ms,
                    plan_ms: plan_ms - predict_ms,
                    shade_ms: shade_ms - plan_ms,
                    total_ms: shade_ms,
                    submissions: 2,
                    gpu_clock: false,
                }
            },
            details,
        })
    }

    /// The frame's buffers read back (`Adaptive::details`): the predictions, the pyramid and
    /// the plan, with the samples of the `n_shaded` shaded blocks (the list's entries).
    fn adaptive_details(&self, state: &State, n_shaded: u32, budget: u64) -> Result<Details, GpuError> {
        let (base, buffers) = (&state.base, &state.buffers);
        let pixels = (base.width * base.height) as usize;
        let bandwidth = self.read_words(&buffers.bandwidths, pixels as u32)?;
        let levels_words = self.read_words(&buffers.levels, 4 * state.blocks)?;
        let parents = self.read_words(&buffers.parents, 4 * state.blocks)?;
        let weights = self.read_words(&buffers.weights, 4 * state.blocks)?;
        let list = self.read_words(&buffers.list, 4 * n_shaded)?;
        let given: std::collections::HashMap<u32, u32> = list.chunks_exact(4).map(|e| (e[0], e[3])).collect();
        let mut levels = Vec::with_capacity(state.levels.len());
        let mut actions = Vec::with_capacity(state.levels.len());
        for (k, &(w, h, first)) in state.levels.iter().enumerate() {
            let range = first as usize..(first + w * h) as usize;
            levels.push(Level {
                level: k,
                width: w as usize,
                height: h as usize,
                min_level: range.clone().map(|b| levels_words[4 * b] as i32).collect(),
                max_variance: range.clone().map(|b| f64::from(f32::from_bits(levels_words[4 * b + 1]))).collect(),
            });
            actions.push(
                range
                    .map(|block| {
                        let action = levels_words[4 * block + 2];
                        let samples = || given.get(&(block as u32)).copied().unwrap_or(0);
                        match action & 0xff {
                            1 => Action::Shade { samples: samples(), rescued: false },
                            2 => Action::Shade { samples: samples(), rescued: true },
                            3 => {
                                let parents = std::array::from_fn(|m| {
                                    (parents[4 * block + m], f32::from_bits(weights[4 * block + m]))
                                });
                                Action::Upsample { parents, count: (action >> 8) as u8 }
                            }
                            _ => Action::Skip,
                        }
                    })
                    .collect(),
            );
        }
        // A pixel that is not shadeable has no prediction (its bandwidth word may hold an oracle's).
        let predictions = (0..pixels)
            .map(|p| match levels[0].min_level[p] {
                -1 => Prediction { level: -1, ..Prediction::default() },
                level => Prediction {
                    bandwidth: f64::from(f32::from_bits(bandwidth[p])),
                    variance: levels[0].max_variance[p],
                    level,
                },
            })
            .collect();
        let plan = Plan { levels, actions, budget };
        let (shaded_level, samples_per_pixel) = Details::origins(&plan);
        Ok(Details { predictions, plan, shaded_level, samples_per_pixel })
    }

    /// The first `count` words of `buffer`, read back.
    fn read_words(&self, buffer: &wgpu::Buffer, count: u32) -> Result<Vec<u32>, GpuError> {
        let bytes = 4 * u64::from(count);
        let encoder = self.device.create_command_encoder(&Default::default());
        self.submit_and_read(encoder, &[(buffer, bytes)], &self.readback_buffer(bytes))
    }
}

/// The adaptive frame's pipelines (`preview_adaptive.wgsl`), group 3 from
/// [`Renderer`]'s `adaptive_layout`.
#[derive(Debug)]
pub(super) struct Pipelines {
    pub levels: wgpu::ComputePipeline,
    pub reduce: wgpu::ComputePipeline,
    pub plan: wgpu::ComputePipeline,
    pub scatter: wgpu::ComputePipeline,
    pub upsample: wgpu::ComputePipeline,
    pub output: wgpu::ComputePipeline,
    pub allocate: wgpu::ComputePipeline,
    pub offsets: wgpu::ComputePipeline,
    pub list: wgpu::ComputePipeline,
}

impl Pipelines {
    pub(super) fn new(make: impl Fn(&'static str) -> wgpu::ComputePipeline) -> Pipelines {
        Pipelines {
            levels: make("adaptive_levels"),
            reduce: make("adaptive_reduce"),
            plan: make("adaptive_plan"),
            scatter: make("adaptive_scatter"),
            upsample: make("adaptive_upsample"),
            output: make("adaptive_output"),
            allocate: make("adaptive_allocate"),
            offsets: make("adaptive_offsets"),
            list: make("adaptive_list"),
        }
    }
}

/// The layout of group 3 of the adaptive passes: binding 2 the pass uniform (one slot per pass),
/// 3 to 12 the state's buffers ([`Buffers`]; the records and the tables read-only).
pub(super) fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let compute = wgpu::ShaderStages::COMPUTE;
    let mut entries = vec![super::uniform_entry(2, compute, true)];
    entries.extend((3..=12).map(|binding| super::storage_entry(binding, compute, matches!(binding, 3 | 4 | 11))));
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("adaptive"), entries: &entries })
}

#[cfg(test)]
mod tests {
    use super::{
        CHUNK, CONTROL_ARGS, CONTROL_CHUNKS, CONTROL_COUNTS, CONTROL_PARTS, CONTROL_SAMPLES, CONTROL_SHADED,
        CONTROL_STATUS, MAX_LEVELS, PART, parts,
    };
    use crate::wgsl::PREVIEW_ADAPTIVE;

    #[test]
    fn the_constants_match_the_wgsl() {
        let weight = format!("const MIN_WEIGHT: f32 = {:e};", render::adaptive::MIN_WEIGHT);
        let declared = PREVIEW_ADAPTIVE.source.lines().find(|l| l.starts_with("const MIN_WEIGHT")).unwrap();
        let value: f64 = declared.split('=').nth(1).unwrap().trim().trim_end_matches(';').parse().unwrap();
        assert_eq!(value, render::adaptive::MIN_WEIGHT, "{declared} against {weight}");
        assert!(PREVIEW_ADAPTIVE.source.contains("const NONE: u32 = 0xffffffffu;"));
        for (name, value) in [
            ("CONTROL_SHADED", CONTROL_SHADED),
            ("CONTROL_STATUS", CONTROL_STATUS),
            ("CONTROL_SAMPLES", CONTROL_SAMPLES),
            ("CONTROL_PARTS", CONTROL_PARTS),
            ("CONTROL_ARGS", CONTROL_ARGS),
            ("CONTROL_COUNTS", CONTROL_COUNTS),
            ("CONTROL_CHUNKS", CONTROL_CHUNKS),
            ("MAX_LEVELS", MAX_LEVELS as u32),
            ("CHUNK", CHUNK),
            ("RUN", CHUNK / 64),
        ] {
            let line = format!("const {name}: u32 = {value}u;");
            assert!(PREVIEW_ADAPTIVE.source.contains(&line), "the WGSL lacks {line}");
        }
        // Per level 4 words from CONTROL_LEVELS, for every level, before the chunks.
        assert!(PREVIEW_ADAPTIVE.source.contains("const CONTROL_LEVELS: u32 = 32u;"));
        assert!(32 + 4 * MAX_LEVELS as u32 <= CONTROL_CHUNKS && CONTROL_COUNTS as usize + MAX_LEVELS <= 32);
    }

    #[test]
    fn a_blocks_parts_cover_its_samples_once() {
        let levels = [(8, 8, 0), (4, 4, 64), (2, 2, 80)];
        let list = [[0, 5, 0, 5], [1, 3, 0, 7], [2, 1, 0, 9]];
        let samples = [1, 40, 256];
        for (capacity, part) in [(1000, PART), (10, 128)] {
            let (items, targets) = parts(&list, &samples, &levels, capacity);
            assert!(items.len() <= capacity, "{} items", items.len());
            assert_eq!(targets.iter().map(|t| t[0]).collect::<Vec<_>>(), [5, 67, 81]);
            assert_eq!(targets.iter().map(|t| t[3]).collect::<Vec<_>>(), samples);
            for (t, (e, &n)) in targets.iter().zip(list.iter().zip(&samples)) {
                let mine = &items[t[1] as usize..(t[1] + t[2]) as usize];
                // Consecutive ranges from 0 to n, each at most a part, all of the block's pixel.
                let mut next = 0;
                for item in mine {
                    assert_eq!([item[0], item[1], item[2]], [e[3], n, next]);
                    assert!(item[3] >= 1 && item[3] <= part, "{item:?}");
                    next += item[3];
                }
                assert_eq!(next, n);
            }
        }
    }
}
