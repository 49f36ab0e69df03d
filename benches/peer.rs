//! Issue 7: raytree against a peer in the same run. The peer is `benches/peer/embree_whitted.c`,
//! a Whitted renderer over Debian's Embree 3 (`apt-get install libembree-dev`), compiled here
//! with the system C compiler (`$CC`, else `cc`) into a temp dir; without Embree the peer is
//! skipped with a message and raytree runs alone.
//!
//! Both render the procedural scene of [`raytree::scene::procedural`] (a bumpy torus of N
//! triangles, a mirror sphere, a glass sphere, a floor, two point lights; 640×480, 1 sample,
//! depth 4 below the primary ray) on the same number of threads, each in its own process:
//! raytree through `raytree render bench.toml --stats-json`, the peer from a binary copy of the
//! very scene raytree loaded, runs alternating. Reported: render-phase Mrays/s (median of the
//! runs), their ratio (the median, smallest and largest of the ratios of each raytree run to
//! the Embree run after it), load and build seconds, bytes per triangle, peak memory, rays by
//! kind (which must agree within a few percent) and how many pixels differ between the two
//! images.
//!
//! Run: `cargo bench --bench peer` (80k and 320k triangles, 2 threads, 7 runs each), or e.g.
//! `cargo bench --bench peer -- --sizes 1000,1000000 --threads 1 --runs 5 --keep /tmp/b`.
//! `--size 1280x960` renders more rays than the scene's 640×480 (a longer, steadier render
//! phase on a noisy machine). `--embree-quality high` (or `low`) builds Embree's BVH at that
//! quality instead of its default, medium. `--scaling` instead prints raytree's build and render time against
//! triangle count (1k to 4M) on 1 and 2 threads, and with `--chart FILE.png` draws it.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use raytree::experiments::chart::{Chart, Series, write_chart};
use raytree::scene::procedural::{torus_triangles, write_bench_scene};
use raytree::scene::{Scene, Shading, load_scene_file};

const HARNESS_SOURCE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/peer/embree_whitted.c");

struct Options {
    sizes: Vec<usize>,
    threads: usize,
    runs: usize,
    keep: Option<PathBuf>,
    scaling: bool,
    peer: bool,
    embree_quality: Option<String>,
    chart: Option<PathBuf>,
    /// Image size instead of the scene's 640×480 (more rays: a longer, steadier render phase).
    size: Option<(u32, u32)>,
}

fn parse_options() -> Options {
    let mut o = Options {
        sizes: vec![80_000, 320_000],
        threads: 2,
        runs: 7,
        keep: None,
        scaling: false,
        peer: true,
        embree_quality: None,
        chart: None,
        size: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| {
            args.next()
                .unwrap_or_else(|| panic!("{name} needs a value"))
        };
        match arg.as_str() {
            "--sizes" => {
                o.sizes = value("--sizes")
                    .split(',')
                    .map(|s| s.trim().parse().expect("--sizes: whole numbers"))
                    .collect();
            }
            "--threads" => o.threads = value("--threads").parse().expect("--threads: a number"),
            "--runs" => o.runs = value("--runs").parse().expect("--runs: a number"),
            "--keep" => o.keep = Some(PathBuf::from(value("--keep"))),
            "--scaling" => o.scaling = true,
            "--no-peer" => o.peer = false,
            "--embree-quality" => o.embree_quality = Some(value("--embree-quality")),
            "--chart" => o.chart = Some(PathBuf::from(value("--chart"))),
            "--size" => {
                let v = value("--size");
                let (w, h) = v.split_once('x').expect("--size: WIDTHxHEIGHT");
                o.size = Some((
                    w.parse().expect("--size: a whole width"),
                    h.parse().expect("--size: a whole height"),
                ));
            }
            // `cargo bench` passes `--bench`; filters and the rest are not ours.
            _ => {}
        }
    }
    o.runs = o.runs.max(1);
    o
}

/// One render's figures, from either renderer.
#[derive(Clone, Debug, Default)]
struct Run {
    load_secs: f64,
    build_secs: f64,
    render_secs: f64,
    rays: [u64; 4],
    /// Bytes the ray tracer keeps per triangle (raytree: scene triangles + accelerator;
    /// Embree: vertex and index buffers + what its memory monitor saw at peak).
    bytes_per_triangle: f64,
    peak_rss_bytes: u64,
}

impl Run {
    fn total_rays(&self) -> u64 {
        self.rays.iter().sum()
    }
    fn mrays(&self) -> f64 {
        self.total_rays() as f64 / self.render_secs / 1e6
    }
}

fn median_by(runs: &[Run], key: impl Fn(&Run) -> f64) -> f64 {
    let mut v: Vec<f64> = runs.iter().map(key).collect();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The median run by render time, with load and build replaced by their own medians.
fn summary(runs: &[Run]) -> Run {
    let render = median_by(runs, |r| r.render_secs);
    let mut out = runs
        .iter()
        .find(|r| r.render_secs == render)
        .cloned()
        .unwrap_or_default();
    out.load_secs = median_by(runs, |r| r.load_secs);
    out.build_secs = median_by(runs, |r| r.build_secs);
    out
}

fn raytree_run(scene_file: &Path, image: &Path, threads: usize, size: Option<(u32, u32)>) -> Run {
    let stats = image.with_extension("json");
    let mut command = Command::new(env!("CARGO_BIN_EXE_raytree"));
    command.arg("render").arg(scene_file);
    if let Some((w, h)) = size {
        command.args(["--width", &w.to_string(), "--height", &h.to_string()]);
    }
    let output = command
        .arg("-o")
        .arg(image)
        .args(["--quiet", "--threads", &threads.to_string(), "--stats-json"])
        .arg(&stats)
        .output()
        .expect("run raytree");
    assert!(
        output.status.success(),
        "raytree render failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = std::fs::read_to_string(&stats).expect("read the stats JSON");
    let json: serde_json::Value = serde_json::from_str(&text).expect("stats JSON");
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    let s = &json["stats"];
    let r = &s["rays"];
    Run {
        load_secs: f(&json["load_secs"]),
        build_secs: f(&s["build_secs"]),
        render_secs: f(&s["render_secs"]),
        rays: ["primary", "reflected", "refracted", "shadow"]
            .map(|k| r[k].as_u64().unwrap_or_default()),
        bytes_per_triangle: f(&json["memory"]["bytes_per_triangle"]),
        peak_rss_bytes: json["memory"]["peak_bytes"].as_u64().unwrap_or_default(),
    }
}

/// The scene in the harness's binary format (see `load_scene` in the C file). Lights must be
/// invisible points (radius 0), as in the bench scene.
fn write_peer_scene(scene: &Scene, path: &Path) {
    let mut b: Vec<u8> = Vec::new();
    let u = |b: &mut Vec<u8>, v: u32| b.extend_from_slice(&v.to_le_bytes());
    let f = |b: &mut Vec<u8>, v: f32| b.extend_from_slice(&v.to_le_bytes());
    let v3 = |b: &mut Vec<u8>, v: glam::Vec3| {
        for c in v.to_array() {
            b.extend_from_slice(&c.to_le_bytes());
        }
    };
    b.extend_from_slice(b"RTPEER01");
    let r = &scene.render;
    u(&mut b, r.width);
    u(&mut b, r.height);
    u(&mut b, r.max_depth);
    u(&mut b, u32::from(r.shading == Shading::BlinnPhong));
    let c = &scene.camera;
    v3(&mut b, c.position);
    v3(&mut b, c.look_at);
    v3(&mut b, c.up);
    f(&mut b, c.fov_y_deg);
    v3(&mut b, r.background);
    v3(&mut b, r.ambient_light);
    u(&mut b, scene.materials.len() as u32);
    for m in &scene.materials {
        v3(&mut b, m.ambient);
        v3(&mut b, m.diffuse);
        v3(&mut b, m.specular);
        f(&mut b, m.shininess);
        v3(&mut b, m.reflectivity);
        v3(&mut b, m.transparency);
        f(&mut b, m.ior);
    }
    u(&mut b, scene.lights.len() as u32);
    for l in &scene.lights {
        assert!(l.radius == 0.0, "the peer takes point lights only");
        v3(&mut b, l.position);
        v3(&mut b, l.color);
    }
    u(&mut b, scene.spheres.len() as u32);
    for s in &scene.spheres {
        v3(&mut b, s.center);
        f(&mut b, s.radius);
        u(&mut b, s.material.0);
    }
    u(&mut b, scene.triangles.len() as u32);
    for t in &scene.triangles {
        for v in t.vertices {
            v3(&mut b, v);
        }
    }
    for t in &scene.triangles {
        u(&mut b, t.material.0);
    }
    std::fs::write(path, b).expect("write the peer scene");
}

/// Compiles the harness; `None` (with the reason printed) when Embree or a C compiler is
/// missing.
fn build_harness(dir: &Path) -> Option<PathBuf> {
    let exe = dir.join("embree_whitted");
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let output = Command::new(&compiler)
        .args(["-O2", "-ffp-contract=off", "-o"])
        .arg(&exe)
        .arg(HARNESS_SOURCE)
        .args(["-lembree3", "-lpthread", "-lm"])
        .output();
    match output {
        Ok(o) if o.status.success() => Some(exe),
        Ok(o) => {
            let err = String::from_utf8_lossy(&o.stderr);
            let reason = if err.contains("embree3/rtcore.h") || err.contains("lembree3") {
                "Embree 3 is not installed (Debian: apt-get install libembree-dev)".to_string()
            } else {
                format!("{compiler} failed:\n{err}")
            };
            println!("peer skipped: {reason}");
            None
        }
        Err(e) => {
            println!("peer skipped: cannot run the C compiler `{compiler}`: {e}");
            None
        }
    }
}

fn harness_run(
    exe: &Path,
    scene_bin: &Path,
    image: &Path,
    threads: usize,
    quality: Option<&str>,
) -> Run {
    let mut command = Command::new(exe);
    if let Some(q) = quality {
        command.env("EMBREE_WHITTED_QUALITY", q);
    }
    let output = command
        .arg(scene_bin)
        .arg(threads.to_string())
        .arg(image)
        .output()
        .expect("run the Embree harness");
    assert!(
        output.status.success(),
        "the Embree harness failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8_lossy(&output.stdout);
    let get = |key: &str| -> f64 {
        text.lines()
            .find_map(|l| l.strip_prefix(key)?.strip_prefix(' '))
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or(f64::NAN)
    };
    let triangles = get("triangles");
    Run {
        load_secs: get("load_secs"),
        build_secs: get("build_secs"),
        render_secs: get("render_secs"),
        rays: ["primary", "reflected", "refracted", "shadow"].map(|k| get(k) as u64),
        bytes_per_triangle: (get("embree_peak_bytes") + get("geometry_bytes")) / triangles,
        peak_rss_bytes: (get("peak_rss_kb") * 1024.0) as u64,
    }
}

/// Pixels whose 8-bit sRGB values differ by more than 2 in some channel: raytree's PNG
/// against the harness's linear float image.
fn differing_pixels(png_path: &Path, f32_path: &Path, width: u32, height: u32) -> usize {
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(png_path).expect("open raytree's PNG"),
    ));
    let mut reader = decoder.read_info().expect("PNG header");
    let mut ours = vec![0; reader.output_buffer_size().expect("PNG size")];
    reader.next_frame(&mut ours).expect("PNG data");
    let theirs = std::fs::read(f32_path).expect("read the harness image");
    let theirs: Vec<f32> = theirs
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    (0..(width * height) as usize)
        .filter(|&i| {
            let c = glam::Vec3::new(theirs[3 * i], theirs[3 * i + 1], theirs[3 * i + 2]);
            let t = raytree::export::to_srgb8(c);
            (0..3).any(|k| (ours[3 * i + k] as i32 - t[k] as i32).abs() > 2)
        })
        .count()
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

fn mb(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn peer_comparison(o: &Options, root: &Path) {
    let harness = if o.peer { build_harness(root) } else { None };
    println!(
        "issue-7 peer bench: {} threads, {} runs each (median), Embree build quality {}, load average before: {}",
        o.threads,
        o.runs,
        o.embree_quality.as_deref().unwrap_or("medium (default)"),
        load_average()
    );
    let mut rows = Vec::new();
    for &size in &o.sizes {
        let dir = root.join(format!("tris_{size}"));
        let scene_file = write_bench_scene(&dir, size).expect("write the bench scene");
        let mut scene = load_scene_file(&scene_file).expect("load the bench scene");
        if let Some((w, h)) = o.size {
            (scene.render.width, scene.render.height) = (w, h);
        }
        let scene_bin = dir.join("scene.bin");
        write_peer_scene(&scene, &scene_bin);
        let (ours_png, theirs_f32) = (dir.join("raytree.png"), dir.join("embree.f32"));
        let mut ours = Vec::new();
        let mut theirs = Vec::new();
        for _ in 0..o.runs {
            ours.push(raytree_run(&scene_file, &ours_png, o.threads, o.size));
            if let Some(exe) = &harness {
                theirs.push(harness_run(
                    exe,
                    &scene_bin,
                    &theirs_f32,
                    o.threads,
                    o.embree_quality.as_deref(),
                ));
            }
        }
        let diff = harness.as_ref().map(|_| {
            differing_pixels(
                &ours_png,
                &theirs_f32,
                scene.render.width,
                scene.render.height,
            )
        });
        // Each raytree run is paired with the Embree run right after it: the median of the
        // pairs' ratios is steadier on a shared machine than the ratio of the two medians,
        // and the pairs' spread shows how steady.
        let mut ratios: Vec<f64> = ours
            .iter()
            .zip(&theirs)
            .map(|(a, b)| a.mrays() / b.mrays())
            .collect();
        ratios.sort_by(f64::total_cmp);
        let ratio = (!ratios.is_empty()).then(|| {
            (
                ratios[ratios.len() / 2],
                ratios[0],
                ratios[ratios.len() - 1],
            )
        });
        rows.push((
            scene.triangles.len(),
            summary(&ours),
            (!theirs.is_empty()).then(|| summary(&theirs)),
            diff,
            ratio,
        ));
        let _ = std::io::stdout().flush();
    }
    println!("load average after: {}", load_average());
    println!();
    println!(
        "| triangles | raytree Mrays/s | Embree Mrays/s | ratio (pairs: median, min–max) | load s (rt / E) | build s (rt / E) | render s (rt / E) | bytes/tri (rt / E) | peak MB (rt / E) |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let pair = |a: f64, b: Option<f64>, digits: usize| match b {
        Some(b) => format!("{a:.digits$} / {b:.digits$}"),
        None => format!("{a:.digits$} / –"),
    };
    for (tris, r, e, _, ratio) in &rows {
        let em = e.as_ref().map(Run::mrays);
        println!(
            "| {} | {:.2} | {} | {} | {} | {} | {} | {} | {} |",
            tris,
            r.mrays(),
            em.map_or("–".into(), |m| format!("{m:.2}")),
            ratio.map_or("–".into(), |(m, lo, hi)| format!(
                "**{m:.2}** ({lo:.2}–{hi:.2})"
            )),
            pair(r.load_secs, e.as_ref().map(|e| e.load_secs), 3),
            pair(r.build_secs, e.as_ref().map(|e| e.build_secs), 3),
            pair(r.render_secs, e.as_ref().map(|e| e.render_secs), 3),
            pair(
                r.bytes_per_triangle,
                e.as_ref().map(|e| e.bytes_per_triangle),
                0
            ),
            pair(
                mb(r.peak_rss_bytes),
                e.as_ref().map(|e| mb(e.peak_rss_bytes)),
                0
            ),
        );
    }
    println!();
    println!(
        "| triangles | rays raytree (P / R / T / S) | rays Embree (P / R / T / S) | total differs | pixels differing (> 2/255) |"
    );
    println!("|---:|---:|---:|---:|---:|");
    for (tris, r, e, diff, _) in &rows {
        let kinds = |x: &Run| {
            let [p, rf, t, s] = x.rays;
            format!("{p} / {rf} / {t} / {s}")
        };
        let (their_kinds, delta) = match e {
            Some(e) => {
                let d = (r.total_rays() as f64 - e.total_rays() as f64) / e.total_rays() as f64;
                (kinds(e), format!("{:+.2} %", 100.0 * d))
            }
            None => ("–".into(), "–".into()),
        };
        let diff = diff.map_or("–".into(), |d| {
            format!(
                "{d} ({:.2} %)",
                100.0 * d as f64 / (r.rays[0].max(1)) as f64
            )
        });
        println!(
            "| {tris} | {} | {their_kinds} | {delta} | {diff} |",
            kinds(r)
        );
        if let Some(e) = e {
            let d = (r.total_rays() as f64 / e.total_rays() as f64 - 1.0).abs();
            assert!(
                d < 0.03,
                "ray counts differ by {:.1} %: the renderers do not trace the same thing",
                100.0 * d
            );
        }
    }
}

/// (triangles, build seconds, render seconds) at one thread count.
type ScalingPoint = (f64, f64, f64);

fn scaling(o: &Options, root: &Path) {
    let sizes = [
        1_000, 10_000, 100_000, 320_000, 1_000_000, 2_000_000, 4_000_000,
    ];
    println!(
        "raytree scaling, bench scene 640×480, median of {} runs; load average before: {}",
        o.runs,
        load_average()
    );
    println!();
    println!(
        "| triangles | build s, 1 thread | build s, 2 threads | render s, 1 thread | render s, 2 threads | Mrays/s, 1 thread | Mrays/s, 2 threads | bytes/tri |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut csv = String::from(
        "triangles,threads,load_secs,build_secs,render_secs,mrays_per_sec,bytes_per_triangle\n",
    );
    let mut series: Vec<(usize, Vec<ScalingPoint>)> = vec![(1, Vec::new()), (2, Vec::new())];
    for size in sizes {
        let dir = root.join(format!("scaling_{size}"));
        let scene_file = write_bench_scene(&dir, size).expect("write the bench scene");
        let png = dir.join("raytree.png");
        let triangles = torus_triangles(size) + 2;
        let mut by_threads = Vec::new();
        for (threads, points) in &mut series {
            let runs: Vec<Run> = (0..o.runs)
                .map(|_| raytree_run(&scene_file, &png, *threads, o.size))
                .collect();
            let r = summary(&runs);
            csv.push_str(&format!(
                "{triangles},{threads},{:.6},{:.6},{:.6},{:.4},{:.1}\n",
                r.load_secs,
                r.build_secs,
                r.render_secs,
                r.mrays(),
                r.bytes_per_triangle
            ));
            points.push((triangles as f64, r.build_secs, r.render_secs));
            by_threads.push(r);
        }
        let (one, two) = (&by_threads[0], &by_threads[1]);
        println!(
            "| {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.0} |",
            triangles,
            one.build_secs,
            two.build_secs,
            one.render_secs,
            two.render_secs,
            one.mrays(),
            two.mrays(),
            two.bytes_per_triangle,
        );
        let _ = std::io::stdout().flush();
    }
    println!("load average after: {}", load_average());
    if let Some(stem) = &o.chart {
        let mut lines = Vec::new();
        for (threads, points) in &series {
            let s = if *threads == 1 { "" } else { "s" };
            lines.push(Series::new(
                format!("render, {threads} thread{s}"),
                points.iter().map(|&(n, _, r)| (n, r)).collect(),
            ));
            lines.push(Series::new(
                format!("BVH build, {threads} thread{s}"),
                points.iter().map(|&(n, b, _)| (n, b)).collect(),
            ));
        }
        let chart = Chart {
            title: "Whitted bench scene, 640x480, 1 spp: time against triangle count".into(),
            x_label: "triangles".into(),
            y_label: "seconds".into(),
            x_log: true,
            y_log: true,
            series: lines,
        };
        let stem = stem.with_extension("");
        std::fs::write(stem.with_extension("csv"), &csv).expect("write the scaling CSV");
        write_chart(&chart, &stem).expect("write the scaling chart");
        println!("wrote {0}.csv, {0}.svg and {0}.png", stem.display());
    }
}

fn main() {
    let o = parse_options();
    let tmp = tempfile::tempdir().expect("temp dir");
    let root = o.keep.clone().unwrap_or_else(|| tmp.path().to_path_buf());
    std::fs::create_dir_all(&root).expect("create the work dir");
    if o.scaling {
        scaling(&o, &root);
    } else {
        peer_comparison(&o, &root);
    }
}
