//! The render on screen: a float texture that finished tiles are written into with
//! `queue.write_texture` in the paint callback's prepare step, drawn by `shaders/display.wgsl`
//! (exposure, tonemap, sRGB). The UI thread only marks rectangles dirty; the GPU side uploads
//! just those. One pipeline draws any number of such displays, each its own texture keyed by a
//! [`DisplayId`] (the render view's and the scene view's).

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use eframe::egui;
use eframe::egui_wgpu::{self, CallbackResources, CallbackTrait, ScreenDescriptor, wgpu};
use serde::{Deserialize, Serialize};

use crate::render::Rect;

/// How colours above 1 are shown. Saved in the preferences as its number (the shader's too).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(from = "u32", into = "u32")]
pub enum Tonemap {
    /// Cut at 1.
    #[default]
    Clamp,
    /// Rolled off by `c / (1 + c)`.
    Reinhard,
    /// Rolled off by the ACES filmic curve.
    Aces,
}

impl Tonemap {
    pub const ALL: [Tonemap; 3] = [Tonemap::Clamp, Tonemap::Reinhard, Tonemap::Aces];

    pub fn label(self) -> &'static str {
        match self {
            Tonemap::Clamp => "clamp",
            Tonemap::Reinhard => "Reinhard",
            Tonemap::Aces => "ACES",
        }
    }
}

impl From<Tonemap> for u32 {
    /// The number `shaders/display.wgsl` reads.
    fn from(t: Tonemap) -> u32 {
        match t {
            Tonemap::Clamp => 0,
            Tonemap::Reinhard => 1,
            Tonemap::Aces => 2,
        }
    }
}

impl From<u32> for Tonemap {
    /// An unknown number (a newer run's preferences) reads as clamp, as the shader does.
    fn from(v: u32) -> Tonemap {
        match v {
            1 => Tonemap::Reinhard,
            2 => Tonemap::Aces,
            _ => Tonemap::Clamp,
        }
    }
}

/// What the texture's pixels are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pixels {
    /// Linear radiance: exposure and the tonemap apply.
    Radiance,
    /// An image mode's colours, display colours already: no exposure, no tonemap.
    Display,
}

/// How the texture is shown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisplayParams {
    pub exposure: f32,
    pub tonemap: Tonemap,
    pub pixels: Pixels,
    /// Bilinear filtering (the image drawn at a non-integer scale); otherwise nearest pixel.
    pub smooth: bool,
}

impl DisplayParams {
    /// The colour the display shader shows for a texture pixel `c` (linear), as 8-bit sRGB:
    /// exposure and the tonemap for radiance, none for an image mode's colours, then clamped
    /// and encoded. The "as shown" export writes these, so the file has the window's colours.
    pub fn shown_srgb8(&self, c: [f32; 4]) -> [u8; 3] {
        let c = glam::Vec3::new(c[0], c[1], c[2]);
        let c = match self.pixels {
            Pixels::Display => c,
            Pixels::Radiance => {
                let c = c * self.exposure;
                match self.tonemap {
                    Tonemap::Clamp => c,
                    Tonemap::Reinhard => c / (glam::Vec3::ONE + c),
                    Tonemap::Aces => (c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14),
                }
            }
        };
        crate::export::to_srgb8(c)
    }
}

impl DisplayState {
    /// The picture as shown: every pixel through [`DisplayParams::shown_srgb8`], RGB bytes
    /// row-major.
    pub fn shown_rgb8(&self) -> Vec<u8> {
        self.rgba
            .iter()
            .flat_map(|&c| self.params.shown_srgb8(c))
            .collect()
    }
}

/// What the texture should hold, shared between the UI thread (which writes pixels and marks
/// rectangles dirty) and the paint callback (which uploads them).
#[derive(Debug)]
pub struct DisplayState {
    pub width: u32,
    pub height: u32,
    /// Linear RGBA, row-major.
    pub rgba: Vec<[f32; 4]>,
    dirty: Vec<Rect>,
    full: bool,
    pub params: DisplayParams,
}

impl DisplayState {
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            rgba: vec![[0.0, 0.0, 0.0, 1.0]; (width * height) as usize],
            dirty: Vec::new(),
            full: true,
            params: DisplayParams {
                exposure: 1.0,
                tonemap: Tonemap::Clamp,
                pixels: Pixels::Radiance,
                smooth: false,
            },
        }
    }

    /// Starts over at a new size (everything re-uploaded).
    pub fn resize(&mut self, width: u32, height: u32) {
        if (width, height) != (self.width, self.height) {
            *self = Self {
                params: self.params,
                ..Self::new(width, height)
            };
        }
        self.full = true;
    }

    pub fn mark(&mut self, rect: Rect) {
        // While nothing paints (a hidden window), one full upload beats a growing list.
        if self.dirty.len() >= 4096 {
            self.mark_all();
        }
        if !self.full {
            self.dirty.push(rect);
        }
    }

    pub fn mark_all(&mut self) {
        self.full = true;
        self.dirty.clear();
    }
}

pub type SharedDisplay = Arc<Mutex<DisplayState>>;

/// Whether an image drawn at `scale` screen pixels per image pixel is filtered: nearest pixel
/// at a whole scale (1:1, or 2×, 3×… for pixel peeping, within 1%), bilinear otherwise, so a
/// minified or oddly magnified render shows neither jaggies nor dropped pixels.
pub fn smooth_at(scale: f32) -> bool {
    let n = scale.round();
    !(n >= 1.0 && (scale - n).abs() <= 0.01 * n)
}

/// Where a `width × height` image is drawn in `avail` (screen points, `ppp` pixels per
/// point): as large as fits with its aspect kept, centred, its corners on whole screen pixels.
/// Returns the rectangle and the scale in screen pixels per image pixel.
pub fn fit_image(avail: egui::Rect, width: u32, height: u32, ppp: f32) -> (egui::Rect, f32) {
    let (w, h) = (width.max(1) as f32, height.max(1) as f32);
    let px = avail.size() * ppp;
    let scale = (px.x / w).min(px.y / h).max(f32::MIN_POSITIVE);
    // Within half a percent of a whole scale, snap to it: 1:1 stays sharp.
    let n = scale.round();
    let scale = if n >= 1.0 && (scale - n).abs() <= 0.005 * n {
        n
    } else {
        scale
    };
    let size = egui::vec2(w * scale, h * scale);
    let min = ((avail.center().to_vec2() * ppp - size * 0.5).round()) / ppp;
    (egui::Rect::from_min_size(min.to_pos2(), size / ppp), scale)
}

/// Which display a paint callback draws: the render view's or the scene view's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DisplayId {
    Render,
    SceneView,
}

/// One display's texture and its parameters on the GPU.
struct Slot {
    texture: wgpu::Texture,
    bind_group: wgpu::BindGroup,
    uniform: wgpu::Buffer,
    width: u32,
    height: u32,
}

/// GPU objects, created once and kept in egui_wgpu's callback resources: one pipeline, and a
/// texture per [`DisplayId`].
pub struct GpuDisplay {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    slots: HashMap<DisplayId, Slot>,
    encode_srgb: bool,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Uniform {
    exposure: f32,
    tonemap: u32,
    encode_srgb: u32,
    raw: u32,
    smooth: u32,
    _pad: [u32; 3],
}

impl GpuDisplay {
    /// Builds the pipeline for the window's framebuffer format and stores it for the callback.
    pub fn install(render_state: &egui_wgpu::RenderState) {
        let device = &render_state.device;
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("raytree display.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/display.wgsl").into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("raytree display"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("raytree display"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("raytree display"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(render_state.target_format.into())],
            }),
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            multiview_mask: None,
            cache: None,
        });
        let gpu = GpuDisplay {
            pipeline,
            layout,
            slots: HashMap::new(),
            encode_srgb: !render_state.target_format.is_srgb(),
        };
        render_state.renderer.write().callback_resources.insert(gpu);
    }

    /// Makes display `id`'s texture `width × height`; true when it was (re)created.
    fn ensure_texture(
        &mut self,
        device: &wgpu::Device,
        id: DisplayId,
        width: u32,
        height: u32,
    ) -> bool {
        if matches!(self.slots.get(&id), Some(s) if (s.width, s.height) == (width, height)) {
            return false;
        }
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("raytree display params"),
            size: std::mem::size_of::<Uniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("raytree render"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("raytree display"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
            ],
        });
        self.slots.insert(
            id,
            Slot {
                texture,
                bind_group,
                uniform,
                width,
                height,
            },
        );
        true
    }
}

/// The paint callback of one frame.
pub struct DisplayCallback {
    pub id: DisplayId,
    pub shared: SharedDisplay,
}

fn upload(queue: &wgpu::Queue, texture: &wgpu::Texture, state: &DisplayState, rect: Rect) {
    let w = state.width;
    let bytes: &[u8] = bytemuck::cast_slice(&state.rgba);
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d {
                x: rect.x,
                y: rect.y,
                z: 0,
            },
            aspect: wgpu::TextureAspect::All,
        },
        bytes,
        wgpu::TexelCopyBufferLayout {
            offset: ((rect.y * w + rect.x) as u64) * 16,
            bytes_per_row: Some(w * 16),
            rows_per_image: Some(rect.height),
        },
        wgpu::Extent3d {
            width: rect.width,
            height: rect.height,
            depth_or_array_layers: 1,
        },
    );
}

impl CallbackTrait for DisplayCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        resources: &mut CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        let Some(gpu) = resources.get_mut::<GpuDisplay>() else {
            return Vec::new();
        };
        let mut state = crate::sync::lock(&self.shared);
        if state.width == 0 || state.height == 0 {
            return Vec::new();
        }
        let recreated = gpu.ensure_texture(device, self.id, state.width, state.height);
        let encode_srgb = gpu.encode_srgb;
        if let Some(Slot {
            texture, uniform, ..
        }) = gpu.slots.get(&self.id)
        {
            if recreated || state.full {
                let all = Rect {
                    x: 0,
                    y: 0,
                    width: state.width,
                    height: state.height,
                };
                upload(queue, texture, &state, all);
            } else {
                for &rect in &state.dirty {
                    upload(queue, texture, &state, rect);
                }
            }
            let u = Uniform {
                exposure: state.params.exposure,
                tonemap: state.params.tonemap.into(),
                encode_srgb: encode_srgb as u32,
                raw: (state.params.pixels == Pixels::Display) as u32,
                smooth: state.params.smooth as u32,
                _pad: [0; 3],
            };
            queue.write_buffer(uniform, 0, bytemuck::bytes_of(&u));
        }
        state.full = false;
        state.dirty.clear();
        Vec::new()
    }

    fn paint(
        &self,
        _info: eframe::egui::PaintCallbackInfo,
        render_pass: &mut wgpu::RenderPass<'static>,
        resources: &CallbackResources,
    ) {
        let Some(gpu) = resources.get::<GpuDisplay>() else {
            return;
        };
        if let Some(slot) = gpu.slots.get(&self.id) {
            render_pass.set_pipeline(&gpu.pipeline);
            render_pass.set_bind_group(0, &slot.bind_group, &[]);
            render_pass.draw(0..3, 0..1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_scales_are_nearest_and_others_smooth() {
        assert!(!smooth_at(1.0));
        assert!(!smooth_at(2.0));
        assert!(!smooth_at(3.004));
        assert!(smooth_at(1.7));
        assert!(smooth_at(0.5));
        assert!(smooth_at(2.5));
    }

    #[test]
    fn a_fitted_image_keeps_its_aspect_and_sits_on_whole_pixels() {
        let avail = egui::Rect::from_min_size(egui::pos2(10.3, 20.0), egui::vec2(400.0, 300.0));
        let (r, s) = fit_image(avail, 200, 100, 1.0);
        assert_eq!(s, 2.0);
        assert_eq!(r.size(), egui::vec2(400.0, 200.0));
        assert_eq!(r.min.x.fract(), 0.0);
        // At pane size (the image as many pixels as the pane) the image fills the pane.
        let (r, s) = fit_image(avail, 600, 450, 1.5);
        assert_eq!(s, 1.0);
        assert!((r.width() - 400.0).abs() < 1e-3 && (r.height() - 300.0).abs() < 1e-3);
    }
}
