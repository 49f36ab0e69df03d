//! `raytree render`: a scene to a PNG or EXR with a progress bar, the stamp of what made it,
//! and the run's statistics (printed, and as JSON with `--stats-json`).

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use clap::Args;
use raytree::export;
use raytree::render::{RenderSettings, RunReport, render};
use raytree::scene::rules;
use raytree::trace::Tracer;

use super::{
    SceneOverrides, apply_overrides, count, load_scene, print_warnings, threads, use_threads,
};

#[derive(Args, Debug)]
pub struct RenderArgs {
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
          value_parser = threads())]
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
    /// Render the image this many times after one load and build (first and warm frames, for
    /// the peer benchmark): the statistics are the first frame's, the JSON's
    /// `frame_render_secs` lists each frame's render phase, the image written is the last.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000))]
    frames: u32,
    #[command(flatten)]
    overrides: SceneOverrides,
}

pub fn run_render(args: &RenderArgs) -> Result<()> {
    use_threads(args.threads);
    let load_start = std::time::Instant::now();
    let mut scene = load_scene(&args.scene)?;
    let load_secs = load_start.elapsed().as_secs_f64();
    print_warnings(&scene);
    let trace = apply_overrides(&mut scene, &args.overrides);
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
    let (mut image, stats) = render(&tracer, samples, settings.threads, &|done, _| {
        bar.set_position(done)
    })?;
    let mut frame_secs = vec![stats.render_secs];
    for _ in 1..args.frames {
        let (warm, warm_stats) = render(&tracer, samples, settings.threads, &|done, _| {
            bar.set_position(done)
        })?;
        frame_secs.push(warm_stats.render_secs);
        image = warm;
    }
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
    let report = RunReport::new(&tracer, stats, load_secs);
    if let Some(path) = &args.stats_json {
        let mut json = serde_json::to_value(&report).context("cannot encode the statistics")?;
        if args.frames > 1 {
            json["frame_render_secs"] = frame_secs.clone().into();
        }
        let json = serde_json::to_string_pretty(&json).context("cannot encode the statistics")?;
        export::write_text(path, &json)?;
    }
    for line in report.lines(&args.output.display().to_string(), args.stats) {
        out!("{line}");
    }
    if args.frames > 1 {
        let secs: Vec<String> = frame_secs.iter().map(|s| format!("{s:.3}")).collect();
        out!("render phase of each frame (s): {}", secs.join(", "));
    }
    Ok(())
}
