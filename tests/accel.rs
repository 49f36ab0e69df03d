//! `Accel`: none, grid and BVH must give the identical closest hit (same t, same primitive, same
//! barycentrics; ties to the lower id) and the identical occlusion verdict for every ray, over
//! random and degenerate scenes (docs/stability.md, rows B2, T1 "including through the BVH",
//! T4).

use glam::Vec3;
use raytree::accel::{AUTO_MIN_BVH_PRIMS, Accel, AccelKind, PrimHit, PrimSet, auto_kind};
use raytree::experiments::meshes::octasphere;
use raytree::geometry::{Methods, Ray, SphereMethod, TriangleMethod};
use raytree::rng::Pcg;

const KINDS: [AccelKind; 3] = [AccelKind::None, AccelKind::Grid, AccelKind::Bvh];

fn bounds(p: &PrimSet) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for &(c, r) in &p.spheres {
        if c.is_finite() && r.is_finite() {
            lo = lo.min(c - r);
            hi = hi.max(c + r);
        }
    }
    for t in &p.triangles {
        for v in t {
            if v.is_finite() {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
    }
    if lo.x > hi.x {
        (Vec3::splat(-1.0), Vec3::ONE)
    } else {
        (lo, hi)
    }
}

/// A mix of ray kinds over the scene's bounds: random (camera-like, from outside and inside),
/// short segments (shadow rays), rays exactly parallel to an axis, rays aimed at primitives.
fn rays_for(p: &PrimSet, rng: &mut Pcg, n: usize) -> Vec<(Ray, f32, f32)> {
    let (lo, hi) = bounds(p);
    let c = (lo + hi) * 0.5;
    let ext = (hi - lo).max(Vec3::splat((hi - lo).max_element() * 0.1));
    let (olo, ohi) = (c - ext, c + ext);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let origin = rng.in_box(olo, ohi);
        let (ray, t_min, t_max) = match i % 5 {
            0 => (Ray::new(origin, rng.unit()), 0.0, f32::INFINITY),
            1 => {
                // Segment to a random point: a shadow ray.
                let target = rng.in_box(olo, ohi);
                let d = target - origin;
                (Ray::new(origin, d.normalize()), 0.0, d.length())
            }
            2 => {
                // Exactly axis-parallel, both signs.
                let axis = rng.below(3);
                let mut d = Vec3::ZERO;
                d[axis] = if rng.f32() < 0.5 { 1.0 } else { -1.0 };
                (Ray::new(origin, d), 0.0, f32::INFINITY)
            }
            3 => {
                // Aimed at a primitive (many hits), with a random t_min.
                let target = aim_point(p, rng).unwrap_or(c);
                let d = (target - origin).normalize();
                let t_min = if rng.f32() < 0.3 {
                    rng.range(0.0, ext.max_element())
                } else {
                    0.0
                };
                (Ray::new(origin, d), t_min, f32::INFINITY)
            }
            _ => {
                // From outside the bounds towards the middle.
                let o = c + rng.unit() * (3.0 * ext.max_element());
                let target = aim_point(p, rng).unwrap_or(c);
                (Ray::new(o, (target - o).normalize()), 0.0, f32::INFINITY)
            }
        };
        if ray.dir.is_finite() {
            out.push((ray, t_min, t_max));
        }
    }
    out
}

fn aim_point(p: &PrimSet, rng: &mut Pcg) -> Option<Vec3> {
    let n = p.spheres.len() + p.triangles.len();
    if n == 0 {
        return None;
    }
    let i = rng.below(n);
    Some(if i < p.spheres.len() {
        let (c, r) = p.spheres[i];
        c + rng.unit() * (r * rng.range(0.0, 1.2))
    } else {
        let [a, b, c] = p.triangles[i - p.spheres.len()];
        let (u, v) = (rng.range(-0.1, 1.0), rng.range(-0.1, 1.0));
        a + u * (b - a) + v * (c - a) * (1.0 - u).max(0.0)
    })
}

/// Compare all kinds on `rays`; returns the number of closest hits (so callers can check the
/// scene was exercised).
fn assert_kinds_agree(
    name: &str,
    prims: &PrimSet,
    methods: &Methods,
    rays: &[(Ray, f32, f32)],
) -> usize {
    let accels: Vec<Accel> = KINDS.iter().map(|&k| Accel::build(k, prims)).collect();
    for (a, k) in accels.iter().zip(KINDS) {
        assert_eq!(a.kind(), k);
    }
    let mut hits = 0;
    for (i, (ray, t_min, t_max)) in rays.iter().enumerate() {
        let reference: Option<PrimHit> = accels[0].closest_hit(methods, ray, *t_min, *t_max);
        let occluded = accels[0].occluded(methods, ray, *t_min, *t_max);
        assert_eq!(
            occluded,
            reference.is_some(),
            "{name}: none's occlusion vs closest, ray {i}"
        );
        hits += usize::from(reference.is_some());
        for (a, k) in accels.iter().zip(KINDS).skip(1) {
            let got = a.closest_hit(methods, ray, *t_min, *t_max);
            assert_eq!(
                got, reference,
                "{name}: {k:?} closest hit differs, ray {i}: {ray:?} ({t_min}, {t_max})"
            );
            let occ = a.occluded(methods, ray, *t_min, *t_max);
            assert_eq!(
                occ, occluded,
                "{name}: {k:?} occlusion differs, ray {i}: {ray:?} ({t_min}, {t_max})"
            );
        }
    }
    hits
}

fn random_triangle(rng: &mut Pcg, lo: Vec3, hi: Vec3, size: f32) -> [Vec3; 3] {
    let c = rng.in_box(lo, hi);
    [
        c + rng.unit() * size,
        c + rng.unit() * size,
        c + rng.unit() * size,
    ]
}

fn random_scene(
    rng: &mut Pcg,
    spheres: usize,
    triangles: usize,
    extent: f32,
    size: f32,
) -> PrimSet {
    let (lo, hi) = (Vec3::splat(-extent), Vec3::splat(extent));
    PrimSet {
        spheres: (0..spheres)
            .map(|_| (rng.in_box(lo, hi), size * rng.range(0.05, 1.0)))
            .collect(),
        triangles: (0..triangles)
            .map(|_| {
                let s = size * rng.range(0.1, 1.0);
                random_triangle(rng, lo, hi, s)
            })
            .collect(),
    }
}

/// A ground plane of `n × n` quads (two triangles each) at height `y`, side `size`.
fn plane(n: usize, size: f32, y: f32) -> Vec<[Vec3; 3]> {
    let step = size / n as f32;
    let at = |i: usize, j: usize| {
        Vec3::new(
            -size / 2.0 + i as f32 * step,
            y,
            -size / 2.0 + j as f32 * step,
        )
    };
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    tris
}

fn default_methods() -> Methods {
    Methods::default()
}

#[test]
fn empty_and_single_primitive_scenes() {
    let m = default_methods();
    let mut rng = Pcg::new(1);
    let empty = PrimSet::default();
    for k in KINDS {
        let a = Accel::build(k, &empty);
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert!(a.closest_hit(&m, &ray, 0.0, f32::INFINITY).is_none());
        assert!(!a.occluded(&m, &ray, 0.0, f32::INFINITY));
    }
    let one_sphere = PrimSet {
        spheres: vec![(Vec3::new(0.5, -0.25, 2.0), 0.75)],
        triangles: vec![],
    };
    let rays = rays_for(&one_sphere, &mut rng, 1000);
    assert!(assert_kinds_agree("one sphere", &one_sphere, &m, &rays) > 100);
    let one_tri = PrimSet {
        spheres: vec![],
        triangles: vec![[
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.5),
        ]],
    };
    let rays = rays_for(&one_tri, &mut rng, 1000);
    assert!(assert_kinds_agree("one triangle", &one_tri, &m, &rays) > 50);
}

#[test]
fn random_mixed_scenes_agree() {
    let mut rng = Pcg::new(2);
    let mut total_hits = 0;
    for (spheres, triangles, size) in [
        (5, 5, 0.5),
        (50, 200, 0.3),
        (300, 1500, 0.15),
        (0, 800, 0.2),
        (400, 0, 0.1),
    ] {
        let scene = random_scene(&mut rng, spheres, triangles, 2.0, size);
        let rays = rays_for(&scene, &mut rng, 2000);
        total_hits += assert_kinds_agree("random", &scene, &default_methods(), &rays);
    }
    assert!(total_hits > 3000, "too few hits to be a test: {total_hits}");
    // The other methods agree across kinds too (well-conditioned scene).
    let scene = random_scene(&mut rng, 40, 300, 2.0, 0.3);
    let rays = rays_for(&scene, &mut rng, 1500);
    for (sphere, triangle) in [
        (SphereMethod::Lecture, TriangleMethod::Lecture),
        (SphereMethod::Robust, TriangleMethod::MollerTrumbore),
    ] {
        let m = Methods {
            sphere,
            triangle,
            ..Methods::default()
        };
        assert_kinds_agree("random, other methods", &scene, &m, &rays);
    }
}

#[test]
fn identical_triangles_tie_to_the_lowest_id() {
    let mut rng = Pcg::new(3);
    let tri = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let mut scene = PrimSet {
        spheres: vec![(Vec3::new(0.0, 0.0, 3.0), 0.5)],
        triangles: vec![tri; 3000],
    };
    // A second stack of identical copies elsewhere, and concentric spheres (nested boxes).
    scene
        .triangles
        .extend(vec![tri.map(|v| v + Vec3::new(3.0, 0.0, 1.0)); 500]);
    scene
        .spheres
        .extend((0..300).map(|i| (Vec3::new(-3.0, 0.0, 0.0), 0.1 + 0.01 * i as f32)));
    let rays = rays_for(&scene, &mut rng, 1500);
    assert!(assert_kinds_agree("identical", &scene, &default_methods(), &rays) > 300);
    let bvh = Accel::build(AccelKind::Bvh, &scene);
    assert!(
        bvh.bvh_depth().is_some_and(|d| d < 32),
        "BVH depth {:?}",
        bvh.bvh_depth()
    );
    // Straight through the stack: the first copy (lowest id) wins in every kind.
    let ray = Ray::new(Vec3::new(0.1, -0.2, -5.0), Vec3::Z);
    for k in KINDS {
        let hit = Accel::build(k, &scene)
            .closest_hit(&default_methods(), &ray, 0.0, f32::INFINITY)
            .expect("hit");
        assert_eq!(
            hit.prim,
            300 + 1,
            "{k:?}: first triangle id is spheres.len() = 301"
        );
    }
}

/// Dense near-ties across cells: a large slanted plane with a dust of small triangles and
/// spheres just in front of it, and a few more layers a hair apart, so the nearest hit is often
/// in the next cell, just past a hit found in the current one (catches a grid walk that stops
/// too early or starts in the wrong cell).
#[test]
fn dust_in_front_of_layers() {
    let mut rng = Pcg::new(9);
    let mut scene = PrimSet::default();
    for k in 0..5 {
        let z = k as f32 * 2e-3;
        scene.triangles.push([
            Vec3::new(-2.5, -2.5, z),
            Vec3::new(5.0, -2.5, z),
            Vec3::new(-2.5, 5.0, z),
        ]);
    }
    for _ in 0..3000 {
        let c = rng.in_box(Vec3::new(-2.0, -2.0, -2e-3), Vec3::new(2.0, 2.0, -1e-4));
        let (a, b) = (rng.unit() * 0.06, rng.unit() * 0.06);
        let flat = Vec3::new(1.0, 1.0, 0.02);
        scene.triangles.push([c, c + a * flat, c + b * flat]);
    }
    for _ in 0..200 {
        let c = rng.in_box(Vec3::new(-2.0, -2.0, -0.3), Vec3::new(2.0, 2.0, 0.4));
        scene.spheres.push((c, rng.range(0.005, 0.05)));
    }
    let mut rays = Vec::new();
    for i in 0..4000 {
        let o = rng.in_box(Vec3::new(-3.0, -3.0, -3.0), Vec3::new(3.0, 3.0, -0.5));
        let target = rng.in_box(Vec3::new(-2.0, -2.0, 0.0), Vec3::new(2.0, 2.0, 0.0));
        let d = (target - o).normalize();
        let t_max = if i % 3 == 0 {
            (target - o).length()
        } else {
            f32::INFINITY
        };
        rays.push((Ray::new(o, d), 0.0, t_max));
    }
    let hits = assert_kinds_agree("dust", &scene, &default_methods(), &rays);
    assert!(hits > 3000, "hits {hits}");
}

/// docs/stability.md, row B2: 1e5 identical triangles build quickly into shallow structures of
/// bounded size.
#[test]
fn hundred_thousand_identical_triangles() {
    let tri = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let scene = PrimSet {
        spheres: vec![],
        triangles: vec![tri; 100_000],
    };
    let accels: Vec<Accel> = KINDS.iter().map(|&k| Accel::build(k, &scene)).collect();
    assert!(
        accels[2].bvh_depth().is_some_and(|d| d <= 12),
        "{:?}",
        accels[2].bvh_depth()
    );
    assert!(
        accels[1].memory_bytes() < 64 << 20,
        "grid uses {} bytes",
        accels[1].memory_bytes()
    );
    let m = default_methods();
    let mut rng = Pcg::new(10);
    for _ in 0..20 {
        let o = rng.unit() * 3.0;
        let ray = Ray::new(o, (rng.unit() * 0.5 - o).normalize());
        let expect = accels[0].closest_hit(&m, &ray, 0.0, f32::INFINITY);
        assert!(expect.is_none_or(|h| h.prim == 0));
        for a in &accels[1..] {
            assert_eq!(
                a.closest_hit(&m, &ray, 0.0, f32::INFINITY),
                expect,
                "{:?}",
                a.kind()
            );
            assert_eq!(a.occluded(&m, &ray, 0.0, f32::INFINITY), expect.is_some());
        }
    }
}

#[test]
fn accel_is_shareable_between_threads() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Accel>();
}

#[test]
fn flat_plane_and_axis_parallel_rays() {
    let mut rng = Pcg::new(4);
    let mut scene = PrimSet {
        spheres: vec![
            (Vec3::new(0.0, 1.0, 0.0), 1.0),
            (Vec3::new(2.0, 0.5, -1.0), 0.5),
        ],
        triangles: plane(20, 10.0, 0.0),
    };
    let rays = rays_for(&scene, &mut rng, 2000);
    assert!(assert_kinds_agree("plane + spheres", &scene, &default_methods(), &rays) > 500);
    // The plane alone is perfectly flat: zero thickness on y.
    scene.spheres.clear();
    let mut rays = rays_for(&scene, &mut rng, 1000);
    // Rays lying exactly in the plane and along grid lines.
    for i in 0..200 {
        let x = -5.0 + 0.5 * (i % 21) as f32;
        let d = if i % 2 == 0 { Vec3::Z } else { Vec3::X };
        rays.push((Ray::new(Vec3::new(x, 0.0, x), d), 0.0, f32::INFINITY));
        rays.push((
            Ray::new(
                Vec3::new(x, 1.0, -6.0),
                Vec3::new(0.0, -1.0, 1.0).normalize(),
            ),
            0.0,
            f32::INFINITY,
        ));
    }
    assert!(assert_kinds_agree("flat plane", &scene, &default_methods(), &rays) > 300);
}

#[test]
fn huge_tiny_and_far_scales_agree() {
    let mut rng = Pcg::new(5);
    // A huge sphere under tiny triangles and spheres.
    let mut scene = random_scene(&mut rng, 100, 400, 1.0, 1e-3);
    scene.spheres.push((Vec3::new(0.0, -1e4 - 1.0, 0.0), 1e4));
    scene.triangles.extend(plane(4, 1e4, -0.5));
    let rays = rays_for(&scene, &mut rng, 2500);
    assert_kinds_agree("huge + tiny", &scene, &default_methods(), &rays);
    // Everything at scale 1e-3 (obvhs' own box test culls boxes closer than 1e-4).
    let scene = random_scene(&mut rng, 50, 300, 1e-3, 2e-4);
    let rays = rays_for(&scene, &mut rng, 2500);
    assert!(assert_kinds_agree("scale 1e-3", &scene, &default_methods(), &rays) > 300);
    // Far from the origin.
    let mut scene = random_scene(&mut rng, 50, 300, 2.0, 0.3);
    let off = Vec3::new(1e4, -3e3, 5e3);
    scene.spheres.iter_mut().for_each(|(c, _)| *c += off);
    scene
        .triangles
        .iter_mut()
        .for_each(|t| t.iter_mut().for_each(|v| *v += off));
    let rays = rays_for(&scene, &mut rng, 2500);
    assert!(assert_kinds_agree("far", &scene, &default_methods(), &rays) > 300);
}

#[test]
fn bad_primitives_are_skipped_and_counted() {
    let mut rng = Pcg::new(6);
    let mut scene = random_scene(&mut rng, 20, 200, 2.0, 0.3);
    let bad_tris = [
        [Vec3::NAN, Vec3::X, Vec3::Y],
        [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X],
        [Vec3::ONE; 3],
        [Vec3::splat(f32::INFINITY), Vec3::X, Vec3::Y],
    ];
    for (i, t) in bad_tris.iter().enumerate() {
        scene.triangles.insert(3 + 40 * i, *t);
    }
    scene.spheres.insert(5, (Vec3::ZERO, -1.0));
    scene.spheres.insert(7, (Vec3::NAN, 1.0));
    scene.spheres.insert(9, (Vec3::ZERO, f32::INFINITY));
    for k in KINDS {
        let a = Accel::build(k, &scene);
        assert_eq!(a.skipped_prims(), 7, "{k:?}");
        assert_eq!(a.prim_count(), 220, "{k:?}");
    }
    let rays = rays_for(&scene, &mut rng, 2000);
    assert!(assert_kinds_agree("bad prims", &scene, &default_methods(), &rays) > 300);
    // Unusable rays hit nothing and never panic.
    let a = Accel::build(AccelKind::Bvh, &scene);
    let m = default_methods();
    for ray in [
        Ray::new(Vec3::NAN, Vec3::X),
        Ray::new(Vec3::ZERO, Vec3::ZERO),
        Ray::new(Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 0.0)),
    ] {
        assert!(a.closest_hit(&m, &ray, 0.0, f32::INFINITY).is_none());
        assert!(!a.occluded(&m, &ray, 0.0, f32::INFINITY));
    }
    assert!(
        a.closest_hit(&m, &Ray::new(Vec3::ZERO, Vec3::X), 1.0, 1.0)
            .is_none()
    );
    assert!(
        a.closest_hit(&m, &Ray::new(Vec3::ZERO, Vec3::X), f32::NAN, 1.0)
            .is_none()
    );
}

#[test]
fn auto_resolves_by_size() {
    let mut rng = Pcg::new(7);
    let small = random_scene(&mut rng, 3, AUTO_MIN_BVH_PRIMS - 4, 1.0, 0.2);
    assert_eq!(
        Accel::build(AccelKind::Auto, &small).kind(),
        AccelKind::None
    );
    let big = random_scene(&mut rng, 3, AUTO_MIN_BVH_PRIMS, 1.0, 0.2);
    let a = Accel::build(AccelKind::Auto, &big);
    assert_eq!(a.kind(), AccelKind::Bvh);
    assert!(a.memory_bytes() > 0);
    assert_eq!(
        Accel::build(AccelKind::Auto, &PrimSet::default()).kind(),
        AccelKind::None
    );
    // The measured rule (see the constant): none for a handful of primitives, then the BVH.
    assert_eq!(auto_kind(AUTO_MIN_BVH_PRIMS - 1), AccelKind::None);
    assert_eq!(auto_kind(AUTO_MIN_BVH_PRIMS), AccelKind::Bvh);
    assert_eq!(auto_kind(1_000_000), AccelKind::Bvh);
    assert_eq!(auto_kind(100_000_000), AccelKind::Bvh);
}

/// Rays from outside at the vertices and edges of a closed mesh never pass through it, through
/// any accelerator (docs/stability.md, row T1: "0 leaks, including through the BVH").
#[test]
fn closed_mesh_has_no_leaks_through_any_accelerator() {
    let mut rng = Pcg::new(8);
    let m = default_methods();
    for (scale, offset) in [
        (1e-3f32, 0.0f32),
        (1.0, 0.0),
        (1e3, 0.0),
        (1.0, 1e2),
        (1e-2, 1e4),
    ] {
        // A closed mesh: an octahedron subdivided twice onto a sphere, moved off the origin.
        let center = Vec3::new(0.3, -0.7, 0.2) * (offset * scale);
        let (verts, idx) = octasphere(2, scale, Vec3::ZERO);
        let verts: Vec<Vec3> = verts.iter().map(|v| *v + center).collect();
        let scene = PrimSet {
            spheres: vec![],
            triangles: idx.iter().map(|t| t.map(|i| verts[i])).collect(),
        };
        let accels: Vec<Accel> = KINDS.iter().map(|&k| Accel::build(k, &scene)).collect();
        let mut targets = verts.clone();
        for t in &idx {
            for k in 0..3 {
                targets.push((verts[t[k]] + verts[t[(k + 1) % 3]]) * 0.5);
            }
        }
        for p in targets {
            for _ in 0..4 {
                let out = ((p - center).normalize() + 0.05 * rng.unit()).normalize();
                let origin = p + out * (scale * rng.range(0.5, 4.0));
                let ray = Ray::new(origin, (p - origin).normalize());
                let t_target = (p - origin).length();
                for (a, k) in accels.iter().zip(KINDS) {
                    let hit = a.closest_hit(&m, &ray, 0.0, f32::INFINITY);
                    assert!(
                        hit.is_some_and(|h| h.t < t_target + 0.1 * scale),
                        "{k:?} leaks at scale {scale}, offset {offset}: {ray:?}"
                    );
                }
            }
        }
    }
}

/// From `accel::bvh::build::FAST_BUILD_MIN_PRIMS` (500k) primitives on the BVH is built with obvhs's
/// faster preset (and PLOC runs in parallel): its hits must still equal the grid's (testing
/// every primitive is too slow at this size; the grid is itself checked against it above).
#[test]
fn large_scene_built_with_the_fast_preset_agrees_with_the_grid() {
    let mut rng = Pcg::new(11);
    let scene = random_scene(&mut rng, 20, 600_000, 4.0, 0.02);
    let rays = rays_for(&scene, &mut rng, 3000);
    let methods = default_methods();
    let bvh = Accel::build(AccelKind::Bvh, &scene);
    let grid = Accel::build(AccelKind::Grid, &scene);
    assert_eq!(bvh.prim_count(), 600_020);
    let mut hits = 0;
    for (i, (ray, t_min, t_max)) in rays.iter().enumerate() {
        let want = grid.closest_hit(&methods, ray, *t_min, *t_max);
        assert_eq!(
            bvh.closest_hit(&methods, ray, *t_min, *t_max),
            want,
            "closest hit, ray {i}: {ray:?}"
        );
        assert_eq!(
            bvh.occluded(&methods, ray, *t_min, *t_max),
            want.is_some(),
            "occlusion, ray {i}: {ray:?}"
        );
        hits += usize::from(want.is_some());
    }
    assert!(hits > 1000, "too few hits to be a test: {hits}");
}

// ---- The accelerator made visible: what one ray's traversal entered and tested. ----

/// Scenes for the visit tests: mixed random primitives, a closed mesh, a flat plane (the grid
/// has one cell layer) and a large random soup (a deep tree).
fn visit_scenes(rng: &mut Pcg) -> Vec<(&'static str, PrimSet)> {
    let (verts, idx) = octasphere(3, 1.5, Vec3::new(0.2, -0.1, 0.3));
    vec![
        ("mixed", random_scene(rng, 30, 150, 2.0, 0.4)),
        (
            "octasphere",
            PrimSet {
                spheres: vec![(Vec3::new(0.2, -0.1, 0.3), 0.5)],
                triangles: idx.iter().map(|t| t.map(|i| verts[i])).collect(),
            },
        ),
        (
            "plane",
            PrimSet {
                spheres: vec![],
                triangles: plane(12, 4.0, -0.5),
            },
        ),
        ("soup", random_scene(rng, 200, 2500, 3.0, 0.15)),
    ]
}

/// Whether the ray's `(t_min, t_max)` meets the box, in `f64`, with the box grown by a small
/// tolerance of its magnitude (the traversal pads boxes and widens its slab test).
fn meets(ray: &Ray, t_min: f32, t_max: f32, lo: Vec3, hi: Vec3) -> bool {
    let (mut t0, mut t1) = (f64::from(t_min), f64::from(t_max));
    let magnitude = f64::from(lo.abs().max(hi.abs()).max_element());
    for axis in 0..3 {
        let o = f64::from(ray.origin[axis]);
        let d = f64::from(ray.dir[axis]);
        let tol = 1e-5 * (1.0 + magnitude + o.abs());
        let (l, h) = (f64::from(lo[axis]) - tol, f64::from(hi[axis]) + tol);
        if d == 0.0 {
            if o < l || o > h {
                return false;
            }
            continue;
        }
        let (a, b) = ((l - o) / d, (h - o) / d);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 <= t1 + 1e-6 * (1.0 + t1.abs().min(1e30))
}

/// The primitive's bounds, for the containment checks (invalid primitives have none).
fn prim_bounds(p: &PrimSet, id: usize) -> (Vec3, Vec3) {
    if id < p.spheres.len() {
        let (c, r) = p.spheres[id];
        (c - r, c + r)
    } else {
        let [a, b, c] = p.triangles[id - p.spheres.len()];
        (a.min(b).min(c), a.max(b).max(c))
    }
}

/// The visits of the closest-hit query (`false`) and of the occlusion query (`true`).
fn both_visits(
    a: &Accel,
    m: &Methods,
    ray: &Ray,
    t_min: f32,
    t_max: f32,
) -> [(bool, raytree::accel::Visits); 2] {
    [
        (false, a.closest_hit_visits(m, ray, t_min, t_max)),
        (true, a.occluded_visits(m, ray, t_min, t_max)),
    ]
}

/// A box as a hashable key: its corners' bits.
fn box_key(lo: Vec3, hi: Vec3) -> [u32; 6] {
    let (l, h) = (lo.to_array(), hi.to_array());
    [l[0], l[1], l[2], h[0], h[1], h[2]].map(f32::to_bits)
}

fn inside(lo: Vec3, hi: Vec3, outer: (Vec3, Vec3), tol: f32) -> bool {
    lo.cmpge(outer.0 - tol).all() && hi.cmple(outer.1 + tol).all()
}

/// (a) A recording query gives the answer of the plain one, for every kind, on many rays; the
/// hit primitive is among those tested.
#[test]
fn visits_answer_as_the_plain_queries() {
    let mut rng = Pcg::new(12);
    let m = default_methods();
    let mut hits = 0;
    for (name, scene) in visit_scenes(&mut rng) {
        let rays = rays_for(&scene, &mut rng, 1500);
        for k in KINDS {
            let a = Accel::build(k, &scene);
            for (i, (ray, t_min, t_max)) in rays.iter().enumerate() {
                let closest = a.closest_hit_visits(&m, ray, *t_min, *t_max);
                assert_eq!(
                    closest.hit,
                    a.closest_hit(&m, ray, *t_min, *t_max),
                    "{name} {k:?} ray {i}"
                );
                let any = a.occluded_visits(&m, ray, *t_min, *t_max);
                assert_eq!(
                    any.hit.is_some(),
                    a.occluded(&m, ray, *t_min, *t_max),
                    "{name} {k:?} ray {i}"
                );
                for (v, what) in [(&closest, "closest"), (&any, "occluded")] {
                    if let Some(h) = v.hit {
                        assert!(v.prims.contains(&h.prim), "{name} {k:?} {what} ray {i}");
                        assert!(h.t > *t_min && h.t <= *t_max, "{name} {k:?} {what} {i}");
                    }
                    if k == AccelKind::None {
                        assert!(v.boxes.is_empty());
                    }
                }
                // Occlusion stops at the first hit: never more tests than the closest hit.
                if k == AccelKind::None {
                    assert!(any.prims.len() <= closest.prims.len());
                }
                hits += usize::from(closest.hit.is_some());
            }
        }
    }
    assert!(hits > 5000, "too few hits to be a test: {hits}");
}

/// (b) The BVH's visited boxes against a brute-force look at the same boxes: every box entered
/// meets the ray's interval; every box from the root to the hit's leaf is entered; every tested
/// primitive lies in an entered leaf; a ray that misses the root box enters nothing.
#[test]
fn bvh_visits_match_a_brute_force_walk_of_its_boxes() {
    let mut rng = Pcg::new(13);
    let m = default_methods();
    let mut checked_paths = 0;
    for (name, scene) in visit_scenes(&mut rng) {
        let a = Accel::build(AccelKind::Bvh, &scene);
        let boxes = a.boxes();
        let key = |lo: Vec3, hi: Vec3, level: u32| (box_key(lo, hi), level);
        let rays = rays_for(&scene, &mut rng, 1500);
        for (i, (ray, t_min, t_max)) in rays.iter().enumerate() {
            for (occlusion, v) in both_visits(&a, &m, ray, *t_min, *t_max) {
                let entered: std::collections::HashSet<_> =
                    v.boxes.iter().map(|b| key(b.lo, b.hi, b.level)).collect();
                for b in &v.boxes {
                    assert!(
                        meets(ray, *t_min, *t_max, b.lo, b.hi),
                        "{name} ray {i}: entered {b:?}, which the ray misses: {ray:?} {t_min} {t_max} {v:?}"
                    );
                }
                if !v.boxes.is_empty() {
                    assert_eq!(v.boxes[0].level, 0, "{name} ray {i}: starts at the root");
                }
                // The leaves entered and what they hold.
                let mut in_leaves = std::collections::HashSet::new();
                for b in boxes.iter().filter(|b| !b.prims.is_empty()) {
                    if entered.contains(&key(b.lo, b.hi, b.level)) {
                        in_leaves.extend(b.prims.iter().copied());
                    }
                }
                for p in &v.prims {
                    assert!(in_leaves.contains(p), "{name} ray {i}: {p} not in a leaf");
                }
                if let (false, Some(hit)) = (occlusion, v.hit) {
                    let leaf = boxes
                        .iter()
                        .position(|b| b.prims.contains(&hit.prim))
                        .expect("the hit's leaf");
                    let mut at = Some(leaf);
                    while let Some(b) = at {
                        let b = &boxes[b];
                        assert!(
                            entered.contains(&key(b.lo, b.hi, b.level)),
                            "{name} ray {i}: the path to the hit skips {b:?}"
                        );
                        at = b.parent;
                    }
                    checked_paths += 1;
                }
            }
        }
        // Rays that leave the root box behind them, or pass beside it, enter nothing.
        let root = &boxes[0];
        let (c, size) = ((root.lo + root.hi) * 0.5, (root.hi - root.lo).length());
        for _ in 0..300 {
            let u = rng.unit();
            let away = Ray::new(c + u * size, u);
            let side = rng.perpendicular(u).normalize();
            let beside = Ray::new(c + side * size - u * (2.0 * size), u);
            for ray in [away, beside] {
                assert!(!meets(&ray, 0.0, f32::INFINITY, root.lo, root.hi));
                for v in [
                    a.closest_hit_visits(&m, &ray, 0.0, f32::INFINITY),
                    a.occluded_visits(&m, &ray, 0.0, f32::INFINITY),
                ] {
                    assert!(v.boxes.is_empty() && v.prims.is_empty(), "{name}: {v:?}");
                }
            }
        }
    }
    assert!(checked_paths > 2000, "{checked_paths}");
}

/// (c) The levels of the BVH: level 0 is the root box, holding every primitive; each box of
/// level k + 1 lies inside one of level k; every level holds every primitive.
#[test]
fn bvh_levels_nest_and_hold_every_primitive() {
    let mut rng = Pcg::new(14);
    for (name, scene) in visit_scenes(&mut rng) {
        let a = Accel::build(AccelKind::Bvh, &scene);
        let levels = a.levels();
        let boxes = a.boxes();
        assert_eq!(
            levels,
            boxes.iter().map(|b| b.level).max().expect("boxes") + 1,
            "{name}"
        );
        assert!(levels >= 2, "{name}: {levels}");
        assert!(a.level_boxes(levels).is_empty());
        let root = a.level_boxes(0);
        assert_eq!(root.len(), 1, "{name}");
        assert_eq!((boxes[0].lo, boxes[0].hi), root[0]);
        let ids = 0..scene.spheres.len() + scene.triangles.len();
        for k in 0..levels {
            let level = a.level_boxes(k);
            assert!(!level.is_empty(), "{name} level {k}");
            for id in ids.clone() {
                let (lo, hi) = prim_bounds(&scene, id);
                let tol = 1e-5 * (1.0 + lo.abs().max(hi.abs()).max_element());
                assert!(
                    level.iter().any(|b| inside(lo, hi, *b, tol)),
                    "{name}: level {k} loses primitive {id}"
                );
            }
            if k + 1 < levels {
                for (lo, hi) in a.level_boxes(k + 1) {
                    assert!(
                        level.iter().any(|b| inside(lo, hi, *b, 0.0)),
                        "{name}: a box of level {} sticks out of level {k}",
                        k + 1
                    );
                }
            }
        }
        // Every primitive is in exactly one leaf, and a leaf's box holds its primitives.
        let mut seen = vec![0; ids.len()];
        for b in &boxes {
            for &p in &b.prims {
                seen[p as usize] += 1;
                let (lo, hi) = prim_bounds(&scene, p as usize);
                let tol = 1e-5 * (1.0 + lo.abs().max(hi.abs()).max_element());
                assert!(inside(lo, hi, (b.lo, b.hi), tol), "{name}: {p}");
            }
            if let Some(parent) = b.parent {
                assert_eq!(boxes[parent].level + 1, b.level);
                assert!(
                    boxes[parent].prims.is_empty(),
                    "{name}: a leaf with children"
                );
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "{name}: {seen:?}");
    }
}

/// (d) Grid cells: the cells entered are consecutive along the ray (each shares a face with
/// the one before, as the 3D-DDA steps), and the primitives tested are those of the entered
/// cells, in order (all of them for the closest hit, a prefix for occlusion).
#[test]
fn grid_visits_step_cell_by_cell() {
    let mut rng = Pcg::new(15);
    let m = default_methods();
    let mut long_walks = 0;
    for (name, scene) in visit_scenes(&mut rng) {
        let a = Accel::build(AccelKind::Grid, &scene);
        assert_eq!(a.levels(), 0);
        let cells: std::collections::HashMap<_, Vec<u32>> = a
            .boxes()
            .into_iter()
            .map(|b| (box_key(b.lo, b.hi), b.prims))
            .collect();
        assert_eq!(a.level_boxes(0).len(), cells.len(), "{name}");
        assert!(a.level_boxes(1).is_empty());
        for id in 0..scene.spheres.len() + scene.triangles.len() {
            assert!(cells.values().any(|p| p.contains(&(id as u32))), "{name}");
        }
        let rays = rays_for(&scene, &mut rng, 1500);
        for (i, (ray, t_min, t_max)) in rays.iter().enumerate() {
            for (occlusion, v) in both_visits(&a, &m, ray, *t_min, *t_max) {
                for b in &v.boxes {
                    assert_eq!(b.level, 0);
                    assert!(
                        meets(ray, *t_min, *t_max, b.lo, b.hi),
                        "{name} ray {i} {ray:?} {t_min} {t_max} {b:?} {v:?}"
                    );
                }
                for w in v.boxes.windows(2) {
                    let (p, q) = (&w[0], &w[1]);
                    let stepped: Vec<usize> = (0..3)
                        .filter(|&axis| (p.lo[axis], p.hi[axis]) != (q.lo[axis], q.hi[axis]))
                        .collect();
                    assert_eq!(stepped.len(), 1, "{name} ray {i}: {p:?} then {q:?}");
                    let axis = stepped[0];
                    assert!(
                        p.hi[axis] == q.lo[axis] || p.lo[axis] == q.hi[axis],
                        "{name} ray {i}: {p:?} then {q:?} do not touch"
                    );
                }
                let listed: Vec<u32> = v
                    .boxes
                    .iter()
                    .flat_map(|b| cells.get(&box_key(b.lo, b.hi)).cloned().unwrap_or_default())
                    .collect();
                if occlusion {
                    assert!(listed.starts_with(&v.prims), "{name} ray {i}");
                } else {
                    assert_eq!(listed, v.prims, "{name} ray {i}");
                }
                long_walks += usize::from(v.boxes.len() > 3);
            }
        }
    }
    assert!(long_walks > 1000, "{long_walks}");
    // Axis-parallel rays beside the grid (and one leaving it) enter no cell.
    let scene = random_scene(&mut rng, 20, 100, 1.0, 0.3);
    let a = Accel::build(AccelKind::Grid, &scene);
    for ray in [
        Ray::new(Vec3::new(-3.0, 5.0, 0.0), Vec3::X),
        Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Y),
        Ray::new(Vec3::new(5.0, 0.0, 0.0), Vec3::X),
        Ray::new(Vec3::new(5.0, 5.0, 5.0), Vec3::ONE.normalize()),
    ] {
        let v = a.closest_hit_visits(&m, &ray, 0.0, f32::INFINITY);
        assert!(v.boxes.is_empty() && v.prims.is_empty(), "{ray:?}: {v:?}");
    }
}
