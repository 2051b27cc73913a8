//! Batch evaluation of the WGSL MERL lookup: upload a table once, then look up any number of
//! direction pairs and read back, for each, the value and the cell the shader chose. This is how
//! the shader is tested against `merl::MerlTable::lookup`; it is not a fast path for baking.

use bytemuck::{Pod, Zeroable};
use merl::{Dims, MerlTable};

use crate::context::{Gpu, check_buffer_fits};
use crate::device::{capture_errors, read_back};
use crate::error::GpuError;

/// Must equal `MERL_WORKGROUP_SIZE` in the WGSL (checked by a test below).
const WORKGROUP_SIZE: u32 = 64;

/// A bound on one dispatch, so that a huge batch costs 64 MB of GPU memory rather than as much as
/// the limits allow; batches beyond it are split.
const MAX_PAIRS_PER_DISPATCH: u32 = 1 << 20;

/// Written to every channel of a cell without data (the file may mark only one channel).
const NO_DATA: f32 = -1.0;

/// The `MerlDims` uniform of the WGSL (group 0, binding 0).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct MerlDimsUniform {
    pub n_theta_h: u32,
    pub n_theta_d: u32,
    pub n_phi_d: u32,
    pub phi_d_range: f32,
}

impl MerlDimsUniform {
    pub fn new(dims: Dims) -> MerlDimsUniform {
        MerlDimsUniform {
            n_theta_h: dims.n_theta_h as u32,
            n_theta_d: dims.n_theta_d as u32,
            n_phi_d: dims.n_phi_d as u32,
            phi_d_range: dims.phi_d_range() as f32,
        }
    }
}

/// The values of a table as the WGSL reads them (group 0, binding 1): f32 in 1/sr,
/// channel-major, and -1 in every channel of a cell that holds no data.
pub fn gpu_table_values(table: &MerlTable) -> Vec<f32> {
    let cells = table.dims().cells();
    let mut values = vec![0.0f32; 3 * cells];
    for index in 0..cells {
        let rgb = table.cell_value(index).map_or([NO_DATA; 3], |v| v.map(|x| x as f32));
        for (c, v) in rgb.into_iter().enumerate() {
            values[c * cells + index] = v;
        }
    }
    values
}

/// One looked-up pair, as the shader wrote it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct MerlSample {
    /// BRDF in 1/sr; negative in every channel where the table holds no data.
    pub rgb: [f32; 3],
    /// Flat index of the cell within a channel, as `merl::Dims::index` numbers them.
    pub cell: u32,
}

impl MerlSample {
    pub fn has_data(&self) -> bool {
        self.rgb.iter().all(|v| *v >= 0.0)
    }
}

/// `MerlDirPair` of the WGSL.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct MerlDirPair {
    pub(crate) wi: [f32; 4],
    pub(crate) wo: [f32; 4],
}

const PAIR_BYTES: u64 = size_of::<MerlDirPair>() as u64;
const SAMPLE_BYTES: u64 = size_of::<MerlSample>() as u64;

/// Bytes of a table as the WGSL reads it.
pub(crate) fn table_bytes(dims: Dims) -> u64 {
    3 * dims.cells() as u64 * size_of::<f32>() as u64
}

/// A MERL table on the GPU and the pipeline that looks it up.
#[derive(Debug)]
pub struct MerlLookup {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::ComputePipeline,
    table_group: wgpu::BindGroup,
    dims: Dims,
    max_pairs_per_dispatch: u32,
}

impl MerlLookup {
    /// Compiles the shader and uploads `table` (17.5 MB for 90 x 90 x 180).
    pub fn new(gpu: &Gpu, table: &MerlTable) -> Result<MerlLookup, GpuError> {
        let dims = table.dims();
        let limits = gpu.limits();
        check_buffer_fits(&limits, gpu.adapter_info(), table_bytes(dims), "the MERL table")?;
        let device = gpu.device().clone();
        let values = gpu_table_values(table);
        let (pipeline, table_group) = capture_errors(&device, || {
            use wgpu::util::DeviceExt;
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("merl_lookup_batch.wgsl"),
                source: wgpu::ShaderSource::Wgsl(crate::wgsl::module(&[&crate::wgsl::MERL_LOOKUP_BATCH]).into()),
            });
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("merl_lookup_batch"),
                layout: None,
                module: &module,
                entry_point: Some("merl_lookup_batch"),
                compilation_options: Default::default(),
                cache: None,
            });
            let dims_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("merl dims"),
                contents: bytemuck::bytes_of(&MerlDimsUniform::new(dims)),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let table_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("merl table"),
                contents: bytemuck::cast_slice(&values),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let table_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("merl table"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: dims_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: table_buffer.as_entire_binding() },
                ],
            });
            (pipeline, table_group)
        })?;
        let max_pairs_per_dispatch = [
            u64::from(limits.max_compute_workgroups_per_dimension) * u64::from(WORKGROUP_SIZE),
            limits.max_storage_buffer_binding_size / PAIR_BYTES,
            limits.max_buffer_size / PAIR_BYTES,
            u64::from(MAX_PAIRS_PER_DISPATCH),
        ]
        .into_iter()
        .min()
        .expect("four bounds") as u32;
        Ok(MerlLookup { device, queue: gpu.queue().clone(), pipeline, table_group, dims, max_pairs_per_dispatch })
    }

    pub fn dims(&self) -> Dims {
        self.dims
    }

    /// The most pairs one dispatch looks up; [`MerlLookup::evaluate`] splits larger batches.
    pub fn max_pairs_per_dispatch(&self) -> u32 {
        self.max_pairs_per_dispatch
    }

    /// Lowers the number of pairs per dispatch (at least 1; never above what the device allows),
    /// so that tests can exercise the splitting of batches without millions of pairs.
    pub fn with_max_pairs_per_dispatch(mut self, max_pairs: u32) -> MerlLookup {
        self.max_pairs_per_dispatch = max_pairs.clamp(1, self.max_pairs_per_dispatch);
        self
    }

    /// Looks up every `(wi, wo)` pair: the value of its nearest cell and that cell, in order.
    /// Directions must satisfy what `merl::half_diff` asks (unit vectors, `wi + wo != 0`).
    pub fn evaluate(&self, pairs: &[([f32; 3], [f32; 3])]) -> Result<Vec<MerlSample>, GpuError> {
        let mut samples = Vec::with_capacity(pairs.len());
        if pairs.is_empty() {
            return Ok(samples);
        }
        let capacity = pairs.len().min(self.max_pairs_per_dispatch as usize) as u64;
        let buffer = |label, bytes, usage| crate::device::buffer(&self.device, label, bytes, usage);
        use wgpu::BufferUsages as U;
        let (pair_buffer, sample_buffer, readback) = capture_errors(&self.device, || {
            (
                buffer("merl pairs", capacity * PAIR_BYTES, U::STORAGE | U::COPY_DST),
                buffer("merl samples", capacity * SAMPLE_BYTES, U::STORAGE | U::COPY_SRC),
                crate::device::readback_buffer(&self.device, "merl readback", capacity * SAMPLE_BYTES),
            )
        })?;
        for batch in pairs.chunks(capacity as usize) {
            let n = batch.len() as u64;
            let packed: Vec<MerlDirPair> = batch
                .iter()
                .map(|(wi, wo)| MerlDirPair { wi: [wi[0], wi[1], wi[2], 0.0], wo: [wo[0], wo[1], wo[2], 0.0] })
                .collect();
            capture_errors(&self.device, || {
                self.queue.write_buffer(&pair_buffer, 0, bytemuck::cast_slice(&packed));
                let batch_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("merl batch"),
                    layout: &self.pipeline.get_bind_group_layout(1),
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: binding(&pair_buffer, n * PAIR_BYTES) },
                        // The shader takes the batch size from the length of this binding.
                        wgpu::BindGroupEntry { binding: 1, resource: binding(&sample_buffer, n * SAMPLE_BYTES) },
                    ],
                });
                let mut encoder = self.device.create_command_encoder(&Default::default());
                {
                    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("merl_lookup_batch"),
                        timestamp_writes: None,
                    });
                    pass.set_pipeline(&self.pipeline);
                    pass.set_bind_group(0, &self.table_group, &[]);
                    pass.set_bind_group(1, &batch_group, &[]);
                    pass.dispatch_workgroups(n.div_ceil(u64::from(WORKGROUP_SIZE)) as u32, 1, 1);
                }
                encoder.copy_buffer_to_buffer(&sample_buffer, 0, &readback, 0, n * SAMPLE_BYTES);
                self.queue.submit([encoder.finish()]);
            })?;
            samples.extend(read_back::<MerlSample>(&self.device, &readback, n * SAMPLE_BYTES)?);
        }
        Ok(samples)
    }
}

fn binding(buffer: &wgpu::Buffer, bytes: u64) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer, offset: 0, size: wgpu::BufferSize::new(bytes) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workgroup_size_matches_the_shader() {
        let decl = format!("const MERL_WORKGROUP_SIZE: u32 = {WORKGROUP_SIZE}u;");
        assert!(crate::wgsl::MERL_LOOKUP_BATCH.source.contains(&decl), "the WGSL does not declare `{decl}`");
    }

    #[test]
    fn the_shared_lookup_has_no_entry_point_or_batch_binding() {
        // Other shaders start with merl_lookup.wgsl and bind their own groups from 1 on.
        for batch_only in ["@compute", "@group(1)", "merl_samples"] {
            assert!(!crate::wgsl::MERL_LOOKUP.source.contains(batch_only), "merl_lookup.wgsl contains `{batch_only}`");
        }
    }

    #[test]
    fn table_values_mark_no_data_in_every_channel() {
        let dims = Dims::MERL;
        let mut raw = vec![3.0; 3 * dims.cells()];
        // The file may mark only one channel; the shader tests one channel only if all agree.
        raw[dims.cells() + 7] = -0.5;
        let table = MerlTable::from_raw(dims, raw).unwrap();
        let values = gpu_table_values(&table);
        for c in 0..3 {
            assert_eq!(values[c * dims.cells() + 7], NO_DATA);
            assert_eq!(values[c * dims.cells() + 8], (3.0 * merl::SCALE[c]) as f32);
        }
    }
}
