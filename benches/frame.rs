//! The viewer's UI work per frame with the ray trees in 3D, measured (never asserted): 64 trees
//! drawn over the render and in the scene view, the selected ray's traversal boxes and every
//! box of one BVH level, on a kitchen-sized scene (a ~60k-triangle mesh with a mirror and a
//! glass sphere), in a 1600×1000 window through egui_kittest on the software renderer. A frame
//! is one `Harness::step` (the app's UI, layout and tessellation) after both renders finished;
//! the baseline is the same frame without trees or boxes, measured in the same run.
//!
//! Run: `cargo bench --bench frame`, or e.g. `cargo bench --bench frame -- --triangles 1000000
//! --level deepest` for the deepest level of a million-triangle tree.

use std::time::{Duration, Instant};

use egui_kittest::Harness;
use raytree::app::{Command, ViewerApp};
use raytree::scene::load_scene_file;
use raytree::scene::procedural::write_bench_scene;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn settle(h: &mut Harness<'static, ViewerApp>) {
    let deadline = Instant::now() + Duration::from_secs(600);
    while !h.state().is_finished() || !h.state().scene_view.is_finished() {
        assert!(Instant::now() < deadline, "the render did not finish");
        h.step();
        std::thread::sleep(Duration::from_millis(5));
    }
    h.step();
}

/// Median and worst time of `n` frames.
fn frames(h: &mut Harness<'static, ViewerApp>, n: usize) -> (f64, f64) {
    let mut times = Vec::with_capacity(n);
    for _ in 0..n {
        let t = Instant::now();
        h.step();
        times.push(t.elapsed().as_secs_f64());
    }
    let worst = times.iter().copied().fold(0.0, f64::max);
    (median(times), worst)
}

fn main() {
    // `--triangles N` (default 60,000) sizes the mesh; `--level K` draws BVH level K instead of
    // the middle one (`--level deepest` the last).
    let (mut triangles, mut level_arg) = (60_000usize, None::<String>);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--triangles" => {
                triangles = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .expect("--triangles: a number")
            }
            "--level" => level_arg = Some(args.next().expect("--level: a number or deepest")),
            "--bench" => {}
            other => panic!("unknown option {other}"),
        }
    }
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = write_bench_scene(dir.path(), triangles).expect("the bench scene is written");
    let scene = load_scene_file(&path).expect("the bench scene loads");
    let (w, h_px) = (scene.render.width, scene.render.height);
    let triangles = scene.triangles.len();
    let renderer = egui_kittest::wgpu::WgpuTestRenderer::new();
    let mut h = Harness::builder()
        .with_size([1600.0, 1000.0])
        .renderer(renderer)
        .build_eframe(|cc| {
            // The scene's size and sample count, not the viewer's own target (quick to settle).
            let samples = scene.render.samples;
            let mut app = ViewerApp::new(cc, scene, "kitchen".into()).expect("the viewer");
            app.set_view(samples, false);
            app.workspace.set_settings_panel(true);
            app
        });
    settle(&mut h);
    let (base, base_worst) = frames(&mut h, 60);

    // 64 trees: one clicked, 63 more over an 8x8 grid of the image.
    h.state_mut().command(Command::Pick(w / 2, h_px / 2));
    h.state_mut().command(Command::PickRect(
        [w / 8, h_px / 8],
        [w * 7 / 8, h_px * 7 / 8],
    ));
    h.step();
    let trees = h.state().selection.trees().count();
    let nodes: usize = h.state().selection.trees().map(|t| t.nodes).sum();
    // The selected ray's visits are on by default; add every box of one BVH level.
    let levels = h.state().accel().levels();
    let last = levels.saturating_sub(1);
    let level = match level_arg.as_deref() {
        None => (levels / 2).max(1).min(last),
        Some("deepest") => last,
        Some(k) => k
            .parse::<u32>()
            .expect("--level: a number or deepest")
            .min(last),
    };
    let shown = raytree::scene_view::level_segments(h.state().accel(), level);
    let boxes = format!("{} of {} boxes drawn", shown.drawn, shown.total);
    h.state_mut().scene_view.bvh_level = Some(level);
    settle(&mut h);
    let (full, full_worst) = frames(&mut h, 60);

    println!(
        "viewer frame, {triangles}-triangle scene ({w}x{h_px}), 1600x1000 window, median of 60 frames"
    );
    println!(
        "  baseline (no trees):                       median {:.2} ms, worst {:.2} ms",
        base * 1e3,
        base_worst * 1e3
    );
    println!(
        "  {trees} trees ({nodes} nodes), visits, BVH level {level} ({boxes}): median {:.2} ms ({:.2}x the baseline), worst {:.2} ms",
        full * 1e3,
        full / base,
        full_worst * 1e3
    );
}
