//! The one viewer test harness: the real app in a window driven through egui_kittest on the
//! wgpu software adapter (Mesa lavapipe in CI: `WGPU_BACKEND=vulkan XDG_RUNTIME_DIR=...`, as
//! scripts/test.sh sets them), and the app without a window for the logic.
//!
//! Included by each viewer test file with `#[path = "common/viewer.rs"] mod viewer;`. The
//! deadlines here are hang guards, not measures of speed: a render that stops making
//! progress fails with its message instead of hanging the suite.
#![allow(dead_code)]

use std::panic::AssertUnwindSafe;
use std::time::{Duration, Instant};

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::wgpu::WgpuTestRenderer;
use raytree::app::ViewerApp;
use raytree::scene::Scene;
use raytree::scene::builtin::load_builtin;

/// The viewer in a window.
pub type Window = Harness<'static, ViewerApp>;

/// How long a test waits for a render or an open before it fails.
pub const DEADLINE: Duration = Duration::from_secs(120);

/// Built-in scene `name` at 160×120.
pub fn small(name: &str) -> Scene {
    sized(name, 160, 120, None)
}

/// Built-in scene `name` at `width × height`, with `samples` per pixel when given.
pub fn sized(name: &str, width: u32, height: u32, samples: Option<u32>) -> Scene {
    let mut s = load_builtin(name).expect("built-in scene");
    (s.render.width, s.render.height) = (width, height);
    if let Some(samples) = samples {
        s.render.samples = samples;
    }
    s
}

/// The wgpu software renderer the windows draw with.
pub fn renderer() -> WgpuTestRenderer {
    std::panic::catch_unwind(AssertUnwindSafe(WgpuTestRenderer::new)).unwrap_or_else(|_| {
        panic!(
            "no wgpu adapter for the viewer tests: install Mesa's software Vulkan \
             (apt-get install mesa-vulkan-drivers libvulkan1), as scripts/install-deps.sh does"
        )
    })
}

/// The viewer in a `size` window, as a new user gets it: the viewer's sample target, the
/// render at the pane's size, the settings panel as the window's width has it.
pub fn window(scene: Scene, size: impl Into<egui::Vec2>) -> Window {
    window_with(scene, size, |_| {})
}

/// [`window`], `setup` done on the app before its first frame.
pub fn window_with(
    scene: Scene,
    size: impl Into<egui::Vec2>,
    setup: impl FnOnce(&mut ViewerApp) + 'static,
) -> Window {
    Harness::builder()
        .with_size(size.into())
        .renderer(renderer())
        .build_eframe(|cc| {
            let mut app = ViewerApp::new(cc, scene, "test".into()).expect("the viewer starts");
            setup(&mut app);
            app
        })
}

/// The viewer in a `size` window rendering the scene at its own size to its own sample count
/// (so its image equals the batch render's), the settings shown whatever the width.
pub fn at_scene_size(scene: Scene, size: impl Into<egui::Vec2>) -> Window {
    let samples = scene.render.samples;
    window_with(scene, size, move |app| {
        app.set_view(samples, false);
        app.workspace.set_settings_panel(true);
    })
}

/// [`at_scene_size`] in a 1280×800 window, one frame drawn.
pub fn harness(scene: Scene) -> Window {
    let mut h = at_scene_size(scene, [1280.0, 800.0]);
    h.step();
    h
}

/// Steps frames until `done`, failing with `what` at the deadline.
pub fn steps_until(h: &mut Window, what: &str, done: impl Fn(&ViewerApp) -> bool) {
    let deadline = Instant::now() + DEADLINE;
    while !done(h.state()) {
        assert!(Instant::now() < deadline, "{what}: timed out");
        h.step();
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Steps frames until both progressive renders (render view and scene view) reach their
/// target, then one more.
pub fn settle(h: &mut Window) {
    steps_until(h, "the render did not finish", |app| {
        app.is_finished() && app.scene_view.is_finished()
    });
    h.step();
}

/// Steps frames until the render view's render reaches its target.
pub fn settle_render(h: &mut Window, what: &str) {
    steps_until(h, what, ViewerApp::is_finished);
}

/// The viewer without a window, refining to the scene's own sample count (not the viewer's
/// target), so its converged film is the batch render's.
pub fn headless(scene: Scene, label: &str) -> ViewerApp {
    let samples = scene.render.samples;
    let mut app = ViewerApp::headless(scene, label.into()).expect("the viewer starts");
    app.set_view(samples, false);
    app.apply();
    app
}

/// One UI frame without a window: what the window's frame does around the panels.
pub fn frame(app: &mut ViewerApp) {
    app.poll_session();
    app.apply();
    std::thread::sleep(Duration::from_millis(2));
}

/// Frames until `done`; false when the deadline came first.
pub fn frames_within(app: &mut ViewerApp, done: impl Fn(&ViewerApp) -> bool) -> bool {
    let deadline = Instant::now() + DEADLINE;
    while !done(app) {
        if Instant::now() >= deadline {
            return false;
        }
        frame(app);
    }
    true
}

/// Frames until `done`, failing with `what` at the deadline.
pub fn frames_until(app: &mut ViewerApp, what: &str, done: impl Fn(&ViewerApp) -> bool) {
    assert!(frames_within(app, done), "{what}: timed out");
}

/// Frames until the current generation finishes.
pub fn settle_headless(app: &mut ViewerApp) {
    frames_until(app, "the render did not finish", ViewerApp::is_finished);
}

/// Hides the status line's timings and rates, which differ from run to run: from the start of
/// its label to the window's right edge (the text's width varies with its digits).
pub fn mask_status(h: &mut Window) {
    use egui_kittest::kittest::Queryable as _;
    let status = h.get_by_label_contains("Mrays/s").rect();
    let right = h.ctx.content_rect().right();
    h.mask(egui::Rect::from_min_max(
        status.min,
        egui::pos2(right, status.max.y),
    ));
}
