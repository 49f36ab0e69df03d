//! OBJ objects and groups (`o`, `g`) name the parts of a mesh: the same names through the
//! parallel reader and through tobj, one name per run of triangles, and the ray tree's nodes
//! (JSON and text) name the part a ray met ("parts: Door"), not only the file.

use std::path::Path;
use std::sync::Arc;

use raytree::ray_tree::{Node, pixel_tree, tree_text};
use raytree::scene::{MeshPart, Scene, load_scene_file};
use raytree::trace::{TraceSettings, Tracer};

const FIXTURE: &str = "tests/fixtures/models/parts.obj";

fn load(path: &Path) -> Scene {
    load_scene_file(path).unwrap_or_else(|e| panic!("{e}"))
}

/// `(name, first triangle, triangle count, material name)` of each part.
fn parts(scene: &Scene) -> Vec<(String, u32, u32, String)> {
    scene
        .parts
        .iter()
        .map(|p: &MeshPart| {
            let material = scene.material(p.material).name.clone();
            (p.name.clone(), p.first_triangle, p.triangle_count, material)
        })
        .collect()
}

fn row(name: &str, first: u32, count: u32, material: &str) -> (String, u32, u32, String) {
    (name.into(), first, count, material.into())
}

#[test]
fn objects_and_groups_name_runs_of_triangles() {
    let scene = load(Path::new(FIXTURE));
    assert_eq!(scene.triangles.len(), 10, "five squares");
    assert_eq!(
        parts(&scene),
        [
            row("Shelf", 2, 2, "parts/White.001"),
            row("Cabinet_3", 4, 2, "parts/White.001"),
            row("Cabinet_3", 6, 2, "parts/Red"),
            // `o Door` then `g Door`: the last name before the faces, as tobj names models.
            row("Door", 8, 2, "parts/White.001"),
        ]
    );
    let names: Vec<Option<&str>> = (0..10)
        .map(|t| scene.part_of(t).map(|p| p.name.as_str()))
        .collect();
    assert_eq!(
        names,
        [
            None,
            None,
            Some("Shelf"),
            Some("Shelf"),
            Some("Cabinet_3"),
            Some("Cabinet_3"),
            Some("Cabinet_3"),
            Some("Cabinet_3"),
            Some("Door"),
            Some("Door"),
        ]
    );
    assert_eq!(scene.part_of(10), None);
}

/// The parallel reader and tobj (which reads a file with a relative index) give the same parts.
#[test]
fn both_readers_give_the_same_names() {
    let dir = tempfile::tempdir().expect("temp dir");
    let text = std::fs::read_to_string(FIXTURE).expect("fixture");
    let mtl = std::fs::read_to_string("tests/fixtures/models/parts.mtl").expect("mtl");
    std::fs::write(dir.path().join("parts.mtl"), mtl).expect("write");
    let path = dir.path().join("parts.obj");
    std::fs::write(&path, &text).expect("write");
    let fast = load(&path);
    assert!(raytree::scene::obj::parse::parse(&text, |_| Ok(Default::default())).is_some());

    // One more face, on the last square, through a relative index: tobj reads the whole file.
    let slow_text = format!("{text}f -4 -3 -2\n");
    assert!(raytree::scene::obj::parse::parse(&slow_text, |_| Ok(Default::default())).is_none());
    std::fs::write(&path, &slow_text).expect("write");
    let slow = load(&path);
    let mut expected = parts(&fast);
    expected.last_mut().expect("a part").2 += 1;
    assert_eq!(parts(&slow), expected);
    assert_eq!(fast.parts.len(), 4);
}

fn all_nodes(node: &Node) -> Vec<&Node> {
    let mut out = vec![node];
    for c in &node.children {
        out.extend(all_nodes(c));
    }
    out
}

/// A tree on a pixel of each square names what it hit: the part after the file's name, or
/// the file alone for the faces before any name. The text form says the same.
#[test]
fn trees_name_the_part_a_ray_met() {
    let scene = Arc::new(load(Path::new(FIXTURE)));
    let tracer = Tracer::new(scene.clone(), TraceSettings::default());
    let (w, h) = (scene.render.width, scene.render.height);
    let expected = |x: f32| match x {
        x if x < 1.5 => "parts",
        x if x < 3.5 => "parts: Shelf",
        x if x < 7.5 => "parts: Cabinet_3",
        _ => "parts: Door",
    };
    let mut seen = std::collections::BTreeSet::new();
    for x in 0..w {
        let tree = pixel_tree(&tracer, x, h / 2).expect("inside");
        let Some(hit) = &tree.root.hit else { continue };
        assert_eq!(
            hit.object,
            expected(hit.point.x),
            "pixel {x}: {:?}",
            hit.point
        );
        seen.insert(hit.object.clone());
        for node in all_nodes(&tree.root) {
            for s in &node.shadow_rays {
                if let Some(b) = &s.blocked_by {
                    assert!(b.starts_with("parts"), "{b}");
                }
            }
        }
        if hit.object == "parts: Door" {
            assert!(tree_text(&tree).contains("hit parts: Door (parts/White.001)"));
            let json = serde_json::to_string(&tree).expect("json");
            assert!(json.contains(r#""object":"parts: Door""#), "{json}");
        }
    }
    let seen: Vec<&str> = seen.iter().map(String::as_str).collect();
    assert_eq!(
        seen,
        ["parts", "parts: Cabinet_3", "parts: Door", "parts: Shelf"]
    );
}

/// A shadow ray blocked by a named part names it as the tree's hits do.
#[test]
fn blockers_are_named_by_their_part() {
    let dir = tempfile::tempdir().expect("temp dir");
    for file in ["parts.obj", "parts.mtl"] {
        std::fs::copy(
            Path::new("tests/fixtures/models").join(file),
            dir.path().join(file),
        )
        .expect("copy");
    }
    // The camera looks through the gap at x 7..8 onto a floor; the light's segment from there
    // crosses the door (x 8..9) at z = 0.
    let scene = r#"
[render]
width = 101
height = 101

[camera]
position = [7.5, 0.5, 10]
look_at = [7.5, 0.5, -2]
up = [0, 1, 0]
fov_y = 10

[[light]]
name = "side"
position = [9.5, 0.5, 2]
color = 1

[[mesh]]
name = "shelves"
file = "parts.obj"

[[triangle]]
name = "floor"
vertices = [[-50, -50, -2], [50, -50, -2], [0, 50, -2]]
"#;
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).expect("write");
    let scene = Arc::new(load(&path));
    let tracer = Tracer::new(scene, TraceSettings::default());
    let tree = pixel_tree(&tracer, 50, 50).expect("inside");
    let hit = tree.root.hit.as_ref().expect("the floor");
    assert_eq!(hit.object, "floor");
    let shadow = &tree.root.shadow_rays[0];
    assert_eq!(shadow.blocked_by.as_deref(), Some("shelves: Door"));
    assert!(tree_text(&tree).contains("blocked by shelves: Door"));
}

/// A part named as its mesh adds nothing to the name ("Door", not "Door: Door").
#[test]
fn a_part_named_as_its_mesh_names_nothing_more() {
    let dir = tempfile::tempdir().expect("temp dir");
    for file in ["parts.obj", "parts.mtl"] {
        std::fs::copy(
            Path::new("tests/fixtures/models").join(file),
            dir.path().join(file),
        )
        .expect("copy");
    }
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, "[[mesh]]\nname = \"Door\"\nfile = \"parts.obj\"\n").expect("write");
    let scene = load(&path);
    let names: Vec<&str> = scene.parts.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["Shelf", "Cabinet_3", "Cabinet_3"]);
    let door = scene.hit_name(scene.triangles[8].object, Some(8));
    assert_eq!(door, "Door");
    assert_eq!(
        scene.hit_name(scene.triangles[4].object, Some(4)),
        "Door: Cabinet_3"
    );
}
