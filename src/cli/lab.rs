//! `raytree bench` and `raytree stability` (feature `lab`): the speed-vs-accuracy and scaling
//! sweeps, and the rows of docs/stability.md, with progress bars; files written, summaries printed.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use anyhow::{Context, Result, bail};
use clap::Args;
use raytree::experiments::{measure, report, scaling, stability, sweep};
use raytree::scene::rules;

use super::{count, load_scene, print_warnings, threads, use_threads};

#[derive(Args, Debug)]
pub struct BenchArgs {
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
          value_parser = threads())]
    threads: usize,
    /// Skip the accelerator scaling sweep.
    #[arg(long)]
    no_scaling: bool,
    /// Skip the speed/accuracy sweep (only the scaling sweep, which does not use SCENE).
    #[arg(long, conflicts_with = "no_scaling")]
    no_sweep: bool,
}

#[derive(Args, Debug)]
pub struct StabilityArgs {
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

/// A progress callback that moves `bar`.
fn show_on(bar: &indicatif::ProgressBar) -> impl Fn(&measure::BenchProgress) + '_ {
    move |p| {
        bar.set_length(p.steps as u64);
        bar.set_position(p.step as u64);
        bar.set_message(p.what.clone());
    }
}

pub fn run_bench(args: &BenchArgs) -> Result<()> {
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
        out!("  {}", report::level_note());
    }
    if !changed.is_empty() {
        bail!("an accelerator changed the image: {}", changed.join(", "));
    }
    Ok(())
}

pub fn run_stability(args: &StabilityArgs) -> Result<()> {
    let opts = if args.quick {
        stability::StabilityOptions::quick()
    } else {
        stability::StabilityOptions::full()
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let bar = indicatif::ProgressBar::new_spinner();
    let measured = stability::rows(&opts, &|id| bar.set_message(format!("row {id}")));
    bar.finish_and_clear();
    stability::write_stability(&args.out, &measured)?;
    if args.json {
        for row in &measured {
            out!(
                "{}",
                serde_json::to_string(row).context("cannot encode a row")?
            );
        }
    } else {
        out!("{}", stability::markdown_table(&measured).trim_end());
        out!(
            "wrote {} and the charts",
            args.out.join("stability.md").display()
        );
    }
    let failed: Vec<&str> = measured
        .iter()
        .filter(|r| r.verdict == stability::Verdict::No)
        .map(|r| r.id)
        .collect();
    if !failed.is_empty() {
        bail!("rows {} miss their targets", failed.join(", "));
    }
    Ok(())
}
