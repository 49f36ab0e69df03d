//! The viewer opening a big OBJ, measured (never asserted): the headless viewer opens the
//! benchmark torus as a bare OBJ while the UI loop runs (poll + apply, a 16 ms sleep between
//! frames, as a window would). Per frame: the wall time and the UI thread's own CPU time and
//! run-queue wait (`/proc/thread-self/schedstat`), so a frame stretched by a loaded machine is
//! told apart from one that worked. Beside it, in the same run, what opening on the UI thread
//! would cost: the whole load (`load_scene_file`) and the scene view's copy of the scene.
//!
//! Run: `cargo bench --bench open -- --triangles 1000000 --runs 3 --threads 2`

use std::time::{Duration, Instant};

use raytree::app::{Command, ViewerApp};
use raytree::scene::builtin::load_builtin;
use raytree::scene::procedural::bumpy_torus_obj;

/// The calling thread's time on the CPU and waiting to run, in seconds.
fn schedstat() -> (f64, f64) {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    let mut fields = text
        .split_whitespace()
        .map(|f| f.parse::<f64>().unwrap_or(0.0));
    let on_cpu = fields.next().unwrap_or(0.0);
    let waiting = fields.next().unwrap_or(0.0);
    (on_cpu * 1e-9, waiting * 1e-9)
}

fn main() {
    let mut triangles = 1_000_000usize;
    let mut runs = 3usize;
    let mut threads = 2usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().and_then(|v| v.parse().ok()).expect("a number");
        match a.as_str() {
            "--triangles" => triangles = value(),
            "--runs" => runs = value(),
            "--threads" => threads = value(),
            "--bench" => {}
            other => panic!("unknown option {other}"),
        }
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .expect("the thread pool");
    let dir = tempfile::tempdir().expect("a temporary folder");
    let file = dir.path().join("open.obj");
    std::fs::write(&file, bumpy_torus_obj(triangles)).expect("the OBJ is written");
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "viewer open of {} MB of OBJ, {threads} threads, load average {}",
        std::fs::metadata(&file).map(|m| m.len()).unwrap_or(0) / 1_000_000,
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    );
    for run in 0..runs {
        // What the UI thread did before: the whole load, then a copy of the scene for the
        // scene view.
        let t = Instant::now();
        let scene = raytree::scene::load_scene_file(&file).expect("the OBJ loads");
        let old_load = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let copy = scene.clone();
        let old_copy = t.elapsed().as_secs_f64();
        drop((scene, copy));

        let mut app = ViewerApp::headless(
            load_builtin("default").expect("a built-in scene"),
            "default".into(),
        )
        .expect("the viewer");
        while !app.is_finished() {
            app.poll_session();
            std::thread::sleep(Duration::from_millis(1));
        }
        let t = Instant::now();
        app.command(Command::OpenFile(file.clone()));
        app.apply();
        let command = t.elapsed().as_secs_f64();
        // (wall, on CPU, waiting) of the longest frame by wall time and by CPU time.
        let (mut by_wall, mut by_cpu) = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0));
        let mut frames = 0;
        let mut installed_after = None;
        while app.files.opening().is_some() || app.samples_done() == 0 {
            let (c0, w0) = schedstat();
            let f = Instant::now();
            app.poll_session();
            app.apply();
            let wall = f.elapsed().as_secs_f64();
            let (c1, w1) = schedstat();
            let frame = (wall, c1 - c0, w1 - w0);
            if frame.0 > by_wall.0 {
                by_wall = frame;
            }
            if frame.1 > by_cpu.1 {
                by_cpu = frame;
            }
            if installed_after.is_none() && app.files.opening().is_none() {
                installed_after = Some(t.elapsed().as_secs_f64());
            }
            frames += 1;
            std::thread::sleep(Duration::from_millis(16));
        }
        let ms = |(w, c, q): (f64, f64, f64)| {
            format!(
                "{:.1} ms (on CPU {:.1} ms, waiting to run {:.1} ms)",
                w * 1e3,
                c * 1e3,
                q * 1e3
            )
        };
        println!(
            "run {run}: before, on the UI thread: load {old_load:.2} s + scene copy {:.0} ms",
            old_copy * 1e3
        );
        println!(
            "  now: open command {:.2} ms; installed after {:.2} s, first pass after {:.2} s; {frames} frames",
            command * 1e3,
            installed_after.unwrap_or(0.0),
            t.elapsed().as_secs_f64()
        );
        println!("  longest frame by wall time: {}", ms(by_wall));
        println!("  longest frame by CPU time:  {}", ms(by_cpu));
        if let Some(o) = app.files.last_open {
            println!(
                "  background: read {:.2} s, parse {:.2} s, copy + build {:.2} s ({} triangles)",
                o.read_secs, o.parse_secs, o.build_secs, o.triangles
            );
        }
    }
}
