//! An adaptive frame's state on the GPU, made once per geometry (camera and supersampling),
//! prediction level and pyramid top: the records, levels and candidates uploaded, one buffer per
//! kind; the pipelines of the passes of `plan.wgsl`, `samples.wgsl` and `frame.wgsl` (on
//! `state.wgsl`) and their bind group layout.

use std::sync::Arc;

use wgpu::util::DeviceExt;

use render::adaptive::Geometry;
use render::{Lighting, Material};

use super::*;
use crate::context::check_buffer_fits;
use crate::device::capture_errors;
use crate::error::GpuError;
use crate::preview::Renderer;
use crate::preview::setup::{
    Shading, bind_group_layout, count_storage_buffers, render_entries, storage_entry, uniform_entry,
};

/// The frame's state on the GPU for one geometry (camera and supersampling), prediction level
/// and pyramid top: `state.wgsl`'s state.
#[derive(Debug)]
pub(crate) struct State {
    pub(super) geometry: Arc<Geometry>,
    /// The prediction level and the pyramid's top.
    pub(super) key: (usize, usize),
    /// `(width, height, first block)` per level.
    pub(super) levels: Vec<(u32, u32, u32)>,
    pub(super) blocks: u32,
    /// Blocks that hold a shadeable pixel, per level (`state.wgsl`'s candidates).
    pub(super) candidates_per_level: Vec<u32>,
    /// The pass uniform with the tables' offsets (the per-pass fields zero).
    pub(super) base: AdaptivePass,
    /// The prediction pixels (`render::adaptive::prediction_pixels`), as `predict_blocks`'
    /// items.
    pub(super) items: wgpu::Buffer,
    pub(super) n_items: u32,
    /// Shadeable render pixels, and output pixels a triangle covers.
    pub(super) shadeable: usize,
    pub(super) covered_output: u64,
    pub(super) buffers: Buffers,
    pub(super) uniform: wgpu::Buffer,
    pub(super) group: wgpu::BindGroup,
    /// For the frame's read-backs (the control words, the list, the image), kept from frame to
    /// frame.
    pub(super) readback: wgpu::Buffer,
    /// The workgroups of `shade_blocks` and of `adaptive_scatter` where the GPU allocates,
    /// copied from the control words: an indirect dispatch's buffer may not be bound beside it.
    pub(super) indirect: wgpu::Buffer,
    /// Where the adapter has timestamp queries: the one-submission frame's stages.
    pub(super) clock: Option<Clock>,
}

/// Four timestamps of a one-submission frame (the starts of its three passes: the prediction; the
/// pyramids, the plan, the samples and the list; the shading, up-sampling and output; and the end
/// of the last), and the buffer they resolve into.
#[derive(Debug)]
pub(super) struct Clock {
    pub(super) set: wgpu::QuerySet,
    pub(super) resolved: wgpu::Buffer,
}

/// Bytes of [`Clock`]'s timestamps.
pub(super) const CLOCK_BYTES: u64 = 4 * 8;

/// The buffers of `state.wgsl`'s state, in its binding order (3 to 12).
#[derive(Debug)]
pub(super) struct Buffers {
    pub(super) records_surface: wgpu::Buffer,
    pub(super) records_lobe: wgpu::Buffer,
    pub(super) bandwidths: wgpu::Buffer,
    pub(super) levels: wgpu::Buffer,
    pub(super) parents: wgpu::Buffer,
    pub(super) weights: wgpu::Buffer,
    pub(super) values: wgpu::Buffer,
    pub(super) list: wgpu::Buffer,
    pub(super) tables: wgpu::Buffer,
    pub(super) control: wgpu::Buffer,
}

impl Buffers {
    pub(super) fn in_binding_order(&self) -> [&wgpu::Buffer; 10] {
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
pub(super) fn slots(top: usize) -> u64 {
    2 * top as u64 + 4
}

/// `RecordSurface` of `state.wgsl`: a render pixel's depth, `cos theta_o` and screen-projected
/// normal (`render::adaptive::Pixel`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct RecordSurface {
    pub(crate) depth: f32,
    pub(crate) cos_o: f32,
    pub(crate) screen_normal: [f32; 2],
}

/// `RecordLobe` of `state.wgsl`: a render pixel's mirror direction and the index of its
/// prediction.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct RecordLobe {
    pub(crate) mirror: [f32; 3],
    pub(crate) prediction: u32,
}

impl Renderer {
    /// The adaptive frames' pipelines, made at the first call: a renderer of the other modes
    /// never makes them. Fails with [`GpuError::AdapterLimit`] where the adapter binds fewer
    /// storage buffers per shader stage than their passes need ([`storage_buffers`]).
    pub(in crate::preview) fn adaptive_pipelines(&self) -> Result<&Pipelines, GpuError> {
        if let Some(pipelines) = self.adaptive_pipelines.get() {
            return Ok(pipelines);
        }
        crate::preview::setup::check_storage_buffers(
            &self.device.limits(),
            &self.adapter_info,
            storage_buffers(),
            "an adaptive frame (reference, fis and prefiltered run on this adapter)",
        )?;
        let pipelines = capture_errors(&self.device, || Pipelines::new(&self.device, &self.shading))?;
        Ok(self.adaptive_pipelines.get_or_init(|| pipelines))
    }

    /// The state for `geometry` and `settings`, made and uploaded when the geometry, the
    /// prediction level or the top changed since the last frame.
    pub(super) fn adaptive_state(
        &self,
        geometry: &Arc<Geometry>,
        settings: &render::adaptive::Settings,
        material: &Material,
        lighting: &Lighting,
    ) -> Result<(), GpuError> {
        let state_layout = &self.adaptive_pipelines()?.layout;
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
        let levels = level_sizes((width, height), top)?;
        let blocks = levels.last().map_or(0, |&(w, h, first)| first + w * h);
        let sharpness = lobe_sharpness(material, lighting);
        let p = (width * height) as u32;
        let (candidates, candidates_per_level) = candidates(&shadeable, &levels);
        let n_candidates = candidates.len() as u32;
        let candidates_at = 4 * (levels.len() as u32 + 1);
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
            sharpness: candidates_at + n_candidates,
            n_rows: sharpness.len() as u32,
            candidates: candidates_at,
            capacity: p,
            ..Default::default()
        };
        let (surface, lobe) = records(geometry, &of_pixel);
        let table = tables(&levels, &candidates_per_level, blocks, &candidates, &sharpness);
        let items = crate::preview::prediction_items(&at, pixels);
        let state = capture_errors(&self.device, || {
            let buffers = Buffers::new(&self.device, (&surface, &lobe), &table, p, blocks, n_candidates);
            let items_buffer = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("adaptive prediction pixels"),
                contents: bytemuck::cast_slice(if items.is_empty() { &[[0u32; 4]][..] } else { &items }),
                usage: wgpu::BufferUsages::COPY_SRC,
            });
            let uniform = crate::device::uniform_buffer(
                &self.device,
                "adaptive passes",
                slot_stride(self.frame_stride) * slots(top),
            );
            let group = buffers.group(&self.device, state_layout, &uniform);
            let out_pixels = (geometry.size().0 * geometry.size().1) as u64;
            let readback = self.readback_buffer(
                (16 * u64::from(blocks)).max(16 * out_pixels + 4 * u64::from(CONTROL_CHUNKS) + CLOCK_BYTES),
            );
            let clock =
                self.device.features().contains(wgpu::Features::TIMESTAMP_QUERY).then(|| Clock::new(&self.device));
            let indirect = crate::device::buffer(
                &self.device,
                "adaptive indirect dispatches",
                24,
                wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            );
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
}

/// The lobe weight's sharpness per view row, as `render::adaptive::render_with` reads it
/// (`check_settings` holds the rows in range where the lobe weight is on).
fn lobe_sharpness(material: &Material, lighting: &Lighting) -> Vec<f32> {
    match lighting.exponents.is_empty() {
        true => vec![0.0; material.view_layers.len()],
        false => material.view_layers.iter().map(|&x| render::layer_exponent(&lighting.exponents, x) as f32).collect(),
    }
}

/// Per level of a render of `width x height` pixels up to `top`: its width and height in blocks
/// and the index of its first block among every level's.
fn level_sizes((width, height): (usize, usize), top: usize) -> Result<Vec<(u32, u32, u32)>, GpuError> {
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
    Ok(levels)
}

/// The candidates (`state.wgsl`): the blocks that hold a shadeable pixel, level by level, as
/// indices among every level's blocks; and their count per level.
fn candidates(shadeable: &[bool], levels: &[(u32, u32, u32)]) -> (Vec<u32>, Vec<u32>) {
    let mut any_shadeable: Vec<bool> = shadeable.to_vec();
    let mut candidates: Vec<u32> = (0..shadeable.len() as u32).filter(|&i| shadeable[i as usize]).collect();
    let mut per_level = vec![candidates.len() as u32];
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
        per_level.push((candidates.len() - before) as u32);
        any_shadeable = mine;
    }
    (candidates, per_level)
}

/// The records of the geometry's render pixels, `of_pixel` the index of each one's prediction.
fn records(geometry: &Geometry, of_pixel: &[u32]) -> (Vec<RecordSurface>, Vec<RecordLobe>) {
    geometry
        .pixels()
        .iter()
        .enumerate()
        .map(|(i, pixel)| match pixel {
            Some(px) => (
                RecordSurface {
                    depth: px.depth as f32,
                    cos_o: px.cos_o as f32,
                    screen_normal: px.screen_normal.map(|v| v as f32),
                },
                RecordLobe { mirror: px.mirror.as_vec3().to_array(), prediction: of_pixel[i] },
            ),
            // The WGSL's output tells covered pixels without a shading frame by a depth of 0: a
            // shaded pixel's is positive.
            None => (
                RecordSurface { depth: if geometry.covers(i) { 0.0 } else { -1.0 }, ..Default::default() },
                RecordLobe { prediction: NONE, ..Default::default() },
            ),
        })
        .unzip()
}

/// The tables buffer (`state.wgsl`): the level table, the candidates, the lobe sharpness per view
/// row.
fn tables(
    levels: &[(u32, u32, u32)],
    candidates_per_level: &[u32],
    blocks: u32,
    candidates: &[u32],
    sharpness: &[f32],
) -> Vec<u32> {
    let mut first_candidate = 0;
    let mut table: Vec<u32> = Vec::with_capacity(4 * (levels.len() + 1) + candidates.len() + sharpness.len());
    for (&(w, h, first), &n) in levels.iter().zip(candidates_per_level) {
        table.extend([w, h, first, first_candidate]);
        first_candidate += n;
    }
    table.extend([0, 0, blocks, first_candidate]);
    table.extend(candidates);
    table.extend(sharpness.iter().map(|v| v.to_bits()));
    table
}

impl Buffers {
    /// The state's buffers for `p` render pixels and `blocks` blocks of every level: the records
    /// and the tables uploaded, every block not a candidate's level entry at min level -1 and
    /// skipped (for every frame of the geometry), the rest written by the passes.
    fn new(
        device: &wgpu::Device,
        (surface, lobe): (&[RecordSurface], &[RecordLobe]),
        table: &[u32],
        p: u32,
        blocks: u32,
        n_candidates: u32,
    ) -> Buffers {
        use wgpu::BufferUsages as U;
        let init = |label: &str, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: U::STORAGE | U::COPY_SRC | U::COPY_DST,
            })
        };
        let empty = |label: &str, bytes: u64| {
            crate::device::buffer(device, label, bytes.max(16), U::STORAGE | U::COPY_SRC | U::COPY_DST)
        };
        let idle: Vec<u32> = [u32::MAX, 0, 0, 0].repeat(blocks as usize);
        Buffers {
            records_surface: init("adaptive records", bytemuck::cast_slice(surface)),
            records_lobe: init("adaptive records", bytemuck::cast_slice(lobe)),
            bandwidths: empty("adaptive bandwidths", 4 * u64::from(p)),
            levels: init("adaptive levels", bytemuck::cast_slice(&idle)),
            parents: empty("adaptive parents", 16 * u64::from(blocks)),
            weights: empty("adaptive weights", 16 * u64::from(blocks)),
            values: empty("adaptive values", 16 * u64::from(blocks)),
            list: empty("adaptive list", 16 * u64::from(blocks)),
            tables: init("adaptive tables", bytemuck::cast_slice(table)),
            control: empty("adaptive control", 4 * u64::from(CONTROL_CHUNKS + n_candidates.div_ceil(CHUNK))),
        }
    }

    /// Group 3 of the passes after the prediction: the pass uniform's slot (binding 2, at a
    /// dynamic offset) and the buffers.
    fn group(&self, device: &wgpu::Device, layout: &wgpu::BindGroupLayout, uniform: &wgpu::Buffer) -> wgpu::BindGroup {
        let slot = wgpu::BufferBinding {
            buffer: uniform,
            offset: 0,
            size: wgpu::BufferSize::new(size_of::<AdaptivePass>() as u64),
        };
        let mut entries = vec![wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Buffer(slot) }];
        for (binding, buffer) in (3..).zip(self.in_binding_order()) {
            entries.push(wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() });
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("adaptive"), layout, entries: &entries })
    }
}

impl Clock {
    /// Four timestamps and the buffer they are resolved into.
    fn new(device: &wgpu::Device) -> Clock {
        Clock {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("adaptive stages"),
                ty: wgpu::QueryType::Timestamp,
                count: 4,
            }),
            resolved: crate::device::buffer(
                device,
                "adaptive stages",
                CLOCK_BYTES,
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
        }
    }
}

/// The adaptive frames' pipelines: `predict_blocks` and `shade_blocks` (the estimators' passes,
/// groups 0 to 2) and the passes after the prediction (group 2 and the state), with the layouts of
/// their groups 3. Made at the first adaptive frame ([`Renderer::adaptive_pipelines`]).
#[derive(Debug)]
pub(crate) struct Pipelines {
    /// Group 3 of `predict_blocks`: the prediction's uniform and bandwidths.
    pub predict_layout: wgpu::BindGroupLayout,
    /// Group 3 of the passes after the prediction: the pass uniform and the state's buffers.
    pub layout: wgpu::BindGroupLayout,
    pub predict: wgpu::ComputePipeline,
    pub blocks: wgpu::ComputePipeline,
    pub levels: wgpu::ComputePipeline,
    pub grade: wgpu::ComputePipeline,
    pub grade_apply: wgpu::ComputePipeline,
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
    pub(crate) fn new(device: &wgpu::Device, shading: &Shading) -> Pipelines {
        let predict_layout = bind_group_layout(device, "preview predict", &predict_entries());
        let state = bind_group_layout(device, "adaptive", &state_entries());
        let pass = |entry| shading.pipeline(device, false, Some(&state), entry);
        Pipelines {
            predict: shading.pipeline(device, true, Some(&predict_layout), "predict_blocks"),
            blocks: shading.pipeline(device, true, None, "shade_blocks"),
            levels: pass("adaptive_levels"),
            grade: pass("adaptive_grade"),
            grade_apply: pass("adaptive_grade_apply"),
            reduce: pass("adaptive_reduce"),
            plan: pass("adaptive_plan"),
            scatter: pass("adaptive_scatter"),
            upsample: pass("adaptive_upsample"),
            output: pass("adaptive_output"),
            allocate: pass("adaptive_allocate"),
            offsets: pass("adaptive_offsets"),
            list: pass("adaptive_list"),
            predict_layout,
            layout: state,
        }
    }
}

/// The most storage buffers an adaptive frame's pass binds in its stage: `predict_blocks` binds
/// groups 0 to 2 and its own, the passes after it group 2 and the state.
pub(crate) fn storage_buffers() -> u32 {
    let predict = Shading::storage_buffers() + count_storage_buffers(&[&predict_entries()]);
    predict.max(count_storage_buffers(&[&render_entries(), &state_entries()]))
}

/// Group 3 of `predict_blocks` (`predict.wgsl`): its uniform and the bandwidths.
fn predict_entries() -> [wgpu::BindGroupLayoutEntry; 2] {
    let compute = wgpu::ShaderStages::COMPUTE;
    [uniform_entry(0, compute, false), storage_entry(1, compute, true)]
}

/// Group 3 of the passes after the prediction (`state.wgsl`): binding 2 the pass uniform (one
/// slot per pass), 3 to 12 the state's buffers ([`Buffers`]; the records and the tables
/// read-only).
fn state_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    let compute = wgpu::ShaderStages::COMPUTE;
    let mut entries = vec![uniform_entry(2, compute, true)];
    entries.extend((3..=12).map(|binding| storage_entry(binding, compute, matches!(binding, 3 | 4 | 11))));
    entries
}
