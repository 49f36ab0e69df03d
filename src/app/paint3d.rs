//! World-space segments ([`crate::scene_view`]) drawn with the egui painter in screen space,
//! for both the render view's overlay and the scene view: projected with the CPU camera
//! ([`CameraFrame::project`]) into a pane's rectangle, cut at the near plane and into parts in
//! front of and behind the surfaces ([`visible_pieces`]), parts behind dimmed. Lines are
//! [`WIDTH`] logical pixels wide so they read on a projector; the hovered or selected node is
//! drawn thicker in [`HIGHLIGHT_RGB`].

use eframe::egui::{self, Color32, Pos2, Rect, Shape, Stroke};
use glam::Vec3;

use crate::scene::CameraFrame;
use crate::scene_view::occlusion::{DepthImage, visible_pieces};
use crate::scene_view::{HIGHLIGHT_RGB, NodePath, Segment, Style, TreeLook, style_rgba};

/// Width of a ray on screen, in logical pixels.
pub const WIDTH: f32 = 2.5;
/// Width of the hovered or selected node's rays.
pub const SELECTED_WIDTH: f32 = 5.0;
/// How far (logical pixels) a click may be from a segment and still pick it.
pub const PICK_DISTANCE: f32 = 6.0;
/// Opacity kept by the parts of a segment behind a surface.
const HIDDEN_ALPHA: f32 = 0.3;

/// A camera's image shown in a rectangle of the screen: how world points land there.
#[derive(Clone, Copy, Debug)]
pub struct ScreenView {
    pub rect: Rect,
    pub frame: CameraFrame,
    /// The image size the frame was made for, in pixels.
    pub width: u32,
    pub height: u32,
}

impl ScreenView {
    /// Where `p` lands on screen, or `None` behind the camera: the image position of
    /// [`CameraFrame::project`] scaled from the image into `rect`.
    pub fn screen_pos(&self, p: Vec3) -> Option<Pos2> {
        self.frame
            .project(p)
            .map(|(x, y)| self.image_to_screen(x, y))
    }

    /// Image position (`x`, `y`) in pixels to a point of `rect`.
    pub fn image_to_screen(&self, x: f32, y: f32) -> Pos2 {
        Pos2::new(
            self.rect.min.x + x / self.width as f32 * self.rect.width(),
            self.rect.min.y + y / self.height as f32 * self.rect.height(),
        )
    }
}

/// How one set of segments is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    /// Opacity multiplier (the pinned tree is fainter).
    pub alpha: f32,
    /// Dashed lines (the pinned tree).
    pub dashed: bool,
    /// The tree's tint and strength among several (`None`: the styles' own colours).
    pub tree: Option<TreeLook>,
}

impl Default for Look {
    fn default() -> Self {
        Self {
            alpha: 1.0,
            dashed: false,
            tree: None,
        }
    }
}

/// A segment as drawn on screen, for picking.
#[derive(Clone, Debug, PartialEq)]
pub struct Drawn {
    /// Which tree it belongs to (the caller's numbering).
    pub tree: usize,
    pub path: NodePath,
    pub a: Pos2,
    pub b: Pos2,
}

fn color(rgba: [u8; 4], alpha: f32) -> Color32 {
    Color32::from_rgba_unmultiplied(
        rgba[0],
        rgba[1],
        rgba[2],
        (rgba[3] as f32 * alpha.clamp(0.0, 1.0)) as u8,
    )
}

/// Draws `segments` of tree number `tree` through `view`, parts behind the surfaces of `depth`
/// (the depth of `view`'s image) dimmed; the nodes at `active` paths (hovered, selected) are
/// drawn thicker in the highlight colour. What was drawn is added to `out`, for picking.
#[allow(clippy::too_many_arguments)]
pub fn draw_segments<'a>(
    painter: &egui::Painter,
    view: &ScreenView,
    depth: &DepthImage,
    segments: impl IntoIterator<Item = &'a Segment>,
    tree: usize,
    active: &[&[usize]],
    look: Look,
    out: &mut Vec<Drawn>,
) {
    let mut shapes = Vec::new();
    for s in segments {
        // The node's own ray lights up; its shadow rays and normal keep their colours, which
        // say lit or blocked.
        let highlighted = matches!(s.style, Style::Ray(_) | Style::NotTraced(_))
            && active.contains(&s.path.as_slice());
        let rgba = if highlighted {
            let [r, g, b] = HIGHLIGHT_RGB;
            [r, g, b, 255]
        } else {
            look.tree
                .map_or_else(|| style_rgba(s.style), |t| t.rgba(s.style))
        };
        if rgba[3] == 0 {
            continue;
        }
        let width =
            look.tree.map_or(1.0, |t| t.width()) * if highlighted { SELECTED_WIDTH } else { WIDTH };
        for piece in visible_pieces(s.a, s.b, &view.frame, depth) {
            let (Some(a), Some(b)) = (view.screen_pos(piece.a), view.screen_pos(piece.b)) else {
                continue;
            };
            let alpha = look.alpha * if piece.hidden { HIDDEN_ALPHA } else { 1.0 };
            let stroke = Stroke::new(
                if piece.hidden { width * 0.7 } else { width },
                color(rgba, alpha),
            );
            if look.dashed {
                shapes.extend(Shape::dashed_line(&[a, b], stroke, 8.0, 5.0));
            } else {
                shapes.push(Shape::line_segment([a, b], stroke));
            }
            out.push(Drawn {
                tree,
                path: s.path.clone(),
                a,
                b,
            });
        }
    }
    painter.extend(shapes);
}

/// Lights as markers: a filled disc in the light's colour with a ring, where in front of the
/// camera.
pub fn draw_lights(painter: &egui::Painter, view: &ScreenView, lights: &[crate::scene::Light]) {
    for l in lights {
        let Some(p) = view.screen_pos(l.position) else {
            continue;
        };
        let c = l.color / l.color.max_element().max(1e-6);
        let fill = Color32::from_rgb(
            (c.x.clamp(0.0, 1.0) * 255.0) as u8,
            (c.y.clamp(0.0, 1.0) * 255.0) as u8,
            (c.z.clamp(0.0, 1.0) * 255.0) as u8,
        );
        painter.circle_filled(p, 6.0, fill);
        painter.circle_stroke(p, 9.0, Stroke::new(2.0, Color32::BLACK));
        let galley = painter.layout_no_wrap(
            l.name.clone(),
            egui::FontId::proportional(13.0),
            Color32::WHITE,
        );
        if let Some(at) = label_place(p, galley.size(), painter.clip_rect()) {
            painter.galley(at, galley, Color32::WHITE);
        }
    }
}

/// Where the top-left corner of a marker's label of `size` goes: above and right of the marker
/// at `marker`, or on its left where the right would leave `clip`, moved down or up to stay in
/// it; `None` when the marker itself is outside `clip` (its label would name nothing shown).
fn label_place(marker: Pos2, size: egui::Vec2, clip: Rect) -> Option<Pos2> {
    if !clip.contains(marker) {
        return None;
    }
    const GAP: f32 = 11.0;
    let x = if marker.x + GAP + size.x <= clip.max.x {
        marker.x + GAP
    } else {
        (marker.x - GAP - size.x).max(clip.min.x)
    };
    let y = (marker.y - GAP - size.y).clamp(clip.min.y, (clip.max.y - size.y).max(clip.min.y));
    Some(Pos2::new(x, y))
}

/// The drawn segment nearest `pos`, within [`PICK_DISTANCE`].
pub fn pick(drawn: &[Drawn], pos: Pos2) -> Option<&Drawn> {
    drawn
        .iter()
        .map(|d| (d, distance_to_segment(pos, d.a, d.b)))
        .filter(|(_, dist)| *dist <= PICK_DISTANCE)
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .map(|(d, _)| d)
}

fn distance_to_segment(p: Pos2, a: Pos2, b: Pos2) -> f32 {
    let ab = b - a;
    let len2 = ab.length_sq();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t).distance(p)
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_lights_label_stays_in_the_pane_and_goes_with_its_marker() {
        use super::label_place;
        use eframe::egui::{Pos2, Rect, vec2};
        let clip = Rect::from_min_max(Pos2::new(100.0, 50.0), Pos2::new(400.0, 300.0));
        let size = vec2(60.0, 14.0);
        // In the open: above and right of the marker.
        assert_eq!(
            label_place(Pos2::new(200.0, 150.0), size, clip),
            Some(Pos2::new(211.0, 125.0))
        );
        // Near the right edge: on the left. Near the top: moved down into the pane.
        assert_eq!(
            label_place(Pos2::new(380.0, 55.0), size, clip),
            Some(Pos2::new(309.0, 50.0))
        );
        // Every label lies inside the pane, wherever in it the marker is.
        for x in (100..400).step_by(7) {
            for y in (50..300).step_by(7) {
                let at = label_place(Pos2::new(x as f32, y as f32), size, clip).expect("a place");
                assert!(
                    clip.contains_rect(Rect::from_min_size(at, size)),
                    "({x}, {y}): {at:?}"
                );
            }
        }
        // A marker left of the pane, as an eye just outside the view: no label.
        assert_eq!(label_place(Pos2::new(90.0, 150.0), size, clip), None);
    }

    use super::*;
    use crate::scene::builtin::load_builtin;

    #[test]
    fn screen_positions_are_the_cpu_projection_mapped_into_the_pane() {
        let scene = load_builtin("default").expect("built-in");
        let (w, h) = (320, 200);
        let mut camera = scene.camera.clone();
        camera.orbit(0.7, 0.3);
        let frame = CameraFrame::new(&camera, w, h);
        let rect = Rect::from_min_size(Pos2::new(100.0, 50.0), egui::vec2(640.0, 400.0));
        let view = ScreenView {
            rect,
            frame,
            width: w,
            height: h,
        };
        for p in [Vec3::ZERO, Vec3::new(1.0, 0.5, -2.0), scene.camera.position] {
            let (x, y) = frame.project(p).expect("in front");
            let s = view.screen_pos(p).expect("in front");
            assert!((s.x - (100.0 + x * 2.0)).abs() < 1e-3, "{s:?} {x}");
            assert!((s.y - (50.0 + y * 2.0)).abs() < 1e-3, "{s:?} {y}");
        }
        // The image corners are the pane's corners.
        assert_eq!(view.image_to_screen(0.0, 0.0), rect.min);
        assert_eq!(view.image_to_screen(w as f32, h as f32), rect.max);
    }

    #[test]
    fn picking_finds_the_nearest_segment_within_reach() {
        let drawn = vec![
            Drawn {
                tree: 0,
                path: vec![0],
                a: Pos2::new(0.0, 0.0),
                b: Pos2::new(100.0, 0.0),
            },
            Drawn {
                tree: 0,
                path: vec![1],
                a: Pos2::new(0.0, 10.0),
                b: Pos2::new(100.0, 10.0),
            },
        ];
        assert_eq!(
            pick(&drawn, Pos2::new(50.0, 7.0)).map(|d| d.path.clone()),
            Some(vec![1])
        );
        assert!(pick(&drawn, Pos2::new(50.0, 30.0)).is_none());
    }
}
