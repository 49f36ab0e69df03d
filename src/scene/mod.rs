//! Plain scene data with typed ids: camera, lights, Phong materials, spheres (analytic) and
//! triangles (from `[[triangle]]` and meshes). Loading lives in [`load`] (strict TOML with file,
//! line and column in every error), [`obj`] (OBJ/MTL through `tobj`) and [`builtin`] (scenes
//! compiled into the binary). SPEC §3 is the contract for the file format.

pub mod budget;
pub mod builtin;
pub mod camera;
pub mod diag;
pub mod files;
pub mod load;
pub mod obj;
pub mod obj_parse;
pub mod procedural;
pub mod rules;
pub mod sampling;
pub mod save;
pub mod toml_reader;

use std::path::PathBuf;

use glam::Vec3;
use serde::{Deserialize, Serialize};

pub use builtin::load_builtin;
pub use camera::{Camera, CameraFrame, primary_ray};
pub use diag::SceneError;
pub use files::{fs_resolver, load_scene_file, load_scene_str, open_scene_arg};
pub use load::load_scene_str_with;

/// Returns the text of a mesh or material library, given its path as written in the scene
/// (relative to the scene file's folder), or the reason it cannot, as a short phrase. Built-in
/// scenes resolve from strings compiled into the binary, files from the scene's folder.
pub type ResolveFn<'a> = dyn Fn(&str) -> Result<String, String> + 'a;
pub use save::scene_to_toml;

/// Index into [`Scene::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct MaterialId(pub u32);

/// Index into [`Scene::objects`]: a named sphere, triangle or mesh, used in trees and errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ObjectId(pub u32);

/// The local illumination model of SPEC §1.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Shading {
    /// Specular term `max(R·V, 0)^n` with `R = 2(N·L)N − L`.
    Phong,
    /// Specular term `max(N·H, 0)^n` with `H = normalize(L + V)`.
    #[default]
    BlinnPhong,
}

crate::choice::choice!(Shading {
    Phong => ("phong", "specular max(R.V, 0)^n with R = 2(N.L)N - L"),
    BlinnPhong => ("blinn-phong", "specular max(N.H, 0)^n with H = normalize(L + V)"),
});

/// The `[render]` section: what the scene asks of an image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderParams {
    /// Image width in pixels, 1..=16384.
    pub width: u32,
    /// Image height in pixels, 1..=16384.
    pub height: u32,
    /// Deepest child ray traced; the primary ray has depth 0. 0..=64.
    pub max_depth: u32,
    /// Samples per pixel, 1..=65536. Sample 0 is the pixel centre.
    pub samples: u32,
    /// Colour of rays that hit nothing (and of children past `max_depth`), linear RGB.
    pub background: Vec3,
    /// The scene's ambient light `A`, multiplied by each material's `ambient` (`ka`).
    pub ambient_light: Vec3,
    /// Phong or Blinn-Phong specular.
    pub shading: Shading,
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            max_depth: 5,
            samples: 1,
            background: Vec3::ZERO,
            ambient_light: Vec3::ONE,
            shading: Shading::BlinnPhong,
        }
    }
}

/// A point light. A radius > 0 also makes it a visible ball that ends the rays hitting it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Light {
    pub name: String,
    pub position: Vec3,
    pub color: Vec3,
    pub radius: f32,
}

/// A Phong material; every coefficient is linear RGB.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    pub name: String,
    /// `ka`, multiplied by the scene's ambient light.
    pub ambient: Vec3,
    /// `kd`.
    pub diffuse: Vec3,
    /// `ks`.
    pub specular: Vec3,
    /// Phong exponent `n`, ≥ 0.
    pub shininess: f32,
    /// `kr`, weight of the reflected ray.
    pub reflectivity: Vec3,
    /// `kt`, weight of the refracted ray.
    pub transparency: Vec3,
    /// Index of refraction of the solid's inside (outside is air, 1).
    pub ior: f32,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            ambient: Vec3::splat(0.1),
            diffuse: Vec3::splat(0.7),
            specular: Vec3::splat(0.3),
            shininess: 32.0,
            reflectivity: Vec3::ZERO,
            transparency: Vec3::ZERO,
            ior: 1.5,
        }
    }
}

/// An analytic sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub material: MaterialId,
    pub object: ObjectId,
}

/// A triangle; counter-clockwise vertices seen from the front (outside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    pub vertices: [Vec3; 3],
    pub material: MaterialId,
    pub object: ObjectId,
}

/// Where a named object came from, kept so the scene can be saved again as it was written.
#[derive(Clone, Debug, PartialEq)]
pub enum ObjectSource {
    Sphere,
    Triangle,
    Mesh {
        /// The `file` key as written (relative to the scene file).
        file: String,
        /// The `material` override, if any.
        material: Option<String>,
        translate: Vec3,
        /// Euler angles in degrees, applied X then Y then Z.
        rotate_deg: Vec3,
        scale: Vec3,
    },
}

/// A named thing in the scene: one sphere, one triangle or one mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    pub source: ObjectSource,
}

/// A whole scene, ready to be traced. Invariants (checked at load time, never in the hot loop):
/// every number finite, radii > 0, triangles of non-zero area, ids in range.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    pub render: RenderParams,
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub objects: Vec<Object>,
    pub spheres: Vec<Sphere>,
    pub triangles: Vec<Triangle>,
    /// Non-fatal findings of the loader (dropped degenerate triangles, MTL fallbacks), one
    /// sentence each.
    pub warnings: Vec<String>,
    /// The file the scene came from, if any (built-in scenes have none).
    pub source: Option<PathBuf>,
}

impl Scene {
    /// The material named "default" (a `[[material]]` of that name, or [`Material::default`]
    /// added once, when first needed).
    pub fn default_material(&mut self) -> MaterialId {
        if let Some(i) = self.materials.iter().position(|m| m.name == "default") {
            return MaterialId(i as u32);
        }
        self.materials.push(Material::default());
        MaterialId(self.materials.len() as u32 - 1)
    }

    pub fn material(&self, id: MaterialId) -> &Material {
        &self.materials[id.0 as usize]
    }

    pub fn object(&self, id: ObjectId) -> &Object {
        &self.objects[id.0 as usize]
    }

    /// Axis-aligned bounds of all spheres and triangles (not lights), or `None` when empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for s in &self.spheres {
            lo = lo.min(s.center - Vec3::splat(s.radius));
            hi = hi.max(s.center + Vec3::splat(s.radius));
        }
        for t in &self.triangles {
            for v in t.vertices {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }
}
