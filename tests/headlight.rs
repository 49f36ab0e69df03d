//! A light that follows the camera (`follow_camera = true`, docs/design.md, "Scene files"): one
//! rule (`Scene::place_lights`) puts it at the render camera's eye, so `raytree render --eye`, the
//! ray tree and the viewer all see it there; saved and loaded as written; held to its rules.

use std::sync::Arc;

use assert_cmd::Command;
use raytree::ray_tree::pixel_tree;
use raytree::render::render;
use raytree::scene::{load_scene_str, scene_to_toml};
use raytree::trace::{TraceSettings, Tracer};

/// A floor and a ball lit only by a headlight: what it lights depends on where the eye is.
const SCENE: &str = r#"
[render]
width = 48
height = 36
ambient_light = 0.05

[camera]
position = [0, 1.5, 5]
look_at = [0, 0.3, 0]

[[light]]
name = "head"
follow_camera = true
color = [1, 1, 1]

[[material]]
name = "matte"
diffuse = [0.8, 0.7, 0.6]
specular = 0.4
shininess = 20

[[sphere]]
center = [0, 0.6, 0]
radius = 0.6
material = "matte"

[[triangle]]
vertices = [[-4, 0, -4], [-4, 0, 4], [4, 0, 4]]
material = "matte"

[[triangle]]
vertices = [[-4, 0, -4], [4, 0, 4], [4, 0, -4]]
material = "matte"
"#;

const EYE: &str = "3,2.5,3";

fn raytree() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytree"))
}

fn render_cli(scene: &std::path::Path, out: &std::path::Path, eye: Option<&str>) -> Vec<u8> {
    let mut cmd = raytree();
    cmd.args(["render", "--quiet", "--threads", "2"])
        .arg(scene)
        .arg("-o")
        .arg(out);
    if let Some(eye) = eye {
        cmd.args(["--eye", eye]);
    }
    let output = cmd.output().expect("runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    image::open(out).expect("a PNG").to_rgb8().into_raw()
}

#[test]
fn render_with_eye_moves_the_headlight_as_a_scene_with_that_camera_does() {
    let dir = tempfile::tempdir().expect("temp dir");
    let follow = dir.path().join("follow.toml");
    std::fs::write(&follow, SCENE).expect("write");
    // The same scene with the camera written at the new eye.
    let moved = dir.path().join("moved.toml");
    std::fs::write(
        &moved,
        SCENE.replace("position = [0, 1.5, 5]", "position = [3, 2.5, 3]"),
    )
    .expect("write");
    // The same light, fixed where the file's camera stands.
    let fixed = dir.path().join("fixed.toml");
    std::fs::write(
        &fixed,
        SCENE.replace("follow_camera = true", "position = [0, 1.5, 5]"),
    )
    .expect("write");

    let with_eye = render_cli(&follow, &dir.path().join("a.png"), Some(EYE));
    let written = render_cli(&moved, &dir.path().join("b.png"), None);
    let fixed_light = render_cli(&fixed, &dir.path().join("c.png"), Some(EYE));
    assert_eq!(
        with_eye, written,
        "--eye and a file with that camera render the same image"
    );
    let differ = with_eye
        .iter()
        .zip(&fixed_light)
        .filter(|(a, b)| a.abs_diff(**b) > 8)
        .count();
    assert!(
        differ > with_eye.len() / 20,
        "the headlight moved with the eye: only {differ} channels differ from the fixed light"
    );
    // Without --eye the followed light is where the file's camera is: as the fixed one.
    let at_file = render_cli(&follow, &dir.path().join("d.png"), None);
    let fixed_at_file = render_cli(&fixed, &dir.path().join("e.png"), None);
    assert_eq!(at_file, fixed_at_file);
}

#[test]
fn a_bad_eye_is_one_sentence() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("follow.toml");
    std::fs::write(&path, SCENE).expect("write");
    let output = raytree()
        .args(["render", "--quiet"])
        .arg(&path)
        .args(["-o", "/dev/null.png", "--eye", "0,0.3,0"])
        .output()
        .expect("runs");
    assert!(!output.status.success());
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(err.contains("--eye") && err.contains("camera"), "{err}");
}

#[test]
fn the_tree_sees_the_headlight_where_the_render_does_after_the_camera_moved() {
    let mut scene = load_scene_str(SCENE, "follow.toml").expect("loads");
    assert_eq!(scene.lights[0].position, scene.camera.position);
    scene.camera.orbit(0.7, 0.2);
    scene.place_lights();
    let eye = scene.camera.position;
    assert_eq!(
        scene.lights[0].position, eye,
        "the light stands at the new eye"
    );
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let (image, _) = render(&tracer, 1, 2, &|_, _| {}).expect("render");
    let mut lit = 0;
    for (x, y) in [(24, 18), (10, 30), (40, 28), (24, 8)] {
        let tree = pixel_tree(&tracer, x, y).expect("a tree");
        let pixel = image.pixels[(y * image.width + x) as usize];
        assert_eq!(
            tree.color, pixel,
            "pixel ({x}, {y}): the tree's colour is the render's, exactly"
        );
        if let Some(hit) = &tree.root.hit {
            let point = hit.point;
            let shadow = &tree.root.shadow_rays[0];
            let to_eye = (eye - point).normalize();
            assert!(
                shadow.to_light.dot(to_eye) > 0.9999,
                "the shadow ray goes to the eye"
            );
            lit += 1;
        }
    }
    assert!(lit >= 3, "the pixels chosen hit the floor or the ball");
}

#[test]
fn follow_camera_is_saved_and_loaded_and_held_to_its_rules() {
    let scene = load_scene_str(SCENE, "follow.toml").expect("loads");
    assert!(scene.lights[0].follow_camera);
    let text = scene_to_toml(&scene);
    assert!(text.contains("follow_camera = true"), "{text}");
    let again = load_scene_str(&text, "saved.toml").expect("the saved scene loads");
    assert_eq!(again.lights, scene.lights);

    let with_position = SCENE.replace(
        "follow_camera = true",
        "follow_camera = true\nposition = [1, 2, 3]",
    );
    let err = load_scene_str(&with_position, "both.toml")
        .expect_err("position and follow_camera contradict")
        .to_string();
    assert!(
        err.starts_with("both.toml:") && err.contains("field `position`"),
        "{err}"
    );
    let ball = SCENE.replace("follow_camera = true", "follow_camera = true\nradius = 0.5");
    let err = load_scene_str(&ball, "ball.toml")
        .expect_err("a ball around the eye")
        .to_string();
    assert!(
        err.contains("field `radius`") && err.contains("follows the camera"),
        "{err}"
    );
    let typo = SCENE.replace("follow_camera = true", "follow_camera = 1");
    let err = load_scene_str(&typo, "typo.toml")
        .expect_err("not a boolean")
        .to_string();
    assert!(err.contains("must be true or false"), "{err}");
}
