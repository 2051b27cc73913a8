//! A renderer made: the inputs checked, every buffer uploaded, the pipelines and bind groups
//! created, the G-buffer drawn.

use render::{Lighting, Material, Scene};
use wgpu::util::DeviceExt;

use std::cell::OnceCell;

use crate::context::{Gpu, check_buffer_fits};
use crate::error::GpuError;
use crate::merl_lookup::{MerlDimsUniform, capture_errors, gpu_table_values, table_bytes};

use super::*;

impl Renderer {
    /// Checks the inputs as `render::render` does, uploads the mesh, the MERL table, the samples,
    /// the mip chain, the prefiltered layers and the view-layer table, and draws the G-buffer
    /// (the triangle at each pixel centre).
    /// Fails with [`GpuError::Scene`] on inconsistent inputs and [`GpuError::AdapterLimit`] where
    /// a buffer or the image exceeds what the adapter can hold.
    pub fn new(gpu: &Gpu, scene: &Scene, material: &Material, lighting: &Lighting) -> Result<Renderer, GpuError> {
        check_scene(scene, material, lighting)?;
        let (width, height) = (scene.width as u32, scene.height as u32);
        let limits = gpu.limits();
        let info = gpu.adapter_info();
        if width.max(height) > limits.max_texture_dimension_2d {
            return Err(GpuError::AdapterLimit {
                adapter: gpu.adapter_summary(),
                limit: "max_texture_dimension_2d",
                have: limits.max_texture_dimension_2d.into(),
                need: width.max(height).into(),
                what: "the image",
            });
        }

        let table = &material.table;
        check_buffer_fits(&limits, info, table_bytes(table.dims()), "the MERL table")?;
        if let Some(w) = &material.wavelet_brdf {
            check_buffer_fits(&limits, info, 4 * w.brdf.slices().len() as u64, "the wavelet BRDF's slices")?;
        }
        let samples = &material.samples;
        check_buffer_fits(&limits, info, 16 * samples.texels.len() as u64, "the importance samples")?;
        let (env_maps, env_texels, maps) = env_buffers(lighting);
        check_buffer_fits(&limits, info, 4 * env_texels.len() as u64, "the mip chain and the prefiltered layers")?;
        let (tables, sampling_layout) = sampling_tables(material, lighting);
        check_buffer_fits(&limits, info, 4 * tables.len() as u64, "the sampling tables")?;
        let pixels = u64::from(width) * u64::from(height);
        check_buffer_fits(&limits, info, 16 * pixels, "the accumulation buffer")?;
        // Clip-space positions, positions and normals interleaved: one storage buffer for all
        // three, one binding of the shading passes' 12 (`Shading::storage_buffers`).
        let n_vertices = scene.mesh.positions.len() as u64;
        check_buffer_fits(&limits, info, 4 * VERTEX_FLOATS * n_vertices, "the mesh's vertices")?;
        check_buffer_fits(&limits, info, 4 * scene.mesh.indices.len() as u64, "the mesh's indices")?;
        check_storage_buffers(&limits, info, Shading::storage_buffers(), "shading (every mode)")?;

        let device = gpu.device().clone();
        let queue = gpu.queue().clone();
        let frame_stride = u64::from(limits.min_uniform_buffer_offset_alignment).max(16);
        let renderer = capture_errors(&device, || {
            let storage = |label: &str, contents: &[u8]| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                })
            };
            let uniform = |label: &str, size: u64| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            };

            // The mesh, read by both passes.
            // Written by `rasterize`, with the camera's projection.
            let vertex_buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("preview mesh vertices"),
                size: 4 * VERTEX_FLOATS * n_vertices,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let index_buffer = storage("preview mesh indices", bytemuck::cast_slice(&scene.mesh.indices));

            // The raster pass.
            let vertex = wgpu::ShaderStages::VERTEX;
            let raster_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("preview raster"),
                entries: &[storage_entry(0, vertex, true), storage_entry(1, vertex, true)],
            });
            let raster_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("preview_raster.wgsl"),
                source: wgpu::ShaderSource::Wgsl(crate::wgsl::PREVIEW_RASTER.source.into()),
            });
            let raster_pipeline = raster_pipeline(&device, &raster_layout, &raster_module);
            let raster_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview raster"),
                layout: &raster_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: vertex_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: index_buffer.as_entire_binding() },
                ],
            });
            let target = |label: &str, format: wgpu::TextureFormat, usage: wgpu::TextureUsages| {
                device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
            };
            use wgpu::TextureUsages as T;
            let triangle_target =
                target("preview gbuffer triangle", TRIANGLE_FORMAT, T::RENDER_ATTACHMENT | T::TEXTURE_BINDING);
            let depth_target = target("preview depth", DEPTH_FORMAT, T::RENDER_ATTACHMENT);

            // The shading pass.
            let layout = |label: &str, entries: &[wgpu::BindGroupLayoutEntry]| {
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries })
            };
            let shading = Shading {
                module: device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some("preview_shade.wgsl"),
                    source: wgpu::ShaderSource::Wgsl(
                        crate::wgsl::module(&[
                            &crate::wgsl::PREVIEW_SHADE,
                            &crate::wgsl::ADAPTIVE_PREDICT,
                            &crate::wgsl::ADAPTIVE_PLAN,
                            &crate::wgsl::ADAPTIVE_SAMPLES,
                            &crate::wgsl::ADAPTIVE_FRAME,
                        ])
                        .into(),
                    ),
                }),
                table: layout("merl table", &table_entries()),
                bake: layout("preview bake", &bake_entries()),
                render: layout("preview render", &render_entries()),
            };
            let shade_pipeline = shading.pipeline(&device, true, None, "shade_frame");
            let backdrop_pipeline = shading.pipeline(&device, true, None, "shade_backdrop");
            let (table_layout, bake_layout, render_layout) = (&shading.table, &shading.bake, &shading.render);

            let dims_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("merl dims"),
                contents: bytemuck::bytes_of(&MerlDimsUniform::new(table.dims())),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let table_buffer = storage("merl table", bytemuck::cast_slice(&gpu_table_values(table)));
            let wavelet = WaveletUniform::new(material.wavelet_brdf.as_ref());
            let wavelet_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("wavelet params"),
                contents: bytemuck::bytes_of(&wavelet),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            // Without a wavelet the shader never reads these; a binding cannot be empty.
            let (map, slices) = match &material.wavelet_brdf {
                Some(w) => (w.brdf.map(), w.brdf.slices()),
                None => (&[0u32][..], &[0f32][..]),
            };
            let wavelet_map_buffer = storage("wavelet map", bytemuck::cast_slice(map));
            let wavelet_slices_buffer = storage("wavelet slices", bytemuck::cast_slice(slices));
            let table_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("merl table"),
                layout: table_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: dims_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: table_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: wavelet_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: wavelet_map_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: wavelet_slices_buffer.as_entire_binding() },
                ],
            });
            let samples_buffer = storage("preview samples", bytemuck::cast_slice(&samples.texels));
            let maps_buffer = storage("preview env maps", bytemuck::cast_slice(&env_maps));
            let texels_buffer = storage("preview env texels", bytemuck::cast_slice(&env_texels));
            // The view rows' layer coordinates, then the layers' exponents and the one past the
            // sharpest (`render::past_exponent`). A binding cannot be empty; a table nobody reads
            // (the mode check rejects the prefiltered mode without one) holds one unused entry.
            let mut view_layers = material.view_layers.clone();
            if !lighting.exponents.is_empty() {
                view_layers.extend(lighting.exponents.iter().map(|&n| n as f32));
                view_layers.push(render::past_exponent(&lighting.exponents) as f32);
            }
            if view_layers.is_empty() {
                view_layers.push(0.0);
            }
            let view_layers_buffer = storage("preview view layers", bytemuck::cast_slice(&view_layers));
            let tables_buffer = storage("preview sampling tables", bytemuck::cast_slice(&tables));
            let bake_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview bake"),
                layout: bake_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: samples_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: maps_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: texels_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: view_layers_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: vertex_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 5, resource: index_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 6, resource: tables_buffer.as_entire_binding() },
                ],
            });

            let shade_uniform = uniform("preview shade", size_of::<ShadeUniform>() as u64);
            let frame_uniform = uniform("preview frames", frame_stride * u64::from(FRAMES_PER_SUBMIT));
            let accumulation = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("preview accumulation"),
                size: 16 * pixels,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let backdrop = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("preview backdrop"),
                size: 16 * pixels,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            });
            let view = |texture: &wgpu::Texture| texture.create_view(&Default::default());
            let render_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview render"),
                layout: render_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: shade_uniform.as_entire_binding() },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &frame_uniform,
                            offset: 0,
                            size: wgpu::BufferSize::new(16),
                        }),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&view(&triangle_target)),
                    },
                    wgpu::BindGroupEntry { binding: 3, resource: accumulation.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: backdrop.as_entire_binding() },
                ],
            });
            Renderer {
                device: device.clone(),
                queue: queue.clone(),
                width,
                height,
                camera: scene.camera,
                n_indices: scene.mesh.indices.len() as u32,
                raster_pipeline,
                vertex_buffer,
                mesh: scene.mesh.clone(),
                geometry: RefCell::new(None),
                raster_group,
                triangle_target,
                depth_target,
                shade_pipeline,
                backdrop_pipeline,
                prediction: None,
                adaptive_pipelines: OnceCell::new(),
                adaptive: RefCell::new(None),
                adapter_info: info.clone(),
                table_group,
                bake_group,
                render_group,
                shading,
                shade_uniform,
                frame_uniform,
                frame_stride,
                accumulation,
                progress: Cell::new(None),
                n_slices: samples.n_slices as u32,
                n_vectors: samples.n_vectors as u32,
                n_samples: samples.n_samples as u32,
                n_levels: lighting.mips.n_levels() as u32,
                n_layers: lighting.layers.len(),
                view_layers: material.view_layers.clone(),
                diffuse: render::diffuse_split(material, lighting),
                maps,
                tables: sampling_layout,
            }
        })?;
        renderer.rasterize()?;
        Ok(renderer)
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
        storage_buffers(&[&table_entries(), &bake_entries(), &render_entries()])
    }
}

/// The most storage buffers one of the previewer's passes binds in a shader stage: the device asks
/// for that many (`Gpu::new`), or the adapter's most where it has fewer, and the modes that need
/// more fail with the limit ([`check_storage_buffers`]).
pub(crate) fn most_storage_buffers() -> u32 {
    Shading::storage_buffers().max(adaptive::storage_buffers())
}

/// The storage buffers among `groups`' entries.
pub(super) fn storage_buffers(groups: &[&[wgpu::BindGroupLayoutEntry]]) -> u32 {
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

/// Group 0: the MERL table's dimensions and values, the wavelet BRDF's parameters, map and slices
/// (`merl_lookup.wgsl`, `wavelet_brdf.wgsl`).
fn table_entries() -> [wgpu::BindGroupLayoutEntry; 5] {
    let compute = wgpu::ShaderStages::COMPUTE;
    [
        uniform_entry(0, compute, false),
        storage_entry(1, compute, true),
        uniform_entry(2, compute, false),
        storage_entry(3, compute, true),
        storage_entry(4, compute, true),
    ]
}

/// Group 1: what the scene, material and lighting upload once (`preview_bindings.wgsl`).
fn bake_entries() -> [wgpu::BindGroupLayoutEntry; 7] {
    std::array::from_fn(|binding| storage_entry(binding as u32, wgpu::ShaderStages::COMPUTE, true))
}

/// Group 2: the render (`preview_bindings.wgsl`): `Shade`, `Frame` at a dynamic offset, the
/// G-buffer, the accumulation and the backdrop.
pub(super) fn render_entries() -> [wgpu::BindGroupLayoutEntry; 5] {
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
        storage_entry(4, compute, false),
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
