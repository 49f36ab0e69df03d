//! The scene view without a window (`raytree tree --scene-view`): the scene rendered by raytree
//! itself from a view camera, with the render camera, the lights and a pixel's ray tree drawn
//! over it by the rules every scene view shares ([`super::occlusion`], [`super::raster`]).

use std::sync::Arc;

use rayon::prelude::*;

use super::cutaway::{Cutaway, cut_triangles, with_cut};
use super::occlusion::DepthImage;
use super::outline::{Seen, outline};
use super::raster::Canvas;
use super::{Filter, Segment, TreeLook, camera_segments, extent, light_markers, tree_segments};
use crate::export::srgb8_bytes;
use crate::ray_tree::RayTree;
use crate::render::{Image, RenderError, render};
use crate::scene::{Camera, CameraFrame, Scene, primary_ray};
use crate::trace::{TraceSettings, Tracer};

/// One tree of an exported picture: how it is drawn among the others (`None`: alone, in the
/// styles' own colours) and the generation it is drawn down to (`None`: as the filter says).
#[derive(Clone, Copy, Debug)]
pub struct Layer<'a> {
    pub tree: &'a RayTree,
    pub look: Option<TreeLook>,
    pub depth: Option<u32>,
}

impl<'a> Layer<'a> {
    /// A tree drawn alone.
    pub fn alone(tree: &'a RayTree) -> Self {
        Self {
            tree,
            look: None,
            depth: None,
        }
    }
}

/// Draws `layers` back to front (the last is drawn on top), each tree's segments that `filter`
/// (cut at the layer's depth) shows.
fn draw_layers(
    canvas: &mut Canvas,
    frame: &CameraFrame,
    depth: &DepthImage,
    layers: &[Layer],
    filter: &Filter,
    extent: f32,
) {
    for layer in layers {
        let filter = Filter {
            max_generation: layer
                .depth
                .map_or(filter.max_generation, |d| d.min(filter.max_generation)),
            ..filter.clone()
        };
        let segments = tree_segments(layer.tree, extent);
        let shown: Vec<&Segment> = segments.iter().filter(|s| filter.shows(s)).collect();
        canvas.draw_tree_segments(frame, depth, &shown, None, layer.look);
    }
}

/// A scene view that could not be made.
#[derive(Debug, thiserror::Error)]
pub enum SceneViewError {
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error("a scene view needs at least one pixel, not {width}x{height}")]
    Empty { width: u32, height: u32 },
}

/// How far from the eye the render camera's image plane is drawn: 15 % of the scene's size,
/// so the frustum reads as a small camera rather than a pyramid over the whole scene, but never
/// past half the way to what the clicked pixel's ray meets first, so the pixel's cross lies on
/// the ray between the eye and its hit, as in the lecture's figure.
pub fn image_plane_distance(scene: &Scene, tree: &RayTree) -> f32 {
    let first = tree
        .root
        .hit
        .as_ref()
        .map(|h| h.t)
        .or(tree.root.light.as_ref().map(|l| l.t));
    let plane = 0.15 * extent(scene);
    match first {
        Some(t) if t > 0.0 => plane.min(0.5 * t),
        _ => plane,
    }
}

/// `scene` rendered from `view` at `width × height` with raytree's own 1-sample render (the
/// scene's settings, `settings` for tracing), with the render camera of `scene` (frustum, image
/// plane, the pixel of the last layer's tree), its lights and the segments of the `layers`'
/// trees that `filter` shows drawn over it; parts behind surfaces are dimmed. With `cutaway` active for the view's eye
/// ([`Cutaway::active`]) the walls between the eye and the render camera are left out of the
/// render and of the depth the rays are hidden by ([`super::cutaway`]). The result is 8-bit
/// sRGB, converted from the render as PNG export does.
#[allow(clippy::too_many_arguments)]
pub fn scene_view_image(
    scene: &Scene,
    settings: TraceSettings,
    layers: &[Layer],
    view: &Camera,
    width: u32,
    height: u32,
    filter: &Filter,
    cutaway: Cutaway,
) -> Result<Canvas, SceneViewError> {
    let mut seen = if cutaway.active(scene, view.position) {
        with_cut(scene, &cut_triangles(scene, view.position))
    } else {
        scene.clone()
    };
    seen.camera = view.clone();
    seen.render.width = width;
    seen.render.height = height;
    let tracer = Tracer::new(Arc::new(seen), settings);
    let (mut image, _) = render(&tracer, 1, 0, &|_, _| {})?;
    let frame = CameraFrame::new(view, width, height);
    let seen = centre_rays(&tracer, &frame, width, height);
    outline(&mut image.pixels, width, height, &seen);
    let depth = DepthImage {
        width,
        height,
        t: seen
            .iter()
            .map(|s| match s {
                Seen::Surface { t, .. } => *t,
                _ => f32::INFINITY,
            })
            .collect(),
    };
    let mut canvas = Canvas::from_srgb8(width, height, &srgb8_bytes(&image))
        .ok_or(SceneViewError::Empty { width, height })?;

    if let Some(last) = layers.last() {
        let plane = image_plane_distance(scene, last.tree);
        let camera = camera_segments(scene, plane, Some(last.tree.pixel));
        let shown: Vec<&Segment> = camera.iter().filter(|s| filter.shows(s)).collect();
        canvas.draw_segments(&frame, &depth, &shown, None);
    }
    draw_layers(&mut canvas, &frame, &depth, layers, filter, extent(scene));
    canvas.draw_light_markers(&frame, &depth, &light_markers(scene));
    Ok(canvas)
}

/// What the centre ray (sample 0) of each pixel of a `width × height` view with `frame` met,
/// row-major: the view's depth and its outlines. Rows run in parallel on rayon's pool.
fn centre_rays(tracer: &Tracer, frame: &CameraFrame, width: u32, height: u32) -> Vec<Seen> {
    (0..height)
        .into_par_iter()
        .flat_map_iter(|y| {
            (0..width).map(
                move |x| match tracer.first_hit_facts(&primary_ray(frame, x, y, 0)) {
                    Some((t, normal)) => Seen::of(t, normal),
                    None => Seen::Background,
                },
            )
        })
        .collect()
}

/// The render `image` of `tracer`'s scene (its own camera and size) with the `layers`' trees
/// drawn over it by the scene view's rules, parts behind surfaces dimmed: the viewer's "render
/// with overlay" export, at full resolution.
pub fn overlay_image(
    tracer: &Tracer,
    image: &Image,
    layers: &[Layer],
    filter: &Filter,
) -> Result<Canvas, SceneViewError> {
    let scene = &tracer.scene;
    let (width, height) = (image.width, image.height);
    let frame = CameraFrame::new(&scene.camera, width, height);
    let depth = DepthImage::of(tracer, &frame, width, height);
    let mut canvas = Canvas::from_srgb8(width, height, &srgb8_bytes(image))
        .ok_or(SceneViewError::Empty { width, height })?;
    draw_layers(&mut canvas, &frame, &depth, layers, filter, extent(scene));
    canvas.draw_light_markers(&frame, &depth, &light_markers(scene));
    Ok(canvas)
}
