//! The real viewer driven through egui_kittest on the wgpu software adapter (Mesa lavapipe in
//! CI): edits restart the render, bad scenes keep the old one, exports write stamped PNGs, a
//! click shows the ray tree, and a snapshot of the whole window.
//!
//! Update the snapshot after a deliberate change (look at it first):
//! `UPDATE_SNAPSHOTS=1 cargo test --release --test viewer`

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use eframe::egui;
use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use raytree::app::ViewerApp;
use raytree::render::render;
use raytree::scene::Scene;
use raytree::scene::builtin::load_builtin;
use raytree::trace::{TraceSettings, Tracer};

fn small(name: &str) -> Scene {
    let mut s = load_builtin(name).expect("built-in scene");
    s.render.width = 160;
    s.render.height = 120;
    s
}

fn harness(scene: Scene) -> Harness<'static, ViewerApp> {
    let renderer =
        std::panic::catch_unwind(AssertUnwindSafe(egui_kittest::wgpu::WgpuTestRenderer::new))
            .unwrap_or_else(|_| {
                panic!(
                    "no wgpu adapter for the viewer tests: install Mesa's software Vulkan \
             (apt-get install mesa-vulkan-drivers libvulkan1), as scripts/install-deps.sh does"
                )
            });
    Harness::builder()
        .with_size([1280.0, 800.0])
        .renderer(renderer)
        .build_eframe(|cc| ViewerApp::new(cc, scene, "test".into()).expect("the viewer starts"))
}

/// Steps frames until the progressive render reaches its target.
fn settle(h: &mut Harness<'static, ViewerApp>) {
    let deadline = Instant::now() + Duration::from_secs(120);
    while !h.state().is_finished() {
        assert!(Instant::now() < deadline, "the render did not finish");
        h.step();
        std::thread::sleep(Duration::from_millis(2));
    }
    h.step();
}

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
    h.step();
    let message = h
        .state()
        .messages
        .last()
        .map(|m| m.1.clone())
        .unwrap_or_default();
    assert!(
        message.contains("broken.toml:2:") && message.contains("radius"),
        "{message}"
    );
    // The message is on screen, and the quiz scene is still the one shown.
    h.get_by_label_contains("broken.toml:2:");
    assert_eq!(h.state().scene().triangles.len(), triangles);
    assert!(h.state().scene().spheres.is_empty());
}

#[test]
fn ctrl_s_exports_a_stamped_png() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("shot.png");
    let mut h = harness(small("glass"));
    settle(&mut h);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    h.step();
    h.step();
    h.get_by_role(Role::TextInput)
        .set_text_value_accesskit(out.to_str().expect("utf-8 path"));
    h.step();
    h.get_by_role_and_label(Role::Button, "Save").click();
    h.step();
    h.step();
    let file = std::fs::File::open(&out).expect("the PNG was written");
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("a valid PNG");
    assert_eq!((reader.info().width, reader.info().height), (160, 120));
    let text: Vec<_> = reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect();
    assert!(
        text.iter()
            .any(|(k, v)| k == "raytree.samples" && v == "1/1"),
        "{text:?}"
    );
}

#[test]
fn clicking_a_pixel_shows_its_ray_tree() {
    let mut h = harness(small("default"));
    settle(&mut h);
    // The centre of the viewport is the glass sphere's neighbourhood in the default scene.
    let image = h.get_by_label("render viewport").rect();
    let centre = image.center();
    h.hover_at(centre);
    h.event(egui::Event::PointerButton {
        pos: centre,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::NONE,
    });
    h.event(egui::Event::PointerButton {
        pos: centre,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::NONE,
    });
    h.step();
    h.step();
    let tree = h.state().tree.clone().expect("a tree after the click");
    let [x, y] = tree.pixel;
    assert!(
        x.abs_diff(80) <= 1 && y.abs_diff(60) <= 1,
        "clicked {x}, {y}"
    );
    h.get_by_label_contains(&format!("Ray tree of ({x}, {y})"));
    assert!(h.query_all_by_label_contains("primary d0").count() >= 1);
    // The diagram shows the same tree, its root labelled with what the primary ray met.
    h.get_by_label(&format!("ray tree diagram of ({x}, {y})"));
    let root = match (&tree.root.end, &tree.root.hit) {
        (_, Some(hit)) => hit.object.clone(),
        (Some(_), None) => "no hit".to_string(),
        _ => unreachable!("a root either ends or hits"),
    };
    h.get_by_label(&format!("tree node primary: {root}"));
    // Selecting a child in the diagram shows its numbers in the detail pane.
    if let Some(child) = tree.root.children.first() {
        let letter = if child.kind == raytree::trace::RayKind::Reflected {
            "R"
        } else {
            "T"
        };
        let label = format!("tree node {letter}:");
        h.query_all_by_label_contains(&label)
            .next()
            .expect("a child node")
            .click();
        h.step();
        h.step();
        assert_eq!(
            h.state().tree_state.selected.as_deref(),
            Some(&[0usize][..])
        );
    }
    // The rays drawn over the image, with the tree panels open.
    let status = h.get_by_label_contains("Mrays/s").rect();
    h.mask(status);
    h.snapshot("viewer_tree");
}

#[test]
fn window_snapshot() {
    let mut h = harness(small("default"));
    settle(&mut h);
    // Timings and rates differ from run to run: hide the status line that shows them.
    let status = h.get_by_label_contains("Mrays/s").rect();
    h.mask(status);
    h.snapshot("viewer_default");
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
    while h.state().sweep.report.is_none() {
        assert!(Instant::now() < deadline, "the sweep did not finish");
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    let report = h.state().sweep.report.clone().expect("a report");
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
    assert!(
        raytree::app::sweep::nearest_point(&report, [at[0] + 0.5, at[1] + 0.5], [1.0, 1.0])
            .is_none()
    );
}
