//! The shadow ray of one light at a hit: whether it is cast at all (not behind the surface, not
//! when the light's unshadowed contribution is exactly zero) and where it starts. The one place
//! that decides, for the single and the packet trace, the tree and [`Tracer::visits_of`] alike.

use glam::Vec3;

use super::{Recorder, SurfaceHit, Tracer, div3, texelled};
use crate::geometry::{Ray, ShadingNormals, offset_ray_origin, terminator_origin};
use crate::shade::{LightTerms, light_terms_with};

impl Tracer {
    /// Light `light` at a hit (`surface` of primitive `prim`, its point's error bound `error`, its
    /// material, `v` towards the viewer): the unit vector `L` to the light, the distance, the
    /// shadow ray with its length when one is cast, and whether the light is behind the geometric
    /// surface (docs/stability.md, row N3, robust; then no ray either). No ray where `N·L ≤ 0` or
    /// the light's unshadowed contribution is exactly zero (see [`casts_shadow_ray`]). `terms` gets
    /// the light's terms when the recorder is on or the decision needed them. The one place that
    /// decides, for the single and the packet trace alike.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn light_ray<R: Recorder>(
        &self,
        surface: &SurfaceHit,
        prim: u32,
        error: Vec3,
        material: &crate::scene::Material,
        v: Vec3,
        light: &crate::scene::Light,
        base: &mut ShadowBase,
        terms: &mut Option<LightTerms>,
    ) -> LightRay {
        let (p, n) = (surface.point, surface.normal);
        let shading = self.scene.render.shading;
        let to_light = light.position - p;
        let distance = to_light.length();
        let l = div3(to_light, distance);
        let kd = texelled(material.diffuse, surface.texel_kd);
        if R::ENABLED {
            *terms = Some(light_terms_with(
                shading,
                material,
                kd,
                light.color,
                n,
                l,
                v,
            ));
        }
        let mut out = LightRay {
            l,
            distance,
            ray: None,
            behind_surface: false,
        };
        if !(n.dot(l) > 0.0 && casts_shadow_ray(shading, material, kd, light.color, n, l, v, terms))
        {
            return out;
        }
        match self.shadow_start(surface, prim, error, l, base) {
            Some((q, q_error, side)) => {
                // Only objects count as blockers, never lights.
                let offset = self.methods().offset;
                let ng = surface.geometric_normal;
                // The origin depends on the side only through `side·ng < 0` (see
                // `offset_ray_origin`): the `+ng` one is shared by the hit's lights.
                let origin = match base.origin_up {
                    _ if side.dot(ng) < 0.0 => offset_ray_origin(offset, q, q_error, ng, side),
                    Some(origin) => origin,
                    None => {
                        let origin = offset_ray_origin(offset, q, q_error, ng, ng);
                        base.origin_up = Some(origin);
                        origin
                    }
                };
                out.ray = Some(shadow_ray(origin, light.position));
            }
            None => out.behind_surface = true,
        }
        out
    }

    /// Where the shadow ray towards a light in direction `l` starts, the error bound of that point
    /// and the side it is offset to; `None` when the light adds nothing without one
    /// (docs/stability.md, row N3, robust: the light is behind the geometric surface and the smooth
    /// surface does not reach above it). Flat surfaces, and the naive method, start from the hit
    /// point offset to the light's side.
    #[inline(always)]
    fn shadow_start(
        &self,
        surface: &SurfaceHit,
        prim: u32,
        error: Vec3,
        l: Vec3,
        base: &mut ShadowBase,
    ) -> Option<(Vec3, Vec3, Vec3)> {
        let (p, ng) = (surface.point, surface.geometric_normal);
        let robust = self.methods().shading_normals == ShadingNormals::Robust;
        // By reference: the three vertex normals are not copied for flat surfaces.
        let (true, Some(ns), Some(b)) = (robust, &surface.vertex_normals, surface.barycentric)
        else {
            return Some((p, error, l));
        };
        // N1 (Hanika 2021): from the smooth surface, when it lies outside the flat one, offset
        // to the visible side: a light behind the surface is then reached only past its edge
        // (N3), never through it. The same point for every light of the hit.
        let in_front = ng.dot(l) > 0.0;
        let terminator = match base.terminator {
            Some(known) => known,
            None => {
                let index = prim as usize - self.scene.spheres.len();
                let v = &self.scene.triangles[index].vertices;
                let found = terminator_origin(v, ns, b, p, error, ng);
                base.terminator = Some(found);
                found
            }
        };
        match terminator {
            Some((q, q_error, clear)) if in_front || clear => Some((q, q_error, ng)),
            _ => in_front.then_some((p, error, l)),
        }
    }
}

/// Whether a light in front of the surface (`N·L > 0`) needs a shadow ray (`kd` is the
/// material's diffuse times its texel, where textured): not when its
/// unshadowed contribution is exactly zero, so the ray could not change the pixel. The diffuse
/// term is `(C_l ⊙ kd)·N·L` and the specular `(C_l ⊙ ks)·spec`: when `C_l ⊙ kd` has a non-zero
/// channel the ray is cast; otherwise the terms are formed (into `terms`, when not already
/// there) and the ray is cast only when the specular is not exactly zero (a NaN is cast, so
/// it reaches the pixel as before). Both the render and the tree (and [`Tracer::visits_of`])
/// decide here, so a light the tree marks "not traced: contributes nothing" is one the image
/// did not trace.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn casts_shadow_ray(
    shading: crate::scene::Shading,
    material: &crate::scene::Material,
    kd: Vec3,
    color: Vec3,
    n: Vec3,
    l: Vec3,
    v: Vec3,
    terms: &mut Option<LightTerms>,
) -> bool {
    if color * kd != Vec3::ZERO {
        return true;
    }
    // Not `get_or_insert_with`: left to the heuristics, that generic call was sometimes
    // not inlined, and the terms' arithmetic with it.
    let t = match *terms {
        Some(t) => t,
        None => {
            let t = light_terms_with(shading, material, kd, color, n, l, v);
            *terms = Some(t);
            t
        }
    };
    t.specular != Vec3::ZERO || t.diffuse != Vec3::ZERO
}

/// One light seen from a hit: the unit vector to it, its distance, the shadow ray and its length
/// when one is cast, and whether it is behind the geometric surface (docs/stability.md, row N3).
#[derive(Clone, Copy)]
pub(super) struct LightRay {
    pub(super) l: Vec3,
    pub(super) distance: f32,
    pub(super) ray: Option<(Ray, f32)>,
    pub(super) behind_surface: bool,
}

/// What every shadow ray of one hit shares, found for the first light that needs it: where the rays
/// start (docs/stability.md, row N1) and that start offset to the side the geometric normal points
/// to. A hit's lights differ only in their directions, so the second light reuses both.
#[derive(Clone, Copy, Default)]
pub(super) struct ShadowBase {
    /// [`terminator_origin`]'s answer, once asked (robust shading normals on a smooth triangle).
    terminator: Option<Option<(Vec3, Vec3, bool)>>,
    /// The offset origin towards the `+ng` side, once formed.
    origin_up: Option<Vec3>,
}

/// The shadow ray from `origin` (the hit point offset to the side of the surface the ray leaves to:
/// the light's side, or the visible side for robust shading normals, so the ray never starts behind
/// the surface, docs/stability.md, row N3) to the light's centre at `light`, and its length.
#[inline(always)]
fn shadow_ray(origin: Vec3, light: Vec3) -> (Ray, f32) {
    let segment = light - origin;
    let length = segment.length();
    (Ray::new(origin, div3(segment, length)), length)
}
