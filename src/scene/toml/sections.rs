//! The values of the `[render]`, `[camera]`, `[[light]]` and `[[material]]` sections, with their
//! defaults, each held to its rule; and the named choices (`shading`, `normals`).

use glam::Vec3;
use toml::de::DeValue;

use super::reader::Section;
use crate::choice::Choice;
use crate::scene::diag::SceneError;
use crate::scene::{Camera, Light, Material, RenderParams, Shading, rules};

/// A named choice (`shading`, `normals`), or `None` when the key is absent.
pub(super) fn choice<T: Choice>(s: &Section, key: &str) -> Result<Option<T>, SceneError> {
    let Some(v) = s.get(key) else {
        return Ok(None);
    };
    let named = match v.get_ref() {
        DeValue::String(text) => T::from_name(text),
        _ => None,
    };
    named.map(Some).ok_or_else(|| {
        let names: Vec<String> = T::ALL.iter().map(|c| format!("\"{}\"", c.name())).collect();
        s.type_error(key, v, &names.join(" or "))
    })
}

pub(super) fn parse_render(s: &Section) -> Result<RenderParams, SceneError> {
    let d = RenderParams::default();
    let shading = choice::<Shading>(s, "shading")?.unwrap_or(d.shading);
    let render = RenderParams {
        width: s.uint("width", d.width, &rules::IMAGE_SIZE)?,
        height: s.uint("height", d.height, &rules::IMAGE_SIZE)?,
        max_depth: s.uint("max_depth", d.max_depth, &rules::DEPTH)?,
        samples: s.uint("samples", d.samples, &rules::SAMPLES)?,
        background: s.color("background", d.background)?,
        ambient_light: s.color("ambient_light", d.ambient_light)?,
        shading,
    };
    rules::check_render(&render).map_err(|v| s.verdict(&v))?;
    Ok(render)
}

pub(super) fn parse_camera(s: &Section) -> Result<Camera, SceneError> {
    let d = Camera::default();
    let camera = Camera {
        position: s.vec3("position", d.position)?,
        look_at: s.vec3("look_at", d.look_at)?,
        up: s.vec3("up", d.up)?,
        fov_y_deg: s.f32("fov_y", d.fov_y_deg)?,
    };
    match rules::check_camera(&camera) {
        Ok(()) => Ok(camera),
        Err(v) if v.index.is_some() => Err(s.verdict(&v)),
        // No frame: point at what was written, the field itself if present, else what it
        // clashes with.
        Err(v) => {
            let order: &[&str] = match v.field {
                "look_at" => &["look_at", "position"],
                _ => &["up", "look_at", "position"],
            };
            let span = order
                .iter()
                .find_map(|k| s.get(k).map(|v| v.span()))
                .unwrap_or_else(|| s.span.clone());
            let phrase = if v.field == "up" && s.get("up").is_none() {
                format!("(by default [0, 1, 0]) {}", v.phrase)
            } else {
                v.phrase
            };
            Err(s.error(&span, v.field, phrase))
        }
    }
}

pub(super) fn parse_material(s: &Section, name: String) -> Result<Material, SceneError> {
    let d = Material::default();
    let material = Material {
        name,
        ambient: s.color("ambient", d.ambient)?,
        diffuse: s.color("diffuse", d.diffuse)?,
        specular: s.color("specular", d.specular)?,
        shininess: s.f32("shininess", d.shininess)?,
        reflectivity: s.color("reflectivity", d.reflectivity)?,
        transparency: s.color("transparency", d.transparency)?,
        ior: s.f32("ior", d.ior)?,
        diffuse_map: None,
        ambient_map: None,
        diffuse_map_placement: Default::default(),
        ambient_map_placement: Default::default(),
    };
    rules::check_material(&material).map_err(|v| s.verdict(&v))?;
    Ok(material)
}

/// A `[[light]]` named `name`; without a position it stands at `eye`, the camera's position
/// (where it stays only with `follow_camera`: see `Scene::place_lights`).
pub(super) fn parse_light(s: &Section, name: String, eye: Vec3) -> Result<Light, SceneError> {
    let follow_camera = s.boolean("follow_camera", false)?;
    if follow_camera && let Some(v) = s.get("position") {
        return Err(s.error(
            &v.span(),
            "position",
            "cannot be given with `follow_camera = true`: that light stands at the camera's eye",
        ));
    }
    let light = Light {
        name,
        position: s.vec3("position", eye)?,
        color: s.color("color", Vec3::ONE)?,
        radius: s.f32("radius", 0.0)?,
        follow_camera,
    };
    rules::check_light(&light).map_err(|v| s.verdict(&v))?;
    Ok(light)
}
