//! Plain scene data with typed ids: camera, lights, Phong materials, spheres (analytic),
//! triangles (from `[[triangle]]` and meshes) with their meshes' normals and texture
//! coordinates, and textures. Nothing here reads a file: scene files are read by [`toml`], OBJ
//! meshes and their MTL materials by [`obj`], textures decoded by [`texture`], files found by
//! [`files`] and [`resolve`]; [`builtin`] holds the scenes compiled into the binary and
//! [`save`] writes a scene back as a file; [`names`] says what the materials panel calls a
//! material. The file format: docs/design.md, "Scene files".

pub mod budget;
pub mod builtin;
pub mod camera;
pub mod diag;
pub(crate) mod disk_names;
pub mod files;
pub mod first_look;
pub(crate) mod lfs;
pub mod names;
pub mod obj;
pub mod procedural;
pub mod resolve;
pub mod rules;
pub mod sampling;
pub mod save;
pub mod texture;
pub mod toml;

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

pub use self::toml::{load_scene_str_with, load_scene_str_with_files};
pub use builtin::load_builtin;
pub use camera::{Camera, CameraFrame, primary_ray, primary_rays};
pub use diag::SceneError;
pub use files::{fs_resolver, load_scene_file, load_scene_str, open_scene_arg};
pub use save::scene_to_toml;

/// Index into [`Scene::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct MaterialId(pub u32);

/// Index into [`Scene::objects`]: a named sphere, triangle or mesh, used in trees and errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ObjectId(pub u32);

/// The local illumination model (docs/design.md, "The model").
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
    /// A headlight (`follow_camera = true`): it stands at the render camera's eye
    /// wherever the camera goes; [`Scene::place_lights`] sets its `position`. Always a point
    /// light (radius 0): a ball around the eye would swallow every camera ray.
    #[serde(default)]
    pub follow_camera: bool,
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
    /// MTL `map_Kd`: a texture (index into [`Scene::textures`]) whose texel multiplies `kd`.
    pub diffuse_map: Option<TextureId>,
    /// MTL `map_Ka`: a texture whose texel multiplies `ka`.
    pub ambient_map: Option<TextureId>,
    /// Where `diffuse_map` lies on the texture coordinates (MTL `-s`, `-o`).
    #[serde(default)]
    pub diffuse_map_placement: MapPlacement,
    /// Where `ambient_map` lies on the texture coordinates.
    #[serde(default)]
    pub ambient_map_placement: MapPlacement,
}

/// How a texture map lies on a mesh's texture coordinates: MTL's `-s u v` (scale, a floor tiled
/// four times is `-s 4 4`) and `-o u v` (origin offset); a map is looked up at `uv · scale +
/// offset`. With `-clamp on` it is not repeated: outside `0..1` it takes its edge's texels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapPlacement {
    pub scale: Vec2,
    pub offset: Vec2,
    #[serde(default)]
    pub clamp: bool,
}

impl Default for MapPlacement {
    fn default() -> Self {
        Self {
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
            clamp: false,
        }
    }
}

impl MapPlacement {
    /// The texture coordinate at which the map is sampled for the mesh's `uv`.
    pub fn apply(self, uv: Vec2) -> Vec2 {
        uv * self.scale + self.offset
    }
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
            diffuse_map: None,
            ambient_map: None,
            diffuse_map_placement: MapPlacement::default(),
            ambient_map_placement: MapPlacement::default(),
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

/// Index into [`Scene::textures`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct TextureId(pub u32);

/// An image texture, decoded once from sRGB to linear RGB, looked up with wrapping (repeat) or
/// clamped to its edges, and bilinear filtering.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// The path as the MTL gave it, for messages and the tree.
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first, linear RGB.
    pub texels: Vec<[f32; 3]>,
}

impl Texture {
    /// Bytes its texels take.
    pub fn bytes(width: u32, height: u32) -> u64 {
        u64::from(width) * u64::from(height) * std::mem::size_of::<[f32; 3]>() as u64
    }

    /// The bilinear texel at texture coordinate `uv` (OBJ convention: `v` = 0 at the bottom
    /// row), wrapping in both directions.
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        self.sample_placed(uv, false)
    }

    /// [`Texture::sample`], or with `clamp` the texels of the image's edges outside `0..1` (and
    /// no blend across an edge with the opposite one).
    pub fn sample_placed(&self, uv: Vec2, clamp: bool) -> Vec3 {
        let (w, h) = (self.width as usize, self.height as usize);
        if w == 0 || h == 0 || self.texels.len() < w * h || !uv.is_finite() {
            return Vec3::ONE;
        }
        let (u, v) = if clamp {
            (uv.x.clamp(0.0, 1.0), uv.y.clamp(0.0, 1.0))
        } else {
            (uv.x.rem_euclid(1.0), uv.y.rem_euclid(1.0))
        };
        // Texel centres at half-integers; `v` flipped so row 0 is the top of the image.
        let x = u * w as f32 - 0.5;
        let y = (1.0 - v) * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |i: f32, n: usize| {
            if clamp {
                (i as i64).clamp(0, n as i64 - 1) as usize
            } else {
                (i as i64).rem_euclid(n as i64) as usize
            }
        };
        let (xa, xb) = (wrap(x0, w), wrap(x0 + 1.0, w));
        let (ya, yb) = (wrap(y0, h), wrap(y0 + 1.0, h));
        let at = |x: usize, y: usize| Vec3::from_array(self.texels[y * w + x]);
        let top = at(xa, ya).lerp(at(xb, ya), fx);
        let bottom = at(xa, yb).lerp(at(xb, yb), fx);
        top.lerp(bottom, fy)
    }
}

/// Where a mesh's shading normals come from (`[[mesh]]` `normals`; docs/design.md, "Scene files").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NormalsMode {
    /// The OBJ's `vn` where its faces give them; flat elsewhere.
    #[default]
    File,
    /// Every triangle flat, whatever the file says.
    Flat,
    /// Area-weighted vertex normals computed from the triangles, split where neighbouring faces
    /// meet at more than `crease_angle` degrees.
    Smooth,
}

crate::choice::choice!(NormalsMode {
    File => ("file", "the OBJ's vn where present, flat elsewhere"),
    Flat => ("flat", "every triangle flat: its own normal"),
    Smooth => ("smooth", "area-weighted vertex normals, split at crease_angle degrees"),
});

/// `[[mesh]]` `crease_angle` when not given, in degrees.
pub const DEFAULT_CREASE_ANGLE_DEG: f32 = 60.0;

/// "No normal (or texture coordinate) at this corner": the triangle is flat (untextured).
pub const NO_INDEX: u32 = u32::MAX;

/// Per-vertex shading normals and texture coordinates of one mesh, for the contiguous run of
/// [`Scene::triangles`] it made. Only meshes that have them carry them: a flat, untextured mesh
/// costs nothing here.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshAttributes {
    /// Index in [`Scene::triangles`] of the mesh's first triangle.
    pub first_triangle: u32,
    /// How many triangles follow it.
    pub triangle_count: u32,
    /// Unit vertex normals in world space.
    pub normals: Vec<Vec3>,
    /// One entry per triangle (corner order as in [`Triangle::vertices`]), or empty when no
    /// triangle has normals; a triangle with [`NO_INDEX`] is flat.
    pub normal_indices: Vec<[u32; 3]>,
    /// Texture coordinates (`vt`).
    pub uvs: Vec<Vec2>,
    /// As `normal_indices`, for `uvs`.
    pub uv_indices: Vec<[u32; 3]>,
    /// Vertex colours (`v x y z r g b`), linear RGB; they multiply `kd` as a texel does.
    pub colors: Vec<Vec3>,
    /// As `normal_indices`, for `colors`.
    pub color_indices: Vec<[u32; 3]>,
}

/// The values of triangle `local`'s three corners, by its entry in `indices`; `None` when it
/// has none (no entry, [`NO_INDEX`], or an index past `values`).
#[inline]
fn corner_values<T: Copy>(indices: &[[u32; 3]], values: &[T], local: usize) -> Option<[T; 3]> {
    let idx = indices.get(local)?;
    if idx[0] == NO_INDEX {
        return None;
    }
    Some([
        *values.get(idx[0] as usize)?,
        *values.get(idx[1] as usize)?,
        *values.get(idx[2] as usize)?,
    ])
}

impl MeshAttributes {
    /// The vertex normals of triangle `local` (counted from `first_triangle`), if it has them.
    #[inline]
    pub fn normals_of(&self, local: usize) -> Option<[Vec3; 3]> {
        corner_values(&self.normal_indices, &self.normals, local)
    }

    /// The texture coordinates of triangle `local`, if it has them.
    #[inline]
    pub fn uvs_of(&self, local: usize) -> Option<[Vec2; 3]> {
        corner_values(&self.uv_indices, &self.uvs, local)
    }

    /// The vertex colours of triangle `local`, if it has them.
    #[inline]
    pub fn colors_of(&self, local: usize) -> Option<[Vec3; 3]> {
        corner_values(&self.color_indices, &self.colors, local)
    }

    /// Bytes the arrays take (for the memory budget).
    pub fn bytes(&self) -> u64 {
        (self.normals.len() * 12
            + self.normal_indices.len() * 12
            + self.uvs.len() * 8
            + self.uv_indices.len() * 12
            + self.colors.len() * 12
            + self.color_indices.len() * 12) as u64
    }
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
        /// `normals`: where the shading normals come from.
        normals: NormalsMode,
        /// `crease_angle` in degrees, for `normals = "smooth"`.
        crease_angle_deg: f32,
    },
}

/// A named part of a mesh: the faces after an OBJ `o` or `g` statement (the last one before
/// them, as tobj names its models) that share a material, a contiguous run of
/// [`Scene::triangles`]. One name per run, not per triangle, keeps memory small. Faces before
/// any name, or under the mesh's own name, belong to no part.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshPart {
    /// Index in [`Scene::triangles`] of the run's first triangle.
    pub first_triangle: u32,
    pub triangle_count: u32,
    /// The mesh the run belongs to.
    pub object: ObjectId,
    pub material: MaterialId,
    /// The `o` or `g` name.
    pub name: String,
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
    /// Shared, not copied, by every render of the scene (a camera move in the viewer makes a
    /// new `Scene` with the same triangles); changed only while loading, through
    /// `Arc::make_mut`.
    pub triangles: Arc<Vec<Triangle>>,
    /// Vertex normals and texture coordinates of the meshes that have them, in the order of
    /// their triangles (so a triangle's are found by binary search).
    pub attributes: Vec<Arc<MeshAttributes>>,
    /// The named parts (`o`, `g`) of the meshes, in the order of their triangles; faces
    /// before any name belong to none. Shared like the triangles.
    pub parts: Arc<Vec<MeshPart>>,
    /// The textures materials use, each loaded once.
    pub textures: Vec<Arc<Texture>>,
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

    /// THE rule of lights that follow the camera (`follow_camera = true`): each stands at the
    /// render camera's eye. Whatever sets the camera (the loader, `raytree render --eye`, a
    /// turntable frame, the viewer before each render) calls this, so the image, its tiles, the ray
    /// trees and the scene view all see the light at the same place. Idempotent; other lights stay.
    pub fn place_lights(&mut self) {
        let eye = self.camera.position;
        for light in self.lights.iter_mut().filter(|l| l.follow_camera) {
            light.position = eye;
        }
    }

    pub fn material(&self, id: MaterialId) -> &Material {
        &self.materials[id.0 as usize]
    }

    /// The attributes of the mesh triangle `index` (into [`Scene::triangles`]) belongs to, and
    /// its index within that mesh; `None` for a triangle without any.
    #[inline]
    pub fn attributes_of(&self, index: usize) -> Option<(&MeshAttributes, usize)> {
        if self.attributes.is_empty() {
            return None;
        }
        let i = self
            .attributes
            .partition_point(|a| (a.first_triangle as usize) <= index);
        let a = &**self.attributes.get(i.checked_sub(1)?)?;
        let local = index - a.first_triangle as usize;
        (local < a.triangle_count as usize).then_some((a, local))
    }

    /// The named mesh part triangle `index` (into [`Scene::triangles`]) belongs to, if any.
    pub fn part_of(&self, index: usize) -> Option<&MeshPart> {
        let i = self
            .parts
            .partition_point(|p| (p.first_triangle as usize) <= index);
        let p = self.parts.get(i.checked_sub(1)?)?;
        (index - (p.first_triangle as usize) < p.triangle_count as usize).then_some(p)
    }

    /// The name the ray tree gives what a ray met: the object's name, and for a face of a
    /// named mesh part the part's after a colon ("kitchen: Cabinet_3"). `primitive` counts
    /// the spheres first, then the triangles, as the accelerators do.
    pub fn hit_name(&self, object: ObjectId, primitive: Option<u32>) -> String {
        let name = &self.object(object).name;
        let part = primitive
            .and_then(|p| (p as usize).checked_sub(self.spheres.len()))
            .and_then(|t| self.part_of(t))
            .filter(|p| p.object == object);
        match part {
            Some(p) => format!("{name}: {}", p.name),
            None => name.clone(),
        }
    }

    pub fn texture(&self, id: TextureId) -> Option<&Texture> {
        self.textures.get(id.0 as usize).map(|t| &**t)
    }

    pub fn object(&self, id: ObjectId) -> &Object {
        &self.objects[id.0 as usize]
    }

    /// Axis-aligned bounds of all spheres and triangles (not lights), or `None` when empty.
    /// The viewer asks every frame; the triangles' part is remembered for the last triangle
    /// list asked about (a camera move shares it), so a million-triangle scene is not walked
    /// again each frame.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let (mut lo, mut hi) = triangle_bounds(&self.triangles);
        for s in &self.spheres {
            lo = lo.min(s.center - Vec3::splat(s.radius));
            hi = hi.max(s.center + Vec3::splat(s.radius));
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }

    /// The bounds a view frames: those of where most of the triangles lie when that is a small
    /// part of the [`Scene::bounds`] (docs/design.md, "A bare `.obj`": a model on a ground
    /// plane far larger than it, a train in a long tunnel), with the spheres; else the bounds.
    /// Remembered, as [`Scene::bounds`] is, for the last triangle list asked about.
    pub fn framing_bounds(&self) -> Option<(Vec3, Vec3)> {
        let bounds = self.bounds()?;
        let Some((mut lo, mut hi)) = detail_bounds(&self.triangles) else {
            return Some(bounds);
        };
        for s in &self.spheres {
            lo = lo.min(s.center - Vec3::splat(s.radius));
            hi = hi.max(s.center + Vec3::splat(s.radius));
        }
        Some((lo, hi))
    }
}

/// The last triangle list's [`detail_bounds`].
static DETAIL_BOUNDS: Memo<Option<(Vec3, Vec3)>> = Mutex::new(None);

/// The bounds of where most of `triangles` lie when that is a small part of their bounds
/// (`first_look::detail`), remembered for the last list asked about ([`remembered`]).
fn detail_bounds(triangles: &Arc<Vec<Triangle>>) -> Option<(Vec3, Vec3)> {
    remembered(&DETAIL_BOUNDS, triangles, || {
        let (lo, hi) = triangle_bounds(triangles);
        first_look::detail(triangles, lo, hi).map(|d| d.bounds)
    })
}

/// Keeps `bounds` as the [`detail_bounds`] of `triangles`, worked out already by a bare OBJ's
/// first look, so the views framing the scene do not work them out again.
fn remember_detail_bounds(triangles: &Arc<Vec<Triangle>>, bounds: Option<(Vec3, Vec3)>) {
    remember(&DETAIL_BOUNDS, triangles, bounds);
}

/// The smallest and largest corner of `triangles` (`+inf`, `-inf` when empty), remembered for
/// the last list asked about ([`remembered`]).
fn triangle_bounds(triangles: &Arc<Vec<Triangle>>) -> (Vec3, Vec3) {
    static LAST: Memo<(Vec3, Vec3)> = Mutex::new(None);
    remembered(&LAST, triangles, || {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for t in triangles.iter() {
            for v in t.vertices {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        (lo, hi)
    })
}

/// What was worked out for the last triangle list asked about, with a `Weak` of that list.
type Memo<T> = Mutex<Option<(std::sync::Weak<Vec<Triangle>>, T)>>;

/// `compute()` for `triangles`, or what `memo` holds when it was worked out for the same list.
/// The memo holds a `Weak` of that list: its allocation cannot be reused while the memo lives,
/// so the same address is the same list, and a list changed through `Arc::make_mut` while the
/// memo refers to it moves to a new allocation.
fn remembered<T: Copy>(
    memo: &Memo<T>,
    triangles: &Arc<Vec<Triangle>>,
    compute: impl FnOnce() -> T,
) -> T {
    if let Ok(last) = memo.lock()
        && let Some((list, value)) = &*last
        && std::ptr::eq(list.as_ptr(), Arc::as_ptr(triangles))
    {
        return *value;
    }
    let value = compute();
    remember(memo, triangles, value);
    value
}

/// Puts `value` in `memo` as what was worked out for `triangles`.
fn remember<T>(memo: &Memo<T>, triangles: &Arc<Vec<Triangle>>, value: T) {
    if let Ok(mut last) = memo.lock() {
        *last = Some((Arc::downgrade(triangles), value));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive_bounds(scene: &Scene) -> Option<(Vec3, Vec3)> {
        let points = scene.triangles.iter().flat_map(|t| t.vertices).chain(
            scene
                .spheres
                .iter()
                .flat_map(|s| [s.center - s.radius, s.center + s.radius]),
        );
        points.fold(None, |b, p| match b {
            None => Some((p, p)),
            Some((lo, hi)) => Some((p.min(lo), p.max(hi))),
        })
    }

    /// The remembered triangle bounds follow every way the triangles change: a camera move
    /// (shared list), an edit through `Arc::make_mut` (while the memo refers to the list, and
    /// after), another scene asked about in between, and an emptied list.
    #[test]
    fn remembered_bounds_follow_the_triangles() {
        let mut scene = load_builtin("default").expect("built-in");
        let tri = |a: Vec3| Triangle {
            vertices: [a, a + Vec3::X, a + Vec3::Y],
            material: MaterialId(0),
            object: ObjectId(0),
        };
        Arc::make_mut(&mut scene.triangles).push(tri(Vec3::new(-50.0, 2.0, 3.0)));
        assert_eq!(scene.bounds(), naive_bounds(&scene));
        let (lo, _) = scene.bounds().expect("bounds");
        assert_eq!(lo.x, -50.0);

        let mut moved = scene.clone();
        moved.camera.position += Vec3::ONE;
        assert_eq!(moved.bounds(), scene.bounds());
        // Changed while another scene shares the list (make_mut copies it).
        Arc::make_mut(&mut scene.triangles)[0].vertices[0] = Vec3::new(0.0, 0.0, 900.0);
        assert_eq!(scene.bounds().expect("bounds").1.z, 900.0);
        assert_eq!(moved.bounds(), naive_bounds(&moved));
        assert_ne!(moved.bounds(), scene.bounds());
        drop(moved);

        // Changed in place while only the memo refers to the list (make_mut moves it).
        assert_eq!(scene.bounds(), naive_bounds(&scene));
        Arc::make_mut(&mut scene.triangles)[0].vertices[0] = Vec3::new(0.0, -700.0, 0.0);
        assert_eq!(scene.bounds(), naive_bounds(&scene));
        assert_eq!(scene.bounds().expect("bounds").0.y, -700.0);

        let other = load_builtin("glass").expect("built-in");
        assert_eq!(other.bounds(), naive_bounds(&other));
        assert_eq!(scene.bounds(), naive_bounds(&scene));

        Arc::make_mut(&mut scene.triangles).clear();
        assert_eq!(scene.bounds(), naive_bounds(&scene));
        scene.spheres.clear();
        assert_eq!(scene.bounds(), None);
    }
}
