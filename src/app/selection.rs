//! What the user picked: the ray trees shown (the current one and the extra ones), the node
//! selected and hovered in them, the pixel under the pointer, the rectangle being dragged over
//! the render, and the material and light selected in the settings.

use eframe::egui;

use super::messages::Messages;
use super::tree_picks::Picker;
use super::tree_view::TreeState;
use crate::ray_tree::{RayTree, pixel_tree};
use crate::scene_view::TreeLook;
use crate::trace::Tracer;

/// The most trees shown at once (the current one and the extra ones).
pub const MAX_TREES: usize = 64;

#[derive(Default)]
pub struct TreeSelection {
    /// The tree of the pixel clicked last: the list and the detail show it.
    pub tree: Option<RayTree>,
    /// More pixels' trees, drawn beside the current one (shift-click, a dragged rectangle);
    /// at most [`MAX_TREES`] with the current one.
    pub extra_trees: Vec<RayTree>,
    /// Selection, hover and the pinned tree, shared by the tree's views.
    pub tree_state: TreeState,
    /// The trees in picking order with their tints, and the rectangle grid's settings.
    pub picker: Picker,
    /// The render's pixel under the pointer.
    pub hover: Option<(u32, u32)>,
    /// The rectangle being dragged over the render with Ctrl or Alt (screen points).
    pub rect_select: Option<(egui::Pos2, egui::Pos2)>,
    pub selected_material: Option<usize>,
    pub selected_light: Option<usize>,
}

/// Pixel `p` of a `from`-sized image as the pixel of a `to`-sized one that looks the same way:
/// the camera keeps its vertical field of view, so rows scale with the height and columns keep
/// their distance from the centre in units of the height (a narrower image is the same picture
/// cropped at the sides). A pixel the new image no longer shows goes to its nearest edge.
pub fn remap_pixel(p: [u32; 2], from: (u32, u32), to: (u32, u32)) -> [u32; 2] {
    let s = to.1 as f64 / from.1.max(1) as f64;
    let cell = |v: f64, n: u32| (v.floor().max(0.0) as u32).min(n.saturating_sub(1));
    let x = (p[0] as f64 + 0.5 - from.0 as f64 * 0.5) * s + to.0 as f64 * 0.5;
    let y = (p[1] as f64 + 0.5) * s;
    [cell(x, to.0), cell(y, to.1)]
}

impl TreeSelection {
    /// The trees shown: the current one first, then the extra ones.
    pub fn trees(&self) -> impl Iterator<Item = &RayTree> {
        self.tree.iter().chain(self.extra_trees.iter())
    }

    /// The generation the step-through reveals down to (every one when it is off).
    pub fn max_generation(&self) -> u32 {
        self.tree_state.reveal.unwrap_or(u32::MAX)
    }

    /// Makes extra tree `i` the current one (the list and detail show it); the current one
    /// joins the extra trees in its place.
    pub fn make_current(&mut self, i: usize) {
        if i < self.extra_trees.len() {
            match self.tree.take() {
                Some(current) => {
                    self.tree = Some(std::mem::replace(&mut self.extra_trees[i], current))
                }
                None => self.tree = Some(self.extra_trees.remove(i)),
            }
        }
    }

    /// The tree of pixel (`x`, `y`) becomes the only one shown, its root selected; the
    /// material its primary ray hit is selected.
    pub fn pick(&mut self, tracer: &Tracer, x: u32, y: u32) {
        self.extra_trees.clear();
        self.picker.entries.clear();
        self.picker.last_rect = None;
        self.tree = pixel_tree(tracer, x, y);
        self.sync();
        self.tree_state.selected = Some(Vec::new());
        if let Some(hit) = self.tree.as_ref().and_then(|t| t.root.hit.as_ref()) {
            self.selected_material = tracer
                .scene
                .materials
                .iter()
                .position(|m| m.name == hit.material);
        }
    }

    /// Adds the tree of pixel (`x`, `y`) to the trees shown, unless it is there or the trees
    /// are full (then says so). Returns false when full.
    pub fn add(&mut self, tracer: &Tracer, x: u32, y: u32, messages: &mut Messages) -> bool {
        self.add_as(tracer, x, y, messages, false)
    }

    /// [`Self::add`], the entry marked as a grid's (`from_grid`).
    fn add_as(
        &mut self,
        tracer: &Tracer,
        x: u32,
        y: u32,
        messages: &mut Messages,
        from_grid: bool,
    ) -> bool {
        self.sync();
        if self.trees().any(|t| t.pixel == [x, y]) {
            return true;
        }
        if self.trees().count() >= MAX_TREES {
            messages.notice(format!(
                "at most {MAX_TREES} trees are shown: click a pixel (without shift) to start over"
            ));
            return false;
        }
        let Some(tree) = pixel_tree(tracer, x, y) else {
            return true;
        };
        match self.tree {
            None => {
                self.tree = Some(tree);
                self.tree_state.selected = Some(Vec::new());
            }
            Some(_) => self.extra_trees.push(tree),
        }
        self.picker.push([x, y], from_grid);
        true
    }

    /// Adds the trees of a sparse grid of the pixels in `x0..=x1 × y0..=y1` (at most the
    /// picker's grid density across and down, spread over the rectangle), until the trees are
    /// full.
    pub fn add_rect(
        &mut self,
        tracer: &Tracer,
        [x0, y0]: [u32; 2],
        [x1, y1]: [u32; 2],
        messages: &mut Messages,
    ) {
        self.picker.last_rect = Some(([x0, y0], [x1, y1]));
        let per_side = self
            .picker
            .grid
            .per_side
            .clamp(1, super::tree_picks::MAX_GRID_SIDE);
        let axis = |a: u32, b: u32| -> Vec<u32> {
            let n = (b - a + 1).min(per_side);
            let mut v: Vec<u32> = (0..n)
                .map(|i| a + ((b - a) as u64 * (2 * i as u64 + 1) / (2 * n as u64)) as u32)
                .collect();
            v.dedup();
            v
        };
        for y in axis(y0.min(y1), y0.max(y1)) {
            for x in axis(x0.min(x1), x0.max(x1)) {
                if !self.add_as(tracer, x, y, messages, true) {
                    return;
                }
            }
        }
    }

    /// The trees follow a new tracer: pixels picked at the `old` render size keep their place
    /// in the image, and every tree is traced again with the new scene and settings.
    pub fn follow(&mut self, tracer: &Tracer, old: (u32, u32)) {
        let new = (tracer.scene.render.width, tracer.scene.render.height);
        if old != new {
            for t in self.tree.iter_mut().chain(self.extra_trees.iter_mut()) {
                t.pixel = remap_pixel(t.pixel, old, new);
            }
            for e in &mut self.picker.entries {
                e.pixel = remap_pixel(e.pixel, old, new);
            }
            self.picker.last_rect = None;
            self.hover = None;
        }
        if let Some(tree) = &self.tree {
            let [x, y] = tree.pixel;
            self.tree = pixel_tree(tracer, x, y);
        }
        self.extra_trees = self
            .extra_trees
            .iter()
            .filter_map(|t| pixel_tree(tracer, t.pixel[0], t.pixel[1]))
            .collect();
        self.sync();
    }

    /// Another scene was opened: nothing of the old one stays picked (the pointer's pixel and
    /// drag stay: they are the render pane's).
    pub fn clear(&mut self) {
        let (hover, rect_select) = (self.hover, self.rect_select);
        let grid = self.picker.grid;
        *self = Self {
            hover,
            rect_select,
            ..Self::default()
        };
        self.picker.grid = grid;
    }

    /// The picker follows the trees shown (a tree closed or re-traced away drops its entry),
    /// and when the current tree was closed the first other one in the picker's order becomes
    /// current.
    pub fn sync(&mut self) {
        let pixels: Vec<[u32; 2]> = self.trees().map(|t| t.pixel).collect();
        self.picker.follow(&pixels);
        if self.tree.is_none()
            && let Some(first) = self.picker.entries.first()
        {
            let pixel = first.pixel;
            self.select_pixel(pixel);
        }
    }

    /// Makes the tree of `pixel` the current one, its root selected.
    pub fn select_pixel(&mut self, pixel: [u32; 2]) {
        if self.tree.as_ref().is_some_and(|t| t.pixel == pixel) {
            return;
        }
        if let Some(i) = self.extra_trees.iter().position(|t| t.pixel == pixel) {
            self.make_current(i);
            self.tree_state.selected = Some(Vec::new());
            self.tree_state.hovered = None;
        }
    }

    /// Selects the tree `delta` places on in the picker's order (held at its ends).
    pub fn step(&mut self, delta: isize) {
        self.sync();
        let Some(current) = self.tree.as_ref().map(|t| t.pixel) else {
            return;
        };
        if let Some(pixel) = self.picker.step(current, delta) {
            self.select_pixel(pixel);
        }
    }

    /// The grid of `a..=b` again at the picker's density: the grid trees go, the others and the
    /// current one stay (unless it was a grid tree), then the new grid's trees are added.
    pub fn regrid(&mut self, tracer: &Tracer, a: [u32; 2], b: [u32; 2]) {
        let gridded: Vec<[u32; 2]> = self
            .picker
            .entries
            .iter()
            .filter(|e| e.from_grid)
            .map(|e| e.pixel)
            .collect();
        self.extra_trees.retain(|t| !gridded.contains(&t.pixel));
        if self
            .tree
            .as_ref()
            .is_some_and(|t| gridded.contains(&t.pixel))
        {
            self.tree = None;
        }
        self.sync();
        let mut quiet = Messages::default();
        self.add_rect(tracer, a, b, &mut quiet);
        self.sync();
    }

    /// The trees to draw, back to front, each with its number (0 the current tree, `i + 1`
    /// extra tree `i`), its look and the generation it is drawn down to (`None`: as the filter
    /// says).
    pub fn layers(&self) -> Vec<(&RayTree, usize, TreeLook, Option<u32>)> {
        let current = self.tree.as_ref().map(|t| t.pixel);
        self.extra_trees
            .iter()
            .enumerate()
            .map(|(i, t)| (t, i + 1))
            .chain(self.tree.iter().map(|t| (t, 0)))
            .map(|(t, n)| {
                let (look, depth) = self.picker.look(t.pixel, current);
                (t, n, look, depth)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pixel_keeps_its_place_at_another_render_size() {
        assert_eq!(remap_pixel([0, 0], (640, 480), (1280, 960)), [1, 1]);
        assert_eq!(remap_pixel([639, 479], (640, 480), (320, 240)), [319, 239]);
        assert_eq!(remap_pixel([320, 240], (640, 480), (800, 300)), [400, 150]);
        // Never outside the new image.
        assert_eq!(remap_pixel([9, 9], (10, 10), (3, 3)), [2, 2]);
    }

    #[test]
    fn a_pixel_keeps_its_ray_when_the_render_changes_shape() {
        use crate::scene::{Camera, CameraFrame};
        let camera = Camera::default();
        let (from, to) = ((694, 543), (238, 543));
        let old = CameraFrame::new(&camera, from.0, from.1);
        let new = CameraFrame::new(&camera, to.0, to.1);
        // A pixel near the centre: the new pixel holds the old pixel's ray.
        for p in [[340, 300], [300, 100], [400, 500]] {
            let ray = old.ray(p[0] as f32 + 0.5, p[1] as f32 + 0.5);
            let (x, y) = new.project(ray.origin + ray.dir).expect("in front");
            let q = remap_pixel(p, from, to);
            assert_eq!(q, [x.floor() as u32, y.floor() as u32], "pixel {p:?}");
        }
        // A pixel the narrower image crops away goes to the nearest edge, its row kept.
        assert_eq!(remap_pixel([20, 300], from, to), [0, 300]);
        assert_eq!(remap_pixel([680, 300], from, to), [237, 300]);
    }
}
