//! Writing a [`Scene`] back as a scene file (docs/design.md, "Scene files"). Everything is written
//! explicitly (every render and camera field, every light, material and object with its name), so
//! the file loads back to an equal scene: meshes as their `[[mesh]]` entry (file and placement, not
//! their triangles), `[[triangle]]` objects as triangles, and every material, including those that
//! came from an MTL (`<mesh>/<mtl name>`): a `[[material]]` of that name overrides the MTL on
//! loading, so materials edited in the viewer survive a save.

use std::fmt::Write;

use glam::Vec3;

use super::{ObjectSource, Scene};
use crate::choice::Choice;

/// The scene as TOML. Mesh `file` paths are written as they were loaded (relative to the
/// original scene file), so save next to it or adjust them.
pub fn scene_to_toml(scene: &Scene) -> String {
    let mut out = String::from("# raytree scene (docs/design.md, \"Scene files\")\n\n");
    let r = &scene.render;
    out += "[render]\n";
    line(&mut out, "width", r.width);
    line(&mut out, "height", r.height);
    line(&mut out, "max_depth", r.max_depth);
    line(&mut out, "samples", r.samples);
    line(&mut out, "background", color(r.background));
    line(&mut out, "ambient_light", color(r.ambient_light));
    line(&mut out, "shading", string(r.shading.name()));

    let c = &scene.camera;
    out += "\n[camera]\n";
    line(&mut out, "position", vec3(c.position));
    line(&mut out, "look_at", vec3(c.look_at));
    line(&mut out, "up", vec3(c.up));
    line(&mut out, "fov_y", float(c.fov_y_deg));

    for l in &scene.lights {
        out += "\n[[light]]\n";
        line(&mut out, "name", string(&l.name));
        if l.follow_camera {
            // It stands at the camera's eye: its position is the camera's.
            line(&mut out, "follow_camera", "true");
        } else {
            line(&mut out, "position", vec3(l.position));
        }
        line(&mut out, "color", color(l.color));
        line(&mut out, "radius", float(l.radius));
    }

    for m in &scene.materials {
        out += "\n[[material]]\n";
        line(&mut out, "name", string(&m.name));
        line(&mut out, "ambient", color(m.ambient));
        line(&mut out, "diffuse", color(m.diffuse));
        line(&mut out, "specular", color(m.specular));
        line(&mut out, "shininess", float(m.shininess));
        line(&mut out, "reflectivity", color(m.reflectivity));
        line(&mut out, "transparency", color(m.transparency));
        line(&mut out, "ior", float(m.ior));
    }

    // The primitive of each sphere and triangle object, found in one pass.
    let mut sphere_of = vec![None; scene.objects.len()];
    for s in &scene.spheres {
        if let Some(slot) = sphere_of.get_mut(s.object.0 as usize) {
            slot.get_or_insert(s);
        }
    }
    let mut triangle_of = vec![None; scene.objects.len()];
    for t in scene.triangles.iter() {
        if let Some(slot) = triangle_of.get_mut(t.object.0 as usize) {
            slot.get_or_insert(t);
        }
    }
    let material_name = |id: super::MaterialId| {
        scene
            .materials
            .get(id.0 as usize)
            .map_or("default", |m| m.name.as_str())
    };

    for (i, object) in scene.objects.iter().enumerate() {
        match &object.source {
            ObjectSource::Sphere => {
                let Some(s) = sphere_of[i] else { continue };
                out += "\n[[sphere]]\n";
                line(&mut out, "name", string(&object.name));
                line(&mut out, "center", vec3(s.center));
                line(&mut out, "radius", float(s.radius));
                line(&mut out, "material", string(material_name(s.material)));
            }
            ObjectSource::Triangle => {
                let Some(t) = triangle_of[i] else { continue };
                out += "\n[[triangle]]\n";
                line(&mut out, "name", string(&object.name));
                let [a, b, c] = t.vertices.map(vec3);
                line(&mut out, "vertices", format!("[{a}, {b}, {c}]"));
                line(&mut out, "material", string(material_name(t.material)));
            }
            ObjectSource::Mesh {
                file,
                material,
                translate,
                rotate_deg,
                scale,
                normals,
                crease_angle_deg,
            } => {
                out += "\n[[mesh]]\n";
                line(&mut out, "name", string(&object.name));
                line(&mut out, "file", string(file));
                if let Some(material) = material {
                    line(&mut out, "material", string(material));
                }
                line(&mut out, "translate", vec3(*translate));
                line(&mut out, "rotate", vec3(*rotate_deg));
                line(&mut out, "scale", color(*scale));
                line(&mut out, "normals", string(normals.name()));
                line(&mut out, "crease_angle", float(*crease_angle_deg));
            }
        }
    }
    out
}

fn line(out: &mut String, key: &str, value: impl std::fmt::Display) {
    // Writing to a String cannot fail.
    let _ = writeln!(out, "{key} = {value}");
}

/// The shortest text that reads back as the same `f32`, always in TOML float syntax.
fn float(x: f32) -> String {
    // `{:?}` prints `1.0` rather than `1` and uses exponents for very large or small values,
    // so the text is never mistaken for an (overflowing) TOML integer. TOML spells the
    // non-finite values its own way; a scene holding one is written as valid TOML, so that the
    // loader, not the TOML parser, says which field is wrong.
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        (if x > 0.0 { "inf" } else { "-inf" }).into()
    } else {
        format!("{x:?}")
    }
}

fn vec3(v: Vec3) -> String {
    format!("[{}, {}, {}]", float(v.x), float(v.y), float(v.z))
}

/// A scalar when all three channels agree, else `[r, g, b]`.
fn color(v: Vec3) -> String {
    if v.x == v.y && v.y == v.z {
        float(v.x)
    } else {
        vec3(v)
    }
}

/// A TOML basic string.
fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out += "\\\"",
            '\\' => out += "\\\\",
            '\n' => out += "\\n",
            '\t' => out += "\\t",
            '\r' => out += "\\r",
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04X}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_read_back_exactly() {
        for x in [1.0f32, 0.1, 1e-7, 3.4e38, -0.0, 0.70710677, 123456.79] {
            // The loader parses float text straight to f32 (no double rounding through f64).
            let text = float(x);
            assert!(
                text.contains(['.', 'e']),
                "{text} must not read as an integer"
            );
            let back: f32 = text.parse().expect("a float");
            assert_eq!(back.to_bits(), x.to_bits(), "{text}");
        }
        assert_eq!(
            [f32::NAN, f32::INFINITY, f32::NEG_INFINITY].map(float),
            ["nan", "inf", "-inf"]
        );
    }

    #[test]
    fn strings_are_escaped() {
        assert_eq!(string("a\"b\\c\u{1}"), "\"a\\\"b\\\\c\\u0001\"");
    }
}
