//! The headless scene view (`raytree tree --scene-view`): lines land where the view camera
//! projects them, hidden parts are dimmed, a golden picture of the default scene's glass sphere,
//! and the command's refusals.
//!
//! Regenerate the golden picture (after a deliberate change, looking at it first) with:
//! `RAYTREE_BLESS=1 cargo test --release --test scene_view golden`

use std::process::Command;
use std::sync::Arc;

mod golden_support;

use glam::Vec3;
use golden_support::{golden_path, mismatch, read_png};
use raytree::scene::{Camera, CameraFrame, Object, ObjectId, ObjectSource, Scene, Sphere};
use raytree::scene_view::cutaway::Cutaway;
use raytree::scene_view::occlusion::DepthImage;
use raytree::scene_view::overview::{FOV_Y_DEG, overview};
use raytree::scene_view::raster::{Canvas, line_width};
use raytree::scene_view::{Filter, Segment, Style, headless};
use raytree::trace::{RayKind, TraceSettings, Tracer};

fn raytree() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytree"))
}

fn segment(a: Vec3, b: Vec3) -> Segment {
    Segment {
        a,
        b,
        style: Style::Ray(RayKind::Primary),
        path: Vec::new(),
        generation: 0,
        end: None,
    }
}

/// A view of `scene` from an oblique camera: its frame and depth image at 200 × 150.
fn view(scene: Scene) -> (CameraFrame, DepthImage) {
    let camera = Camera {
        position: Vec3::new(3.0, 2.0, 6.0),
        look_at: Vec3::new(0.0, 0.5, 0.0),
        up: Vec3::Y,
        fov_y_deg: 50.0,
    };
    let frame = CameraFrame::new(&camera, 200, 150);
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let depth = DepthImage::of(&tracer, &frame, 200, 150);
    (frame, depth)
}

/// The pixels brighter than `level` (of the red channel), as image positions of their centres.
fn lit(canvas: &Canvas, level: u8) -> Vec<(f32, f32, u8)> {
    let w = canvas.width() as usize;
    canvas
        .rgba()
        .chunks(4)
        .enumerate()
        .filter(|(_, p)| p[0] > level)
        .map(|(i, p)| ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5, p[0]))
        .collect()
}

#[test]
fn a_segment_is_drawn_where_the_view_camera_projects_it() {
    let (frame, depth) = view(Scene::default());
    let mut canvas = Canvas::from_srgb8(200, 150, &[0; 200 * 150 * 3]).expect("canvas");
    let (a, b) = (Vec3::new(-1.5, 1.0, 0.5), Vec3::new(1.0, -0.5, -1.0));
    canvas.draw_segments(&frame, &depth, &[&segment(a, b)], None);
    let (pa, pb) = (
        glam::Vec2::from(frame.project(a).expect("in front")),
        glam::Vec2::from(frame.project(b).expect("in front")),
    );
    let pixels = lit(&canvas, 100);
    assert!(pixels.len() > 50, "{} pixels drawn", pixels.len());
    let width = line_width(150);
    // Every drawn pixel lies on the projected segment, within the line's half width and a
    // pixel of anti-aliasing.
    let reach = 0.5 * width + 1.0;
    for &(x, y, _) in &pixels {
        let p = glam::Vec2::new(x, y);
        let s = ((p - pa).dot(pb - pa) / (pb - pa).length_squared()).clamp(0.0, 1.0);
        let off = (p - (pa + (pb - pa) * s)).length();
        assert!(off <= reach, "pixel ({x}, {y}) is {off} px off the line");
    }
    // And both ends are reached: some drawn pixel is within the reach of each projected end.
    for end in [pa, pb] {
        let nearest = pixels
            .iter()
            .map(|&(x, y, _)| (glam::Vec2::new(x, y) - end).length())
            .fold(f32::INFINITY, f32::min);
        assert!(nearest <= reach, "nothing drawn within {reach} px of {end}");
    }
}

#[test]
fn a_highlighted_node_is_drawn_wider() {
    let (frame, depth) = view(Scene::default());
    let line = segment(Vec3::new(-1.5, 1.0, 0.5), Vec3::new(1.0, -0.5, -1.0));
    let drawn = |highlight: Option<&[usize]>| {
        let mut canvas = Canvas::from_srgb8(200, 150, &[0; 200 * 150 * 3]).expect("canvas");
        canvas.draw_segments(&frame, &depth, &[&line], highlight);
        lit(&canvas, 100).len()
    };
    let (plain, wide) = (drawn(None), drawn(Some(&[])));
    assert!(
        wide as f32 > 1.8 * plain as f32,
        "{plain} pixels, {wide} highlighted"
    );
    assert_eq!(drawn(Some(&[0])), plain, "another node's highlight");
}

#[test]
fn the_part_behind_a_sphere_is_drawn_dimmed_not_left_out() {
    let mut scene = Scene::default();
    let material = scene.default_material();
    scene.objects.push(Object {
        name: "ball".into(),
        source: ObjectSource::Sphere,
    });
    scene.spheres.push(Sphere {
        center: Vec3::new(0.0, 0.5, 0.0),
        radius: 1.0,
        material,
        object: ObjectId(0),
    });
    let (frame, depth) = view(scene);
    // Behind the ball as the view sees it: through its centre, across the view.
    let right = Vec3::new(6.0, 0.0, -3.0).normalize();
    let centre = Vec3::new(0.0, 0.5, 0.0) - Vec3::new(3.0, 1.5, 6.0).normalize() * 1.5;
    let (a, b) = (centre - right * 3.0, centre + right * 3.0);
    let mut canvas = Canvas::from_srgb8(200, 150, &[0; 200 * 150 * 3]).expect("canvas");
    canvas.draw_segments(&frame, &depth, &[&segment(a, b)], None);
    let (x, y) = frame.project(centre).expect("in front");
    let w = canvas.width() as usize;
    let at = |x: f32, y: f32| canvas.rgba()[(y as usize * w + x as usize) * 4];
    // The primary ray's grey is 235; a third of its opacity over black gives about 78.
    let behind = at(x, y);
    assert!((60..=100).contains(&behind), "behind the ball: {behind}");
    let (x, y) = frame.project(a).expect("in front");
    let (x2, y2) = frame.project(centre).expect("in front");
    // Past the ball's outline, a fifth of the way in from the end: full strength.
    let clear = at(x + (x2 - x) * 0.2, y + (y2 - y) * 0.2);
    assert!(clear > 200, "in the clear: {clear}");
}

/// A black ball (no ambient, diffuse or specular) against a black background: the headless
/// scene view draws its outline, a ring of dark grey at the ball's edge as the ball projects,
/// while its inside and the background stay black.
#[test]
fn a_black_ball_on_black_keeps_its_outline() {
    let mut scene = Scene::default();
    scene.render.background = Vec3::ZERO;
    let material = scene.default_material();
    let m = &mut scene.materials[material.0 as usize];
    (m.ambient, m.diffuse, m.specular) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    scene.objects.push(Object {
        name: "ball".into(),
        source: ObjectSource::Sphere,
    });
    let (center, radius) = (Vec3::new(0.0, 0.5, 0.0), 1.0);
    scene.spheres.push(Sphere {
        center,
        radius,
        material,
        object: ObjectId(0),
    });
    let camera = Camera {
        position: Vec3::new(0.0, 0.5, 6.0),
        look_at: center,
        up: Vec3::Y,
        fov_y_deg: 40.0,
    };
    let (w, h) = (200u32, 150u32);
    let canvas = headless::scene_view_image(
        &scene,
        TraceSettings::default(),
        &[],
        &camera,
        w,
        h,
        &Filter::default(),
        Cutaway::Off,
    )
    .expect("a picture");
    // The ball's outline in pixels: its angular radius asin(r / d) against the half field.
    let half = (20.0f32).to_radians().tan();
    let ring = (radius / 6.0f32).asin().tan() / half * h as f32 / 2.0;
    let (cx, cy) = (w as f32 / 2.0, h as f32 / 2.0);
    let mut grey = 0;
    for (i, p) in canvas.rgba().chunks(4).enumerate() {
        let (x, y) = ((i as u32 % w) as f32 + 0.5, (i as u32 / w) as f32 + 0.5);
        let r = ((x - cx).powi(2) + (y - cy).powi(2)).sqrt();
        if p[0] > 0 {
            grey += 1;
            assert!(p[0] == p[1] && p[1] == p[2], "grey at ({x}, {y}): {p:?}");
            // Linear 0.05 is about 63 in sRGB.
            assert!(
                (55..=70).contains(&p[0]),
                "outline level at ({x}, {y}): {p:?}"
            );
            assert!(
                (r - ring).abs() < 2.0,
                "lit at ({x}, {y}), {r} from the centre, the ring at {ring}"
            );
        }
    }
    // The ring is about one pixel wide all round.
    assert!(
        grey as f32 > 0.8 * std::f32::consts::TAU * ring
            && grey as f32 <= 2.5 * std::f32::consts::TAU * ring,
        "{grey} grey pixels for a ring of radius {ring}"
    );
}

/// The default scene's glass sphere seen from the right of the render camera, at 320 × 240:
/// pixel (125, 135) looks into the glass sphere, so its tree refracts through it; the picture
/// shows the frustum, the image plane with the pixel's cross, both lights and the tree.
/// Tolerance as the render goldens: a channel may differ by more than 2/255 on at most 0.5 %
/// of pixels (a libm's rounding can move a shadow edge or a hidden piece's end by a pixel), and
/// the mean difference stays below 0.25/255.
#[test]
fn golden_glass_sphere_from_the_side() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("view.png");
    let status = raytree()
        .args([
            "tree",
            "default",
            "--pixel",
            "125,135",
            "--width",
            "320",
            "--height",
            "240",
            "--scene-view",
        ])
        .arg(&out)
        .args([
            "--eye",
            "5,3.2,6.5",
            "--target",
            "-1.2,2,2.8",
            "--fov",
            "60",
        ])
        .stdout(std::process::Stdio::null())
        .status()
        .expect("runs");
    assert!(status.success());
    let path = golden_path("scene_view_glass.png");
    if std::env::var_os("RAYTREE_BLESS").is_some() {
        std::fs::copy(&out, &path).expect("write golden");
        return;
    }
    let regenerate = "RAYTREE_BLESS=1 cargo test --release --test scene_view golden";
    let (w, h, want) = read_png(&path, png::ColorType::Rgba, regenerate);
    let (gw, gh, got) = read_png(&out, png::ColorType::Rgba, regenerate);
    assert_eq!((gw, gh), (w, h), "size");
    if let Some(why) = mismatch(&got, &want, 4) {
        let new = path.with_extension("new.png");
        std::fs::copy(&out, &new).expect("write new");
        panic!("{why}; see {}; regenerate with {regenerate}", new.display());
    }
}

/// Runs `raytree tree default --pixel 10,10` with `args`; returns (exit code, stderr).
fn refused(args: &[&str]) -> (Option<i32>, String) {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = raytree()
        .args(["tree", "default", "--pixel", "10,10"])
        .args(args)
        .current_dir(dir.path())
        .output()
        .expect("runs");
    assert!(
        std::fs::read_dir(dir.path())
            .expect("list")
            .next()
            .is_none(),
        "nothing written"
    );
    assert!(out.stdout.is_empty(), "no tree printed when refused");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn the_command_refuses_a_view_without_a_frame_in_one_sentence() {
    let (code, err) = refused(&[
        "--scene-view",
        "v.png",
        "--eye",
        "1,2,3",
        "--target",
        "1,2,3",
    ]);
    assert_eq!(code, Some(1));
    assert_eq!(
        err.trim(),
        "error: the scene view's --target must be a point apart from --eye (at a distance f32 \
         can represent)"
    );
    let (code, err) = refused(&[
        "--scene-view",
        "v.png",
        "--eye=-1,2,3",
        "--target",
        "0,0,0",
        "--up",
        "-1,2,3",
    ]);
    assert_eq!(code, Some(1));
    assert!(err.contains("--up must not be parallel"), "{err}");
    let (code, err) = refused(&[
        "--scene-view",
        "v.svg",
        "--eye",
        "1,2,3",
        "--target",
        "0,0,0",
    ]);
    assert_eq!(code, Some(1));
    assert!(err.contains("must end in .png"), "{err}");
}

#[test]
fn the_command_wants_eye_and_target_together() {
    let (code, err) = refused(&["--scene-view", "v.png", "--target", "0,0,0"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--eye"), "{err}");
    let (code, err) = refused(&[
        "--scene-view",
        "v.png",
        "--eye",
        "1,2,x",
        "--target",
        "0,0,0",
    ]);
    assert_eq!(code, Some(2));
    assert!(err.contains("`x` is not a number"), "{err}");
}

/// Without --eye and --target the view is the viewer's first look: the same picture as from
/// the camera [`overview`] gives, named with the flags. --up and --fov are of a view given.
#[test]
fn without_an_eye_the_command_draws_the_viewers_first_look() {
    let scene = raytree::scene::load_builtin("default").expect("built-in");
    let (w, h) = (scene.render.width, scene.render.height);
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let first = overview(&tracer, w as f32 / h as f32, FOV_Y_DEG, Cutaway::Auto);
    let dir = tempfile::tempdir().expect("temp dir");
    let run = |name: &str, extra: &[String]| {
        let out = raytree()
            .args([
                "tree",
                "default",
                "--pixel",
                "250,270",
                "--scene-view",
                name,
            ])
            .args(extra)
            .current_dir(dir.path())
            .output()
            .expect("runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        read_png(&dir.path().join(name), png::ColorType::Rgba, "no golden")
    };
    let v3 = |v: Vec3| format!("{},{},{}", v.x, v.y, v.z);
    let own = run("first.png", &[]);
    let given = run(
        "given.png",
        &[
            format!("--eye={}", v3(first.position)),
            format!("--target={}", v3(first.look_at)),
            format!("--up={}", v3(first.up)),
            format!("--fov={}", first.fov_y_deg),
        ],
    );
    assert_eq!((own.0, own.1), (w, h));
    assert!(own == given, "the first look differs from its camera given");
    let (code, err) = refused(&["--scene-view", "v.png", "--up", "0,0,1"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--eye"), "{err}");
    let (code, err) = refused(&["--scene-view", "v.png", "--fov", "500"]);
    assert_eq!(code, Some(1));
    assert!(err.contains("--fov"), "{err}");
}

/// A closed room of twelve triangles (-2..2 on each axis, brown walls) around the render
/// camera, a sphere on the floor and a light under the ceiling, written into `dir`; returns the
/// scene file.
fn closed_room(dir: &std::path::Path) -> std::path::PathBuf {
    let corners: String = (0..8)
        .map(|k| {
            let c = |bit: usize| if k & bit == 0 { -2 } else { 2 };
            format!("v {} {} {}\n", c(1), c(2), c(4))
        })
        .collect();
    // Each side as four corners in order around it (1-based, bit 0 picks x, 1 y, 2 z).
    let sides = [
        [1, 3, 4, 2],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 5, 7, 3],
        [2, 4, 8, 6],
    ];
    let faces: String = sides
        .iter()
        .map(|s| {
            format!(
                "f {} {} {}\nf {} {} {}\n",
                s[0], s[1], s[2], s[0], s[2], s[3]
            )
        })
        .collect();
    std::fs::write(
        dir.join("room.obj"),
        format!("mtllib room.mtl\n{corners}usemtl brown\n{faces}"),
    )
    .expect("write the room");
    std::fs::write(
        dir.join("room.mtl"),
        "newmtl brown\nKa 0.6 0.35 0.15\nKd 0.6 0.35 0.15\nKs 0 0 0\n",
    )
    .expect("write its material");
    let scene = dir.join("room.toml");
    std::fs::write(
        &scene,
        r#"
[render]
width = 320
height = 240
max_depth = 3
samples = 1
background = 0
ambient_light = 0.1

[camera]
position = [0, 0, 1.4]
look_at = [0, -1.2, -1]
up = [0, 1, 0]
fov_y = 50

[[light]]
name = "bulb"
position = [0, 1.6, 0]
color = 0.9

[[material]]
name = "matte"
ambient = 0.5
diffuse = 0.5
specular = 0
shininess = 10

[[mesh]]
name = "room"
file = "room.obj"

[[sphere]]
name = "ball"
center = [0, -1.2, -1]
radius = 0.6
material = "matte"
"#,
    )
    .expect("write the scene");
    scene
}

/// The scene view's camera outside the closed room, above its front right corner.
fn outside_view() -> Camera {
    Camera {
        position: Vec3::new(7.0, 5.0, 8.0),
        look_at: Vec3::new(0.0, -0.5, 0.0),
        up: Vec3::Y,
        fov_y_deg: 40.0,
    }
}

/// Of points along the middle of the segments of `tree` drawn in `style`, the fraction where
/// an RGBA picture seen through `frame` shows that style's colour (within 40 of each channel,
/// in the 3 × 3 pixels around the point).
fn colour_along(
    rgba: &[u8],
    frame: &CameraFrame,
    (w, h): (u32, u32),
    tree: &raytree::ray_tree::RayTree,
    style: Style,
) -> f32 {
    let extent = 10.0;
    let [r, g, b, _] = raytree::scene_view::style_rgba(style);
    let segments: Vec<Segment> = raytree::scene_view::tree_segments(tree, extent)
        .into_iter()
        .filter(|s| s.style == style)
        .collect();
    assert!(!segments.is_empty(), "the tree has no {style:?} ray");
    let (mut points, mut found) = (0, 0);
    for s in &segments {
        for i in 0..=20 {
            let p = s.a.lerp(s.b, 0.2 + 0.6 * i as f32 / 20.0);
            let Some((x, y)) = frame.project(p) else {
                continue;
            };
            points += 1;
            let near = (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (px, py) = (x as i64 + dx, y as i64 + dy);
                    if px < 0 || py < 0 || px >= w as i64 || py >= h as i64 {
                        return false;
                    }
                    let q = &rgba[((py as usize) * w as usize + px as usize) * 4..][..3];
                    [r, g, b]
                        .iter()
                        .zip(q)
                        .all(|(want, got)| want.abs_diff(*got) <= 40)
                })
            });
            found += usize::from(near);
        }
    }
    assert!(
        points > 0,
        "the {style:?} rays are not in front of the view"
    );
    found as f32 / points as f32
}

/// From outside a closed room around the render camera, the cut-away (on, and auto, which is
/// on from there) shows the primary and shadow rays in their colours; with it off the walls
/// hide them (dimmed over the wall, not their colour).
#[test]
fn the_cut_away_shows_the_rays_inside_a_closed_room() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = raytree::scene::files::load_scene_file(&closed_room(dir.path())).expect("loads");
    assert_eq!(scene.triangles.len(), 12);
    let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
    let tree = raytree::ray_tree::pixel_tree(&tracer, 160, 120).expect("inside");
    assert!(tree.root.hit.is_some(), "the pixel looks at the ball");
    let view = outside_view();
    let (w, h) = (320, 240);
    let frame = CameraFrame::new(&view, w, h);
    let draw = |cutaway| {
        headless::scene_view_image(
            &scene,
            TraceSettings::default(),
            &[headless::Layer::alone(&tree)],
            &view,
            w,
            h,
            &Filter::default(),
            cutaway,
        )
        .expect("drawn")
    };
    let (on, auto, off) = (draw(Cutaway::On), draw(Cutaway::Auto), draw(Cutaway::Off));
    assert_eq!(on.rgba(), auto.rgba(), "auto cuts from outside the room");
    for style in [Style::Ray(RayKind::Primary), Style::ShadowLit] {
        let seen = colour_along(on.rgba(), &frame, (w, h), &tree, style);
        let hidden = colour_along(off.rgba(), &frame, (w, h), &tree, style);
        assert!(seen > 0.9, "{style:?} with the cut-away: {seen}");
        assert!(hidden < 0.1, "{style:?} behind the walls: {hidden}");
    }
    // Not black on black: the walls inside are lit.
    let lit_pixels = on.rgba().chunks(4).filter(|p| p[0] > 60).count();
    assert!(lit_pixels > (w * h / 4) as usize, "{lit_pixels} lit pixels");
}

/// `raytree tree --scene-view` cuts the room open by itself (auto) and not with
/// `--cutaway off`; the exported PNG shows the rays in their colours.
#[test]
fn the_exported_scene_view_of_a_closed_room_shows_its_rays() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = closed_room(dir.path());
    let scene = raytree::scene::files::load_scene_file(&file).expect("loads");
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let tree = raytree::ray_tree::pixel_tree(&tracer, 160, 120).expect("inside");
    let export = |cutaway: &str| {
        let out = dir.path().join(format!("view-{cutaway}.png"));
        let status = raytree()
            .arg("tree")
            .arg(&file)
            .args(["--pixel", "160,120", "--scene-view"])
            .arg(&out)
            .args(["--eye", "7,5,8", "--target", "0,-0.5,0", "--fov", "40"])
            .args(["--cutaway", cutaway])
            .stdout(std::process::Stdio::null())
            .status()
            .expect("runs");
        assert!(status.success());
        let (w, h, rgba) = read_png(&out, png::ColorType::Rgba, "");
        assert_eq!((w, h), (320, 240));
        rgba
    };
    let frame = CameraFrame::new(&outside_view(), 320, 240);
    let primary = Style::Ray(RayKind::Primary);
    let auto = colour_along(&export("auto"), &frame, (320, 240), &tree, primary);
    let off = colour_along(&export("off"), &frame, (320, 240), &tree, primary);
    assert!(auto > 0.9 && off < 0.1, "auto {auto}, off {off}");
    let (code, err) = refused(&[
        "--scene-view",
        "v.png",
        "--eye",
        "1,2,3",
        "--target",
        "0,0,0",
        "--cutaway",
        "maybe",
    ]);
    assert_eq!(code, Some(2));
    assert!(err.contains("auto, on or off"), "{err}");
}

/// The viewer's "render with rays" export draws each tree as the viewer does: a faint tree of
/// several in its tint, the selected one in the rays' own colours.
#[test]
fn an_exported_overlay_draws_a_faint_tree_in_its_tint() {
    use raytree::scene_view::{Strength, TreeLook, tree_tint};
    let scene = raytree::scene::builtin::load_builtin("default").expect("built in");
    let tracer = Tracer::new(Arc::new(scene.clone()), TraceSettings::default());
    let (w, h) = (scene.render.width, scene.render.height);
    // A pixel of the glass sphere: reflected and refracted rays, seen from the side.
    let (x, y) = (w * 3 / 8, h * 23 / 40);
    let tree = raytree::ray_tree::pixel_tree(&tracer, x, y).expect("inside");
    assert!(
        tree.nodes > 3,
        "the pixel's tree branches ({} nodes)",
        tree.nodes
    );
    // Over a black image every lit pixel is a ray's colour (or a light's disc).
    let black = raytree::render::Image::new(w, h);
    let tint = tree_tint(3);
    let share_in_tint = |look: Option<TreeLook>| {
        let layer = headless::Layer {
            tree: &tree,
            look,
            depth: None,
        };
        let canvas =
            headless::overlay_image(&tracer, &black, &[layer], &Filter::default()).expect("drawn");
        let t = Vec3::new(tint[0] as f32, tint[1] as f32, tint[2] as f32).normalize();
        let (mut lit, mut tinted) = (0, 0);
        for p in canvas.rgba().chunks(4) {
            let c = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
            if c.max_element() < 24.0 {
                continue;
            }
            lit += 1;
            if c.normalize().dot(t) > 0.995 {
                tinted += 1;
            }
        }
        assert!(lit > 50, "the tree is drawn ({lit} lit pixels)");
        tinted as f32 / lit as f32
    };
    let faint = share_in_tint(Some(TreeLook {
        tint,
        strength: Strength::Faint,
    }));
    let own = share_in_tint(None);
    assert!(
        faint > 0.8,
        "{:.0} % of the faint tree is in its tint",
        faint * 100.0
    );
    assert!(
        own < 0.2,
        "{:.0} % of the tree alone is in the tint",
        own * 100.0
    );
}
