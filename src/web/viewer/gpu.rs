//! The wgpu renderer: it owns the device, the canvas surface and one buffer
//! set per layer, and draws a [`Scene`] seen through an [`OrbitCamera`].
//! It knows nothing about the app; plain data goes in, pixels come out.
//!
//! The capability tier is decided once, here, at start-up: WebGPU where the
//! browser has a working adapter ("full"), WebGL2 otherwise ("limited").
//! The tier sets the device limits; nothing else branches on the backend.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::camera::OrbitCamera;
use super::scene::{LineSet, PointSet, Surface};
use super::shaders;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tier {
    /// WebGPU.
    Full,
    /// WebGL2 through wgpu's GL backend (downlevel limits).
    Limited,
}

/// Which backend the page asked for (`?backend=webgl2` forces the fallback).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BackendPreference {
    Auto,
    WebGl2,
}

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("could not use the canvas: {0}")]
    Surface(#[from] wgpu::CreateSurfaceError),
    #[error("no graphics adapter (neither WebGPU nor WebGL2 is available): {0}")]
    Adapter(#[from] wgpu::RequestAdapterError),
    #[error("could not open the graphics device: {0}")]
    Device(#[from] wgpu::RequestDeviceError),
    #[error("the canvas supports no colour format")]
    NoFormat,
    #[error("the canvas surface was rejected by the browser (validation error)")]
    Validation,
}

const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const BACKGROUND: wgpu::Color = wgpu::Color {
    r: 0.965,
    g: 0.969,
    b: 0.976,
    a: 1.0,
};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Globals {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    viewport: [f32; 4],
    flags: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SegmentInstance {
    a: [f32; 3],
    b: [f32; 3],
    color: [u8; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct PointInstance {
    position: [f32; 3],
    color: [u8; 4],
    size: f32,
}

struct SurfaceBuffers {
    positions: wgpu::Buffer,
    normals: wgpu::Buffer,
    colors: wgpu::Buffer,
    /// Per-vertex (u, v) of the parametrization layer (zeros otherwise).
    uv: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    /// Drawn vertex → surface vertex (the crease split).
    draw: super::scene::DrawMesh,
}

struct Instances {
    buffer: wgpu::Buffer,
    count: u32,
}

pub struct Gpu {
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    pub tier: Tier,
    sample_count: u32,
    depth: wgpu::TextureView,
    msaa: Option<wgpu::TextureView>,
    globals: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    surface_pipeline: wgpu::RenderPipeline,
    line_pipeline: wgpu::RenderPipeline,
    point_pipeline: wgpu::RenderPipeline,
    mesh: Option<SurfaceBuffers>,
    /// Drawn in the order they were first set (later layers on top).
    lines: Vec<(String, Instances)>,
    points: Vec<(String, Instances)>,
}

/// Replaces the layer called `name` in place, appends it, or removes it.
fn put(layers: &mut Vec<(String, Instances)>, name: &str, value: Option<Instances>) {
    let index = layers.iter().position(|(n, _)| n == name);
    match (index, value) {
        (Some(i), Some(v)) => layers[i].1 = v,
        (None, Some(v)) => layers.push((name.to_string(), v)),
        (Some(i), None) => {
            layers.remove(i);
        }
        (None, None) => {}
    }
}

async fn open(
    instance: &wgpu::Instance,
    adapter: &wgpu::Adapter,
) -> Result<(wgpu::Device, wgpu::Queue), GpuError> {
    let _ = instance;
    Ok(adapter
        .request_device(&wgpu::DeviceDescriptor {
            label: Some("quadrille"),
            required_limits: adapter.limits(),
            ..Default::default()
        })
        .await?)
}

impl Gpu {
    /// Opens WebGPU (unless WebGL2 is asked for) and falls back to WebGL2.
    /// The canvas gets its context only after a device exists, because a
    /// canvas that has handed out a "webgpu" context can never be WebGL2.
    pub async fn new(
        canvas: web_sys::HtmlCanvasElement,
        preference: BackendPreference,
        width: u32,
        height: u32,
    ) -> Result<Gpu, GpuError> {
        if preference == BackendPreference::Auto {
            let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
                backends: wgpu::Backends::BROWSER_WEBGPU,
                ..wgpu::InstanceDescriptor::new_without_display_handle()
            });
            if let Ok(adapter) = instance
                .request_adapter(&wgpu::RequestAdapterOptions::default())
                .await
            {
                if let Ok((device, queue)) = open(&instance, &adapter).await {
                    let surface =
                        instance.create_surface(wgpu::SurfaceTarget::Canvas(canvas.clone()))?;
                    return Gpu::finish(
                        surface,
                        &adapter,
                        device,
                        queue,
                        Tier::Full,
                        width,
                        height,
                    );
                }
            }
        }
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::GL,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let surface = instance.create_surface(wgpu::SurfaceTarget::Canvas(canvas))?;
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                compatible_surface: Some(&surface),
                ..Default::default()
            })
            .await?;
        let (device, queue) = open(&instance, &adapter).await?;
        Gpu::finish(
            surface,
            &adapter,
            device,
            queue,
            Tier::Limited,
            width,
            height,
        )
    }

    fn finish(
        surface: wgpu::Surface<'static>,
        adapter: &wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
        tier: Tier,
        width: u32,
        height: u32,
    ) -> Result<Gpu, GpuError> {
        device.on_uncaptured_error(std::sync::Arc::new(|e: wgpu::Error| {
            web_sys::console::error_1(&format!("wgpu: {e}").into());
        }));
        let config = surface_config(&surface, adapter, &device, width, height)?;
        let format = config.format;
        surface.configure(&device, &config);
        let msaa_ok = adapter
            .get_texture_format_features(format)
            .flags
            .sample_count_supported(4)
            && adapter
                .get_texture_format_features(DEPTH_FORMAT)
                .flags
                .sample_count_supported(4);
        let sample_count = if msaa_ok { 4 } else { 1 };

        let (globals, layout, bind_group) = globals_binding(&device);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("viewer"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });

        let make = |label: &str,
                    source: &str,
                    buffers: &[Option<wgpu::VertexBufferLayout>],
                    cull: Option<wgpu::Face>| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    cull_mode: cull,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: sample_count,
                    ..Default::default()
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let vertex = |stride: u64, location: u32, format: wgpu::VertexFormat| {
            (
                stride,
                [wgpu::VertexAttribute {
                    format,
                    offset: 0,
                    shader_location: location,
                }],
            )
        };
        let (p, pa) = vertex(12, 0, wgpu::VertexFormat::Float32x3);
        let (n, na) = vertex(12, 1, wgpu::VertexFormat::Float32x3);
        let (c, ca) = vertex(4, 2, wgpu::VertexFormat::Unorm8x4);
        let (t, ta) = vertex(8, 3, wgpu::VertexFormat::Float32x2);
        let per_vertex = |stride, attributes| {
            Some(wgpu::VertexBufferLayout {
                array_stride: stride,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes,
            })
        };
        let surface_pipeline = make(
            "surface",
            shaders::SURFACE,
            &[
                per_vertex(p, &pa),
                per_vertex(n, &na),
                per_vertex(c, &ca),
                per_vertex(t, &ta),
            ],
            None,
        );
        let segment_attributes =
            wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Unorm8x4];
        let line_pipeline = make(
            "lines",
            shaders::LINES,
            &[Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<SegmentInstance>() as u64,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes: &segment_attributes,
            })],
            None,
        );
        let point_attributes =
            wgpu::vertex_attr_array![0 => Float32x3, 1 => Unorm8x4, 2 => Float32];
        let point_pipeline = make(
            "points",
            shaders::POINTS,
            &[Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<PointInstance>() as u64,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes: &point_attributes,
            })],
            None,
        );
        let (depth, msaa) = targets(&device, &config, sample_count);
        Ok(Gpu {
            surface,
            device,
            queue,
            config,
            tier,
            sample_count,
            depth,
            msaa,
            globals,
            bind_group,
            surface_pipeline,
            line_pipeline,
            point_pipeline,
            mesh: None,
            lines: Vec::new(),
            points: Vec::new(),
        })
    }

    pub fn size(&self) -> (u32, u32) {
        (self.config.width, self.config.height)
    }

    pub fn msaa_samples(&self) -> u32 {
        self.sample_count
    }

    /// Resizes the drawing buffer (pixels), clamped to the device's limit.
    pub fn resize(&mut self, width: u32, height: u32) {
        let max = self.device.limits().max_texture_dimension_2d;
        let (width, height) = (width.clamp(1, max), height.clamp(1, max));
        if (width, height) == self.size() {
            return;
        }
        self.config.width = width;
        self.config.height = height;
        self.surface.configure(&self.device, &self.config);
        (self.depth, self.msaa) = targets(&self.device, &self.config, self.sample_count);
    }

    fn buffer(&self, label: &str, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: usage | wgpu::BufferUsages::COPY_DST,
            })
    }

    /// Uploads a surface with its per-vertex colours (`None` removes it),
    /// its vertices split at creases sharper than `crease_degrees`.
    pub fn set_surface(&mut self, surface: Option<(&Surface, &[[u8; 4]])>, crease_degrees: f32) {
        self.mesh = surface
            .filter(|(s, _)| !s.triangles.is_empty())
            .map(|(s, colors)| {
                let draw = s.split_at_creases(crease_degrees);
                let positions: Vec<[f32; 3]> = draw
                    .source
                    .iter()
                    .map(|&v| s.positions[v as usize].to_array())
                    .collect();
                let normals: Vec<[f32; 3]> = draw.normals.iter().map(|n| n.to_array()).collect();
                let colors = draw
                    .expand(colors)
                    .unwrap_or_else(|| vec![super::scene::PLAIN; draw.source.len()]);
                SurfaceBuffers {
                    positions: self.buffer(
                        "positions",
                        bytemuck::cast_slice(&positions),
                        wgpu::BufferUsages::VERTEX,
                    ),
                    normals: self.buffer(
                        "normals",
                        bytemuck::cast_slice(&normals),
                        wgpu::BufferUsages::VERTEX,
                    ),
                    colors: self.buffer(
                        "colors",
                        bytemuck::cast_slice(&colors),
                        wgpu::BufferUsages::VERTEX,
                    ),
                    uv: self.buffer(
                        "uv",
                        bytemuck::cast_slice(&vec![[0.0f32; 2]; draw.source.len()]),
                        wgpu::BufferUsages::VERTEX,
                    ),
                    indices: self.buffer(
                        "indices",
                        bytemuck::cast_slice(&draw.triangles),
                        wgpu::BufferUsages::INDEX,
                    ),
                    index_count: (draw.triangles.len() * 3) as u32,
                    draw,
                }
            });
    }

    /// Replaces the surface's per-vertex colours (one per surface vertex).
    pub fn set_surface_colors(&mut self, colors: &[[u8; 4]]) {
        if let Some(mesh) = &self.mesh {
            if let Some(c) = mesh.draw.expand(colors) {
                self.queue
                    .write_buffer(&mesh.colors, 0, bytemuck::cast_slice(&c));
            }
        }
    }

    /// Replaces the surface's per-vertex (u, v) (one per surface vertex).
    pub fn set_surface_uv(&mut self, uv: &[[f32; 2]]) {
        if let Some(mesh) = &self.mesh {
            if let Some(c) = mesh.draw.expand(uv) {
                self.queue
                    .write_buffer(&mesh.uv, 0, bytemuck::cast_slice(&c));
            }
        }
    }

    /// Removes every line and point layer.
    pub fn clear_layers(&mut self) {
        self.lines.clear();
        self.points.clear();
    }

    pub fn set_lines(&mut self, name: &str, lines: Option<&LineSet>) {
        let instances: Vec<SegmentInstance> = lines
            .map(|l| {
                l.segments
                    .iter()
                    .zip(&l.colors)
                    .map(|(s, &color)| SegmentInstance {
                        a: s[0].into(),
                        b: s[1].into(),
                        color,
                    })
                    .collect()
            })
            .unwrap_or_default();
        let value = (!instances.is_empty()).then(|| Instances {
            buffer: self.buffer(
                name,
                bytemuck::cast_slice(&instances),
                wgpu::BufferUsages::VERTEX,
            ),
            count: instances.len() as u32,
        });
        put(&mut self.lines, name, value);
    }

    pub fn set_points(&mut self, name: &str, points: Option<&PointSet>) {
        let instances: Vec<PointInstance> = points
            .map(|p| {
                p.points
                    .iter()
                    .zip(&p.colors)
                    .map(|(q, &color)| PointInstance {
                        position: (*q).into(),
                        color,
                        size: p.size_px,
                    })
                    .collect()
            })
            .unwrap_or_default();
        let value = (!instances.is_empty()).then(|| Instances {
            buffer: self.buffer(
                name,
                bytemuck::cast_slice(&instances),
                wgpu::BufferUsages::VERTEX,
            ),
            count: instances.len() as u32,
        });
        put(&mut self.points, name, value);
    }

    /// Draws one frame. `visible` says which layers to draw ("surface" and
    /// the line and point layer names); `line_width` is in pixels; `grid`
    /// draws the surface's (u, v) as a checkerboard with integer isolines.
    pub fn render(
        &mut self,
        camera: &OrbitCamera,
        visible: &dyn Fn(&str) -> bool,
        line_width: f32,
        flat: bool,
        grid: bool,
    ) -> Result<(), GpuError> {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Validation => return Err(GpuError::Validation),
        };
        let (w, h) = self.size();
        let globals = Globals {
            view_proj: camera.view_proj().to_cols_array_2d(),
            eye: camera.eye().extend(1.0).into(),
            viewport: [w as f32, h as f32, line_width, camera.distance * 2e-3],
            flags: [
                if self.config.format.is_srgb() {
                    1.0
                } else {
                    0.0
                },
                if flat { 1.0 } else { 0.0 },
                // Markers sit this far toward the eye (world units), so
                // result faces that cut below the input do not hide them.
                camera.scene_radius * 0.02,
                if grid { 1.0 } else { 0.0 },
            ],
        };
        self.queue
            .write_buffer(&self.globals, 0, bytemuck::bytes_of(&globals));

        let view = frame.texture.create_view(&Default::default());
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let (target, resolve) = match &self.msaa {
                Some(msaa) => (msaa, Some(&view)),
                None => (&view, None),
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("scene"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: resolve,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(BACKGROUND),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &self.bind_group, &[]);
            if let Some(mesh) = self.mesh.as_ref().filter(|_| visible("surface")) {
                pass.set_pipeline(&self.surface_pipeline);
                pass.set_vertex_buffer(0, mesh.positions.slice(..));
                pass.set_vertex_buffer(1, mesh.normals.slice(..));
                pass.set_vertex_buffer(2, mesh.colors.slice(..));
                pass.set_vertex_buffer(3, mesh.uv.slice(..));
                pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..mesh.index_count, 0, 0..1);
            }
            pass.set_pipeline(&self.line_pipeline);
            for (name, lines) in &self.lines {
                if visible(name) {
                    pass.set_vertex_buffer(0, lines.buffer.slice(..));
                    pass.draw(0..6, 0..lines.count);
                }
            }
            pass.set_pipeline(&self.point_pipeline);
            for (name, points) in &self.points {
                if visible(name) {
                    pass.set_vertex_buffer(0, points.buffer.slice(..));
                    pass.draw(0..6, 0..points.count);
                }
            }
        }
        self.queue.submit([encoder.finish()]);
        self.queue.present(frame);
        Ok(())
    }
}

/// The surface configuration: a non-sRGB format if there is one, opaque
/// alpha if offered, the canvas size clamped to the device's limit.
fn surface_config(
    surface: &wgpu::Surface<'static>,
    adapter: &wgpu::Adapter,
    device: &wgpu::Device,
    width: u32,
    height: u32,
) -> Result<wgpu::SurfaceConfiguration, GpuError> {
    let caps = surface.get_capabilities(adapter);
    // A non-sRGB target shows colormap colours exactly; an sRGB one gets
    // linearised colours (flags.x in the shaders).
    let format = caps
        .formats
        .iter()
        .copied()
        .find(|f| !f.is_srgb())
        .or_else(|| caps.formats.first().copied())
        .ok_or(GpuError::NoFormat)?;
    let alpha_mode = if caps.alpha_modes.contains(&wgpu::CompositeAlphaMode::Opaque) {
        wgpu::CompositeAlphaMode::Opaque
    } else {
        caps.alpha_modes
            .first()
            .copied()
            .unwrap_or(wgpu::CompositeAlphaMode::Auto)
    };
    let max = device.limits().max_texture_dimension_2d;
    let config = wgpu::SurfaceConfiguration {
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        format,
        color_space: Default::default(),
        width: width.clamp(1, max),
        height: height.clamp(1, max),
        present_mode: wgpu::PresentMode::Fifo,
        desired_maximum_frame_latency: 2,
        alpha_mode,
        view_formats: vec![],
    };
    Ok(config)
}

/// The globals uniform buffer, its bind group layout and bind group.
fn globals_binding(
    device: &wgpu::Device,
) -> (wgpu::Buffer, wgpu::BindGroupLayout, wgpu::BindGroup) {
    let globals = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("globals"),
        size: std::mem::size_of::<Globals>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("globals"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("globals"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: globals.as_entire_binding(),
        }],
    });
    (globals, layout, bind_group)
}

fn targets(
    device: &wgpu::Device,
    config: &wgpu::SurfaceConfiguration,
    sample_count: u32,
) -> (wgpu::TextureView, Option<wgpu::TextureView>) {
    let size = wgpu::Extent3d {
        width: config.width,
        height: config.height,
        depth_or_array_layers: 1,
    };
    let texture = |label, format| {
        device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default())
    };
    let depth = texture("depth", DEPTH_FORMAT);
    let msaa = (sample_count > 1).then(|| texture("msaa", config.format));
    (depth, msaa)
}
