//! An adaptive frame (`render::adaptive`) on the GPU, whole: the camera's G-buffer records are
//! uploaded once (from `render::adaptive::Geometry`, the CPU's, so that both renderers plan
//! from the same surfaces), and each frame then runs as one submission, one wait:
//!
//! 1. the prediction at the prediction pixels (`predict_blocks`), the levels of the bandwidth
//!    buffer, the min and max pyramids and the plan of every block (`predict.wgsl`, `plan.wgsl`),
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

use bytemuck::{Pod, Zeroable};
use render::adaptive::{Action, Adaptive, Allocation, Details, Level, Plan, Prediction, Timings};
use render::{Image, Lighting, Material};

use super::{Renderer, no_bandwidths};

mod state;

use crate::device::capture_errors;
use crate::error::GpuError;
use state::*;
pub(super) use state::{Pipelines, State, storage_buffers};
#[cfg(test)]
pub(crate) use state::{RecordLobe, RecordSurface};

/// `AdaptivePass` of `state.wgsl`.
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

/// The WGSL's control words (`state.wgsl`): shaded blocks in all, the status, the
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

/// Bytes between the pass uniform's slots: its size rounded up to the dynamic-offset alignment.
fn slot_stride(alignment: u64) -> u64 {
    (size_of::<AdaptivePass>() as u64).div_ceil(alignment) * alignment
}

/// The passes of one adaptive frame after its prediction, and their slots of the pass uniform:
/// the levels' (0), one per coarser level's reduction (1 to `top`), the plan's, the scatter's,
/// one per level's up-sampling and the output's.
struct Passes<'a> {
    renderer: &'a Renderer,
    state: &'a State,
    pipelines: &'a Pipelines,
    /// Bytes between the slots.
    stride: u64,
    top: usize,
    out_pixels: u64,
}

impl Passes<'_> {
    const LEVELS_SLOT: u64 = 0;

    fn plan_slot(&self) -> u64 {
        1 + self.top as u64
    }

    fn scatter_slot(&self) -> u64 {
        2 + self.top as u64
    }

    fn output_slot(&self) -> u64 {
        self.scatter_slot() + 1 + self.top as u64
    }

    /// Sets one of the adaptive passes, with the pass uniform's slot `slot`. Groups 2 and 3 are
    /// bound again after the pipeline: the adaptive passes' layouts leave groups 0 and 1 out where
    /// the estimators' name them, and Vulkan disturbs a set bound under a layout whose lower sets
    /// differ, which wgpu does not bind again (on lavapipe a second frame then read stale bindings
    /// and differed from the first); `shade_blocks` binds 0 to 2 likewise.
    fn bind(&self, cpass: &mut wgpu::ComputePass, pipeline: &wgpu::ComputePipeline, slot: u64) {
        cpass.set_pipeline(pipeline);
        cpass.set_bind_group(2, &self.renderer.render_group, &[0]);
        cpass.set_bind_group(3, &self.state.group, &[(slot * self.stride) as u32]);
    }

    /// Dispatches one of the adaptive passes in `(x, y)` workgroups ([`Passes::bind`]).
    fn run(&self, cpass: &mut wgpu::ComputePass, pipeline: &wgpu::ComputePipeline, slot: u64, (x, y): (u32, u32)) {
        self.bind(cpass, pipeline, slot);
        cpass.dispatch_workgroups(x, y, 1);
    }

    /// The pass uniform's slots, written at once: `base` with each pass's level or count.
    fn uniform(&self, base: AdaptivePass, candidates: u32) -> Vec<u8> {
        let mut uniform = vec![0u8; (self.stride * slots(self.top)) as usize];
        let mut pass = |slot: u64, fields: AdaptivePass| {
            uniform[(slot * self.stride) as usize..][..size_of::<AdaptivePass>()]
                .copy_from_slice(bytemuck::bytes_of(&fields));
        };
        pass(Self::LEVELS_SLOT, base);
        for k in 1..=self.top {
            pass(k as u64, AdaptivePass { level: k as u32, ..base });
        }
        pass(self.plan_slot(), AdaptivePass { count: candidates, ..base });
        for slot in self.scatter_slot()..=self.output_slot() {
            let level = (slot - self.scatter_slot()).saturating_sub(1) as u32;
            pass(slot, AdaptivePass { level, ..base });
        }
        uniform
    }

    /// The levels, their grading, the pyramids, the plan of every candidate, where the GPU
    /// allocates its samples, and the list of shaded blocks (`chunks` chunks of candidates).
    fn plan(&self, cpass: &mut wgpu::ComputePass, candidates: u32, chunks: u32, on_gpu: bool) {
        let (pipelines, per_level) = (self.pipelines, &self.state.candidates_per_level);
        self.run(cpass, &pipelines.levels, Self::LEVELS_SLOT, groups(per_level[0]));
        self.run(cpass, &pipelines.grade, Self::LEVELS_SLOT, groups(per_level[0]));
        self.run(cpass, &pipelines.grade_apply, Self::LEVELS_SLOT, groups(per_level[0]));
        for (k, &n) in per_level.iter().enumerate().skip(1) {
            self.run(cpass, &pipelines.reduce, k as u64, groups(n));
        }
        self.run(cpass, &pipelines.plan, self.plan_slot(), groups(candidates));
        if on_gpu {
            self.run(cpass, &pipelines.allocate, self.plan_slot(), (1, 1));
        }
        self.run(cpass, &pipelines.offsets, self.plan_slot(), (1, 1));
        self.run(cpass, &pipelines.list, self.plan_slot(), super::workgroups(chunks));
    }

    /// Submission 1: the prediction, the levels, pyramids and plan, the list of shaded blocks in
    /// the plan's order; where the GPU allocates (`on_gpu`) also the samples and all of
    /// submission 2, the passes after the prediction's timestamped where the adapter can.
    fn encode(
        &self,
        prediction: &super::Prediction,
        candidates: u32,
        chunks: u32,
        on_gpu: bool,
    ) -> wgpu::CommandEncoder {
        let (renderer, state) = (self.renderer, self.state);
        let mut encoder = renderer.device.create_command_encoder(&Default::default());
        // Every word, the chunks' too: the plan adds to them.
        encoder.clear_buffer(&state.buffers.control, 0, None);
        encoder.copy_buffer_to_buffer(&state.items, 0, &renderer.accumulation, 0, 16 * u64::from(state.n_items));
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
            let mut cpass = renderer.begin_timed_pass(&mut encoder, stamp(0, None));
            if state.n_items > 0 {
                cpass.set_pipeline(&self.pipelines.predict);
                cpass.set_bind_group(3, &prediction.group, &[]);
                let (x, y) = super::item_groups(state.n_items);
                cpass.dispatch_workgroups(x, y, 1);
            }
            if on_gpu {
                drop(cpass);
                cpass = renderer.begin_timed_pass(&mut encoder, stamp(1, None));
            }
            self.plan(&mut cpass, candidates, chunks, on_gpu);
        }
        if on_gpu {
            let items_at = std::mem::offset_of!(super::ShadeUniform, items) as u64;
            let control = &state.buffers.control;
            encoder.copy_buffer_to_buffer(control, 4 * u64::from(CONTROL_PARTS), &renderer.shade_uniform, items_at, 4);
            encoder.copy_buffer_to_buffer(control, 4 * u64::from(CONTROL_ARGS), &state.indirect, 0, 24);
            self.shade(&mut renderer.begin_timed_pass(&mut encoder, stamp(2, Some(3))), None, None);
            if let Some(clock) = state.clock.as_ref() {
                encoder.resolve_query_set(&clock.set, 0..4, &clock.resolved, 0);
            }
        }
        encoder
    }

    /// Submission 1 written, encoded ([`Passes::encode`]), submitted and read back: the frame's
    /// uniforms (the prediction's, the shading's `shade`, the passes' from `budget`), the oracle's
    /// bandwidths where it has one; then the image (where the GPU allocates), the control words and
    /// the timestamps.
    fn submit_first(
        &self,
        prediction: &super::Prediction,
        settings: &render::adaptive::Settings,
        oracle: Option<&[f64]>,
        budget: Budget,
        shade: super::ShadeUniform,
    ) -> Result<FirstRead, GpuError> {
        let (renderer, state) = (self.renderer, self.state);
        let base = AdaptivePass {
            depth_sigma: settings.depth_sigma as f32,
            rescue_below: settings.rescue_below as f32,
            n_rows: if settings.lobe_weight { state.base.n_rows } else { 0 },
            oracle: u32::from(oracle.is_some()),
            budget: budget.total.min(u64::from(u32::MAX)) as u32,
            max_spp: settings.max_spp,
            allocate: u32::from(budget.on_gpu),
            ..state.base
        };
        let candidates: u32 = state.candidates_per_level.iter().sum();
        let chunks = candidates.div_ceil(CHUNK).max(1);
        let encoder = capture_errors(&renderer.device, || {
            renderer.progress.set(None);
            renderer.write_predict_uniform(prediction, settings);
            renderer.queue.write_buffer(&renderer.shade_uniform, 0, bytemuck::bytes_of(&shade));
            renderer.queue.write_buffer(
                &renderer.frame_uniform,
                0,
                bytemuck::bytes_of(&super::FrameUniform::default()),
            );
            if let Some(oracle) = oracle {
                let values: Vec<f32> = oracle.iter().map(|&b| b as f32).collect();
                renderer.queue.write_buffer(&state.buffers.bandwidths, 0, bytemuck::cast_slice(&values));
            }
            renderer.queue.write_buffer(&state.uniform, 0, &self.uniform(base, candidates));
            self.encode(prediction, candidates, chunks, budget.on_gpu)
        })?;
        let image = if budget.on_gpu { 16 * self.out_pixels } else { 0 };
        let stamps = match &state.clock {
            Some(clock) if budget.on_gpu => (&clock.resolved, CLOCK_BYTES),
            _ => (&state.buffers.control, 0),
        };
        let control_bytes = 4 * u64::from(CONTROL_CHUNKS);
        let sources = [(&renderer.accumulation, image), (&state.buffers.control, control_bytes), stamps];
        renderer.submit_and_map(encoder, &sources, &state.readback, |bytes| {
            let (image, rest) = bytes.split_at(image as usize);
            let words: Vec<u32> = bytemuck::pod_collect_to_vec(rest);
            let (control, stamps) = words.split_at(CONTROL_CHUNKS as usize);
            FirstRead { image_rgb: super::rgb_of(image, 1.0), control: control.to_vec(), stamps: stamps.to_vec() }
        })
    }

    /// The samples of the `n_shaded` blocks of the list, allocated on the host
    /// (`render::adaptive::allocation`) from their variances.
    fn allocate_on_host(
        &self,
        n_shaded: u32,
        budget: u64,
        settings: &render::adaptive::Settings,
        (width, height): (usize, usize),
    ) -> Result<HostSamples, GpuError> {
        let (renderer, state) = (self.renderer, self.state);
        let encoder = renderer.device.create_command_encoder(&Default::default());
        let shaded: Vec<u32> =
            renderer.submit_and_read(encoder, &[(&state.buffers.list, 16 * u64::from(n_shaded))], &state.readback)?;
        let list: Vec<[u32; 4]> = shaded.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let blocks_in: Vec<(usize, f64)> =
            list.iter().map(|e| (e[0] as usize, f64::from(f32::from_bits(e[2])))).collect();
        let samples = render::adaptive::allocation(&blocks_in, budget, settings)?;
        let (items, targets) = parts(&list, &samples, &state.levels, width * height);
        Ok(HostSamples { total: samples.iter().map(|&n| u64::from(n)).sum(), items, targets })
    }

    /// Submission 2 of a frame whose samples the host allocated: the parts, their estimates in
    /// place, the up-sampling and the output, read back as RGB.
    fn shade_on_host(
        &self,
        samples: &HostSamples,
        n_shaded: u32,
        shade_uniform: &dyn Fn(u32) -> super::ShadeUniform,
    ) -> Result<Vec<f32>, GpuError> {
        let (renderer, state) = (self.renderer, self.state);
        let HostSamples { items, targets, .. } = samples;
        capture_errors(&renderer.device, || {
            let shade = shade_uniform(items.len() as u32);
            renderer.queue.write_buffer(&renderer.shade_uniform, 0, bytemuck::bytes_of(&shade));
            if !items.is_empty() {
                renderer.queue.write_buffer(&renderer.accumulation, 0, bytemuck::cast_slice(items));
                renderer.queue.write_buffer(&state.buffers.list, 0, bytemuck::cast_slice(targets));
            }
            let mut encoder = renderer.device.create_command_encoder(&Default::default());
            self.shade(&mut renderer.begin_pass(&mut encoder), Some(items.len() as u32), Some(n_shaded));
            encoder
        })
        .and_then(|encoder| {
            let sources = [(&renderer.accumulation, 16 * self.out_pixels)];
            renderer.submit_and_map(encoder, &sources, &state.readback, |rgba| super::rgb_of(rgba, 1.0))
        })
    }

    /// The shaded blocks' parts (`shade_blocks`), their estimates in place, the up-sampling and
    /// the output: `Some(count)` dispatches a known count, `None` the counts `adaptive_allocate`
    /// left in the indirect buffer.
    fn shade(&self, cpass: &mut wgpu::ComputePass, parts: Option<u32>, shaded: Option<u32>) {
        let (pipelines, state) = (self.pipelines, self.state);
        cpass.set_pipeline(&pipelines.blocks);
        self.renderer.bind_estimator_groups(cpass);
        match parts {
            Some(0) => {}
            Some(n) => {
                let (x, y) = super::item_groups(n);
                cpass.dispatch_workgroups(x, y, 1);
            }
            None => cpass.dispatch_workgroups_indirect(&state.indirect, 0),
        }
        match shaded {
            Some(n) => self.run(cpass, &pipelines.scatter, self.scatter_slot(), groups(n)),
            None => {
                self.bind(cpass, &pipelines.scatter, self.scatter_slot());
                cpass.dispatch_workgroups_indirect(&state.indirect, 12);
            }
        }
        for k in (0..self.top).rev() {
            let slot = self.scatter_slot() + 1 + k as u64;
            self.run(cpass, &pipelines.upsample, slot, groups(state.candidates_per_level[k]));
        }
        self.run(cpass, &pipelines.output, self.output_slot(), groups(self.out_pixels as u32));
    }
}

/// A frame's budget of samples and where they are allocated: on the GPU under the area
/// allocation, where 32-bit words hold the budget and 64-bit sums of shifts its products (module
/// docs); otherwise on the host.
#[derive(Clone, Copy)]
struct Budget {
    total: u64,
    on_gpu: bool,
}

impl Budget {
    fn new(settings: &render::adaptive::Settings, covered_output: u64) -> Self {
        let total = u64::from(settings.spp) * covered_output;
        let on_gpu =
            settings.allocation == Allocation::Area && total <= u64::from(u32::MAX) && settings.max_spp <= 1 << 16;
        Self { total, on_gpu }
    }
}

/// What submission 1 reads back: the image's RGB (empty unless the GPU allocated the samples,
/// where the frame is done), the control words and the timestamps.
struct FirstRead {
    image_rgb: Vec<f32>,
    control: Vec<u32>,
    stamps: Vec<u32>,
}

/// An oracle's bandwidths must cover the `width` x `height` render pixels.
fn check_oracle(oracle: Option<&[f64]>, width: usize, height: usize) -> Result<(), GpuError> {
    match oracle {
        Some(oracle) if oracle.len() != width * height => Err(render::Error::Invalid(format!(
            "an oracle of {} values for {width} x {height} render pixels",
            oracle.len()
        ))
        .into()),
        _ => Ok(()),
    }
}

/// The samples the host allocated for a frame: their total, `shade_blocks`' items and the list's
/// targets ([`parts`]).
struct HostSamples {
    total: u64,
    items: Vec<[u32; 4]>,
    targets: Vec<[u32; 4]>,
}

/// A frame's timings: in one submission (`gpu`: its timestamps and their period) the stages on
/// the GPU's clock where it has one, all of it the shading's otherwise; in two, the wall clock's
/// laps at the prediction's end, the host's allocation's and the frame's (ms).
fn frame_timings(
    gpu: Option<(&[u32], f32)>,
    gbuffer_ms: f64,
    (predict_ms, plan_ms, shade_ms): (f64, f64, f64),
) -> Timings {
    let Some((stamps, period)) = gpu else {
        return Timings {
            gbuffer_ms,
            predict_ms,
            plan_ms: plan_ms - predict_ms,
            shade_ms: shade_ms - plan_ms,
            total_ms: shade_ms,
            submissions: 2,
            gpu_clock: false,
        };
    };
    let ticks: Vec<u64> = stamps.chunks_exact(2).map(|w| u64::from(w[0]) | u64::from(w[1]) << 32).collect();
    let period_ms = f64::from(period) * 1e-6;
    let ms = |a: usize, b: usize| ticks[b].saturating_sub(ticks[a]) as f64 * period_ms;
    let (predict_ms, plan_ms, stages_ms) =
        if ticks.len() == 4 { (ms(0, 1), ms(1, 2), ms(2, 3)) } else { (0.0, 0.0, shade_ms) };
    Timings {
        gbuffer_ms,
        predict_ms,
        plan_ms,
        shade_ms: stages_ms,
        total_ms: shade_ms,
        submissions: 1,
        gpu_clock: ticks.len() == 4,
    }
}

/// Workgroups of 64 for `count` items, as `(x, y)` within the dispatch limits.
fn groups(count: u32) -> (u32, u32) {
    super::workgroups(count.div_ceil(64).max(1))
}

impl Renderer {
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
        check_oracle(options.oracle, width, height)?;
        self.adaptive_state(&geometry, settings, material, lighting)?;
        let borrowed = self.adaptive.borrow();
        let state = borrowed.as_ref().expect("made above");
        let top = state.levels.len() - 1;
        let (out_width, out_height) = geometry.size();
        let clock = std::time::Instant::now();
        let lap = || clock.elapsed().as_secs_f64() * 1e3;
        let budget = Budget::new(settings, state.covered_output);
        // The shading uniform of the frame's passes with `items` items (the prediction's, then
        // `shade_blocks`' parts): the estimator, the seed, the prefiltered estimator's layers.
        let shade_uniform = |items: u32| super::ShadeUniform {
            layer_shift: settings.layer_shift,
            items,
            filter_samples: settings.frames,
            ..self.shade_uniform(
                super::mode_index(settings.estimator),
                &render::Settings { estimator: settings.estimator, spp: 1, frames: 1, seed: settings.seed },
            )
        };
        let passes = Passes {
            renderer: self,
            state,
            pipelines: self.adaptive_pipelines()?,
            stride: slot_stride(self.frame_stride),
            top,
            out_pixels: (out_width * out_height) as u64,
        };

        let first = passes.submit_first(prediction, settings, options.oracle, budget, shade_uniform(state.n_items))?;
        let predict_ms = lap();
        let n_shaded = first.control[CONTROL_SHADED as usize];
        let counts = &first.control[CONTROL_COUNTS as usize..][..=top];
        if first.control[CONTROL_STATUS as usize] != 0 {
            render::adaptive::check_budget(u64::from(n_shaded), budget.total)?;
        }
        let (rgb, samples, plan_ms) = if budget.on_gpu {
            (first.image_rgb, u64::from(first.control[CONTROL_SAMPLES as usize]), predict_ms)
        } else {
            // The host: the samples, then submission 2: shading, estimates in place,
            // up-sampling, output.
            let samples = passes.allocate_on_host(n_shaded, budget.total, settings, (width, height))?;
            let plan_ms = lap();
            let rgb = passes.shade_on_host(&samples, n_shaded, &shade_uniform)?;
            (rgb, samples.total, plan_ms)
        };
        let shade_ms = lap();
        let details = if options.details { Some(self.adaptive_details(state, n_shaded, budget.total)?) } else { None };
        Ok(Adaptive {
            image: Image { width: out_width, height: out_height, rgb, covered: geometry.output_coverage().to_vec() },
            width,
            height,
            shadeable: state.shadeable,
            shaded_per_level: counts.iter().map(|&n| n as usize).collect(),
            samples,
            budget: budget.total,
            timings: frame_timings(
                budget.on_gpu.then_some((&first.stamps[..], self.queue.get_timestamp_period())),
                geometry.millis(),
                (predict_ms, plan_ms, shade_ms),
            ),
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

#[cfg(test)]
mod tests {
    use super::{
        CHUNK, CONTROL_ARGS, CONTROL_CHUNKS, CONTROL_COUNTS, CONTROL_PARTS, CONTROL_SAMPLES, CONTROL_SHADED,
        CONTROL_STATUS, MAX_LEVELS, PART, parts,
    };
    use crate::wgsl::ADAPTIVE_STATE;

    #[test]
    fn the_constants_match_the_wgsl() {
        let weight = format!("const MIN_WEIGHT: f32 = {:e};", render::adaptive::MIN_WEIGHT);
        let declared = ADAPTIVE_STATE.source.lines().find(|l| l.starts_with("const MIN_WEIGHT")).unwrap();
        let value: f64 = declared.split('=').nth(1).unwrap().trim().trim_end_matches(';').parse().unwrap();
        assert_eq!(value, render::adaptive::MIN_WEIGHT, "{declared} against {weight}");
        let rate = format!("const SAMPLES_PER_CYCLE: f32 = {:.1};", render::adaptive::SAMPLES_PER_CYCLE);
        assert!(ADAPTIVE_STATE.source.contains(&rate), "the WGSL lacks {rate}");
        assert!(ADAPTIVE_STATE.source.contains("const NONE: u32 = 0xffffffffu;"));
        for decl in [
            format!("const GRADE_RADIUS: i32 = {};", render::adaptive::GRADE_RADIUS),
            format!("const GRADE_SLACK: i32 = {};", render::adaptive::GRADE_SLACK),
        ] {
            assert!(crate::wgsl::ADAPTIVE_PLAN.source.contains(&decl), "plan.wgsl lacks {decl}");
        }
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
            assert!(ADAPTIVE_STATE.source.contains(&line), "the WGSL lacks {line}");
        }
        // Per level 4 words from CONTROL_LEVELS, for every level, before the chunks.
        assert!(ADAPTIVE_STATE.source.contains("const CONTROL_LEVELS: u32 = 32u;"));
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
