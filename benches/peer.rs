//! raytree against a peer in the same run, the peer held at its best. The
//! peer is `benches/peer/embree_whitted.c`, a Whitted renderer over Debian's Embree 3
//! (`apt-get install libembree-dev`), compiled here with the system C compiler (`$CC`, else
//! `cc`) into a temp dir; without Embree the peer is skipped with a message and raytree runs
//! alone.
//!
//! Both render the procedural scene of [`raytree::scene::procedural`] (a bumpy torus of N
//! triangles, a mirror sphere, a glass sphere, a floor, two point lights; 640×480, 1 sample,
//! depth 4 below the primary ray) on the same number of threads, each in its own process:
//! raytree through `raytree render bench.toml --frames K --stats-json`, the peer from a binary
//! copy of the very scene raytree loaded. Both shade alike and trace the same rays (a shadow
//! ray only where N·L > 0 and the light meets some diffuse or specular colour); rays are
//! counted by kind on both sides and the bench fails when one kind differs by more than 1 %.
//!
//! Peer configurations (`--peer-config`, a comma list; default `best,user-high,
//! user:high:ftz:packet,user:high:ftz:packet2x4,user:high:ftz:packet:secstream`, the ones that
//! measured fastest; `all` adds the built-in spheres' packets and camera streams): `best` gives the spheres to Embree as its built-in sphere geometry, builds every
//! BVH at `RTC_BUILD_QUALITY_HIGH`, sets flush-to-zero/denormals-are-zero on its tracing threads
//! (Embree's advice) and traces single rays; `user-high` is the same with the spheres as an
//! Embree user geometry (whose callback is raytree's robust intersection); `user-medium` has
//! user-geometry spheres with Embree's default build quality (medium) and denormals kept, for
//! comparison; `SPHERES:QUALITY[:FLAG...]` any other, the flags `:ftz`, `:robust`
//! (`RTC_SCENE_FLAG_ROBUST`, Embree's watertight mode; without it the scene flags are
//! `RTC_SCENE_FLAG_NONE`, its fastest), `:packet` or `:packetWxH` (camera rays in 8-wide
//! packets of a 4×2 or W×H pixel block, `rtcIntersect8`, and each light's shadow rays of a
//! block as one `rtcOccluded8`), `:stream` (a tile's camera and their shadow rays as
//! `rtcIntersect1M`/`rtcOccluded1M` streams) and `:secstream` (reflected and refracted rays
//! and their shadow rays as one stream per generation of a tile; without it they go one by
//! one). After the per-configuration tables the bench names **Embree at its best**: per size
//! and frame (first, warm), the configuration with the shortest median time, and raytree's
//! ratio against it. The harness is compiled with `-O3 -march=native -ffp-contract=off` (no
//! FMA contraction: its shading rounds as raytree's).
//!
//! Each process builds once and renders K frames (`--frames`, default 5): the first frame is
//! frame 1, the warm frame the median of frames 2..K. Each size starts with `--warmup` rounds
//! (default 1) that are run and dropped. Rounds alternate (who goes first turns each round);
//! each round's Embree time is divided by the same round's raytree time, and the median,
//! smallest and largest of those ratios are reported (above 1: raytree faster). Also
//! load and build seconds, bytes per triangle, peak memory, rays by kind and how many pixels
//! of the two images differ.
//!
//! Run: `cargo bench --bench peer` (80k, 320k and 1.28M triangles, 2 threads, 5 rounds), or
//! e.g. `cargo bench --bench peer -- --sizes 1000,1000000 --threads 1 --runs 3 --keep /tmp/b`.
//! With `--keep DIR` each scene's directory also gets `differences_N.png` for peer N: raytree's
//! image with every pixel that differs by more than 2 of 255 marked red (the peer's is the
//! brighter) or blue (raytree's is).
//! `--check` (the test suite runs it on a small scene) fails unless the harness builds and
//! every configuration gives raytree's image: no pixel more than 2/255 apart and at most one
//! in 1,000 apart at all.
//! `--size 1280x960` renders more rays than the scene's 640×480 (a longer, steadier render
//! phase on a noisy machine). `--scene A,B` races on other scenes instead of the generated
//! ones: built-in names, scene files or bare OBJ files, within the peer's reach (point lights,
//! no textures; meshes are shaded flat on both sides, as the peer has no vertex normals). `--scaling` instead prints raytree's build and render time
//! against triangle count (1k to 4M) on 1 and 2 threads, and with `--chart FILE.png` draws it.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use raytree::experiments::chart::{Chart, Series, write_chart};
use raytree::scene::procedural::{torus_triangles, write_bench_scene};
use raytree::scene::{Scene, Shading, load_scene_file};

const HARNESS_SOURCE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/peer/embree_whitted.c");

/// One Embree configuration of the peer: its sphere geometry, build quality and ray calls.
#[derive(Clone, Debug)]
struct PeerConfig {
    /// `builtin` (Embree's RTC_GEOMETRY_TYPE_SPHERE_POINT) or `user` (a callback per test).
    spheres: String,
    /// `low`, `medium` or `high`.
    quality: String,
    /// Flush-to-zero and denormals-are-zero on the tracing threads (Embree's advice).
    ftz: bool,
    /// `RTC_SCENE_FLAG_ROBUST`: Embree's watertight mode, for a race at equal robustness
    /// (raytree's triangle test is watertight).
    robust: bool,
    /// How the camera rays and their shadow rays are traced: `single` (rtcIntersect1 and
    /// rtcOccluded1, depth first), `packet` (8-wide packets of a pixel block: rtcIntersect8 and
    /// rtcOccluded8 per light) or `stream` (a tile's rays as one rtcIntersect1M/rtcOccluded1M
    /// stream).
    camera: String,
    /// The packet's pixel block, `WxH` with W × H = 8.
    block: String,
    /// How reflected and refracted rays and their shadow rays are traced: `single` or
    /// `stream` (each generation of a tile as one stream).
    secondary: String,
}

/// The configurations `--peer-config all` names: every ray-call layout with either sphere
/// geometry, at high quality with FTZ/DAZ.
const ALL_CONFIGS: &str = "best,user-high,builtin:high:ftz:packet,user:high:ftz:packet,user:high:ftz:packet2x4,builtin:high:ftz:packet:secstream,user:high:ftz:packet:secstream,user:high:ftz:stream:secstream";

/// The default: the single-ray configurations and the packet ones that measured fastest (the
/// user-geometry spheres; with the built-in ones every layout was slower).
const DEFAULT_CONFIGS: &str =
    "best,user-high,user:high:ftz:packet,user:high:ftz:packet2x4,user:high:ftz:packet:secstream";

impl PeerConfig {
    /// `best` (built-in spheres, high quality, FTZ/DAZ: the peer at its best with single rays
    /// as Embree's own advice sets it up), `user-high` (the same with user-geometry spheres),
    /// `user-medium` (user-geometry spheres, medium quality, denormals kept), or
    /// `SPHERES:QUALITY` followed by flags: `:ftz` (FTZ/DAZ), `:robust` (Embree's watertight
    /// mode), `:packet` or `:packetWxH` (camera and their shadow rays in 8-wide packets of a
    /// 4×2 or W×H block), `:stream` (camera rays as tile streams), `:secstream` (secondary
    /// rays as streams).
    fn parse(text: &str) -> Self {
        let text = match text {
            "best" => "builtin:high:ftz",
            "user-high" => "user:high:ftz",
            "user-medium" => "user:medium",
            other => other,
        };
        let mut parts = text.split(':');
        let (spheres, quality) = (
            parts.next().unwrap_or_default(),
            parts.next().unwrap_or_else(|| {
                panic!("--peer-config: best, user-high, user-medium, all or SPHERES:QUALITY[:FLAG...], not {text}")
            }),
        );
        let mut config = Self {
            spheres: spheres.into(),
            quality: quality.into(),
            ftz: false,
            robust: false,
            camera: "single".into(),
            block: "4x2".into(),
            secondary: "single".into(),
        };
        for flag in parts {
            match flag {
                "ftz" => config.ftz = true,
                "robust" => config.robust = true,
                "stream" => config.camera = "stream".into(),
                "secstream" => config.secondary = "stream".into(),
                "packet" => config.camera = "packet".into(),
                block if block.starts_with("packet") => {
                    let shape = &block["packet".len()..];
                    assert!(
                        matches!(shape, "8x1" | "4x2" | "2x4" | "1x8"),
                        "--peer-config: a packet block is 8x1, 4x2, 2x4 or 1x8, not {shape}"
                    );
                    config.camera = "packet".into();
                    config.block = shape.into();
                }
                other => panic!(
                    "--peer-config: after the quality only :ftz, :robust, :packet[WxH], :stream and :secstream, not {other}"
                ),
            }
        }
        assert!(
            matches!(spheres, "builtin" | "user"),
            "--peer-config: spheres are builtin or user, not {spheres}"
        );
        assert!(
            matches!(quality, "low" | "medium" | "high"),
            "--peer-config: quality is low, medium or high, not {quality}"
        );
        assert!(
            config.secondary == "single" || config.camera != "single",
            "--peer-config {text}: :secstream needs :packet or :stream"
        );
        config
    }

    /// A comma list of configurations, `all` standing for [`ALL_CONFIGS`].
    fn parse_list(text: &str) -> Vec<Self> {
        text.split(',')
            .flat_map(|c| match c.trim() {
                "all" => ALL_CONFIGS.split(',').collect::<Vec<_>>(),
                one => vec![one],
            })
            .map(Self::parse)
            .collect()
    }

    fn label(&self) -> String {
        let spheres = if self.spheres == "builtin" {
            "built-in spheres"
        } else {
            "user-geometry spheres"
        };
        let ftz = if self.ftz { ", FTZ/DAZ" } else { "" };
        let robust = if self.robust { ", robust" } else { "" };
        let rays = match (self.camera.as_str(), self.secondary.as_str()) {
            ("single", _) => "single rays".to_string(),
            ("packet", sec) => format!("{} packets, secondary {sec}", self.block),
            (_, sec) => format!("camera streams, secondary {sec}"),
        };
        format!("{spheres}, {} quality{ftz}{robust}, {rays}", self.quality)
    }

    /// The Embree calls this configuration makes.
    fn calls(&self) -> String {
        let camera = match self.camera.as_str() {
            "packet" => format!(
                "camera rays in {} blocks by rtcIntersect8, their shadow rays by rtcOccluded8",
                self.block
            ),
            "stream" => "camera and their shadow rays as tile streams (rtcIntersect1M/rtcOccluded1M, coherent)".into(),
            _ => "rtcIntersect1/rtcOccluded1 for every ray".into(),
        };
        let secondary = match (self.camera.as_str(), self.secondary.as_str()) {
            ("single", _) => String::new(),
            (_, "stream") => "; reflected, refracted and their shadow rays as streams (rtcIntersect1M/rtcOccluded1M) per generation of a tile".into(),
            _ => "; reflected, refracted and their shadow rays by rtcIntersect1/rtcOccluded1".into(),
        };
        format!("{camera}{secondary}")
    }
}

struct Options {
    sizes: Vec<usize>,
    threads: usize,
    runs: usize,
    /// Rounds run before the counted ones at each size and discarded (`--warmup`, default 1):
    /// the first size otherwise starts on a machine that was compiling or idle, and its first
    /// frames ran up to 30 % slower than the next round's.
    warmup: usize,
    /// Renders per process after one build: frame 1 is the first frame, 2..K the warm ones.
    frames: usize,
    keep: Option<PathBuf>,
    scaling: bool,
    peer: bool,
    peer_configs: Vec<PeerConfig>,
    chart: Option<PathBuf>,
    /// Image size instead of the scene's 640×480 (more rays: a longer, steadier render phase).
    size: Option<(u32, u32)>,
    /// The camera- and shadow-dominated frame: every material's reflectivity and transparency
    /// set to 0, so each ray is a camera ray or a shadow ray.
    opaque: bool,
    /// Scenes to race on instead of the generated ones (`--scene`): built-in names, scene
    /// files or bare OBJ files.
    scenes: Vec<String>,
    /// `--check`: the harness must build, and every configuration must trace the same rays
    /// as raytree and give its image (no pixel more than 2/255 apart, at most one in
    /// [`CHECK_PIXELS`] apart at all); the bench fails otherwise. The test suite runs it.
    check: bool,
}

/// With `--check`, at most one pixel in this many may differ at all between the two images.
const CHECK_PIXELS: usize = 1000;

fn parse_options() -> Options {
    let mut o = Options {
        sizes: vec![80_000, 320_000, 1_280_000],
        threads: 2,
        runs: 5,
        warmup: 1,
        frames: 5,
        keep: None,
        scaling: false,
        peer: true,
        peer_configs: PeerConfig::parse_list(DEFAULT_CONFIGS),
        chart: None,
        size: None,
        opaque: false,
        scenes: Vec::new(),
        check: false,
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
            "--warmup" => o.warmup = value("--warmup").parse().expect("--warmup: a number"),
            "--frames" => o.frames = value("--frames").parse().expect("--frames: a number"),
            "--keep" => o.keep = Some(PathBuf::from(value("--keep"))),
            "--scaling" => o.scaling = true,
            "--opaque" => o.opaque = true,
            "--check" => o.check = true,
            "--scene" => o
                .scenes
                .extend(value("--scene").split(',').map(str::to_string)),
            "--no-peer" => o.peer = false,
            "--peer-config" => {
                o.peer_configs = PeerConfig::parse_list(&value("--peer-config"));
            }
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
    o.frames = o.frames.clamp(1, 1000);
    o
}

/// What one row of the race renders.
enum Entry {
    /// The generated bench scene with this many triangles.
    Generated(usize),
    /// A scene named on the command line (`--scene`).
    Given(String),
}

impl Entry {
    fn label(&self, triangles: usize) -> String {
        match self {
            Entry::Generated(_) => triangles.to_string(),
            Entry::Given(arg) => format!("`{arg}`, {triangles}"),
        }
    }
}

/// Writes the scene `arg` (a built-in name, a scene file or a bare OBJ) as a scene file in
/// `dir`, its meshes by absolute path and shaded flat (the peer has no vertex normals).
fn write_given_scene(arg: &str, dir: &Path) -> PathBuf {
    use raytree::scene::{NormalsMode, ObjectSource};
    let mut scene =
        raytree::scene::open_scene_arg(arg).unwrap_or_else(|e| panic!("--scene {arg}: {e}"));
    // Where the scene's mesh paths start: the file's folder, or a built-in's in `assets`.
    let folder = if Path::new(arg).exists() {
        let parent = Path::new(arg)
            .parent()
            .filter(|p| !p.as_os_str().is_empty());
        std::fs::canonicalize(parent.unwrap_or(Path::new(".")))
            .unwrap_or_else(|e| panic!("--scene {arg}: {e}"))
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes")
    };
    for object in &mut scene.objects {
        if let ObjectSource::Mesh { file, normals, .. } = &mut object.source {
            *file = folder.join(&*file).to_string_lossy().into_owned();
            *normals = NormalsMode::Flat;
        }
    }
    std::fs::create_dir_all(dir).expect("make the scene's folder");
    let path = dir.join("bench.toml");
    std::fs::write(&path, raytree::scene::save::scene_to_toml(&scene))
        .expect("write the scene file");
    path
}

/// Why scene `arg`, as raytree loads it for the race, is beyond what the peer renders alike,
/// if it is: lights with a radius, textures, or (with `--opaque`) a reflective or transparent
/// material the rewrite could not reach (one an OBJ's MTL file brings).
fn beyond_reach(arg: &str, scene: &Scene, opaque: bool) -> Option<String> {
    if let Some(l) = scene.lights.iter().find(|l| l.radius != 0.0) {
        return Some(format!(
            "--scene {arg}: light `{}` has a radius; the peer takes point lights only",
            l.name
        ));
    }
    if let Some(m) = scene
        .materials
        .iter()
        .find(|m| m.diffuse_map.is_some() || m.ambient_map.is_some())
    {
        return Some(format!(
            "--scene {arg}: material `{}` is textured; the peer has no textures",
            m.name
        ));
    }
    if opaque
        && let Some(m) = scene
            .materials
            .iter()
            .find(|m| m.reflectivity != glam::Vec3::ZERO || m.transparency != glam::Vec3::ZERO)
    {
        return Some(format!(
            "--scene {arg} --opaque: material `{}` still reflects or refracts (it comes from the mesh's MTL file, which the rewrite does not reach)",
            m.name
        ));
    }
    None
}

/// Rewrites the scene file with every material's reflectivity and transparency 0: the
/// camera- and shadow-dominated frame (no reflected or refracted rays).
fn make_opaque(scene_file: &Path) {
    let text = std::fs::read_to_string(scene_file).expect("read the bench scene");
    let mut table: toml::Table = text.parse().expect("the bench scene is TOML");
    let materials = table
        .get_mut("material")
        .and_then(|m| m.as_array_mut())
        .expect("the bench scene has materials");
    for material in materials.iter_mut().filter_map(|m| m.as_table_mut()) {
        material.insert("reflectivity".into(), toml::Value::Float(0.0));
        material.insert("transparency".into(), toml::Value::Float(0.0));
    }
    let text = format!(
        "# The bench scene with every material opaque (no reflection, no refraction).\n{}",
        toml::to_string(&table).expect("write TOML")
    );
    std::fs::write(scene_file, text).expect("write the opaque bench scene");
}

/// One process's figures, from either renderer.
#[derive(Clone, Debug, Default)]
struct Run {
    load_secs: f64,
    build_secs: f64,
    /// The render phase of each frame after the one build.
    frame_secs: Vec<f64>,
    /// Rays of one frame by kind: primary, reflected, refracted, shadow.
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
    /// Millions of rays per second of the first frame.
    fn mrays(&self) -> f64 {
        self.total_rays() as f64 / self.first_secs() / 1e6
    }
    /// The first frame's render phase.
    fn first_secs(&self) -> f64 {
        self.frame_secs.first().copied().unwrap_or(f64::NAN)
    }
    /// The median render phase of frames 2..K (NaN with one frame).
    fn warm_secs(&self) -> f64 {
        self.frame_secs
            .get(1..)
            .map_or(f64::NAN, |warm| median(warm.to_vec()))
    }
}

/// Medians of `runs` (a frame each: the scaling table's), as one run.
fn summary(runs: &[Run]) -> Run {
    let m = |key: fn(&Run) -> f64| median(runs.iter().map(key).collect());
    Run {
        load_secs: m(|r| r.load_secs),
        build_secs: m(|r| r.build_secs),
        frame_secs: vec![m(Run::first_secs)],
        bytes_per_triangle: m(|r| r.bytes_per_triangle),
        ..runs.first().cloned().unwrap_or_default()
    }
}

/// The median (the mean of the middle two for an even count); NaN of nothing.
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Median, smallest and largest.
fn spread(v: Vec<f64>) -> (f64, f64, f64) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (median(v), lo, hi)
}

fn raytree_run(
    scene_file: &Path,
    image: &Path,
    threads: usize,
    frames: usize,
    size: Option<(u32, u32)>,
) -> Run {
    let stats = image.with_extension("json");
    let mut command = Command::new(env!("CARGO_BIN_EXE_raytree"));
    command.arg("render").arg(scene_file);
    if let Some((w, h)) = size {
        command.args(["--width", &w.to_string(), "--height", &h.to_string()]);
    }
    let output = command
        .arg("-o")
        .arg(image)
        .args(["--quiet", "--threads", &threads.to_string()])
        .args(["--frames", &frames.to_string(), "--stats-json"])
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
    let frame_secs = match json["frame_render_secs"].as_array() {
        Some(list) => list.iter().map(f).collect(),
        None => vec![f(&s["render_secs"])],
    };
    Run {
        load_secs: f(&json["load_secs"]),
        build_secs: f(&s["build_secs"]),
        frame_secs,
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
    for t in scene.triangles.iter() {
        for v in t.vertices {
            v3(&mut b, v);
        }
    }
    for t in scene.triangles.iter() {
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
        .args(["-O3", "-march=native", "-ffp-contract=off", "-o"])
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
    frames: usize,
    config: &PeerConfig,
) -> Run {
    let output = Command::new(exe)
        .args(["--spheres", &config.spheres, "--quality", &config.quality])
        .args(["--frames", &frames.to_string()])
        .args(["--ftz", if config.ftz { "1" } else { "0" }])
        .args(["--robust", if config.robust { "1" } else { "0" }])
        .args(["--camera", &config.camera, "--block", &config.block])
        .args(["--secondary", &config.secondary])
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
    let value = |key: &str| -> Option<&str> {
        text.lines()
            .find_map(|l| l.strip_prefix(key)?.strip_prefix(' '))
    };
    let get = |key: &str| -> f64 {
        value(key)
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or(f64::NAN)
    };
    let triangles = get("triangles");
    Run {
        load_secs: get("load_secs"),
        build_secs: get("build_secs"),
        frame_secs: value("frame_secs")
            .unwrap_or_default()
            .split_whitespace()
            .map(|v| v.parse().unwrap_or(f64::NAN))
            .collect(),
        rays: ["primary", "reflected", "refracted", "shadow"].map(|k| get(k) as u64),
        bytes_per_triangle: (get("embree_peak_bytes") + get("geometry_bytes")) / triangles,
        peak_rss_bytes: (get("peak_rss_kb") * 1024.0) as u64,
    }
}

/// How many pixels of raytree's PNG and the harness's linear `f32` image differ at all and by
/// more than 2 of 255 (after the same sRGB encoding). With `marks`, also writes raytree's image
/// there with each pixel of the second kind marked by a 3×3 dot: red where the peer's pixel is
/// the brighter, blue where raytree's is (on the `cracks` scene, red inside the panel is sky
/// seen through a crack of the peer's).
fn differing_pixels(
    png_path: &Path,
    f32_path: &Path,
    width: u32,
    height: u32,
    marks: Option<&Path>,
) -> [usize; 2] {
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
    let mut counts = [0, 0];
    // Only when asked for: the marks go on a copy of raytree's image.
    let mut marked = marks.map(|_| ours.clone());
    let (w, h) = (width as usize, height as usize);
    for i in 0..w * h {
        let c = glam::Vec3::new(theirs[3 * i], theirs[3 * i + 1], theirs[3 * i + 2]);
        let t = raytree::export::to_srgb8(c);
        let most = (0..3)
            .map(|k| (ours[3 * i + k] as i32 - t[k] as i32).abs())
            .max()
            .unwrap_or(0);
        counts[0] += usize::from(most > 0);
        counts[1] += usize::from(most > 2);
        if let (true, Some(marked)) = (most > 2, marked.as_mut()) {
            let sum = |p: &[u8]| p.iter().map(|&v| u32::from(v)).sum::<u32>();
            let colour = if sum(&t) > sum(&ours[3 * i..3 * i + 3]) {
                [255, 0, 0]
            } else {
                [0, 0, 255]
            };
            let (x, y) = (i % w, i / w);
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    let j = 3 * (yy * w + xx);
                    marked[j..j + 3].copy_from_slice(&colour);
                }
            }
        }
    }
    if let (Some(path), Some(marked)) = (marks, marked) {
        let file = std::fs::File::create(path).expect("create the differences image");
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().expect("PNG header");
        writer
            .write_image_data(&marked)
            .expect("write the differences image");
    }
    counts
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

fn mb(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

/// One scene size's results: raytree's runs and each peer configuration's runs, round by
/// round (the same index is the same round), and the pixels each peer's image differs in.
struct SizeResult {
    /// The row's name: the triangle count of a generated scene, or the scene's name and count.
    label: String,
    ours: Vec<Run>,
    theirs: Vec<Vec<Run>>,
    differing: Vec<[usize; 2]>,
    pixels: usize,
}

/// The largest relative difference between two renderers' rays of one kind (of the larger
/// count), over the four kinds.
fn ray_difference(a: &Run, b: &Run) -> f64 {
    a.rays
        .iter()
        .zip(&b.rays)
        .map(|(&x, &y)| x.abs_diff(y) as f64 / x.max(y).max(1) as f64)
        .fold(0.0, f64::max)
}

/// Equal work means the same rays: a run whose counts differ by more than this from
/// raytree's is flagged, and the bench fails.
const MAX_RAY_DIFFERENCE: f64 = 0.01;

fn peer_comparison(o: &Options, root: &Path) {
    let harness = if o.peer { build_harness(root) } else { None };
    if o.check && harness.is_none() {
        eprintln!("--check: the Embree harness did not build (the reason is above)");
        std::process::exit(1);
    }
    let configs: &[PeerConfig] = if harness.is_some() {
        &o.peer_configs
    } else {
        &[]
    };
    println!(
        "peer bench: {} threads, {} alternating rounds after {} discarded warm-up round(s) per size, {} frames per process (first = frame 1 after the build, warm = median of frames 2..{}), load average before: {}",
        o.threads,
        o.runs,
        o.warmup,
        o.frames,
        o.frames,
        load_average()
    );
    if o.opaque {
        println!(
            "frame: --opaque, every material's reflectivity and transparency 0 (camera and shadow rays only)"
        );
    }
    for (i, c) in configs.iter().enumerate() {
        println!(
            "peer {}: Embree 3 ({}), {}; triangles in Embree's own BVH, scene flags {}, {}, pthreads over 32x32 tiles",
            i + 1,
            embree_version(),
            c.label(),
            if c.robust { "robust" } else { "none" },
            c.calls()
        );
    }
    let mut results = Vec::new();
    let entries: Vec<Entry> = if o.scenes.is_empty() {
        o.sizes.iter().map(|&n| Entry::Generated(n)).collect()
    } else {
        o.scenes.iter().cloned().map(Entry::Given).collect()
    };
    for (k, entry) in entries.iter().enumerate() {
        let (dir, scene_file) = match entry {
            Entry::Generated(size) => {
                let dir = root.join(format!("tris_{size}"));
                let file = write_bench_scene(&dir, *size).expect("write the bench scene");
                (dir, file)
            }
            Entry::Given(arg) => {
                let dir = root.join(format!("scene_{k}"));
                let file = write_given_scene(arg, &dir);
                (dir, file)
            }
        };
        if o.opaque {
            make_opaque(&scene_file);
        }
        let mut scene = load_scene_file(&scene_file).expect("load the bench scene");
        if let Entry::Given(arg) = entry
            && let Some(why) = beyond_reach(arg, &scene, o.opaque)
        {
            println!("skipped: {why}");
            continue;
        }
        if let Some((w, h)) = o.size {
            (scene.render.width, scene.render.height) = (w, h);
        }
        let scene_bin = dir.join("scene.bin");
        write_peer_scene(&scene, &scene_bin);
        let ours_png = dir.join("raytree.png");
        let images: Vec<PathBuf> = configs
            .iter()
            .enumerate()
            .map(|(i, c)| dir.join(format!("embree_{}_{}_{i}.f32", c.spheres, c.quality)))
            .collect();
        let mut ours = Vec::new();
        let mut theirs: Vec<Vec<Run>> = vec![Vec::new(); configs.len()];
        for round in 0..o.warmup + o.runs {
            // Alternating: who goes first turns with the round, so a slow spell of the
            // machine falls on each renderer in turn. The warm-up rounds' runs are dropped.
            let counted = round >= o.warmup;
            let players = configs.len() + 1;
            for k in 0..players {
                match (round + k) % players {
                    0 => {
                        let run = raytree_run(&scene_file, &ours_png, o.threads, o.frames, o.size);
                        ours.extend(counted.then_some(run));
                    }
                    c => {
                        if let Some(exe) = &harness {
                            let run = harness_run(
                                exe,
                                &scene_bin,
                                &images[c - 1],
                                o.threads,
                                o.frames,
                                &configs[c - 1],
                            );
                            theirs[c - 1].extend(counted.then_some(run));
                        }
                    }
                }
            }
        }
        let (w, h) = (scene.render.width, scene.render.height);
        let differing = images
            .iter()
            .enumerate()
            .map(|(i, image)| {
                let marks = o
                    .keep
                    .is_some()
                    .then(|| dir.join(format!("differences_{}.png", i + 1)));
                differing_pixels(&ours_png, image, w, h, marks.as_deref())
            })
            .collect();
        println!(
            "{} done; load average {}",
            entry.label(scene.triangles.len()),
            load_average()
        );
        let _ = std::io::stdout().flush();
        results.push(SizeResult {
            label: entry.label(scene.triangles.len()),
            ours,
            theirs,
            differing,
            pixels: (w * h) as usize,
        });
    }
    println!("load average after: {}", load_average());
    print_tables(&results, configs);

    let mut flagged = Vec::new();
    for r in &results {
        for (c, runs) in r.theirs.iter().enumerate() {
            for (mine, peer) in r.ours.iter().zip(runs) {
                let d = ray_difference(mine, peer);
                if d > MAX_RAY_DIFFERENCE {
                    flagged.push(format!(
                        "{}, peer {}: rays differ by {:.2} % in one kind",
                        r.label,
                        c + 1,
                        100.0 * d
                    ));
                }
            }
        }
    }
    if o.check {
        for r in &results {
            for (c, &[any, visible]) in r.differing.iter().enumerate() {
                if visible > 0 || any * CHECK_PIXELS > r.pixels {
                    flagged.push(format!(
                        "{}, peer {}: {any} pixels differ, {visible} by more than 2/255 (of {})",
                        r.label,
                        c + 1,
                        r.pixels
                    ));
                }
            }
        }
        if flagged.is_empty() {
            println!("check: every configuration traced the same rays and gave the same image");
        }
    }
    if !flagged.is_empty() {
        eprintln!(
            "unequal work: the renderers did not trace the same rays (a kind more than {} % \
             apart), or with --check did not give the same image:\n{}",
            100.0 * MAX_RAY_DIFFERENCE,
            flagged.join("\n")
        );
        std::process::exit(1);
    }
}

/// The Embree version the harness reports (`embree_version` of `rtcore_config.h`), read from
/// the header so the table names it without a run.
fn embree_version() -> String {
    let header =
        std::fs::read_to_string("/usr/include/embree3/rtcore_config.h").unwrap_or_default();
    let part = |name: &str| {
        header
            .lines()
            .find_map(|l| l.strip_prefix(&format!("#define RTC_VERSION_{name} ")))
            .map(str::trim)
            .unwrap_or("?")
            .to_string()
    };
    format!("{}.{}.{}", part("MAJOR"), part("MINOR"), part("PATCH"))
}

/// One frame's time of a run: [`Run::first_secs`] or [`Run::warm_secs`].
type FrameTime = fn(&Run) -> f64;

fn print_tables(results: &[SizeResult], configs: &[PeerConfig]) {
    let pair = |a: f64, b: Option<f64>, digits: usize| match b {
        Some(b) => format!("{a:.digits$} / {b:.digits$}"),
        None => format!("{a:.digits$} / –"),
    };
    let ratio = |(m, lo, hi): (f64, f64, f64)| {
        if m.is_nan() {
            "–".to_string()
        } else {
            format!("**{m:.2}** ({lo:.2}–{hi:.2})")
        }
    };
    // Each round's raytree run is paired with the same round's Embree run: the median of
    // the pairs' ratios is steadier on a shared machine than the ratio of two medians, and
    // the pairs' spread shows how steady.
    let ratios = |ours: &[Run], theirs: &[Run], key: fn(&Run) -> f64| {
        spread(
            ours.iter()
                .zip(theirs)
                .map(|(a, b)| key(b) / key(a))
                .collect(),
        )
    };
    let medians = |runs: &[Run], key: fn(&Run) -> f64| median(runs.iter().map(key).collect());
    let mrays = |runs: &[Run], key: fn(&Run) -> f64| {
        runs.first().map_or(f64::NAN, |r| {
            r.total_rays() as f64 / medians(runs, key) / 1e6
        })
    };
    // Rows: each size with each peer configuration (raytree alone without a peer).
    let rows = || -> Vec<(String, Option<usize>)> {
        if configs.is_empty() {
            vec![("–".into(), None)]
        } else {
            (0..configs.len())
                .map(|c| (format!("{}. {}", c + 1, configs[c].label()), Some(c)))
                .collect()
        }
    };
    println!();
    println!(
        "| triangles | peer | first frame s (raytree / Embree) | Embree / raytree, first (pairs: median, min–max) | warm frame s (raytree / Embree) | Embree / raytree, warm | Mrays/s warm (raytree / Embree) |"
    );
    println!("|---:|---|---:|---:|---:|---:|---:|");
    for r in results {
        for (label, c) in rows() {
            let e = c.map(|c| r.theirs[c].as_slice());
            println!(
                "| {} | {label} | {} | {} | {} | {} | {} |",
                r.label,
                pair(
                    medians(&r.ours, Run::first_secs),
                    e.map(|e| medians(e, Run::first_secs)),
                    3
                ),
                e.map_or("–".into(), |e| ratio(ratios(&r.ours, e, Run::first_secs))),
                pair(
                    medians(&r.ours, Run::warm_secs),
                    e.map(|e| medians(e, Run::warm_secs)),
                    3
                ),
                e.map_or("–".into(), |e| ratio(ratios(&r.ours, e, Run::warm_secs))),
                pair(
                    mrays(&r.ours, Run::warm_secs),
                    e.map(|e| mrays(e, Run::warm_secs)),
                    2
                ),
            );
        }
    }
    // Embree at its best: per size and frame, the configuration with the shortest median time.
    if !configs.is_empty() {
        println!();
        println!(
            "Embree at its best: per size and frame, the configuration above with the shortest median time"
        );
        println!();
        println!(
            "| triangles | frame | Embree at its best | raytree s | Embree s | Embree / raytree (pairs: median, min–max) |"
        );
        println!("|---:|---|---|---:|---:|---:|");
        let frames: [(&str, FrameTime); 2] = [("first", Run::first_secs), ("warm", Run::warm_secs)];
        for r in results {
            for (frame, key) in frames {
                let Some(best) = (0..configs.len())
                    .filter(|&c| !r.theirs[c].is_empty())
                    .min_by(|&a, &b| {
                        medians(&r.theirs[a], key).total_cmp(&medians(&r.theirs[b], key))
                    })
                else {
                    continue;
                };
                println!(
                    "| {} | {frame} | {}. {} | {:.4} | {:.4} | {} |",
                    r.label,
                    best + 1,
                    configs[best].label(),
                    medians(&r.ours, key),
                    medians(&r.theirs[best], key),
                    ratio(ratios(&r.ours, &r.theirs[best], key)),
                );
            }
        }
    }
    println!();
    println!(
        "| triangles | peer | load s (raytree / Embree) | build s (raytree / Embree) | bytes/tri (raytree / Embree) | peak MB (raytree / Embree) |"
    );
    println!("|---:|---|---:|---:|---:|---:|");
    for r in results {
        for (label, c) in rows() {
            let e = c.map(|c| r.theirs[c].as_slice());
            let m = |runs: &[Run], key: fn(&Run) -> f64| medians(runs, key);
            println!(
                "| {} | {label} | {} | {} | {} | {} |",
                r.label,
                pair(
                    m(&r.ours, |x| x.load_secs),
                    e.map(|e| m(e, |x| x.load_secs)),
                    3
                ),
                pair(
                    m(&r.ours, |x| x.build_secs),
                    e.map(|e| m(e, |x| x.build_secs)),
                    3
                ),
                pair(
                    m(&r.ours, |x| x.bytes_per_triangle),
                    e.map(|e| m(e, |x| x.bytes_per_triangle)),
                    0
                ),
                pair(
                    mb(m(&r.ours, |x| x.peak_rss_bytes as f64) as u64),
                    e.map(|e| mb(m(e, |x| x.peak_rss_bytes as f64) as u64)),
                    0
                ),
            );
        }
    }
    println!();
    println!(
        "| triangles | peer | rays raytree (P / R / T / S) | rays Embree (P / R / T / S) | largest difference in one kind | pixels differing (at all / > 2 of 255) |"
    );
    println!("|---:|---|---:|---:|---:|---:|");
    let kinds = |x: &Run| {
        let [p, rf, t, s] = x.rays;
        format!("{p} / {rf} / {t} / {s}")
    };
    for r in results {
        let Some(mine) = r.ours.first() else { continue };
        for (label, c) in rows() {
            let peer = c.and_then(|c| r.theirs[c].first());
            let (theirs, delta, diff) = match (peer, c) {
                (Some(e), Some(c)) => {
                    let d = ray_difference(mine, e);
                    let flag = if d > MAX_RAY_DIFFERENCE {
                        " **unequal**"
                    } else {
                        ""
                    };
                    let [any, far] = r.differing[c];
                    let share = |n: usize| 100.0 * n as f64 / r.pixels.max(1) as f64;
                    (
                        kinds(e),
                        format!("{:.3} %{flag}", 100.0 * d),
                        format!("{any} / {far} ({:.3} % / {:.3} %)", share(any), share(far)),
                    )
                }
                _ => ("–".into(), "–".into(), "–".into()),
            };
            println!(
                "| {} | {label} | {} | {theirs} | {delta} | {diff} |",
                r.label,
                kinds(mine)
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
                .map(|_| raytree_run(&scene_file, &png, *threads, 1, o.size))
                .collect();
            let r = summary(&runs);
            csv.push_str(&format!(
                "{triangles},{threads},{:.6},{:.6},{:.6},{:.4},{:.1}\n",
                r.load_secs,
                r.build_secs,
                r.first_secs(),
                r.mrays(),
                r.bytes_per_triangle
            ));
            points.push((triangles as f64, r.build_secs, r.first_secs()));
            by_threads.push(r);
        }
        let (one, two) = (&by_threads[0], &by_threads[1]);
        println!(
            "| {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.0} |",
            triangles,
            one.build_secs,
            two.build_secs,
            one.first_secs(),
            two.first_secs(),
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
