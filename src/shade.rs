//! Local illumination (Phong and Blinn-Phong, docs/design.md, "The model") and the directions of
//! the secondary rays: reflection `R = u − 2(u·N)N` and refraction by Snell's law
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
/// reflection, i.e. when `cos²θr = 1 − eta²(1 − cos²θi) < 0`.
#[inline]
pub fn refract(u: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    // The same index on both sides is no interface: the ray goes on as it came, bit for bit
    // (the normalisation below would move a direction that is unit only to within rounding).
    if eta == 1.0 {
        return Some(u);
    }
    let cos_i = (-u.dot(n)).clamp(0.0, 1.0);
    let eta2 = eta * eta;
    // cos²θr as `(1 − eta²) + eta²·cos²θi`, not `1 − eta²(1 − cos²θi)`: the latter cancels at
    // grazing angles (cos θi → 0), where `1 − cos²θi` rounds to within ε/2 of 1, and bends a
    // ray by up to ~1e-4 for an index near 1.
    let k = (1.0 - eta2) + eta2 * (cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    let cos_r = k.sqrt();
    // Exact arithmetic gives a unit vector; renormalise so rounding never accumulates with depth
    // (measured: leaving it out or normalising only past a tolerance reverses worse, see
    // docs/stability.md, row R1).
    Some((eta * u - (cos_r - eta * cos_i) * n).normalize())
}

/// Blinn's halfway vector `H = normalize(L + V)`. `L = −V` has no halfway vector; `N·H` is then
/// taken as 0 by returning the zero vector.
#[inline]
pub fn halfway(l: Vec3, v: Vec3) -> Vec3 {
    (l + v).normalize_or_zero()
}

/// `N·H` with `H` Blinn's halfway vector, formed as `N·(L + V) / |L + V|`: the normalised
/// vector is never formed (fewer roundings than `N·halfway(L, V)`, and the division no
/// longer waits for the three products of a normalisation). 0 where `L + V` has no direction
/// (`L = −V`) or is not finite, as [`halfway`]'s zero vector gives.
#[inline(always)]
pub fn cos_halfway(n: Vec3, l: Vec3, v: Vec3) -> f32 {
    let s = l + v;
    let len = s.length();
    if len > 0.0 && len.is_finite() {
        n.dot(s) / len
    } else {
        0.0
    }
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
    light_terms_with(shading, material, material.diffuse, color, n, l, v)
}

/// [`light_terms`] with the diffuse coefficient `kd` given (the material's, times a texel).
/// Always inlined: shading calls it once per unblocked light, and left to the heuristics it
/// was sometimes a call (+3 % of `glass`'s instructions when it was).
#[inline(always)]
pub fn light_terms_with(
    shading: Shading,
    material: &Material,
    kd: Vec3,
    color: Vec3,
    n: Vec3,
    l: Vec3,
    v: Vec3,
) -> LightTerms {
    let n_dot_l = n.dot(l);
    let n_dot_h = cos_halfway(n, l, v);
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
    let ks = color * material.specular;
    LightTerms {
        n_dot_l,
        n_dot_h,
        r_dot_v,
        diffuse: color * kd * n_dot_l,
        specular: specular_term(ks, cos_spec, material.shininess),
    }
}

/// `ks·max(cos, 0)^shininess` (`ks` is `C_l ⊙ ks`). Where `ks` is zero in every channel (a
/// mirror or glass without highlights) the power is not formed: for a shininess in
/// `[0, 10⁶]` it is finite and not negative (`cos` of unit vectors is at most `1` plus a few
/// ulp), so the product is `ks` itself, signed zeros included, bit for bit.
#[inline(always)]
fn specular_term(ks: Vec3, cos: f32, shininess: f32) -> Vec3 {
    if ks == Vec3::ZERO && (0.0..=MAX_SKIPPED_SHININESS).contains(&shininess) {
        return ks;
    }
    ks * highlight_power(cos.max(0.0), shininess)
}

/// Largest shininess for which [`specular_term`] may skip the power.
const MAX_SKIPPED_SHININESS: f32 = 1e6;

/// `x^shininess` for the specular term (`x = max(cos, 0)`). A whole-number shininess up to
/// [`MAX_WHOLE_SHININESS`] (the built-in scenes' 10, 40, 200 and 300 among them) is raised by
/// repeated squaring in `f64`: relative error below `2n·2⁻⁵³` before the one rounding to
/// `f32`, so the correctly rounded power but for rare ties, within one unit in the last place
/// always (`highlight_power_is_the_rounded_power`), where the C library's `powf` is within
/// 0.82 of one and a call of a few dozen instructions. Other exponents (MTL files' `Ns 96.08`)
/// go to `powf`. `x^0` is 1 and `x^1` is `x`, exactly.
#[inline(always)]
pub fn highlight_power(x: f32, shininess: f32) -> f32 {
    // NaN and negative exponents convert to 0 and fail the comparison (−0 passes, as 0).
    let mut n = shininess as u32;
    if n as f32 != shininess || n > MAX_WHOLE_SHININESS {
        return x.powf(shininess);
    }
    let (mut base, mut power) = (f64::from(x), 1.0f64);
    while n > 0 {
        if n & 1 == 1 {
            power *= base;
        }
        base *= base;
        n >>= 1;
    }
    power as f32
}

/// Largest shininess [`highlight_power`] raises by repeated squaring.
pub const MAX_WHOLE_SHININESS: u32 = 1024;

/// `ka ⊙ A`.
#[inline]
pub fn ambient_term(material: &Material, ambient_light: Vec3) -> Vec3 {
    material.ambient * ambient_light
}

#[cfg(test)]
mod tests {
    use super::*;

    const H: f32 = std::f32::consts::FRAC_1_SQRT_2;

    use crate::rng::{signed, uniform};

    /// Skipping the power where `C_l ⊙ ks` is zero gives the full product's bits: random
    /// cosines (negative, above 1, NaN), colours and specular coefficients with `+0` and `−0`
    /// channels, every shininess up to the bound.
    #[test]
    fn zero_specular_skips_the_power_bit_for_bit() {
        let mut rnd = signed(99);
        let mut skipped = 0;
        for k in 0..20000 {
            let cos = match k % 7 {
                0 => f32::NAN,
                1 => 1.0 + 1e-6 * rnd().abs(),
                _ => rnd(),
            };
            let shininess = [0.0, 1.0, 40.0, 200.0, 1e4, 1e6][k % 6];
            let zero = |x: f32| if x < 0.0 { -0.0 } else { 0.0 };
            let color = Vec3::new(rnd().abs(), zero(rnd()), rnd().abs() * 3.0);
            let specular = match k % 3 {
                0 => Vec3::new(zero(rnd()), zero(rnd()), zero(rnd())),
                1 => Vec3::new(0.0, rnd().abs(), 0.0),
                _ => Vec3::new(rnd().abs(), rnd().abs(), rnd().abs()),
            };
            let ks = color * specular;
            skipped += usize::from(ks == Vec3::ZERO);
            let full = ks * highlight_power(cos.max(0.0), shininess);
            let fast = specular_term(ks, cos, shininess);
            assert_eq!(
                fast.to_array().map(f32::to_bits),
                full.to_array().map(f32::to_bits),
                "cos {cos} shininess {shininess} ks {ks}"
            );
        }
        assert!(skipped > 5000, "{skipped}");
    }

    /// `cos_halfway` is `N·H` of the exact halfway vector within a few units in the last
    /// place (checked against `f64` over random unit vectors), closer to it than `N·halfway`
    /// on average, and 0 where `L = −V` or an input is NaN.
    #[test]
    fn cos_halfway_is_n_dot_h() {
        let mut rnd = signed(7);
        let mut unit = || loop {
            let v = Vec3::new(rnd(), rnd(), rnd());
            if v.length_squared() > 0.01 {
                break v.normalize();
            }
        };
        let (mut err_new, mut err_old) = (0.0f64, 0.0f64);
        for _ in 0..100_000 {
            let (n, l, v) = (unit(), unit(), unit());
            let (n64, s64) = (n.as_dvec3(), (l.as_dvec3() + v.as_dvec3()));
            let exact = n64.dot(s64) / s64.length();
            let new = cos_halfway(n, l, v);
            let old = n.dot(halfway(l, v));
            // Absolute error against a cosine (at most 1): a few f32 ulps of 1.
            assert!(
                (f64::from(new) - exact).abs() < 4e-7,
                "{n} {l} {v}: {new} vs {exact}"
            );
            err_new += (f64::from(new) - exact).abs();
            err_old += (f64::from(old) - exact).abs();
        }
        assert!(err_new < err_old, "mean error {err_new} against {err_old}");
        let l = Vec3::new(0.0, H, H);
        assert_eq!(cos_halfway(Vec3::Z, l, -l), 0.0);
        assert_eq!(cos_halfway(Vec3::Z, Vec3::NAN, l), 0.0);
        // The lecture's quiz (Q5): L = (H, 0, H) and V = (−H, H, 0) give the halfway vector
        // (0, H, H), so N·H = H for N = Z.
        let q = cos_halfway(Vec3::Z, Vec3::new(H, 0.0, H), Vec3::new(-H, H, 0.0));
        assert!((q - H).abs() < 1e-7, "{q}");
    }

    /// Against `f64`'s power rounded to `f32`: every whole exponent up to the bound, bases
    /// across `[0, 1]` (uniform, near 1, tiny, subnormal) and a little above 1 (cosines of unit
    /// vectors): never more than one unit in the last place, equal in all but a few in a
    /// million; the C library's `powf` is counted beside it. Other exponents give `powf`'s
    /// bits.
    #[test]
    fn highlight_power_is_the_rounded_power() {
        let mut rnd = uniform(0x2545_f491);
        let ulps = |a: f32, b: f32| a.to_bits().abs_diff(b.to_bits());
        let (mut total, mut differ, mut powf_differ) = (0u32, 0u32, 0u32);
        for n in 0..=MAX_WHOLE_SHININESS {
            for k in 0..400 {
                let u = rnd();
                let x = match k % 6 {
                    0 => u,
                    1 => 1.0 - u * 1e-3,
                    2 => 1.0 + u * 1e-6,
                    3 => u * 1e-30,
                    4 => f32::from_bits((u * 8_388_607.0) as u32),
                    _ => u.sqrt(),
                };
                let y = n as f32;
                let want = f64::from(x).powf(f64::from(y)) as f32;
                let got = highlight_power(x, y);
                assert!(ulps(got, want) <= 1, "{x:e}^{n}: {got:e} vs {want:e}");
                total += 1;
                differ += u32::from(got != want);
                powf_differ += u32::from(x.powf(y) != want);
            }
        }
        eprintln!("{differ} of {total} differ from the rounded power (powf: {powf_differ})");
        assert!(differ <= total / 100_000, "{differ} of {total} differ");
        for x in [0.0, 1e-40, 0.25, 0.999, 1.0, 1.0001] {
            assert_eq!(highlight_power(x, 0.0), 1.0);
            assert_eq!(highlight_power(x, -0.0), 1.0);
            assert_eq!(highlight_power(x, 1.0).to_bits(), x.to_bits());
        }
        assert_eq!(highlight_power(0.0, 40.0).to_bits(), 0.0f32.to_bits());
        for (x, y) in [
            (0.5, 40.5),
            (0.3, 96.078_43),
            (0.5, 1025.0),
            (0.5, 1e6),
            (0.5, -2.0),
            (0.5, f32::NAN),
            (0.0, 0.5),
        ] {
            let (got, want) = (highlight_power(x, y), x.powf(y));
            assert!(
                got.to_bits() == want.to_bits() || got.is_nan() && want.is_nan(),
                "{x}^{y}: {got} vs {want}"
            );
        }
    }

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

    /// Incidence cosines from normal incidence to grazing: an even sweep, then down to 1e-7 by
    /// factors of ten (cos θi = 1e-3 included), then exactly grazing.
    fn incidence_cosines() -> Vec<f32> {
        let mut c: Vec<f32> = (0..=200).map(|i| 1.0 - i as f32 / 200.0).collect();
        c.extend((1..=7).flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f32.powi(-e))));
        c.push(0.0);
        c
    }

    /// Unit normals, axis-aligned and not, each with two tangents.
    fn frames() -> Vec<(Vec3, Vec3)> {
        let normals = [
            Vec3::Y,
            -Vec3::Z,
            Vec3::new(1.0, 2.0, 3.0).normalize(),
            Vec3::new(-0.3, 0.05, -0.9).normalize(),
        ];
        normals
            .into_iter()
            .flat_map(|n| {
                let t = n.any_orthonormal_vector();
                [(n, t), (n, n.cross(t))]
            })
            .collect()
    }

    /// The incoming unit direction at cosine `cos_i` to `-n`, in the plane of `n` and `t`.
    fn incoming(n: Vec3, t: Vec3, cos_i: f32) -> Vec3 {
        let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
        (sin_i * t - cos_i * n).normalize()
    }

    #[test]
    fn refract_same_index_leaves_direction_alone_at_every_angle() {
        // `1 − η²(1 − cos²θ)` cancels at grazing angles and bent these rays by up to ~1e-4.
        for (n, t) in frames() {
            for cos_i in incidence_cosines() {
                let u = incoming(n, t, cos_i);
                let r = refract(u, n, 1.0)
                    .unwrap_or_else(|| panic!("TIR with eta = 1 at cos θi = {cos_i}, n = {n}"));
                let dev = (r - u).abs().max_element();
                assert!(
                    dev < 1e-6,
                    "eta = 1, cos θi = {cos_i}, n = {n}: T = {r}, u = {u}, deviation {dev:e}"
                );
            }
        }
    }

    #[test]
    fn refract_snell_and_total_internal_reflection_sweep() {
        for eta in [1.5f32, 1.0 / 1.5] {
            for (n, t) in frames() {
                for cos_i in incidence_cosines() {
                    let u = incoming(n, t, cos_i);
                    let (ud, nd) = (u.as_dvec3(), n.as_dvec3());
                    let cos_exact = -ud.dot(nd);
                    let sin_i = ud.cross(nd).length();
                    let k = 1.0 - f64::from(eta).powi(2) * (1.0 - cos_exact * cos_exact);
                    let what = format!("eta = {eta}, cos θi = {cos_i}, n = {n}");
                    match refract(u, n, eta) {
                        None => assert!(k < 1e-6, "{what}: TIR reported, k = {k}"),
                        Some(r) => {
                            assert!(k > -1e-6, "{what}: TIR missed, k = {k}, T = {r}");
                            let rd = r.as_dvec3();
                            assert!((rd.length() - 1.0).abs() < 1e-6, "{what}: |T| = {rd}");
                            // Transmitted into the far side, in the plane of incidence.
                            assert!(rd.dot(nd) <= 1e-6, "{what}: T = {r}");
                            assert!(rd.dot(nd.cross(ud)).abs() < 1e-6, "{what}: T = {r}");
                            let sin_t = rd.cross(nd).length();
                            let want = f64::from(eta) * sin_i;
                            assert!(
                                (sin_t - want).abs() < 1e-5,
                                "{what}: sin θt = {sin_t}, η sin θi = {want}"
                            );
                        }
                    }
                    if eta < 1.0 {
                        assert!(refract(u, n, eta).is_some(), "{what}: entering never TIRs");
                    } else if (k).abs() > 1e-6 {
                        assert_eq!(refract(u, n, eta).is_none(), k < 0.0, "{what}: k = {k}");
                    }
                }
            }
        }
        // Both sides of the critical angle asin(1/1.5) occur in the sweep.
        let n = Vec3::Y;
        let t = Vec3::X;
        let crit = (1.0f32 / 1.5).asin().cos();
        assert!(refract(incoming(n, t, crit + 1e-3), n, 1.5).is_some());
        assert!(refract(incoming(n, t, crit - 1e-3), n, 1.5).is_none());
    }
}
