//! What a hit is: the point and its error bound, the geometric and shading normals, the object,
//! material, barycentrics and texels, as the shading and the tree use them.

use glam::Vec3;

use super::{SurfaceHit, Tracer, div3};
use crate::accel::PrimHit;
use crate::geometry::{Ray, interpolate_normal, sphere_hit_point, triangle_hit_point};
use crate::scene::{MaterialId, ObjectId};

/// What a surface slot holds before [`Tracer::surface_into`] first fills it.
pub(super) const PLACEHOLDER_SURFACE: SurfaceHit = SurfaceHit {
    t: 0.0,
    point: Vec3::ZERO,
    normal: Vec3::Z,
    geometric_normal: Vec3::Z,
    object: ObjectId(0),
    material: MaterialId(0),
    front_face: true,
    barycentric: None,
    vertex_normals: None,
    uv: None,
    texel_kd: None,
    texel_ka: None,
};

impl Tracer {
    /// The distance along `ray` to the closest object and that object's unit geometric normal
    /// there (facing the ray): where the scene view's first look
    /// scores what a view shows face on.
    pub fn first_hit_normal(&self, ray: &Ray) -> Option<(f32, Vec3)> {
        let hit = self
            .accel
            .closest_hit(self.methods(), ray, 0.0, f32::INFINITY)?;
        let (surface, _) = self.surface(ray, &hit);
        surface
            .geometric_normal
            .is_finite()
            .then_some((hit.t, surface.geometric_normal))
    }

    /// Hit point, its error bound, normals, object, material, barycentrics and texture.
    /// Inlined into its callers: returned by value, its result is otherwise copied.
    #[inline(always)]
    pub(super) fn surface(&self, ray: &Ray, hit: &PrimHit) -> (SurfaceHit, Vec3) {
        let mut out = (PLACEHOLDER_SURFACE, Vec3::ZERO);
        self.surface_into(ray, hit, &mut out);
        out
    }

    /// [`Tracer::surface`] written field by field into `out` (a packet's slot): a surface
    /// formed in a temporary and copied into the slot reads its optional fields across the
    /// ends of the stores that wrote only their tags, and stalls.
    #[inline(always)]
    pub(super) fn surface_into(&self, ray: &Ray, hit: &PrimHit, out: &mut (SurfaceHit, Vec3)) {
        let scene = &self.scene;
        let n_spheres = scene.spheres.len();
        let prim = hit.prim as usize;
        let mut vertex_normals = None;
        let mut uvs = None;
        let mut colors = None;
        let (point, error, normal, object, material, barycentric) = if prim < n_spheres {
            let s = &scene.spheres[prim];
            let (p, err) = sphere_hit_point(self.methods().sphere, s.center, s.radius, ray, hit.t);
            let n = div3(p - s.center, s.radius).normalize();
            (p, err, n, s.object, s.material, None)
        } else {
            let index = prim - n_spheres;
            let tri = &scene.triangles[index];
            let v = &tri.vertices;
            let (p, err) = triangle_hit_point(v, hit.b1, hit.b2);
            let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            let b = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
            if let Some((attrs, local)) = scene.attributes_of(index) {
                vertex_normals = attrs.normals_of(local);
                uvs = attrs.uvs_of(local);
                colors = attrs.colors_of(local);
            }
            (p, err, n, tri.object, tri.material, Some(b))
        };
        let front_face = ray.dir.dot(normal) < 0.0;
        let side = if front_face { 1.0 } else { -1.0 };
        let geometric_normal = side * normal;
        let mut shading_normal = geometric_normal;
        let b = barycentric.unwrap_or([1.0, 0.0, 0.0]);
        if let Some(ns) = vertex_normals.as_mut() {
            *ns = ns.map(|n| side * n);
            if let Some(n) = interpolate_normal(ns, b) {
                shading_normal = n;
            }
        }
        let uv = uvs.map(|t| b[0] * t[0] + b[1] * t[1] + b[2] * t[2]);
        let (mut texel_kd, mut texel_ka) = (None, None);
        if let Some(uv) = uv {
            let m = scene.material(material);
            let texel = |map: Option<crate::scene::TextureId>, at: crate::scene::MapPlacement| {
                map.and_then(|id| scene.texture(id))
                    .map(|t| t.sample_placed(at.apply(uv), at.clamp))
            };
            texel_kd = texel(m.diffuse_map, m.diffuse_map_placement);
            texel_ka = texel(m.ambient_map, m.ambient_map_placement);
        }
        // Vertex colours multiply `kd` and `ka` as a texel does (and with one).
        if let Some(c) = colors {
            let c = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
            texel_kd = Some(texel_kd.unwrap_or(Vec3::ONE) * c);
            texel_ka = Some(texel_ka.unwrap_or(Vec3::ONE) * c);
        }
        // Field by field: a whole `SurfaceHit` assigned at once is formed on the stack and
        // copied (+0.2 % instructions on the 80k bench frame).
        let (surface, out_error) = out;
        surface.t = hit.t;
        surface.point = point;
        surface.normal = shading_normal;
        surface.geometric_normal = geometric_normal;
        surface.object = object;
        surface.material = material;
        surface.front_face = front_face;
        surface.barycentric = barycentric;
        surface.vertex_normals = vertex_normals;
        surface.uv = uv;
        surface.texel_kd = texel_kd;
        surface.texel_ka = texel_ka;
        *out_error = error;
    }
}
