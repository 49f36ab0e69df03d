//! Coherent rays: camera rays traced in packets (and their shadow rays towards each light) give
//! the image of the single-ray path bit for bit, with the same ray counts and pixel facts, on
//! every built-in scene (the stability scenes `acne` and `cracks` among them), with every
//! accelerator and every intersection, offset and shading-normal method (the smooth, textured
//! `smooth` scene among them); and the packet queries of the
//! accelerator answer what the single queries answer.

use std::sync::Arc;

use glam::Vec3;
use raytree::accel::{Accel, AccelKind, PrimSet};
use raytree::choice::Choice;
use raytree::geometry::{Methods, OffsetMethod, Ray, ShadingNormals, SphereMethod, TriangleMethod};
use raytree::render::{
    Rect, accumulate_tile, accumulate_tile_single, preview_tile, preview_tile_single, render,
    render_with, trace_tile_single,
};
use raytree::scene::builtin::{NAMES, load_builtin};
use raytree::scene::{CameraFrame, Scene};
use raytree::trace::{RayCounts, TraceSettings, Tracer};

/// Each colour's bits, to compare images (or sums) exactly.
fn bits(pixels: &[Vec3]) -> Vec<[u32; 3]> {
    pixels
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

/// Renders `scene` with packets and ray by ray and asserts the images and ray counts agree
/// exactly; returns the rays traced.
fn assert_same(scene: &Scene, settings: TraceSettings, samples: u32, what: &str) -> RayCounts {
    let tracer = Tracer::new(Arc::new(scene.clone()), settings);
    let (packets, ps) = render(&tracer, samples, 2, &|_, _| {}).expect("packet render");
    let (single, ss) =
        render_with(&tracer, samples, 2, &|_, _| {}, &trace_tile_single).expect("single render");
    assert_eq!(ps.rays, ss.rays, "{what}: ray counts");
    let (a, b) = (bits(&packets.pixels), bits(&single.pixels));
    let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert_eq!(differ, 0, "{what}: {differ} pixels differ");
    ps.rays
}

fn sized(name: &str, width: u32, height: u32) -> Scene {
    let mut s = load_builtin(name).unwrap_or_else(|e| panic!("built-in {name}: {e}"));
    // Odd sizes: packets cut by the tile and image edges are partial.
    s.render.width = width;
    s.render.height = height;
    s
}

#[test]
fn every_builtin_scene_is_bit_identical_with_every_accelerator() {
    for name in NAMES {
        let scene = sized(name, 97, 71);
        for accel in [AccelKind::None, AccelKind::Grid, AccelKind::Bvh] {
            let settings = TraceSettings {
                accel,
                ..TraceSettings::default()
            };
            let rays = assert_same(&scene, settings, 2, &format!("{name} {accel:?}"));
            assert!(rays.primary == 2 * 97 * 71, "{name}: {rays:?}");
        }
    }
}

#[test]
fn every_method_and_the_cutoff_are_bit_identical() {
    for name in NAMES {
        let scene = sized(name, 61, 45);
        let mut variants = Vec::new();
        for &sphere in SphereMethod::ALL {
            for &triangle in TriangleMethod::ALL {
                for &offset in OffsetMethod::ALL {
                    for &shading_normals in ShadingNormals::ALL {
                        variants.push((
                            Methods {
                                sphere,
                                triangle,
                                offset,
                                shading_normals,
                            },
                            0.0,
                        ));
                    }
                }
            }
        }
        variants.push((Methods::default(), 0.3));
        // Above 1 even the primary rays end untraced (cutoff), on both paths.
        variants.push((Methods::default(), 1.5));
        for (methods, cutoff) in variants {
            let settings = TraceSettings {
                accel: AccelKind::Bvh,
                methods,
                cutoff,
            };
            assert_same(
                &scene,
                settings,
                1,
                &format!("{name} {methods:?} cutoff {cutoff}"),
            );
        }
    }
}

/// The peer bench's scene (a mesh, mirror and glass spheres, two lights), small.
#[test]
fn bench_scene_is_bit_identical() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = raytree::scene::procedural::write_bench_scene(dir.path(), 3000).expect("write");
    let mut scene = raytree::scene::load_scene_file(&path).expect("load");
    scene.render.width = 130;
    scene.render.height = 98;
    let rays = assert_same(&scene, TraceSettings::default(), 1, "bench scene");
    assert!(rays.shadow > rays.primary && rays.reflected > 0 && rays.refracted > 0);
}

/// The pixel facts the viewer's image modes show come out row-major and equal, appended after
/// what the list held.
#[test]
fn tile_facts_are_the_single_paths() {
    let scene = sized("default", 40, 30);
    let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
    let frame = CameraFrame::new(&scene.camera, 40, 30);
    let rect = Rect {
        x: 3,
        y: 5,
        width: 31,
        height: 23,
    };
    let n = (rect.width * rect.height) as usize;
    let (mut sums_p, mut sums_s) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]);
    let (mut counts_p, mut counts_s) = (RayCounts::default(), RayCounts::default());
    let before = raytree::trace::SampleInfo {
        rays: 77,
        ..Default::default()
    };
    let (mut first_p, mut first_s) = (vec![before], vec![before]);
    let samples = 0..3;
    accumulate_tile(
        &tracer,
        &frame,
        rect,
        samples.clone(),
        &mut sums_p,
        &mut counts_p,
        Some(&mut first_p),
    );
    accumulate_tile_single(
        &tracer,
        &frame,
        rect,
        samples,
        &mut sums_s,
        &mut counts_s,
        Some(&mut first_s),
    );
    assert_eq!(first_p.len(), n + 1);
    assert_eq!(first_p, first_s);
    assert_eq!(counts_p, counts_s);
    assert_eq!(sums_p, sums_s);
    // A later pass (no sample 0) adds no facts.
    let mut later = Vec::new();
    accumulate_tile(
        &tracer,
        &frame,
        rect,
        3..4,
        &mut sums_p,
        &mut counts_p,
        Some(&mut later),
    );
    assert!(later.is_empty());
}

/// Hits on surfaces without reflection or refraction take the packet's local-only shading
/// (`Tracer::shade_given_local`), the others and scenes of more lights than a packet keeps
/// the general path: the same colours, facts and ray counts as ray by ray either way, with
/// one to six lights (one of them black, one below the floor, one a visible ball), every
/// material opaque or the scene's own, on the textured `default` scene and `smooth`.
#[test]
fn local_only_shading_is_the_general_paths() {
    let extra = [
        (Vec3::new(2.0, 7.0, 4.0), Vec3::splat(0.3), 0.0),
        (Vec3::new(0.0, -3.0, 0.0), Vec3::splat(0.6), 0.0),
        (Vec3::new(-3.0, 2.0, -4.0), Vec3::ZERO, 0.0),
        (Vec3::new(1.5, 3.0, 3.0), Vec3::new(0.2, 0.5, 0.1), 0.1),
    ];
    for name in ["default", "smooth"] {
        for opaque in [true, false] {
            for lights in 1..=6 {
                let mut scene = sized(name, 45, 37);
                if opaque {
                    for m in scene.materials.iter_mut() {
                        m.reflectivity = Vec3::ZERO;
                        m.transparency = Vec3::ZERO;
                    }
                }
                for (k, &(position, color, radius)) in extra.iter().cycle().enumerate() {
                    if scene.lights.len() >= lights {
                        break;
                    }
                    let mut light = scene.lights[0].clone();
                    light.name = format!("extra {k}");
                    (light.position, light.color, light.radius) = (position, color, radius);
                    light.follow_camera = false;
                    scene.lights.push(light);
                }
                scene.lights.truncate(lights);
                let what = format!("{name}, opaque {opaque}, {lights} lights");
                let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
                let (w, h) = (scene.render.width, scene.render.height);
                let frame = CameraFrame::new(&scene.camera, w, h);
                let rect = Rect {
                    x: 0,
                    y: 0,
                    width: w,
                    height: h,
                };
                let n = (w * h) as usize;
                let (mut sums_p, mut sums_s) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]);
                let (mut counts_p, mut counts_s) = (RayCounts::default(), RayCounts::default());
                let (mut facts_p, mut facts_s) = (Vec::new(), Vec::new());
                let (p, s) = (&mut sums_p, &mut counts_p);
                accumulate_tile(&tracer, &frame, rect, 0..2, p, s, Some(&mut facts_p));
                let (p, s) = (&mut sums_s, &mut counts_s);
                accumulate_tile_single(&tracer, &frame, rect, 0..2, p, s, Some(&mut facts_s));
                assert_eq!(counts_p, counts_s, "{what}: ray counts");
                assert!(counts_p.shadow > 0, "{what}: {counts_p:?}");
                assert_eq!(facts_p, facts_s, "{what}: pixel facts");
                let (a, b) = (bits(&sums_p), bits(&sums_s));
                let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
                assert_eq!(differ, 0, "{what}: {differ} pixels differ");
            }
        }
    }
}

/// The viewer's coarse preview traces its block centres in packets: the same colours, facts
/// and ray counts as one ray at a time, on every built-in scene, for whole tiles, tiles cut by
/// the image's edge (centres clamped into it) and a block size that does not divide the tile.
#[test]
fn coarse_preview_is_bit_identical() {
    for name in NAMES {
        let scene = sized(name, 75, 47);
        let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
        let frame = CameraFrame::new(&scene.camera, 75, 47);
        let rects = [
            (0, 0, 32, 32),
            (64, 32, 11, 15),
            (32, 0, 32, 32),
            (5, 7, 70, 40),
        ];
        for (x, y, width, height) in rects {
            let rect = Rect {
                x,
                y,
                width,
                height,
            };
            for block in [8, 3] {
                let (mut counts_p, mut counts_s) = (RayCounts::default(), RayCounts::default());
                let (pixels_p, facts_p) = preview_tile(&tracer, &frame, rect, block, &mut counts_p);
                let (pixels_s, facts_s) =
                    preview_tile_single(&tracer, &frame, rect, block, &mut counts_s);
                let what = format!("{name} {rect:?} block {block}");
                assert_eq!(pixels_p.len(), (width * height) as usize, "{what}");
                assert_eq!(counts_p, counts_s, "{what}");
                assert!(counts_p.primary > 0, "{what}");
                assert_eq!(facts_p, facts_s, "{what}");
                assert_eq!(bits(&pixels_p), bits(&pixels_s), "{what}");
                // Every pixel of a block shows its centre's sample.
                let b = block as usize;
                let w = width as usize;
                for (k, c) in pixels_p.iter().enumerate() {
                    let (i, j) = (k % w, k / w);
                    assert_eq!(
                        *c,
                        pixels_p[(j / b * b) * w + i / b * b],
                        "{what} pixel {k}"
                    );
                }
            }
        }
    }
}

/// The packet traversal's node test eight rays wide (AVX2, chosen at run time) and four wide
/// (SSE, the fallback) give the single-ray image bit for bit, on every built-in scene and the
/// bench scene; on a CPU with AVX2 (this project's machines) asking for it uses it, and off
/// x86-64 every choice is the four-wide test. The choice is process-wide: the other tests of
/// this file hold under either.
#[test]
fn avx2_and_sse_node_tests_are_bit_identical() {
    use raytree::accel::{PacketSimd, packet_uses_avx2, set_packet_simd};
    let has_avx2 = cpu_has_avx2_and_fma();
    let dir = tempfile::tempdir().expect("temp dir");
    let path = raytree::scene::procedural::write_bench_scene(dir.path(), 3000).expect("write");
    let mut bench = raytree::scene::load_scene_file(&path).expect("load");
    bench.render.width = 90;
    bench.render.height = 70;
    let mut scenes: Vec<(String, Scene)> = NAMES
        .iter()
        .map(|name| (name.to_string(), sized(name, 57, 43)))
        .collect();
    scenes.push(("bench".into(), bench));
    for (name, scene) in &scenes {
        let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
        let (single, ss) =
            render_with(&tracer, 1, 2, &|_, _| {}, &trace_tile_single).expect("single render");
        for simd in [PacketSimd::Sse, PacketSimd::Avx2, PacketSimd::Auto] {
            set_packet_simd(simd);
            let wide = packet_uses_avx2();
            assert_eq!(wide, has_avx2 && simd != PacketSimd::Sse, "{simd:?}");
            let (image, ps) = render(&tracer, 1, 2, &|_, _| {}).expect("packet render");
            assert_eq!(ps.rays, ss.rays, "{name} {simd:?}: ray counts");
            let (a, b) = (bits(&image.pixels), bits(&single.pixels));
            let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
            assert_eq!(
                differ, 0,
                "{name} {simd:?} (AVX2 {wide}): {differ} pixels differ"
            );
        }
    }
    set_packet_simd(PacketSimd::Auto);
}

/// Whether this CPU has AVX2 and FMA (the eight-wide node test's needs).
#[cfg(target_arch = "x86_64")]
fn cpu_has_avx2_and_fma() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// Off x86-64 there is no eight-wide node test: asking for it gives the four-wide one, which
/// the test above still checks against the single-ray image.
#[cfg(not(target_arch = "x86_64"))]
fn cpu_has_avx2_and_fma() -> bool {
    false
}

/// Seeded numbers in `[−1, 1)`: the packets' rays.
struct Rng(raytree::rng::Pcg);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(raytree::rng::Pcg::new(seed))
    }

    fn next(&mut self) -> f32 {
        self.0.range(-1.0, 1.0)
    }

    fn vec(&mut self) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next())
    }
}

/// Packet queries against single ones on a triangle soup with spheres: neighbouring rays,
/// scattered rays, unusable rays (NaN, zero direction, empty interval) and inactive lanes,
/// which are left alone. Packets of 8 rays (what the render casts), and of 5, 13 and 32 (the
/// traversal keeps 8, 16 and 32 lanes by packet size).
#[test]
fn packet_queries_answer_as_single_queries() {
    packet_queries_of_size::<8>(12345);
    packet_queries_of_size::<5>(777);
    packet_queries_of_size::<13>(4242);
    packet_queries_of_size::<32>(31337);
}

fn packet_queries_of_size<const K: usize>(seed: u32) {
    let mut rng = Rng::new(u64::from(seed));
    let mut prims = PrimSet::default();
    for _ in 0..40 {
        prims
            .spheres
            .push((rng.vec() * 3.0, 0.05 + rng.next().abs() * 0.3));
    }
    for _ in 0..4000 {
        let c = rng.vec() * 3.0;
        prims
            .triangles
            .push([0, 1, 2].map(|_| c + rng.vec() * 0.25));
    }
    let m = Methods::default();
    for kind in [AccelKind::Bvh, AccelKind::Grid, AccelKind::None] {
        let accel = Accel::build(kind, &prims);
        let (mut hits, mut blocked_count) = (0, 0);
        for round in 0..300 {
            let origin = rng.vec() * 6.0;
            let aim = rng.vec() * 2.0;
            let spread = if round % 3 == 0 { 2.0 } else { 0.02 };
            let mut rays: [Ray; K] = std::array::from_fn(|_| {
                Ray::new(origin, (aim + rng.vec() * spread - origin).normalize())
            });
            let lengths: [f32; K] = std::array::from_fn(|_| 1.0 + rng.next().abs() * 8.0);
            if round % 7 == 0 {
                rays[3].dir = Vec3::ZERO;
                rays[K - 1].origin.x = f32::NAN;
            }
            let all = u32::MAX >> (32 - K);
            let active = if round % 5 == 0 {
                all & 0xb6b7_b6b7
            } else {
                all
            };
            let sentinel = Some(raytree::accel::PrimHit {
                t: -1.0,
                prim: 7,
                b1: 0.0,
                b2: 0.0,
            });
            let mut out = [sentinel; K];
            accel.closest_hits(&m, &rays, active, &mut out);
            let blocked = accel.occluded_packet(&m, &rays, &lengths, active);
            for i in 0..K {
                if active & (1 << i) == 0 {
                    assert_eq!(out[i], sentinel, "{kind:?} K={K} lane {i} touched");
                    assert_eq!(blocked & (1 << i), 0);
                    continue;
                }
                let single = accel.closest_hit(&m, &rays[i], 0.0, f32::INFINITY);
                assert_eq!(out[i], single, "{kind:?} K={K} round {round} lane {i}");
                let occluded = accel.occluded(&m, &rays[i], 0.0, lengths[i]);
                assert_eq!(
                    blocked & (1 << i) != 0,
                    occluded,
                    "{kind:?} K={K} round {round} lane {i}"
                );
                hits += usize::from(single.is_some());
                blocked_count += usize::from(occluded);
            }
        }
        // 300 rounds of K rays: at least an eighth hit and a twentieth are blocked.
        assert!(
            hits > 300 * K / 8 && blocked_count > 300 * K / 20,
            "{kind:?} K={K}: {hits} hits, {blocked_count} blocked"
        );
    }
}

/// More lights than a packet's shadow answers hold (64, then one ray at a time), visible lights
/// (balls that end rays) among them, and a light behind everything: still bit-identical.
#[test]
fn many_and_visible_lights_are_bit_identical() {
    let mut scene = sized("glass", 53, 37);
    let mut rng = Rng::new(99);
    for k in 0..70 {
        scene.lights.push(raytree::scene::Light {
            name: format!("extra {k}"),
            position: rng.vec() * 6.0 + Vec3::Y * 3.0,
            color: Vec3::splat(0.01),
            radius: if k % 9 == 0 { 0.2 } else { 0.0 },
            follow_camera: false,
        });
    }
    let rays = assert_same(
        &scene,
        TraceSettings::default(),
        1,
        "glass with 70 more lights",
    );
    assert!(rays.shadow > 64 * rays.primary / 4, "{rays:?}");
}
