//! What the user changed between two states of the viewer's edits, named as a scene file names
//! it ("material glass: ior 1.5 → 1.3"): the compare view says which edit caused the change in
//! the tree. Render settings the tree records itself (max depth, shading, the tracing methods)
//! are named from the trees instead ([`crate::diagram::changes`]), so they are left out here.

use glam::Vec3;

use super::undo::Edits;
use crate::scene::Scene;

/// One phrase per changed value, in the order of a scene file's sections; `scene` names the
/// spheres (its objects).
pub fn between(before: &Edits, after: &Edits, scene: &Scene) -> Vec<String> {
    let mut out = Vec::new();
    let (r, s) = (&before.render, &after.render);
    let mut render = Fields::new("render");
    render.num("samples", r.samples as f32, s.samples as f32);
    render.vec("background", r.background, s.background);
    render.vec("ambient_light", r.ambient_light, s.ambient_light);
    out.extend(render.done());

    let (c, d) = (&before.camera, &after.camera);
    let mut camera = Fields::new("camera");
    camera.vec("position", c.position, d.position);
    camera.vec("look_at", c.look_at, d.look_at);
    camera.vec("up", c.up, d.up);
    camera.num("fov_y", c.fov_y_deg, d.fov_y_deg);
    out.extend(camera.done());

    for (i, l) in after.lights.iter().enumerate() {
        let subject = format!("light {}", named(&l.name, i));
        let Some(k) = before.lights.iter().find(|k| k.name == l.name) else {
            out.push(format!("{subject} added"));
            continue;
        };
        let mut f = Fields::new(&subject);
        if !(l.follow_camera && k.follow_camera) {
            f.vec("position", k.position, l.position);
        }
        f.vec("color", k.color, l.color);
        f.num("radius", k.radius, l.radius);
        if k.follow_camera != l.follow_camera {
            f.text("follow_camera", k.follow_camera, l.follow_camera);
        }
        out.extend(f.done());
    }
    for (i, k) in before.lights.iter().enumerate() {
        if !after.lights.iter().any(|l| l.name == k.name) {
            out.push(format!("light {} removed", named(&k.name, i)));
        }
    }

    for (i, m) in after.materials.iter().enumerate() {
        let subject = format!("material {}", named(&m.name, i));
        let Some(k) = before.materials.iter().find(|k| k.name == m.name) else {
            out.push(format!("{subject} added"));
            continue;
        };
        let mut f = Fields::new(&subject);
        f.vec("ambient", k.ambient, m.ambient);
        f.vec("diffuse", k.diffuse, m.diffuse);
        f.vec("specular", k.specular, m.specular);
        f.num("shininess", k.shininess, m.shininess);
        f.vec("reflectivity", k.reflectivity, m.reflectivity);
        f.vec("transparency", k.transparency, m.transparency);
        f.num("ior", k.ior, m.ior);
        out.extend(f.done());
    }

    for (i, (a, b)) in before.spheres.iter().zip(&after.spheres).enumerate() {
        let name = scene
            .objects
            .get(b.object.0 as usize)
            .map(|o| o.name.as_str())
            .unwrap_or("");
        let mut f = Fields::new(&format!("sphere {}", named(name, i)));
        f.vec("center", a.center, b.center);
        f.num("radius", a.radius, b.radius);
        if a.material != b.material {
            let of = |e: &Edits, id: crate::scene::MaterialId| {
                e.materials
                    .get(id.0 as usize)
                    .map(|m| m.name.clone())
                    .unwrap_or_default()
            };
            f.text("material", of(before, a.material), of(after, b.material));
        }
        out.extend(f.done());
    }
    if before.spheres.len() != after.spheres.len() {
        out.push(format!(
            "spheres {} \u{2192} {}",
            before.spheres.len(),
            after.spheres.len()
        ));
    }
    out
}

/// `name`, or the 1-based position where the scene gave none.
fn named(name: &str, i: usize) -> String {
    if name.is_empty() {
        format!("{}", i + 1)
    } else {
        name.to_string()
    }
}

/// The changed fields of one subject, gathered into one phrase.
struct Fields {
    subject: String,
    changed: Vec<String>,
}

impl Fields {
    fn new(subject: &str) -> Self {
        Self {
            subject: subject.to_string(),
            changed: Vec::new(),
        }
    }

    fn text(&mut self, key: &str, a: impl ToString, b: impl ToString) {
        let (a, b) = (a.to_string(), b.to_string());
        if a != b {
            self.changed.push(format!("{key} {a} \u{2192} {b}"));
        }
    }

    fn num(&mut self, key: &str, a: f32, b: f32) {
        if a != b {
            self.text(key, a, b);
        }
    }

    fn vec(&mut self, key: &str, a: Vec3, b: Vec3) {
        if a != b {
            self.text(key, show(a), show(b));
        }
    }

    fn done(self) -> Option<String> {
        (!self.changed.is_empty()).then(|| format!("{}: {}", self.subject, self.changed.join(", ")))
    }
}

/// A colour or point as a scene file writes it: one number where the three are equal.
fn show(v: Vec3) -> String {
    if v.x == v.y && v.y == v.z {
        format!("{}", v.x)
    } else {
        format!("({}, {}, {})", v.x, v.y, v.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin::load_builtin;

    #[test]
    fn an_ior_edit_is_named_by_its_material_and_key() {
        let scene = load_builtin("default").expect("built in");
        let before = Edits::of(&scene, Default::default());
        let mut after = before.clone();
        let glass = after
            .materials
            .iter()
            .position(|m| m.transparency.max_element() > 0.0)
            .expect("the default scene has a transparent material");
        let name = after.materials[glass].name.clone();
        let ior = after.materials[glass].ior;
        after.materials[glass].ior = 1.3;
        after.camera.fov_y_deg += 5.0;
        let said = between(&before, &after, &scene);
        assert!(
            said.contains(&format!("material {name}: ior {ior} \u{2192} 1.3")),
            "{said:?}"
        );
        assert!(
            said.iter().any(|s| s.starts_with("camera: fov_y")),
            "{said:?}"
        );
        assert_eq!(said.len(), 2, "{said:?}");
        assert!(between(&before, &before, &scene).is_empty());
    }
}
