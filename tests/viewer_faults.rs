//! Faults in the viewer (docs/reliability.md): bursts of edits never deadlock and never leave a
//! stale tile (after the burst, the converged film equals the batch render of the final
//! scene); a new scene opened mid-render replaces the old one cleanly, a bad one leaves it
//! rendering; the window survives being 0×0. The logic runs headless
//! (`ViewerApp::headless`); the window cases drive the real app through the harness of
//! `tests/common/viewer.rs`.

#[path = "common/viewer.rs"]
mod viewer;

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use eframe::egui;
use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use glam::Vec3;
use raytree::app::{Command, ViewerApp};
use raytree::render::{Image, render};
use raytree::scene::Scene;
use raytree::scene::builtin::scene_text;
use raytree::trace::{TraceSettings, Tracer};
use viewer::{at_scene_size, frames_until, headless, settle_headless, settle_render, sized};

fn batch(scene: &Scene, trace: TraceSettings) -> Image {
    let tracer = Tracer::new(Arc::new(scene.clone()), trace);
    render(&tracer, scene.render.samples, 0, &|_, _| {})
        .expect("render")
        .0
}

fn assert_converged(app: &ViewerApp) {
    let image = app.image();
    let scene = app.scene();
    assert_eq!(
        (image.width, image.height),
        (scene.render.width, scene.render.height)
    );
    // The film holds the viewer's target of samples.
    let mut scene = scene.clone();
    scene.render.samples = app.viewer_target();
    assert!(
        image == batch(&scene, app.working.settings.trace),
        "the converged film differs from the batch render of the final scene: a stale tile"
    );
}

/// Edits as fast as they come, of every kind that restarts the render: camera, depth, light
/// colour, material, image size (so stale tiles of another size are in flight), accelerator
/// rebuilds. Every edit starts its own generation and none waits for its render; then the film
/// converges to the final scene exactly.
#[test]
fn bursts_of_edits_never_deadlock_or_leave_stale_tiles() {
    let mut app = headless(sized("default", 48, 36, Some(4)), "burst");
    let edits = 400;
    let first = app.generation();
    for i in 0..edits {
        let e = &mut app.working.scene;
        e.camera.position.x += 0.002;
        e.render.max_depth = i % 7;
        e.render.width = 40 + i % 17;
        e.render.height = 30 + i % 11;
        if let Some(light) = e.lights.first_mut() {
            light.color = Vec3::splat(0.5 + (i % 5) as f32 * 0.1);
        }
        if let Some(m) = e.materials.first_mut() {
            m.reflectivity = Vec3::splat((i % 3) as f32 * 0.2);
        }
        app.command(if i % 25 == 0 {
            Command::Rebuild
        } else {
            Command::Restart
        });
        app.apply();
        // Each edit starts exactly one generation and returns before any pass of it is
        // taken: the render runs on the workers, after the edit, never inside it.
        assert_eq!(
            app.generation(),
            first + u64::from(i) + 1,
            "edit {i} started no generation of its own"
        );
        assert!(
            app.samples_done() == 0 && !app.is_finished(),
            "edit {i} returned with its render done"
        );
        app.poll_session();
    }
    settle_headless(&mut app);
    assert_eq!(app.scene().render.width, 40 + (edits - 1) % 17);
    assert_converged(&app);
    assert!(
        app.messages.log().iter().all(|m| !m.is_error()),
        "{:?}",
        app.messages.log()
    );
}

/// Opening another scene while a render runs: the new scene (another size) replaces the old,
/// whose tiles still in flight are dropped; a bad file instead leaves the old scene rendering
/// to the end.
#[test]
fn opening_a_scene_mid_render() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut app = headless(sized("default", 160, 120, Some(8)), "default");
    app.poll_session();

    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[render]\nwidth = 0\n").expect("write");
    app.command(Command::OpenFile(bad.clone()));
    app.apply();
    // Read and parsed in the background: the error comes when the open ends.
    settle_headless(&mut app);
    assert_eq!(app.files.opening(), None);
    let last = app.messages.last().cloned().expect("a message");
    let (error, message) = (last.is_error(), last.text);
    assert!(error, "{message}");
    assert!(
        message.starts_with(&format!("{}:2:9: render field `width`", bad.display())),
        "{message}"
    );
    assert_eq!(app.scene().render.width, 160, "the old scene stays");
    settle_headless(&mut app);
    assert_converged(&app);

    // Restart a long render, then open a scene of another size in the middle of it.
    app.working.scene.camera.position.y += 0.1;
    app.command(Command::Restart);
    app.apply();
    app.poll_session();
    let text = scene_text("glass")
        .expect("glass")
        .replace("width = 640", "width = 50")
        .replace("height = 480", "height = 30")
        .replace("../models/", "");
    let good = dir.path().join("glass.toml");
    std::fs::write(&good, text).expect("write");
    for model in ["checker_floor.obj", "checker_floor.mtl", "prism.obj"] {
        std::fs::copy(
            Path::new("assets/models").join(model),
            dir.path().join(model),
        )
        .expect("copy model");
    }
    app.command(Command::OpenFile(good.clone()));
    app.apply();
    // The new scene's accelerator is built off the UI thread; it replaces the old one when built.
    settle_headless(&mut app);
    assert_eq!(app.scene().source.as_deref(), Some(good.as_path()));
    assert_eq!(
        (app.scene().render.width, app.scene().render.height),
        (50, 30)
    );
    assert_converged(&app);
}

/// A window of no area, or of one pixel, and shrinking to nothing mid-render: frames still run,
/// the render still finishes, and growing the window back shows it.
#[test]
fn zero_and_tiny_windows_survive() {
    for size in [
        egui::vec2(0.0, 0.0),
        egui::vec2(1.0, 1.0),
        egui::vec2(3.0, 2.0),
    ] {
        let mut h = at_scene_size(sized("quiz", 40, 30, Some(2)), size);
        for _ in 0..5 {
            h.step();
        }
        settle_render(&mut h, &format!("no progress in a {size:?} window"));
    }
    let mut h = at_scene_size(sized("quiz", 40, 30, Some(2)), egui::vec2(800.0, 500.0));
    h.step();
    h.set_size(egui::vec2(0.0, 0.0));
    for _ in 0..5 {
        h.step();
    }
    h.set_size(egui::vec2(800.0, 500.0));
    h.step();
    h.step();
    h.get_by_label("render viewport");
}

/// Edits through the real window as fast as frames go: the max-depth slider moved every frame.
#[test]
fn slider_bursts_through_the_window() {
    let mut h = at_scene_size(sized("default", 48, 36, Some(2)), egui::vec2(1000.0, 700.0));
    h.step();
    let start = Instant::now();
    let edits = 120;
    for i in 0..edits {
        h.get_by_role_and_label(Role::Slider, "max depth")
            .set_value_accesskit(f64::from(i % 9));
        h.step();
    }
    eprintln!(
        "{edits} slider edits through the window in {:.2} s",
        start.elapsed().as_secs_f64()
    );
    settle_render(&mut h, "the render did not finish");
    assert_eq!(h.state().scene().render.max_depth, (edits - 1) % 9);
    assert_converged(h.state());
}

/// A scene wider than the largest texture eframe's device allows (8192: egui-wgpu asks for
/// exactly that limit) is shown scaled down to it, with a message.
#[test]
fn a_scene_wider_than_the_largest_texture_is_refused() {
    // The device eframe asks for in the real window (textures up to 8192), not kittest's.
    let mut setup = egui_kittest::wgpu::default_wgpu_setup();
    if let eframe::egui_wgpu::WgpuSetup::CreateNew(new) = &mut setup {
        new.device_descriptor =
            eframe::egui_wgpu::WgpuSetupCreateNew::without_display_handle().device_descriptor;
    }
    let renderer = egui_kittest::wgpu::WgpuTestRenderer::from_setup(setup);
    let scene = sized("quiz", 9000, 4, Some(1));
    let mut h = egui_kittest::Harness::builder()
        .with_size(egui::vec2(800.0, 500.0))
        .renderer(renderer)
        .build_eframe(|cc| ViewerApp::new(cc, scene, "wide".into()).expect("the viewer starts"));
    for _ in 0..5 {
        h.step();
    }
    // Drawing runs the paint callback, which creates the texture.
    h.render().expect("the window draws");
    assert!(
        h.state().messages.log().iter().any(|m| m.is_error()),
        "no message about the size"
    );
}

/// Edits are held to the loader's ±1e15 bound (a BVH build over a primitive near f32::MAX
/// panics in obvhs): the far spheres are refused with a message, the edit is undone, and the
/// scene stays and renders.
#[test]
fn an_edit_far_beyond_the_scene_size_limit_is_refused() {
    let mut app = headless(sized("default", 32, 24, Some(1)), "far");
    let spheres = app.scene().spheres.clone();
    let messages = app.messages.len();
    let mut far = app.working.scene.spheres[0];
    far.center = Vec3::new(3e38, 0.0, 0.0);
    for _ in 0..8 {
        app.working.scene.spheres.push(far);
    }
    app.command(Command::Rebuild);
    app.apply();
    assert_eq!(app.messages.len(), messages + 1, "{:?}", app.messages.log());
    let last = app.messages.last().cloned().expect("a message");
    let (error, message) = (last.is_error(), last.text);
    assert!(error, "{message}");
    assert_eq!(app.scene().spheres, spheres, "the scene stays");
    assert_eq!(app.working.scene.spheres, spheres, "the edit is undone");
    settle_headless(&mut app);
    assert_converged(&app);
}

/// Every file of the hostile corpus that the loader refuses (broken `vn`/`vt` indices,
/// `crease_angle`, `normals`, devices, folders, ...), opened in the viewer: the message is the
/// loader's sentence, and the scene being shown stays exactly as it was.
#[test]
fn opening_each_refused_hostile_file_keeps_the_scene() {
    let mut app = headless(sized("default", 64, 48, Some(1)), "default");
    let before = app.scene().clone();
    let mut paths: Vec<_> = std::fs::read_dir("tests/fixtures/hostile")
        .expect("the hostile corpus")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj" || e == "toml"))
        .collect();
    paths.sort();
    let mut refused = 0;
    for path in paths {
        let Err(e) = raytree::scene::load_scene_file(&path) else {
            continue;
        };
        refused += 1;
        let messages = app.messages.len();
        app.command(Command::OpenFile(path.clone()));
        app.apply();
        // The open runs in the background: its sentence comes when it ends.
        let what = format!("{}: still opening", path.display());
        frames_until(&mut app, &what, |a| a.files.opening().is_none());
        assert_eq!(app.messages.len(), messages + 1, "{:?}", app.messages.log());
        let last = app.messages.last().cloned().expect("a message");
        let (error, message) = (last.is_error(), last.text);
        assert!(error, "{}: {message}", path.display());
        assert_eq!(message, e.to_string());
        assert!(
            app.scene() == &before,
            "{}: the scene changed",
            path.display()
        );
    }
    assert!(refused >= 40, "{refused} refused files");
    settle_headless(&mut app);
    assert_converged(&app);
}
