//! A bare OBJ's first look (issue 14.4), measured on three models made here: a closed room with
//! furniture (walls facing inwards, no MTL), the same room with a Blender-style MTL (`Ka 1`),
//! and an outdoor model (the torus of assets/models, seen from outside). Each renders with a
//! mean luminance in a readable band and few saturated pixels; the room's camera stands inside
//! its bounds, the outdoor model's outside.

use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use raytree::render::render;
use raytree::scene::{Scene, load_scene_file};
use raytree::trace::{TraceSettings, Tracer};

/// The walls of a closed box `[-3, 3] × [0, 4] × [-4, 4]`, counter-clockwise seen from inside,
/// a table and a cabinet (outward), as OBJ text; `usemtl` lines when `materials`.
fn room(materials: bool) -> String {
    let mut out = String::new();
    if materials {
        out += "mtllib kitchen.mtl\nusemtl wall\n";
    }
    let mut base = 0;
    let mut block = |out: &mut String, lo: Vec3, hi: Vec3, inward: bool| {
        for i in 0..8 {
            let p = |bit: usize, l: f32, h: f32| if i & bit != 0 { h } else { l };
            *out += &format!(
                "v {} {} {}\n",
                p(4, lo.x, hi.x),
                p(2, lo.y, hi.y),
                p(1, lo.z, hi.z)
            );
        }
        // Outward quads of the cube of corners 1..8 (x: 4, y: 2, z: 1).
        for q in [
            [1, 2, 4, 3],
            [5, 7, 8, 6],
            [1, 5, 6, 2],
            [3, 4, 8, 7],
            [1, 3, 7, 5],
            [2, 6, 8, 4],
        ] {
            let [a, b, c, d] = q.map(|i| i + base);
            if inward {
                *out += &format!("f {a} {c} {b}\nf {a} {d} {c}\n");
            } else {
                *out += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
            }
        }
        base += 8;
    };
    block(
        &mut out,
        Vec3::new(-3.0, 0.0, -4.0),
        Vec3::new(3.0, 4.0, 4.0),
        true,
    );
    if materials {
        out += "usemtl wood\n";
    }
    block(
        &mut out,
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.8, 0.5),
        false,
    );
    block(
        &mut out,
        Vec3::new(-2.9, 0.0, -3.9),
        Vec3::new(-1.5, 2.0, -2.5),
        false,
    );
    out
}

/// What Blender writes: `Ka 1` on every material.
const BLENDER_MTL: &str = "newmtl wall\nNs 225\nKa 1.000000 1.000000 1.000000\nKd 0.800000 0.800000 0.800000\nKs 0.500000 0.500000 0.500000\nNi 1.45\nd 1.000000\nillum 2\n\nnewmtl wood\nNs 225\nKa 1.000000 1.000000 1.000000\nKd 0.600000 0.350000 0.150000\nKs 0.500000 0.500000 0.500000\nNi 1.45\nd 1.000000\nillum 2\n";

/// Mean luminance (of the displayed, clamped linear colour) and the fraction of pixels with a
/// channel at 1 or more.
fn look(scene: Scene) -> (f32, f32, Scene) {
    let mut scene = scene;
    scene.render.width = 160;
    scene.render.height = 120;
    let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
    let (image, _) = render(&tracer, 1, 0, &|_, _| {}).expect("renders");
    let n = image.pixels.len() as f32;
    let lum = |c: Vec3| {
        let c = c.clamp(Vec3::ZERO, Vec3::ONE);
        0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
    };
    let mean = image.pixels.iter().map(|&c| lum(c)).sum::<f32>() / n;
    let saturated = image
        .pixels
        .iter()
        .filter(|c| c.max_element() >= 1.0)
        .count() as f32
        / n;
    eprintln!("mean luminance {mean:.3}, saturated {saturated:.3}");
    (mean, saturated, scene)
}

fn inside(p: Vec3, scene: &Scene) -> bool {
    let (lo, hi) = scene.bounds().expect("bounds");
    p.cmpgt(lo).all() && p.cmplt(hi).all()
}

fn load(dir: &Path, name: &str, text: &str) -> Scene {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    load_scene_file(&path).expect("loads")
}

#[test]
fn a_bare_room_and_a_blender_room_are_readable_from_inside() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("kitchen.mtl"), BLENDER_MTL).expect("write");
    for (name, text) in [("room.obj", room(false)), ("kitchen.obj", room(true))] {
        let scene = load(dir.path(), name, &text);
        assert!(
            inside(scene.camera.position, &scene),
            "{name}: camera outside the room"
        );
        assert!(scene.render.ambient_light.max_element() <= 0.1 + 1e-6);
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.contains("closed around its centre")),
            "{name}: {:?}",
            scene.warnings
        );
        let (mean, saturated, scene) = look(scene);
        assert!((0.2..0.75).contains(&mean), "{name}: mean luminance {mean}");
        assert!(
            saturated < 0.1,
            "{name}: {saturated} of the pixels saturated"
        );
        if name == "kitchen.obj" {
            let wall = scene
                .materials
                .iter()
                .find(|m| m.name.ends_with("/wall"))
                .expect("wall");
            assert_eq!(wall.ambient, wall.diffuse, "`Ka 1` read as `Kd`");
            assert!(
                scene
                    .warnings
                    .iter()
                    .any(|w| w.contains("`Ka 1` (Blender's default)"))
            );
        }
    }
}

#[test]
fn an_outdoor_model_is_framed_from_outside_and_readable() {
    let text = std::fs::read_to_string("assets/models/torus.obj").expect("the torus");
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = load(dir.path(), "torus.obj", &text);
    assert!(
        !inside(scene.camera.position, &scene),
        "the camera stands outside"
    );
    assert_eq!(
        scene
            .lights
            .iter()
            .map(|l| l.name.as_str())
            .collect::<Vec<_>>(),
        ["key", "headlight"]
    );
    assert_eq!(scene.lights[1].position, scene.camera.position);
    let (mean, saturated, _) = look(scene);
    // A model on black: darker on average than a room, but lit.
    assert!((0.03..0.6).contains(&mean), "mean luminance {mean}");
    assert!(saturated < 0.1, "{saturated} of the pixels saturated");
}
