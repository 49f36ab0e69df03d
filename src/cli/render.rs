//! `raytree render`: a scene to a PNG or EXR with a progress bar, the stamp of what made it,
//! and the run's statistics (printed, and as JSON with `--stats-json`). For a render spread
//! over machines: part of the image (`--region`, `--tile`) and turntable frames
//! (`--turntable`, `--frame`, `--frame-range`).

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use clap::Args;
use raytree::export;
use raytree::render::region::{check_region, full, render_region, tile_rect};
use raytree::render::{Image, Rect, RenderSettings, RenderStats, RunReport, render};
use raytree::scene::{Scene, rules};
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
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000),
          conflicts_with = "turntable")]
    frames: u32,
    /// Render only these pixels of the full image, X,Y,W,H (x and y from the top left): the
    /// output is W×H, each pixel bit for bit the same as in the full render, and its stamp
    /// says where it goes for `raytree merge`.
    #[arg(long, value_parser = region_arg, conflicts_with = "tile", value_name = "X,Y,W,H")]
    region: Option<Rect>,
    /// Render part I of N, counted from 0 (I = 0 … N−1): row band I of N even bands, so a job
    /// array's index maps straight onto it (`--tile $SLURM_ARRAY_TASK_ID/4`).
    #[arg(long, value_parser = tile_arg, value_name = "I/N")]
    tile: Option<(u32, u32)>,
    /// A turntable of N frames: the camera orbits its target about its up axis, frame I turned
    /// by I/N of a full turn. The output name gets the frame number: `{frame}` in it is
    /// replaced by the 4-digit number, else `_NNNN` goes before the extension
    /// (out.png → out_0007.png). Without --frame or --frame-range, every frame.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000), value_name = "N")]
    turntable: Option<u32>,
    /// The turntable frame to render, counted from 0.
    #[arg(
        long,
        requires = "turntable",
        conflicts_with = "frame_range",
        value_name = "I"
    )]
    frame: Option<u32>,
    /// Turntable frames A to B−1 (A..B, B excluded, as in Rust), for a node that takes several.
    #[arg(long, requires = "turntable", value_parser = frame_range_arg, value_name = "A..B")]
    frame_range: Option<Range<u32>>,
    /// Put the camera's eye here, X,Y,Z (it keeps looking at its `look_at`); lights with
    /// `follow_camera = true` move with it.
    #[arg(long, value_name = "X,Y,Z", value_parser = super::tree::parse_vec3, allow_hyphen_values = true)]
    eye: Option<glam::Vec3>,
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
    if let Some(eye) = args.eye {
        scene.camera.position = eye;
        if let Err(v) = rules::check_camera(&scene.camera) {
            bail!("--eye {eye}: the camera's `{}` {}", v.field, v.phrase);
        }
        scene.place_lights();
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
    export::check_writable(&args.output)?;
    let (width, height) = (scene.render.width, scene.render.height);
    let region = match (args.region, args.tile) {
        (Some(r), _) => check_region(r, width, height)?,
        (None, Some((i, n))) => tile_rect(width, height, i, n)?,
        (None, None) => full(width, height),
    };
    let frames = frame_list(args)?;
    let settings = RenderSettings {
        trace,
        threads: args.threads,
    };
    let samples = scene.render.samples;
    let base_tracer = Tracer::new(Arc::new(scene), settings.trace);
    for frame in frames {
        match frame {
            None => render_one(
                args,
                &base_tracer,
                samples,
                region,
                None,
                &args.output,
                load_secs,
            )?,
            Some((i, n)) => {
                // The geometry is the same in every frame: one accelerator for all.
                let mut scene: Scene = (*base_tracer.scene).clone();
                turn(&mut scene, i, n);
                let mut tracer =
                    Tracer::with_accel(Arc::new(scene), settings.trace, base_tracer.accel.clone());
                tracer.build_secs = base_tracer.build_secs;
                let output = frame_path(&args.output, i);
                render_one(args, &tracer, samples, region, frame, &output, load_secs)?;
            }
        }
    }
    Ok(())
}

/// Renders one image (the scene, or one turntable frame) and writes it with its stamp and
/// statistics.
fn render_one(
    args: &RenderArgs,
    tracer: &Tracer,
    samples: u32,
    region: Rect,
    frame: Option<(u32, u32)>,
    output: &Path,
    load_secs: f64,
) -> Result<()> {
    let scene = &tracer.scene;
    let whole = region == full(scene.render.width, scene.render.height);
    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(region.width as u64 * region.height as u64)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent}% ({eta} left)",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let progress = |done, _| bar.set_position(done);
    let once = || -> Result<(Image, RenderStats)> {
        Ok(if whole {
            render(tracer, samples, args.threads, &progress)?
        } else {
            render_region(tracer, region, samples, args.threads, &progress)?
        })
    };
    let (mut image, stats) = once()?;
    let mut frame_secs = vec![stats.render_secs];
    for _ in 1..args.frames {
        let (warm, warm_stats) = once()?;
        frame_secs.push(warm_stats.render_secs);
        image = warm;
    }
    bar.finish_and_clear();

    let mut text = export::stamp(
        &args.scene,
        samples,
        samples,
        &scene.render,
        &tracer.settings,
        tracer.accel.kind(),
    );
    text.extend(export::part_stamp(scene, region));
    if let Some((i, n)) = frame {
        text.push((export::KEY_FRAME.to_string(), format!("{i}/{n}")));
    }
    export::write_image(output, &image, &text)?;
    let report = RunReport::new(tracer, stats, load_secs);
    if let Some(path) = &args.stats_json {
        let mut json = serde_json::to_value(&report).context("cannot encode the statistics")?;
        if args.frames > 1 {
            json["frame_render_secs"] = frame_secs.clone().into();
        }
        let json = serde_json::to_string_pretty(&json).context("cannot encode the statistics")?;
        export::write_text(path, &json)?;
    }
    for line in report.lines(&output.display().to_string(), args.stats) {
        out!("{line}");
    }
    if args.frames > 1 {
        let secs: Vec<String> = frame_secs.iter().map(|s| format!("{s:.3}")).collect();
        out!("render phase of each frame (s): {}", secs.join(", "));
    }
    Ok(())
}

/// The turntable frames asked for, each (I, N); one `None` without `--turntable`.
fn frame_list(args: &RenderArgs) -> Result<Vec<Option<(u32, u32)>>> {
    let Some(n) = args.turntable else {
        return Ok(vec![None]);
    };
    let range = match (args.frame, &args.frame_range) {
        (Some(i), _) => {
            if i >= n {
                bail!(
                    "--frame {i} does not exist: a {n}-frame turntable has frames 0 to {}",
                    n - 1
                );
            }
            i..i + 1
        }
        (None, Some(r)) => {
            if r.end > n {
                bail!(
                    "--frame-range {}..{} reaches past the turntable's last frame {}: B is at most {n}",
                    r.start,
                    r.end,
                    n - 1
                );
            }
            r.clone()
        }
        (None, None) => 0..n,
    };
    Ok(range.map(|i| Some((i, n))).collect())
}

/// Turns the scene's camera about its target by `i/n` of a full turn, about its up axis.
pub fn turn(scene: &mut Scene, i: u32, n: u32) {
    let angle = std::f64::consts::TAU * f64::from(i) / f64::from(n);
    scene.camera.orbit(angle as f32, 0.0);
    scene.place_lights();
}

/// The output name of turntable frame `i`: `{frame}` replaced by the 4-digit number, or
/// `_NNNN` before the extension.
pub fn frame_path(output: &Path, i: u32) -> PathBuf {
    let number = format!("{i:04}");
    let name = output
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let named = if name.contains("{frame}") {
        name.replace("{frame}", &number)
    } else {
        match name.rsplit_once('.') {
            Some((stem, ext)) => format!("{stem}_{number}.{ext}"),
            None => format!("{name}_{number}"),
        }
    };
    output.with_file_name(named)
}

/// `--region X,Y,W,H`.
fn region_arg(text: &str) -> Result<Rect, String> {
    export::parse_region(text).ok_or_else(|| {
        format!("expected X,Y,W,H as four whole numbers such as 0,0,320,240, got `{text}`")
    })
}

/// `--tile I/N`.
fn tile_arg(text: &str) -> Result<(u32, u32), String> {
    let bad = || format!("expected I/N such as 0/4 (part I of N, from 0), got `{text}`");
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let i = i.trim().parse::<u32>().map_err(|_| bad())?;
    let n = n.trim().parse::<u32>().map_err(|_| bad())?;
    if n == 0 || i >= n {
        return Err(format!(
            "tile {i}/{n} does not exist: tiles are numbered 0 to N−1 of N (N ≥ 1)"
        ));
    }
    Ok((i, n))
}

/// `--frame-range A..B`.
fn frame_range_arg(text: &str) -> Result<Range<u32>, String> {
    let bad = || format!("expected A..B such as 0..24 (frames A to B−1), got `{text}`");
    let (a, b) = text.split_once("..").ok_or_else(bad)?;
    let a = a.trim().parse::<u32>().map_err(|_| bad())?;
    let b = b.trim().parse::<u32>().map_err(|_| bad())?;
    if a >= b {
        return Err(format!(
            "the frame range {a}..{b} is empty: A must be below B"
        ));
    }
    Ok(a..b)
}
