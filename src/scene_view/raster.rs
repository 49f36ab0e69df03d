//! Drawing the scene view's segments and light markers into an 8-bit sRGB image, with
//! anti-aliased strokes and discs from `tiny-skia`: lines wide enough to read on a projector,
//! the parts the scene hides ([`super::occlusion`]) dimmed to a third of their opacity, a
//! highlighted node wider, in the highlight colour under its own.
//!
//! Colours blend in sRGB values, as the window's overlay does: the lines are marks over the
//! picture, not light in the scene.

use glam::Vec2;
use tiny_skia::{Color, FillRule, LineCap, Paint, PathBuilder, Pixmap, Stroke, Transform};

use super::occlusion::{DepthImage, Piece, clip_to_rect, point_sight, visible_pieces};
use super::{HIGHLIGHT_RGB, LightMarker, Segment, TreeLook, style_rgba};
use crate::scene::CameraFrame;

/// What a hidden piece keeps of its opacity.
pub const HIDDEN_OPACITY: f32 = 1.0 / 3.0;

/// How much wider than a line its highlight is.
pub const HIGHLIGHT_WIDTH: f32 = 2.4;

/// The width of a line in pixels on an image `height` pixels tall: 0.3 % of the height (3 px on
/// a 1080-line projector), at least 2 px.
pub fn line_width(height: u32) -> f32 {
    (height as f32 * 0.003).max(2.0)
}

/// The radius in pixels of a light marker: 0.9 % of the height, at least 4 px.
pub fn marker_radius(height: u32) -> f32 {
    (height as f32 * 0.009).max(4.0)
}

/// An opaque 8-bit sRGB picture being drawn on.
#[derive(Clone, Debug)]
pub struct Canvas {
    pixmap: Pixmap,
}

impl Canvas {
    /// A canvas holding `rgb` (8-bit sRGB, row-major, 3 bytes a pixel), or `None` when the size
    /// is zero or does not match.
    pub fn from_srgb8(width: u32, height: u32, rgb: &[u8]) -> Option<Canvas> {
        if rgb.len() != width as usize * height as usize * 3 {
            return None;
        }
        let rgba = rgb
            .chunks_exact(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect();
        let size = tiny_skia::IntSize::from_wh(width, height)?;
        Pixmap::from_vec(rgba, size).map(|pixmap| Canvas { pixmap })
    }

    pub fn width(&self) -> u32 {
        self.pixmap.width()
    }

    pub fn height(&self) -> u32 {
        self.pixmap.height()
    }

    /// The picture as 8-bit sRGB RGBA, row-major. It stays opaque (every stroke is drawn over
    /// an opaque picture), so premultiplied and straight alpha are the same bytes.
    pub fn rgba(&self) -> &[u8] {
        self.pixmap.data()
    }

    /// Strokes `a..b` (image positions) in `rgba` with round caps, clipped to the image first
    /// so that a point projected far away cannot upset the rasterizer.
    fn line(&mut self, a: Vec2, b: Vec2, width: f32, rgba: [u8; 4]) {
        let margin = width * 2.0;
        let offset = Vec2::splat(margin);
        let (w, h) = (self.width() as f32, self.height() as f32);
        let Some((s0, s1)) =
            clip_to_rect(a + offset, b + offset, w + 2.0 * margin, h + 2.0 * margin)
        else {
            return;
        };
        let (a, b) = (a + (b - a) * s0, a + (b - a) * s1);
        let mut path = PathBuilder::new();
        path.move_to(a.x, a.y);
        path.line_to(b.x, b.y);
        let Some(path) = path.finish() else {
            return;
        };
        let stroke = Stroke {
            width,
            line_cap: LineCap::Round,
            ..Stroke::default()
        };
        self.pixmap
            .stroke_path(&path, &paint(rgba), &stroke, Transform::identity(), None);
    }

    /// A filled disc with a dark outline, so it reads on light and dark surfaces alike.
    fn disc(&mut self, centre: Vec2, radius: f32, rgba: [u8; 4]) {
        let Some(path) = PathBuilder::from_circle(centre.x, centre.y, radius) else {
            return;
        };
        self.pixmap.fill_path(
            &path,
            &paint(rgba),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
        let outline = Stroke {
            width: (radius * 0.3).max(1.0),
            ..Stroke::default()
        };
        self.pixmap.stroke_path(
            &path,
            &paint([0, 0, 0, rgba[3]]),
            &outline,
            Transform::identity(),
            None,
        );
    }

    /// Draws `segments` as seen through `frame`, split by `depth` ([`visible_pieces`]): every
    /// hidden piece first, dimmed, then the visible pieces over them, each on a thin dark band
    /// so a white ray reads on a white floor. The segments of node `highlight` (when given)
    /// are drawn wider in [`HIGHLIGHT_RGB`] under their own colour.
    pub fn draw_segments(
        &mut self,
        frame: &CameraFrame,
        depth: &DepthImage,
        segments: &[&Segment],
        highlight: Option<&[usize]>,
    ) {
        self.draw_tree_segments(frame, depth, segments, highlight, None);
    }

    /// [`Self::draw_segments`] for one tree among several: `look` gives its tint and strength
    /// as the viewer draws it (a faint tree thinner, in its tint, without normals); `None`
    /// draws the styles' own colours.
    pub fn draw_tree_segments(
        &mut self,
        frame: &CameraFrame,
        depth: &DepthImage,
        segments: &[&Segment],
        highlight: Option<&[usize]>,
        look: Option<TreeLook>,
    ) {
        let width = line_width(self.height()) * look.map_or(1.0, |l| l.width());
        let split: Vec<(&Segment, Vec<Piece>)> = segments
            .iter()
            .map(|s| (*s, visible_pieces(s.a, s.b, frame, depth)))
            .collect();
        let ends = |p: &Piece| {
            Some((
                Vec2::from(frame.project(p.a)?),
                Vec2::from(frame.project(p.b)?),
            ))
        };
        for pass in [Pass::Hidden, Pass::Band, Pass::Highlight, Pass::Visible] {
            for (segment, pieces) in &split {
                let highlighted = highlight.is_some_and(|h| h == segment.path.as_slice());
                for piece in pieces {
                    let Some((a, b)) = ends(piece) else { continue };
                    let [r, g, bl, alpha] =
                        look.map_or_else(|| style_rgba(segment.style), |l| l.rgba(segment.style));
                    if alpha == 0 {
                        continue;
                    }
                    let dim = |alpha: u8| (f32::from(alpha) * HIDDEN_OPACITY).round() as u8;
                    match pass {
                        Pass::Hidden if piece.hidden => {
                            self.line(a, b, width, [r, g, bl, dim(alpha)]);
                        }
                        Pass::Band if !piece.hidden => {
                            self.line(a, b, width + 2.0, [0, 0, 0, alpha / 2]);
                        }
                        Pass::Highlight if highlighted => {
                            let [hr, hg, hb] = HIGHLIGHT_RGB;
                            let a8 = if piece.hidden { dim(255) } else { 255 };
                            self.line(a, b, width * HIGHLIGHT_WIDTH, [hr, hg, hb, a8]);
                        }
                        Pass::Visible if !piece.hidden => {
                            self.line(a, b, width, [r, g, bl, alpha]);
                        }
                        _ => {}
                    }
                }
            }
        }
    }

    /// Draws each light as a small disc in its colour at its position, dimmed when the scene
    /// hides it; lights behind the camera are left out.
    pub fn draw_light_markers(
        &mut self,
        frame: &CameraFrame,
        depth: &DepthImage,
        markers: &[LightMarker],
    ) {
        let radius = marker_radius(self.height());
        for m in markers {
            let Some(centre) = frame.project(m.position) else {
                continue;
            };
            let hidden = point_sight(m.position, m.radius, frame, depth).is_hidden();
            let alpha = if hidden {
                (255.0 * HIDDEN_OPACITY).round() as u8
            } else {
                255
            };
            let [r, g, b] = m.rgb;
            self.disc(Vec2::from(centre), radius, [r, g, b, alpha]);
        }
    }
}

/// The order of drawing: what is drawn later lies on top.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Pass {
    Hidden,
    Band,
    Highlight,
    Visible,
}

fn paint(rgba: [u8; 4]) -> Paint<'static> {
    let [r, g, b, a] = rgba;
    let mut paint = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    paint.set_color(Color::from_rgba8(r, g, b, a));
    paint
}
