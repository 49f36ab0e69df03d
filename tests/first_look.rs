//! A bare OBJ's first look, measured on three models made here: a closed room with furniture (walls
//! facing inwards, no MTL), the same room with a Blender-style MTL (`Ka 1`), and an outdoor model
//! (the torus of assets/models, seen from outside). Each renders with a mean luminance in a
//! readable band and few saturated pixels; the room's camera stands inside its bounds, the outdoor
//! model's outside.

use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use raytree::render::render;
use raytree::scene::{Material, Scene, load_scene_file};
use raytree::scene_view::cutaway::{Cutaway, encloses_render_camera};
use raytree::scene_view::overview::{Candidate, FOV_Y_DEG, candidates, overview};
use raytree::trace::{TraceSettings, Tracer};

/// The walls of a closed box `[-3, 3] × [0, 4] × [-4, 4]`, counter-clockwise seen from inside,
/// a table and a cabinet (outward), as OBJ text; `usemtl` lines when `materials`.
fn room(materials: bool) -> String {
    let mut out = String::new();
    if materials {
        out += "mtllib kitchen.mtl\nusemtl wall\n";
    }
    let mut base = 0;
    cuboid(
        &mut out,
        &mut base,
        Vec3::new(-3.0, 0.0, -4.0),
        Vec3::new(3.0, 4.0, 4.0),
        true,
        &[],
    );
    if materials {
        out += "usemtl wood\n";
    }
    cuboid(
        &mut out,
        &mut base,
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.8, 0.5),
        false,
        &[],
    );
    cuboid(
        &mut out,
        &mut base,
        Vec3::new(-2.9, 0.0, -3.9),
        Vec3::new(-1.5, 2.0, -2.5),
        false,
        &[],
    );
    out
}

/// What Blender writes: `Ka 1` on every material.
const BLENDER_MTL: &str = "newmtl wall\nNs 225\nKa 1.000000 1.000000 1.000000\nKd 0.800000 0.800000 0.800000\nKs 0.500000 0.500000 0.500000\nNi 1.45\nd 1.000000\nillum 2\n\nnewmtl wood\nNs 225\nKa 1.000000 1.000000 1.000000\nKd 0.600000 0.350000 0.150000\nKs 0.500000 0.500000 0.500000\nNi 1.45\nd 1.000000\nillum 2\n";

/// Mean luminance (of the displayed, clamped linear colour) and the fraction of pixels with a
/// channel at 1 or more, of the scene rendered at 160×120.
fn look(scene: &Scene) -> (f32, f32) {
    let image = pixels(scene);
    let n = image.len() as f32;
    let lum = |c: Vec3| {
        let c = c.clamp(Vec3::ZERO, Vec3::ONE);
        0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
    };
    let mean = image.iter().map(|&c| lum(c)).sum::<f32>() / n;
    let saturated = image.iter().filter(|c| c.max_element() >= 1.0).count() as f32 / n;
    eprintln!("mean luminance {mean:.3}, saturated {saturated:.3}");
    (mean, saturated)
}

/// The scene `name` renders readably: its mean luminance in `mean`, fewer than
/// `max_saturated` of its pixels saturated.
fn assert_readable(scene: &Scene, name: &str, mean: Range<f32>, max_saturated: f32) {
    let (m, saturated) = look(scene);
    assert!(mean.contains(&m), "{name}: mean luminance {m}");
    assert!(
        saturated < max_saturated,
        "{name}: {saturated} of the pixels saturated"
    );
}

/// The scene `name` has a warning that contains every one of `needles`.
fn assert_warned(scene: &Scene, name: &str, needles: &[&str]) {
    assert!(
        (scene.warnings.iter()).any(|w| needles.iter().all(|n| w.contains(n))),
        "{name}: {needles:?} in {:?}",
        scene.warnings
    );
}

/// The scene `name` has no warning that contains `needle`.
fn assert_not_warned(scene: &Scene, name: &str, needle: &str) {
    assert!(
        !scene.warnings.iter().any(|w| w.contains(needle)),
        "{name}: no {needle:?} in {:?}",
        scene.warnings
    );
}

/// The scene's material whose name ends with `suffix`.
fn material<'a>(scene: &'a Scene, suffix: &str) -> &'a Material {
    scene
        .materials
        .iter()
        .find(|m| m.name.ends_with(suffix))
        .unwrap_or_else(|| panic!("material {suffix} in {:?}", scene.materials))
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
        assert_warned(&scene, name, &["the camera starts inside it"]);
        assert_readable(&scene, name, 0.2..0.75, 0.1);
        if name == "kitchen.obj" {
            let wall = material(&scene, "/wall");
            assert_eq!(wall.ambient, wall.diffuse, "`Ka 1` read as `Kd`");
            assert_warned(&scene, name, &["`Ka 1` (Blender's default)"]);
        }
    }
}

/// The same room written z-up (3ds Max, SketchUp's z-up export): it is lower in z than in x
/// and y, so it opens z-up, from inside, lit from under its ceiling; written y-up it stays y-up.
#[test]
fn a_z_up_room_opens_z_up_from_inside() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A quarter turn about x: y becomes z, z becomes −y.
    let z_up: String = room(false)
        .lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(v) => {
                let c: Vec<f32> = v
                    .split_whitespace()
                    .map(|t| t.parse().expect("number"))
                    .collect();
                format!("v {} {} {}\n", c[0], -c[2], c[1])
            }
            None => format!("{line}\n"),
        })
        .collect();
    let scene = load(dir.path(), "room_z.obj", &z_up);
    assert_eq!(scene.camera.up, Vec3::Z, "z-up");
    assert!(inside(scene.camera.position, &scene), "camera inside");
    assert_warned(&scene, "room_z.obj", &["+z is taken as up"]);
    assert_warned(&scene, "room_z.obj", &["the camera starts inside it"]);
    let key = scene
        .lights
        .iter()
        .find(|l| l.name == "key")
        .expect("key light");
    let (lo, hi) = scene.bounds().expect("bounds");
    assert!(
        key.position.z > 0.5 * (lo.z + hi.z) && key.position.z < hi.z,
        "the key light hangs under the ceiling: {} in {lo}..{hi}",
        key.position
    );
    assert_readable(&scene, "room_z.obj", 0.2..0.75, 0.1);

    let y_up = load(dir.path(), "room.obj", &room(false));
    assert_eq!(y_up.camera.up, Vec3::Y, "the y-up room stays y-up");
    assert_not_warned(&y_up, "room.obj", "+z is taken as up");
}

/// A part with a hole through its middle (a rocker arm, a bearing) and a solid whose middle
/// is a pocket (a low-poly hand): the hole's walls face the middle as a room's do, but they
/// stand close around it, far from the model's outer shell, so the model is framed from
/// outside, not from inside the hole.
#[test]
fn a_hole_through_a_part_is_not_a_room() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut text = String::new();
    let mut base = 0;
    // The outer walls of a 4-unit block (its ends left open) and the walls of a 1-unit square
    // hole through it along z, facing into the hole.
    cuboid(
        &mut text,
        &mut base,
        Vec3::splat(-2.0),
        Vec3::splat(2.0),
        false,
        &[4, 5],
    );
    cuboid(
        &mut text,
        &mut base,
        Vec3::new(-0.5, -0.5, -2.0),
        Vec3::new(0.5, 0.5, 2.0),
        true,
        &[4, 5],
    );
    let scene = load(dir.path(), "part.obj", &text);
    assert_not_warned(&scene, "part.obj", "(a room)");
    let (lo, hi) = scene.bounds().expect("bounds");
    let p = scene.camera.position;
    assert!(
        p.cmplt(lo).any() || p.cmpgt(hi).any(),
        "the camera stands outside the part, not in its hole: {p}"
    );
    assert_readable(&scene, "part.obj", 0.03..0.6, 0.1);
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
    // A model on black: darker on average than a room, but lit.
    assert_readable(&scene, "torus.obj", 0.03..0.6, 0.1);
}

// ---- Traits of real files, each reproduced on a small generated model: a room whose middle is
// furniture (Sweet Home 3D bedroom), walls without a ceiling (a Blender kitchen), a box open on one
// side (the Cornell box), a z-up bust (a scanned Nefertiti, a MeshLab bottle), MeshLab's `Tr 1`,
// and framing tight enough to read.

/// The 8 corners and 12 triangles of the box `lo..hi` appended to `out` (vertex numbers from
/// `*base + 1`), facing inwards when `inward`; faces listed in `skip` (0 −x, 1 +x, 2 −y, 3 +y,
/// 4 −z, 5 +z) left out.
fn cuboid(out: &mut String, base: &mut usize, lo: Vec3, hi: Vec3, inward: bool, skip: &[usize]) {
    for i in 0..8 {
        let p = |bit: usize, l: f32, h: f32| if i & bit != 0 { h } else { l };
        *out += &format!(
            "v {} {} {}\n",
            p(4, lo.x, hi.x),
            p(2, lo.y, hi.y),
            p(1, lo.z, hi.z)
        );
    }
    let faces = [
        [1, 2, 4, 3],
        [5, 7, 8, 6],
        [1, 5, 6, 2],
        [3, 4, 8, 7],
        [1, 3, 7, 5],
        [2, 6, 8, 4],
    ];
    for (k, q) in faces.iter().enumerate() {
        if skip.contains(&k) {
            continue;
        }
        let [a, b, c, d] = q.map(|i| i + *base);
        if inward {
            *out += &format!("f {a} {c} {b}\nf {a} {d} {c}\n");
        } else {
            *out += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    *base += 8;
}

/// A rendered image at 160×120: its linear pixels.
fn pixels(scene: &Scene) -> Vec<Vec3> {
    let mut scene = scene.clone();
    scene.render.width = 160;
    scene.render.height = 120;
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    render(&tracer, 1, 0, &|_, _| {}).expect("renders").0.pixels
}

fn forward(scene: &Scene) -> Vec3 {
    (scene.camera.look_at - scene.camera.position).normalize()
}

#[test]
fn a_room_whose_middle_is_a_bed_is_seen_from_inside_and_not_from_inside_the_bed() {
    // The bounds' centre (0, 1.5, 0) is inside the (four-poster) bed: rays from there meet the
    // bed's faces from behind, which the 14-ray test from the centre took for a statue.
    let mut text = String::new();
    let mut base = 0;
    let (lo, hi) = (Vec3::new(-3.0, 0.0, -4.0), Vec3::new(3.0, 3.0, 4.0));
    cuboid(&mut text, &mut base, lo, hi, true, &[]);
    let bed = (Vec3::new(-1.0, 0.0, -1.5), Vec3::new(1.0, 2.0, 1.5));
    cuboid(&mut text, &mut base, bed.0, bed.1, false, &[]);
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = load(dir.path(), "bedroom.obj", &text);
    let p = scene.camera.position;
    assert!(inside(p, &scene), "camera at {p}, outside the room");
    let in_bed = p.cmpgt(bed.0).all() && p.cmplt(bed.1).all();
    assert!(!in_bed, "camera at {p}, inside the bed");
    assert_warned(&scene, "bedroom.obj", &["the camera starts inside it"]);
    let key = scene.lights[0].position;
    assert!(inside(key, &scene), "key light at {key}, outside the room");
    // Darker than an empty room: the bed fills much of the view and shades the floor.
    assert_readable(&scene, "bedroom.obj", 0.15..0.75, 0.02);
}

#[test]
fn walls_without_a_ceiling_are_seen_from_above_outside() {
    let mut text = String::new();
    let mut base = 0;
    let (lo, hi) = (Vec3::new(-3.0, 0.0, -4.0), Vec3::new(3.0, 3.0, 4.0));
    cuboid(&mut text, &mut base, lo, hi, true, &[3]);
    cuboid(
        &mut text,
        &mut base,
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.9, 1.0),
        false,
        &[],
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = load(dir.path(), "kitchen.obj", &text);
    let p = scene.camera.position;
    assert!(!inside(p, &scene), "camera at {p}, inside");
    assert!(p.y > hi.y, "camera at {p}, not above the walls");
    assert!(forward(&scene).y < -0.3, "looks down into the room");
    assert_readable(&scene, "kitchen.obj", 0.1..0.75, 0.02);
    // Boxes without a lid, as high as they are wide and higher (a bin, a vase): from inside a
    // tall one, most rays upwards meet its walls, but its top is open. Seen from above too,
    // not from inside.
    for height in [2.0, 3.0, 4.0] {
        let mut bin = String::new();
        let (lo, hi) = (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, height, 1.0));
        cuboid(&mut bin, &mut 0, lo, hi, true, &[3]);
        let scene = load(dir.path(), "bin.obj", &bin);
        let p = scene.camera.position;
        assert!(
            !inside(p, &scene) && p.y > hi.y,
            "bin {height}: camera at {p}"
        );
        assert!(forward(&scene).y < -0.3, "bin {height}: looks down into it");
        assert_not_warned(&scene, "bin.obj", "(a room)");
    }
}

/// Cornell-box colours: white, red and green walls of `Kd 1` (no `Ka`).
const CORNELL_MTL: &str = "newmtl white\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\n\nnewmtl red\nKa 0 0 0\nKd 1 0 0\nKs 0 0 0\n\nnewmtl green\nKa 0 0 0\nKd 0 1 0\nKs 0 0 0\n";

/// A Cornell box 5.5 on a side open at −z (as the Cornell box's data is), white with a red
/// and a green wall, two white boxes in it: its OBJ text and bounds.
fn cornell() -> (String, Vec3, Vec3) {
    let mut text = String::from("mtllib cornell.mtl\nusemtl white\n");
    let mut base = 0;
    let (lo, hi) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(5.5, 5.5, 5.5));
    cuboid(&mut text, &mut base, lo, hi, true, &[0, 1, 4]);
    text += "usemtl red\n";
    cuboid(&mut text, &mut base, lo, hi, true, &[1, 2, 3, 4, 5]);
    text += "usemtl green\n";
    cuboid(&mut text, &mut base, lo, hi, true, &[0, 2, 3, 4, 5]);
    text += "usemtl white\n";
    cuboid(
        &mut text,
        &mut base,
        Vec3::new(1.0, 0.0, 3.0),
        Vec3::new(2.5, 3.3, 4.5),
        false,
        &[],
    );
    cuboid(
        &mut text,
        &mut base,
        Vec3::new(3.2, 0.0, 1.0),
        Vec3::new(4.7, 1.6, 2.5),
        false,
        &[],
    );
    (text, lo, hi)
}

/// The Cornell box of [`cornell`] loaded from a temporary folder.
fn load_cornell(dir: &Path) -> Scene {
    let (text, _, _) = cornell();
    std::fs::write(dir.join("cornell.mtl"), CORNELL_MTL).expect("write");
    load(dir, "cornell.obj", &text)
}

#[test]
fn a_box_open_on_one_side_is_seen_through_its_opening_without_clipping_white() {
    // The camera used to stand at +z and see the back of the box.
    let (_, lo, _) = cornell();
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = load_cornell(dir.path());
    assert!(
        scene.camera.position.z < lo.z,
        "camera at {}, not in front of the opening",
        scene.camera.position
    );
    assert!(forward(&scene).z > 0.99, "looks in: {}", forward(&scene));
    assert_warned(&scene, "cornell.obj", &["open on one side"]);
    let key = scene.lights[0].position;
    assert!(inside(key, &scene), "key light at {key}, outside the box");
    assert_readable(&scene, "cornell.obj", 0.15..0.75, 0.01);
}

/// The directions the scene view may first look from, scored on `scene` for a pane of
/// `aspect`, and the one taken.
fn scene_view_looks(scene: Scene, aspect: f32) -> (Vec<Candidate>, usize) {
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let all = candidates(&tracer, aspect, FOV_Y_DEG);
    let chosen = overview(&tracer, aspect, FOV_Y_DEG, Cutaway::Auto);
    let taken = all
        .iter()
        .position(|c| c.camera == chosen)
        .expect("the first look is one of the candidates");
    let sees: Vec<f32> = all.iter().map(|c| c.sees).collect();
    eprintln!("aspect {aspect}: sees {sees:?}, taken {taken}");
    (all, taken)
}

/// The scene view's panes: tall beside the render view, square above the tree, wide when
/// popped out.
const PANES: [f32; 4] = [0.46, 0.9, 4.0 / 3.0, 1.8];

/// `all[taken]` sees at least 0.8 of the best and `all[0]` (beside the render camera) less,
/// and the taken eye is in front of the box `lo..` (on its open −z side).
fn assert_looks_in(all: &[Candidate], taken: usize, lo: Vec3) {
    let best = all.iter().map(|c| c.sees).fold(0.0, f32::max);
    assert!(
        all[0].sees < 0.8 * best,
        "from beside the box the view sees {} of it, the best {best}",
        all[0].sees
    );
    assert!(taken > 0 && all[taken].sees >= 0.8 * best);
    let eye = all[taken].camera.position;
    assert!(
        eye.z < lo.z,
        "the view's eye {eye} is not on the opening's side"
    );
}

/// The scene view's first look at a box open on one side sees into it: from its preferred
/// side, beside the render camera, it saw the outside of a side wall.
#[test]
fn the_scene_view_first_looks_into_a_box_open_on_one_side() {
    let (_, lo, _) = cornell();
    let dir = tempfile::tempdir().expect("temp dir");
    for aspect in PANES {
        let (all, taken) = scene_view_looks(load_cornell(dir.path()), aspect);
        assert_looks_in(&all, taken, lo);
    }
}

/// The same through a doorway in a front wall, seen from far (as a room modelled with the wall
/// around its opening, `diningRoom.obj` from a Maya scene): every view in front sees the
/// wall's face, so the hits alone scored the side view nearly as well as the views into the
/// room, and it was taken in a square pane.
#[test]
fn the_scene_view_first_looks_through_a_doorway_seen_from_far() {
    let (mut text, lo, hi) = cornell();
    let mut base = text.lines().filter(|l| l.starts_with("v ")).count();
    for (a, b) in [
        (Vec3::new(0.0, 0.0, -0.2), Vec3::new(1.5, 5.5, 0.0)),
        (Vec3::new(4.0, 0.0, -0.2), Vec3::new(5.5, 5.5, 0.0)),
        (Vec3::new(1.5, 4.2, -0.2), Vec3::new(4.0, 5.5, 0.0)),
    ] {
        cuboid(&mut text, &mut base, a, b, false, &[]);
    }
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("cornell.mtl"), CORNELL_MTL).expect("write");
    let mut scene = load(dir.path(), "doorway.obj", &text);
    let center = 0.5 * (lo + hi);
    scene.camera.position = Vec3::new(center.x, center.y, lo.z - 12.0);
    scene.camera.look_at = center;
    scene.camera.up = Vec3::Y;
    let front = Vec3::new(lo.x, lo.y, lo.z - 0.2);
    for aspect in PANES {
        let (all, taken) = scene_view_looks(scene.clone(), aspect);
        assert_looks_in(&all, taken, front);
    }
}

/// Where the preferred side sees the scene (Whitted's spheres on their floor) or the render
/// camera stands in a closed room (the cut-away opens it from there), the first look keeps it.
#[test]
fn the_scene_view_first_looks_from_beside_the_render_camera_where_that_sees() {
    let open = raytree::scene::load_builtin("default").expect("built-in");
    for aspect in PANES {
        let (all, taken) = scene_view_looks(open.clone(), aspect);
        assert_eq!(taken, 0);
        let best = all.iter().map(|c| c.sees).fold(0.0, f32::max);
        assert!(
            all[0].sees > 0.8 * best,
            "{} of the best {best}",
            all[0].sees
        );
    }
    let room = raytree::scene::load_builtin("box").expect("built-in");
    let (all, taken) = scene_view_looks(room.clone(), 4.0 / 3.0);
    assert!(encloses_render_camera(&room, all[0].camera.position));
    assert_eq!(taken, 0);
}

#[test]
fn a_room_with_a_hole_in_half_a_wall_is_seen_from_the_hole() {
    // A closed room whose +z wall is missing on its −x half (a hole, as in convector's
    // `suzannes_in_box.obj`), with a block in the middle. Framed from outside as an open box,
    // the picture was mostly the wall beside the hole.
    let (lo, hi) = (Vec3::new(-4.0, 0.0, -4.0), Vec3::new(4.0, 3.0, 4.0));
    let mut text = String::new();
    let mut base = 0;
    cuboid(&mut text, &mut base, lo, hi, true, &[5]);
    // The +z wall's +x half, facing in (towards −z).
    text += "v 0 0 4\nv 4 0 4\nv 4 3 4\nv 0 3 4\n";
    let b = base;
    text += &format!(
        "f {} {} {}\nf {} {} {}\n",
        b + 1,
        b + 3,
        b + 2,
        b + 1,
        b + 4,
        b + 3
    );
    base += 4;
    cuboid(
        &mut text,
        &mut base,
        Vec3::new(-0.7, 0.0, -0.7),
        Vec3::new(0.7, 1.2, 0.7),
        false,
        &[],
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = load(dir.path(), "holed.obj", &text);
    assert_warned(&scene, "holed.obj", &["opening", "stands in it"]);
    let eye = scene.camera.position;
    assert!(
        eye.z < hi.z && eye.z > hi.z - 0.5 && eye.x > -4.0 && eye.x < 0.0,
        "camera at {eye}, not in the hole (x in −4..0, just inside z = 4)"
    );
    // Inside the bounds, so the scene view seen from outside cuts the walls away.
    assert!(
        encloses_render_camera(&scene, Vec3::new(0.0, 10.0, 20.0)),
        "camera at {eye}: the cut-away would not engage"
    );
    assert!(
        eye.y > 0.0 && eye.y < 3.0,
        "camera at {eye}, above or below the hole"
    );
    assert!(forward(&scene).z < -0.7, "looks in: {}", forward(&scene));
    // Most of the picture is the room (its back wall, the floor, the block), not the outside.
    let image = pixels(&scene);
    let lit = image.iter().filter(|c| c.max_element() > 0.02).count();
    assert!(
        lit * 10 >= image.len() * 9,
        "{lit} of {} pixels show the room",
        image.len()
    );
    assert_readable(&scene, "holed.obj", 0.15..0.75, 0.01);
}

/// An octagonal prism around the `up` axis (a corner, not a face, towards the other
/// horizontal axes' minimum, as a scanned bust's round sides), from height `h0` to `h1`.
fn prism(out: &mut String, base: &mut usize, radius: f32, h0: f32, h1: f32, z_up: bool) {
    let at = |a: f32, r: f32, h: f32| {
        let (x, s) = (r * a.cos(), r * a.sin());
        if z_up {
            format!("v {x} {s} {h}\n")
        } else {
            format!("v {x} {h} {s}\n")
        }
    };
    for h in [h0, h1] {
        for k in 0..8 {
            let a = (k as f32 * 45.0 - 90.0).to_radians();
            *out += &at(a, radius, h);
        }
    }
    let v = |i: usize| *base + 1 + i;
    // Counter-clockwise seen from outside when z is up; a y-up copy mirrors, so flip.
    let tri = |out: &mut String, a: usize, b: usize, c: usize| {
        if z_up {
            *out += &format!("f {a} {b} {c}\n");
        } else {
            *out += &format!("f {a} {c} {b}\n");
        }
    };
    for k in 0..8 {
        let n = (k + 1) % 8;
        tri(out, v(k), v(n), v(8 + n));
        tri(out, v(k), v(8 + n), v(8 + k));
    }
    for k in 1..7 {
        tri(out, v(0), v(k + 1), v(k));
        tri(out, v(8), v(8 + k), v(8 + k + 1));
    }
    *base += 16;
}

#[test]
fn a_bust_standing_on_z_is_seen_upright_and_a_y_up_one_keeps_y() {
    let dir = tempfile::tempdir().expect("temp dir");
    for z_up in [true, false] {
        let mut text = String::new();
        let mut base = 0;
        prism(&mut text, &mut base, 1.0, 0.0, 0.6, z_up);
        prism(&mut text, &mut base, 0.6, 0.6, 3.0, z_up);
        let name = if z_up { "bust_z.obj" } else { "bust_y.obj" };
        let scene = load(dir.path(), name, &text);
        let up = if z_up { Vec3::Z } else { Vec3::Y };
        assert_eq!(scene.camera.up, up, "{name}");
        let said = scene
            .warnings
            .iter()
            .any(|w| w.contains("+z is taken as up"));
        assert_eq!(said, z_up, "{name}: {:?}", scene.warnings);
        // Seen from the side (a little above), not from the top or the bottom.
        assert!(
            forward(&scene).dot(up).abs() < 0.5,
            "{name}: {}",
            forward(&scene)
        );
        assert_readable(&scene, name, 0.03..0.6, 0.02);
    }
}

#[test]
fn meshlab_tr_1_is_opaque_and_ns_0_no_wash_of_specular() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mtl = "newmtl material_0\nKa 0.2 0.2 0.2\nKd 1 1 1\nKs 1 1 1\nTr 1.000000\nillum 2\nNs 0\n\nnewmtl glass\nKd 1 1 1\nKs 1 1 1\nTr 1.000000\nillum 4\n";
    std::fs::write(dir.path().join("bottle.mtl"), mtl).expect("write");
    let text = "mtllib bottle.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 2 1 0\nusemtl material_0\nf 1 2 3\nusemtl glass\nf 4 5 6\n";
    let scene = load(dir.path(), "bottle.obj", text);
    let m = |n: &str| material(&scene, n);
    assert_eq!(m("/material_0").transparency, Vec3::ZERO);
    // Its `Ns 0` (exponent 0: all of `Ks` wherever light falls) shows no highlight.
    assert_eq!(m("/material_0").specular, Vec3::ZERO);
    assert_eq!(m("/glass").specular, Vec3::ONE, "no `Ns`: kept");
    assert_warned(&scene, "bottle.obj", &["`material_0` has `Ns 0`"]);
    assert_eq!(m("/glass").transparency, Vec3::ONE, "glass keeps `Tr 1`");
    assert_warned(&scene, "bottle.obj", &["`Tr 1`", "material_0"]);
}

/// The same MTL through a scene file's `[[mesh]]`: `Ns 0` shows no highlight there too (it
/// used to be read only for a bare OBJ), with the same warning, and a mirror (`illum 3`) with
/// `Ns 0` keeps its reflectivity.
#[test]
fn ns_0_shows_no_highlight_through_a_scene_file_too() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mtl = "newmtl material_0\nKd 1 1 1\nKs 1 1 1\nillum 2\nNs 0\n\nnewmtl chrome\nKd 0 0 0\nKs 0.9 0.9 0.9\nillum 3\nNs 0\n\nnewmtl shiny\nKd 1 1 1\nKs 1 1 1\nNs 50\n";
    std::fs::write(dir.path().join("bottle.mtl"), mtl).expect("write");
    let obj = "mtllib bottle.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl material_0\nf 1 2 3\nusemtl chrome\nf 1 2 3\nusemtl shiny\nf 1 2 3\n";
    std::fs::write(dir.path().join("bottle.obj"), obj).expect("write");
    let toml = "[camera]\nposition = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\n\n[[light]]\nposition = [0.0, 2.0, 5.0]\n\n[[mesh]]\nfile = \"bottle.obj\"\n";
    let scene = load(dir.path(), "bottle.toml", toml);
    let m = |n: &str| material(&scene, n);
    assert_eq!(m("material_0").specular, Vec3::ZERO);
    assert_eq!(m("chrome").specular, Vec3::ZERO, "no highlight");
    assert_eq!(m("chrome").reflectivity, Vec3::splat(0.9), "still a mirror");
    assert_eq!(m("shiny").specular, Vec3::ONE, "`Ns 50`: kept");
    // One sentence for both.
    assert_warned(
        &scene,
        "bottle.toml",
        &["materials `material_0` and `chrome` have `Ns 0`"],
    );
    assert_not_warned(&scene, "bottle.toml", "`shiny`");
}

/// A Blender export whose material is black in every colour (`Kd 0`, `Ka 0`, a bump map only)
/// was invisible on the dark background: it is shown grey, with a note, and so is one a little
/// see-through (Blender 2.7's `d 0.75`); a black material that is a mirror, or glass (more
/// transparent than opaque), is left alone.
#[test]
fn a_black_material_of_a_bare_obj_is_shown_grey() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mtl = "newmtl body\nKa 0 0 0\nKd 0 0 0\nKs 0.5 0.5 0.5\nNs 100\nmap_Bump bump.png\nillum 2\n\nnewmtl chrome\nKa 0 0 0\nKd 0 0 0\nKs 0.9 0.9 0.9\nillum 3\n\nnewmtl visor\nKa 0 0 0\nKd 0 0 0\nKs 0 0 0\nd 0.75\n\nnewmtl pane\nKa 0 0 0\nKd 0 0 0\nKs 0 0 0\nd 0.1\n";
    std::fs::write(dir.path().join("statue.mtl"), mtl).expect("write");
    let mut text = String::from("mtllib statue.mtl\nusemtl body\n");
    let mut base = 0;
    cuboid(
        &mut text,
        &mut base,
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 2.0, 1.0),
        false,
        &[],
    );
    text.push_str("usemtl chrome\nv 3 0 0\nv 4 0 0\nv 3 1 0\nf -3 -2 -1\n");
    text.push_str("usemtl visor\nv -3 0 0\nv -4 0 0\nv -3 1 0\nf -3 -1 -2\n");
    text.push_str("usemtl pane\nv -3 1 0\nv -4 1 0\nv -3 2 0\nf -3 -1 -2\n");
    let scene = load(dir.path(), "statue.obj", &text);
    let m = |n: &str| material(&scene, n);
    assert_ne!(
        m("/visor").diffuse,
        Vec3::ZERO,
        "a little see-through: grey"
    );
    assert_eq!(m("/pane").diffuse, Vec3::ZERO, "glass stays as it is");
    assert_ne!(m("/body").diffuse, Vec3::ZERO, "shown grey");
    assert_eq!(m("/body").diffuse, m("/body").ambient);
    assert_eq!(
        m("/chrome").diffuse,
        Vec3::ZERO,
        "a black mirror stays black"
    );
    assert_warned(
        &scene,
        "statue.obj",
        &["materials `body` and `visor` are black"],
    );
    assert_not_warned(&scene, "statue.obj", "`chrome`");
    assert_not_warned(&scene, "statue.obj", "`pane`");
    assert_readable(&scene, "statue.obj", 0.03..0.6, 0.02);
}

/// A long low box (a kitchen counter), 10 × 1 × 2, as a bare OBJ.
fn counter(dir: &Path) -> Scene {
    let mut text = String::new();
    let mut base = 0;
    cuboid(
        &mut text,
        &mut base,
        Vec3::new(-5.0, 0.0, -1.0),
        Vec3::new(5.0, 1.0, 1.0),
        false,
        &[],
    );
    load(dir, "counter.obj", &text)
}

#[test]
fn a_wide_model_fills_the_frame_and_nothing_is_cut_off() {
    // A long low model (a kitchen counter, a car): framing its bounding sphere left it a
    // third of the image wide.
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = counter(dir.path());
    let image = pixels(&scene);
    let (w, h) = (160usize, 120usize);
    let lit = |x: usize, y: usize| image[y * w + x].max_element() > 0.0;
    let columns: Vec<usize> = (0..w).filter(|&x| (0..h).any(|y| lit(x, y))).collect();
    let (first, last) = (columns[0], columns[columns.len() - 1]);
    let span = (last - first + 1) as f32 / w as f32;
    assert!(span > 0.75, "the model spans {span} of the width");
    assert!(
        first > 0 && last < w - 1,
        "cut off: columns {first}..={last}"
    );
    let rows: Vec<usize> = (0..h).filter(|&y| (0..w).any(|x| lit(x, y))).collect();
    assert!(
        rows[0] > 0 && rows[rows.len() - 1] < h - 1,
        "cut off at the top or bottom"
    );
}

/// A Blender export with many materials (a city of 40, say) names them in one short sentence:
/// "all N materials" when every one had `Ka 1`, five names and a count when most did.
#[test]
fn many_blender_materials_make_one_short_warning() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut obj = String::from("mtllib city.mtl\n");
    let mut base = 0;
    for i in 0..12 {
        obj += &format!("usemtl m{i}\n");
        let x = 2.0 * i as f32;
        cuboid(
            &mut obj,
            &mut base,
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(x + 1.0, 1.0 + i as f32, 1.0),
            false,
            &[],
        );
    }
    let blender = |i: usize, ka: f32| {
        format!(
            "newmtl m{i}\nKa {ka} {ka} {ka}\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\nNs 225\nillum 2\n\n"
        )
    };
    for (name, plain) in [("all.obj", None), ("most.obj", Some(3))] {
        let mtl: String = (0..12)
            .map(|i| blender(i, if Some(i) == plain { 0.0 } else { 1.0 }))
            .collect();
        std::fs::write(dir.path().join("city.mtl"), mtl).expect("write");
        let scene = load(dir.path(), name, &obj);
        let warning = scene
            .warnings
            .iter()
            .find(|w| w.contains("`Ka 1`"))
            .unwrap_or_else(|| panic!("{name}: no `Ka 1` warning in {:?}", scene.warnings));
        let expected = if plain.is_none() {
            "`Ka 1` (Blender's default) in all 12 materials taken as"
        } else {
            "`Ka 1` (Blender's default) in `m0`, `m1`, `m2`, `m4`, `m5` and 6 more taken as"
        };
        assert!(warning.contains(expected), "{name}: {warning}");
        assert_eq!(
            material(&scene, "/m11").ambient,
            material(&scene, "/m11").diffuse,
            "{name}: the last material is washed too"
        );
    }
}

/// A twelve-pointed star of `2 * 12` corners as one face, in the plane `axis` = 0.5 (the
/// other two coordinates from `plane`), wound as written or reversed.
fn flat_star(axis: usize, reversed: bool) -> String {
    let mut obj = String::new();
    let n = 24;
    for i in 0..n {
        let a = i as f32 / n as f32 * std::f32::consts::TAU;
        let r = if i % 2 == 0 { 1.0 } else { 0.5 };
        let (u, v) = (r * a.cos(), r * a.sin());
        let p = match axis {
            0 => Vec3::new(0.5, u + 2.0, v),
            _ => Vec3::new(u, 0.5, v),
        };
        obj.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    let mut corners: Vec<String> = (1..=n).map(|i| i.to_string()).collect();
    if reversed {
        corners.reverse();
    }
    obj.push_str(&format!("f {}\n", corners.join(" ")));
    obj
}

/// How much of the image shows the model (pixels brighter than the black background).
fn covered(scene: &Scene) -> f32 {
    let image = pixels(scene);
    image.iter().filter(|c| c.max_element() > 0.02).count() as f32 / image.len() as f32
}

#[test]
fn a_flat_model_is_seen_square_to_its_plane_not_edge_on() {
    let dir = tempfile::tempdir().expect("temp dir");
    // Upright in x = 0.5 (a LightWave polygon as assimp's test files have it): from the +z
    // front it was edge-on and the image black. Looked at from the side its faces face.
    for (reversed, toward) in [(false, -1.0), (true, 1.0)] {
        let scene = load(dir.path(), "upright.obj", &flat_star(0, reversed));
        let f = forward(&scene);
        assert!(
            f.x * toward > 0.9,
            "reversed {reversed}: looks along {f}, not square to the plane facing the faces"
        );
        let c = covered(&scene);
        assert!(
            c > 0.15,
            "reversed {reversed}: the star covers {c} of the image"
        );
    }
    // Lying in y = 0.5 (a floor plan): from above at 45°, not at a grazing 17°.
    let scene = load(dir.path(), "lying.obj", &flat_star(1, false));
    let f = forward(&scene);
    assert!(f.y < -0.6, "looks along {f}");
    let c = covered(&scene);
    assert!(c > 0.15, "the star covers {c} of the image");
}

/// The star of [`flat_star`] in the plane through `center` square to `normal`, wound so that
/// its faces face `normal`.
fn slanted_star(center: Vec3, normal: Vec3) -> String {
    let n = normal.normalize();
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let mut obj = String::new();
    for i in 0..24 {
        let a = i as f32 / 24.0 * std::f32::consts::TAU;
        let r = if i % 2 == 0 { 1.0 } else { 0.5 };
        let p = center + u * (r * a.cos()) + v * (r * a.sin());
        obj.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    let corners: Vec<String> = (1..=24).map(|i| i.to_string()).collect();
    obj.push_str(&format!("f {}\n", corners.join(" ")));
    obj
}

#[test]
fn a_flat_model_in_a_slanted_plane_is_seen_square_to_it() {
    // Flat, but along no axis, so its bounds are not thin: seen from the +z front it was
    // almost edge-on, a sliver across a black image.
    let dir = tempfile::tempdir().expect("temp dir");
    for normal in [
        Vec3::new(-1.0, -0.25, -0.1),
        Vec3::new(1.0, 0.3, 0.2),
        Vec3::new(0.9, 0.1, -0.3),
    ] {
        let scene = load(
            dir.path(),
            "slanted.obj",
            &slanted_star(Vec3::new(3.0, 1.0, -2.0), normal),
        );
        let f = forward(&scene);
        let square = -f.dot(normal.normalize());
        assert!(
            square > 0.9,
            "normal {normal}: looks along {f}, {square} of square to the faces' side"
        );
        let c = covered(&scene);
        assert!(
            c > 0.15,
            "normal {normal}: the star covers {c} of the image"
        );
    }
    // One long slanted triangle, as a reader's test file has it.
    let triangle = "v 1.864151 -1.219172 -5.532511\nv 0.575869 -0.666304 5.896140\n\
        v 0.940448 1.000000 -1.971128\nf 1 2 3\n";
    let scene = load(dir.path(), "triangle.obj", triangle);
    let c = covered(&scene);
    assert!(
        c > 0.07,
        "the triangle covers {c} of the image (seen from +z: 0.02)"
    );
    // A flat model seen well from the front keeps the front view, whichever way it faces.
    let scene = load(
        dir.path(),
        "front.obj",
        &slanted_star(Vec3::ZERO, Vec3::new(0.3, 0.0, -1.0)),
    );
    let f = forward(&scene);
    assert!(f.z < -0.9, "looks along {f}");
}

#[test]
fn a_bare_obj_rendered_at_another_size_is_framed_for_that_size() {
    // `raytree render counter.obj --width 320 --height 100`: framed for the 640×480 it loaded
    // with, the model filled under half the width; framed again for 320×100 it fills it, and
    // nothing is cut off.
    let dir = tempfile::tempdir().expect("temp dir");
    let mut scene = counter(dir.path());
    let (w, h) = (320usize, 100usize);
    scene.render.width = w as u32;
    scene.render.height = h as u32;
    let span = |scene: &Scene| {
        let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
        let image = render(&tracer, 1, 0, &|_, _| {}).expect("renders").0.pixels;
        let lit = |x: usize, y: usize| image[y * w + x].max_element() > 0.0;
        let columns: Vec<usize> = (0..w).filter(|&x| (0..h).any(|y| lit(x, y))).collect();
        let rows: Vec<usize> = (0..h).filter(|&y| (0..w).any(|x| lit(x, y))).collect();
        let cut = columns[0] == 0
            || columns[columns.len() - 1] == w - 1
            || rows[0] == 0
            || rows[rows.len() - 1] == h - 1;
        ((columns.len()) as f32 / w as f32, cut)
    };
    let (before, _) = span(&scene);
    let forward_before = forward(&scene);
    raytree::scene::first_look::refit_bare_obj(&mut scene);
    let (after, cut) = span(&scene);
    eprintln!("span {before} -> {after}");
    assert!(
        after > 0.75,
        "spans {after} of the width (before: {before})"
    );
    assert!(!cut, "cut off");
    assert!(
        forward(&scene).distance(forward_before) < 1e-5,
        "the same direction"
    );
}

/// A closed UV sphere of radius 1 about `(0, 1, 0)` (`rings` × `segments` quads, split in two),
/// counter-clockwise seen from outside, without normals.
fn ball(rings: usize, segments: usize) -> String {
    let mut out = String::new();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            let (s, c) = theta.sin_cos();
            out += &format!("v {} {} {}\n", s * phi.cos(), 1.0 + c, -s * phi.sin());
        }
    }
    let at = |i: usize, j: usize| i * segments + j % segments + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if i > 0 {
                out += &format!("f {a} {b} {d}\n");
            }
            if i + 1 < rings {
                out += &format!("f {b} {c} {d}\n");
            }
        }
    }
    out
}

/// `text` (positions and triangles `f a b c` only) with a `vn` per face, the normal its
/// winding gives, on each of its corners; with the corners listed the other way round when
/// `wind_back`, so the faces are wound clockwise seen from the side their normals face.
fn with_face_normals(text: &str, wind_back: bool) -> String {
    let mut points = Vec::new();
    let mut out = String::new();
    let mut faces = String::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first() {
            Some(&"v") => {
                let p: Vec<f32> = words[1..4].iter().map(|w| w.parse().expect("x")).collect();
                points.push(Vec3::new(p[0], p[1], p[2]));
                out += line;
                out += "\n";
            }
            Some(&"f") => {
                let i: Vec<usize> = words[1..4].iter().map(|w| w.parse().expect("i")).collect();
                let [a, b, c] = [i[0], i[1], i[2]].map(|i| points[i - 1]);
                let n = (b - a).cross(c - a).normalize();
                out += &format!("vn {} {} {}\n", n.x, n.y, n.z);
                let k = out.matches("vn ").count();
                let order = if wind_back {
                    [i[0], i[2], i[1]]
                } else {
                    [i[0], i[1], i[2]]
                };
                faces += &format!("f {}//{k} {}//{k} {}//{k}\n", order[0], order[1], order[2]);
            }
            _ => {}
        }
    }
    out + &faces
}

/// The two balls get the same first look and render alike.
fn assert_same_look(right: &Scene, back: &Scene) {
    assert!(
        back.camera.position.distance(right.camera.position) < 1e-4,
        "the same first look: {:?} against {:?}",
        back.camera,
        right.camera
    );
    let (a, b) = (pixels(right), pixels(back));
    let differ = a
        .iter()
        .zip(&b)
        .filter(|(x, y)| (**x - **y).abs().max_element() > 1e-3);
    assert!(
        differ.count() * 1000 < a.len(),
        "the two balls render alike"
    );
}

#[test]
fn a_model_wound_against_its_normals_opens_as_the_normals_say() {
    // Wound clockwise with outward normals (a file converted from left-handed axes by
    // negating z): the same ball as wound right, seen from outside and lit, not a dark room.
    let dir = tempfile::tempdir().expect("temp dir");
    let right = load(
        dir.path(),
        "ball.obj",
        &with_face_normals(&ball(12, 24), false),
    );
    let back = load(
        dir.path(),
        "ball_cw.obj",
        &with_face_normals(&ball(12, 24), true),
    );
    assert_not_warned(&right, "ball.obj", "wound clockwise");
    assert_warned(
        &back,
        "ball_cw.obj",
        &["its faces are wound clockwise", "`vn`"],
    );
    assert!(!inside(back.camera.position, &back), "outside the ball");
    assert_same_look(&right, &back);
    assert_readable(&back, "ball_cw.obj", 0.03..0.6, 0.1);
    // Wound outwards with inward normals (a furnace test's box, made to be seen from inside):
    // a room, so the camera starts inside it and the walls are lit.
    let mut room = String::new();
    let hi = Vec3::new(3.0, 4.0, 4.0);
    cuboid(&mut room, &mut 0, -hi.with_y(0.0), hi, true, &[]);
    let furnace = load(dir.path(), "furnace.obj", &with_face_normals(&room, true));
    assert_warned(&furnace, "furnace.obj", &["its faces are wound clockwise"]);
    assert!(inside(furnace.camera.position, &furnace), "inside the box");
    assert_readable(&furnace, "furnace.obj", 0.1..0.9, 0.1);
}

#[test]
fn a_thing_wound_inside_out_without_normals_is_seen_from_outside() {
    // Wound clockwise seen from outside and no `vn`: from its middle every face faces the
    // point, as a room's walls do, but nothing of it lies on its bounds as walls do. The same
    // first look as the ball wound right, and the same image.
    let dir = tempfile::tempdir().expect("temp dir");
    let text = ball(12, 24);
    let turned: String = text
        .lines()
        .map(
            |line| match line.split_whitespace().collect::<Vec<_>>()[..] {
                ["f", a, b, c] => format!("f {a} {c} {b}\n"),
                _ => format!("{line}\n"),
            },
        )
        .collect();
    let right = load(dir.path(), "ball.obj", &text);
    let back = load(dir.path(), "ball_cw.obj", &turned);
    assert_not_warned(&right, "ball.obj", "wound clockwise");
    assert_warned(
        &back,
        "ball_cw.obj",
        &[
            "wound clockwise seen from outside",
            "no `vn`",
            "seen from outside",
        ],
    );
    assert_not_warned(&back, "ball_cw.obj", "(a room)");
    assert_same_look(&right, &back);
    // With `vn` facing inwards as its winding does (a furnace test's sphere, made to be seen
    // from inside), the file says which side is the front: it is still read as walls round
    // its middle.
    let furnace = load(dir.path(), "sphere.obj", &with_face_normals(&turned, false));
    assert_not_warned(&furnace, "sphere.obj", "wound clockwise");
    assert_warned(&furnace, "sphere.obj", &["walls around its middle"]);
    // A room without `vn` faces inwards too, its walls, floor and ceiling on its bounds: it
    // stays a room.
    let room = load(dir.path(), "room.obj", &room(false));
    assert!(inside(room.camera.position, &room), "the room: outside");
    assert_not_warned(&room, "room.obj", "wound clockwise");
    // So does a store room whose stacks of boxes along two walls have five times the area of
    // its walls, floor and ceiling: those cover its bounds all the same.
    let mut store = String::new();
    let mut base = 0;
    let hi = Vec3::new(3.0, 4.0, 4.0);
    cuboid(&mut store, &mut base, -hi.with_y(0.0), hi, true, &[]);
    for x in [-2.9f32, -2.45, -2.0, 1.6, 2.05, 2.5] {
        for i in 0..22 {
            for j in 0..12 {
                let lo = Vec3::new(x, 0.32 * j as f32, -3.9 + 0.35 * i as f32);
                let size = Vec3::new(0.4, 0.3, 0.3);
                cuboid(&mut store, &mut base, lo, lo + size, false, &[]);
            }
        }
    }
    let store = load(dir.path(), "store.obj", &store);
    assert!(
        inside(store.camera.position, &store),
        "the store room: outside"
    );
    assert_warned(&store, "store.obj", &["(a room)"]);
    assert_not_warned(&store, "store.obj", "wound clockwise");
}

/// A pipe of `segments` sides with walls of radius `inner` and `outer`, `length` long along
/// `axis` (0 x, 1 y, 2 z) from the origin: a closed solid, wound outwards.
fn pipe(axis: usize, inner: f32, outer: f32, length: f32, segments: usize) -> String {
    let place = |r: f32, a: f32, t: f32| {
        let (u, v) = (r * a.cos(), r * a.sin());
        let p = match axis {
            0 => Vec3::new(t, u, v),
            1 => Vec3::new(v, t, u),
            _ => Vec3::new(u, v, t),
        };
        format!("v {} {} {}\n", p.x, p.y, p.z)
    };
    let mut obj = String::new();
    // Per segment, four vertices per end: outer and inner at t = 0, then at t = length.
    for k in 0..segments {
        let a = k as f32 / segments as f32 * std::f32::consts::TAU;
        for t in [0.0, length] {
            obj.push_str(&place(outer, a, t));
            obj.push_str(&place(inner, a, t));
        }
    }
    let at = |k: usize, i: usize| 4 * (k % segments) + i + 1;
    for k in 0..segments {
        let (o0, i0, o1, i1) = (at(k, 0), at(k, 1), at(k, 2), at(k, 3));
        let (p0, j0, p1, j1) = (at(k + 1, 0), at(k + 1, 1), at(k + 1, 2), at(k + 1, 3));
        obj.push_str(&format!("f {o0} {p0} {p1} {o1}\n")); // outer wall
        obj.push_str(&format!("f {i0} {i1} {j1} {j0}\n")); // inner wall
        obj.push_str(&format!("f {o0} {i0} {j0} {p0}\n")); // the ring at t = 0
        obj.push_str(&format!("f {o1} {p1} {j1} {i1}\n")); // the ring at t = length
    }
    obj
}

#[test]
fn a_pipe_is_seen_from_outside_not_from_inside_its_hole() {
    // Its hole's walls face the middle as a room's walls do; from inside, the first look showed
    // one grey wall filling the image.
    let dir = tempfile::tempdir().expect("temp dir");
    for axis in 0..3 {
        let name = format!("pipe{axis}.obj");
        let scene = load(dir.path(), &name, &pipe(axis, 0.68, 0.83, 12.0, 32));
        assert!(
            !inside(scene.camera.position, &scene),
            "{name}: the camera stands inside, at {}",
            scene.camera.position
        );
        assert!(
            !scene.warnings.iter().any(|w| w.contains("a room")),
            "{name}: {:?}",
            scene.warnings
        );
        let c = covered(&scene);
        assert!(
            c > 0.05 && c < 0.9,
            "{name}: the pipe covers {c} of the image"
        );
    }
    // A short, wide ring (a washer, a bushing) is seen from outside as before; a room open at
    // both ends, 10 long and 3 high, is still a room (a tube would be under 2.5 across).
    let scene = load(dir.path(), "ring.obj", &pipe(0, 0.5, 1.0, 0.5, 32));
    assert!(!inside(scene.camera.position, &scene), "ring: inside");
    let mut hall = String::new();
    let (lo, hi) = (Vec3::new(-2.0, 0.0, -5.0), Vec3::new(2.0, 3.0, 5.0));
    cuboid(&mut hall, &mut 0, lo, hi, true, &[4, 5]);
    let scene = load(dir.path(), "hall.obj", &hall);
    assert_warned(
        &scene,
        "hall.obj",
        &["open on one side", "seen level through the opening"],
    );
}

#[test]
fn a_shell_open_below_is_seen_from_outside_and_a_tray_from_above_with_z_up() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A toy brick: walls and a top around a hollow, open at the bottom. From inside its walls
    // face the middle as a room's do, but nothing is underfoot.
    let mut brick = String::new();
    let mut base = 0;
    let (lo, hi) = (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 1.2, 1.0));
    cuboid(&mut brick, &mut base, lo, hi, false, &[2]);
    let hollow = (Vec3::new(-0.9, 0.0, -0.9), Vec3::new(0.9, 1.1, 0.9));
    cuboid(&mut brick, &mut base, hollow.0, hollow.1, true, &[2]);
    let scene = load(dir.path(), "brick.obj", &brick);
    let p = scene.camera.position;
    assert!(
        !inside(p, &scene),
        "brick: the camera stands inside, at {p}"
    );
    assert_not_warned(&scene, "brick.obj", "(a room)");
    let c = covered(&scene);
    assert!(c > 0.05 && c < 0.9, "brick: it covers {c} of the image");
    // With a floor under the same walls it is a room, seen from inside.
    let mut room = brick.clone();
    cuboid(
        &mut room,
        &mut base,
        Vec3::new(-0.9, 0.0, -0.9),
        Vec3::new(0.9, 0.02, 0.9),
        false,
        &[],
    );
    let scene = load(dir.path(), "floored.obj", &room);
    assert!(inside(scene.camera.position, &scene), "floored: outside");
    assert_warned(&scene, "floored.obj", &["(a room)"]);

    // A tray written z-up (robotics and CAD files are): a base, walls 0.7 high around it, and
    // a shelf over a fifth of it. Open above once z is up, as the shelf aside most of the sky
    // from inside is: seen from above, outside, z up.
    let mut tray = String::new();
    let mut base = 0;
    let mut part = |lo: [f32; 3], hi: [f32; 3]| {
        cuboid(
            &mut tray,
            &mut base,
            Vec3::from(lo),
            Vec3::from(hi),
            false,
            &[],
        );
    };
    part([-1.0, -1.0, 0.0], [1.0, 1.0, 0.02]);
    part([-1.0, -1.0, 0.0], [-0.95, 1.0, 0.7]);
    part([0.95, -1.0, 0.0], [1.0, 1.0, 0.7]);
    part([-1.0, -1.0, 0.0], [1.0, -0.95, 0.7]);
    part([-1.0, 0.95, 0.0], [1.0, 1.0, 0.7]);
    part([-1.0, -1.0, 0.68], [-0.4, 1.0, 0.7]);
    let scene = load(dir.path(), "tray.obj", &tray);
    assert_eq!(scene.camera.up, Vec3::Z, "tray: {:?}", scene.warnings);
    let (p, (_, hi)) = (scene.camera.position, scene.bounds().expect("bounds"));
    assert!(!inside(p, &scene) && p.z > hi.z, "tray: camera at {p}");
    assert!(forward(&scene).z < -0.3, "tray: looks down into it");
    assert_warned(
        &scene,
        "tray.obj",
        &["open towards +z (a tray, a box without a lid): +z is taken as up"],
    );
    assert_not_warned(&scene, "tray.obj", "(a room)");
}

/// The torus of assets/models without its material, as OBJ text, and how many vertices it has.
fn bare_torus() -> (String, usize) {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/models/torus.obj"),
    )
    .expect("torus.obj");
    let kept: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with("mtllib") && !l.starts_with("usemtl"))
        .collect();
    let vertices = kept.iter().filter(|l| l.starts_with("v ")).count();
    (kept.join("\n") + "\n", vertices)
}

/// The share of a 64 × 48 grid over the scene's image whose rays first meet the torus of
/// [`bare_torus`] (major radius 1, tube 0.35, about the origin in y = 0).
fn torus_share(scene: &Scene) -> f32 {
    let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
    let (w, h) = (scene.render.width, scene.render.height);
    let frame = raytree::scene::CameraFrame::new(&scene.camera, w, h);
    let (gx, gy) = (64, 48);
    let mut on = 0;
    for j in 0..gy {
        for i in 0..gx {
            let x = (i as f32 + 0.5) * w as f32 / gx as f32;
            let y = (j as f32 + 0.5) * h as f32 / gy as f32;
            let ray = frame.ray(x, y);
            if let Some(t) = tracer.first_hit_t(&ray) {
                let p = ray.origin + ray.dir * t;
                let ring = (Vec3::new(p.x, 0.0, p.z).length() - 1.0).hypot(p.y);
                on += usize::from(ring < 0.36);
            }
        }
    }
    on as f32 / (gx * gy) as f32
}

/// A model on a ground plane hundreds of times its size (as a Blender scene with a large plane
/// under it is exported): framing the bounds made the model a speck on the plane.
#[test]
fn a_model_on_a_ground_plane_far_larger_than_it_is_framed_on_the_model() {
    let (mut text, n) = bare_torus();
    text += "v -500 -0.35 -500\nv 500 -0.35 -500\nv 500 -0.35 500\nv -500 -0.35 500\n";
    text += &format!("f {} {} {} {}\n", n + 1, n + 4, n + 3, n + 2);
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = load(dir.path(), "on_plane.obj", &text);
    assert_warned(&scene, "on_plane.obj", &["small part of its bounds"]);
    let share = torus_share(&scene);
    assert!(share > 0.25, "the torus covers {share} of the image");
    // A model alone is framed on its bounds, as before, and fills as much.
    let alone = load(dir.path(), "alone.obj", &bare_torus().0);
    assert_not_warned(&alone, "alone.obj", "small part of its bounds");
    let alone_share = torus_share(&alone);
    assert!(
        share > 0.8 * alone_share,
        "on the plane {share}, alone {alone_share}"
    );
}

/// A model inside a tunnel a hundred times its length, open at both ends (a train in a subway
/// scene): framed on the model from outside, the camera would see the tunnel's wall; it stands
/// inside the tunnel and sees the model end on.
#[test]
fn a_model_in_a_long_tunnel_is_seen_from_inside_the_tunnel() {
    let (mut text, n) = bare_torus();
    let mut base = n;
    let (lo, hi) = (Vec3::new(-200.0, -0.35, -1.8), Vec3::new(200.0, 2.0, 1.8));
    cuboid(&mut text, &mut base, lo, hi, true, &[0, 1]);
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = load(dir.path(), "tunnel.obj", &text);
    assert_warned(
        &scene,
        "tunnel.obj",
        &["small part of its bounds", "from inside the rest"],
    );
    let eye = scene.camera.position;
    assert!(
        eye.y > lo.y && eye.y < hi.y && eye.z > lo.z && eye.z < hi.z,
        "the eye {eye} is outside the tunnel"
    );
    let share = torus_share(&scene);
    assert!(share > 0.1, "the torus covers {share} of the image");
    let key = scene.lights[0].position;
    assert!(key.y < hi.y, "the key light at {key} is above the tunnel");
    // The scene view frames the model and the render camera, not the tunnel, and draws its
    // stubs and normal ticks in proportion to the model.
    let extent = raytree::scene_view::extent(&scene);
    assert!(extent < 10.0, "the scene view's extent is {extent}");
    let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
    let view = overview(&tracer, 4.0 / 3.0, FOV_Y_DEG, Cutaway::Auto);
    assert!(
        view.position.length() < 20.0,
        "the scene view looks from {}",
        view.position
    );
}

/// A scene a fifth across seen from a million away: the points along the render camera's rays
/// are counted, where stepping by the scene's spacing, under half a step of f32 there, never
/// ended.
#[test]
fn the_scene_view_first_looks_at_a_tiny_scene_from_far_away() {
    let mut scene = raytree::scene::load_builtin("default").expect("built-in");
    scene.triangles = Arc::new(Vec::new());
    scene.spheres.truncate(1);
    scene.spheres[0].center = Vec3::ZERO;
    scene.spheres[0].radius = 0.1;
    scene.camera.position = Vec3::new(0.0, 0.0, 1e6);
    scene.camera.look_at = Vec3::ZERO;
    scene.camera.fov_y_deg = 2e-5;
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let all = candidates(&tracer, 4.0 / 3.0, FOV_Y_DEG);
    let best = all.iter().map(|c| c.sees).fold(0.0, f32::max);
    assert!(best > 0.0, "no direction sees the sphere: {all:?}");
}
