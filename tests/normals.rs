//! Shading normals and textures from OBJ files (docs/design.md, "Scene files"): `vn` interpolated
//! at the hit, the `[[mesh]]` keys `normals` and `crease_angle` (held to scene::rules, saved and
//! loaded back), `vt` and `map_Kd` textures, and the sentences for broken `vn`, `vt` and texture
//! files.

use std::sync::Arc;

use glam::Vec3;
use raytree::ray_tree::{pixel_tree, tree_text};
use raytree::scene::{
    NormalsMode, ObjectSource, Scene, load_scene_file, load_scene_str_with,
    load_scene_str_with_files, scene_to_toml,
};
use raytree::trace::{TraceSettings, Tracer};

/// One triangle facing +z with three different vertex normals, and a texture coordinate each.
const TRI: &str = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\n\
vn -0.5 0 1\nvn 0.5 0 1\nvn 0 0.5 1\n\
vt 0 0\nvt 1 0\nvt 0 1\n\
f 1/1/1 2/2/2 3/3/3\n";

/// An octahedron (faces meet at 109.5°, their normals 70.5° apart), no `vn`.
const OCTA: &str = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

fn files(list: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Result<String, String> {
    move |path: &str| {
        list.iter()
            .find(|(p, _)| *p == path)
            .map(|(_, t)| (*t).to_string())
            .ok_or_else(|| format!("{path}: no such test file"))
    }
}

fn load(toml: &str, list: &'static [(&'static str, &'static str)]) -> Scene {
    load_scene_str_with(toml, "t.toml", &files(list)).unwrap_or_else(|e| panic!("{e}"))
}

const CAMERA: &str = "[render]\nwidth = 9\nheight = 9\nambient_light = 0\n\
[camera]\nposition = [0, 0, 3]\nlook_at = [0, 0, 0]\nfov_y = 10\n\
[[light]]\nposition = [0, 0, 5]\n";

#[test]
fn vertex_normals_are_interpolated_and_the_tree_shows_both_normals() {
    let scene = load(
        &format!("{CAMERA}[[mesh]]\nfile = \"tri.obj\"\n"),
        &[("tri.obj", TRI)],
    );
    assert_eq!(scene.attributes.len(), 1);
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let tree = pixel_tree(&tracer, 4, 4).expect("centre pixel");
    let hit = tree.root.hit.as_ref().expect("hits the triangle");
    let b = hit.barycentric.expect("a triangle");
    let n = [
        Vec3::new(-0.5, 0.0, 1.0).normalize(),
        Vec3::new(0.5, 0.0, 1.0).normalize(),
        Vec3::new(0.0, 0.5, 1.0).normalize(),
    ];
    let want = (b[0] * n[0] + b[1] * n[1] + b[2] * n[2]).normalize();
    assert!(
        (hit.normal - want).length() < 1e-5,
        "{} vs {want}",
        hit.normal
    );
    assert_eq!(hit.geometric_normal, Some(Vec3::Z));
    // No texture: no uv shown.
    assert_eq!(hit.uv, None);
    let json = serde_json::to_string(&tree).expect("json");
    assert!(json.contains("\"geometric_normal\""), "{json}");
}

#[test]
fn flat_ignores_vn_and_smooth_splits_at_the_crease_angle() {
    let flat = load(
        &format!("{CAMERA}[[mesh]]\nfile = \"tri.obj\"\nnormals = \"flat\"\n"),
        &[("tri.obj", TRI)],
    );
    assert!(flat.attributes.is_empty(), "flat meshes carry nothing");
    // Neighbouring faces' normals are 70.5° apart, opposite ones 109.5°: the default 60° keeps
    // every face flat, 120° smooths all four around a corner.
    for (crease, smooth) in [(60.0, false), (120.0, true)] {
        let s = load(
            &format!(
                "{CAMERA}[[mesh]]\nfile = \"o.obj\"\nnormals = \"smooth\"\ncrease_angle = {crease}\n"
            ),
            &[("o.obj", OCTA)],
        );
        let a = &s.attributes[0];
        let n = a.normals_of(0).expect("normals");
        let face = Vec3::ONE.normalize();
        if smooth {
            // The corner at (1, 0, 0) averages its four faces: the normal is +x.
            assert!((n[0] - Vec3::X).length() < 1e-6, "{n:?}");
        } else {
            assert!(n.iter().all(|v| (*v - face).length() < 1e-6), "{n:?}");
        }
    }
    // A file without vn under the default "file": flat, nothing kept.
    let plain = load(
        &format!("{CAMERA}[[mesh]]\nfile = \"o.obj\"\n"),
        &[("o.obj", OCTA)],
    );
    assert!(plain.attributes.is_empty());
}

/// A shallow roof of four triangles around (0, 0, h), no `vn`: neighbouring faces' normals are
/// far less than the default crease angle apart. `group` is the `s` statement before the faces.
fn roof(group: &str) -> String {
    format!(
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 0 0 0.3\n{group}\n\
         f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n"
    )
}

/// A scene of the camera above and one mesh, `obj` as `r.obj`, with the `[[mesh]]` keys
/// `keys`.
fn load_obj(obj: String, keys: &str) -> Scene {
    let files = move |path: &str| match path {
        "r.obj" => Ok(obj.clone()),
        _ => Err(format!("{path}: no such test file")),
    };
    load_scene_str_with(
        &format!("{CAMERA}[[mesh]]\nfile = \"r.obj\"\n{keys}"),
        "t.toml",
        &files,
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// The shading normal at the apex (vertex 5 is the third corner of the first triangle).
fn apex_normal(scene: &Scene) -> Option<Vec3> {
    let a = scene.attributes.first()?;
    Some(a.normals_of(0)?[2])
}

#[test]
fn smoothing_groups_without_vn_shade_smooth_and_say_so() {
    let load_roof = |group: &str, normals: &str| load_obj(roof(group), normals);
    // `s 1` (and a named group): the apex's normal is the average of the four faces, +z.
    for group in ["s 1", "s 7", "s roof"] {
        let scene = load_roof(group, "");
        let n = apex_normal(&scene).unwrap_or_else(|| panic!("{group}: no normals kept"));
        assert!((n - Vec3::Z).length() < 1e-5, "{group}: apex normal {n}");
        assert_eq!(scene.warnings.len(), 1, "{group}: {:?}", scene.warnings);
        let w = &scene.warnings[0];
        assert!(
            w.starts_with("r.obj: no vertex normals") && w.contains("normals = \"flat\""),
            "{w}"
        );
    }
    // No group, `s off`, `s 0`, or `normals = "flat"`: flat, nothing kept, nothing said.
    for (group, normals) in [
        ("", ""),
        ("s off", ""),
        ("s 0", ""),
        ("s 1", "normals = \"flat\"\n"),
    ] {
        let scene = load_roof(group, normals);
        assert!(
            scene.attributes.is_empty() && scene.warnings.is_empty(),
            "{group:?} {normals:?}: {:?}",
            scene.warnings
        );
    }
    // Per face: under `s off` a face stays flat, and two groups do not average together. The
    // roof's first two faces (towards -y and +x) in one group, the other two flat or in a
    // second group.
    let mixed = |second: &str| {
        load_obj(
            format!(
                "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 0 0 0.3\ns 1\nf 1 2 5\nf 2 3 5\n\
                 {second}\nf 3 4 5\nf 4 1 5\n"
            ),
            "",
        )
    };
    let face = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - a).normalize();
    let (v1, v2, v3, v4, apex) = (
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 0.3),
    );
    let (f0, f1, f2) = (face(v1, v2, apex), face(v2, v3, apex), face(v3, v4, apex));
    // The first group's two faces are equal in area: their apex normal is their mean.
    let pair = (f0 + f1).normalize();
    for second in ["s off", "s 2"] {
        let scene = mixed(second);
        let a = &scene.attributes[0];
        let first = a.normals_of(0).expect("normals")[2];
        assert!(
            (first - pair).length() < 1e-5,
            "{second}: {first} vs {pair}"
        );
        let third = a.normals_of(2).expect("normals")[2];
        let want = if second == "s off" {
            f2
        } else {
            (f2 + face(v4, v1, apex)).normalize()
        };
        assert!(
            (third - want).length() < 1e-5,
            "{second}: {third} vs {want}"
        );
    }
    // A group is its number, however written: `s 01` goes on with `s 1`, so all four faces
    // average to +z at the apex.
    let scene = mixed("s 01");
    for face in [0, 2] {
        let n = scene.attributes[0].normals_of(face).expect("normals")[2];
        assert!((n - Vec3::Z).length() < 1e-5, "face {face}: {n}");
    }
    // A file with its own `vn` keeps them whatever its groups.
    let scene = load_obj(format!("{TRI}s 1\n"), "");
    let n = apex_normal(&scene).expect("the file's normals");
    assert!(
        (n - Vec3::new(0.0, 0.5, 1.0).normalize()).length() < 1e-5,
        "{n}"
    );
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

#[test]
fn faces_without_vn_in_a_file_with_vn_shade_by_their_groups() {
    // The roof's first two faces give `vn` (all (0.6, 0, 0.8), so they can be told apart); the other two
    // give none. In one group, the two without `vn` take the normals computed within it: the
    // apex averages all four faces, +z. Under `s off` they stay flat.
    let roof = |group: &str| {
        format!(
            "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 0 0 0.3\nvn 0.6 0 0.8\ns 1\n\
             f 1//1 2//1 5//1\nf 2//1 3//1 5//1\n{group}\nf 3 4 5\nf 4 1 5\n"
        )
    };
    let scene = load_obj(roof("s 1"), "");
    let a = &scene.attributes[0];
    for face in [0, 1] {
        let kept = a.normals_of(face).expect("the file's normals");
        assert!(
            kept.iter()
                .all(|n| (*n - Vec3::new(0.6, 0.0, 0.8)).length() < 1e-5),
            "{kept:?}"
        );
    }
    for face in [2, 3] {
        let n = a.normals_of(face).expect("computed normals")[2];
        assert!((n - Vec3::Z).length() < 1e-5, "face {face}: apex {n}");
    }
    // The file's one normal, and the computed ones those two faces take at their four
    // distinct corners, no more.
    assert!(a.normals.len() <= 1 + 4, "{} normals kept", a.normals.len());
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = &scene.warnings[0];
    assert!(
        w.starts_with("r.obj: the faces without vertex normals (`vn`) in its smoothing groups (`s`) are shaded"),
        "{w}"
    );
    // Under `s off` the two stay flat (no normals of their own), and nothing is said.
    let scene = load_obj(roof("s off"), "");
    let a = &scene.attributes[0];
    assert!(a.normals_of(2).is_none() && a.normals_of(3).is_none());
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // `normals = "flat"` keeps every facet.
    let scene = load_obj(roof("s 1"), "normals = \"flat\"\n");
    assert!(scene.attributes.is_empty() && scene.warnings.is_empty());
}

#[test]
fn normals_keys_are_checked_saved_and_loaded_back() {
    let list: &'static [(&str, &str)] = &[("o.obj", OCTA)];
    let bad = load_scene_str_with(
        "[[mesh]]\nfile = \"o.obj\"\ncrease_angle = 200\n",
        "t.toml",
        &files(list),
    )
    .expect_err("crease above 180")
    .to_string();
    assert!(
        bad.starts_with("t.toml:3:")
            && bad.contains("`crease_angle` must be between 0 and 180 degrees"),
        "{bad}"
    );
    let bad = load_scene_str_with(
        "[[mesh]]\nfile = \"o.obj\"\nnormals = \"bumpy\"\n",
        "t.toml",
        &files(list),
    )
    .expect_err("unknown mode")
    .to_string();
    assert!(bad.contains("\"file\" or \"flat\" or \"smooth\""), "{bad}");
    let scene = load(
        "[[mesh]]\nfile = \"o.obj\"\nnormals = \"smooth\"\ncrease_angle = 75.5\n",
        list,
    );
    let text = scene_to_toml(&scene);
    assert!(
        text.contains("normals = \"smooth\"\ncrease_angle = 75.5\n"),
        "{text}"
    );
    let back = load(&text, list);
    assert_eq!(back.objects, scene.objects);
    assert_eq!(back.attributes, scene.attributes);
    assert!(matches!(
        back.objects[0].source,
        ObjectSource::Mesh {
            normals: NormalsMode::Smooth,
            ..
        }
    ));
}

#[test]
fn broken_vn_faces_are_flat_with_one_warning() {
    // Face 1: a normal too long for f32 (its length overflows); face 2: a zero normal; face 3
    // fine.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
vn 0 0 1\nvn 3e38 3e38 0\nvn 0 0 0\n\
f 2//2 4//1 3//1\nf 2//3 4//1 3//1\nf 1//1 2//1 3//1\n";
    let list: &'static [(&str, &str)] = Box::leak(Box::new([("b.obj", obj)]));
    let scene = load("[[mesh]]\nfile = \"b.obj\"\n", list);
    assert_eq!(scene.triangles.len(), 3);
    assert_eq!(
        scene.warnings,
        [
            "b.obj: 2 faces name normals (`vn`) that are out of range, zero or not finite; they are shaded flat."
        ]
    );
    let a = &scene.attributes[0];
    let has: Vec<bool> = (0..3).map(|i| a.normals_of(i).is_some()).collect();
    assert_eq!(has, [false, false, true]);
    // A vn index out of range: the OBJ reader refuses the file, naming the line.
    let bad: &'static [(&str, &str)] = &[(
        "c.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//9 3//1\n",
    )];
    let e = load_scene_str_with("[[mesh]]\nfile = \"c.obj\"\n", "t.toml", &files(bad))
        .expect_err("index out of range")
        .to_string();
    assert_eq!(
        e,
        "t.toml:2:8: mesh 1 field `file` cannot be loaded: c.obj:5: `f 1//1 2//9 3//1` names normal 9, which is not defined: 1 normal (a `vn` line) comes before this face (OBJ numbers them from 1, and -1 is the last one)."
    );
}

fn png_bytes(w: u32, h: u32, rgb: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header().expect("header");
    writer.write_image_data(rgb).expect("data");
    drop(writer);
    out
}

/// A folder with TRI under material `t` of `t.mtl` (not written) and a scene of it seen by
/// CAMERA: the folder and the scene file.
fn textured_tri() -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("tri.obj"),
        format!("mtllib t.mtl\nusemtl t\n{TRI}"),
    )
    .expect("obj");
    let scene_file = dir.path().join("s.toml");
    std::fs::write(
        &scene_file,
        format!("{CAMERA}[[mesh]]\nfile = \"tri.obj\"\n"),
    )
    .expect("toml");
    (dir, scene_file)
}

#[test]
fn a_black_kd_under_a_texture_takes_the_texture_as_its_colour() {
    // Maya writes `Kd 0` under every texture: read as Kd × texel, the texture never shows.
    let (dir, scene_file) = textured_tri();
    std::fs::write(dir.path().join("red.png"), png_bytes(1, 1, &[255, 0, 0])).expect("png");
    let diffuse_at_centre = |mtl: &str| {
        std::fs::write(dir.path().join("t.mtl"), mtl).expect("mtl");
        let scene = load_scene_file(&scene_file).unwrap_or_else(|e| panic!("{e}"));
        let warnings = scene.warnings.clone();
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let tree = pixel_tree(&tracer, 4, 4).expect("centre pixel");
        (tree.root.local.expect("shaded").diffuse, warnings)
    };
    let (red, warnings) = diffuse_at_centre("newmtl t\nKd 0 0 0\nmap_Kd red.png\n");
    assert!(
        red.x > 0.0 && red.y == 0.0 && red.z == 0.0,
        "the red texel shows: {red}"
    );
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("material `t` has `Kd 0` under a `map_Kd`")
            && warnings[0].contains("`Kd 1` is taken"),
        "{}",
        warnings[0]
    );
    // Its diffuse term is the texel's, as under `Kd 1`.
    let (white, _) = diffuse_at_centre("newmtl t\nKd 1 1 1\nmap_Kd red.png\n");
    assert!(red.abs_diff_eq(white, 1e-6), "{red} against {white}");
    // Without the texture, a black `Kd` stays black; a scene's `[[material]]` of that name
    // keeps its colours.
    let (black, warnings) = diffuse_at_centre("newmtl t\nKd 0 0 0\nmap_Kd nope.png\n");
    assert_eq!(black, Vec3::ZERO, "{warnings:?}");
    std::fs::write(
        &scene_file,
        format!("{CAMERA}[[material]]\nname = \"tri/t\"\ndiffuse = [0, 0, 0]\n\n[[mesh]]\nfile = \"tri.obj\"\n"),
    )
    .expect("toml");
    let (chosen, warnings) = diffuse_at_centre("newmtl t\nKd 0 0 0\nmap_Kd red.png\n");
    assert_eq!(chosen, Vec3::ZERO, "the scene's own black: {warnings:?}");
}

#[test]
fn map_kd_multiplies_kd_and_the_tree_shows_uv_and_texel() {
    let (dir, scene_file) = textured_tri();
    std::fs::write(
        dir.path().join("t.mtl"),
        "newmtl t\nKd 0.5 0.5 0.5\nmap_Kd red.png\n",
    )
    .expect("mtl");
    std::fs::write(dir.path().join("red.png"), png_bytes(1, 1, &[255, 0, 0])).expect("png");
    let scene = load_scene_file(&scene_file).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.textures.len(), 1);
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let tree = pixel_tree(&tracer, 4, 4).expect("centre pixel");
    let hit = tree.root.hit.as_ref().expect("hit");
    assert_eq!(hit.texel, Some(Vec3::X));
    assert!(hit.uv.is_some());
    // Red texel × kd 0.5: no green or blue diffuse at all.
    let local = tree.root.local.expect("shaded");
    assert!(
        local.diffuse.x > 0.0 && local.diffuse.y == 0.0 && local.diffuse.z == 0.0,
        "{local:?}"
    );

    // A missing texture, a folder and /dev/zero: one warning each naming the file and the
    // MTL line; the flat colour stays.
    for (what, target) in [
        ("missing", "nope.png"),
        ("folder", "sub"),
        ("device", "/dev/zero"),
        ("not an image", "t.mtl"),
    ] {
        std::fs::create_dir_all(dir.path().join("sub")).expect("folder");
        std::fs::write(
            dir.path().join("t.mtl"),
            format!("newmtl t\nKd 0.5 0.5 0.5\nmap_Kd {target}\n"),
        )
        .expect("mtl");
        let scene = load_scene_file(&scene_file).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(scene.warnings.len(), 1, "{what}: {:?}", scene.warnings);
        let w = &scene.warnings[0];
        assert!(
            w.contains("`t.mtl` line 3") && w.contains("its flat colour stays"),
            "{what}: {w}"
        );
        assert!(scene.textures.is_empty());
    }
}

#[test]
fn an_obj_that_names_no_material_takes_the_texture_named_for_it() {
    // Model packs (tinyrenderer's heads, raylib's buildings) ship `<name>_diffuse.<ext>` beside
    // an OBJ with texture coordinates and no material library. An image named for the OBJ
    // without `_diffuse` (a render saved beside it) is not taken.
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("tri.obj"), TRI).expect("obj");
    std::fs::write(
        dir.path().join("tri_diffuse.PNG"),
        png_bytes(1, 1, &[255, 0, 0]),
    )
    .expect("png");
    std::fs::write(dir.path().join("tri.png"), png_bytes(1, 1, &[0, 0, 255])).expect("png");
    let scene_file = dir.path().join("s.toml");
    std::fs::write(
        &scene_file,
        format!("{CAMERA}[[mesh]]\nfile = \"tri.obj\"\n"),
    )
    .expect("toml");
    // Found whatever the case of its name, as every file a model names is.
    let note = "tri.obj: no material library gives its faces a material; `tri_diffuse.png` beside it, named for it, is taken as their texture.";
    // Through a scene file and opened bare: the same texture, red at the centre pixel.
    for file in [scene_file.clone(), dir.path().join("tri.obj")] {
        let scene = load_scene_file(&file).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            scene.warnings.len() == 1 && scene.warnings[0].ends_with(note),
            "{}: {:?}",
            file.display(),
            scene.warnings
        );
        assert_eq!(scene.textures.len(), 1);
        let (width, height) = (scene.render.width, scene.render.height);
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let tree = pixel_tree(&tracer, width / 2, height / 2).expect("centre pixel");
        let hit = tree.root.hit.as_ref().expect("hit");
        assert_eq!(hit.texel, Some(Vec3::X), "{}", file.display());
        let local = tree.root.local.expect("shaded");
        assert!(
            local.diffuse.x > 0.0 && local.diffuse.y == 0.0 && local.diffuse.z == 0.0,
            "{local:?}"
        );
        assert!(
            local.ambient.y == 0.0 && local.ambient.z == 0.0,
            "{local:?}"
        );
    }
    // Saved as a scene file (the viewer's Save) and loaded back: the same material, with its
    // texture, whose colours the file now sets.
    let bare = load_scene_file(&dir.path().join("tri.obj")).unwrap_or_else(|e| panic!("{e}"));
    let saved = dir.path().join("saved.toml");
    let text = scene_to_toml(&bare).replace("\ndiffuse = 1.0\n", "\ndiffuse = 0.5\n");
    std::fs::write(&saved, &text).expect("save");
    let back = load_scene_file(&saved).unwrap_or_else(|e| panic!("{e}\n{text}"));
    let used = back.material(back.triangles[0].material);
    assert_eq!(used.name, "tri/tri_diffuse.png", "{text}");
    assert!(
        used.diffuse_map.is_some() && used.ambient_map.is_some(),
        "{text}"
    );
    assert_eq!(used.diffuse, Vec3::splat(0.5), "{text}");
    // Faces without texture coordinates, or with a material of their own, keep theirs; an
    // image of that name that cannot be read is one sentence, and the default grey stays.
    std::fs::write(dir.path().join("m.mtl"), "newmtl a\nKd 0 1 0\n").expect("mtl");
    let red = png_bytes(1, 1, &[255, 0, 0]);
    for (name, obj, material, warning) in [
        (
            "flat",
            "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n",
            "default",
            None,
        ),
        (
            "own",
            &*format!("mtllib m.mtl\nusemtl a\n{TRI}"),
            "own/a",
            None,
        ),
        (
            "bad",
            TRI,
            "default",
            Some(
                "bad.obj: cannot use `bad_diffuse.png`, the texture named for it, on its faces without a material (",
            ),
        ),
    ] {
        std::fs::write(dir.path().join(format!("{name}.obj")), obj).expect("obj");
        let image: &[u8] = if name == "bad" { b"not an image" } else { &red };
        std::fs::write(dir.path().join(format!("{name}_diffuse.png")), image).expect("image");
        let scene = load_scene_file(&dir.path().join(format!("{name}.obj")))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(scene.textures.is_empty(), "{name}: {:?}", scene.warnings);
        let used = scene.material(scene.triangles[0].material);
        assert_eq!(used.name, material, "{name}");
        assert!(used.diffuse_map.is_none(), "{name}");
        match warning {
            Some(w) => assert!(
                scene
                    .warnings
                    .iter()
                    .any(|x| x.contains(w) && x.ends_with("they keep the default grey.")),
                "{name}: {:?}",
                scene.warnings
            ),
            None => assert!(
                !scene.warnings.iter().any(|x| x.contains("diffuse")),
                "{name}: {:?}",
                scene.warnings
            ),
        }
    }
}

#[test]
fn map_kd_scale_and_offset_move_the_texture_on_the_texture_coordinates() {
    // The centre pixel meets TRI at (0, 0): barycentric (¼, ¼, ½), so uv = (0.25, 0.5). The
    // texture is two texels, red | blue, whose centres lie at u = 0.25 and 0.75; `-s` and `-o`
    // move the lookup to u · s + o. `-clamp on` keeps the lookup on the image: past an edge
    // it takes that edge's texels (u = 1: blue, where a repeated map blends blue and red).
    let (dir, scene_file) = textured_tri();
    std::fs::write(
        dir.path().join("rb.png"),
        png_bytes(2, 1, &[255, 0, 0, 0, 0, 255]),
    )
    .expect("png");
    for (options, want) in [
        ("", Vec3::X),
        ("-o 0.5 0 0 ", Vec3::Z),
        ("-s 3 1 1 ", Vec3::Z),
        ("-s 2 1 1 ", Vec3::new(0.5, 0.0, 0.5)),
        ("-clamp on -s 2 1 1 -o 0.25 0 ", Vec3::Z),
        ("-o 0.75 0 ", Vec3::new(0.5, 0.0, 0.5)),
        ("-clamp on -o 0.75 0 ", Vec3::Z),
        ("-o 1 0 ", Vec3::X),
        ("-clamp on -o 1 0 ", Vec3::Z),
        ("-clamp on -o -1 0 ", Vec3::X),
        ("-colorspace sRGB -clamp off -o 1 0 ", Vec3::X),
    ] {
        std::fs::write(
            dir.path().join("t.mtl"),
            format!("newmtl t\nKd 1 1 1\nmap_Kd {options}rb.png\n"),
        )
        .expect("mtl");
        let scene = load_scene_file(&scene_file).unwrap_or_else(|e| panic!("{options}: {e}"));
        assert!(scene.warnings.is_empty(), "{options}: {:?}", scene.warnings);
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let tree = pixel_tree(&tracer, 4, 4).expect("centre pixel");
        let hit = tree.root.hit.as_ref().expect("hit");
        let uv = glam::Vec2::from_array(hit.uv.expect("uv"));
        assert!(
            (uv - glam::Vec2::new(0.25, 0.5)).abs().max_element() < 1e-5,
            "{options}: uv {uv}"
        );
        let texel = hit.texel.expect("texel");
        assert!(
            (texel - want).abs().max_element() < 1e-4,
            "{options}: texel {texel}, want {want}"
        );
        // `raytree tree` prints the uv and the texel.
        let text = tree_text(&tree);
        let line = format!(
            ", uv (0.2500, 0.5000), texel (× kd) ({:.4}, {:.4}, {:.4})",
            texel.x, texel.y, texel.z
        );
        assert!(text.contains(&line), "{options}: {line} in {text}");
    }
}

#[test]
fn vertex_colours_multiply_kd_interpolated_at_the_hit() {
    // The centre pixel meets the triangle at barycentric (¼, ¼, ½) (as TRI): red, green and
    // blue corners (sRGB 1, linear 1) give (0.25, 0.25, 0.5); a grey of sRGB 0.5 at every
    // corner gives its linear 0.2140.
    for (colours, want) in [
        (["1 0 0", "0 1 0", "0 0 1"], Vec3::new(0.25, 0.25, 0.5)),
        (["0.5 0.5 0.5"; 3], Vec3::splat(0.214_041)),
        // Two corners without a colour among coloured ones (a file tobj refuses): white.
        (["1 0 0", "", ""], Vec3::new(1.0, 0.75, 0.75)),
    ] {
        let obj = format!(
            "v -1 -1 0 {}\nv 1 -1 0 {}\nv 0 1 0 {}\nf 1 2 3\n",
            colours[0], colours[1], colours[2]
        );
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::write(dir.path().join("c.obj"), obj).expect("obj");
        let scene_file = dir.path().join("s.toml");
        std::fs::write(&scene_file, format!("{CAMERA}[[mesh]]\nfile = \"c.obj\"\n")).expect("toml");
        let scene = load_scene_file(&scene_file).unwrap_or_else(|e| panic!("{e}"));
        if colours.contains(&"") {
            assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
            assert!(
                scene.warnings[0].contains("2 vertices give no colour (`v x y z`) where the others give one (`v x y z r g b`): taken as white"),
                "{:?}",
                scene.warnings
            );
        } else {
            assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        }
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let tree = pixel_tree(&tracer, 4, 4).expect("centre pixel");
        let hit = tree.root.hit.as_ref().expect("hit");
        let texel = hit.texel.expect("the colour multiplies kd");
        assert!(
            (texel - want).abs().max_element() < 1e-4,
            "{colours:?}: {texel}, want {want}"
        );
        // `raytree tree` prints it too.
        let text = tree_text(&tree);
        let line = format!(
            ", vertex colour (× kd) ({:.4}, {:.4}, {:.4})",
            texel.x, texel.y, texel.z
        );
        assert!(text.contains(&line), "{line} in {text}");
        // kd (0.7 by default) × the colour: no other hue.
        let local = tree.root.local.expect("shaded");
        let ratio = local.diffuse / want;
        assert!(
            (ratio - Vec3::splat(ratio.x)).abs().max_element() < 1e-3,
            "{colours:?}: diffuse {} not in the colour's proportions",
            local.diffuse
        );
    }
}

#[test]
fn built_in_textures_are_read_from_the_binary() {
    let scene = load_scene_str_with_files(
        raytree::scene::builtin::scene_text("smooth").expect("smooth"),
        "smooth.toml",
        &raytree::scene::builtin::resolve,
        &raytree::scene::builtin::resolve_bytes,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // Two meshes share one texture.
    assert_eq!(scene.textures.len(), 1);
    assert_eq!(scene.attributes.len(), 2);
    assert!(
        scene.attributes[1].normal_indices.is_empty(),
        "the faceted copy has no normals"
    );
}

/// Faces that give `vn` (`vt`) at some corners or none, in a file whose other faces give them:
/// flat (untextured), not shaded with a neighbour's normal as the OBJ reader fills them in;
/// a face that gives them at some corners only is named in one warning. An index of 0, or a
/// relative one before the first entry, is refused with its line like any index out of range.
#[test]
fn faces_without_normals_at_every_corner_are_flat() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n\
vn 0.3 0 1\nvn 0 0.3 1\n\
f 1//1 2//2 3//1\nf 2 4 3\nf 2//1 5 4//2\nf 1//2 2//2 4//1 3//2\n";
    let list: &'static [(&str, &str)] = Box::leak(Box::new([("m.obj", obj)]));
    let scene = load("[[mesh]]\nfile = \"m.obj\"\n", list);
    assert_eq!(scene.triangles.len(), 5);
    let a = &scene.attributes[0];
    let has: Vec<bool> = (0..5).map(|i| a.normals_of(i).is_some()).collect();
    // The quad's two triangles keep their normals; the face without and the one with `vn` at
    // two corners of three are flat.
    assert_eq!(has, [true, false, false, true, true]);
    assert_eq!(
        scene.warnings,
        ["m.obj: 1 face gives normals (`vn`) at some corners only; it is shaded flat."]
    );
    // The same under `normals = "flat"` and `"smooth"`: no warning about the file's `vn`.
    for mode in ["flat", "smooth"] {
        let s = load(
            &format!("[[mesh]]\nfile = \"m.obj\"\nnormals = \"{mode}\"\n"),
            list,
        );
        assert!(s.warnings.is_empty(), "{mode}: {:?}", s.warnings);
    }

    for (what, face, line) in [
        (
            "vn zero",
            "f 1//1 2//0 3//1",
            "names normal 0, which is not defined: 2 normals (`vn` lines) come before this face",
        ),
        (
            "vn before the first",
            "f 1//-3 2//1 3//1",
            "names normal -3, which is not defined: 2 normals (`vn` lines) come before this face",
        ),
        (
            "vt zero",
            "f 1/0 2/1 3/1",
            "names texture coordinate 0, which is not defined: 1 texture coordinate (a `vt` line) comes",
        ),
        (
            "vt before the first",
            "f 1/1 2/-2 3/1",
            "names texture coordinate -2, which is not defined: 1 texture coordinate (a `vt` line) comes",
        ),
    ] {
        let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nvt 0 0\n{face}\n");
        let list: &'static [(&str, &str)] = Box::leak(Box::new([("z.obj", &*text.leak())]));
        let e = load_scene_str_with("[[mesh]]\nfile = \"z.obj\"\n", "t.toml", &files(list))
            .expect_err(what)
            .to_string();
        let start =
            format!("t.toml:2:8: mesh 1 field `file` cannot be loaded: z.obj:7: `{face}` {line}");
        assert!(e.starts_with(&start), "{what}: {e}");
    }
}

/// The same for texture coordinates: a textured face without `vt` at every corner shows the
/// flat colour, not a neighbour's texel.
#[test]
fn faces_without_texture_coordinates_at_every_corner_are_untextured() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("t.mtl"),
        "newmtl t\nKd 1 1 1\nmap_Kd red.png\n",
    )
    .expect("mtl");
    std::fs::write(dir.path().join("red.png"), png_bytes(1, 1, &[255, 0, 0])).expect("png");
    std::fs::write(
        dir.path().join("m.obj"),
        "mtllib t.mtl\nusemtl t\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
vt 0 0\nvt 1 0\nvt 0 1\n\
f 1/1 2/2 3/3\nf 2 4 3\nf 2/2 4 3/3\n",
    )
    .expect("obj");
    let scene = load_scene_file(&dir.path().join("m.obj")).unwrap_or_else(|e| panic!("{e}"));
    let a = &scene.attributes[0];
    let has: Vec<bool> = (0..3).map(|i| a.uvs_of(i).is_some()).collect();
    assert_eq!(has, [true, false, false]);
    let label = dir.path().join("m.obj").display().to_string();
    assert_eq!(
        scene.warnings,
        [format!(
            "{label}: 1 face gives texture coordinates (`vt`) at some corners only; it is not textured."
        )]
    );
}

#[test]
fn blenders_ka_1_on_a_textured_material_takes_the_texture_too() {
    // A bare OBJ reads `Ka 1` as `Kd`; with `map_Kd` the diffuse colour is the texture's, so
    // the ambient term is textured too: (0.1 ambient light) × Kd × the red texel, no grey.
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("red.png"), png_bytes(1, 1, &[255, 0, 0])).expect("png");
    for kd in ["0.8 0.8 0.8", "1 1 1"] {
        std::fs::write(
            dir.path().join("t.mtl"),
            format!("newmtl t\nKa 1 1 1\nKd {kd}\nmap_Kd red.png\n"),
        )
        .expect("mtl");
        std::fs::write(
            dir.path().join("tri.obj"),
            format!("mtllib t.mtl\nusemtl t\n{TRI}"),
        )
        .expect("obj");
        let scene = load_scene_file(&dir.path().join("tri.obj")).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.contains("`Ka 1` (Blender's default) in `t`")),
            "Kd {kd}: {:?}",
            scene.warnings
        );
        let (width, height) = (scene.render.width, scene.render.height);
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let tree = pixel_tree(&tracer, width / 2, height / 2).expect("centre pixel");
        let ambient = tree.root.local.expect("shaded").ambient;
        let k: f32 = kd
            .split_whitespace()
            .next()
            .and_then(|x| x.parse().ok())
            .expect("kd");
        assert!(
            (ambient - Vec3::new(0.1 * k, 0.0, 0.0)).abs().max_element() < 1e-5,
            "Kd {kd}: ambient {ambient}"
        );
    }
}

/// Vertex normals written for other faces (raylib's `cube.obj`: the `+z` face given `-x` at its
/// corners): a face whose three `vn` lie within 5° of its own plane is shaded flat, with one
/// sentence; one whose normals lean 80° from it keeps them.
const EDGE_ON: &str = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\n\
vn 1 0 0\nvn 0 1 0\nvn 1 1 0.05\n\
f 1//1 2//2 3//3\n";
const LEANING: &str = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\n\
vn 1 0 0.18\nvn 0 1 0.18\nvn 1 1 0.25\n\
f 1//1 2//2 3//3\n";

#[test]
fn normals_in_the_faces_own_plane_are_dropped_for_the_face_normal() {
    // The shading normal at the centre pixel, and the warnings.
    let centre = |name: &'static str, text: &'static str| {
        let scene = load(
            &format!("{CAMERA}[[mesh]]\nfile = \"{name}\"\n"),
            Box::leak(Box::new([(name, text)])),
        );
        let warnings = scene.warnings.clone();
        let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
        let hit = pixel_tree(&tracer, 4, 4)
            .expect("centre")
            .root
            .hit
            .expect("hit");
        (hit.normal, warnings)
    };
    let (normal, warnings) = centre("e.obj", EDGE_ON);
    assert_eq!(
        warnings,
        [
            "e.obj: 1 face has normals (`vn`) lying in the face's own plane, which no surface has there (they belong to other faces); it is shaded flat."
        ]
    );
    assert_eq!(normal, Vec3::Z, "the face's own normal");
    let (normal, warnings) = centre("l.obj", LEANING);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(normal.z < 0.5, "the file's leaning normals: {normal}");
}
