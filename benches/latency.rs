//! Viewer latency, measured (never asserted): from an edit to the coarse preview and to the
//! full 1-sample image at 1280×720 on every core, median of 10 edits, on the default scene and
//! on the 80k-triangle benchmark scene; and the UI thread's per-frame cost of taking tiles
//! while a render runs. The baseline, measured in the same run, is the batch render of the same
//! 1-sample image (camera rays in packets, as the viewer's passes trace them), beside the same
//! batch render with every ray traced alone. Then the whole refinement: from a camera edit to
//! the viewer's 64 samples, against the batch 64-sample render of the same image (median of 3
//! each, alternating), the ratio being what the viewer's progressive passes cost over batch.
//!
//! Run: `cargo bench --bench latency` (`-- --no-64` leaves out the 64-sample measure).

use std::sync::Arc;
use std::time::{Duration, Instant};

use raytree::app::{Command, ViewerApp};
use raytree::render::session::{Pass, Session, SessionEvent};
use raytree::render::{render, render_with, trace_tile_single};
use raytree::scene::Scene;
use raytree::scene::builtin::load_builtin;
use raytree::scene::procedural::write_bench_scene;
use raytree::trace::{TraceSettings, Tracer};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Batch (packets), batch (single rays), edit → preview and edit → full image, then preview
/// and full image with the viewer's sample target, in seconds.
fn latencies(mut scene: Scene) -> [f64; 6] {
    scene.render.width = 1280;
    scene.render.height = 720;
    let settings = TraceSettings::default();
    let base = Tracer::new(Arc::new(scene.clone()), settings);

    let (mut batch, mut single) = (Vec::new(), Vec::new());
    for _ in 0..3 {
        let t = Instant::now();
        render(&base, 1, 0, &|_, _| {}).expect("render");
        batch.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        render_with(&base, 1, 0, &|_, _| {}, &trace_tile_single).expect("render");
        single.push(t.elapsed().as_secs_f64());
    }

    let mut session = Session::new(0).expect("pool");
    let (mut preview, mut full) = (Vec::new(), Vec::new());
    for i in 0..10 {
        // An edit as an orbit step makes it: the camera moves, the geometry stays.
        scene.camera.position.x += 0.01 * (i as f32 + 1.0);
        let tracer = Tracer::with_accel(Arc::new(scene.clone()), settings, base.accel.clone());
        let start = Instant::now();
        let generation = session.start(Arc::new(tracer), 1, None);
        loop {
            match session.try_next() {
                Some(SessionEvent::PassDone {
                    pass: Pass::Preview,
                    ..
                }) => {
                    preview.push(start.elapsed().as_secs_f64());
                }
                Some(SessionEvent::Finished { generation: g, .. }) if g == generation => {
                    full.push(start.elapsed().as_secs_f64());
                    break;
                }
                Some(_) => {}
                None => std::thread::sleep(Duration::from_micros(200)),
            }
        }
    }
    // The same edits with the viewer's sample target: a restart stops the refining render,
    // so the preview and the 1-sample pass arrive as soon as with a 1-sample target.
    let (mut preview64, mut full64) = (Vec::new(), Vec::new());
    for i in 0..10 {
        scene.camera.position.x -= 0.01 * (i as f32 + 1.0);
        let tracer = Tracer::with_accel(Arc::new(scene.clone()), settings, base.accel.clone());
        let start = Instant::now();
        session.start(Arc::new(tracer), raytree::app::VIEWER_SAMPLES, None);
        loop {
            match session.try_next() {
                Some(SessionEvent::PassDone {
                    pass: Pass::Preview,
                    ..
                }) => preview64.push(start.elapsed().as_secs_f64()),
                Some(SessionEvent::PassDone {
                    pass: Pass::Samples(1),
                    ..
                }) => {
                    full64.push(start.elapsed().as_secs_f64());
                    break;
                }
                Some(_) => {}
                None => std::thread::sleep(Duration::from_micros(200)),
            }
        }
    }
    [
        median(batch),
        median(single),
        median(preview),
        median(full),
        median(preview64),
        median(full64),
    ]
}

/// Batch 64-sample render and edit → the viewer's 64 samples, in seconds: medians of `runs`
/// pairs, alternating, and each pair's ratio (viewer / batch).
fn refinement(mut scene: Scene, runs: usize) -> (f64, f64, Vec<f64>) {
    scene.render.width = 1280;
    scene.render.height = 720;
    let settings = TraceSettings::default();
    let base = Tracer::new(Arc::new(scene.clone()), settings);
    let samples = raytree::app::VIEWER_SAMPLES;
    let mut session = Session::new(0).expect("pool");
    let (mut batch, mut viewer) = (Vec::new(), Vec::new());
    for i in 0..runs {
        let t = Instant::now();
        render(&base, samples, 0, &|_, _| {}).expect("render");
        batch.push(t.elapsed().as_secs_f64());
        scene.camera.position.x += 0.01 * (i as f32 + 1.0);
        let tracer = Tracer::with_accel(Arc::new(scene.clone()), settings, base.accel.clone());
        let start = Instant::now();
        let generation = session.start(Arc::new(tracer), samples, None);
        loop {
            match session.try_next() {
                Some(SessionEvent::Finished { generation: g, .. }) if g == generation => {
                    viewer.push(start.elapsed().as_secs_f64());
                    break;
                }
                Some(_) => {}
                None => std::thread::sleep(Duration::from_micros(200)),
            }
        }
    }
    let ratios = viewer.iter().zip(&batch).map(|(v, b)| v / b).collect();
    (median(batch), median(viewer), ratios)
}

fn main() {
    let with_64 = !std::env::args().any(|a| a == "--no-64");
    let dir = tempfile::tempdir().expect("a temporary folder");
    let bench = write_bench_scene(dir.path(), 80_000).expect("the bench scene is written");
    let scenes = [
        (
            "default scene",
            load_builtin("default").expect("built-in scene"),
        ),
        (
            "80k-triangle bench scene",
            raytree::scene::load_scene_file(&bench).expect("the bench scene loads"),
        ),
    ];
    let threads = Session::new(0).expect("pool").threads();
    for (name, scene) in scenes {
        let [batch, single, p, f, p64, f64_] = latencies(scene.clone());
        println!("viewer latency, {name} 1280x720, {threads} threads, median of 10 edits");
        println!("  batch 1-spp render (baseline): {:.1} ms", batch * 1e3);
        println!(
            "  batch 1-spp, single rays:      {:.1} ms ({:.2}x the baseline)",
            single * 1e3,
            single / batch
        );
        println!(
            "  edit -> coarse preview:        {:.1} ms ({:.2}x the baseline)",
            p * 1e3,
            p / batch
        );
        println!(
            "  edit -> full 1-sample image:   {:.1} ms ({:.2}x the baseline)",
            f * 1e3,
            f / batch
        );
        println!(
            "  with the viewer's {}-sample target: preview {:.1} ms, 1-sample image {:.1} ms",
            raytree::app::VIEWER_SAMPLES,
            p64 * 1e3,
            f64_ * 1e3
        );
        if with_64 {
            let (batch64, viewer64, mut ratios) = refinement(scene, 3);
            ratios.sort_by(f64::total_cmp);
            println!(
                "  batch {0}-sample render: {1:.2} s; edit -> the viewer's {0} samples: {2:.2} s ({3:.3}x batch, pairs {4:.3}-{5:.3})",
                raytree::app::VIEWER_SAMPLES,
                batch64,
                viewer64,
                median(ratios.clone()),
                ratios[0],
                ratios[ratios.len() - 1]
            );
        }
    }
    let mut scene = load_builtin("default").expect("built-in scene");
    scene.render.width = 1280;
    scene.render.height = 720;

    // The UI thread: a frame every 16 ms takes what arrived; time that work per frame.
    let mut app = ViewerApp::headless(scene.clone(), "default".into()).expect("viewer state");
    // One sample: the frames of a whole render, not of a 64-sample one.
    app.set_view(1, false);
    let mut frames = Vec::new();
    for _ in 0..3 {
        app.command(Command::Restart);
        app.apply();
        while !app.is_finished() {
            let t = Instant::now();
            app.poll_session();
            frames.push(t.elapsed().as_secs_f64());
            std::thread::sleep(Duration::from_millis(16));
        }
    }
    let worst = frames.iter().copied().fold(0.0, f64::max);
    println!(
        "  UI thread per frame taking tiles: median {:.2} ms, worst {:.2} ms over {} frames",
        median(frames.clone()) * 1e3,
        worst * 1e3,
        frames.len()
    );
}
