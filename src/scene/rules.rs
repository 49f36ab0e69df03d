//! The rules every scene obeys, in one place: the limits on sizes, counts and coordinates, the
//! rule of every field, and the checks of whole sections. The TOML loader reports a broken rule
//! at its file, line and column; every viewer edit is held to the same checks; the CLI's ranges
//! are these constants. So the viewer can never save a scene that would not load.
//!
//! The hot loop never validates anything: this is where bad data stops.

use std::ops::RangeInclusive;

use glam::Vec3;

use super::{Camera, Light, Material, ObjectId, ObjectSource, RenderParams, Scene};

/// Largest image side, in pixels.
pub const MAX_IMAGE_SIZE: u32 = 16384;
/// Most samples per pixel.
pub const MAX_SAMPLES: u32 = 65536;
/// Deepest recursion (the primary ray has depth 0).
pub const MAX_DEPTH: u32 = 64;

/// `[render]` `width` and `height`.
pub const IMAGE_SIZE: RangeInclusive<u32> = 1..=MAX_IMAGE_SIZE;
/// `[render]` `samples`.
pub const SAMPLES: RangeInclusive<u32> = 1..=MAX_SAMPLES;
/// `[render]` `max_depth`.
pub const DEPTH: RangeInclusive<u32> = 0..=MAX_DEPTH;

/// Positions (and radii) must lie within this distance of the origin. The BVH's traversal is
/// exact only for scenes below about 1e17 in size (`accel/bvh`), its build overflows to NaN
/// near `f32::MAX` (a mesh moved to x = 3e38 made it panic: `found_bvh_far.toml`), and at 1e15
/// an `f32` already cannot tell apart points 1e8 apart, so no meaningful scene is larger.
pub const MAX_COORDINATE: f32 = 1e15;

/// Largest scene (`.toml`) file read. Hand-written and exported scenes are kilobytes; the TOML
/// tree takes several times the text, so the cap also bounds the parser's memory.
pub const MAX_SCENE_FILE_BYTES: u64 = 64 << 20;

/// Largest OBJ or MTL file read: about 20 million triangles of OBJ text. The memory a mesh
/// needs is estimated from its counts before it is parsed (see `obj`); this cap comes first,
/// so that a huge or endless file is refused before it is read at all.
pub const MAX_MESH_FILE_BYTES: u64 = 512 << 20;

/// A check on one finite number: `None` if fine, else the phrase saying what it must be.
pub type Rule = fn(f32) -> Option<&'static str>;

pub const ANY: Rule = |_| None;
pub const NON_NEGATIVE: Rule = |x| (x < 0.0).then_some("must be at least 0");
pub const POSITIVE: Rule = |x| (x <= 0.0).then_some("must be greater than 0");
pub const NON_ZERO: Rule = |x| (x == 0.0).then_some("must not be 0");
pub const COORDINATE: Rule = |x| {
    (x.abs() > MAX_COORDINATE).then_some("must be within ±1e15 (raytree's limit on scene size)")
};
pub const RADIUS: Rule = |x| match POSITIVE(x) {
    Some(problem) => Some(problem),
    None => COORDINATE(x),
};
pub const LIGHT_RADIUS: Rule = |x| match NON_NEGATIVE(x) {
    Some(problem) => Some(problem),
    None => COORDINATE(x),
};
pub const FOV: Rule =
    |x| (x <= 0.0 || x >= 180.0).then_some("must be between 0 and 180 degrees (both excluded)");

/// `[[mesh]]` `crease_angle`, degrees: faces meeting at more than this keep their own normals.
pub const CREASE_ANGLE: Rule =
    |x| (!(0.0..=180.0).contains(&x)).then_some("must be between 0 and 180 degrees");

/// Worker threads a render or a sweep may ask for (0: every core).
pub const MAX_THREADS: usize = 1024;

/// The weight cutoff of adaptive depth (a render setting, not a scene field): a ray whose
/// weight falls below it is not traced. 1 or more would cut the primary ray itself.
pub const CUTOFF: Rule = |x| (!(0.0..1.0).contains(&x)).then_some("must be at least 0 and below 1");

/// `rule` on `x`, after `x` is known to be finite.
pub fn number_phrase(x: f32, rule: Rule) -> Option<&'static str> {
    if x.is_finite() {
        rule(x)
    } else {
        Some("must be finite")
    }
}

/// What a whole number must be when it is outside `range` (`n`: the number as written, `None`
/// when it does not even fit an `i64`).
pub fn count_phrase(n: Option<i64>, range: &RangeInclusive<u32>) -> Option<String> {
    let (lo, hi) = (*range.start(), *range.end());
    match n.and_then(|n| u32::try_from(n).ok()) {
        Some(n) if range.contains(&n) => None,
        _ => Some(match n {
            Some(n) if n > i64::from(hi) && lo == 0 => format!("must be at most {hi}"),
            Some(n) if n < i64::from(lo) && hi == u32::MAX => format!("must be at least {lo}"),
            _ => format!("must be between {lo} and {hi}"),
        }),
    }
}

/// One broken rule: the field (its key in the scene file), which of its numbers (`Some(i)`:
/// the i-th number of the field in file order, the value is quoted in messages; `None`: the
/// field as a whole) and what it must be.
#[derive(Clone, Debug, PartialEq)]
pub struct Violation {
    pub field: &'static str,
    pub index: Option<usize>,
    pub value: Option<f32>,
    pub phrase: String,
}

fn number(field: &'static str, index: usize, x: f32, rule: Rule) -> Result<(), Violation> {
    match number_phrase(x, rule) {
        None => Ok(()),
        Some(phrase) => Err(Violation {
            field,
            index: Some(index),
            value: Some(x),
            phrase: phrase.into(),
        }),
    }
}

fn vector(field: &'static str, v: Vec3, rule: Rule) -> Result<(), Violation> {
    v.to_array()
        .into_iter()
        .enumerate()
        .try_for_each(|(i, x)| number(field, i, x, rule))
}

fn count(field: &'static str, n: u32, range: &RangeInclusive<u32>) -> Result<(), Violation> {
    match count_phrase(Some(i64::from(n)), range) {
        None => Ok(()),
        Some(phrase) => Err(Violation {
            field,
            index: Some(0),
            value: Some(n as f32),
            phrase,
        }),
    }
}

fn whole(field: &'static str, phrase: &str) -> Violation {
    Violation {
        field,
        index: None,
        value: None,
        phrase: phrase.into(),
    }
}

/// `[render]`.
pub fn check_render(r: &RenderParams) -> Result<(), Violation> {
    count("width", r.width, &IMAGE_SIZE)?;
    count("height", r.height, &IMAGE_SIZE)?;
    count("max_depth", r.max_depth, &DEPTH)?;
    count("samples", r.samples, &SAMPLES)?;
    vector("background", r.background, NON_NEGATIVE)?;
    vector("ambient_light", r.ambient_light, NON_NEGATIVE)
}

/// Why a camera cannot make an image, as the phrase for the field that is wrong.
pub const EYE_ON_TARGET: &str =
    "must be a point apart from `position` (at a distance f32 can represent)";
pub const ZERO_UP: &str = "must not be the zero vector";
pub const PARALLEL_UP: &str =
    "must not be parallel to the view direction from `position` to `look_at`";

/// `[camera]`: its numbers, then a target apart from the eye and an `up` that is neither zero
/// nor (within 1e-4 rad) along the view direction, so the camera's frame exists.
pub fn check_camera(c: &Camera) -> Result<(), Violation> {
    vector("position", c.position, COORDINATE)?;
    vector("look_at", c.look_at, COORDINATE)?;
    vector("up", c.up, ANY)?;
    number("fov_y", 0, c.fov_y_deg, FOV)?;
    let view = (c.look_at - c.position).normalize_or_zero();
    if view == Vec3::ZERO {
        return Err(whole("look_at", EYE_ON_TARGET));
    }
    let up = c.up.normalize_or_zero();
    if up == Vec3::ZERO {
        return Err(whole("up", ZERO_UP));
    }
    if view.cross(up).length() < 1e-4 {
        return Err(whole("up", PARALLEL_UP));
    }
    Ok(())
}

/// `[[light]]`.
pub fn check_light(l: &Light) -> Result<(), Violation> {
    vector("position", l.position, COORDINATE)?;
    vector("color", l.color, NON_NEGATIVE)?;
    number("radius", 0, l.radius, LIGHT_RADIUS)?;
    // A ball around the eye would end every camera ray at once.
    let headlight: Rule = |x| {
        (x != 0.0).then_some("must be 0 for a light that follows the camera (a ball around the eye would hide the scene)")
    };
    if l.follow_camera {
        number("radius", 0, l.radius, headlight)?;
    }
    Ok(())
}

/// `[[material]]`.
pub fn check_material(m: &Material) -> Result<(), Violation> {
    vector("ambient", m.ambient, NON_NEGATIVE)?;
    vector("diffuse", m.diffuse, NON_NEGATIVE)?;
    vector("specular", m.specular, NON_NEGATIVE)?;
    number("shininess", 0, m.shininess, NON_NEGATIVE)?;
    vector("reflectivity", m.reflectivity, NON_NEGATIVE)?;
    vector("transparency", m.transparency, NON_NEGATIVE)?;
    number("ior", 0, m.ior, POSITIVE)
}

/// `[[sphere]]`.
pub fn check_sphere(center: Vec3, radius: f32) -> Result<(), Violation> {
    vector("center", center, COORDINATE)?;
    number("radius", 0, radius, RADIUS)
}

/// A point within the scene's bounds (finite, within ±[`MAX_COORDINATE`]).
pub fn within_bounds(p: Vec3) -> bool {
    p.is_finite() && p.abs().max_element() <= MAX_COORDINATE
}

/// A triangle that can be seen: finite corners and a finite, non-zero cross product. The
/// others are refused in scene files and skipped in meshes.
pub fn is_visible_triangle(v: &[Vec3; 3]) -> bool {
    let cross = (v[1] - v[0]).cross(v[2] - v[0]);
    v.iter().all(|p| p.is_finite()) && cross.is_finite() && cross != Vec3::ZERO
}

/// `[[triangle]]` `vertices`: nine coordinates, then a visible triangle.
pub fn check_triangle(vertices: &[Vec3; 3]) -> Result<(), Violation> {
    for (corner, v) in vertices.iter().enumerate() {
        for (axis, x) in v.to_array().into_iter().enumerate() {
            number("vertices", 3 * corner + axis, x, COORDINATE)?;
        }
    }
    if !is_visible_triangle(vertices) {
        return Err(whole(
            "vertices",
            "gives a triangle of zero area, which would never be seen",
        ));
    }
    Ok(())
}

/// `[[mesh]]` placement.
pub fn check_placement(translate: Vec3, rotate_deg: Vec3, scale: Vec3) -> Result<(), Violation> {
    vector("translate", translate, COORDINATE)?;
    vector("rotate", rotate_deg, ANY)?;
    vector("scale", scale, NON_ZERO)
}

/// `[[mesh]]` `crease_angle` (degrees).
pub fn check_mesh_normals(crease_angle_deg: f32) -> Result<(), Violation> {
    number("crease_angle", 0, crease_angle_deg, CREASE_ANGLE)
}

/// `what field `key` phrase[, got value]`: the words the loader uses, for checks of scenes that
/// come from elsewhere (the viewer's edits), where there is no file to point into.
pub fn describe(what: &str, v: &Violation) -> String {
    let got = v.value.map(|x| format!(", got {x}")).unwrap_or_default();
    format!("{what} field `{}` {}{got}", v.field, v.phrase)
}

/// Names of one kind (lights, materials, objects), as the loader requires them: not blank,
/// and all different. The first broken one as a violation of field `name`.
pub fn check_names<'a>(
    names: impl IntoIterator<Item = &'a str>,
    kind: &str,
) -> Result<(), Violation> {
    let mut seen = std::collections::HashSet::new();
    for name in names {
        if name.trim().is_empty() {
            return Err(whole("name", "must not be empty"));
        }
        if !seen.insert(name) {
            return Err(whole(
                "name",
                &format!(
                    "repeats \"{}\", the name of another {kind}; {kind} names must be unique",
                    name.escape_debug()
                ),
            ));
        }
    }
    Ok(())
}

/// Every rule over a whole scene that did not come from a file (a viewer edit): the first
/// broken one as a phrase naming the section and field. `geometry`: also every sphere and
/// triangle (an edit that leaves the geometry alone need not walk a million triangles).
pub fn check_scene(s: &Scene, geometry: bool) -> Result<(), String> {
    check_render(&s.render).map_err(|v| describe("render", &v))?;
    check_camera(&s.camera).map_err(|v| describe("camera", &v))?;
    // Names first, as the loader reads them.
    check_names(s.lights.iter().map(|l| l.name.as_str()), "light")
        .map_err(|v| describe("light", &v))?;
    for l in &s.lights {
        check_light(l).map_err(|v| describe(&format!("light \"{}\"", l.name), &v))?;
    }
    for m in &s.materials {
        check_material(m).map_err(|v| describe(&format!("material \"{}\"", m.name), &v))?;
    }
    if geometry {
        // The first broken object in the order the loader meets them (file order, the order
        // of `objects`), so that both name the same field.
        let mut first: Option<(u32, String)> = None;
        let mut note = |object: ObjectId, what: &str, v: Violation| {
            if first.as_ref().is_none_or(|(o, _)| object.0 < *o) {
                let what = format!("{what} \"{}\"", s.object(object).name);
                first = Some((object.0, describe(&what, &v)));
            }
        };
        for sphere in &s.spheres {
            if let Err(v) = check_sphere(sphere.center, sphere.radius) {
                note(sphere.object, "sphere", v);
            }
        }
        for (i, o) in s.objects.iter().enumerate() {
            if let ObjectSource::Mesh {
                translate,
                rotate_deg,
                scale,
                crease_angle_deg,
                ..
            } = &o.source
            {
                let checked = check_placement(*translate, *rotate_deg, *scale)
                    .and_then(|()| check_mesh_normals(*crease_angle_deg));
                if let Err(v) = checked {
                    note(ObjectId(i as u32), "mesh", v);
                }
            }
        }
        for t in s.triangles.iter() {
            if let Err(v) = check_triangle(&t.vertices) {
                note(t.object, "object", v);
            }
        }
        if let Some((_, message)) = first {
            return Err(message);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_say_what_they_must_be() {
        assert_eq!(count_phrase(Some(5), &IMAGE_SIZE), None);
        assert_eq!(
            count_phrase(Some(0), &IMAGE_SIZE).as_deref(),
            Some("must be between 1 and 16384")
        );
        assert_eq!(
            count_phrase(Some(65), &DEPTH).as_deref(),
            Some("must be at most 64")
        );
        assert_eq!(
            count_phrase(None, &SAMPLES).as_deref(),
            Some("must be between 1 and 65536")
        );
    }

    #[test]
    fn cameras_need_a_frame() {
        let ok = Camera::default();
        assert_eq!(check_camera(&ok), Ok(()));
        let on_target = Camera {
            look_at: ok.position,
            ..ok.clone()
        };
        assert_eq!(
            check_camera(&on_target).map_err(|v| v.field),
            Err("look_at")
        );
        // Within 1e-4 rad of the view direction is as bad as exactly along it.
        let nearly = Camera {
            up: Vec3::new(1e-5, 0.0, -1.0),
            ..ok.clone()
        };
        let v = check_camera(&nearly).expect_err("parallel up");
        assert_eq!((v.field, v.phrase.as_str()), ("up", PARALLEL_UP));
        let far = Camera {
            position: Vec3::new(2e15, 0.0, 0.0),
            ..ok
        };
        let v = check_camera(&far).expect_err("too far");
        assert_eq!((v.field, v.index), ("position", Some(0)));
    }

    #[test]
    fn scenes_from_elsewhere_get_the_loaders_words() {
        let mut s = Scene::default();
        assert_eq!(check_scene(&s, true), Ok(()));
        s.render.samples = 0;
        assert_eq!(
            check_scene(&s, false),
            Err("render field `samples` must be between 1 and 65536, got 0".into())
        );
        s.render.samples = 1;
        s.lights.push(Light {
            name: "key".into(),
            position: Vec3::ZERO,
            color: Vec3::new(1.0, f32::NAN, 1.0),
            radius: 0.0,
            follow_camera: false,
        });
        assert_eq!(
            check_scene(&s, false),
            Err("light \"key\" field `color` must be finite, got NaN".into())
        );
        // Two lights of one name: the loader would refuse the saved file, so the viewer does.
        s.lights[0].color = Vec3::ONE;
        let twin = s.lights[0].clone();
        s.lights.push(twin);
        assert_eq!(
            check_scene(&s, false),
            Err(
                "light field `name` repeats \"key\", the name of another light; light names \
                 must be unique"
                    .into()
            )
        );
    }
}
