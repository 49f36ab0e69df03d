//! The trace against answers derived by hand: the lecture's quiz, reflection and refraction,
//! max_depth semantics, shadows, and pixels of small scenes (1e-5).

mod common;

use common::{Build, close, floor, looking, mat, wall_z};
use glam::{DVec3, Vec3};
use raytree::accel::AccelKind;
use raytree::geometry::{Ray, TriangleMethod, intersect_triangle, triangle_hit_point};
use raytree::scene::Shading;
use raytree::shade::{halfway, light_terms};

const S: f32 = std::f32::consts::FRAC_1_SQRT_2;

#[test]
fn lecture_quiz_numbers() {
    let a = [
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(0.0, 1.0, -1.0),
    ];
    // Q1: N = normalize(A1A2 × A1A3) = (0, 0, 1).
    let n = (a[1] - a[0]).cross(a[2] - a[0]).normalize();
    assert_eq!(n, Vec3::Z);
    let ray = Ray::new(Vec3::ZERO, Vec3::NEG_Z);
    for method in [
        TriangleMethod::Lecture,
        TriangleMethod::MollerTrumbore,
        TriangleMethod::Watertight,
    ] {
        // Q2: P = (0, 0, −1) at s = 1; Q3: barycentric (1/4, 1/4, 1/2).
        let hit = intersect_triangle(method, &a, &ray, 0.0, f32::INFINITY)
            .unwrap_or_else(|| panic!("{method:?} misses the quiz triangle"));
        assert!((hit.t - 1.0).abs() < 1e-6, "{method:?} t = {}", hit.t);
        let (p, _) = triangle_hit_point(&a, hit.b1, hit.b2);
        assert!(
            close(p, Vec3::new(0.0, 0.0, -1.0), 1e-6),
            "{method:?} P = {p}"
        );
        let b = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
        for (got, want) in b.iter().zip([0.25, 0.25, 0.5]) {
            assert!((got - want).abs() < 1e-6, "{method:?} barycentric {b:?}");
        }
    }
    // Q4: L towards K = (1, 0, 0) from P.
    let p = Vec3::new(0.0, 0.0, -1.0);
    let l = (Vec3::X - p).normalize();
    assert!(close(l, Vec3::new(S, 0.0, S), 1e-7));
    // Q5: H = normalize(L + V) with the quiz's V.
    let v = Vec3::new(-S, S, 0.0);
    let h = halfway(l, v);
    assert!(close(h, Vec3::new(0.0, S, S), 1e-7), "H = {h}");
    // Q6: I = (1/√2)(N·L) + (1/√2)(N·H) = 1: kd = ks = 1/√2, shininess 1, white light.
    let m = mat("quiz", Vec3::ZERO, Vec3::splat(S), S, 1.0, 0.0);
    let terms = light_terms(Shading::BlinnPhong, &m, Vec3::ONE, n, l, v);
    let i = terms.diffuse + terms.specular;
    assert!(close(i, Vec3::ONE, 1e-6), "I = {i}");
}

/// Pixel (2, 2) of a 5×5 image looks exactly along the camera's view direction.
#[test]
fn lit_mirror_sphere_pixel_by_hand() {
    let ka = Vec3::new(0.1, 0.2, 0.3);
    let kd = Vec3::new(0.5, 0.6, 0.7);
    let light_color = Vec3::new(1.0, 0.9, 0.8);
    let b = Build::new(looking(Vec3::ZERO, Vec3::NEG_Z, 90.0), 5, 5)
        .material(mat("m", ka, kd, 0.25, 8.0, 0.5))
        .light(Vec3::new(0.0, 2.0, 0.0), light_color)
        .sphere("ball", Vec3::new(0.0, 0.0, -3.0), 1.0, 0);
    // P = (0, 0, −2), N = V = (0, 0, 1), L = (0, 1, 1)/√2, H = normalize(L + V).
    let n = DVec3::Z;
    let l = DVec3::new(0.0, 1.0, 1.0).normalize();
    let h = (l + DVec3::Z).normalize();
    let ambient = ka.as_dvec3() * 0.5;
    let lc = light_color.as_dvec3();
    let local = ambient + lc * (kd.as_dvec3() * n.dot(l) + 0.25 * n.dot(h).powf(8.0));
    // R = (0, 0, 1) leaves the scene: kr · background.
    let expect = local + 0.5 * b.0.render.background.as_dvec3();
    for accel in [AccelKind::None, AccelKind::Grid, AccelKind::Bvh] {
        let got = b.pixel(2, 2, accel);
        assert!(
            close(got, expect.as_vec3(), 1e-5),
            "{accel:?}: {got} vs {expect}"
        );
    }
    // A corner pixel misses everything: the background exactly.
    assert_eq!(b.pixel(0, 0, AccelKind::Bvh), b.0.render.background);
}

/// Facing mirror and wall: the reflected ray from the mirror hits the wall behind the camera.
fn mirror_and_wall(max_depth: u32) -> Build {
    let mut b = Build::new(looking(Vec3::ZERO, Vec3::NEG_Z, 60.0), 5, 5)
        .material(mat(
            "mirror",
            Vec3::splat(0.1),
            Vec3::splat(0.2),
            0.3,
            16.0,
            0.6,
        ))
        .material(mat(
            "wall",
            Vec3::new(0.2, 0.1, 0.0),
            Vec3::new(0.3, 0.5, 0.7),
            0.1,
            4.0,
            0.0,
        ))
        .light(Vec3::ZERO, Vec3::ONE)
        .quad("mirror", wall_z(-2.0, 5.0, true), 0)
        .quad("wall", wall_z(2.0, 5.0, false), 1);
    b.0.render.max_depth = max_depth;
    b
}

#[test]
fn max_depth_zero_children_return_background() {
    // Light at the eye: at both hits N·L = N·H = 1, so local = ka·A + kd + ks.
    let mirror_local = Vec3::splat(0.1 * 0.5 + 0.2 + 0.3);
    let wall_local = Vec3::new(0.2, 0.1, 0.0) * 0.5 + Vec3::new(0.3, 0.5, 0.7) + Vec3::splat(0.1);
    let d0 = mirror_and_wall(0);
    let bg = d0.0.render.background;
    let got0 = d0.pixel(2, 2, AccelKind::None);
    assert!(
        close(got0, mirror_local + 0.6 * bg, 1e-5),
        "depth 0: {got0}"
    );
    let got1 = mirror_and_wall(1).pixel(2, 2, AccelKind::None);
    assert!(
        close(got1, mirror_local + 0.6 * wall_local, 1e-5),
        "depth 1: {got1}"
    );
    // The wall does not reflect, so deeper limits change nothing.
    assert_eq!(mirror_and_wall(7).pixel(2, 2, AccelKind::Grid), got1);
}

#[test]
fn shadowed_floor_point_is_ambient_only() {
    let floor_ka = Vec3::new(0.3, 0.2, 0.1);
    let b = Build::new(looking(Vec3::ZERO, Vec3::new(0.0, -1.0, -2.0), 40.0), 5, 5)
        .material(mat("floor", floor_ka, Vec3::splat(0.8), 0.5, 10.0, 0.0))
        .material(mat("blocker", Vec3::ONE, Vec3::ONE, 0.0, 1.0, 0.0))
        .light(Vec3::new(0.0, 4.0, -2.0), Vec3::ONE)
        .sphere("blocker", Vec3::new(0.0, 1.0, -2.0), 0.5, 1)
        .quad("floor", floor(), 0);
    for accel in [AccelKind::None, AccelKind::Grid, AccelKind::Bvh] {
        let got = b.pixel(2, 2, accel);
        assert!(close(got, floor_ka * 0.5, 1e-6), "{accel:?}: {got}");
    }
    // Without the blocker the same point is lit: N = L = (0, 1, 0).
    let mut lit = b;
    lit.0.spheres.clear();
    let v = DVec3::new(0.0, 1.0, 2.0).normalize();
    let h = (DVec3::Y + v).normalize();
    let expect = floor_ka.as_dvec3() * 0.5 + DVec3::splat(0.8) + 0.5 * h.y.powf(10.0);
    let got = lit.pixel(2, 2, AccelKind::Bvh);
    assert!(close(got, expect.as_vec3(), 1e-5), "{got} vs {expect}");
}

#[test]
fn phong_uses_mirror_direction_of_the_light() {
    // Camera looks down at a floor point straight under the light: N = L = (0, 1, 0), so
    // R_l = 2(N·L)N − L = N and R·V = V·y, while Blinn-Phong's N·H is larger.
    let ka = Vec3::new(0.3, 0.2, 0.1);
    let mut b = Build::new(looking(Vec3::ZERO, Vec3::new(0.0, -1.0, -2.0), 40.0), 5, 5)
        .material(mat("floor", ka, Vec3::splat(0.8), 0.5, 10.0, 0.0))
        .light(Vec3::new(0.0, 4.0, -2.0), Vec3::ONE)
        .quad("floor", floor(), 0);
    b.0.render.shading = Shading::Phong;
    let v = DVec3::new(0.0, 1.0, 2.0).normalize();
    let expect = ka.as_dvec3() * 0.5 + DVec3::splat(0.8) + 0.5 * v.y.powf(10.0);
    let got = b.pixel(2, 2, AccelKind::None);
    assert!(close(got, expect.as_vec3(), 1e-5), "{got} vs {expect}");
}

/// A light whose unshadowed terms are exactly zero at a hit casts no shadow ray (it cannot
/// change the pixel): a black-diffuse, black-specular mirror; a green-only light on a red-only
/// surface; and a surface with no diffuse whose highlight points away (spec = 0). The tree
/// still lists each light, marked "contributes nothing", and its pixel equals the render's.
#[test]
fn lights_that_contribute_nothing_cast_no_shadow_ray() {
    use raytree::ray_tree::pixel_tree;
    use raytree::render::render;
    // (name, kd, ks, shininess, light colour); the last one has no diffuse but a highlight
    // (N·H > 0 at every pixel), so its shadow rays are traced.
    let cases: [(&str, Vec3, Vec3, f32, Vec3); 3] = [
        ("black mirror", Vec3::ZERO, Vec3::ZERO, 8.0, Vec3::ONE),
        ("red surface, green light", Vec3::X, Vec3::X, 8.0, Vec3::Y),
        (
            "no diffuse, specular seen",
            Vec3::ZERO,
            Vec3::ONE,
            1.0,
            Vec3::ONE,
        ),
    ];
    for (name, kd, ks, n, light) in cases {
        let mut m = mat(name, Vec3::splat(0.1), kd, 0.0, n, 0.5);
        m.specular = ks;
        let b = Build::new(looking(Vec3::ZERO, Vec3::NEG_Z, 60.0), 5, 5)
            .material(m)
            .light(Vec3::new(0.0, 3.0, 0.0), light)
            .light(Vec3::new(0.0, -3.0, -2.5), light)
            .quad("wall", wall_z(-3.0, 5.0, true), 0);
        let tracer = b.tracer();
        let (image, stats) = render(&tracer, 1, 1, &|_, _| {}).expect("render");
        let tree = pixel_tree(&tracer, 2, 2).expect("the centre pixel's tree");
        let hit = &tree.root;
        assert_eq!(hit.shadow_rays.len(), 2, "{name}");
        let traced = name == "no diffuse, specular seen";
        for s in &hit.shadow_rays {
            assert!(!s.facing_away, "{name}");
            assert_eq!(s.contributes_nothing, !traced, "{name}");
        }
        let want_shadow = if traced { 2 * 25 } else { 0 };
        assert_eq!(stats.rays.shadow, want_shadow, "{name}");
        assert_eq!(tree.root.color, image.get(2, 2), "{name}");
        if !traced {
            let text = raytree::ray_tree::tree_text(&tree);
            assert!(text.contains("not traced: contributes nothing"), "{text}");
        }
    }
}
