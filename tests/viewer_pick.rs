//! The tree picker in the real viewer: shift-clicked pixels are listed and stepped through with
//! the arrow keys and [ ], the list and diagram following the selected tree; a click a few
//! pixels from a drawn ray selects that ray's node and keeps every tree; Ctrl+drag grids a
//! rectangle at the picker's density; the Show filters hide rays in the overlay too.

#[path = "common/viewer.rs"]
mod viewer;

use eframe::egui;
use egui_kittest::kittest::Queryable;
use raytree::scene::CameraFrame;
use viewer::{Window, harness, settle, small};

/// Where pixel (`x`, `y`) of the render is on screen.
fn pixel_pos(h: &Window, x: u32, y: u32) -> egui::Pos2 {
    let image = h.get_by_label("render viewport").rect();
    let (w, hh) = (
        h.state().scene().render.width as f32,
        h.state().scene().render.height as f32,
    );
    egui::pos2(
        image.min.x + (x as f32 + 0.5) / w * image.width(),
        image.min.y + (y as f32 + 0.5) / hh * image.height(),
    )
}

/// Where world point `p` is drawn over the render, if in front of the render camera.
fn world_pos(h: &Window, p: glam::Vec3) -> Option<egui::Pos2> {
    let scene = h.state().scene();
    let (w, hh) = (scene.render.width, scene.render.height);
    let image = h.get_by_label("render viewport").rect();
    let (x, y) = CameraFrame::new(&scene.camera, w, hh).project(p)?;
    Some(egui::pos2(
        image.min.x + x / w as f32 * image.width(),
        image.min.y + y / hh as f32 * image.height(),
    ))
}

/// A press and release at `pos` with `modifiers` held.
fn click(h: &mut Window, pos: egui::Pos2, modifiers: egui::Modifiers) {
    h.event(egui::Event::ModifiersChanged(modifiers));
    h.hover_at(pos);
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers,
        });
        h.step();
    }
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.step();
}

/// A pixel of the glass sphere and one of the floor in the 160×120 default scene.
const GLASS: [u32; 2] = [60, 69];
const FLOOR: [u32; 2] = [99, 53];

fn current(h: &Window) -> Option<[u32; 2]> {
    h.state().selection.tree.as_ref().map(|t| t.pixel)
}

fn press(h: &mut Window, key: egui::Key) {
    h.key_press(key);
    h.step();
    h.step();
}

#[test]
fn shift_clicked_trees_are_listed_and_the_arrow_keys_step_through_them() {
    let mut h = harness(small("default"));
    settle(&mut h);
    for [x, y] in [GLASS, FLOOR] {
        let at = pixel_pos(&h, x, y);
        click(&mut h, at, egui::Modifiers::SHIFT);
    }
    assert_eq!(h.state().selection.trees().count(), 2);
    assert_eq!(
        current(&h),
        Some(FLOOR),
        "the last shift-clicked tree is shown"
    );
    press(&mut h, egui::Key::ArrowUp);
    assert_eq!(current(&h), Some(GLASS), "Up selects the tree before");
    // The picker lists both, in picking order, each with its own tint.
    let entries = &h.state().selection.picker.entries;
    assert_eq!(
        entries.iter().map(|e| e.pixel).collect::<Vec<_>>(),
        [GLASS, FLOOR]
    );
    assert_ne!(entries[0].tint, entries[1].tint);
    h.get_by_label_contains("tree 1 of 2");
    press(&mut h, egui::Key::ArrowDown);
    assert_eq!(current(&h), Some(FLOOR), "Down selects the next tree");
    h.get_by_label_contains("tree 2 of 2");
    // The diagram shows the selected tree.
    h.get_by_label(&format!("ray tree diagram of ({}, {})", FLOOR[0], FLOOR[1]));
    // Held at the end, then back with Up and with [.
    press(&mut h, egui::Key::ArrowDown);
    assert_eq!(current(&h), Some(FLOOR));
    press(&mut h, egui::Key::ArrowUp);
    assert_eq!(current(&h), Some(GLASS));
    press(&mut h, egui::Key::CloseBracket);
    assert_eq!(current(&h), Some(FLOOR));
    press(&mut h, egui::Key::OpenBracket);
    assert_eq!(current(&h), Some(GLASS));
    assert_eq!(
        h.state().selection.trees().count(),
        2,
        "stepping keeps every tree"
    );
}

#[test]
fn a_click_three_pixels_from_a_drawn_ray_selects_it_and_keeps_every_tree() {
    let mut h = harness(small("default"));
    settle(&mut h);
    for ([x, y], modifiers) in [
        (FLOOR, egui::Modifiers::NONE),
        (GLASS, egui::Modifiers::SHIFT),
    ] {
        let at = pixel_pos(&h, x, y);
        click(&mut h, at, modifiers);
    }
    let tree = h.state().selection.tree.clone().expect("a tree");
    // The glass sphere's first child as drawn: from the sphere to what it met (or out of the
    // scene), a long line on screen.
    let extent = raytree::scene_view::extent(h.state().scene());
    let ray = raytree::scene_view::tree_segments(&tree, extent)
        .into_iter()
        .find(|s| s.path == [0] && matches!(s.style, raytree::scene_view::Style::Ray(_)))
        .expect("the child's ray");
    // A point of it well away from its start, in front of the render camera (a ray reflected
    // back may pass behind it), and the line's direction on screen there.
    let a = world_pos(&h, ray.a).expect("in front");
    let (mid, along) = [0.5f32, 0.3, 0.2, 0.1, 0.05]
        .into_iter()
        .find_map(|t| {
            let p = ray.a + (ray.b - ray.a) * t;
            let q = ray.a + (ray.b - ray.a) * (t * 0.9);
            let (p, q) = (world_pos(&h, p)?, world_pos(&h, q)?);
            (p.distance(a) > 20.0).then(|| (p, (p - q).normalized()))
        })
        .expect("the child's ray is a long line on screen");
    let off = mid + egui::vec2(-along.y, along.x) * 3.0;
    click(&mut h, off, egui::Modifiers::NONE);
    let selection = &h.state().selection;
    assert_eq!(selection.trees().count(), 2, "the click discarded trees");
    assert_eq!(current(&h), Some(GLASS));
    assert_eq!(
        selection.tree_state.selected.as_deref(),
        Some(&[0usize][..])
    );
    // A click on the image far from every ray picks its pixel as before.
    let empty = pixel_pos(&h, 150, 5);
    click(&mut h, empty, egui::Modifiers::NONE);
    assert_eq!(current(&h), Some([150, 5]));
    assert_eq!(h.state().selection.trees().count(), 1);
}

#[test]
fn ctrl_drag_grids_the_rectangle_at_the_pickers_density() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let (from, to) = (pixel_pos(&h, 10, 10), pixel_pos(&h, 150, 110));
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::COMMAND));
    h.hover_at(from);
    h.event(egui::Event::PointerButton {
        pos: from,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::COMMAND,
    });
    h.step();
    for i in 1..=5 {
        h.hover_at(from + (to - from) * (i as f32 / 5.0));
        h.step();
    }
    h.event(egui::Event::PointerButton {
        pos: to,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::COMMAND,
    });
    h.step();
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.step();
    let selection = &h.state().selection;
    assert_eq!(selection.trees().count(), 16, "a 4×4 grid by default");
    assert!(selection.picker.entries.iter().all(|e| e.from_grid));
    // Only the selected tree is drawn whole: the others to the grid's depth.
    let current = current(&h).expect("a current tree");
    let (_, depth) = selection.picker.look(current, Some(current));
    assert_eq!(depth, None);
    let other = selection.picker.entries[1].pixel;
    assert_eq!(selection.picker.look(other, Some(current)).1, Some(2));
}

#[test]
fn hiding_shadow_rays_hides_them_over_the_render_too() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let at = pixel_pos(&h, GLASS[0], GLASS[1]);
    click(&mut h, at, egui::Modifiers::NONE);
    let image = h.get_by_label("render viewport").rect();
    let lines = |h: &Window| {
        h.output()
            .shapes
            .iter()
            .filter(|c| match &c.shape {
                egui::Shape::LineSegment { points, .. } => {
                    points.iter().any(|p| image.contains(*p))
                }
                _ => false,
            })
            .count()
    };
    h.step();
    let before = lines(&h);
    h.state_mut().scene_view.filter.shadow = false;
    h.step();
    h.step();
    let after = lines(&h);
    assert!(
        after < before,
        "{before} lines over the render with shadow rays, {after} without"
    );
}

/// At 1024×640 with many trees (two shift-clicks and a rectangle's grid) the picker's strip
/// stays inside its pane: its step line, the grid settings and "to depth" are all on screen
/// (the strip wraps), and the window snapshot shows it.
#[test]
fn the_picker_strip_fits_its_pane_at_1024x640() {
    let mut h = viewer::window_with(small("default"), [1024.0, 640.0], |app| {
        app.set_view(2, false)
    });
    settle(&mut h);
    for [x, y] in [GLASS, FLOOR] {
        let at = pixel_pos(&h, x, y);
        click(&mut h, at, egui::Modifiers::SHIFT);
    }
    h.state_mut()
        .command(raytree::app::Command::PickRect([20, 20], [140, 100]));
    h.step();
    settle(&mut h);
    h.step();
    let trees = h.state().selection.trees().count();
    assert!(trees > 10, "{trees} trees");
    let right = h.ctx.content_rect().right();
    // The last shift-clicked tree is the current one: the grid's trees were added after it.
    for label in ["tree 2 of", "to depth", "list all trees"] {
        let rect = h.get_by_label_contains(label).rect();
        assert!(
            rect.right() <= right + 0.5 && rect.width() > 0.0,
            "{label:?} at {rect:?} leaves the window (right edge {right})"
        );
    }
    h.state_mut().messages.clear_toasts();
    h.step();
    viewer::mask_status(&mut h);
    h.snapshot("picker_1024x640");
}
