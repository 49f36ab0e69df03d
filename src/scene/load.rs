//! The scene builder (SPEC §3): the file format's sections and keys, their defaults, object and
//! material names, meshes placed and loaded, in the order the file gives them. Values are read
//! by [`super::toml_reader`] and held to [`super::rules`], so every error names the file, line,
//! column and field; the hot loop never validates anything.
//!
//! Mesh files are read through a resolver ([`ResolveFn`]) so that built-in scenes can take
//! their OBJ and MTL text from strings compiled into the binary.

use std::collections::HashMap;
use std::ops::Range;

use glam::Vec3;
use toml::de::{DeTable, DeValue};

use super::diag::{SceneError, Src, list_and, short, short_path, suggest};
use super::obj::{self, MeshPlacement};
use super::rules;
use super::toml_reader::{Section, describe, syntax_error};
use super::{
    Camera, Light, Material, MaterialId, NormalsMode, Object, ObjectId, ObjectSource, RenderParams,
    ResolveBytesFn, ResolveFn, Scene, Shading, Sphere, Triangle,
};
use crate::choice::Choice;

/// Parses scene TOML, reading meshes and material libraries through `resolve` (textures are
/// not read: each is a missing-texture warning).
pub fn load_scene_str_with(
    text: &str,
    name: &str,
    resolve: &ResolveFn<'_>,
) -> Result<Scene, SceneError> {
    load_scene_str_with_files(text, name, resolve, &super::no_binary_files)
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

const SECTIONS: &[&str] = &[
    "render", "camera", "light", "material", "sphere", "triangle", "mesh",
];
const RENDER_KEYS: &[&str] = &[
    "width",
    "height",
    "max_depth",
    "samples",
    "background",
    "ambient_light",
    "shading",
];
const CAMERA_KEYS: &[&str] = &["position", "look_at", "up", "fov_y"];
const LIGHT_KEYS: &[&str] = &["name", "position", "color", "radius", "follow_camera"];
const MATERIAL_KEYS: &[&str] = &[
    "name",
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "reflectivity",
    "transparency",
    "ior",
];
const SPHERE_KEYS: &[&str] = &["name", "center", "radius", "material"];
const TRIANGLE_KEYS: &[&str] = &["name", "vertices", "material"];
const MESH_KEYS: &[&str] = &[
    "name",
    "file",
    "material",
    "translate",
    "rotate",
    "scale",
    "normals",
    "crease_angle",
];

/// `[section]` or `[[section]]`, as written in the format.
fn section_syntax(name: &str) -> String {
    if matches!(name, "render" | "camera") {
        format!("[{name}]")
    } else {
        format!("[[{name}]]")
    }
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

/// Every top-level key must be a known section of the right shape (`[render]` a table,
/// `[[sphere]]` an array of tables).
fn check_sections(src: &Src, root: &DeTable) -> Result<(), SceneError> {
    for (key, value) in root.iter() {
        let name = key.get_ref().as_ref();
        if !SECTIONS.contains(&name) {
            let home = [("render", RENDER_KEYS), ("camera", CAMERA_KEYS)]
                .into_iter()
                .find(|(_, keys)| keys.contains(&name));
            let hint = match home {
                Some((section, _)) => format!(" (it belongs under [{section}])"),
                None => suggest(name, SECTIONS.iter().copied())
                    .map(|s| format!(" (did you mean `{}`?)", section_syntax(s)))
                    .unwrap_or_default(),
            };
            let what = match value.get_ref() {
                DeValue::Table(_) | DeValue::Array(_) => "unknown section",
                _ => "unknown top-level key",
            };
            let listed: Vec<String> = SECTIONS.iter().map(|s| section_syntax(s)).collect();
            return Err(src.error(
                &key.span(),
                format!(
                    "{what} `{}`{hint}; the sections are {}",
                    short(name),
                    list_and(&listed)
                ),
            ));
        }
        let wants_table = matches!(name, "render" | "camera");
        let shape_ok = match value.get_ref() {
            DeValue::Table(_) => wants_table,
            DeValue::Array(_) => !wants_table,
            _ => false,
        };
        if !shape_ok {
            let shape = if wants_table {
                "a table"
            } else {
                "an array of tables"
            };
            return Err(src.error(
                &value.span(),
                format!(
                    "`{name}` must be written as {} ({shape}), got {}",
                    section_syntax(name),
                    describe(value.get_ref())
                ),
            ));
        }
    }
    Ok(())
}

/// The names of `sections` (their `name` keys, unique), with `default(i)` for the others,
/// stepping around the names given explicitly.
fn unique_names(
    sections: &[&Section],
    kind: &str,
    default: impl Fn(usize) -> Result<String, SceneError>,
) -> Result<Vec<String>, SceneError> {
    let mut names = Names::default();
    let mut given = Vec::with_capacity(sections.len());
    for s in sections {
        let name = s.string("name")?;
        if let Some((name, span)) = &name {
            names.claim(s, name, span, kind)?;
        }
        given.push(name.map(|(name, _)| name));
    }
    given
        .into_iter()
        .enumerate()
        .map(|(i, name)| match name {
            Some(name) => Ok(name),
            None => Ok(names.fresh(&default(i)?)),
        })
        .collect()
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
            let what = |i: usize| format!("{name} {}", i + 1);
            items
                .iter()
                .enumerate()
                .map(|(i, v)| Section::new(src, what(i), v, keys))
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
                // Without a position, a light at the eye (where it stays only with
                // `follow_camera`: see `Scene::place_lights`).
                position: s.vec3("position", self.scene.camera.position)?,
                color: s.color("color", Vec3::ONE)?,
                radius: s.f32("radius", 0.0)?,
                follow_camera,
            };
            rules::check_light(&light).map_err(|v| s.verdict(&v))?;
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
        let crease_angle_deg = s.f32("crease_angle", super::DEFAULT_CREASE_ANGLE_DEG)?;
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
        if loaded == 0 {
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

/// Names given so far, so that duplicates are errors and default names stay unique.
#[derive(Default)]
struct Names {
    taken: HashMap<String, String>,
}

impl Names {
    /// An explicit name (`name` of section `s`): an error if an earlier one is the same.
    fn claim(
        &mut self,
        s: &Section,
        name: &str,
        span: &Range<usize>,
        kind: &str,
    ) -> Result<(), SceneError> {
        if let Some(first) = self.taken.get(name) {
            return Err(s.error(
                span,
                "name",
                format!(
                    "repeats \"{}\", the name of {first}; {kind} names must be unique",
                    short(name).escape_debug()
                ),
            ));
        }
        self.taken.insert(name.to_string(), s.what.clone());
        Ok(())
    }

    /// `base`, or `base 2`, `base 3`, ... if taken.
    fn fresh(&mut self, base: &str) -> String {
        let mut name = base.to_string();
        let mut n = 2;
        while self.taken.contains_key(&name) {
            name = format!("{base} {n}");
            n += 1;
        }
        self.taken.insert(name.clone(), String::new());
        name
    }
}

/// A named choice (`shading`, `normals`), or `None` when the key is absent.
fn choice<T: Choice>(s: &Section, key: &str) -> Result<Option<T>, SceneError> {
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

fn parse_render(s: &Section) -> Result<RenderParams, SceneError> {
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

fn parse_camera(s: &Section) -> Result<Camera, SceneError> {
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

fn parse_material(s: &Section, name: String) -> Result<Material, SceneError> {
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
    };
    rules::check_material(&material).map_err(|v| s.verdict(&v))?;
    Ok(material)
}
