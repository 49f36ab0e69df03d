//! Ray tracing trees of hand-built scenes whose trees are known: structure, end reasons,
//! weights and numbers; plus the JSON form as a snapshot.
//!
//! Update the snapshot after a deliberate change: `INSTA_UPDATE=always cargo test --release
//! --test ray_tree` (then review the diff).

mod common;

use common::{Build, close, floor, looking, mat, wall_z};
use glam::Vec3;
use raytree::ray_tree::{MAX_NODES, Node, RayTree, pixel_tree};
use raytree::scene::Material;
use raytree::trace::{EndReason, MAX_RAYS_PER_SAMPLE, RayKind, TraceSettings};

fn glass(name: &str, kr: f32, kt: f32) -> Material {
    Material {
        name: name.into(),
        ambient: Vec3::ZERO,
        diffuse: Vec3::splat(0.1),
        specular: Vec3::splat(0.5),
        shininess: 50.0,
        reflectivity: Vec3::splat(kr),
        transparency: Vec3::splat(kt),
        ior: 1.5,
        ..Material::default()
    }
}

fn tree(b: &Build) -> RayTree {
    pixel_tree(&b.tracer(), 2, 2).expect("pixel inside the image")
}

/// Every node's colour is its local term plus its weighted children, as recorded.
fn check_sums(node: &Node) {
    if let Some(local) = &node.local {
        let mut sum = local.total;
        for c in &node.children {
            let w = match c.kind {
                RayKind::Reflected => node.kr.expect("kr recorded"),
                _ => node.kt.expect("kt recorded"),
            };
            sum += w * c.color;
            assert!(close(c.weight, node.weight * w, 1e-6), "child weight");
        }
        assert!(close(sum, node.color, 1e-6), "{sum} vs {}", node.color);
    }
    node.children.iter().for_each(check_sums);
}

fn mirrors(max_depth: u32) -> Build {
    let mut b = Build::new(looking(Vec3::ZERO, Vec3::NEG_Z, 60.0), 5, 5)
        .material(mat(
            "mirror",
            Vec3::splat(0.1),
            Vec3::splat(0.2),
            0.3,
            16.0,
            0.5,
        ))
        .light(Vec3::new(0.0, 0.0, 0.0), Vec3::ONE)
        .quad("far mirror", wall_z(-2.0, 5.0, true), 0)
        .quad("near mirror", wall_z(2.0, 5.0, false), 0);
    b.0.render.max_depth = max_depth;
    b
}

#[test]
fn mirror_pair_bounces_until_max_depth() {
    let b = mirrors(3);
    let t = tree(&b);
    check_sums(&t.root);
    let mut node = &t.root;
    let mut chain = Vec::new();
    loop {
        chain.push(node);
        match node.children.as_slice() {
            [] => break,
            [only] => {
                assert_eq!(only.kind, RayKind::Reflected);
                node = only;
            }
            more => panic!("a mirror spawns one ray, got {}", more.len()),
        }
    }
    // Depths 0..=3 hit the mirrors in turn; the depth-4 child is not traced.
    assert_eq!(chain.len(), 5);
    for (d, n) in chain.iter().enumerate() {
        assert_eq!(n.depth, d as u32);
        assert!(close(n.weight, Vec3::splat(0.5f32.powi(d as i32)), 1e-7));
    }
    let names: Vec<_> = chain[..4]
        .iter()
        .map(|n| n.hit.as_ref().expect("hit").object.as_str())
        .collect();
    assert_eq!(
        names,
        ["far mirror", "near mirror", "far mirror", "near mirror"]
    );
    let ts: Vec<f32> = chain[..4]
        .iter()
        .map(|n| n.hit.as_ref().expect("hit").t)
        .collect();
    for (t, want) in ts.iter().zip([2.0, 4.0, 4.0, 4.0]) {
        assert!((t - want).abs() < 1e-5, "{ts:?}");
    }
    let leaf = chain[4];
    assert_eq!(leaf.end, Some(EndReason::MaxDepth));
    assert!(leaf.hit.is_none());
    assert_eq!(leaf.color, b.0.render.background);
    assert_eq!(t.rays.reflected, 3, "the max-depth child is not traced");
}

#[test]
fn glass_sphere_refracts_in_and_out() {
    let b = Build::new(looking(Vec3::ZERO, Vec3::NEG_Z, 60.0), 5, 5)
        .material(glass("glass", 0.1, 0.9))
        .light(Vec3::new(0.0, 5.0, 0.0), Vec3::ONE)
        .sphere("ball", Vec3::new(0.0, 0.0, -4.0), 1.0, 0);
    let t = tree(&b);
    check_sums(&t.root);
    let root_hit = t.root.hit.as_ref().expect("the ball");
    assert!(root_hit.front_face && (root_hit.point.z + 3.0).abs() < 1e-6);
    let kinds: Vec<_> = t.root.children.iter().map(|c| c.kind).collect();
    assert_eq!(kinds, [RayKind::Reflected, RayKind::Refracted]);
    assert_eq!(t.root.children[0].end, Some(EndReason::NoHit));
    // Normal incidence: T goes straight through, meets the far side from inside…
    let t1 = &t.root.children[1];
    assert!(close(t1.direction, Vec3::NEG_Z, 1e-6));
    let inner = t1.hit.as_ref().expect("the far side");
    assert!(!inner.front_face, "the far side is met from inside");
    assert!((inner.t - 2.0).abs() < 1e-5 && (inner.point.z + 5.0).abs() < 1e-5);
    assert!(
        close(inner.normal, Vec3::Z, 1e-6),
        "N turned towards the ray"
    );
    // …and leaves again (T then T), weight kt·kt.
    let t2 = t1
        .children
        .iter()
        .find(|c| c.kind == RayKind::Refracted)
        .expect("T at depth 2");
    assert_eq!(t2.depth, 2);
    assert!(close(t2.weight, Vec3::splat(0.81), 1e-6));
    assert!(close(t2.direction, Vec3::NEG_Z, 1e-6));
    assert_eq!(t2.end, Some(EndReason::NoHit));
    assert!(!t1.total_internal_reflection);
    // The light is outside: from inside the ball its shadow ray is blocked by the ball.
    assert_eq!(t1.shadow_rays[0].blocked_by.as_deref(), Some("ball"));
}

#[test]
fn total_internal_reflection_moves_kt_to_r() {
    let b = Build::new(looking(Vec3::ZERO, Vec3::NEG_Z, 60.0), 5, 5)
        .material(glass("glass", 0.1, 0.9))
        .light(Vec3::new(0.0, 5.0, 0.0), Vec3::ONE)
        .quad("entry face", wall_z(-2.0, 3.0, true), 0)
        // The plane y = z + 4, its front facing (0, 1, −1)/√2: met from behind at 45°.
        .triangle(
            "slanted face",
            [
                Vec3::new(-3.0, -3.0, -7.0),
                Vec3::new(0.0, 3.0, -1.0),
                Vec3::new(3.0, -3.0, -7.0),
            ],
            0,
        );
    let t = tree(&b);
    check_sums(&t.root);
    let t1 = &t.root.children[1];
    assert_eq!(t1.kind, RayKind::Refracted);
    let hit = t1.hit.as_ref().expect("the slanted face");
    assert_eq!(hit.object, "slanted face");
    assert!(!hit.front_face);
    // Leaving glass at 45° > asin(1/1.5) = 41.8°: no T, and kt moves to R.
    assert!(t1.total_internal_reflection);
    assert_eq!(t1.children.len(), 1);
    assert!(close(t1.kr.expect("kr"), Vec3::ONE, 1e-6), "kr + kt");
    assert!(close(t1.kt.expect("kt"), Vec3::ZERO, 0.0));
    let r = &t1.children[0];
    assert_eq!(r.kind, RayKind::Reflected);
    assert!(close(r.direction, Vec3::NEG_Y, 1e-6), "{}", r.direction);
    assert!(close(r.weight, Vec3::splat(0.9), 1e-6));
}

#[test]
fn shadow_ray_names_its_blocker() {
    let floor_ka = Vec3::new(0.3, 0.2, 0.1);
    let b = Build::new(looking(Vec3::ZERO, Vec3::new(0.0, -1.0, -2.0), 40.0), 5, 5)
        .material(mat("floor", floor_ka, Vec3::splat(0.8), 0.5, 10.0, 0.0))
        .material(mat("blocker", Vec3::ONE, Vec3::ONE, 0.0, 1.0, 0.0))
        .light(Vec3::new(0.0, 4.0, -2.0), Vec3::ONE)
        .sphere("blocker", Vec3::new(0.0, 1.0, -2.0), 0.5, 1)
        .quad("floor", floor(), 0);
    let t = tree(&b);
    let s = &t.root.shadow_rays[0];
    assert_eq!(t.root.hit.as_ref().expect("floor").object, "floor");
    assert_eq!(s.blocked_by.as_deref(), Some("blocker"));
    // From the floor at y = −1 up to the sphere's bottom at y = 0.5.
    let d = s.blocked_at.expect("distance to the blocker");
    assert!((d - 1.5).abs() < 1e-4, "{d}");
    assert!((s.distance - 5.0).abs() < 1e-5);
    assert!(close(s.to_light, Vec3::Y, 1e-6));
    assert_eq!((s.diffuse, s.specular), (Vec3::ZERO, Vec3::ZERO));
    let local = t.root.local.expect("local terms");
    assert!(close(local.total, floor_ka * 0.5, 1e-6));
    assert_eq!(t.color, local.total);
}

#[test]
fn a_visible_light_ends_the_ray_with_its_colour() {
    let color = Vec3::new(1.0, 0.8, 0.6);
    let b = Build::new(looking(Vec3::ZERO, Vec3::NEG_Z, 60.0), 5, 5).visible_light(
        "bulb",
        Vec3::new(0.0, 0.0, -5.0),
        color,
        0.5,
    );
    let t = tree(&b);
    assert_eq!(t.root.end, Some(EndReason::HitLight));
    let light = t.root.light.as_ref().expect("the light met");
    assert_eq!(light.name, "bulb");
    assert!((light.t - 4.5).abs() < 1e-5);
    assert!(t.root.hit.is_none() && t.root.children.is_empty());
    assert_eq!(t.color, color);
}

#[test]
fn a_miss_returns_the_background() {
    let b = Build::new(looking(Vec3::ZERO, Vec3::NEG_Z, 60.0), 5, 5).light(Vec3::Y, Vec3::ONE);
    let t = tree(&b);
    assert_eq!(t.root.end, Some(EndReason::NoHit));
    assert_eq!(t.color, b.0.render.background);
    assert_eq!((t.nodes, t.rays.total()), (1, 1));
}

#[test]
fn trees_are_capped_but_colours_stay_exact() {
    // Ten glass panes: every hit spawns R and T, so the tree doubles with depth.
    let mut b = Build::new(looking(Vec3::ZERO, Vec3::NEG_Z, 60.0), 5, 5)
        .material(glass("pane", 0.5, 0.5))
        .light(Vec3::new(0.0, 5.0, 0.0), Vec3::ONE);
    for k in 1..=10 {
        let z = -(k as f32);
        b = b.quad(&format!("pane {k}"), wall_z(z, 5.0, true), 0);
    }
    b.0.render.max_depth = 14;
    let tracer = b.tracer();
    let t = pixel_tree(&tracer, 2, 2).expect("pixel");
    assert!(t.truncated);
    assert_eq!(t.nodes, MAX_NODES);
    assert!(t.rays.total() as usize > MAX_NODES);
    let (image, _) = raytree::render::render(&tracer, 1, 1, &|_, _| {}).expect("render");
    assert_eq!(t.color, image.get(2, 2), "the cap never changes the colour");
}

/// Every `end` of a tree in its JSON form, depth first.
fn json_ends(node: &serde_json::Value, out: &mut Vec<String>) {
    if let Some(end) = node["end"].as_str() {
        out.push(end.to_string());
    }
    for child in node["children"].as_array().into_iter().flatten() {
        json_ends(child, out);
    }
}

fn tree_json_ends(t: &RayTree) -> Vec<String> {
    let json = serde_json::to_value(t).expect("json");
    let mut ends = Vec::new();
    json_ends(&json["root"], &mut ends);
    ends
}

/// Glass between mirrors at depth 64 (weight cutoff 0): the sample spends its ray budget, and
/// the branches cut short by it say `budget`, never `cutoff`. With the fixture's one light the
/// budget runs out far beyond the tree's node cap; 32 lights make every hit cost dozens of
/// shadow rays, so it runs out within the recorded part of the tree.
#[test]
fn a_branch_past_the_ray_budget_ends_as_budget() {
    let mut scene = raytree::scene::load_scene_file(std::path::Path::new(
        "tests/fixtures/hostile/glass_between_mirrors.toml",
    ))
    .expect("loads");
    let light = scene.lights[0].clone();
    scene.lights = (0..32)
        .map(|i| {
            let a = i as f32 * std::f32::consts::TAU / 32.0;
            raytree::scene::Light {
                name: format!("light {i}"),
                position: Vec3::new(1.5 * a.cos(), 1.5, 1.5 * a.sin()),
                ..light.clone()
            }
        })
        .collect();
    let lights = scene.lights.len() as u64;
    let tracer = raytree::trace::Tracer::new(std::sync::Arc::new(scene), Default::default());
    let t = pixel_tree(&tracer, 16, 12).expect("centre pixel");
    // The budget stops new rays; the shadow rays of the last hit are still traced.
    let budget = u64::from(MAX_RAYS_PER_SAMPLE);
    assert!(
        (budget..=budget + lights).contains(&t.rays.total()),
        "{:?}",
        t.rays
    );
    let ends = tree_json_ends(&t);
    assert!(t.nodes < MAX_NODES, "{} nodes", t.nodes);
    assert!(ends.iter().any(|e| e == "budget"), "{ends:?}");
    assert!(!ends.iter().any(|e| e == "cutoff"), "{ends:?}");
}

/// A weight below the cutoff still ends as `cutoff`: mirrors of reflectivity 0.5 with a cutoff
/// of 0.2 trace depths 0 to 2 (weights 1, 0.5, 0.25) and end the depth-3 ray (0.125).
#[test]
fn a_branch_below_the_weight_cutoff_ends_as_cutoff() {
    let b = mirrors(10);
    let settings = TraceSettings {
        cutoff: 0.2,
        ..TraceSettings::default()
    };
    let tracer = raytree::trace::Tracer::new(std::sync::Arc::new(b.0.clone()), settings);
    let t = pixel_tree(&tracer, 2, 2).expect("pixel");
    assert_eq!(tree_json_ends(&t), ["cutoff"]);
    assert_eq!(t.rays.primary + t.rays.reflected, 3);
}

/// Rounds every float of a JSON value, so the snapshot does not hang on the last ulp.
fn rounded(v: serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::Number(n) if n.is_f64() => {
            let x = n.as_f64().unwrap_or(0.0);
            serde_json::json!((x * 1e5).round() / 1e5)
        }
        Value::Array(a) => Value::Array(a.into_iter().map(rounded).collect()),
        Value::Object(o) => Value::Object(o.into_iter().map(|(k, v)| (k, rounded(v))).collect()),
        other => other,
    }
}

#[test]
fn quiz_tree_json() {
    let scene = raytree::scene::builtin::load_builtin("quiz").expect("quiz");
    let tracer = raytree::trace::Tracer::new(std::sync::Arc::new(scene), Default::default());
    let t = pixel_tree(&tracer, 100, 100).expect("centre pixel");
    let json = rounded(serde_json::to_value(&t).expect("json"));
    insta::assert_json_snapshot!("quiz_centre_tree", json);
}
