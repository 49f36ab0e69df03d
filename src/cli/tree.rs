//! `raytree tree`: the ray tracing tree of one pixel's centre sample, as text or JSON; its
//! figure as SVG (`--diagram`); and (`--scene-view`) drawn in 3D over the scene seen from
//! another camera, as a PNG.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use clap::Args;
use glam::Vec3;
use raytree::ray_tree::{self, RayTree};
use raytree::scene::{Camera, Scene, rules};
use raytree::scene_view::cutaway::Cutaway;
use raytree::scene_view::overview::{self, overview};
use raytree::scene_view::{Filter, headless};
use raytree::{export, trace::Tracer};

use super::{SceneOverrides, apply_overrides, load_scene, parse_pixel, print_warnings};

#[derive(Args, Debug)]
pub struct TreeArgs {
    /// Scene file, OBJ file or built-in scene name.
    scene: String,
    /// The pixel, as X,Y (0,0 is the top-left corner).
    #[arg(long, value_parser = parse_pixel)]
    pixel: (u32, u32),
    /// Print the tree as JSON (the schema: docs/design.md, "The ray tree as data") instead of
    /// indented text.
    #[arg(long)]
    json: bool,
    /// Also write the lecture's tree figure as SVG to this file.
    #[arg(long)]
    diagram: Option<PathBuf>,
    #[command(flatten)]
    overrides: SceneOverrides,
    #[command(flatten)]
    view: SceneViewArgs,
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
    let view_from = args.view.view_from(&scene)?;
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
    if let (Some(path), Some(from)) = (&args.view.scene_view, view_from) {
        let view = from.camera(&tracer, args.view.cutaway);
        write_scene_view(&args.scene, &tracer, &tree, &view, args.view.cutaway, path)?;
    }
    Ok(())
}

/// `--scene-view` and its camera. The tree is printed as without it (text, or JSON with
/// `--json`): the picture is written besides, never instead.
#[derive(Args, Debug)]
pub struct SceneViewArgs {
    /// Also draw the tree in 3D over the scene, with the render camera and the lights, as a
    /// PNG of the scene's size (--width, --height): seen from --eye towards --target, or
    /// without them from where the viewer's scene view first looks.
    #[arg(long, value_name = "OUT.png")]
    scene_view: Option<PathBuf>,
    /// The scene view's eye, as X,Y,Z.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true, requires_all = ["scene_view", "target"])]
    eye: Option<Vec3>,
    /// The point the scene view looks at, as X,Y,Z.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true, requires_all = ["scene_view", "eye"])]
    target: Option<Vec3>,
    /// The scene view's up direction, as X,Y,Z [default: 0,1,0].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true, requires = "eye")]
    up: Option<Vec3>,
    /// The scene view's vertical field of view in degrees [default: the scene camera's with
    /// --eye, else the viewer's 45].
    #[arg(
        long,
        value_name = "DEG",
        allow_hyphen_values = true,
        requires = "scene_view"
    )]
    fov: Option<f32>,
    /// Cut away the walls between the scene view's eye and the render camera, to see inside
    /// a closed model: auto does when the render camera is inside the model and the eye
    /// outside it.
    #[arg(
        long,
        value_name = "auto|on|off",
        default_value = "auto",
        requires = "scene_view"
    )]
    cutaway: Cutaway,
}

/// A point or direction written X,Y,Z.
pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!("expected X,Y,Z such as 4,1.5,-2, got `{s}`"));
    };
    let parse = |v: &str| {
        v.trim()
            .parse::<f32>()
            .map_err(|_| format!("`{v}` is not a number"))
    };
    Ok(Vec3::new(parse(x)?, parse(y)?, parse(z)?))
}

/// Where `--scene-view` looks from.
enum ViewFrom {
    /// `--eye` towards `--target`.
    Given(Camera),
    /// Where the viewer's scene view first looks from, with this vertical field of view.
    Overview(f32),
}

impl ViewFrom {
    /// The view camera for the scene of `tracer` in an image of its size.
    fn camera(&self, tracer: &Tracer, cutaway: Cutaway) -> Camera {
        match self {
            ViewFrom::Given(camera) => camera.clone(),
            ViewFrom::Overview(fov_y_deg) => {
                let render = &tracer.scene.render;
                let aspect = render.width as f32 / render.height.max(1) as f32;
                overview(tracer, aspect, *fov_y_deg, cutaway)
            }
        }
    }
}

impl SceneViewArgs {
    /// Where `--scene-view` looks from (`None` without it), held to the scene file's rule in
    /// the words of the flags; the file name is checked too, all before any work is done.
    fn view_from(&self, scene: &Scene) -> Result<Option<ViewFrom>> {
        let Some(path) = &self.scene_view else {
            return Ok(None);
        };
        let png = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !png {
            bail!(
                "cannot write {}: a scene view is a PNG, so the file name must end in .png",
                path.display()
            );
        }
        let (Some(eye), Some(target)) = (self.eye, self.target) else {
            // Only the field of view can be wrong: the camera is checked on a stand-in.
            let fov_y_deg = self.fov.unwrap_or(overview::FOV_Y_DEG);
            check_view(&Camera {
                position: Vec3::Z,
                look_at: Vec3::ZERO,
                up: Vec3::Y,
                fov_y_deg,
            })?;
            return Ok(Some(ViewFrom::Overview(fov_y_deg)));
        };
        let view = Camera {
            position: eye,
            look_at: target,
            up: self.up.unwrap_or(Vec3::Y),
            fov_y_deg: self.fov.unwrap_or(scene.camera.fov_y_deg),
        };
        check_view(&view)?;
        Ok(Some(ViewFrom::Given(view)))
    }
}

/// `view` held to the scene file's rule for a camera, in the words of the flags.
fn check_view(view: &Camera) -> Result<()> {
    if let Err(v) = rules::check_camera(view) {
        let flag = match v.field {
            "position" => "--eye",
            "look_at" => "--target",
            "up" => "--up",
            _ => "--fov",
        };
        let phrase = v
            .phrase
            .replace("`position`", "--eye")
            .replace("`look_at`", "--target");
        let got = v.value.map(|x| format!(", got {x}")).unwrap_or_default();
        bail!("the scene view's {flag} {phrase}{got}");
    }
    Ok(())
}

/// Renders the scene view of `tree` from `view` at the scene's size and writes it as a PNG
/// stamped like a render.
fn write_scene_view(
    label: &str,
    tracer: &Tracer,
    tree: &RayTree,
    view: &Camera,
    cutaway: Cutaway,
    path: &Path,
) -> Result<()> {
    let scene = &tracer.scene;
    let (w, h) = (scene.render.width, scene.render.height);
    let filter = Filter::default();
    let canvas = headless::scene_view_image(
        scene,
        tracer.settings,
        &[headless::Layer::alone(tree)],
        view,
        w,
        h,
        &filter,
        cutaway,
    )?;
    let text = export::stamp(
        label,
        1,
        1,
        &scene.render,
        &tracer.settings,
        tracer.accel.kind(),
    );
    export::write_png_rgba8(path, w, h, canvas.rgba(), &text)?;
    Ok(())
}
