//! The scene builder: a scene file's sections read in the order the file gives them, objects
//! named and numbered, materials referred to by name, meshes placed and loaded. Values are read
//! by [`super::reader`] and held to [`crate::scene::rules`], so every error names the file,
//! line, column and field; the hot loop never validates anything.
//!
//! Mesh files are read through a resolver ([`ResolveFn`]) so that built-in scenes can take
//! their OBJ and MTL text from strings compiled into the binary.

use std::collections::HashMap;

use glam::Vec3;
use toml::de::{DeTable, DeValue};

use super::keys::{
    CAMERA_KEYS, LIGHT_KEYS, MATERIAL_KEYS, MESH_KEYS, RENDER_KEYS, SPHERE_KEYS, TRIANGLE_KEYS,
    check_sections,
};
use super::names::unique_names;
use super::reader::{Section, Value, syntax_error};
use super::sections::{choice, parse_camera, parse_light, parse_material, parse_render};
use crate::scene::diag::{SceneError, Src, list_and, short, short_path, suggest};
use crate::scene::obj::{self, MeshPlacement};
use crate::scene::resolve::{ResolveBytesFn, ResolveFn, no_binary_files};
use crate::scene::{
    MaterialId, NormalsMode, Object, ObjectId, ObjectSource, Scene, Sphere, Triangle, rules,
};

/// Parses scene TOML, reading meshes and material libraries through `resolve` (textures are
/// not read: each is a missing-texture warning).
pub fn load_scene_str_with(
    text: &str,
    name: &str,
    resolve: &ResolveFn<'_>,
) -> Result<Scene, SceneError> {
    load_scene_str_with_files(text, name, resolve, &no_binary_files)
}

/// Parses scene TOML, reading meshes and material libraries through `resolve` and textures
/// through `resolve_bytes`.
pub fn load_scene_str_with_files(
    text: &str,
    name: &str,
    resolve: &ResolveFn<'_>,
    resolve_bytes: &ResolveBytesFn<'_>,
) -> Result<Scene, SceneError> {
    let src = Src { file: name, text };
    let root = DeTable::parse(text).map_err(|e| syntax_error(&src, &e))?;
    SceneBuilder {
        src: &src,
        resolve,
        resolve_bytes,
        scene: Scene::default(),
        user_materials: HashMap::new(),
    }
    .build(root.get_ref())
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Sphere,
    Triangle,
    Mesh,
}

impl Kind {
    fn label(self) -> &'static str {
        match self {
            Kind::Sphere => "sphere",
            Kind::Triangle => "triangle",
            Kind::Mesh => "mesh",
        }
    }
}

struct SceneBuilder<'a> {
    src: &'a Src<'a>,
    resolve: &'a ResolveFn<'a>,
    resolve_bytes: &'a ResolveBytesFn<'a>,
    scene: Scene,
    /// The `[[material]]` entries by name (MTL materials are not referable by name).
    user_materials: HashMap<String, MaterialId>,
}

impl SceneBuilder<'_> {
    fn build(mut self, root: &DeTable) -> Result<Scene, SceneError> {
        let src = self.src;
        check_sections(src, root)?;
        let get = |name: &str| {
            root.iter()
                .find(|(k, _)| k.get_ref().as_ref() == name)
                .map(|(_, v)| v)
        };
        let sections = |name: &str, keys: &[&str]| -> Result<Vec<Section>, SceneError> {
            let Some(DeValue::Array(items)) = get(name).map(|v| v.get_ref()) else {
                return Ok(Vec::new());
            };
            // Messages call an item by its name where it has one ("material `glass`"), else by
            // its place ("sphere 2").
            let what = |i: usize, v: &Value| {
                let named = match v.get_ref() {
                    DeValue::Table(t) => t.iter().find_map(|(k, v)| match v.get_ref() {
                        DeValue::String(s) if k.get_ref().as_ref() == "name" && !s.is_empty() => {
                            Some(s.to_string())
                        }
                        _ => None,
                    }),
                    _ => None,
                };
                match named {
                    Some(n) => format!("{name} `{n}`"),
                    None => format!("{name} {}", i + 1),
                }
            };
            items
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    let mut section = Section::new(src, what(i, v), v, keys)?;
                    section.place = format!("{name} {}", i + 1);
                    Ok(section)
                })
                .collect()
        };

        if let Some(v) = get("render") {
            let section = Section::new(src, "render".into(), v, RENDER_KEYS)?;
            self.scene.render = parse_render(&section)?;
        }
        if let Some(v) = get("camera") {
            let section = Section::new(src, "camera".into(), v, CAMERA_KEYS)?;
            self.scene.camera = parse_camera(&section)?;
        }

        let lights = sections("light", LIGHT_KEYS)?;
        let refs: Vec<&Section> = lights.iter().collect();
        let names = unique_names(&refs, "light", |i| Ok(format!("light {}", i + 1)))?;
        for (s, name) in lights.iter().zip(names) {
            let light = parse_light(s, name, self.scene.camera.position)?;
            self.scene.lights.push(light);
        }

        let materials = sections("material", MATERIAL_KEYS)?;
        let refs: Vec<&Section> = materials.iter().collect();
        let names = unique_names(&refs, "material", |i| Ok(format!("material {}", i + 1)))?;
        for (s, name) in materials.iter().zip(names) {
            let id = MaterialId(self.scene.materials.len() as u32);
            self.user_materials.insert(name.clone(), id);
            self.scene.materials.push(parse_material(s, name)?);
        }

        // Objects keep the order of the file, whatever their kind, so ids and names follow
        // what the author wrote.
        let mut objects: Vec<(Kind, Section)> = Vec::new();
        for (kind, keys) in [
            (Kind::Sphere, SPHERE_KEYS),
            (Kind::Triangle, TRIANGLE_KEYS),
            (Kind::Mesh, MESH_KEYS),
        ] {
            objects.extend(sections(kind.label(), keys)?.into_iter().map(|s| (kind, s)));
        }
        objects.sort_by_key(|(_, s)| s.span.start);
        let refs: Vec<&Section> = objects.iter().map(|(_, s)| s).collect();
        let names = unique_names(&refs, "object", |i| {
            let (kind, s) = &objects[i];
            default_object_name(*kind, s)
        })?;
        for ((kind, s), name) in objects.iter().zip(names) {
            let object = ObjectId(self.scene.objects.len() as u32);
            match kind {
                Kind::Sphere => self.add_sphere(s, name, object)?,
                Kind::Triangle => self.add_triangle(s, name, object)?,
                Kind::Mesh => self.add_mesh(s, name, object)?,
            }
        }
        Ok(self.scene)
    }

    /// The material named by `key`, or the shared default material when the key is absent.
    fn material(&mut self, s: &Section, key: &str) -> Result<MaterialId, SceneError> {
        let Some((name, span)) = s.string(key)? else {
            return Ok(self.scene.default_material());
        };
        if let Some(&id) = self.user_materials.get(&name) {
            return Ok(id);
        }
        if name == "default" {
            return Ok(self.scene.default_material());
        }
        let mut known: Vec<&str> = self
            .scene
            .materials
            .iter()
            .filter(|m| self.user_materials.contains_key(&m.name))
            .map(|m| m.name.as_str())
            .collect();
        let hint = suggest(&name, known.iter().copied())
            .map(|k| format!(" (did you mean \"{k}\"?)"))
            .unwrap_or_default();
        let listing = match known.len() {
            0 => "no [[material]] is defined".to_string(),
            1..=12 => {
                known.push("default");
                let quoted: Vec<String> = known.iter().map(|k| format!("\"{k}\"")).collect();
                format!("the known materials are {}", list_and(&quoted))
            }
            n => format!("{n} materials are defined"),
        };
        Err(s.error(
            &span,
            key,
            format!(
                "names an unknown material \"{}\"{hint}; {listing}",
                short(&name).escape_debug()
            ),
        ))
    }

    /// Adds the object of a sphere or triangle section and returns the material it names.
    fn add_object(
        &mut self,
        s: &Section,
        name: String,
        source: ObjectSource,
    ) -> Result<MaterialId, SceneError> {
        let material = self.material(s, "material")?;
        self.scene.objects.push(Object { name, source });
        Ok(material)
    }

    fn add_sphere(
        &mut self,
        s: &Section,
        name: String,
        object: ObjectId,
    ) -> Result<(), SceneError> {
        let center = s.vec3("center", Vec3::ZERO)?;
        let radius = s.f32("radius", 1.0)?;
        rules::check_sphere(center, radius).map_err(|v| s.verdict(&v))?;
        let material = self.add_object(s, name, ObjectSource::Sphere)?;
        self.scene.spheres.push(Sphere {
            center,
            radius,
            material,
            object,
        });
        Ok(())
    }

    fn add_triangle(
        &mut self,
        s: &Section,
        name: String,
        object: ObjectId,
    ) -> Result<(), SceneError> {
        const EXPECTED: &str = "an array of 3 corners [[x, y, z], [x, y, z], [x, y, z]]";
        let Some(value) = s.get("vertices") else {
            return Err(s.missing(
                "vertices",
                "three [x, y, z] corners, counter-clockwise seen from the front",
            ));
        };
        let corners = match value.get_ref() {
            DeValue::Array(items) if items.len() == 3 => items,
            _ => return Err(s.type_error("vertices", value, EXPECTED)),
        };
        let mut vertices = [Vec3::ZERO; 3];
        for (v, corner) in vertices.iter_mut().zip(corners.iter()) {
            *v = s.vec3_of("vertices", corner)?;
        }
        rules::check_triangle(&vertices).map_err(|v| s.verdict(&v))?;
        let material = self.add_object(s, name, ObjectSource::Triangle)?;
        std::sync::Arc::make_mut(&mut self.scene.triangles).push(Triangle {
            vertices,
            material,
            object,
        });
        Ok(())
    }

    fn add_mesh(&mut self, s: &Section, name: String, object: ObjectId) -> Result<(), SceneError> {
        let Some((file, file_span)) = s.string("file")? else {
            return Err(s.missing("file", "an OBJ path relative to the scene file"));
        };
        // Only OBJ files are meshes: a scene (or anything else) named here would be read as
        // OBJ text and make no sense, and scenes never include scenes, so there are no cycles.
        if !obj::is_obj_path(&file) {
            return Err(s.error(
                &file_span,
                "file",
                format!(
                    "must name an OBJ file (ending in `.obj`), got \"{}\"",
                    short_path(&file).escape_debug()
                ),
            ));
        }
        let override_name = s.string("material")?.map(|(n, _)| n);
        let material_override = match override_name {
            Some(_) => Some(self.material(s, "material")?),
            None => None,
        };
        let placement = MeshPlacement {
            translate: s.vec3("translate", Vec3::ZERO)?,
            rotate_deg: s.vec3("rotate", Vec3::ZERO)?,
            scale: s.scalar_or_vec3("scale", Vec3::ONE, "a number or an array [x, y, z]")?,
        };
        rules::check_placement(placement.translate, placement.rotate_deg, placement.scale)
            .map_err(|v| s.verdict(&v))?;
        let normals = choice::<NormalsMode>(s, "normals")?.unwrap_or_default();
        let crease_angle_deg = s.f32("crease_angle", crate::scene::DEFAULT_CREASE_ANGLE_DEG)?;
        rules::check_mesh_normals(crease_angle_deg).map_err(|v| s.verdict(&v))?;
        let cannot =
            |problem: String| s.error(&file_span, "file", format!("cannot be loaded: {problem}"));
        let text = (self.resolve)(&file).map_err(cannot)?;
        self.scene.objects.push(Object {
            name: name.clone(),
            source: ObjectSource::Mesh {
                file: file.clone(),
                material: override_name,
                translate: placement.translate,
                rotate_deg: placement.rotate_deg,
                scale: placement.scale,
                normals,
                crease_angle_deg,
            },
        });
        let loaded = obj::add_mesh(
            &mut self.scene,
            &obj::MeshRequest {
                object,
                object_name: &name,
                label: &short_path(&file),
                key: &file,
                text: &text,
                resolve: self.resolve,
                resolve_bytes: self.resolve_bytes,
                material_override,
                placement: &placement,
                normals,
                crease_angle_deg,
            },
        )
        .map_err(|p| cannot(format!("{}{}", short_path(&file), p.with_line())))?;
        if loaded.triangles == 0 {
            self.scene.warnings.push(format!(
                "{}: the mesh has no triangles to show.",
                short_path(&file)
            ));
        }
        Ok(())
    }
}

fn default_object_name(kind: Kind, s: &Section) -> Result<String, SceneError> {
    let number = s.what.rsplit(' ').next().unwrap_or("1");
    Ok(match kind {
        Kind::Mesh => match s.string("file")? {
            Some((file, _)) => obj::file_stem(&file).unwrap_or_else(|| s.what.clone()),
            None => s.what.clone(),
        },
        _ => format!("{} {number}", kind.label()),
    })
}
