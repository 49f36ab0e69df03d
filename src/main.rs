//! The `raytree` command: parse, call the library, print one-line errors, set the exit code.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use raytree::accel::AccelKind;
use raytree::geometry::{Methods, OffsetMethod, SphereMethod, TriangleMethod};
use raytree::render::{RenderSettings, render};
use raytree::scene::{self, Scene, Shading};
use raytree::trace::{TraceSettings, Tracer};
use raytree::{export, ray_tree};

/// raytree: recursive (Whitted) ray tracing with the ray tracing tree of every pixel.
///
/// SCENE is a scene file (.toml), a bare OBJ file (.obj), or the name of a built-in scene:
/// default, quiz, glass, box.
#[derive(Parser, Debug)]
#[command(version, about, long_about, max_term_width = 100)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Scene to open in the viewer (default: the built-in default scene).
    scene: Option<String>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene to an image file, with a progress bar and statistics.
    Render(RenderArgs),
    /// Print the ray tracing tree of one pixel's centre sample.
    Tree(TreeArgs),
    /// List the built-in scenes.
    Scenes,
}

#[derive(Args, Debug)]
struct SceneOverrides {
    /// Image width in pixels (overrides the scene's [render] width).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: Option<u32>,
    /// Image height in pixels.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: Option<u32>,
    /// Deepest child ray traced; the primary ray has depth 0 (0..=64).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
    max_depth: Option<u32>,
    /// Specular model.
    #[arg(long, value_enum)]
    shading: Option<ShadingArg>,
    /// Accelerator: auto picks from the scene's size.
    #[arg(long, value_enum, default_value_t = AccelKind::Auto)]
    accel: AccelKind,
    /// Ray/sphere intersection method.
    #[arg(long, value_enum, default_value_t = SphereMethod::default())]
    sphere: SphereMethod,
    /// Ray/triangle intersection method.
    #[arg(long, value_enum, default_value_t = TriangleMethod::default())]
    triangle: TriangleMethod,
    /// How secondary rays leave a surface.
    #[arg(long, value_enum, default_value_t = OffsetMethod::default())]
    offset: OffsetMethod,
    /// Skip rays whose weight (product of kr/kt) is below this (adaptive depth); 0 = off.
    #[arg(long, default_value_t = 0.0)]
    cutoff: f32,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum ShadingArg {
    Phong,
    BlinnPhong,
}

#[derive(Args, Debug)]
struct RenderArgs {
    /// Scene file, OBJ file or built-in scene name.
    scene: String,
    /// Output image: .png (8-bit sRGB) or .exr (linear 32-bit float).
    #[arg(short, long)]
    output: PathBuf,
    /// Samples per pixel (sample 0 is the pixel centre).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    samples: Option<u32>,
    /// Worker threads; 0 uses every core.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
    /// Write the statistics as JSON to this file.
    #[arg(long)]
    stats_json: Option<PathBuf>,
    #[command(flatten)]
    overrides: SceneOverrides,
}

#[derive(Args, Debug)]
struct TreeArgs {
    /// Scene file, OBJ file or built-in scene name.
    scene: String,
    /// The pixel, as X,Y (0,0 is the top-left corner).
    #[arg(long, value_parser = parse_pixel)]
    pixel: (u32, u32),
    /// Print the tree as JSON (the schema in the README) instead of indented text.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    overrides: SceneOverrides,
}

fn parse_pixel(s: &str) -> Result<(u32, u32), String> {
    let (x, y) = s
        .split_once(',')
        .ok_or_else(|| format!("expected X,Y such as 320,240, got `{s}`"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{v}` is not a pixel coordinate (a whole number ≥ 0)"))
    };
    Ok((parse(x)?, parse(y)?))
}

/// Loads a scene file, an OBJ, or a built-in scene by name (a file of that name wins).
fn load_scene(arg: &str) -> Result<Scene> {
    let path = Path::new(arg);
    if !path.exists() && scene::builtin::NAMES.contains(&arg) {
        return Ok(scene::builtin::load_builtin(arg)?);
    }
    Ok(scene::load_scene_file(path)?)
}

fn apply_overrides(scene: &mut Scene, o: &SceneOverrides) -> TraceSettings {
    if let Some(w) = o.width {
        scene.render.width = w;
    }
    if let Some(h) = o.height {
        scene.render.height = h;
    }
    if let Some(d) = o.max_depth {
        scene.render.max_depth = d;
    }
    if let Some(s) = o.shading {
        scene.render.shading = match s {
            ShadingArg::Phong => Shading::Phong,
            ShadingArg::BlinnPhong => Shading::BlinnPhong,
        };
    }
    TraceSettings {
        accel: o.accel,
        methods: Methods {
            sphere: o.sphere,
            triangle: o.triangle,
            offset: o.offset,
        },
        cutoff: o.cutoff,
    }
}

fn print_warnings(scene: &Scene) {
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
}

fn run_render(args: &RenderArgs) -> Result<()> {
    let load_start = std::time::Instant::now();
    let mut scene = load_scene(&args.scene)?;
    let load_secs = load_start.elapsed().as_secs_f64();
    print_warnings(&scene);
    let trace = apply_overrides(&mut scene, &args.overrides);
    if !(0.0..1.0).contains(&trace.cutoff) {
        bail!("--cutoff must be in [0, 1), got {}", trace.cutoff);
    }
    if let Some(s) = args.samples {
        scene.render.samples = s;
    }
    // Refuse a bad output name before spending time on the render.
    let ext = args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        bail!(
            "cannot write {}: the file name must end in .png (8-bit sRGB) or .exr (linear float)",
            args.output.display()
        );
    }
    let settings = RenderSettings {
        trace,
        threads: args.threads,
    };
    let samples = scene.render.samples;
    let scene = Arc::new(scene);
    let tracer = Tracer::new(scene.clone(), settings.trace);

    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(scene.render.width as u64 * scene.render.height as u64)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent}% ({eta} left)",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let (image, stats) = render(&tracer, samples, settings.threads, &|done, _| {
        bar.set_position(done)
    })?;
    bar.finish_and_clear();

    let text =
        vec![
        ("Software".to_string(), format!("raytree {}", env!("CARGO_PKG_VERSION"))),
        ("raytree.scene".to_string(), args.scene.clone()),
        ("raytree.samples".to_string(), format!("{samples}/{samples}")),
        (
            "raytree.settings".to_string(),
            serde_json::json!({
                "width": stats.width, "height": stats.height, "max_depth": scene.render.max_depth,
                "shading": scene.render.shading, "trace": settings.trace,
                "accel_used": stats.accel,
            })
            .to_string(),
        ),
    ];
    export::write_image(&args.output, &image, &text)?;
    if let Some(path) = &args.stats_json {
        let memory = raytree::render::MemoryStats::of(&tracer);
        let json = serde_json::to_string_pretty(&serde_json::json!({
            "stats": stats, "mrays_per_sec": stats.mrays_per_sec(),
            "triangles": scene.triangles.len(), "spheres": scene.spheres.len(),
            "load_secs": load_secs, "memory": memory,
        }))
        .context("cannot encode the statistics")?;
        export::write_text(path, &json)?;
    }
    let r = &stats.rays;
    println!(
        "wrote {} ({}x{}, {} spp, max depth {}, {} threads, accel {:?})",
        args.output.display(),
        stats.width,
        stats.height,
        samples,
        scene.render.max_depth,
        stats.threads,
        stats.accel.unwrap_or_default(),
    );
    println!(
        "rays: {} primary, {} reflected, {} refracted, {} shadow, {} in all",
        r.primary,
        r.reflected,
        r.refracted,
        r.shadow,
        r.total()
    );
    println!(
        "time: load {:.3} s, build {:.3} s, render {:.3} s, {:.2} Mrays/s",
        load_secs,
        stats.build_secs,
        stats.render_secs,
        stats.mrays_per_sec()
    );
    Ok(())
}

fn run_tree(args: &TreeArgs) -> Result<()> {
    let mut scene = load_scene(&args.scene)?;
    print_warnings(&scene);
    let trace = apply_overrides(&mut scene, &args.overrides);
    let (w, h) = (scene.render.width, scene.render.height);
    let (x, y) = args.pixel;
    if x >= w || y >= h {
        bail!(
            "pixel {x},{y} is outside the {w}x{h} image of {}",
            args.scene
        );
    }
    let tracer = Tracer::new(Arc::new(scene), trace);
    let tree = ray_tree::pixel_tree(&tracer, x, y).context("the pixel has no tree")?;
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&tree).context("cannot encode the tree")?
        );
    } else {
        print!("{}", ray_tree::tree_text(&tree));
    }
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Render(args)) => run_render(&args),
        Some(Command::Tree(args)) => run_tree(&args),
        Some(Command::Scenes) => {
            for name in scene::builtin::NAMES {
                println!("{name}");
            }
            Ok(())
        }
        None => raytree::app::run(cli.scene.as_deref()),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Each error is one sentence already (file, place, field); print the chain joined.
            let msg = e
                .chain()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(": ");
            eprintln!("error: {msg}");
            ExitCode::FAILURE
        }
    }
}
