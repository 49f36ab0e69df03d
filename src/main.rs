//! The `raytree` command: parse, call the library, print one-line errors, set the exit code.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
#[cfg(feature = "lab")]
use std::sync::atomic::AtomicBool;

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use raytree::accel::AccelKind;
use raytree::choice::Choice;
#[cfg(feature = "lab")]
use raytree::experiments::{measure, report, rows, scaling, sweep};
use raytree::geometry::{Methods, OffsetMethod, SphereMethod, TriangleMethod};
use raytree::render::{MemoryStats, RenderSettings, render};
use raytree::scene::{self, Scene, Shading, rules};
use raytree::trace::{TraceSettings, Tracer};
use raytree::{export, ray_tree};

/// `println!` that ignores a closed stdout (`raytree … | head -1`): a broken pipe is not an
/// error worth a panic.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

/// raytree: recursive (Whitted) ray tracing with the ray tracing tree of every pixel.
///
/// SCENE is a scene file (.toml), a bare OBJ file (.obj), or the name of a built-in scene:
/// default, quiz, glass, box, acne, cracks.
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
    #[cfg(feature = "lab")]
    /// Chart render time against image error for every speed/accuracy knob (bench.csv,
    /// bench.svg, bench.png) and build/render time against triangle count per accelerator
    /// (scaling.csv, scaling.svg, scaling.png).
    Bench(BenchArgs),
    #[cfg(feature = "lab")]
    /// Measure where the naive intersection, offset and refraction methods fail and that the
    /// robust ones hold (the rows of STABILITY.md): stability.md and one chart per row.
    Stability(StabilityArgs),
    /// List the built-in scenes.
    Scenes,
}

#[derive(Args, Debug)]
struct SceneOverrides {
    /// Image width in pixels (overrides the scene's [render] width).
    #[arg(long, value_parser = count(&rules::IMAGE_SIZE))]
    width: Option<u32>,
    /// Image height in pixels.
    #[arg(long, value_parser = count(&rules::IMAGE_SIZE))]
    height: Option<u32>,
    /// Deepest child ray traced; the primary ray has depth 0.
    #[arg(long, value_parser = count(&rules::DEPTH))]
    max_depth: Option<u32>,
    /// Specular model.
    #[arg(long, value_parser = ChoiceParser::<Shading>::default())]
    shading: Option<Shading>,
    /// Accelerator: auto picks from the scene's size.
    #[arg(long, value_parser = ChoiceParser::<AccelKind>::default(), default_value = "auto")]
    accel: AccelKind,
    /// Ray/sphere intersection method.
    #[arg(long, value_parser = ChoiceParser::<SphereMethod>::default(),
          default_value = SphereMethod::default().name())]
    sphere: SphereMethod,
    /// Ray/triangle intersection method.
    #[arg(long, value_parser = ChoiceParser::<TriangleMethod>::default(),
          default_value = TriangleMethod::default().name())]
    triangle: TriangleMethod,
    /// How secondary rays leave a surface.
    #[arg(long, value_parser = ChoiceParser::<OffsetMethod>::default(),
          default_value = OffsetMethod::default().name())]
    offset: OffsetMethod,
    /// Skip rays whose weight (product of kr/kt) is below this (adaptive depth); 0 = off.
    #[arg(long, default_value_t = 0.0)]
    cutoff: f32,
}

/// A clap parser for a library [`Choice`]: its names are the possible values, each with its
/// help line (the library stays free of CLI derives).
#[derive(Clone, Debug)]
struct ChoiceParser<T>(std::marker::PhantomData<T>);

impl<T> Default for ChoiceParser<T> {
    fn default() -> Self {
        Self(std::marker::PhantomData)
    }
}

impl<T: Choice> clap::builder::TypedValueParser for ChoiceParser<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        let names = T::ALL.iter().map(|c| c.name());
        clap::builder::PossibleValuesParser::new(names)
            .parse_ref(cmd, arg, value)
            .map(|name| T::from_name(&name).unwrap_or_default())
    }

    fn possible_values(
        &self,
    ) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        Some(Box::new(T::ALL.iter().map(|c| {
            clap::builder::PossibleValue::new(c.name()).help(c.help())
        })))
    }
}

/// A whole-number option held to a scene rule's range.
fn count(range: &std::ops::RangeInclusive<u32>) -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(i64::from(*range.start())..=i64::from(*range.end()))
}

#[derive(Args, Debug)]
struct RenderArgs {
    /// Scene file, OBJ file or built-in scene name.
    scene: String,
    /// Output image: .png (8-bit sRGB) or .exr (linear 32-bit float).
    #[arg(short, long)]
    output: PathBuf,
    /// Samples per pixel (sample 0 is the pixel centre).
    #[arg(long, value_parser = count(&rules::SAMPLES))]
    samples: Option<u32>,
    /// Worker threads for the BVH build and the render; 0 uses every core (at most 1024).
    #[arg(long, default_value_t = 0,
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=1024))]
    threads: usize,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
    /// Write the statistics as JSON to this file.
    #[arg(long)]
    stats_json: Option<PathBuf>,
    /// Also print the geometry's memory: the accelerator, the scene's records, bytes per
    /// primitive.
    #[arg(long)]
    stats: bool,
    #[command(flatten)]
    overrides: SceneOverrides,
}

#[cfg(feature = "lab")]
#[derive(Args, Debug)]
struct BenchArgs {
    /// Scene file, OBJ file or built-in scene name.
    scene: String,
    /// Folder for the CSV files and charts (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// A small image, one run per point and smaller meshes: seconds instead of minutes.
    #[arg(long)]
    quick: bool,
    /// Image width of the sweep (default 320; --quick: 96).
    #[arg(long, value_parser = count(&rules::IMAGE_SIZE))]
    width: Option<u32>,
    /// Image height of the sweep (default 240; --quick: 72).
    #[arg(long, value_parser = count(&rules::IMAGE_SIZE))]
    height: Option<u32>,
    /// Worker threads for the builds and renders; 0 uses every core (at most 1024).
    #[arg(long, default_value_t = 0,
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=1024))]
    threads: usize,
    /// Skip the accelerator scaling sweep.
    #[arg(long)]
    no_scaling: bool,
    /// Skip the speed/accuracy sweep (only the scaling sweep, which does not use SCENE).
    #[arg(long, conflicts_with = "no_scaling")]
    no_sweep: bool,
}

#[cfg(feature = "lab")]
#[derive(Args, Debug)]
struct StabilityArgs {
    /// Folder for stability.md and the charts (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Print one JSON object per row (its measured figures) instead of the table.
    #[arg(long)]
    json: bool,
    /// Fewer rays per cell (1000) and smaller builds: seconds instead of minutes.
    #[arg(long)]
    quick: bool,
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
    Ok(scene::open_scene_arg(arg)?)
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
        scene.render.shading = s;
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

/// Makes `--threads N` hold for everything parallel in the command, the accelerator build
/// included (it runs on rayon's global pool), not only for the render's own pool. 0 keeps
/// rayon's default (every core).
fn use_threads(threads: usize) {
    if threads > 0 {
        // Fails only when the global pool already exists, and then it keeps its size: a
        // command configures it first thing, so that cannot happen here.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global();
    }
}

fn run_render(args: &RenderArgs) -> Result<()> {
    use_threads(args.threads);
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

    let text = export::stamp(
        &args.scene,
        samples,
        samples,
        &scene.render,
        &settings.trace,
        tracer.accel.kind(),
    );
    export::write_image(&args.output, &image, &text)?;
    let memory = MemoryStats::of(&tracer);
    if let Some(path) = &args.stats_json {
        let json = serde_json::to_string_pretty(&serde_json::json!({
            "stats": stats, "mrays_per_sec": stats.mrays_per_sec(),
            "triangles": scene.triangles.len(), "spheres": scene.spheres.len(),
            "load_secs": load_secs, "memory": memory,
            "build_threads": rayon::current_num_threads(),
        }))
        .context("cannot encode the statistics")?;
        export::write_text(path, &json)?;
    }
    let r = &stats.rays;
    out!(
        "wrote {} ({}x{}, {} spp, max depth {}, {} threads, accel {:?})",
        args.output.display(),
        stats.width,
        stats.height,
        samples,
        scene.render.max_depth,
        stats.threads,
        stats.accel.unwrap_or_default(),
    );
    out!(
        "rays: {} primary, {} reflected, {} refracted, {} shadow, {} in all",
        r.primary,
        r.reflected,
        r.refracted,
        r.shadow,
        r.total()
    );
    out!(
        "time: load {:.3} s, build {:.3} s, render {:.3} s, {:.2} Mrays/s",
        load_secs,
        stats.build_secs,
        stats.render_secs,
        stats.mrays_per_sec()
    );
    if args.stats {
        out!(
            "memory: accelerator {} B + scene records {} B for {} triangles and {} spheres = \
             {:.1} B per primitive{} ({} skipped{})",
            memory.accel_bytes,
            memory.scene_geometry_bytes,
            memory.triangles,
            memory.spheres,
            memory.bytes_per_primitive(),
            memory
                .bytes_per_triangle
                .map(|b| format!(", {b:.1} B per triangle"))
                .unwrap_or_default(),
            tracer.accel.skipped_prims(),
            tracer
                .accel
                .bvh_depth()
                .map(|d| format!(", BVH depth {d}"))
                .unwrap_or_default(),
        );
    }
    Ok(())
}

#[cfg(feature = "lab")]
/// A progress bar for the sweeps: position, length and what is running.
fn sweep_bar() -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(1);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

#[cfg(feature = "lab")]
/// A progress callback that moves `bar`.
fn show_on(bar: &indicatif::ProgressBar) -> impl Fn(&measure::BenchProgress) + '_ {
    move |p| {
        bar.set_length(p.steps as u64);
        bar.set_position(p.step as u64);
        bar.set_message(p.what.clone());
    }
}

#[cfg(feature = "lab")]
fn run_bench(args: &BenchArgs) -> Result<()> {
    use_threads(args.threads);
    let scene = load_scene(&args.scene)?;
    print_warnings(&scene);
    let (mut opts, scaling) = if args.quick {
        (
            sweep::BenchOptions::quick(),
            scaling::ScalingOptions::quick(),
        )
    } else {
        (sweep::BenchOptions::full(), scaling::ScalingOptions::full())
    };
    opts.width = args.width.or(opts.width);
    opts.height = args.height.or(opts.height);
    opts.threads = args.threads;
    let scaling = scaling::ScalingOptions {
        threads: args.threads,
        ..scaling
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let cancel = AtomicBool::new(false);
    let mut changed: Vec<String> = Vec::new();
    if !args.no_sweep {
        let bar = sweep_bar();
        let report = sweep::run_sweep(&scene, &opts, &show_on(&bar), &cancel)?;
        bar.finish_and_clear();
        report::write_bench(&args.out, &report, &args.scene)?;
        out!(
            "wrote {} and bench.svg/.png ({} points, reference {}x{} at {} spp, depth {}, {:.1} s)",
            args.out.join("bench.csv").display(),
            report.points.len(),
            report.reference.width,
            report.reference.height,
            report.reference.samples,
            report.reference.max_depth,
            report.reference.secs
        );
        out!("Pareto-optimal settings (time against mean FLIP):");
        for line in report::pareto_lines(&report) {
            out!("  {line}");
        }
        changed = report
            .accel_changes()
            .iter()
            .filter(|(_, n)| *n > 0)
            .map(|(k, n)| format!("{} changed {n} pixels", measure::value_name(k)))
            .collect();
        if changed.is_empty() {
            out!("accelerators: none, grid and bvh give the identical image (0 differing pixels)");
        }
    }
    if !args.no_scaling {
        let bar = sweep_bar();
        let points = scaling::run_scaling(&scaling, &show_on(&bar), &cancel)?;
        bar.finish_and_clear();
        report::write_scaling(&args.out, &points, &scaling)?;
        out!(
            "wrote {} and scaling.svg/.png",
            args.out.join("scaling.csv").display()
        );
        for line in report::crossover_lines(&points) {
            out!("  {line}");
        }
    }
    if !changed.is_empty() {
        bail!("an accelerator changed the image: {}", changed.join(", "));
    }
    Ok(())
}

#[cfg(feature = "lab")]
fn run_stability(args: &StabilityArgs) -> Result<()> {
    let opts = if args.quick {
        rows::StabilityOptions::quick()
    } else {
        rows::StabilityOptions::full()
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let bar = indicatif::ProgressBar::new_spinner();
    let measured = rows::rows(&opts, &|id| bar.set_message(format!("row {id}")));
    bar.finish_and_clear();
    rows::write_stability(&args.out, &measured)?;
    if args.json {
        for row in &measured {
            out!(
                "{}",
                serde_json::to_string(row).context("cannot encode a row")?
            );
        }
    } else {
        out!("{}", rows::markdown_table(&measured).trim_end());
        out!(
            "wrote {} and the charts",
            args.out.join("stability.md").display()
        );
    }
    let failed: Vec<&str> = measured
        .iter()
        .filter(|r| r.verdict == rows::Verdict::No)
        .map(|r| r.id)
        .collect();
    if !failed.is_empty() {
        bail!("rows {} miss their targets", failed.join(", "));
    }
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
        out!(
            "{}",
            serde_json::to_string_pretty(&tree).context("cannot encode the tree")?
        );
    } else {
        {
            use std::io::Write as _;
            let _ = write!(std::io::stdout(), "{}", ray_tree::tree_text(&tree));
        }
    }
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Render(args)) => run_render(&args),
        Some(Command::Tree(args)) => run_tree(&args),
        #[cfg(feature = "lab")]
        Some(Command::Bench(args)) => run_bench(&args),
        #[cfg(feature = "lab")]
        Some(Command::Stability(args)) => run_stability(&args),
        Some(Command::Scenes) => {
            for name in scene::builtin::NAMES {
                out!("{name}");
            }
            Ok(())
        }
        #[cfg(feature = "viewer")]
        None => raytree::app::run(cli.scene.as_deref()),
        #[cfg(not(feature = "viewer"))]
        None => bail!(
            "this raytree was built without the viewer (feature `viewer`); use `raytree render \
             SCENE -o out.png` or `raytree tree SCENE --pixel X,Y`"
        ),
    }
}

/// Parses the arguments; a usage error becomes one line on stderr (exit code 2), as every
/// other error is one line. `--help` and `--version` print as clap formats them.
fn parse_args() -> Result<Cli, ExitCode> {
    Cli::try_parse().map_err(|e| {
        if !e.use_stderr() {
            e.exit();
        }
        // clap's message is "error: ...", tips, a usage block and a pointer to --help:
        // keep the error and its tips, on one line.
        let text = e.render().to_string();
        let mut line = String::new();
        for part in text
            .lines()
            .map(str::trim)
            .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
            .filter(|l| !l.is_empty())
        {
            if !line.is_empty() {
                line += if line.ends_with(':') { " " } else { "; " };
            }
            line += part;
        }
        let line = line.strip_prefix("error: ").unwrap_or(&line);
        eprintln!("error: {line} (see `raytree --help`)");
        ExitCode::from(2)
    })
}

fn main() -> ExitCode {
    let cli = match parse_args() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
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
