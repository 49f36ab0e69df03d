//! Local illumination (Phong and Blinn-Phong, SPEC §1) and the directions of the secondary rays:
//! reflection `R = u − 2(u·N)N` and refraction by Snell's law
//! `T = (ηi/ηr)u − (cosθr − (ηi/ηr)cosθi)N` with total internal reflection (lecture:
//! "Reflection and Refraction").

use glam::Vec3;

use crate::scene::{Material, Shading};

/// Mirror direction of the unit incoming direction `u` about the unit normal `n`.
#[inline]
pub fn reflect(u: Vec3, n: Vec3) -> Vec3 {
    u - 2.0 * u.dot(n) * n
}

/// Refracted direction of the unit incoming direction `u` through a surface with unit normal `n`
/// facing the incoming side (`u·n ≤ 0`), where `eta = ηi/ηr`. `None` on total internal
/// reflection, i.e. when `1 − eta²(1 − cos²θi) < 0`.
#[inline]
pub fn refract(u: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = (-u.dot(n)).clamp(0.0, 1.0);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    let cos_r = k.sqrt();
    // Exact arithmetic gives a unit vector; renormalise so rounding never accumulates with depth.
    Some((eta * u - (cos_r - eta * cos_i) * n).normalize())
}

/// Blinn's halfway vector `H = normalize(L + V)`. `L = −V` has no halfway vector; `N·H` is then
/// taken as 0 by returning the zero vector.
#[inline]
pub fn halfway(l: Vec3, v: Vec3) -> Vec3 {
    (l + v).normalize_or_zero()
}

/// One light's contribution at a surface point, before visibility: every number the ray tree
/// shows for a shadow ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightTerms {
    pub n_dot_l: f32,
    pub n_dot_h: f32,
    /// `R_l·V` with `R_l = 2(N·L)N − L`.
    pub r_dot_v: f32,
    /// `C_l ⊙ kd·max(N·L, 0)`.
    pub diffuse: Vec3,
    /// `C_l ⊙ ks·spec` with `spec = max(N·H, 0)^n` (Blinn-Phong) or `max(R·V, 0)^n` (Phong).
    pub specular: Vec3,
}

/// The diffuse and specular terms of one light of colour `color` for unit normal `n`, unit
/// direction to the light `l` and unit direction to the viewer `v`. A light behind the surface
/// (`N·L ≤ 0`) adds nothing, its specular included.
#[inline]
pub fn light_terms(
    shading: Shading,
    material: &Material,
    color: Vec3,
    n: Vec3,
    l: Vec3,
    v: Vec3,
) -> LightTerms {
    let n_dot_l = n.dot(l);
    let h = halfway(l, v);
    let n_dot_h = n.dot(h);
    let r_dot_v = reflect(-l, n).dot(v);
    // NaN (a light exactly at the point) counts as behind the surface.
    if n_dot_l.is_nan() || n_dot_l <= 0.0 {
        return LightTerms {
            n_dot_l,
            n_dot_h,
            r_dot_v,
            diffuse: Vec3::ZERO,
            specular: Vec3::ZERO,
        };
    }
    let cos_spec = match shading {
        Shading::BlinnPhong => n_dot_h,
        Shading::Phong => r_dot_v,
    };
    let spec = cos_spec.max(0.0).powf(material.shininess);
    LightTerms {
        n_dot_l,
        n_dot_h,
        r_dot_v,
        diffuse: color * material.diffuse * n_dot_l,
        specular: color * material.specular * spec,
    }
}

/// `ka ⊙ A`.
#[inline]
pub fn ambient_term(material: &Material, ambient_light: Vec3) -> Vec3 {
    material.ambient * ambient_light
}

#[cfg(test)]
mod tests {
    use super::*;

    const H: f32 = std::f32::consts::FRAC_1_SQRT_2;

    #[test]
    fn reflect_about_floor() {
        let u = Vec3::new(1.0, -1.0, 0.0).normalize();
        let r = reflect(u, Vec3::Y);
        assert!((r - Vec3::new(H, H, 0.0)).length() < 1e-6);
    }

    #[test]
    fn refract_normal_incidence_is_straight() {
        let t = refract(-Vec3::Y, Vec3::Y, 1.0 / 1.5).expect("no TIR at normal incidence");
        assert!((t + Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn refract_obeys_snell() {
        // 45° incidence from air into glass: sin θr = sin 45° / 1.5.
        let u = Vec3::new(H, -H, 0.0);
        let t = refract(u, Vec3::Y, 1.0 / 1.5).expect("entering never reflects totally");
        let sin_r = (H / 1.5) as f64;
        let cos_r = (1.0 - sin_r * sin_r).sqrt();
        assert!((t.x as f64 - sin_r).abs() < 1e-6, "{t}");
        assert!((t.y as f64 + cos_r).abs() < 1e-6, "{t}");
    }

    #[test]
    fn total_internal_reflection_past_critical_angle() {
        // Leaving glass (eta = 1.5): critical angle asin(1/1.5) = 41.8°.
        let n = -Vec3::Y; // facing the incoming ray, which travels upwards inside the glass
        let at = |deg: f32| {
            let a = deg.to_radians();
            refract(Vec3::new(a.sin(), a.cos(), 0.0), n, 1.5)
        };
        assert!(at(41.0).is_some());
        assert!(at(42.0).is_none());
        assert!(at(80.0).is_none());
    }
}
