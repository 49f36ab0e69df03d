//! The subcommands of `raytree`, one file each, and what they share: the options that
//! override a scene, named choices and rule-bound numbers as clap parsers, loading the scene
//! argument, warnings, the thread count.

use anyhow::Result;
use clap::Args;
use raytree::accel::AccelKind;
use raytree::choice::Choice;
use raytree::geometry::{Methods, OffsetMethod, ShadingNormals, SphereMethod, TriangleMethod};
use raytree::scene::{self, Scene, Shading, rules};
use raytree::trace::TraceSettings;

/// `println!` that ignores a closed stdout (`raytree … | head -1`): a broken pipe is not an
/// error worth a panic.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

#[cfg(feature = "lab")]
pub mod lab;
pub mod lesson;
pub mod merge;
pub mod render;
pub mod tree;

#[derive(Args, Debug)]
pub struct SceneOverrides {
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
    /// Where shading and geometric normals disagree (docs/stability.md, rows N1–N3).
    #[arg(long, value_parser = ChoiceParser::<ShadingNormals>::default(),
          default_value = ShadingNormals::default().name())]
    shading_normals: ShadingNormals,
    /// Skip rays whose weight (product of kr/kt) is below this (adaptive depth); 0 = off,
    /// below 1.
    #[arg(long, default_value_t = 0.0, value_parser = cutoff)]
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

/// `--cutoff`, held to [`rules::CUTOFF`].
fn cutoff(text: &str) -> Result<f32, String> {
    let x: f32 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number"))?;
    match rules::number_phrase(x, rules::CUTOFF) {
        None => Ok(x),
        Some(phrase) => Err(format!("{phrase}, got {text}")),
    }
}

/// `--threads`: 0 (every core) to [`rules::MAX_THREADS`].
pub fn threads() -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::<usize>::new().range(0..=rules::MAX_THREADS as u64)
}

/// A whole-number option held to a scene rule's range.
pub fn count(range: &std::ops::RangeInclusive<u32>) -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(i64::from(*range.start())..=i64::from(*range.end()))
}

pub fn parse_pixel(s: &str) -> Result<(u32, u32), String> {
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
pub fn load_scene(arg: &str) -> Result<Scene> {
    Ok(scene::open_scene_arg(arg)?)
}

pub fn apply_overrides(scene: &mut Scene, o: &SceneOverrides) -> TraceSettings {
    let size = (scene.render.width, scene.render.height);
    if let Some(w) = o.width {
        scene.render.width = w;
    }
    if let Some(h) = o.height {
        scene.render.height = h;
    }
    if (scene.render.width, scene.render.height) != size {
        scene::first_look::refit_bare_obj(scene);
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
            shading_normals: o.shading_normals,
        },
        cutoff: o.cutoff,
    }
}

pub fn print_warnings(scene: &Scene) {
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
}

/// Makes `--threads N` hold for everything parallel in the command, the accelerator build
/// included (it runs on rayon's global pool), not only for the render's own pool. 0 keeps
/// rayon's default (every core).
pub fn use_threads(threads: usize) {
    if threads > 0 {
        // Fails only when the global pool already exists, and then it keeps its size: a
        // command configures it first thing, so that cannot happen here.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global();
    }
}
