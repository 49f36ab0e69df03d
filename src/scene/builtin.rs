//! Scenes compiled into the binary: the files of `assets/scenes` and the models they use from
//! `assets/models`, loaded through the same TOML loader with a resolver that reads the
//! embedded text instead of the disk. `default` is Whitted's classic picture (mirror and glass
//! spheres over a checkerboard), `quiz` is the lecture's closing quiz, `glass` shows refraction
//! and total internal reflection, `box` is a closed room with a mirror wall, `smooth` a smooth
//! textured ball beside a faceted copy of itself (`normals = "smooth"` and a `map_Kd`). `acne`
//! and `cracks` are made to show two failures of the naive methods (`--offset fixed`; `--triangle
//! moller-trumbore` or `lecture`) that the defaults do not have.

use super::Scene;
use super::diag::{SceneError, list_and};
use super::toml::load_scene_str_with_files;

/// The built-in scenes, in the order a menu should show them.
pub const NAMES: &[&str] = &[
    "default", "quiz", "glass", "box", "smooth", "acne", "cracks",
];

/// One line on each built-in scene, in the order of [`NAMES`] (`raytree scenes`, `--help`).
const DESCRIPTIONS: &[&str] = &[
    "Whitted's picture: mirror and glass spheres over a checkerboard, a gold torus",
    "the lecture's closing quiz: one triangle, one light, numbers to check by hand",
    "refraction and total internal reflection: a glass sphere and a Porro prism",
    "a closed room seen from inside, a mirror wall, glass and matte spheres",
    "a smooth textured ball beside a faceted copy (vertex normals, map_Kd)",
    "shadow acne on purpose: try --offset fixed against the default",
    "cracks at shared edges: try --triangle moller-trumbore or lecture",
];

/// The one-line description of built-in scene `name`.
pub fn describe(name: &str) -> Option<&'static str> {
    NAMES
        .iter()
        .position(|n| *n == name)
        .map(|i| DESCRIPTIONS[i])
}

/// Every built-in scene with its description, a line each, the names aligned.
pub fn listing() -> String {
    let width = NAMES.iter().map(|n| n.len()).max().unwrap_or(0);
    NAMES
        .iter()
        .zip(DESCRIPTIONS)
        .map(|(n, d)| format!("  {n:<width$}  {d}\n"))
        .collect()
}

const SCENES: &[(&str, &str)] = &[
    ("default", include_str!("../../assets/scenes/default.toml")),
    ("quiz", include_str!("../../assets/scenes/quiz.toml")),
    ("glass", include_str!("../../assets/scenes/glass.toml")),
    ("box", include_str!("../../assets/scenes/box.toml")),
    ("smooth", include_str!("../../assets/scenes/smooth.toml")),
    ("acne", include_str!("../../assets/scenes/acne.toml")),
    ("cracks", include_str!("../../assets/scenes/cracks.toml")),
];

/// Embedded model files by their path from the crate root.
const MODELS: &[(&str, &str)] = &[
    (
        "assets/models/checker_floor.obj",
        include_str!("../../assets/models/checker_floor.obj"),
    ),
    (
        "assets/models/checker_floor.mtl",
        include_str!("../../assets/models/checker_floor.mtl"),
    ),
    (
        "assets/models/torus.obj",
        include_str!("../../assets/models/torus.obj"),
    ),
    (
        "assets/models/torus.mtl",
        include_str!("../../assets/models/torus.mtl"),
    ),
    (
        "assets/models/prism.obj",
        include_str!("../../assets/models/prism.obj"),
    ),
    (
        "assets/models/room.obj",
        include_str!("../../assets/models/room.obj"),
    ),
    (
        "assets/models/room.mtl",
        include_str!("../../assets/models/room.mtl"),
    ),
    (
        "assets/models/smooth_ball.obj",
        include_str!("../../assets/models/smooth_ball.obj"),
    ),
    (
        "assets/models/smooth_ball.mtl",
        include_str!("../../assets/models/smooth_ball.mtl"),
    ),
];

/// Embedded binary files (textures) by their path from the crate root.
const IMAGES: &[(&str, &[u8])] = &[(
    "assets/models/checker.png",
    include_bytes!("../../assets/models/checker.png"),
)];

/// The TOML text of a built-in scene, e.g. to show it or save it as a starting point.
pub fn scene_text(name: &str) -> Option<&'static str> {
    SCENES.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// "there is no `what` "name" (did you mean "glass"?); the built-in scenes are ...": the
/// closest built-in names to a mistyped one.
pub fn unknown(name: &str, what: &str) -> SceneError {
    let names: Vec<String> = NAMES.iter().map(|n| format!("\"{n}\"")).collect();
    let closest = super::diag::suggest(name, NAMES.iter().copied())
        .map(|n| format!(" (did you mean \"{n}\"?)"))
        .unwrap_or_default();
    SceneError(format!(
        "there is no {what} \"{name}\"{closest}; the built-in scenes are {}.",
        list_and(&names)
    ))
}

/// Loads a built-in scene by name ([`NAMES`]); [`Scene::source`] stays `None`.
pub fn load_builtin(name: &str) -> Result<Scene, SceneError> {
    let text = scene_text(name).ok_or_else(|| unknown(name, "built-in scene"))?;
    load_scene_str_with_files(
        text,
        &format!("builtin/{name}.toml"),
        &resolve,
        &resolve_bytes,
    )
}

/// The binary resolver of built-in scenes (textures), as [`resolve`].
pub fn resolve_bytes(path: &str) -> Result<Vec<u8>, String> {
    let wanted = normalize(&format!("assets/scenes/{path}"));
    IMAGES
        .iter()
        .find(|(p, _)| Some(*p) == wanted.as_deref())
        .map(|(_, bytes)| bytes.to_vec())
        .ok_or_else(|| format!("{path}: not among the images built into raytree"))
}

/// The resolver of built-in scenes: `path` is relative to `assets/scenes`, as in the scene
/// files on disk, and must name an embedded model.
pub fn resolve(path: &str) -> Result<String, String> {
    let wanted = normalize(&format!("assets/scenes/{path}"));
    MODELS
        .iter()
        .find(|(p, _)| Some(*p) == wanted.as_deref())
        .map(|(_, text)| (*text).to_string())
        .ok_or_else(|| format!("{path}: not among the models built into raytree"))
}

/// Resolves `.` and `..` in a `/`-separated relative path; `None` if it climbs out of the root.
fn normalize(path: &str) -> Option<String> {
    let mut parts: Vec<&str> = Vec::new();
    for part in path.split(['/', '\\']) {
        match part {
            "" | "." => {}
            ".." => {
                parts.pop()?;
            }
            p => parts.push(p),
        }
    }
    Some(parts.join("/"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_normalized() {
        assert_eq!(
            normalize("assets/scenes/../models/./a.obj").as_deref(),
            Some("assets/models/a.obj")
        );
        assert_eq!(normalize("../../x"), None);
    }

    #[test]
    fn every_name_has_a_scene() {
        assert_eq!(NAMES.len(), SCENES.len());
        assert_eq!(NAMES.len(), DESCRIPTIONS.len());
        for name in NAMES {
            assert!(scene_text(name).is_some(), "{name}");
        }
    }
}
