//! `raytree tree`: the ray tracing tree of one pixel's centre sample, as text or JSON, and its
//! figure as SVG.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use clap::Args;
use raytree::ray_tree;
use raytree::trace::Tracer;

use super::{SceneOverrides, apply_overrides, load_scene, parse_pixel, print_warnings};

#[derive(Args, Debug)]
pub struct TreeArgs {
    /// Scene file, OBJ file or built-in scene name.
    scene: String,
    /// The pixel, as X,Y (0,0 is the top-left corner).
    #[arg(long, value_parser = parse_pixel)]
    pixel: (u32, u32),
    /// Print the tree as JSON (the schema in the README) instead of indented text.
    #[arg(long)]
    json: bool,
    /// Also write the lecture's tree figure as SVG to this file.
    #[arg(long)]
    diagram: Option<PathBuf>,
    #[command(flatten)]
    overrides: SceneOverrides,
}

pub fn run_tree(args: &TreeArgs) -> Result<()> {
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
    if let Some(path) = &args.diagram {
        let svg = raytree::diagram::svg(&tree, &Default::default());
        raytree::export::write_text(path, &svg)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
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
