//! The ray tree in 3D (docs/design.md, "The viewer"), as data every view draws the same way: the tree's rays as
//! world-space segments with a style (the one palette of ray kinds), the render camera as a
//! frustum with its image plane and the clicked pixel, the lights as markers, and the filters
//! (generation, ray kind, end reason) that hide segments. The viewer's render overlay and scene
//! view and the headless `raytree tree --scene-view` draw these, so their rules cannot drift.

pub mod cutaway;
pub mod headless;
pub mod occlusion;
pub mod outline;
pub mod overview;
pub mod raster;

use glam::Vec3;

use crate::accel::{Accel, Visits};
use crate::export::to_srgb8;
use crate::ray_tree::{Node, RayTree};
use crate::scene::{CameraFrame, Scene};
use crate::trace::{EndReason, RayKind, Tracer, VisitQuery};

/// A node's place in its tree: the child indices from the root.
pub type NodePath = Vec<usize>;

/// How a segment is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Style {
    /// A ray of the tree, to its hit, to the light it met, or out of the scene.
    Ray(RayKind),
    /// A ray that was not traced (past max depth, below the cutoff, past the ray budget): a
    /// short stub.
    NotTraced(RayKind),
    /// A shadow ray that reached its light.
    ShadowLit,
    /// A blocked shadow ray, up to its blocker.
    ShadowBlocked,
    /// A blocked shadow ray, past its blocker to the light (faded).
    ShadowPastBlocker,
    /// The surface normal at a hit, a short tick.
    Normal,
    /// The render camera's frustum edges.
    Frustum,
    /// The render camera's image plane outline.
    ImagePlane,
    /// The clicked pixel on the image plane.
    Pixel,
    /// A box (BVH node or grid cell) the selected ray's traversal entered.
    VisitedBox,
    /// A box of the BVH level shown.
    LevelBox,
}

/// sRGB colour and opacity of each style: the one palette of ray kinds, used by the tree's
/// list and diagram, the overlay, the scene view and the headless scene view.
pub fn style_rgba(style: Style) -> [u8; 4] {
    match style {
        Style::Ray(kind) => {
            let [r, g, b] = kind_rgb(kind);
            [r, g, b, 255]
        }
        Style::NotTraced(kind) => {
            let [r, g, b] = kind_rgb(kind);
            [r, g, b, 115]
        }
        Style::ShadowLit => {
            let [r, g, b] = kind_rgb(RayKind::Shadow);
            [r, g, b, 230]
        }
        Style::ShadowBlocked => [220, 60, 60, 255],
        Style::ShadowPastBlocker => [90, 30, 30, 204],
        Style::Normal => [255, 0, 255, 255],
        Style::Frustum => [150, 150, 150, 200],
        Style::ImagePlane => [200, 200, 200, 230],
        Style::Pixel => [255, 255, 255, 255],
        Style::VisitedBox => [0, 230, 230, 220],
        Style::LevelBox => [160, 160, 255, 110],
    }
}

/// The colour of each ray kind (sRGB).
pub fn kind_rgb(kind: RayKind) -> [u8; 3] {
    match kind {
        RayKind::Primary => [235, 235, 235],
        RayKind::Reflected => [80, 170, 255],
        RayKind::Refracted => [90, 220, 120],
        RayKind::Shadow => [255, 200, 60],
    }
}

/// The hovered or selected node, drawn over its style.
pub const HIGHLIGHT_RGB: [u8; 3] = [255, 120, 255];

/// The tints that tell several trees apart (sRGB), one per tree in picking order, repeating
/// after the last: none of them a ray kind's colour (white, blue, green, yellow) or the
/// highlight's pink, so a tinted tree never reads as a kind of ray.
pub const TREE_TINTS: [[u8; 3]; 8] = [
    [255, 140, 0],
    [0, 200, 200],
    [190, 120, 255],
    [255, 90, 130],
    [150, 200, 40],
    [200, 150, 100],
    [110, 110, 255],
    [240, 240, 120],
];

/// Tint number `i` (any number: the palette repeats).
pub fn tree_tint(i: usize) -> [u8; 3] {
    TREE_TINTS[i % TREE_TINTS.len()]
}

/// How strongly a tree is drawn among several.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strength {
    /// The selected tree: its rays in their kinds' colours, full width.
    Strong,
    /// Another tree: thin, in its tint, faint, without normals, so many trees leave the image
    /// readable and the selected one stands out.
    Faint,
}

/// Opacity kept by a faint tree's rays.
pub const FAINT_ALPHA: f32 = 0.55;
/// Width of a faint tree's rays, as a share of a strong tree's.
pub const FAINT_WIDTH: f32 = 0.6;

/// How one tree among several is drawn: its tint and strength.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TreeLook {
    pub tint: [u8; 3],
    pub strength: Strength,
}

impl TreeLook {
    /// The colour and opacity of a segment of `style` of this tree (opacity 0: not drawn).
    pub fn rgba(&self, style: Style) -> [u8; 4] {
        let own = style_rgba(style);
        match (self.strength, style) {
            (Strength::Strong, _) => own,
            (Strength::Faint, Style::Normal) => [0, 0, 0, 0],
            (
                Strength::Faint,
                Style::Ray(_)
                | Style::NotTraced(_)
                | Style::ShadowLit
                | Style::ShadowBlocked
                | Style::ShadowPastBlocker,
            ) => {
                let [r, g, b] = self.tint;
                [r, g, b, (own[3] as f32 * FAINT_ALPHA) as u8]
            }
            (Strength::Faint, _) => own,
        }
    }

    /// The width of this tree's rays as a share of a strong tree's.
    pub fn width(&self) -> f32 {
        match self.strength {
            Strength::Strong => 1.0,
            Strength::Faint => FAINT_WIDTH,
        }
    }
}

/// One straight piece to draw, in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    pub a: Vec3,
    pub b: Vec3,
    pub style: Style,
    /// The node it belongs to (empty for camera and light markers).
    pub path: NodePath,
    /// The node's depth (0 for the primary ray): the step-through reveals generation by
    /// generation. Shadow rays and normals belong to their node's generation.
    pub generation: u32,
    /// How the node's branch ended, for the end-reason filter.
    pub end: Option<EndReason>,
}

/// Which segments to show.
#[derive(Clone, Debug, PartialEq)]
pub struct Filter {
    /// Show generations `0..=max_generation`.
    pub max_generation: u32,
    pub primary: bool,
    pub reflected: bool,
    pub refracted: bool,
    pub shadow: bool,
    pub normals: bool,
    /// Hide rays whose branch ended this way (`None`: the ray hit a surface).
    pub hidden_ends: Vec<EndReason>,
}

impl Default for Filter {
    fn default() -> Self {
        Self {
            max_generation: u32::MAX,
            primary: true,
            reflected: true,
            refracted: true,
            shadow: true,
            normals: true,
            hidden_ends: Vec::new(),
        }
    }
}

impl Filter {
    /// Whether `s` is shown.
    pub fn shows(&self, s: &Segment) -> bool {
        if s.generation > self.max_generation {
            return false;
        }
        if s.end.is_some_and(|e| self.hidden_ends.contains(&e)) {
            return false;
        }
        match s.style {
            Style::Ray(kind) | Style::NotTraced(kind) => match kind {
                RayKind::Primary => self.primary,
                RayKind::Reflected => self.reflected,
                RayKind::Refracted => self.refracted,
                RayKind::Shadow => self.shadow,
            },
            Style::ShadowLit | Style::ShadowBlocked | Style::ShadowPastBlocker => self.shadow,
            Style::Normal => self.normals,
            Style::Frustum
            | Style::ImagePlane
            | Style::Pixel
            | Style::VisitedBox
            | Style::LevelBox => true,
        }
    }
}

/// The node at `path` below `root`.
pub fn node_at<'a>(root: &'a Node, path: &[usize]) -> Option<&'a Node> {
    let mut node = root;
    for &i in path {
        node = node.children.get(i)?;
    }
    Some(node)
}

/// The scene's size (the diagonal of the bounds a view frames, [`Scene::framing_bounds`], at
/// least 1e-3; 10 for an empty scene): how long rays that hit nothing, stubs and normal ticks
/// are drawn.
pub fn extent(scene: &Scene) -> f32 {
    scene
        .framing_bounds()
        .map(|(lo, hi)| (hi - lo).length())
        .unwrap_or(10.0)
        .max(1e-3)
}

/// Every ray of `tree` as segments: each ray to its hit (or out of the scene, or to the light it
/// met), the normal at each hit as a tick, each shadow ray to its light (split at a blocker),
/// and untraced rays as stubs. `extent` is the scene's size ([`extent`]).
pub fn tree_segments(tree: &RayTree, extent: f32) -> Vec<Segment> {
    let mut out = Vec::new();
    let mut stack: Vec<(NodePath, &Node)> = vec![(Vec::new(), &tree.root)];
    while let Some((path, node)) = stack.pop() {
        let mut push = |a: Vec3, b: Vec3, style: Style| {
            out.push(Segment {
                a,
                b,
                style,
                path: path.clone(),
                generation: node.depth,
                end: node.end,
            });
        };
        match (&node.hit, node.end) {
            (Some(hit), _) => {
                push(node.origin, hit.point, Style::Ray(node.kind));
                push(
                    hit.point,
                    hit.point + hit.normal * extent * 0.04,
                    Style::Normal,
                );
                for s in node
                    .shadow_rays
                    .iter()
                    .filter(|s| !s.facing_away && !s.contributes_nothing)
                {
                    let light = hit.point + s.to_light * s.distance;
                    match s.blocked_at {
                        Some(d) if s.blocked_by.is_some() => {
                            let blocker = hit.point + s.to_light * d;
                            push(hit.point, blocker, Style::ShadowBlocked);
                            push(blocker, light, Style::ShadowPastBlocker);
                        }
                        _ => push(hit.point, light, Style::ShadowLit),
                    }
                }
            }
            (None, Some(EndReason::NoHit)) => {
                push(
                    node.origin,
                    node.origin + node.direction * extent * 2.0,
                    Style::Ray(node.kind),
                );
            }
            (None, Some(EndReason::MaxDepth | EndReason::Cutoff | EndReason::Budget)) => {
                push(
                    node.origin,
                    node.origin + node.direction * extent * 0.08,
                    Style::NotTraced(node.kind),
                );
            }
            // A visible light ends the ray at its surface.
            (None, _) => {
                let t = node.light.as_ref().map_or(extent * 0.2, |l| l.t);
                push(
                    node.origin,
                    node.origin + node.direction * t,
                    Style::Ray(node.kind),
                );
            }
        }
        for (i, child) in node.children.iter().enumerate().rev() {
            let mut p = path.clone();
            p.push(i);
            stack.push((p, child));
        }
    }
    out
}

/// The render camera of `scene` as segments: the four edges from the eye to the corners of an
/// image plane at distance `plane` along the view, the plane's outline, and a cross on the
/// centre of `pixel` (when given).
pub fn camera_segments(scene: &Scene, plane: f32, pixel: Option<[u32; 2]>) -> Vec<Segment> {
    let (w, h) = (scene.render.width, scene.render.height);
    let frame = CameraFrame::new(&scene.camera, w, h);
    let eye = scene.camera.position;
    // A point of the image plane: the ray through image position (x, y) at distance `plane`
    // along the view direction.
    let view = (scene.camera.look_at - eye).normalize_or(Vec3::NEG_Z);
    let at = |x: f32, y: f32| {
        let d = frame.ray(x, y).dir;
        eye + d * (plane / d.dot(view).max(1e-6))
    };
    let (wf, hf) = (w as f32, h as f32);
    let corners = [at(0.0, 0.0), at(wf, 0.0), at(wf, hf), at(0.0, hf)];
    let seg = |a: Vec3, b: Vec3, style: Style| Segment {
        a,
        b,
        style,
        path: Vec::new(),
        generation: 0,
        end: None,
    };
    let mut out: Vec<Segment> = corners
        .iter()
        .map(|&c| seg(eye, c, Style::Frustum))
        .collect();
    for i in 0..4 {
        out.push(seg(corners[i], corners[(i + 1) % 4], Style::ImagePlane));
    }
    if let Some([x, y]) = pixel {
        let (x, y) = (x as f32, y as f32);
        // A cross over the pixel, 4 % of the plane wide so it can be seen at any size.
        let r = (0.5f32).max(wf.max(hf) * 0.02);
        let (cx, cy) = (x + 0.5, y + 0.5);
        out.push(seg(at(cx - r, cy - r), at(cx + r, cy + r), Style::Pixel));
        out.push(seg(at(cx - r, cy + r), at(cx + r, cy - r), Style::Pixel));
    }
    out
}

/// A light as the scene views mark it: a small disc at its position, in its colour.
#[derive(Clone, Debug, PartialEq)]
pub struct LightMarker {
    pub position: Vec3,
    /// The light's hue at full brightness (sRGB): a dim light is as easy to see as a bright one.
    pub rgb: [u8; 3],
    /// The radius of its visible ball (0 for a point light): the marker's centre lies behind
    /// that surface, which must not hide it.
    pub radius: f32,
}

/// The scene's lights as markers.
pub fn light_markers(scene: &Scene) -> Vec<LightMarker> {
    scene
        .lights
        .iter()
        .map(|l| {
            let peak = l.color.max_element();
            let rgb = if peak > 0.0 && peak.is_finite() {
                to_srgb8(l.color / peak)
            } else {
                // A black light still has a place: grey.
                [128, 128, 128]
            };
            LightMarker {
                position: l.position,
                rgb,
                radius: l.radius,
            }
        })
        .collect()
}

/// Corner `k` (0..8) of the box `lo..hi`: bit 0 picks x, bit 1 y, bit 2 z.
pub fn box_corner(lo: Vec3, hi: Vec3, k: usize) -> Vec3 {
    Vec3::new(
        if k & 1 == 0 { lo.x } else { hi.x },
        if k & 2 == 0 { lo.y } else { hi.y },
        if k & 4 == 0 { lo.z } else { hi.z },
    )
}

/// The twelve edges of the box `lo..hi` in `style`.
pub fn box_segments(lo: Vec3, hi: Vec3, style: Style) -> Vec<Segment> {
    let corner = |i: usize| box_corner(lo, hi, i);
    // Corner pairs that differ in one bit are the edges.
    (0..8)
        .flat_map(|i| [1, 2, 4].map(move |bit| (i, i | bit)))
        .filter(|&(i, j)| i != j)
        .map(|(i, j)| Segment {
            a: corner(i),
            b: corner(j),
            style,
            path: Vec::new(),
            generation: 0,
            end: None,
        })
        .collect()
}

/// What the accelerator did for the ray of node `path` of `tree`: the boxes it entered as
/// segments, and the counts (boxes entered, primitives tested). `None` when the path is not
/// in the tree.
pub fn visit_segments(
    tracer: &Tracer,
    tree: &RayTree,
    path: &[usize],
) -> Option<(Vec<Segment>, Visits)> {
    let node = node_at(&tree.root, path)?;
    let visits = tracer.visits_of(node.origin, node.direction, VisitQuery::Closest);
    let segments = visits
        .boxes
        .iter()
        .flat_map(|b| box_segments(b.lo, b.hi, Style::VisitedBox))
        .collect();
    Some((segments, visits))
}

/// The most boxes of one BVH level the scene view draws. Each box costs its twelve edges cut
/// against the view's depth every frame (about 4 µs a box); the deepest level of a
/// million-triangle tree holds 313,559 boxes, which took 1.8 s a frame drawn whole
/// (`cargo bench --bench frame -- --triangles 1000000 --level deepest`).
pub const MAX_LEVEL_BOXES: usize = 2048;

/// The boxes of one BVH level as the scene view draws them.
#[derive(Clone, Debug, Default)]
pub struct LevelSegments {
    /// The edges of the boxes drawn.
    pub segments: Vec<Segment>,
    /// How many boxes are drawn: all of the level's, or the [`MAX_LEVEL_BOXES`] with the
    /// largest surface area when it holds more.
    pub drawn: usize,
    /// How many boxes the level holds.
    pub total: usize,
}

/// The boxes of level `level` of the BVH `accel` (or the grid's non-empty cells) as segments:
/// all of them, or the [`MAX_LEVEL_BOXES`] with the largest surface area (the ones that cost
/// a ray the most, and that are seen at all from a distance), in the tree's order.
pub fn level_segments(accel: &Accel, level: u32) -> LevelSegments {
    let boxes = accel.level_boxes(level);
    let total = boxes.len();
    let area = |(lo, hi): &(Vec3, Vec3)| {
        let d = (*hi - *lo).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    };
    let mut keep: Vec<usize> = (0..total).collect();
    if total > MAX_LEVEL_BOXES {
        // Largest first; ties by the tree's order, so the choice is the same every time.
        keep.select_nth_unstable_by(MAX_LEVEL_BOXES - 1, |&i, &j| {
            area(&boxes[j]).total_cmp(&area(&boxes[i])).then(i.cmp(&j))
        });
        keep.truncate(MAX_LEVEL_BOXES);
        keep.sort_unstable();
    }
    LevelSegments {
        segments: keep
            .iter()
            .flat_map(|&i| box_segments(boxes[i].0, boxes[i].1, Style::LevelBox))
            .collect(),
        drawn: keep.len(),
        total,
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::ray_tree::pixel_tree;
    use crate::scene::builtin::load_builtin;
    use crate::trace::{TraceSettings, Tracer};

    fn tree(name: &str, x: u32, y: u32) -> (Scene, RayTree) {
        let scene = load_builtin(name).expect("built-in");
        let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
        let tree = pixel_tree(&tracer, x, y).expect("inside");
        (scene, tree)
    }

    #[test]
    fn every_node_has_its_ray_and_every_ray_starts_where_its_node_does() {
        let (scene, tree) = tree("glass", 160, 120);
        let segments = tree_segments(&tree, extent(&scene));
        let mut count = 0;
        let mut stack = vec![(Vec::new(), &tree.root)];
        while let Some((path, node)) = stack.pop() {
            count += 1;
            let ray = segments
                .iter()
                .find(|s| s.path == path && matches!(s.style, Style::Ray(_) | Style::NotTraced(_)))
                .unwrap_or_else(|| panic!("no ray for {path:?}"));
            assert_eq!(ray.a, node.origin);
            assert_eq!(ray.generation, node.depth);
            if let Some(hit) = &node.hit {
                assert_eq!(ray.b, hit.point);
            }
            for (i, c) in node.children.iter().enumerate() {
                let mut p: NodePath = path.clone();
                p.push(i);
                stack.push((p, c));
            }
        }
        assert!(count > 3, "the glass sphere's tree has children: {count}");
    }

    #[test]
    fn the_filter_hides_by_generation_kind_and_end() {
        let (scene, tree) = tree("glass", 160, 120);
        let segments = tree_segments(&tree, extent(&scene));
        let shown = |f: &Filter| segments.iter().filter(|s| f.shows(s)).count();
        let all = shown(&Filter::default());
        let first = Filter {
            max_generation: 0,
            ..Filter::default()
        };
        assert!(shown(&first) < all);
        assert!(
            segments
                .iter()
                .filter(|s| first.shows(s))
                .all(|s| s.generation == 0)
        );
        let no_shadow = Filter {
            shadow: false,
            ..Filter::default()
        };
        assert!(
            segments
                .iter()
                .filter(|s| no_shadow.shows(s))
                .all(|s| !matches!(
                    s.style,
                    Style::ShadowLit | Style::ShadowBlocked | Style::ShadowPastBlocker
                ))
        );
    }

    #[test]
    fn tints_are_distinct_from_the_ray_kinds_and_faint_trees_wear_them() {
        let kinds = [
            RayKind::Primary,
            RayKind::Reflected,
            RayKind::Refracted,
            RayKind::Shadow,
        ];
        let near = |a: [u8; 3], b: [u8; 3]| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (*x as i32 - y as i32).abs())
                .sum::<i32>()
                < 60
        };
        for (i, &t) in TREE_TINTS.iter().enumerate() {
            assert!(kinds.iter().all(|&k| !near(t, kind_rgb(k))), "tint {i}");
            assert!(!near(t, HIGHLIGHT_RGB), "tint {i}");
            assert!(
                TREE_TINTS[..i].iter().all(|&u| !near(t, u)),
                "tint {i} twice"
            );
        }
        assert_eq!(tree_tint(TREE_TINTS.len() + 1), TREE_TINTS[1]);
        let style = Style::Ray(RayKind::Reflected);
        let strong = TreeLook {
            tint: TREE_TINTS[2],
            strength: Strength::Strong,
        };
        assert_eq!(strong.rgba(style), style_rgba(style));
        assert_eq!(strong.width(), 1.0);
        let faint = TreeLook {
            strength: Strength::Faint,
            ..strong
        };
        let [r, g, b, a] = faint.rgba(style);
        assert_eq!([r, g, b], TREE_TINTS[2]);
        assert!(a < 255 && a > 0);
        assert!(faint.width() < 1.0);
        // Faint trees drop their normals; the camera keeps its colours.
        assert_eq!(faint.rgba(Style::Normal)[3], 0);
        assert_eq!(faint.rgba(Style::Frustum), style_rgba(Style::Frustum));
    }

    #[test]
    fn the_frustum_reaches_the_image_corners_and_the_pixel_lies_on_its_ray() {
        let (scene, tree) = tree("default", 100, 80);
        let segments = camera_segments(&scene, 1.0, Some(tree.pixel));
        let frame = CameraFrame::new(&scene.camera, scene.render.width, scene.render.height);
        let frustum: Vec<_> = segments
            .iter()
            .filter(|s| s.style == Style::Frustum)
            .collect();
        assert_eq!(frustum.len(), 4);
        let (x, y) = frame.project(frustum[2].b).expect("in front");
        assert!(
            (x - scene.render.width as f32).abs() < 1e-2
                && (y - scene.render.height as f32).abs() < 1e-2,
            "{x} {y}"
        );
        // The pixel's cross is centred on the primary ray of the tree.
        let cross: Vec<_> = segments
            .iter()
            .filter(|s| s.style == Style::Pixel)
            .collect();
        let centre = (cross[0].a + cross[0].b) * 0.5;
        let (x, y) = frame.project(centre).expect("in front");
        assert!(
            (x - 100.5).abs() < 1e-2 && (y - 80.5).abs() < 1e-2,
            "{x} {y}"
        );
        let dir = (centre - scene.camera.position).normalize();
        assert!(dir.abs_diff_eq(tree.root.direction, 1e-4));
    }

    #[test]
    fn a_box_has_twelve_edges_of_its_sides() {
        let edges = box_segments(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0), Style::LevelBox);
        assert_eq!(edges.len(), 12);
        let mut lengths: Vec<f32> = edges.iter().map(|e| (e.b - e.a).length()).collect();
        lengths.sort_by(f32::total_cmp);
        assert_eq!(
            lengths,
            [1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0, 3.0, 3.0, 3.0, 3.0]
        );
    }

    #[test]
    fn the_selected_rays_visits_are_boxes_around_its_path() {
        let scene = load_builtin("default").expect("built-in");
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let tree = pixel_tree(&tracer, 320, 300).expect("inside");
        let (segments, visits) = visit_segments(&tracer, &tree, &[]).expect("the root");
        assert_eq!(segments.len(), 12 * visits.boxes.len());
        assert!(!visits.boxes.is_empty() && !visits.prims.is_empty());
        // The hit lies inside an entered box.
        let p = tree.root.hit.as_ref().expect("a hit").point;
        assert!(
            visits
                .boxes
                .iter()
                .any(|b| (b.lo - Vec3::splat(1e-3)).cmple(p).all()
                    && p.cmple(b.hi + Vec3::splat(1e-3)).all())
        );
        assert!(visit_segments(&tracer, &tree, &[7, 7]).is_none());
        let root = level_segments(&tracer.accel, 0);
        assert_eq!((root.drawn, root.total), (1, 1));
        assert_eq!(root.segments.len(), 12);
    }

    /// A level with more boxes than are drawn keeps the largest: every box drawn is at least
    /// as large as every box left out, and the count drawn is the cap.
    #[test]
    fn a_level_of_more_boxes_than_drawn_keeps_the_largest() {
        use crate::scene::{MaterialId, ObjectId, Triangle};
        let mut scene = load_builtin("default").expect("built-in");
        // 30,000 triangles of many sizes on a grid, so the deep levels hold many boxes of
        // different areas.
        let triangles: Vec<Triangle> = (0..30_000)
            .map(|i| {
                let p = Vec3::new((i % 200) as f32, 0.5 * (i % 7) as f32, (i / 200) as f32);
                let size = 0.1 + (i % 13) as f32 * 0.07;
                Triangle {
                    vertices: [p, p + Vec3::X * size, p + Vec3::new(0.0, size, size)],
                    material: MaterialId(0),
                    object: ObjectId(0),
                }
            })
            .collect();
        scene.triangles = Arc::new(triangles);
        let settings = TraceSettings {
            accel: crate::accel::AccelKind::Bvh,
            ..TraceSettings::default()
        };
        let tracer = Tracer::new(Arc::new(scene), settings);
        let accel = &tracer.accel;
        let level = (0..accel.levels())
            .find(|&l| accel.level_boxes(l).len() > MAX_LEVEL_BOXES)
            .expect("a level with more boxes than are drawn");
        let all = accel.level_boxes(level);
        let shown = level_segments(accel, level);
        assert_eq!((shown.drawn, shown.total), (MAX_LEVEL_BOXES, all.len()));
        assert_eq!(shown.segments.len(), 12 * MAX_LEVEL_BOXES);
        let area = |lo: Vec3, hi: Vec3| {
            let d = hi - lo;
            d.x * d.y + d.y * d.z + d.z * d.x
        };
        // Each box's twelve edges span its corners.
        let drawn: Vec<(Vec3, Vec3)> = shown
            .segments
            .chunks(12)
            .map(|edges| {
                edges.iter().fold(
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    |(lo, hi), s| (lo.min(s.a).min(s.b), hi.max(s.a).max(s.b)),
                )
            })
            .collect();
        assert!(drawn.iter().all(|b| all.contains(b)));
        let smallest_drawn = drawn
            .iter()
            .map(|&(lo, hi)| area(lo, hi))
            .fold(f32::INFINITY, f32::min);
        let left_out: Vec<f32> = all
            .iter()
            .filter(|b| !drawn.contains(b))
            .map(|&(lo, hi)| area(lo, hi))
            .collect();
        assert!(!left_out.is_empty());
        let largest_left_out = left_out.iter().copied().fold(0.0, f32::max);
        assert!(
            smallest_drawn >= largest_left_out,
            "a box of area {largest_left_out} left out for one of {smallest_drawn}"
        );
    }
}
