//! The viewer edits like a desktop application, driven through egui_kittest on the wgpu
//! software adapter: undo restores the previous scene exactly and redo re-applies it, a scalar
//! colour edit changes all three channels in one undoable step, a drag is one step, Home puts
//! the scene's camera back, a drag across the whole image orbits about 180°, and the value
//! modes get a colour scale beside the image.

#[path = "common/viewer.rs"]
mod viewer;

use eframe::egui;
use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use glam::Vec3;
use raytree::app::modes::ImageMode;
use raytree::scene::Scene;
use viewer::{Window, harness, settle, small};

fn keys(h: &mut Window, modifiers: egui::Modifiers, key: egui::Key) {
    h.key_press_modifiers(modifiers, key);
    h.step();
    h.step();
}

/// Drags from `from` by `by` with the primary button, in five moves.
fn drag(h: &mut Window, from: egui::Pos2, by: egui::Vec2) {
    drag_with(h, from, by, egui::Modifiers::NONE);
}

/// [`drag`] with `modifiers` held.
fn drag_with(h: &mut Window, from: egui::Pos2, by: egui::Vec2, modifiers: egui::Modifiers) {
    h.event(egui::Event::ModifiersChanged(modifiers));
    h.hover_at(from);
    h.step();
    h.event(egui::Event::PointerButton {
        pos: from,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers,
    });
    h.step();
    for i in 1..=5 {
        h.hover_at(from + by * (i as f32 / 5.0));
        h.step();
    }
    h.event(egui::Event::PointerButton {
        pos: from + by,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers,
    });
    h.step();
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.step();
}

#[test]
fn undo_restores_the_previous_scene_exactly_and_redo_reapplies() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let before = h.state().scene().clone();
    h.get_by_role_and_label(Role::Slider, "max depth")
        .set_value_accesskit(1.0);
    h.step();
    h.step();
    let after = h.state().scene().clone();
    assert_eq!(after.render.max_depth, 1);
    assert_eq!(h.state().working.history.undo_steps(), 1);

    keys(&mut h, egui::Modifiers::COMMAND, egui::Key::Z);
    assert!(
        *h.state().scene() == before,
        "undo did not restore the scene"
    );
    assert!(h.state().working.scene == before);
    keys(
        &mut h,
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    assert!(*h.state().scene() == after, "Ctrl+Shift+Z did not redo");
    keys(&mut h, egui::Modifiers::COMMAND, egui::Key::Z);
    assert!(*h.state().scene() == before);
    keys(&mut h, egui::Modifiers::COMMAND, egui::Key::Y);
    assert!(*h.state().scene() == after, "Ctrl+Y did not redo");
    // Nothing more to redo: the scene stays.
    keys(&mut h, egui::Modifiers::COMMAND, egui::Key::Y);
    assert!(*h.state().scene() == after);
}

#[test]
fn a_scalar_colour_edit_changes_all_three_channels_in_one_step() {
    let scene = small("default");
    // A material whose kr is grey: its field opens in scalar mode.
    let (i, m) = scene
        .materials
        .iter()
        .enumerate()
        .find(|(_, m)| m.reflectivity.x == m.reflectivity.y && m.reflectivity.y == m.reflectivity.z)
        .expect("a grey kr");
    let old = m.reflectivity;
    let mut h = harness(scene.clone());
    h.state_mut().selection.selected_material = Some(i);
    settle(&mut h);
    let steps = h.state().working.history.undo_steps();
    let target = if old.x == 0.5 { 0.25 } else { 0.5 };
    h.get_by_role_and_label(Role::SpinButton, "reflect kr")
        .set_value_accesskit(target as f64);
    h.step();
    h.step();
    assert_eq!(
        h.state().scene().materials[i].reflectivity,
        Vec3::splat(target),
        "one edit sets R, G and B"
    );
    assert_eq!(
        h.state().working.history.undo_steps(),
        steps + 1,
        "one undo step"
    );
    keys(&mut h, egui::Modifiers::COMMAND, egui::Key::Z);
    assert_eq!(h.state().scene().materials[i].reflectivity, old);
    assert!(*h.state().scene() == scene);
}

/// The angle in degrees between the camera's offsets from its target, about the up axis.
fn yaw_between(a: &Scene, b: &Scene) -> f32 {
    let flat = |s: &Scene| {
        let o = s.camera.position - s.camera.look_at;
        let up = s.camera.up.normalize();
        (o - up * o.dot(up)).normalize()
    };
    flat(a).dot(flat(b)).clamp(-1.0, 1.0).acos().to_degrees()
}

#[test]
fn a_drag_across_the_image_orbits_about_180_degrees_as_one_step_and_home_resets() {
    let scene = small("default");
    let mut h = harness(scene.clone());
    settle(&mut h);
    let image = h.get_by_label("render viewport").rect();
    // Across the whole width, at mid height (the drag starts just inside the left edge).
    let from = egui::pos2(image.min.x + 1.0, image.center().y);
    drag(&mut h, from, egui::vec2(image.width() - 2.0, 0.0));
    let turned = yaw_between(&scene, h.state().scene());
    assert!(
        (turned - 180.0).abs() < 12.0,
        "a full-width drag turned {turned}°"
    );
    let distance = |s: &Scene| (s.camera.position - s.camera.look_at).length();
    assert!((distance(h.state().scene()) - distance(&scene)).abs() < 1e-3);
    // The whole drag is one step.
    assert_eq!(h.state().working.history.undo_steps(), 1);
    keys(&mut h, egui::Modifiers::COMMAND, egui::Key::Z);
    assert_eq!(h.state().scene().camera, scene.camera);

    // A half-width drag at half the orbit speed: about 45°.
    h.state_mut().workspace.prefs.orbit_degrees = 90.0;
    drag(&mut h, from, egui::vec2(image.width() * 0.5, 0.0));
    let turned = yaw_between(&scene, h.state().scene());
    assert!((turned - 45.0).abs() < 6.0, "turned {turned}°");
    // Home: back to the scene's camera, itself one undoable step.
    keys(&mut h, egui::Modifiers::NONE, egui::Key::Home);
    assert_eq!(h.state().scene().camera, scene.camera);
    keys(&mut h, egui::Modifiers::COMMAND, egui::Key::Z);
    assert!(
        yaw_between(&scene, h.state().scene()) > 30.0,
        "undo of the reset"
    );
}

#[test]
fn value_modes_show_a_colour_scale_beside_the_image() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let full = h.get_by_label("render viewport").rect();
    for (mode, scale) in [
        (ImageMode::Depth, "colour scale: Depth reached from 0 to 5"),
        (ImageMode::Cost, "colour scale: Cost from 1 to 256+"),
    ] {
        h.state_mut().workspace.prefs.mode = mode;
        h.step();
        h.step();
        let bar = h.get_by_label(scale).rect();
        let image = h.get_by_label("render viewport").rect();
        assert!(
            !bar.intersects(image.shrink(0.5)),
            "{mode:?}: the scale {bar:?} overlaps the image {image:?}"
        );
        assert!(image.width() <= full.width());
    }
    h.state_mut().workspace.prefs.mode = ImageMode::Termination;
    h.step();
    h.step();
    h.get_by_label("max depth reached");
    h.get_by_label("escaped (no hit)");
    h.state_mut().workspace.prefs.mode = ImageMode::Normals;
    h.step();
    h.step();
    h.get_by_label("no hit");
    h.state_mut().workspace.prefs.mode = ImageMode::Render;
    h.step();
    h.step();
    assert!(h.query_by_label_contains("colour scale").is_none());
}

/// At 1024×640 the render pane is narrow: the scale goes under the image, which keeps its
/// width.
#[test]
fn in_a_small_window_the_scale_goes_under_the_image() {
    let mut h = harness(small("default"));
    h.set_size(egui::vec2(1024.0, 640.0));
    settle(&mut h);
    let full = h.get_by_label("render viewport").rect();
    h.state_mut().workspace.prefs.mode = ImageMode::Depth;
    h.step();
    h.step();
    let bar = h
        .get_by_label("colour scale: Depth reached from 0 to 5")
        .rect();
    let image = h.get_by_label("render viewport").rect();
    assert!(!bar.intersects(image.shrink(0.5)), "{bar:?} over {image:?}");
    assert!(
        image.width() >= 0.75 * full.width(),
        "the scale shrank the image from {} to {} points wide",
        full.width(),
        image.width()
    );
}

#[test]
fn f1_lists_ray_colours_glyphs_and_the_built_in_scenes() {
    let mut h = harness(small("default"));
    settle(&mut h);
    keys(&mut h, egui::Modifiers::NONE, egui::Key::F1);
    h.get_by_label("R: reflected ray");
    h.get_by_label("shadow ray blocked: in shadow");
    let names = raytree::scene::builtin::NAMES.join(", ");
    h.get_by_label_contains(&names);
    h.get_by_label_contains("Ctrl+Shift+Z");
}

#[test]
fn dragging_a_light_in_the_scene_view_moves_it_as_one_undoable_step() {
    let mut scene = small("default");
    // A light near the middle of the scene, in view of the narrow scene-view column.
    scene.lights[0].position = Vec3::new(0.3, 2.5, 0.5);
    let mut h = harness(scene.clone());
    settle(&mut h);
    let rect = h.get_by_label("scene view").rect();
    let view_camera = h.state().scene_view.camera.clone();
    let frame =
        raytree::scene::CameraFrame::new(&view_camera, rect.width() as u32, rect.height() as u32);
    let at = |p: Vec3| {
        frame
            .project(p)
            .map(|(x, y)| rect.min + egui::vec2(x, y))
            .expect("the light is in view")
    };
    let light = scene.lights[0].position;
    let from = at(light);
    drag(&mut h, from, egui::vec2(60.0, 0.0));
    let moved = h.state().scene().lights[0].position;
    assert!(moved != light, "the light did not move");
    // It followed the pointer: about 60 points to the right on screen.
    let now = at(moved);
    assert!(
        (now.x - from.x - 60.0).abs() < 8.0 && (now.y - from.y).abs() < 8.0,
        "the light went from {from:?} to {now:?}"
    );
    assert_eq!(h.state().scene_view.camera, view_camera, "the view orbited");
    assert_eq!(h.state().working.history.undo_steps(), 1);
    keys(&mut h, egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    assert!(*h.state().scene() == scene);
}

#[test]
fn shift_dragging_a_sphere_in_the_scene_view_moves_it_as_one_undoable_step() {
    let scene = small("default");
    let mut h = harness(scene.clone());
    settle(&mut h);
    let rect = h.get_by_label("scene view").rect();
    let view_camera = h.state().scene_view.camera.clone();
    let frame =
        raytree::scene::CameraFrame::new(&view_camera, rect.width() as u32, rect.height() as u32);
    // The sphere nearest the view's camera whose centre is in view.
    let (i, from) = scene
        .spheres
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            frame
                .project(s.center)
                .map(|(x, y)| (i, rect.min + egui::vec2(x, y)))
        })
        .filter(|(_, p)| rect.shrink(40.0).contains(*p))
        .min_by(|a, b| {
            let d = |i: usize| (scene.spheres[i].center - view_camera.position).length();
            d(a.0).total_cmp(&d(b.0))
        })
        .expect("a sphere in the scene view");
    let found = raytree::app::gesture::sphere_at(&scene.spheres, &view_camera, rect, from);
    assert_eq!(found, Some(i), "the ray through its centre meets it first");
    drag_with(&mut h, from, egui::vec2(0.0, -40.0), egui::Modifiers::SHIFT);
    // Moving a sphere rebuilds the accelerator off the UI thread: the scene shown changes
    // when the new one is built.
    settle(&mut h);
    let moved = h.state().scene().spheres[i].center;
    assert!(moved != scene.spheres[i].center, "the sphere did not move");
    let (_, y) = frame.project(moved).expect("in view");
    assert!(
        (rect.min.y + y - (from.y - 40.0)).abs() < 8.0,
        "the sphere did not follow the pointer"
    );
    assert_eq!(h.state().scene_view.camera, view_camera, "the view orbited");
    assert_eq!(h.state().working.history.undo_steps(), 1);
    keys(&mut h, egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    assert!(*h.state().scene() == scene);
}

#[test]
fn a_selected_material_opens_once_then_folds_and_the_settings_do_not_slide_sideways() {
    let scene = small("default");
    let i = scene.materials.len() - 1;
    let mut h = harness(scene);
    settle(&mut h);
    let left = |h: &Window| h.get_by_label_contains("Materials (").rect().left();
    let before = left(&h);
    // Each open material shows its reflection coefficient (one field, or three for RGB).
    let opened = |h: &Window| {
        h.query_all_by_role_and_label(Role::SpinButton, "reflect kr")
            .count()
    };
    let opened_before = opened(&h);
    h.state_mut().selection.selected_material = Some(i);
    // The scroll is animated: frames enough for it to end.
    for _ in 0..30 {
        h.step();
    }
    let header = |h: &Window| {
        h.query_by(|n| n.label().is_some_and(|l| l.starts_with("> ")))
            .map(|n| n.rect())
    };
    let shown = header(&h).expect("the selected material's header, marked >");
    let panel = h.get_by_label("« hide").rect();
    assert!(
        shown.top() >= panel.bottom() && shown.top() < 800.0,
        "the selected material scrolled into view: its header at {shown:?}"
    );
    assert!(opened(&h) > opened_before, "the selected material opened");
    assert_eq!(left(&h), before, "the settings slid sideways");
    // Its header folds on a click, and stays folded while it stays selected.
    h.query_by(|n| n.label().is_some_and(|l| l.starts_with("> ")))
        .expect("the header")
        .click();
    for _ in 0..10 {
        h.step();
    }
    assert_eq!(
        opened(&h),
        opened_before,
        "the selected material did not fold"
    );
    assert_eq!(h.state().selection.selected_material, Some(i));
}
