//! Reload on save (headless viewer): a scene file saved in an editor reloads by itself, keeping
//! the camera moved in the viewer and the clicked tree when the geometry is unchanged; a change
//! of geometry rebuilds; a broken save shows its error and keeps the last good scene.

#[path = "common/viewer.rs"]
mod viewer;

use std::path::Path;
use std::time::{Duration, Instant};

use raytree::app::watch::DEBOUNCE;
use raytree::app::{Command, ViewerApp};
use raytree::scene::load_scene_file;
use viewer::{frame, frames_until, frames_within};

const SCENE: &str = r#"
[render]
width = 40
height = 30
samples = 1
max_depth = 2

[camera]
position = [0, 1, 5]
look_at = [0, 0.5, 0]
fov_y = 45

[[light]]
position = [2, 5, 4]
color = [1, 1, 1]

[[material]]
name = "red"
diffuse = [0.8, 0.1, 0.1]

[[sphere]]
center = [0, 0.5, 0]
radius = 0.7
material = "red"
"#;

/// Saves `text` as an editor does: a new file renamed over the old one.
fn save(path: &Path, text: &str) {
    let tmp = path.with_extension("toml.tmp");
    std::fs::write(&tmp, text).expect("write");
    std::fs::rename(&tmp, path).expect("rename");
}

#[test]
fn saving_the_scene_reloads_it_and_a_broken_save_keeps_the_last_good_one() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("watched.toml");
    std::fs::write(&path, SCENE).expect("write");
    let scene = load_scene_file(&path).expect("loads");
    let mut app = ViewerApp::headless(scene, "watched".into()).expect("the viewer starts");
    assert!(frames_within(&mut app, ViewerApp::is_finished));
    // The user moves the camera and clicks a pixel.
    app.working.scene.camera.position.x += 0.25;
    app.command(Command::MoveCamera);
    app.command(Command::Pick(20, 15));
    app.apply();
    assert!(frames_within(&mut app, ViewerApp::is_finished));
    let camera = app.scene().camera.clone();
    assert!(app.selection.tree.is_some());

    // A save that changes the light only: reloaded, camera and tree kept.
    frames_until(&mut app, "nothing waits for a reload", |a| {
        !a.reload_pending()
    });
    save(
        &path,
        &SCENE.replace("color = [1, 1, 1]", "color = [0.5, 0.5, 1]"),
    );
    assert!(
        frames_within(&mut app, |a| a.scene().lights[0].color.x == 0.5
            && a.is_finished()),
        "the save was not reloaded: {:?}",
        app.messages.log()
    );
    assert_eq!(app.scene().camera, camera, "the viewer's camera stays");
    assert!(app.selection.tree.is_some(), "the clicked tree stays");
    assert!(
        app.messages
            .log()
            .iter()
            .any(|m| !m.is_error() && m.text.starts_with("reloaded "))
    );

    // A save that moves the sphere: a new scene (rebuilt), its own camera.
    save(
        &path,
        &SCENE.replace("center = [0, 0.5, 0]", "center = [0.3, 0.5, 0]"),
    );
    assert!(
        frames_within(&mut app, |a| a.scene().spheres[0].center.x == 0.3
            && a.is_finished()),
        "the geometry change was not reloaded"
    );

    // A broken save: its error, and the scene stays.
    let errors = app.messages.log().iter().filter(|m| m.is_error()).count();
    save(&path, "[render]\nwidth = 0\n");
    assert!(
        frames_within(&mut app, |a| a
            .messages
            .log()
            .iter()
            .filter(|m| m.is_error())
            .count()
            > errors),
        "no error for the broken save"
    );
    let message = &app
        .messages
        .log()
        .iter()
        .rev()
        .find(|m| m.is_error())
        .expect("an error")
        .text;
    assert!(
        message.contains("watched.toml:2:9: render field `width`")
            && message.contains("the last good scene stays"),
        "{message}"
    );
    assert_eq!(
        app.scene().spheres[0].center.x,
        0.3,
        "the last good scene stays"
    );
    assert_eq!(app.scene().render.width, 40);

    // Fixed again: reloaded.
    save(&path, SCENE);
    assert!(
        frames_within(&mut app, |a| a.scene().spheres[0].center.x == 0.0
            && a.is_finished()),
        "the fixed file was not reloaded"
    );
}

/// The reload runs in the background like an open: while it is held before its parse, the
/// scene shown stays and keeps rendering; then the saved scene comes in.
#[test]
fn a_reload_is_read_and_parsed_off_the_ui_thread() {
    use raytree::app::opening::OpenStage;
    use std::sync::{Arc, Condvar, Mutex};

    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("held.toml");
    std::fs::write(&path, SCENE).expect("write");
    let scene = load_scene_file(&path).expect("loads");
    let mut app = ViewerApp::headless(scene, "held".into()).expect("the viewer starts");
    assert!(frames_within(&mut app, ViewerApp::is_finished));
    let gate = Arc::new((Mutex::new(true), Condvar::new()));
    let hook_gate = gate.clone();
    app.files.set_hook(Some(Arc::new(move |stage| {
        let (held, released) = &*hook_gate;
        let mut held = held.lock().expect("gate");
        let deadline = Instant::now() + Duration::from_secs(60);
        while stage == OpenStage::Parse && *held && Instant::now() < deadline {
            held = released
                .wait_timeout(held, Duration::from_millis(50))
                .expect("gate")
                .0;
        }
    })));
    frames_until(&mut app, "nothing waits for a reload", |a| {
        !a.reload_pending()
    });
    save(
        &path,
        &SCENE.replace("color = [1, 1, 1]", "color = [0.25, 0.5, 1]"),
    );
    assert!(
        frames_within(&mut app, |a| a.files.opening() == Some(path.as_path())),
        "the save started no reload"
    );
    // Held: the old scene stays and renders an edit.
    app.working.scene.camera.position.y += 0.1;
    app.command(Command::MoveCamera);
    app.apply();
    let generation = app.generation();
    assert!(frames_within(&mut app, |a| a.samples_done() >= 1
        && a.generation() == generation));
    assert_eq!(app.scene().lights[0].color.x, 1.0, "the old scene stays");
    assert!(
        app.files.opening().is_some(),
        "the reload waits in the background"
    );
    let camera = app.working.scene.camera.clone();
    // Let go: the reload comes in, keeping the camera as moved.
    *gate.0.lock().expect("gate") = false;
    gate.1.notify_all();
    assert!(
        frames_within(&mut app, |a| a.scene().lights[0].color.x == 0.25
            && a.is_finished()),
        "the reload did not come in: {:?}",
        app.messages.log()
    );
    assert_eq!(app.scene().camera, camera, "the viewer's camera stays");
}

/// Writes a `w`×1 PNG of one colour.
fn png(path: &Path, w: u32, rgb: [u8; 3]) {
    image::RgbImage::from_pixel(w, 1, image::Rgb(rgb))
        .save(path)
        .expect("png");
}

#[test]
fn the_used_texture_reloads_and_other_images_beside_it_do_not() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = dir.path().join("quad.obj");
    std::fs::write(
        &obj,
        "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3 4/4\n",
    )
    .expect("obj");
    std::fs::write(
        dir.path().join("quad.mtl"),
        "newmtl tex\nKd 1 1 1\nmap_Kd wood.png\n",
    )
    .expect("mtl");
    png(&dir.path().join("wood.png"), 2, [200, 100, 50]);
    let scene = load_scene_file(&obj).expect("loads");
    assert_eq!(scene.textures.len(), 1, "{:?}", scene.warnings);
    let mut app = ViewerApp::headless(scene, "quad".into()).expect("the viewer starts");
    assert!(frames_within(&mut app, ViewerApp::is_finished));
    let reloads = |app: &ViewerApp| {
        app.messages
            .log()
            .iter()
            .filter(|m| !m.is_error() && m.text.starts_with("reloaded "))
            .count()
    };
    // A screenshot saved beside the model is not part of the scene: no reload, and nothing
    // waits for one, for several times the watch's settling time (a change it took for the
    // scene's would be pending within it, and reloaded at its end).
    png(&dir.path().join("screenshot.png"), 3, [1, 2, 3]);
    let quiet = Instant::now() + 4 * DEBOUNCE;
    while Instant::now() < quiet {
        assert!(
            !app.reload_pending(),
            "the screenshot was taken for the scene's"
        );
        frame(&mut app);
    }
    assert_eq!(reloads(&app), 0, "{:?}", app.messages.log());
    assert!(!app.reload_pending());
    // The texture the material uses: reloaded with its new colour.
    png(&dir.path().join("wood.png"), 2, [10, 200, 30]);
    assert!(
        frames_within(&mut app, |a| reloads(a) == 1 && a.is_finished()),
        "the texture's save was not reloaded: {:?}",
        app.messages.log()
    );
}
