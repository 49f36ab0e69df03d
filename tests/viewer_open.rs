//! Opening a file never freezes the viewer: the read, the parse and the build run
//! in the background while the previous scene stays up and usable; a second open cancels the
//! first, which never installs; the progress only goes up and stays below 100 % until the new
//! scene is in; a headlight follows the camera without a rebuild. Headless
//! (`ViewerApp::headless`), the open held at a stage boundary by the open hook; the window
//! case drives the real app through the harness of `tests/common/viewer.rs`.

#[path = "common/viewer.rs"]
mod viewer;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use egui_kittest::kittest::Queryable;
use raytree::accel::AccelKind;
use raytree::app::opening::OpenStage;
use raytree::app::{Command, ViewerApp};
use raytree::scene::Scene;
use raytree::scene::procedural::bumpy_torus_obj;
use raytree::trace::TraceSettings;
use viewer::{frame, frames_until, headless, sized, steps_until, window_with};

/// Holds background opens at one stage boundary until told to let go, and records the
/// stages they reached.
#[derive(Default)]
struct Gate {
    hold: Mutex<Option<OpenStage>>,
    released: Condvar,
    seen: Mutex<Vec<OpenStage>>,
}

impl Gate {
    fn new(hold: Option<OpenStage>) -> Arc<Self> {
        let gate = Arc::new(Self::default());
        *gate.hold.lock().expect("gate") = hold;
        gate
    }

    fn install(self: &Arc<Self>, app: &mut ViewerApp) {
        let gate = self.clone();
        app.files.set_hook(Some(Arc::new(move |stage| {
            gate.seen.lock().expect("gate").push(stage);
            let mut hold = gate.hold.lock().expect("gate");
            // Held for at most a minute: a test that forgets to let go fails instead of hanging.
            let deadline = Instant::now() + Duration::from_secs(60);
            while *hold == Some(stage) && Instant::now() < deadline {
                hold = gate
                    .released
                    .wait_timeout(hold, Duration::from_millis(50))
                    .expect("gate")
                    .0;
            }
        })));
    }

    fn hold_at(&self, stage: Option<OpenStage>) {
        *self.hold.lock().expect("gate") = stage;
        self.released.notify_all();
    }

    fn count(&self, stage: OpenStage) -> usize {
        self.seen
            .lock()
            .expect("gate")
            .iter()
            .filter(|s| **s == stage)
            .count()
    }
}

fn small_default() -> Scene {
    sized("default", 96, 72, Some(4))
}

fn write_obj(dir: &Path, name: &str, triangles: usize) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bumpy_torus_obj(triangles)).expect("the OBJ is written");
    path
}

/// The open's percentage each frame: never back, below 100 while it runs.
struct Watch(f32);

impl Watch {
    fn check(&mut self, app: &mut ViewerApp) {
        if let Some((label, percent)) = app.files.status() {
            assert!(percent >= self.0, "{percent} % after {} %", self.0);
            assert!(percent < 100.0, "{label} before the scene is in");
            assert!(
                label.starts_with("loading ") || label.starts_with("building BVH… "),
                "{label}"
            );
            assert!(label.ends_with(" %"), "{label}");
            self.0 = percent;
        }
    }
}

#[test]
fn an_open_held_in_the_background_leaves_the_old_scene_usable_then_installs() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = write_obj(dir.path(), "torus.obj", 20_000);
    let mut app = headless(small_default(), "default");
    frames_until(&mut app, "first render", ViewerApp::is_finished);
    let old_triangles = app.scene().triangles.len();
    let gate = Gate::new(Some(OpenStage::Parse));
    gate.install(&mut app);

    app.command(Command::OpenFile(obj.clone()));
    app.apply();
    assert_eq!(app.files.opening(), Some(obj.as_path()));
    let mut watch = Watch(0.0);
    // Held before the parse: the UI goes on with the old scene.
    let generation = app.generation();
    for _ in 0..20 {
        frame(&mut app);
        watch.check(&mut app);
    }
    assert_eq!(app.scene().source, None, "the old (built-in) scene stays");
    assert_eq!(app.scene().triangles.len(), old_triangles);
    let (label, _) = app.files.status().expect("still opening");
    assert!(label.starts_with("loading torus.obj… "), "{label}");
    // The old scene is usable: a click gives its tree, a camera move renders it again.
    app.command(Command::Pick(48, 36));
    app.working.scene.camera.position.x += 0.2;
    app.command(Command::MoveCamera);
    app.apply();
    assert!(app.selection.tree.is_some(), "a tree of the old scene");
    assert!(app.generation() > generation, "the old scene re-renders");
    let moved = app.generation();
    frames_until(&mut app, "the old scene's first pass", |a| {
        a.samples_done() >= 1 && a.generation() == moved
    });
    watch.check(&mut app);

    // Let it parse, hold it before the build.
    gate.hold_at(Some(OpenStage::Build));
    frames_until(&mut app, "the parse", |_| gate.count(OpenStage::Build) == 1);
    for _ in 0..10 {
        frame(&mut app);
        watch.check(&mut app);
    }
    let (label, _) = app.files.status().expect("still opening");
    assert!(label.starts_with("building BVH… "), "{label}");
    assert_eq!(app.scene().source, None, "not installed before it is built");

    gate.hold_at(None);
    let deadline = Instant::now() + Duration::from_secs(120);
    while app.files.opening().is_some() {
        assert!(Instant::now() < deadline, "the install timed out");
        watch.check(&mut app);
        frame(&mut app);
    }
    assert_eq!(app.scene().source.as_deref(), Some(obj.as_path()));
    assert!(app.scene().triangles.len() > 10_000);
    assert!(
        app.selection.tree.is_none(),
        "the old scene's trees went with it"
    );
    let names: Vec<&str> = app.scene().lights.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["key", "headlight"]);
    frames_until(&mut app, "the new scene's render", ViewerApp::is_finished);
    assert!(app.samples_done() >= 1);
    let timings = app.files.last_open.expect("the open's times");
    assert!(timings.built && timings.triangles > 10_000, "{timings:?}");
}

#[test]
fn a_second_open_cancels_the_first_which_never_installs() {
    let dir = tempfile::tempdir().expect("temp dir");
    let first = write_obj(dir.path(), "first.obj", 3_000);
    let second = write_obj(dir.path(), "second.obj", 2_000);
    let mut app = headless(small_default(), "default");
    let gate = Gate::new(Some(OpenStage::Parse));
    gate.install(&mut app);

    app.command(Command::OpenFile(first.clone()));
    app.apply();
    frames_until(&mut app, "the first open's read", |_| {
        gate.count(OpenStage::Parse) == 1
    });
    app.command(Command::OpenFile(second.clone()));
    app.apply();
    assert_eq!(app.files.opening(), Some(second.as_path()));
    frames_until(&mut app, "the second open's read", |_| {
        gate.count(OpenStage::Parse) == 2
    });
    // Both let go at once: the first stops at its boundary, the second goes on.
    gate.hold_at(None);
    let deadline = Instant::now() + Duration::from_secs(120);
    while app.files.opening().is_some() || !app.is_finished() {
        assert!(Instant::now() < deadline, "the second open did not finish");
        frame(&mut app);
        assert_ne!(
            app.scene().source.as_deref(),
            Some(first.as_path()),
            "the cancelled open was installed"
        );
    }
    assert_eq!(app.scene().source.as_deref(), Some(second.as_path()));
    // Give a straggler time to show up: the first never reaches the build nor installs.
    for _ in 0..50 {
        frame(&mut app);
    }
    assert_eq!(app.scene().source.as_deref(), Some(second.as_path()));
    assert_eq!(
        gate.count(OpenStage::Build),
        1,
        "only the second open built"
    );
    assert_eq!(gate.count(OpenStage::Ready), 1);
}

#[test]
fn an_accelerator_change_mid_open_starts_it_again_with_that_accelerator() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = write_obj(dir.path(), "grid.obj", 3_000);
    let mut app = headless(small_default(), "default");
    let gate = Gate::new(Some(OpenStage::Build));
    gate.install(&mut app);
    app.command(Command::OpenFile(obj.clone()));
    app.apply();
    frames_until(&mut app, "the parse", |_| gate.count(OpenStage::Build) == 1);
    app.set_trace(TraceSettings {
        accel: AccelKind::Grid,
        ..TraceSettings::default()
    });
    app.apply();
    assert_eq!(app.files.opening(), Some(obj.as_path()), "opening again");
    gate.hold_at(None);
    frames_until(&mut app, "the open", |a| {
        a.files.opening().is_none() && a.is_finished()
    });
    assert_eq!(app.scene().source.as_deref(), Some(obj.as_path()));
    assert_eq!(app.accel().kind(), AccelKind::Grid);
    assert_eq!(
        gate.count(OpenStage::Ready),
        1,
        "the first open, cancelled at its build, never finished"
    );
}

#[test]
fn a_broken_file_opened_in_the_background_is_one_sentence_and_the_scene_stays() {
    let dir = tempfile::tempdir().expect("temp dir");
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nf 1 2 9\n").expect("write");
    let mut app = headless(small_default(), "default");
    app.command(Command::OpenFile(bad.clone()));
    app.apply();
    frames_until(&mut app, "the open", |a| a.files.opening().is_none());
    let last = app.messages.last().cloned().expect("a message");
    let (error, message) = (last.is_error(), last.text);
    assert!(error, "{message}");
    let direct = raytree::scene::load_scene_file(&bad)
        .expect_err("the file is broken")
        .to_string();
    assert_eq!(message, direct, "the loader's one sentence, as before");
    assert_eq!(app.scene().source, None, "the old scene stays");
}

#[test]
fn a_moved_camera_moves_the_headlight_without_a_rebuild() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = write_obj(dir.path(), "lamp.obj", 2_000);
    let mut app = headless(small_default(), "default");
    app.command(Command::OpenFile(obj));
    app.apply();
    frames_until(&mut app, "the open", |a| {
        a.files.opening().is_none() && a.is_finished()
    });
    let head = app
        .scene()
        .lights
        .iter()
        .position(|l| l.follow_camera)
        .expect("a bare OBJ has a headlight");
    assert_eq!(
        app.scene().lights[head].position,
        app.scene().camera.position
    );
    let accel = app.accel() as *const _;
    let triangles = app.scene().triangles.clone();
    app.working.scene.camera.orbit(0.8, 0.1);
    app.command(Command::MoveCamera);
    app.apply();
    frames_until(&mut app, "the render", ViewerApp::is_finished);
    let eye = app.scene().camera.position;
    assert_eq!(
        app.scene().lights[head].position,
        eye,
        "rendered at the new eye"
    );
    assert_eq!(
        app.working.scene.lights[head].position, eye,
        "the panel shows it there"
    );
    assert!(
        std::ptr::eq(accel, app.accel()),
        "the accelerator was kept (no rebuild)"
    );
    assert!(
        std::sync::Arc::ptr_eq(&triangles, &app.scene().triangles),
        "the moved camera's scene shares the triangles (no copy on the UI thread)"
    );
    // The tree sees it there too.
    app.command(Command::Pick(48, 36));
    app.apply();
    if let Some(shadow) = app
        .selection
        .tree
        .as_ref()
        .and_then(|t| t.root.shadow_rays.iter().find(|s| s.light == "headlight"))
    {
        let point = app
            .selection
            .tree
            .as_ref()
            .and_then(|t| t.root.hit.as_ref())
            .expect("hit")
            .point;
        assert!(shadow.to_light.dot((eye - point).normalize()) > 0.9999);
    }
}

/// The window while a file loads: frames keep coming, the status says what is loading.
#[test]
fn the_window_keeps_drawing_and_says_what_it_loads() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = write_obj(dir.path(), "window.obj", 5_000);
    let gate = Gate::new(Some(OpenStage::Parse));
    let hook_gate = gate.clone();
    let mut h = window_with(small_default(), [1024.0, 640.0], move |app| {
        app.set_view(4, false);
        hook_gate.install(app);
    });
    h.run_steps(3);
    h.state_mut().command(Command::OpenFile(obj.clone()));
    let mut steps = 0;
    for _ in 0..15 {
        h.step();
        steps += 1;
    }
    assert_eq!(steps, 15, "the window drew while the open was held");
    assert!(h.state().files.opening().is_some());
    h.get_by_label_contains("loading window.obj… ");
    gate.hold_at(None);
    steps_until(&mut h, "the open did not finish", |a| {
        a.files.opening().is_none()
    });
    assert_eq!(h.state().scene().source.as_deref(), Some(obj.as_path()));
}

/// The previous render keeps refining while a file opens, and does not hold the open back:
/// the new scene comes in long before the old one would have converged.
#[test]
fn an_open_does_not_wait_for_the_previous_render_to_converge() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = write_obj(dir.path(), "quick.obj", 3_000);
    let mut scene = small_default();
    (scene.render.width, scene.render.height) = (160, 120);
    let mut app = ViewerApp::headless(scene, "default".into()).expect("the viewer starts");
    // Thousands of samples of a glass scene: minutes of work for the render's workers.
    app.set_view(4096, false);
    app.apply();
    frames_until(&mut app, "the first pass", |a| a.samples_done() >= 1);
    app.command(Command::OpenFile(obj.clone()));
    app.apply();
    let deadline = Instant::now() + Duration::from_secs(300);
    let mut old_samples = 0;
    while app.files.opening().is_some() {
        assert!(Instant::now() < deadline, "the open did not finish");
        old_samples = app.samples_done();
        frame(&mut app);
    }
    assert_eq!(app.scene().source.as_deref(), Some(obj.as_path()));
    assert!(
        old_samples < 4096,
        "the open waited for the previous render to converge"
    );
}

/// Esc (the Stop command) stops an open under way: it never installs, the scene shown stays.
#[test]
fn stopping_cancels_the_open() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = write_obj(dir.path(), "stopped.obj", 2_000);
    let mut app = headless(small_default(), "default");
    let gate = Gate::new(Some(OpenStage::Parse));
    gate.install(&mut app);
    app.command(Command::OpenFile(obj.clone()));
    app.apply();
    frames_until(&mut app, "the read", |_| gate.count(OpenStage::Parse) == 1);
    app.command(Command::Stop);
    app.apply();
    assert_eq!(app.files.opening(), None);
    gate.hold_at(None);
    for _ in 0..50 {
        frame(&mut app);
    }
    assert_eq!(app.scene().source, None, "the stopped open never installs");
    assert_eq!(
        gate.count(OpenStage::Build),
        0,
        "it stopped before its build"
    );
}

/// A file named on the command line is opened before the window's first frame, when the
/// render pane's size is not known yet. When it came in after the pane's size was taken, it
/// was rendered at the scene's 640×480 and shown scaled into the pane, letterboxed, until the
/// window was resized. Once in, it is rendered at the pane's size, as a scene opened later is.
#[test]
fn a_file_opened_before_the_first_frame_is_rendered_at_the_panes_size() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = write_obj(dir.path(), "first.obj", 2_000);
    let path = obj.clone();
    let gate = Gate::new(Some(OpenStage::Parse));
    let hook_gate = gate.clone();
    let mut h = window_with(small_default(), [1280.0, 800.0], move |app| {
        app.set_view(4, true);
        hook_gate.install(app);
        app.command(Command::OpenFile(path));
        // Begun now, before any frame, as the window's own start does it.
        app.apply();
        assert!(app.files.opening().is_some(), "the open began");
    });
    // The pane's size is taken (by the scene shown meanwhile) while the file is still read.
    steps_until(&mut h, "the render did not take the pane's size", |a| {
        let pane = a.render.pane_seen(&a.workspace.prefs);
        pane.is_some() && pane == Some(a.render_size())
    });
    assert!(h.state().files.opening().is_some(), "the open was held");
    gate.hold_at(None);
    steps_until(&mut h, "the open did not finish", |a| {
        a.files.opening().is_none() && a.scene().source.as_deref() == Some(obj.as_path())
    });
    let pane = h.state().render.pane_seen(&h.state().workspace.prefs);
    let (w, hh) = h.state().render_size();
    assert_eq!(
        pane,
        Some((w, hh)),
        "rendered at {w}x{hh}, not at the 1280×800 window's pane"
    );
}

/// A bare OBJ's first look is framed by the loader for 640×480; shown in a pane narrower than
/// 4:3 (the settings panel beside it at 1600×1000), a long model lost both ends. Opened in
/// the viewer it is framed again for the pane, whether the file came in before the pane's size
/// was known or after: every corner of a bar ten times as long as it is high lies inside the
/// image.
#[test]
fn a_bare_obj_opened_in_a_narrow_pane_is_framed_for_that_pane() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("bar.obj");
    let corners: Vec<glam::Vec3> = (0..8)
        .map(|i| {
            let pick = |bit: usize, lo: f32, hi: f32| if i & bit != 0 { hi } else { lo };
            glam::Vec3::new(pick(4, -5.0, 5.0), pick(2, 0.0, 1.0), pick(1, -0.5, 0.5))
        })
        .collect();
    let mut obj: String = corners
        .iter()
        .map(|p| format!("v {} {} {}\n", p.x, p.y, p.z))
        .collect();
    obj.push_str("f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n");
    std::fs::write(&path, obj).expect("write");
    // The file in before the window's first frame; begun then but in after the pane's size
    // was taken; begun once the pane's size is known (the Scene menu's open).
    for what in [
        "in before the pane",
        "in after the pane",
        "opened in the pane",
    ] {
        let open = path.clone();
        let gate = Gate::new((what == "in after the pane").then_some(OpenStage::Parse));
        let hook_gate = gate.clone();
        let mut h = window_with(small_default(), [900.0, 1000.0], move |app| {
            app.set_view(4, true);
            hook_gate.install(app);
            if what != "opened in the pane" {
                app.command(Command::OpenFile(open.clone()));
                app.apply();
            }
            if what == "in before the pane" {
                frames_until(app, "the open did not finish", |a| {
                    a.scene().source.as_deref() == Some(open.as_path())
                });
            }
        });
        steps_until(&mut h, "the render did not take the pane's size", |a| {
            let pane = a.render.pane_seen(&a.workspace.prefs);
            pane.is_some() && pane == Some(a.render_size())
        });
        if what == "opened in the pane" {
            h.state_mut().command(Command::OpenFile(path.clone()));
        }
        gate.hold_at(None);
        steps_until(&mut h, "the open did not finish", |a| {
            a.files.opening().is_none() && a.scene().source.as_deref() == Some(path.as_path())
        });
        let (w, hh) = h.state().render_size();
        let aspect = w as f32 / hh as f32;
        assert!(
            aspect < 1.2,
            "{what}: the pane is {w}x{hh}, not narrower than 4:3"
        );
        let camera = h.state().scene().camera.clone();
        let forward = (camera.look_at - camera.position).normalize();
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        let tan_v = (0.5 * camera.fov_y_deg).to_radians().tan();
        for p in &corners {
            let d = *p - camera.position;
            let (x, y, z) = (d.dot(right), d.dot(up), d.dot(forward));
            assert!(
                z > 0.0 && (x / z).abs() <= tan_v * aspect && (y / z).abs() <= tan_v,
                "{what}: corner {p} lies outside the {w}x{hh} image (camera {camera:?})"
            );
        }
        // The working scene, the one a save writes and Home returns to, has that camera too.
        assert_eq!(h.state().working.scene.camera, camera, "{what}");
    }
}
