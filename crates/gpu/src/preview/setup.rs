//! A renderer made: the inputs checked, every buffer uploaded, the pipelines and bind groups
//! created, the G-buffer drawn.

use render::{Lighting, Material, Scene};
use wgpu::util::DeviceExt;

use std::cell::OnceCell;

use crate::context::{Gpu, check_buffer_fits};
use crate::device::capture_errors;
use crate::error::GpuError;
use crate::merl_lookup::{MerlDimsUniform, gpu_table_values, table_bytes};

use super::*;

impl Renderer {
    /// Checks the inputs as `render::render` does, uploads the mesh, the MERL table, the samples,
    /// the mip chain, the prefiltered layers and the view-layer table, and draws the G-buffer
    /// (the triangle at each pixel centre).
    /// Fails with [`GpuError::Scene`] on inconsistent inputs and [`GpuError::AdapterLimit`] where
    /// a buffer or the image exceeds what the adapter can hold.
    pub fn new(gpu: &Gpu, scene: &Scene, material: &Material, lighting: &Lighting) -> Result<Renderer, GpuError> {
        check_scene(scene, material, lighting)?;
        let uploads = Uploads::new(scene, material, lighting);
        uploads.check_fits(gpu, scene, material)?;
        let (width, height) = (scene.width as u32, scene.height as u32);
        let device = gpu.device().clone();
        let frame_stride = u64::from(gpu.limits().min_uniform_buffer_offset_alignment).max(16);
        let renderer = capture_errors(&device, || {
            let raster = Raster::new(&device, scene, &uploads.words);
            let shading = Shading::new(&device);
            let table_group = table_group(&device, &shading.table, material);
            let bake_group = uploads.bake_group(&device, &shading.bake, material, &raster);
            let render =
                RenderGroup::new(&device, &shading.render, &raster.triangle_target, frame_stride, (width, height));
            let samples = &material.samples;
            Renderer {
                device: device.clone(),
                queue: gpu.queue().clone(),
                width,
                height,
                camera: scene.camera,
                n_indices: scene.mesh.indices.len() as u32,
                raster_pipeline: raster.pipeline,
                vertex_buffer: raster.vertex_buffer,
                mesh: scene.mesh.clone(),
                geometry: RefCell::new(None),
                raster_group: raster.group,
                triangle_target: raster.triangle_target,
                depth_target: raster.depth_target,
                shade_pipeline: shading.pipeline(&device, true, None, "shade_frame"),
                backdrop_pipeline: shading.pipeline(&device, true, None, "shade_backdrop"),
                prediction: None,
                adaptive_pipelines: OnceCell::new(),
                adaptive: RefCell::new(None),
                adapter_info: gpu.adapter_info().clone(),
                table_group,
                bake_group,
                render_group: render.group,
                shading,
                shade_uniform: render.shade_uniform,
                frame_uniform: render.frame_uniform,
                frame_stride,
                accumulation: render.accumulation,
                progress: Cell::new(None),
                n_slices: samples.n_slices as u32,
                n_vectors: samples.n_vectors as u32,
                n_samples: samples.n_samples as u32,
                n_levels: lighting.mips.n_levels() as u32,
                n_layers: lighting.layers.len(),
                view_layers: material.view_layers.clone(),
                diffuse: render::diffuse_split(material, lighting),
                maps: uploads.maps,
                tables: uploads.sampling_layout,
            }
        })?;
        renderer.rasterize()?;
        Ok(renderer)
    }
}

/// What group 1 uploads from the scene, the material and the lighting, laid out for the WGSL in
/// as few buffers as the shading passes can read (each binding counts against the adapter's
/// storage buffers per stage).
struct Uploads {
    /// The mesh's indices, then the maps' records ([`MapLayout::records`]): the raster pass reads
    /// the indices alone.
    words: Vec<u32>,
    env_texels: Vec<f32>,
    maps: MapLayout,
    /// The sampling tables, then the view rows' layer coordinates, the layers' exponents and the
    /// one past the sharpest (`render::past_exponent`).
    tables: Vec<f32>,
    sampling_layout: TableLayout,
}

impl Uploads {
    fn new(scene: &Scene, material: &Material, lighting: &Lighting) -> Uploads {
        let indices = &scene.mesh.indices;
        let (records, env_texels, maps) = env_buffers(lighting, indices.len() as u32);
        let mut view_layers = material.view_layers.clone();
        if !lighting.exponents.is_empty() {
            view_layers.extend(lighting.exponents.iter().map(|&n| n as f32));
            view_layers.push(render::past_exponent(&lighting.exponents) as f32);
        }
        let (tables, sampling_layout) = sampling_tables(material, lighting, &view_layers);
        let words = indices.iter().copied().chain(records.iter().flatten().copied()).collect();
        Uploads { words, env_texels, maps, tables, sampling_layout }
    }

    /// Fails with [`GpuError::AdapterLimit`] where the image, a buffer or the shading passes'
    /// bindings exceed what the adapter holds.
    fn check_fits(&self, gpu: &Gpu, scene: &Scene, material: &Material) -> Result<(), GpuError> {
        let (limits, info) = (gpu.limits(), gpu.adapter_info());
        let side = scene.width.max(scene.height) as u32;
        if side > limits.max_texture_dimension_2d {
            return Err(GpuError::AdapterLimit {
                adapter: gpu.adapter_summary(),
                limit: "max_texture_dimension_2d",
                have: limits.max_texture_dimension_2d.into(),
                need: side.into(),
                what: "the image",
            });
        }
        let fits = |bytes: u64, what| check_buffer_fits(&limits, info, bytes, what);
        fits(table_bytes(material.table.dims()), "the MERL table")?;
        if let Some(w) = &material.wavelet_brdf {
            fits(4 * (w.brdf.map().len() + w.brdf.slices().len()) as u64, "the wavelet BRDF's map and slices")?;
        }
        fits(16 * material.samples.texels.len() as u64, "the importance samples")?;
        fits(4 * self.env_texels.len() as u64, "the mip chain and the prefiltered layers")?;
        fits(4 * self.tables.len() as u64, "the sampling tables and the view-layer table")?;
        fits(2 * 16 * (scene.width * scene.height) as u64, "the accumulation buffer and the backdrop")?;
        // Clip-space positions, positions and normals interleaved: one storage buffer for all
        // three, one binding of the shading passes' (`Shading::storage_buffers`).
        fits(4 * VERTEX_FLOATS * scene.mesh.positions.len() as u64, "the mesh's vertices")?;
        fits(4 * self.words.len() as u64, "the mesh's indices and the maps' records")?;
        check_storage_buffers(&limits, info, Shading::storage_buffers(), "shading (every mode)")
    }

    /// Group 1: the samples, the maps' texels, the mesh (its vertices; its indices with the maps'
    /// records) and the sampling tables with the view-layer table.
    fn bake_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        material: &Material,
        raster: &Raster,
    ) -> wgpu::BindGroup {
        let samples = storage(device, "preview samples", bytemuck::cast_slice(&material.samples.texels));
        let texels = storage(device, "preview env texels", bytemuck::cast_slice(&self.env_texels));
        let tables = storage(device, "preview sampling tables", bytemuck::cast_slice(&self.tables));
        let resources = [&samples, &texels, &raster.vertex_buffer, &raster.index_buffer, &tables];
        let entries: Vec<wgpu::BindGroupEntry> = (0..)
            .zip(resources)
            .map(|(binding, buffer)| wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("preview bake"), layout, entries: &entries })
    }
}

/// A read-only storage buffer holding `contents`.
fn storage(device: &wgpu::Device, label: &str, contents: &[u8]) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// The raster pass: the mesh's buffers (read by the shading passes too), its pipeline and group,
/// and its targets.
struct Raster {
    /// Written by `rasterize`, with the camera's projection.
    vertex_buffer: wgpu::Buffer,
    index_buffer: wgpu::Buffer,
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    triangle_target: wgpu::Texture,
    depth_target: wgpu::Texture,
}

impl Raster {
    /// `words`: the mesh's indices and what follows them in the same buffer ([`Uploads`]).
    fn new(device: &wgpu::Device, scene: &Scene, words: &[u32]) -> Raster {
        let vertex_buffer = crate::device::buffer(
            device,
            "preview mesh vertices",
            4 * VERTEX_FLOATS * scene.mesh.positions.len() as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let index_buffer = storage(device, "preview mesh indices and map records", bytemuck::cast_slice(words));
        let vertex = wgpu::ShaderStages::VERTEX;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview raster"),
            entries: &[storage_entry(0, vertex, true), storage_entry(1, vertex, true)],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("preview_raster.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::wgsl::PREVIEW_RASTER.source.into()),
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview raster"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: vertex_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: index_buffer.as_entire_binding() },
            ],
        });
        let target = |label: &str, format: wgpu::TextureFormat, usage: wgpu::TextureUsages| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: scene.width as u32,
                    height: scene.height as u32,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        use wgpu::TextureUsages as T;
        Raster {
            pipeline: raster_pipeline(device, &layout, &module),
            group,
            triangle_target: target(
                "preview gbuffer triangle",
                TRIANGLE_FORMAT,
                T::RENDER_ATTACHMENT | T::TEXTURE_BINDING,
            ),
            depth_target: target("preview depth", DEPTH_FORMAT, T::RENDER_ATTACHMENT),
            vertex_buffer,
            index_buffer,
        }
    }
}

/// The wavelet BRDF's map and slices in one buffer, as `wavelet_brdf.wgsl` reads them: the map
/// (one slice index per coefficient position, `n^2` of them), then the slices' values as `f32`
/// bits. Without a wavelet the shader never reads it; a binding cannot be empty.
fn wavelet_words(material: &Material) -> Vec<u32> {
    match &material.wavelet_brdf {
        Some(w) => {
            debug_assert_eq!(w.brdf.map().len(), w.brdf.grid().cells(), "a map entry per coefficient position");
            w.brdf.map().iter().copied().chain(w.brdf.slices().iter().map(|v| v.to_bits())).collect()
        }
        None => vec![0],
    }
}

/// Group 0: the MERL table and the wavelet BRDF.
fn table_group(device: &wgpu::Device, layout: &wgpu::BindGroupLayout, material: &Material) -> wgpu::BindGroup {
    let table = &material.table;
    let dims = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("merl dims"),
        contents: bytemuck::bytes_of(&MerlDimsUniform::new(table.dims())),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let values = storage(device, "merl table", bytemuck::cast_slice(&gpu_table_values(table)));
    let wavelet = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("wavelet params"),
        contents: bytemuck::bytes_of(&WaveletUniform::new(material.wavelet_brdf.as_ref())),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let words = storage(device, "wavelet map and slices", bytemuck::cast_slice(&wavelet_words(material)));
    let entries: Vec<wgpu::BindGroupEntry> = (0..)
        .zip([&dims, &values, &wavelet, &words])
        .map(|(binding, buffer)| wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("merl table"), layout, entries: &entries })
}

/// Group 2: the render's uniforms (`ShadeUniform`, and `FrameUniform` one slot per frame of a
/// submission), the G-buffer, and the accumulation with the backdrop behind it.
struct RenderGroup {
    group: wgpu::BindGroup,
    shade_uniform: wgpu::Buffer,
    frame_uniform: wgpu::Buffer,
    accumulation: wgpu::Buffer,
}

impl RenderGroup {
    fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        triangle_target: &wgpu::Texture,
        frame_stride: u64,
        (width, height): (u32, u32),
    ) -> RenderGroup {
        let uniform = |label: &str, size: u64| crate::device::uniform_buffer(device, label, size);
        let pixels = u64::from(width) * u64::from(height);
        let shade_uniform = uniform("preview shade", size_of::<ShadeUniform>() as u64);
        let frame_uniform = uniform("preview frames", frame_stride * u64::from(FRAMES_PER_SUBMIT));
        // The sums, then the backdrop (`backdrop_index` in the WGSL): one binding.
        let accumulation = crate::device::buffer(
            device,
            "preview accumulation and backdrop",
            2 * 16 * pixels,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        );
        let frame = wgpu::BufferBinding { buffer: &frame_uniform, offset: 0, size: wgpu::BufferSize::new(16) };
        let triangles = triangle_target.create_view(&Default::default());
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview render"),
            layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: shade_uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Buffer(frame) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&triangles) },
                wgpu::BindGroupEntry { binding: 3, resource: accumulation.as_entire_binding() },
            ],
        });
        RenderGroup { group, shade_uniform, frame_uniform, accumulation }
    }
}

/// The checks of `render::render` on the scene, the material and the lighting, before anything is
/// allocated from them.
pub(super) fn check_scene(scene: &Scene, material: &Material, lighting: &Lighting) -> Result<(), GpuError> {
    scene.mesh.validate()?;
    render::raster::check_size(scene.width, scene.height)?;
    Ok(render::check_inputs(material, lighting)?)
}

/// What every compute pipeline of the shading module is made from: the module and the layouts of
/// its groups 0 to 2. The shading passes are made with the renderer, the adaptive frames' at the
/// first adaptive frame ([`Renderer::adaptive_pipelines`]).
#[derive(Debug)]
pub(super) struct Shading {
    module: wgpu::ShaderModule,
    table: wgpu::BindGroupLayout,
    bake: wgpu::BindGroupLayout,
    render: wgpu::BindGroupLayout,
}

impl Shading {
    /// The shading module (`preview_shade.wgsl` and the adaptive files, `crate::wgsl::module`)
    /// and the layouts of groups 0 to 2.
    fn new(device: &wgpu::Device) -> Shading {
        let layout = |label, entries: &[_]| bind_group_layout(device, label, entries);
        let files = [
            &crate::wgsl::PREVIEW_SHADE,
            &crate::wgsl::ADAPTIVE_PREDICT,
            &crate::wgsl::ADAPTIVE_PLAN,
            &crate::wgsl::ADAPTIVE_SAMPLES,
            &crate::wgsl::ADAPTIVE_FRAME,
        ];
        Shading {
            module: device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("preview_shade.wgsl"),
                source: wgpu::ShaderSource::Wgsl(crate::wgsl::module(&files).into()),
            }),
            table: layout("merl table", &table_entries()),
            bake: layout("preview bake", &bake_entries()),
            render: layout("preview render", &render_entries()),
        }
    }

    /// The pipeline of `entry`: groups 0 to 2 where `estimator` (a pass that reads the BRDF, the
    /// samples or the maps), group 2 alone otherwise, and `group3` where the entry has one. A
    /// layout names only the groups its pass reads, so that only their storage buffers count
    /// against the adapter's limit per shader stage ([`Shading::storage_buffers`]).
    pub(super) fn pipeline(
        &self,
        device: &wgpu::Device,
        estimator: bool,
        group3: Option<&wgpu::BindGroupLayout>,
        entry: &'static str,
    ) -> wgpu::ComputePipeline {
        let (table, bake) = if estimator { (Some(&self.table), Some(&self.bake)) } else { (None, None) };
        let layouts = [table, bake, Some(&self.render), group3];
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(entry),
            bind_group_layouts: &layouts[..3 + usize::from(group3.is_some())],
            immediate_size: 0,
        });
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&layout),
            module: &self.module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    }

    /// The storage buffers a shading pass binds in its stage: groups 0 to 2.
    pub(super) fn storage_buffers() -> u32 {
        count_storage_buffers(&[&table_entries(), &bake_entries(), &render_entries()])
    }
}

/// The most storage buffers one of the previewer's passes binds in a shader stage: the device asks
/// for that many (`Gpu::new`), or the adapter's most where it has fewer, and the modes that need
/// more fail with the limit ([`check_storage_buffers`]).
pub(crate) fn most_storage_buffers() -> u32 {
    Shading::storage_buffers().max(adaptive::storage_buffers())
}

/// A bind group layout of `entries`.
pub(super) fn bind_group_layout(
    device: &wgpu::Device,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries })
}

/// The storage buffers among `groups`' entries.
pub(super) fn count_storage_buffers(groups: &[&[wgpu::BindGroupLayoutEntry]]) -> u32 {
    let storage = |e: &&wgpu::BindGroupLayoutEntry| {
        matches!(e.ty, wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Storage { .. }, .. })
    };
    groups.iter().map(|g| g.iter().filter(storage).count() as u32).sum()
}

/// Fails with [`GpuError::AdapterLimit`] where the adapter binds fewer than `need` storage buffers
/// per shader stage; `what` names the work and, where some modes still run, which.
pub(super) fn check_storage_buffers(
    limits: &wgpu::Limits,
    info: &wgpu::AdapterInfo,
    need: u32,
    what: &'static str,
) -> Result<(), GpuError> {
    let have = limits.max_storage_buffers_per_shader_stage;
    if have < need {
        return Err(GpuError::AdapterLimit {
            adapter: crate::context::describe(info),
            limit: "max_storage_buffers_per_shader_stage",
            have: have.into(),
            need: need.into(),
            what,
        });
    }
    Ok(())
}

/// Group 0: the MERL table's dimensions and values, the wavelet BRDF's parameters, and its map
/// and slices in one buffer (`merl_lookup.wgsl`, `wavelet_brdf.wgsl`).
fn table_entries() -> [wgpu::BindGroupLayoutEntry; 4] {
    let compute = wgpu::ShaderStages::COMPUTE;
    [
        uniform_entry(0, compute, false),
        storage_entry(1, compute, true),
        uniform_entry(2, compute, false),
        storage_entry(3, compute, true),
    ]
}

/// Group 1: what the scene, material and lighting upload once (`preview_bindings.wgsl`).
fn bake_entries() -> [wgpu::BindGroupLayoutEntry; 5] {
    std::array::from_fn(|binding| storage_entry(binding as u32, wgpu::ShaderStages::COMPUTE, true))
}

/// Group 2: the render (`preview_bindings.wgsl`): `ShadeUniform`, `FrameUniform` at a dynamic
/// offset, the G-buffer, and the accumulation with the backdrop behind it.
pub(super) fn render_entries() -> [wgpu::BindGroupLayoutEntry; 4] {
    let compute = wgpu::ShaderStages::COMPUTE;
    [
        uniform_entry(0, compute, false),
        uniform_entry(1, compute, true),
        wgpu::BindGroupLayoutEntry {
            binding: 2,
            visibility: compute,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Uint,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        },
        storage_entry(3, compute, false),
    ]
}

pub(super) fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages, dynamic: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic,
            min_binding_size: None,
        },
        count: None,
    }
}

pub(super) fn storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

pub(super) fn raster_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    module: &wgpu::ShaderModule,
) -> wgpu::RenderPipeline {
    let target =
        Some(wgpu::ColorTargetState { format: TRIANGLE_FORMAT, blend: None, write_mask: wgpu::ColorWrites::ALL });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("preview raster"),
        layout: Some(&device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("preview raster"),
            bind_group_layouts: &[Some(layout)],
            immediate_size: 0,
        })),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("raster_vertex"),
            compilation_options: Default::default(),
            // The vertex shader reads the mesh from storage buffers.
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            // Back faces are drawn: the CPU keeps them, and the shading frame blackens them.
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            // Strictly less: of two equal depths the triangle drawn first stays, as on the CPU.
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("raster_fragment"),
            compilation_options: Default::default(),
            targets: &[target],
        }),
        multiview_mask: None,
        cache: None,
    })
}
