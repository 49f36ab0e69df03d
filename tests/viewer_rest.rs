//! A viewer at rest: once the image has converged and nothing changes, it asks for no frame,
//! whatever the scene's origin (built-in, TOML file, OBJ file) and whatever was done before
//! (a click, an export, a toggle, Esc). Each case counts the frames an event loop would paint
//! over an idle interval: a frame is painted only when the app asked for one (now or after a
//! delay), as eframe's loop does.

#[path = "common/viewer.rs"]
mod viewer;

use std::path::Path;
use std::time::{Duration, Instant};

use eframe::egui::{self, ViewportId};
use egui_kittest::kittest::Queryable;
use raytree::app::{Command, PANE_SIZE_DEBOUNCE};
use raytree::scene::load_scene_file;
use viewer::{Window, settle, small, window_with};

/// How long each case watches the idle viewer.
const IDLE: Duration = Duration::from_secs(3);
/// At most this many frames over [`IDLE`]: one per message that leaves the screen (a toast
/// expires by the clock) and one spare. A viewer that polls (a file watcher every 200 ms, a
/// toast timer counting frames) paints tens.
const MOST_FRAMES: usize = 2;

/// Frames painted over `interval` when frames come only as the app asks for them.
fn painted_while_idle(h: &mut Window, interval: Duration) -> (usize, Vec<String>) {
    let end = Instant::now() + interval;
    let mut frames = 0;
    let mut causes = Vec::new();
    loop {
        let now = Instant::now();
        if now >= end {
            break;
        }
        let asked = h.ctx.has_requested_repaint_for(&ViewportId::ROOT);
        let delay = h
            .output()
            .viewport_output
            .get(&ViewportId::ROOT)
            .map_or(Duration::MAX, |v| v.repaint_delay);
        if !asked {
            // Nothing asked for: a thread (the file watcher, an export) may still ask.
            std::thread::sleep(Duration::from_millis(50).min(end - now));
            continue;
        }
        let wake = now + delay.min(end - now);
        if wake >= end {
            break;
        }
        std::thread::sleep(wake - now);
        h.step();
        frames += 1;
        causes = h
            .ctx
            .repaint_causes()
            .iter()
            .map(|c| format!("{c:?}"))
            .collect();
    }
    (frames, causes)
}

/// Frames asked for within this much are the viewer settling, not resting: a pane that
/// changed size (a click opens the tree) is followed once its size held for
/// [`PANE_SIZE_DEBOUNCE`], and the render restarts at it. A toast's expiry is seconds away.
const SETTLING: Duration = PANE_SIZE_DEBOUNCE.saturating_mul(2);

/// Steps until both renders have converged and the last frame asked for no frame within
/// [`SETTLING`] (a layout change after a click restarts the renders at the new size).
fn converge(h: &mut Window) {
    let deadline = Instant::now() + viewer::DEADLINE;
    loop {
        settle(h);
        let delay = h
            .output()
            .viewport_output
            .get(&ViewportId::ROOT)
            .map_or(Duration::MAX, |v| v.repaint_delay);
        let finished = h.state().is_finished() && h.state().scene_view.is_finished();
        if finished && delay > SETTLING {
            return;
        }
        assert!(Instant::now() < deadline, "the viewer never converged");
        std::thread::sleep(delay.min(SETTLING));
        h.step();
    }
}

fn assert_rests(h: &mut Window, after: &str) {
    converge(h);
    let (frames, causes) = painted_while_idle(h, IDLE);
    assert!(
        frames <= MOST_FRAMES,
        "{after}: {frames} frames painted in {IDLE:?} of rest (at most {MOST_FRAMES}); the \
         last asked for by {causes:?}"
    );
}

/// The viewer in a `size` window as a new user gets it, but refining to 2 samples a pixel
/// (rest does not depend on the target; the cases converge sooner).
fn window(scene: raytree::scene::Scene, size: [f32; 2]) -> Window {
    window_with(scene, size, |app| app.set_view(2, true))
}

fn assets(rel: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(rel)
}

#[test]
fn a_converged_built_in_scene_rests_after_a_click_an_export_a_toggle_and_esc() {
    let mut h = window(small("default"), [1024.0, 640.0]);
    assert_rests(&mut h, "the built-in scene, untouched");

    h.get_by_label("render viewport").click();
    h.step();
    assert!(
        h.state().selection.tree.is_some(),
        "the click picked a tree"
    );
    assert_rests(&mut h, "after a click on the render");

    let dir = tempfile::tempdir().expect("temp dir");
    let shot = dir.path().join("shot.png");
    h.state_mut().command(Command::Export(shot.clone()));
    h.step();
    viewer::steps_until(&mut h, "the export was not written", |_| shot.is_file());
    assert_rests(&mut h, "after an export");

    // Focus on the tree and back: the layout changes twice.
    h.key_press(egui::Key::F);
    h.step();
    h.key_press(egui::Key::F);
    h.step();
    assert_rests(&mut h, "after toggling focus");

    h.key_press(egui::Key::Escape);
    h.step();
    assert_rests(&mut h, "after Esc");
}

#[test]
fn a_scene_opened_from_a_toml_file_rests_while_its_file_is_watched() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("quiz.toml");
    std::fs::copy(assets("scenes/quiz.toml"), &path).expect("copied");
    let mut scene = load_scene_file(&path).expect("loads");
    (scene.render.width, scene.render.height) = (160, 120);
    let mut h = window(scene, [1280.0, 800.0]);
    settle(&mut h);
    assert!(h.state().files.is_watched(), "the file is watched");
    assert_rests(&mut h, "a TOML scene, watched");

    // The watcher still wakes the viewer on a save, and the reload comes in.
    let text = std::fs::read_to_string(&path).expect("read");
    std::fs::write(&path, format!("{text}\n# saved again\n")).expect("saved");
    viewer::steps_until(&mut h, "the save was not reloaded", |app| {
        app.messages
            .log()
            .iter()
            .any(|m| m.text.starts_with("reloaded "))
    });
    assert_rests(&mut h, "after a reload");
}

#[test]
fn an_obj_opened_from_a_file_rests_after_a_click() {
    let mut scene = load_scene_file(&assets("models/room.obj")).expect("loads");
    (scene.render.width, scene.render.height) = (160, 120);
    let mut h = window(scene, [1024.0, 640.0]);
    assert_rests(&mut h, "an OBJ scene, watched");
    h.get_by_label("render viewport").click();
    h.step();
    assert_rests(&mut h, "an OBJ scene after a click");
}

#[test]
fn a_new_window_renders_once_at_its_panes_final_size() {
    for size in [[1024.0, 640.0], [1280.0, 800.0], [1600.0, 1000.0]] {
        let mut h = window(small("default"), size);
        h.step();
        let first = h.state().generation();
        converge(&mut h);
        let app = h.state();
        assert_eq!(
            app.render.pane_seen(&app.workspace.prefs),
            Some(app.render_size()),
            "{size:?}: the render follows the pane"
        );
        assert_eq!(
            app.generation(),
            first,
            "{size:?}: the render restarted after the first frame (the first frame's pane size \
             was taken before the layout settled)"
        );
    }
}
