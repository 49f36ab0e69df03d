//! The `raytree` command: parse, call the library, print one-line errors, set the exit code.
//! The subcommands live in [`cli`]: `render`, `merge`, `tree`, `scenes`, `lessons`, `lesson`, and with the `lab` feature
//! `bench` and `stability`; without a subcommand, the viewer (feature `viewer`).

#[macro_use]
mod cli;

use std::process::ExitCode;

use anyhow::Result;
#[cfg(not(feature = "viewer"))]
use anyhow::bail;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
#[cfg(feature = "lab")]
use cli::lab::{BenchArgs, StabilityArgs, run_bench, run_stability};
use cli::lesson::{LessonArgs, run_lesson, run_lessons};
use cli::merge::{MergeArgs, run_merge};
use cli::render::{RenderArgs, run_render};
use cli::tree::{TreeArgs, run_tree};
use raytree::scene;

/// raytree: recursive (Whitted) ray tracing with the ray tracing tree of every pixel.
///
/// SCENE is a scene file (.toml), a bare OBJ file (.obj), or the name of a built-in scene
/// (listed below and by `raytree scenes`).
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
    /// Put the parts of a render spread over machines (`render --region` or `--tile`) back
    /// into one image, after checking they are of one render and cover it exactly once.
    Merge(MergeArgs),
    /// Print the ray tracing tree of one pixel's centre sample.
    Tree(TreeArgs),
    #[cfg(feature = "lab")]
    /// Chart render time against image error for every speed/accuracy knob (bench.csv,
    /// bench.svg, bench.png) and build/render time against triangle count per accelerator
    /// (scaling.csv, scaling.svg, scaling.png).
    Bench(BenchArgs),
    #[cfg(feature = "lab")]
    /// Measure where the naive intersection, offset and refraction methods fail and that the
    /// robust ones hold (the rows of docs/stability.md): stability.md and one chart per row.
    Stability(StabilityArgs),
    /// List the built-in scenes.
    Scenes,
    /// List the shipped lessons: the lecture as guided steps with checked tasks.
    Lessons,
    /// Check a lesson file, answer one of its tasks, or print it (docs/lessons.md).
    Lesson(LessonArgs),
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Render(args)) => run_render(&args),
        Some(Command::Merge(args)) => run_merge(&args),
        Some(Command::Tree(args)) => run_tree(&args),
        #[cfg(feature = "lab")]
        Some(Command::Bench(args)) => run_bench(&args),
        #[cfg(feature = "lab")]
        Some(Command::Stability(args)) => run_stability(&args),
        Some(Command::Lessons) => run_lessons(),
        // Has exit codes of its own (0 right, 1 wrong, 2 not evaluated): handled in `main`.
        Some(Command::Lesson(_)) => Ok(()),
        Some(Command::Scenes) => {
            out!("{}", scene::builtin::listing().trim_end());
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
    // The built-in scenes in the help from the one list `raytree scenes` prints.
    let command =
        Cli::command().after_help(format!("Built-in scenes:\n{}", scene::builtin::listing()));
    command
        .try_get_matches()
        .and_then(|m| Cli::from_arg_matches(&m))
        .map_err(|e| {
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
    if let Some(Command::Lesson(args)) = &cli.command {
        return run_lesson(args);
    }
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
