//! Viewer latency, measured (never asserted): from an edit to the coarse preview and to the
//! full 1-sample image, default scene at 1280×720 on every core, median of 10 edits; and the
//! UI thread's per-frame cost of taking tiles while a render runs. The baseline, measured in the
//! same run, is the batch render of the same 1-sample image.
//!
//! Run: `cargo bench --bench latency`

use std::sync::Arc;
use std::time::{Duration, Instant};

use raytree::app::{Command, ViewerApp};
use raytree::render::render;
use raytree::render::session::{Pass, Session, SessionEvent};
use raytree::scene::builtin::load_builtin;
use raytree::trace::{TraceSettings, Tracer};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut scene = load_builtin("default").expect("built-in scene");
    scene.render.width = 1280;
    scene.render.height = 720;
    let settings = TraceSettings::default();
    let base = Tracer::new(Arc::new(scene.clone()), settings);

    let mut batch = Vec::new();
    for _ in 0..3 {
        let t = Instant::now();
        render(&base, 1, 0, &|_, _| {}).expect("render");
        batch.push(t.elapsed().as_secs_f64());
    }
    let batch = median(batch);

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
    let (p, f) = (median(preview), median(full));

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
    let (p64, f64_) = (median(preview64), median(full64));

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
    let threads = session.threads();
    println!("viewer latency, default scene 1280x720, {threads} threads, median of 10 edits");
    println!("  batch 1-spp render (baseline): {:.1} ms", batch * 1e3);
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
    println!(
        "  UI thread per frame taking tiles: median {:.2} ms, worst {:.2} ms over {} frames",
        median(frames.clone()) * 1e3,
        worst * 1e3,
        frames.len()
    );
}
