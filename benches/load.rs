//! OBJ loading, measured (never asserted): raytree's parallel reader (`scene::obj::parse`)
//! against `tobj` in the same run, on the same text already in memory, and the whole bare-OBJ
//! load (`load_scene_file`: read, parse, place, drop degenerate triangles, frame a camera).
//! Two meshes of about `--triangles` triangles: the benchmark torus (`v` and `f a b c` only,
//! as `cargo bench --bench peer` writes it) and the same torus with `vt`, `vn` and
//! `f a/a/a b/b/b c/c/c` faces. Runs alternate between the readers; median and spread printed.
//!
//! Run: `cargo bench --bench load -- --triangles 1280000 --runs 5 --threads 2 [--keep DIR]`;
//! `--whole` times only `load_scene_file` (to profile it), `--memory` the BVH build's memory.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use raytree::scene::obj::parse;
use raytree::scene::procedural::{bumpy_torus_obj, torus_grid};

struct Options {
    triangles: usize,
    runs: usize,
    threads: usize,
    keep: Option<PathBuf>,
    /// Only the build-memory measurement.
    memory: bool,
    /// Only the viewer's open of a big OBJ: its load, build and longest frame.
    viewer: bool,
    /// Only `load_scene_file` (no readers alone, no tobj): for profiling the whole load.
    whole: bool,
}

fn options() -> Options {
    let mut o = Options {
        triangles: 1_280_000,
        runs: 5,
        threads: 2,
        keep: None,
        memory: false,
        viewer: false,
        whole: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |name: &str| {
            args.next()
                .unwrap_or_else(|| panic!("{name} needs a value"))
        };
        match a.as_str() {
            "--triangles" => o.triangles = value("--triangles").parse().expect("a number"),
            "--runs" => o.runs = value("--runs").parse().expect("a number"),
            "--threads" => o.threads = value("--threads").parse().expect("a number"),
            "--keep" => o.keep = Some(PathBuf::from(value("--keep"))),
            "--memory" => o.memory = true,
            "--viewer" => o.viewer = true,
            "--whole" => o.whole = true,
            "--bench" => {}
            other => panic!("unknown option {other}"),
        }
    }
    o
}

/// The torus of [`bumpy_torus_obj`] with a texture coordinate and a normal per vertex (the
/// torus's own parameters and analytic normals), faces `v/vt/vn`.
fn textured_torus_obj(triangles: usize) -> String {
    let (nu, nv) = torus_grid(triangles);
    let (ring, tube) = (1.35f64, 0.5f64);
    let mut out = String::with_capacity(nu * nv * 150);
    let _ = writeln!(out, "# torus with vt and vn, {} triangles", 2 * nu * nv);
    let _ = writeln!(out, "o torus");
    for pass in 0..3 {
        for i in 0..nu {
            let u = std::f64::consts::TAU * i as f64 / nu as f64;
            for j in 0..nv {
                let v = std::f64::consts::TAU * j as f64 / nv as f64;
                let (su, cu) = u.sin_cos();
                let (sv, cv) = v.sin_cos();
                let _ = match pass {
                    0 => writeln!(
                        out,
                        "v {:?} {:?} {:?}",
                        ((ring + tube * cv) * cu) as f32,
                        (tube * sv) as f32,
                        ((ring + tube * cv) * su) as f32
                    ),
                    1 => writeln!(
                        out,
                        "vt {:?} {:?}",
                        (i as f64 / nu as f64) as f32,
                        (j as f64 / nv as f64) as f32
                    ),
                    _ => writeln!(
                        out,
                        "vn {:?} {:?} {:?}",
                        (cv * cu) as f32,
                        sv as f32,
                        (cv * su) as f32
                    ),
                };
            }
        }
    }
    let index = |i: usize, j: usize| (i % nu) * nv + (j % nv) + 1;
    for i in 0..nu {
        for j in 0..nv {
            let (a, b) = (index(i, j), index(i + 1, j));
            let (c, d) = (index(i + 1, j + 1), index(i, j + 1));
            let _ = writeln!(out, "f {a}/{a}/{a} {d}/{d}/{d} {c}/{c}/{c}");
            let _ = writeln!(out, "f {a}/{a}/{a} {c}/{c}/{c} {b}/{b}/{b}");
        }
    }
    out
}

/// CPU seconds (user and system, all threads) this process has used so far, from
/// `/proc/self/stat` (Linux; 0 elsewhere): on a shared machine the wall time also counts
/// other processes' turns.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the parenthesised command name: state is field 3, utime 14, stime 15.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn stats(mut v: Vec<f64>) -> String {
    v.sort_by(f64::total_cmp);
    format!(
        "median {:.3} s (min {:.3}, max {:.3})",
        v[v.len() / 2],
        v[0],
        v[v.len() - 1]
    )
}

/// A `/proc/self/status` value in bytes (`VmRSS`, `VmHWM`), 0 where there is none.
fn status_bytes(key: &str) -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|rest| {
            rest.trim()
                .trim_end_matches("kB")
                .trim()
                .parse::<u64>()
                .ok()
        })
        .map_or(0, |kb| kb * 1024)
}

/// The BVH build's memory on the benchmark torus of `triangles` triangles loaded as a bare
/// OBJ: the resident set before the build, the peak during it (the kernel's peak is reset
/// first through `/proc/self/clear_refs`), and what the scene and accelerator keep.
fn build_memory(triangles: usize, root: &std::path::Path) {
    let file = root.join("build_memory.obj");
    std::fs::write(&file, bumpy_torus_obj(triangles)).expect("the OBJ is written");
    let scene = std::sync::Arc::new(raytree::scene::load_scene_file(&file).expect("it loads"));
    let before = status_bytes("VmRSS:");
    let reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
    let t = Instant::now();
    let tracer = raytree::trace::Tracer::new(scene.clone(), Default::default());
    let secs = t.elapsed().as_secs_f64();
    let peak = status_bytes("VmHWM:");
    let after = status_bytes("VmRSS:");
    let accel = tracer.accel.memory_bytes() as u64;
    let records = (scene.triangles.capacity() * size_of::<raytree::scene::Triangle>()) as u64;
    let mb = |b: u64| b as f64 / 1e6;
    println!(
        "BVH build of {} triangles: {secs:.2} s; resident before {:.0} MB, after {:.0} MB, peak during {:.0} MB{}",
        scene.triangles.len(),
        mb(before),
        mb(after),
        mb(peak),
        if reset {
            ""
        } else {
            " (peak not reset: whole process)"
        }
    );
    println!(
        "  kept: accelerator {:.0} MB + scene triangles {:.0} MB = {:.0} MB; build peak above the loaded scene {:.0} MB; peak / kept {:.2}",
        mb(accel),
        mb(records),
        mb(accel + records),
        mb(peak.saturating_sub(before)),
        peak as f64 / (accel + records) as f64
    );
}

/// The headless viewer opens the benchmark torus as a bare OBJ: the time `apply` takes (the
/// UI thread reads and parses the file), then frames (`poll_session` + `apply`, as the window's
/// frame does) until the new tracer is in and its first pass is done; the longest such frame.
#[cfg(feature = "viewer")]
fn viewer_open(triangles: usize, root: &std::path::Path) {
    use raytree::app::{Command, ViewerApp};
    let file = root.join("viewer_open.obj");
    std::fs::write(&file, bumpy_torus_obj(triangles)).expect("the OBJ is written");
    let mut app = ViewerApp::headless(
        raytree::scene::builtin::load_builtin("default").expect("a built-in scene"),
        "default".into(),
    )
    .expect("the viewer");
    while !app.is_finished() {
        app.poll_session();
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    let t = Instant::now();
    app.command(Command::OpenFile(file.clone()));
    app.apply();
    let open = t.elapsed().as_secs_f64();
    let mut longest: f64 = 0.0;
    let mut frames = 0;
    while app.scene().source.as_deref() != Some(file.as_path()) || app.samples_done() == 0 {
        let f = Instant::now();
        let before = app.scene().triangles.len();
        app.poll_session();
        app.apply();
        let dt = f.elapsed().as_secs_f64();
        if app.scene().triangles.len() != before {
            println!(
                "  the frame that installs the built tracer: {:.1} ms",
                dt * 1e3
            );
        }
        longest = longest.max(dt);
        frames += 1;
        std::thread::sleep(std::time::Duration::from_millis(16));
    }
    println!(
        "viewer opens {} triangles: open (read + parse on the UI thread) {open:.2} s; built and first pass after {:.2} s; {frames} frames meanwhile, the longest {:.1} ms",
        app.scene().triangles.len(),
        t.elapsed().as_secs_f64(),
        longest * 1e3
    );
}

#[cfg(not(feature = "viewer"))]
fn viewer_open(_: usize, _: &std::path::Path) {
    println!("--viewer needs the `viewer` feature");
}

fn main() {
    let o = options();
    rayon::ThreadPoolBuilder::new()
        .num_threads(o.threads)
        .build_global()
        .expect("the thread pool");
    if o.viewer {
        let tmp = tempfile::tempdir().expect("a temporary folder");
        viewer_open(o.triangles, tmp.path());
        return;
    }
    if o.memory {
        let tmp = tempfile::tempdir().expect("a temporary folder");
        build_memory(o.triangles, tmp.path());
        return;
    }
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let root = o.keep.clone().unwrap_or_else(|| tmp.path().to_path_buf());
    std::fs::create_dir_all(&root).expect("the output folder");
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "OBJ load, {} threads, {} runs each, alternating (load average {})",
        o.threads,
        o.runs,
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    );
    for (name, text) in [
        ("plain (v, f)", bumpy_torus_obj(o.triangles)),
        ("v, vt, vn, f v/vt/vn", textured_torus_obj(o.triangles)),
    ] {
        let file = root.join(if name.starts_with("plain") {
            "load_plain.obj"
        } else {
            "load_vt_vn.obj"
        });
        std::fs::write(&file, &text).expect("the OBJ is written");
        let (mut fast, mut slow, mut whole) = (Vec::new(), Vec::new(), Vec::new());
        let (mut fast_cpu, mut slow_cpu, mut whole_cpu) = (Vec::new(), Vec::new(), Vec::new());
        let mut triangles = 0;
        for _ in 0..o.runs {
            if o.whole {
                let (t, c) = (Instant::now(), cpu_seconds());
                let scene = raytree::scene::load_scene_file(&file).expect("the scene loads");
                whole.push(t.elapsed().as_secs_f64());
                whole_cpu.push(cpu_seconds() - c);
                triangles = scene.triangles.len();
                drop(scene);
                continue;
            }
            let (t, c) = (Instant::now(), cpu_seconds());
            let a = parse::parse(&text, |_| Ok(Default::default()))
                .expect("the fast reader takes the benchmark mesh")
                .expect("it loads");
            fast.push(t.elapsed().as_secs_f64());
            fast_cpu.push(cpu_seconds() - c);
            triangles = a.0.iter().map(|m| m.mesh.indices.len() / 3).sum::<usize>();
            drop(a);
            let (t, c) = (Instant::now(), cpu_seconds());
            let b = tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| Ok(Default::default()))
                .expect("tobj loads it");
            slow.push(t.elapsed().as_secs_f64());
            slow_cpu.push(cpu_seconds() - c);
            drop(b);
            let (t, c) = (Instant::now(), cpu_seconds());
            let scene = raytree::scene::load_scene_file(&file).expect("the scene loads");
            whole.push(t.elapsed().as_secs_f64());
            whole_cpu.push(cpu_seconds() - c);
            drop(scene);
        }
        println!(
            "{name}: {triangles} triangles, {:.1} MB of text",
            text.len() as f64 / 1e6
        );
        if o.whole {
            println!(
                "  load_scene_file (read, parse, place, frame): {}; CPU seconds {:.2}",
                stats(whole),
                median(&whole_cpu)
            );
            continue;
        }
        let (f, s) = (median(&fast), median(&slow));
        println!("  raytree obj_parse: {}", stats(fast));
        println!("  tobj 4.0.5:        {}", stats(slow));
        println!(
            "  tobj time / obj_parse time: {:.2}; CPU seconds (all threads): obj_parse {:.2}, tobj {:.2}",
            s / f,
            median(&fast_cpu),
            median(&slow_cpu)
        );
        println!(
            "  load_scene_file (read, parse, place, frame): {}; CPU seconds {:.2}",
            stats(whole),
            median(&whole_cpu)
        );
    }
}
