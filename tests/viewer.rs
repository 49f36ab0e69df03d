//! The real viewer driven through egui_kittest on the wgpu software adapter (Mesa lavapipe in
//! CI): edits restart the render, bad scenes keep the old one, exports write stamped PNGs, a
//! click shows the ray tree in the list, the diagram and the scene view, orbiting the scene view
//! re-traces nothing, shift-click adds trees, the depth slider hides deeper rays, and snapshots
//! of the whole window.
//!
//! Update the snapshot after a deliberate change (look at it first):
//! `UPDATE_SNAPSHOTS=1 cargo test --release --test viewer`

#[path = "common/viewer.rs"]
mod viewer;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use eframe::egui;
use egui::accesskit::Role;
use egui_kittest::kittest::NodeT as _;
use egui_kittest::kittest::Queryable;
use raytree::app::messages::{MAX_TOASTS, Message};
use raytree::render::render;
use raytree::scene::Scene;
use raytree::trace::{TraceSettings, Tracer};
use viewer::{Window, harness, mask_status, settle, sized, small, window};

fn batch(scene: &Scene) -> raytree::render::Image {
    let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
    render(&tracer, scene.render.samples, 0, &|_, _| {})
        .expect("render")
        .0
}

#[test]
fn changing_max_depth_restarts_the_render_and_changes_the_image() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let before = h.state().image();
    assert!(
        before == batch(h.state().scene()),
        "viewer and batch render differ"
    );
    let generation = h.state().generation();
    h.get_by_role_and_label(Role::Slider, "max depth")
        .set_value_accesskit(0.0);
    h.step();
    assert!(
        h.state().generation() > generation,
        "the edit did not restart the render"
    );
    settle(&mut h);
    assert_eq!(h.state().scene().render.max_depth, 0);
    let after = h.state().image();
    assert!(after != before, "max depth 0 left the image unchanged");
    assert!(
        after == batch(h.state().scene()),
        "the restarted image is not the new scene's"
    );
}

#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn dropping_a_bad_scene_shows_its_error_and_keeps_the_old_scene() {
    let dir = tempfile::tempdir().expect("temp dir");
    let bad = dir.path().join("broken.toml");
    std::fs::write(&bad, "[[sphere]]\nradius = -2\n").expect("write");
    let mut h = harness(small("quiz"));
    settle(&mut h);
    let triangles = h.state().scene().triangles.len();
    h.input_mut()
        .dropped_files
        .push(Arc::new(Dropped(bad.clone())));
    h.step();
    // Read and parsed in the background: the error comes when that open ends.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    while h.state().files.opening().is_some() || h.state().messages.is_empty() {
        assert!(std::time::Instant::now() < deadline, "the open never ended");
        h.step();
    }
    h.step();
    let message = h
        .state()
        .messages
        .last()
        .map(|m| m.text.clone())
        .unwrap_or_default();
    assert!(
        message.contains("broken.toml:2:") && message.contains("radius"),
        "{message}"
    );
    // The message is on screen as a toast, and the quiz scene is still the one shown.
    assert!(h.state().messages.toasts_shown() >= 1);
    assert_eq!(h.state().scene().triangles.len(), triangles);
    assert!(h.state().scene().spheres.is_empty());
}

/// Ctrl+S, the picture `choice` in the Export window, then `out` in the file dialog.
fn export_via(h: &mut Window, choice: &str, out: &std::path::Path) {
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    // A new window lays itself out in its first frame and takes clicks from the second.
    h.step();
    h.step();
    h.get_by_role_and_label(Role::Button, choice).click();
    h.step();
    h.step();
    h.step();
    // The file name field is the dialog's last text field (the folder's path is the first).
    h.get_all_by_role(Role::TextInput)
        .last()
        .expect("the file name field")
        .set_text_value_accesskit(out.to_str().expect("utf-8 path"));
    h.step();
    h.get_by_role_and_label(Role::Button, "Save").click();
    h.step();
    h.step();
}

/// A PNG as read back: its size, its pixels (RGB or RGBA) and its text chunks.
type Png = ((u32, u32), Vec<u8>, Vec<(String, String)>);

fn read_png(path: &std::path::Path) -> Png {
    let file = std::fs::File::open(path).expect("the PNG was written");
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("a valid PNG");
    let text = reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect();
    let size = (reader.info().width, reader.info().height);
    let mut buf = vec![0; reader.output_buffer_size().expect("a size")];
    let frame = reader.next_frame(&mut buf).expect("pixels");
    buf.truncate(frame.buffer_size());
    (size, buf, text)
}

#[test]
fn ctrl_s_exports_a_stamped_png() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("shot.png");
    let mut h = harness(small("glass"));
    settle(&mut h);
    export_via(&mut h, "Render as shown", &out);
    let (size, pixels, text) = read_png(&out);
    assert_eq!(size, (160, 120));
    assert!(
        text.iter()
            .any(|(k, v)| k == "raytree.samples" && v == "1/1"),
        "{text:?}"
    );
    assert!(
        text.iter()
            .any(|(k, v)| k == "raytree.display" && v.contains("exposure")),
        "{text:?}"
    );
    // As shown: the display's colours, exposure included.
    h.state_mut().workspace.prefs.exposure = 2.0;
    h.step();
    let brighter = dir.path().join("brighter.png");
    export_via(&mut h, "Render as shown", &brighter);
    let (_, bright, _) = read_png(&brighter);
    let sum = |p: &[u8]| p.iter().map(|&v| u64::from(v)).sum::<u64>();
    assert!(
        sum(&bright) > sum(&pixels) * 11 / 10,
        "exposure 2 brightens the picture as shown"
    );
    let display = h.state().render.display_shown();
    assert_eq!(bright, display, "the file holds what the display shows");
}

#[test]
fn ctrl_s_offers_the_render_with_rays_and_the_scene_view() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut h = harness(small("glass"));
    settle(&mut h);
    // Without a tree, only the clean render can be chosen.
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    h.step();
    h.step();
    let rays_button = h.get_by_role_and_label(Role::Button, "Render with rays (PNG)");
    assert!(rays_button.accesskit_node().is_disabled());
    h.key_press(egui::Key::Escape);
    h.step();
    let at = pixel_pos(&h, GLASS.0, GLASS.1);
    click(&mut h, at, egui::Modifiers::NONE);
    assert!(h.state().selection.tree.is_some());
    let (plain, rays, view) = (
        dir.path().join("plain.png"),
        dir.path().join("rays.png"),
        dir.path().join("view.png"),
    );
    export_via(&mut h, "Render as shown", &plain);
    export_via(&mut h, "Render with rays (PNG)", &rays);
    export_via(&mut h, "Scene view (PNG)", &view);
    let (plain_size, plain_px, _) = read_png(&plain);
    let (rays_size, rays_px, rays_text) = read_png(&rays);
    let (view_size, view_px, _) = read_png(&view);
    // Both at the scene's size, stamped like the render, and the rays change pixels.
    assert_eq!(
        (plain_size, rays_size, view_size),
        ((160, 120), (160, 120), (160, 120))
    );
    assert!(
        rays_text.iter().any(|(k, _)| k == "raytree.settings"),
        "{rays_text:?}"
    );
    let rgb = |px: &[u8], stride: usize| -> Vec<[u8; 3]> {
        px.chunks(stride).map(|c| [c[0], c[1], c[2]]).collect()
    };
    let (a, b) = (rgb(&plain_px, 3), rgb(&rays_px, 4));
    let changed = a.iter().zip(&b).filter(|(p, q)| p != q).count();
    assert!(
        changed > 100 && changed < a.len() / 2,
        "{changed} pixels changed by the rays"
    );
    assert_ne!(rgb(&view_px, 4), b, "the scene view is another picture");
}

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

fn click(h: &mut Window, pos: egui::Pos2, modifiers: egui::Modifiers) {
    drag(h, pos, egui::Vec2::ZERO, modifiers);
}

/// A pixel of the glass sphere in the 160×120 default scene.
const GLASS: (u32, u32) = (60, 69);

#[test]
fn the_glass_pixel_is_on_the_glass_sphere() {
    let scene = small("default");
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let tree = raytree::ray_tree::pixel_tree(&tracer, GLASS.0, GLASS.1).expect("inside");
    let hit = tree.root.hit.as_ref().expect("a hit");
    assert!(hit.material.contains("glass"), "{}", hit.material);
}

/// Line shapes painted inside `rect` in the last frame.
fn lines_in(h: &Window, rect: egui::Rect) -> usize {
    h.output()
        .shapes
        .iter()
        .filter(|c| match &c.shape {
            egui::Shape::LineSegment { points, .. } => points.iter().all(|p| rect.contains(*p)),
            _ => false,
        })
        .count()
}

#[test]
fn clicking_a_pixel_shows_its_ray_tree_in_every_view() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let scene_view = h.get_by_label("scene view").rect();
    let lines_before = lines_in(&h, scene_view);
    let at = pixel_pos(&h, GLASS.0, GLASS.1);
    click(&mut h, at, egui::Modifiers::NONE);
    let tree = h
        .state()
        .selection
        .tree
        .clone()
        .expect("a tree after the click");
    assert_eq!(tree.pixel, [GLASS.0, GLASS.1]);
    assert!(tree.nodes > 3, "the glass sphere's tree has children");
    let [x, y] = tree.pixel;
    // The list is the diagram's neighbouring tab.
    h.get_by_role_and_label(Role::Button, "Tree list").click();
    h.step();
    h.step();
    h.get_by_label_contains(&format!("Ray tree of ({x}, {y})"));
    assert!(h.query_all_by_label_contains("primary d0").count() >= 1);
    h.get_by_role_and_label(Role::Button, "Diagram").click();
    h.step();
    h.step();
    // The diagram shows the same tree, its root labelled with what the primary ray met.
    h.get_by_label(&format!("ray tree diagram of ({x}, {y})"));
    let root = tree.root.hit.as_ref().expect("the sphere").object.clone();
    h.get_by_label(&format!("tree node primary: {root}"));
    // The scene view draws the tree's rays: more lines in its rectangle than the camera alone.
    assert!(h.state().scene_view.drawn_count() >= tree.nodes);
    let lines_after = lines_in(&h, scene_view);
    assert!(
        lines_after > lines_before,
        "scene view lines: {lines_before} before the click, {lines_after} after"
    );
    // Selecting a child in the diagram shows its numbers in the detail pane.
    let child = tree.root.children.first().expect("a child");
    let letter = if child.kind == raytree::trace::RayKind::Reflected {
        "R"
    } else {
        "T"
    };
    h.query_all_by_label_contains(&format!("tree node {letter}:"))
        .next()
        .expect("a child node")
        .click();
    h.step();
    h.step();
    assert_eq!(
        h.state().selection.tree_state.selected.as_deref(),
        Some(&[0usize][..])
    );
    settle(&mut h);
    mask_status(&mut h);
    h.snapshot("viewer_tree");
}

/// Drags from `from` by `by` with the primary button, `modifiers` held (by zero: a click).
fn drag(h: &mut Window, from: egui::Pos2, by: egui::Vec2, modifiers: egui::Modifiers) {
    h.event(egui::Event::ModifiersChanged(modifiers));
    h.hover_at(from);
    for (pressed, pos) in [(true, from), (false, from + by)] {
        if !pressed && by != egui::Vec2::ZERO {
            for i in 1..=5 {
                h.hover_at(from + by * (i as f32 / 5.0));
                h.step();
            }
        }
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

/// The scene view's picture follows the render camera where it shows it: the walls of a room
/// cut away for where the render camera stands (out of the room none, back in the same ones
/// again), and a headlight's light. A move with neither leaves the picture alone.
#[test]
fn the_scene_view_follows_the_render_camera_where_it_shows_it() {
    use raytree::app::Command;
    fn move_camera(h: &mut Window, position: glam::Vec3) {
        h.state_mut().working.scene.camera.position = position;
        h.state_mut().command(Command::MoveCamera);
        h.step();
        settle(h);
    }
    let mut h = harness(small("box"));
    settle(&mut h);
    let cut = h.state().scene_view.walls_cut();
    assert!(cut > 0, "the box's near walls are not cut from outside it");
    let inside = h.state().scene().camera.position;
    let before = h.state().scene_view.generation();
    move_camera(&mut h, glam::Vec3::new(0.0, 1.8, 40.0));
    assert_eq!(
        h.state().scene_view.walls_cut(),
        0,
        "walls stay cut with the render camera out of the room"
    );
    assert!(
        h.state().scene_view.generation() > before,
        "the view did not restart"
    );
    move_camera(&mut h, inside);
    assert_eq!(h.state().scene_view.walls_cut(), cut);

    for headlight in [false, true] {
        let mut scene = small("default");
        scene.lights[0].follow_camera = headlight;
        scene.place_lights();
        let mut h = harness(scene);
        settle(&mut h);
        let before = h.state().scene_view.generation();
        let mut at = h.state().scene().camera.position;
        at.x += 0.5;
        move_camera(&mut h, at);
        assert_eq!(
            h.state().scene_view.generation() > before,
            headlight,
            "with a headlight {headlight}, the scene view's restart"
        );
    }
}

#[test]
fn orbiting_the_scene_view_leaves_the_tree_and_the_render_unchanged() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let at = pixel_pos(&h, GLASS.0, GLASS.1);
    click(&mut h, at, egui::Modifiers::NONE);
    let tree = h.state().selection.tree.clone().expect("a tree");
    let render_camera = h.state().scene().camera.clone();
    let generation = h.state().generation();
    let camera = h.state().scene_view.camera.clone();
    let view = h.get_by_label("scene view").rect();
    drag(
        &mut h,
        view.center(),
        egui::vec2(120.0, 30.0),
        egui::Modifiers::NONE,
    );
    assert_ne!(
        h.state().scene_view.camera,
        camera,
        "the drag did not orbit"
    );
    assert_eq!(
        h.state().selection.tree.as_ref(),
        Some(&tree),
        "the tree was re-traced"
    );
    assert_eq!(h.state().scene().camera, render_camera);
    assert_eq!(h.state().generation(), generation, "the render restarted");
}

#[test]
fn shift_click_adds_a_tree_and_a_plain_click_starts_over() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let a = pixel_pos(&h, GLASS.0, GLASS.1);
    click(&mut h, a, egui::Modifiers::NONE);
    let b = pixel_pos(&h, 99, 53);
    click(&mut h, b, egui::Modifiers::SHIFT);
    let c = pixel_pos(&h, 20, 100);
    click(&mut h, c, egui::Modifiers::SHIFT);
    // Each shift-clicked tree becomes the one shown; the earlier ones stay, in picking order.
    let pixels: Vec<[u32; 2]> = h.state().selection.trees().map(|t| t.pixel).collect();
    assert_eq!(
        pixels[0],
        [20, 100],
        "the last shift-clicked tree is the current one"
    );
    let picked: Vec<[u32; 2]> = h
        .state()
        .selection
        .picker
        .entries
        .iter()
        .map(|e| e.pixel)
        .collect();
    assert_eq!(picked, vec![[60, 69], [99, 53], [20, 100]]);
    // A plain click away from the drawn rays (a click on one selects it instead).
    let d = pixel_pos(&h, 150, 5);
    click(&mut h, d, egui::Modifiers::NONE);
    assert_eq!(h.state().selection.trees().count(), 1);
}

#[test]
fn the_depth_slider_hides_deeper_segments() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let at = pixel_pos(&h, GLASS.0, GLASS.1);
    click(&mut h, at, egui::Modifiers::NONE);
    let all = h.state().scene_view.drawn_count();
    h.get_by_role_and_label(Role::Slider, "depth")
        .set_value_accesskit(0.0);
    h.step();
    h.step();
    assert_eq!(h.state().selection.tree_state.reveal, Some(0));
    let first = h.state().scene_view.drawn_count();
    assert!(
        first > 0 && first < all,
        "generation 0 shows {first} pieces, the whole tree {all}"
    );
}

/// A snapshot of the window at `size` as a new user sees it (the render at the pane's size,
/// 4 samples for speed).
fn window_snapshot(size: [f32; 2], name: &str) {
    let mut h = window(small("default"), size);
    h.state_mut().set_view(4, true);
    follow_pane(&mut h);
    settle(&mut h);
    // The toast of the hidden settings (at 1024) fades on a timer: take it off.
    h.state_mut().messages.clear_toasts();
    h.step();
    // Timings and rates differ from run to run: hide the status line that shows them.
    mask_status(&mut h);
    h.snapshot(name);
}

#[test]
fn window_snapshot_1024x640() {
    window_snapshot([1024.0, 640.0], "viewer_1024x640");
}

#[test]
fn window_snapshot_1600x1000() {
    window_snapshot([1600.0, 1000.0], "viewer_1600x1000");
}

#[test]
fn speed_vs_accuracy_window_runs_the_sweep_and_a_point_applies() {
    let mut h = harness(small("quiz"));
    settle(&mut h);
    h.get_by_role_and_label(Role::Button, "Speed vs accuracy")
        .click();
    h.run_steps(3);
    h.get_by_label_contains("quick").click();
    h.run_steps(2);
    h.get_by_role_and_label(Role::Button, "Run the sweep")
        .click();
    h.run_steps(2);
    let deadline = Instant::now() + Duration::from_secs(300);
    while h.state().workspace.sweep.report.is_none() {
        assert!(Instant::now() < deadline, "the sweep did not finish");
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    let report = h.state().workspace.sweep.report.clone().expect("a report");
    assert!(report.points.iter().any(|p| p.pareto), "no Pareto front");
    // The plot's click handler picks the nearest point; here, the 4-sample point.
    let p = report
        .points
        .iter()
        .find(|p| p.knob == raytree::experiments::sweep::Knob::Samples && p.settings.samples == 4)
        .expect("a 4-sample point");
    let at = [
        p.secs.max(1e-6).log10(),
        p.error.mean_flip.max(1e-6).log10(),
    ];
    let chosen = raytree::app::sweep::nearest_point(&report, at, [1.0, 1.0]).expect("near");
    assert_eq!(chosen.samples, 4);
    // Applied, it changes what the viewer shows: its own target becomes 4 samples.
    h.state_mut().apply_point(&chosen);
    h.step();
    assert_eq!(h.state().viewer_target(), 4);
    settle(&mut h);
    assert_eq!(h.state().samples_done(), 4);
    assert!(
        raytree::app::sweep::nearest_point(&report, [at[0] + 0.5, at[1] + 0.5], [1.0, 1.0])
            .is_none()
    );
}

#[test]
fn ctrl_drag_traces_a_sparse_grid_of_the_rectangle() {
    let mut h = harness(small("default"));
    settle(&mut h);
    // The densest grid (the picker's default is 4 × 4), which fills the trees.
    h.state_mut().selection.picker.grid.per_side = 8;
    let (from, to) = (pixel_pos(&h, 10, 10), pixel_pos(&h, 150, 110));
    drag(&mut h, from, to - from, egui::Modifiers::COMMAND);
    let n = h.state().selection.trees().count();
    assert_eq!(n, 64, "an 8×8 grid");
    assert!(
        h.state()
            .selection
            .trees()
            .all(|t| (10..=150).contains(&t.pixel[0]) && (10..=110).contains(&t.pixel[1])),
        "every pixel inside the rectangle"
    );
    assert_eq!(
        h.state().scene().camera,
        small("default").camera,
        "the drag orbited"
    );
    // Full: one more pixel is refused with a message.
    let at = pixel_pos(&h, 1, 1);
    click(&mut h, at, egui::Modifiers::SHIFT);
    assert_eq!(h.state().selection.trees().count(), 64);
    assert!(
        h.state()
            .messages
            .last()
            .is_some_and(|m| m.text.contains("at most 64"))
    );
}

#[test]
fn play_reveals_the_tree_generation_by_generation() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let at = pixel_pos(&h, GLASS.0, GLASS.1);
    click(&mut h, at, egui::Modifiers::NONE);
    h.state_mut().scene_view.speed = 8.0;
    h.get_by_role_and_label(Role::Button, "Play").click();
    h.step();
    let mut seen = vec![h.state().selection.tree_state.reveal];
    let deadline = Instant::now() + Duration::from_secs(30);
    while h.state().scene_view.playing.is_some() {
        assert!(Instant::now() < deadline, "the playback did not end");
        h.step();
        std::thread::sleep(Duration::from_millis(20));
        if seen.last() != Some(&h.state().selection.tree_state.reveal) {
            seen.push(h.state().selection.tree_state.reveal);
        }
    }
    let deepest = raytree::app::scene_pane::deepest(h.state().selection.trees());
    let mut expected: Vec<Option<u32>> = (0..=deepest).map(Some).collect();
    expected.push(None);
    assert_eq!(
        seen, expected,
        "one generation at a time, then the whole tree"
    );
}

#[test]
fn opening_another_scene_clears_the_pinned_and_extra_trees() {
    let mut h = harness(small("default"));
    settle(&mut h);
    let (a, b) = (pixel_pos(&h, GLASS.0, GLASS.1), pixel_pos(&h, 99, 53));
    click(&mut h, a, egui::Modifiers::NONE);
    click(&mut h, b, egui::Modifiers::SHIFT);
    h.get_by_role_and_label(Role::Button, "Tree list").click();
    h.step();
    h.step();
    h.get_by_role_and_label(Role::Button, "Pin for comparison")
        .click();
    h.step();
    h.step();
    assert!(h.state().selection.tree_state.pinned.is_some());
    assert_eq!(h.state().selection.trees().count(), 2);
    // The list pane is too narrow for the two tables side by side: one above the other, each
    // as wide as the pane.
    let mut headers: Vec<egui::Rect> = h
        .query_all_by_value("ray")
        .map(|n| n.rect())
        .filter(|r| r.is_finite())
        .collect();
    headers.dedup();
    assert!(
        headers.len() == 2
            && (headers[0].min.x - headers[1].min.x).abs() < 1.0
            && (headers[0].min.y - headers[1].min.y).abs() > 20.0,
        "the pinned and current tables' headers: {headers:?}"
    );
    h.state_mut()
        .command(raytree::app::Command::OpenBuiltin("quiz".into()));
    h.step();
    h.step();
    assert!(h.state().selection.tree_state.pinned.is_none());
    assert_eq!(h.state().selection.trees().count(), 0);
}

/// Steps until the render follows the pane (the pane's pixels are the render's), or panics.
fn follow_pane(h: &mut Window) {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        h.step();
        let image = h.get_by_label("render viewport").rect();
        let (w, hh) = h.state().render_size();
        // The pane's pixels are the render's, and the image fills it 1:1.
        let app = h.state();
        if app.render.pane_seen(&app.workspace.prefs) == Some((w, hh))
            && (image.width() - w as f32).abs() <= 1.0
            && (image.height() - hh as f32).abs() <= 1.0
        {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "the render ({w}x{hh}) never followed the pane ({image:?})"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// The render image's area as a fraction of the window's.
fn image_share(h: &Window) -> f32 {
    let image = h.get_by_label("render viewport").rect();
    let window = h.ctx.content_rect();
    image.area() / window.area()
}

/// Clicks the render image a third of the way across and a little below the middle, lets the
/// tree open, and gives the point clicked.
fn click_a_third_across(h: &mut Window) -> egui::Pos2 {
    let image = h.get_by_label("render viewport").rect();
    let at = image.lerp_inside(egui::vec2(0.35, 0.6));
    click(h, at, egui::Modifiers::NONE);
    h.run_steps(3);
    at
}

/// Once a pixel is clicked, the scene view shares its column with the tree's pane: its toolbar
/// stays two rows and the 3D view below keeps a third of the window's height, at
/// both window sizes (at 1024×640 the filters wrapped into five rows and left it a strip). In
/// a narrow pane the filters are in the "Show" menu, which stays open while they are clicked.
#[test]
fn the_scene_view_keeps_a_third_of_the_height_beside_a_tree() {
    for size in [[1024.0, 640.0], [1600.0, 1000.0]] {
        let mut h = window(small("default"), size);
        follow_pane(&mut h);
        click_a_third_across(&mut h);
        assert!(
            h.state().selection.tree.is_some(),
            "{size:?}: no tree after the click"
        );
        let view = h.get_by_label("scene view").rect();
        let play = h.get_by_role_and_label(Role::Button, "Play").rect();
        assert!(
            view.height() >= size[1] / 3.0,
            "{size:?}: the 3D view is {:.0} points tall",
            view.height()
        );
        // Play's row and one more above the view.
        assert!(
            view.top() - play.top() <= 2.0 * (play.height() + 8.0),
            "{size:?}: the toolbar takes {:.0} points",
            view.top() - play.top()
        );
        if view.width() < raytree::app::scene_pane::FILTERS_INLINE_WIDTH {
            assert!(h.state().scene_view.filter.shadow);
            h.get_by_role_and_label(Role::Button, "Show").click();
            h.run_steps(2);
            h.get_by_label("shadow").click();
            h.run_steps(2);
            assert!(
                !h.state().scene_view.filter.shadow,
                "{size:?}: the Show menu's shadow box did not hide the shadow rays"
            );
            // The menu stays open: a second box in the same visit.
            h.get_by_label("reflected").click();
            h.run_steps(2);
            assert!(
                !h.state().scene_view.filter.reflected,
                "{size:?}: the Show menu closed after one click"
            );
        }
    }
}

#[test]
fn the_render_holds_half_the_window_and_its_place_when_a_pixel_is_clicked() {
    for size in [[1024.0, 640.0], [1600.0, 1000.0]] {
        let mut h = window(small("default"), size);
        follow_pane(&mut h);
        let before = h.get_by_label("render viewport").rect();
        let share = image_share(&h);
        assert!(
            share >= 0.5,
            "{size:?}: the render has {share:.2} of the window"
        );
        // Click a third of the way across: the tree is of the pixel under the pointer.
        let at = click_a_third_across(&mut h);
        let tree = h
            .state()
            .selection
            .tree
            .clone()
            .expect("a tree after the click");
        let after = h.get_by_label("render viewport").rect();
        assert_eq!(before, after, "{size:?}: the render moved or changed size");
        assert!(image_share(&h) >= 0.5);
        let [x, y] = tree.pixel;
        let centre = pixel_pos(&h, x, y);
        assert!(
            (centre - at).length() <= 1.0,
            "{size:?}: pixel ({x}, {y}) is at {centre:?}, the click at {at:?}"
        );
        // The diagram opened in its own pane, beside the render.
        let diagram = h
            .get_by_label(&format!("ray tree diagram of ({x}, {y})"))
            .rect();
        assert!(
            !diagram.intersects(after),
            "{size:?}: the diagram covers the render"
        );
    }
}

#[test]
fn toasts_do_not_move_the_layout() {
    let mut h = window(small("default"), [1024.0, 640.0]);
    follow_pane(&mut h);
    let before = h.get_by_label("render viewport").rect();
    let menu = h.get_by_label("Scene").rect();
    let shown = h.state().messages.toasts_shown();
    let logged = h.state().messages.len();
    for i in 0..4 {
        let text = format!("message {i}");
        let message = if i % 2 == 0 {
            Message::error(text)
        } else {
            Message::notice(text)
        };
        h.state_mut().messages.push(message);
    }
    h.run_steps(3);
    // At most three at once, the newest; all four are in the log.
    assert_eq!(
        h.state().messages.toasts_shown(),
        (shown + 4).min(MAX_TOASTS)
    );
    let newest = h.get_by_label_contains("message 3").rect();
    assert!(h.query_by_label_contains("message 0").is_none());
    // In the render pane's corner, over the image: not over the scene view or the status bar.
    let pane = h.get_by_label("render viewport").rect().expand(12.0);
    assert!(
        pane.contains_rect(newest) && newest.center().x > pane.center().x,
        "the toast {newest:?} is not in the render pane's bottom-right corner {pane:?}"
    );
    assert_eq!(h.state().messages.len(), logged + 4);
    assert_eq!(h.get_by_label("render viewport").rect(), before);
    assert_eq!(h.get_by_label("Scene").rect(), menu);
}

#[test]
fn the_viewer_refines_to_its_sample_target_then_idles() {
    let mut h = harness(small("glass"));
    h.state_mut().set_view(8, false);
    h.step();
    settle(&mut h);
    // The viewer's target, not the scene's batch samples (1), which stay for export.
    assert_eq!(h.state().samples_done(), 8);
    assert_eq!(h.state().scene().render.samples, 1);
    let rays = h.state().rays_traced();
    let generation = h.state().generation();
    for _ in 0..10 {
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(
        h.state().rays_traced(),
        rays,
        "rays traced after the target"
    );
    assert_eq!(h.state().generation(), generation);
    // Nothing asks for another frame: the window idles.
    h.run_steps(2);
    assert!(
        !h.ctx.has_requested_repaint(),
        "a finished render keeps repainting"
    );
    // The converged film is the batch render at 8 samples.
    let mut scene = h.state().scene().clone();
    scene.render.samples = 8;
    assert!(h.state().image() == batch(&scene));
}

#[test]
fn render_at_pane_size_follows_the_window_and_export_keeps_the_scene_size() {
    let mut h = window(small("glass"), [1280.0, 800.0]);
    h.state_mut().set_view(1, true);
    follow_pane(&mut h);
    let first = h.state().render_size();
    assert!(first.0 > 300 && first.1 > 300, "{first:?}");
    h.set_size(egui::vec2(1000.0, 700.0));
    // The size settles after the debounce; until then the old render is shown scaled.
    h.step();
    assert_eq!(h.state().render_size(), first);
    follow_pane(&mut h);
    let second = h.state().render_size();
    assert_ne!(second, first);
    // The scene's own size is kept for export and saving.
    assert_eq!(
        (
            h.state().working.scene.render.width,
            h.state().working.scene.render.height
        ),
        (160, 120)
    );
    settle(&mut h);
    let dir = tempfile::tempdir().expect("temp dir");
    // As shown: the pane's size.
    let shown = dir.path().join("shown.png");
    export_via(&mut h, "Render as shown", &shown);
    assert_eq!(read_png(&shown).0, second);
    // At the scene's size: rendered again in the background.
    let out = dir.path().join("shot.png");
    export_via(&mut h, "Render at the scene's size", &out);
    let deadline = Instant::now() + Duration::from_secs(60);
    while h.state().render.exporting() {
        assert!(Instant::now() < deadline, "the export did not finish");
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    let (size, _, text) = read_png(&out);
    assert_eq!(size, (160, 120));
    assert!(
        text.iter()
            .any(|(k, v)| k == "raytree.samples" && v == "1/1"),
        "{text:?}"
    );
}

#[test]
fn ctrl_b_hides_the_settings_and_the_render_takes_the_room() {
    let mut h = window(small("default"), [1600.0, 1000.0]);
    follow_pane(&mut h);
    assert!(
        h.state().workspace.prefs.settings_panel,
        "shown in a 1600 px window"
    );
    let before = h.get_by_label("render viewport").rect();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::B);
    h.step();
    assert!(!h.state().workspace.prefs.settings_panel);
    follow_pane(&mut h);
    let after = h.get_by_label("render viewport").rect();
    assert!(
        after.width() > before.width() + 100.0,
        "{before:?} -> {after:?}"
    );
    // The strip left in its place brings the settings back.
    h.get_by_role_and_label(Role::Button, "»").click();
    h.step();
    assert!(h.state().workspace.prefs.settings_panel);
}

/// An export at the scene's size renders in the background, with its progress in the status
/// bar; Cancel stops it, no file is written and a message says so.
#[test]
fn an_export_at_the_scenes_size_can_be_cancelled() {
    let mut h = window(sized("default", 320, 240, Some(256)), [1024.0, 640.0]);
    h.state_mut().set_view(1, true);
    follow_pane(&mut h);
    settle(&mut h);
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("full.png");
    h.state_mut()
        .command(raytree::app::Command::ExportFull(out.clone()));
    h.step();
    assert!(h.state().render.exporting());
    // Applied at the end of that frame: the status bar shows it from the next one.
    h.step();
    h.get_by_label_contains("exporting");
    // The status bar grew a row: let its layout settle before clicking its Cancel.
    h.step();
    h.get_by_role_and_label(Role::Button, "Cancel").click();
    h.step();
    h.step();
    let deadline = Instant::now() + Duration::from_secs(60);
    while h.state().render.exporting() {
        assert!(
            Instant::now() < deadline,
            "the cancelled export did not stop"
        );
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    // Another event's message may follow it (the render view finishing, say): any of them.
    let texts: Vec<String> = h
        .state()
        .messages
        .log()
        .iter()
        .map(|m| m.text.clone())
        .collect();
    assert!(
        texts.iter().any(|t| t.starts_with("cancelled the export")),
        "no message says the export was cancelled: {texts:?}"
    );
    assert!(!out.exists(), "no file for a cancelled export");
}
