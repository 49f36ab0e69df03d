//! Faults in the viewer (SPEC §9): bursts of edits (hundreds a second) never deadlock and never
//! leave a stale tile (after the burst, the converged film equals the batch render of the final
//! scene); a new scene opened mid-render replaces the old one cleanly, a bad one leaves it
//! rendering; the window survives being 0×0. The logic runs headless
//! (`ViewerApp::headless`); the window cases drive the real app through egui_kittest on the
//! wgpu software adapter, like `tests/viewer.rs` (same environment: `XDG_RUNTIME_DIR=/tmp
//! WGPU_BACKEND=vulkan` where needed).

use std::panic::AssertUnwindSafe;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use eframe::egui;
use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::Vec3;
use raytree::app::{Command, ViewerApp};
use raytree::render::{Image, render};
use raytree::scene::Scene;
use raytree::scene::builtin::{load_builtin, scene_text};
use raytree::trace::{TraceSettings, Tracer};

fn small(name: &str, width: u32, height: u32, samples: u32) -> Scene {
    let mut s = load_builtin(name).expect("built-in scene");
    s.render.width = width;
    s.render.height = height;
    s.render.samples = samples;
    s
}

/// The viewer without a window, refining to the scene's own sample count (not the viewer's
/// target), so its converged film is the batch render's.
fn headless(scene: Scene, label: &str) -> ViewerApp {
    let samples = scene.render.samples;
    let mut app = ViewerApp::headless(scene, label.into()).expect("the viewer starts");
    app.set_view(samples, false);
    app.apply();
    app
}

fn batch(scene: &Scene, trace: TraceSettings) -> Image {
    let tracer = Tracer::new(Arc::new(scene.clone()), trace);
    render(&tracer, scene.render.samples, 0, &|_, _| {})
        .expect("render")
        .0
}

/// Polls until the current generation finishes. The deadline is a hang guard, not a measure of
/// speed: a deadlock fails here instead of hanging the suite.
fn settle(app: &mut ViewerApp) {
    let deadline = Instant::now() + Duration::from_secs(120);
    while !app.is_finished() {
        assert!(Instant::now() < deadline, "the render did not finish");
        app.poll_session();
        std::thread::sleep(Duration::from_millis(1));
    }
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
        image == batch(&scene, app.settings.trace),
        "the converged film differs from the batch render of the final scene: a stale tile"
    );
}

/// Edits as fast as they come, of every kind that restarts the render: camera, depth, light
/// colour, material, image size (so stale tiles of another size are in flight), accelerator
/// rebuilds. No edit waits for a render, and then the film converges to the final scene exactly.
#[test]
fn bursts_of_edits_never_deadlock_or_leave_stale_tiles() {
    let mut app = headless(small("default", 48, 36, 4), "burst");
    let start = Instant::now();
    let edits = 400;
    let mut finished_at_once = 0u32;
    for i in 0..edits {
        let e = &mut app.edit;
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
        app.poll_session();
        finished_at_once += u32::from(app.is_finished());
    }
    let per_second = edits as f64 / start.elapsed().as_secs_f64();
    eprintln!("{edits} edits at {per_second:.0} a second");
    // An edit returns while its render runs on the workers. Were the render done on the UI
    // thread, every edit would find its render finished.
    assert!(
        finished_at_once < edits / 2,
        "{finished_at_once} of {edits} edits waited for their render"
    );
    settle(&mut app);
    assert_eq!(app.scene().render.width, 40 + (edits - 1) % 17);
    assert_converged(&app);
    assert!(
        app.messages.iter().all(|(error, _)| !error),
        "{:?}",
        app.messages
    );
}

/// Opening another scene while a render runs: the new scene (another size) replaces the old,
/// whose tiles still in flight are dropped; a bad file instead leaves the old scene rendering
/// to the end.
#[test]
fn opening_a_scene_mid_render() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut app = headless(small("default", 160, 120, 8), "default");
    app.poll_session();

    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[render]\nwidth = 0\n").expect("write");
    app.command(Command::OpenFile(bad.clone()));
    app.apply();
    // Read and parsed in the background: the error comes when the open ends.
    settle(&mut app);
    assert_eq!(app.opening(), None);
    let (error, message) = app.messages.last().cloned().expect("a message");
    assert!(error, "{message}");
    assert!(
        message.starts_with(&format!("{}:2:9: render field `width`", bad.display())),
        "{message}"
    );
    assert_eq!(app.scene().render.width, 160, "the old scene stays");
    settle(&mut app);
    assert_converged(&app);

    // Restart a long render, then open a scene of another size in the middle of it.
    app.edit.camera.position.y += 0.1;
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
    settle(&mut app);
    assert_eq!(app.scene().source.as_deref(), Some(good.as_path()));
    assert_eq!(
        (app.scene().render.width, app.scene().render.height),
        (50, 30)
    );
    assert_converged(&app);
}

fn harness(scene: Scene, size: egui::Vec2) -> Harness<'static, ViewerApp> {
    let renderer =
        std::panic::catch_unwind(AssertUnwindSafe(egui_kittest::wgpu::WgpuTestRenderer::new))
            .unwrap_or_else(|_| panic!("no wgpu adapter: see tests/viewer.rs"));
    Harness::builder()
        .with_size(size)
        .renderer(renderer)
        .build_eframe(|cc| {
            // The scene's size and sample count, the settings shown whatever the width.
            let samples = scene.render.samples;
            let mut app = ViewerApp::new(cc, scene, "faults".into()).expect("the viewer starts");
            app.set_view(samples, false);
            app.set_settings_panel(true);
            app
        })
}

/// Steps the window until its render finishes. The deadline is a hang guard, not a measure of
/// speed: a render that stopped making progress fails here instead of hanging the suite.
fn settle_window(h: &mut Harness<'static, ViewerApp>, what: &str) {
    let deadline = Instant::now() + Duration::from_secs(60);
    while !h.state().is_finished() {
        assert!(Instant::now() < deadline, "{what}");
        h.step();
        std::thread::sleep(Duration::from_millis(2));
    }
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
        let mut h = harness(small("quiz", 40, 30, 2), size);
        for _ in 0..5 {
            h.step();
        }
        settle_window(&mut h, &format!("no progress in a {size:?} window"));
    }
    let mut h = harness(small("quiz", 40, 30, 2), egui::vec2(800.0, 500.0));
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
    let mut h = harness(small("default", 48, 36, 2), egui::vec2(1000.0, 700.0));
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
    settle_window(&mut h, "the render did not finish");
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
    let scene = small("quiz", 9000, 4, 1);
    let mut h = Harness::builder()
        .with_size(egui::vec2(800.0, 500.0))
        .renderer(renderer)
        .build_eframe(|cc| ViewerApp::new(cc, scene, "wide".into()).expect("the viewer starts"));
    for _ in 0..5 {
        h.step();
    }
    // Drawing runs the paint callback, which creates the texture.
    h.render().expect("the window draws");
    assert!(
        h.state().messages.iter().any(|(error, _)| *error),
        "no message about the size"
    );
}

/// Edits are held to the loader's ±1e15 bound (a BVH build over a primitive near f32::MAX
/// panics in obvhs): the far spheres are refused with a message, the edit is undone, and the
/// scene stays and renders.
#[test]
fn an_edit_far_beyond_the_scene_size_limit_is_refused() {
    let mut app = headless(small("default", 32, 24, 1), "far");
    let spheres = app.scene().spheres.clone();
    let messages = app.messages.len();
    let mut far = app.edit.spheres[0];
    far.center = Vec3::new(3e38, 0.0, 0.0);
    for _ in 0..8 {
        app.edit.spheres.push(far);
    }
    app.command(Command::Rebuild);
    app.apply();
    assert_eq!(app.messages.len(), messages + 1, "{:?}", app.messages);
    let (error, message) = app.messages.last().cloned().expect("a message");
    assert!(error, "{message}");
    assert_eq!(app.scene().spheres, spheres, "the scene stays");
    assert_eq!(app.edit.spheres, spheres, "the edit is undone");
    settle(&mut app);
    assert_converged(&app);
}

/// Every file of the hostile corpus that the loader refuses (broken `vn`/`vt` indices,
/// `crease_angle`, `normals`, devices, folders, ...), opened in the viewer: the message is the
/// loader's sentence, and the scene being shown stays exactly as it was.
#[test]
fn opening_each_refused_hostile_file_keeps_the_scene() {
    let mut app = headless(small("default", 64, 48, 1), "default");
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
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(30);
        while app.opening().is_some() && std::time::Instant::now() < deadline {
            app.poll_session();
            app.apply();
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert!(app.opening().is_none(), "{}: still opening", path.display());
        assert_eq!(app.messages.len(), messages + 1, "{:?}", app.messages);
        let (error, message) = app.messages.last().cloned().expect("a message");
        assert!(error, "{}: {message}", path.display());
        assert_eq!(message, e.to_string());
        assert!(
            app.scene() == &before,
            "{}: the scene changed",
            path.display()
        );
    }
    assert!(refused >= 40, "{refused} refused files");
    settle(&mut app);
    assert_converged(&app);
}
