//! Scene loading as the rest of raytree sees it (docs/design.md, "Scene files"): defaults, the
//! value forms, the errors and their places, meshes and their MTL materials, bare OBJ files, the
//! built-in scenes and the TOML round trip.

mod common;

use std::path::Path;

use glam::Vec3;
use raytree::scene::{
    Camera, Material, MaterialId, ObjectId, ObjectSource, RenderParams, Scene, Shading, builtin,
    load_builtin, load_scene_file, load_scene_str, load_scene_str_with, scene_to_toml,
};

/// A resolver over in-memory files, for meshes written inside a test.
fn files(list: &[(&'static str, &'static str)]) -> impl Fn(&str) -> Result<String, String> + use<> {
    let list = list.to_vec();
    move |path: &str| {
        list.iter()
            .find(|(p, _)| *p == path)
            .map(|(_, text)| (*text).to_string())
            .ok_or_else(|| format!("{path}: no such test file"))
    }
}

fn load(text: &str) -> Scene {
    load_scene_str(text, "t.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn load_err(text: &str) -> String {
    match load_scene_str(text, "t.toml") {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn assert_scene_eq(a: &Scene, b: &Scene, what: &str) {
    assert_eq!(a.render, b.render, "{what}: render");
    assert_eq!(a.camera, b.camera, "{what}: camera");
    assert_eq!(a.lights, b.lights, "{what}: lights");
    assert_eq!(a.materials, b.materials, "{what}: materials");
    assert_eq!(a.objects, b.objects, "{what}: objects");
    assert_eq!(a.spheres, b.spheres, "{what}: spheres");
    assert_eq!(a.triangles, b.triangles, "{what}: triangles");
    assert_eq!(a.warnings, b.warnings, "{what}: warnings");
}

fn material<'s>(scene: &'s Scene, name: &str) -> &'s Material {
    scene
        .materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name} in {:?}", names(scene)))
}

fn names(scene: &Scene) -> Vec<&str> {
    scene.materials.iter().map(|m| m.name.as_str()).collect()
}

#[test]
fn defaults_apply_to_everything_left_out() {
    let scene = load("[[sphere]]\n[[light]]\n");
    assert_eq!(scene.render, RenderParams::default());
    assert_eq!(scene.camera, Camera::default());
    // The sphere names no material: the shared "default" one is added, once.
    assert_eq!(scene.materials, vec![Material::default()]);
    assert_eq!(scene.spheres.len(), 1);
    let s = scene.spheres[0];
    assert_eq!((s.center, s.radius), (Vec3::ZERO, 1.0));
    assert_eq!((s.material, s.object), (MaterialId(0), ObjectId(0)));
    assert_eq!(scene.objects[0].name, "sphere 1");
    assert_eq!(scene.objects[0].source, ObjectSource::Sphere);
    let light = &scene.lights[0];
    assert_eq!(light.name, "light 1");
    assert_eq!(light.position, Camera::default().position, "a headlight");
    assert_eq!((light.color, light.radius), (Vec3::ONE, 0.0));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.source, None);
}

#[test]
fn empty_scene_loads() {
    let scene = load("# nothing\n");
    assert!(scene.objects.is_empty() && scene.materials.is_empty() && scene.lights.is_empty());
    assert!(scene.warnings.is_empty());
}

#[test]
fn coefficients_are_scalars_or_rgb_and_integers_are_numbers() {
    let scene = load(
        r#"
        [render]
        background = [0.1, 0.2, 0.3]
        ambient_light = 0.5
        shading = "phong"
        [camera]
        fov_y = 45
        [[material]]
        name = "m"
        ambient = 0
        diffuse = [0.25, 0.5, 1]
        specular = 1
        shininess = 10
        [[sphere]]
        material = "m"
        "#,
    );
    assert_eq!(scene.render.background, Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(scene.render.ambient_light, Vec3::splat(0.5));
    assert_eq!(scene.render.shading, Shading::Phong);
    assert_eq!(scene.camera.fov_y_deg, 45.0);
    let m = material(&scene, "m");
    assert_eq!(m.ambient, Vec3::ZERO);
    assert_eq!(m.diffuse, Vec3::new(0.25, 0.5, 1.0));
    assert_eq!(m.specular, Vec3::ONE);
    assert_eq!(m.shininess, 10.0);
    // Unset fields keep Material::default()'s values.
    assert_eq!(m.ior, Material::default().ior);
    assert_eq!(m.reflectivity, Material::default().reflectivity);
    // "default" is not added: nothing needs it.
    assert_eq!(names(&scene), ["m"]);
}

#[test]
fn errors_give_line_and_column_of_the_value_or_key() {
    // Columns count characters from 1; the value, not the key, is what is wrong.
    assert_eq!(
        load_err("[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\n\n[[sphere]]\n\nradius = -1\n"),
        "t.toml:7:10: sphere 2 field `radius` must be greater than 0, got -1."
    );
    // Inside an array, the offending item.
    assert_eq!(
        load_err("[camera]\n  position = [1, 2, -inf]\n"),
        "t.toml:2:21: camera field `position` must be finite, got -inf."
    );
    // An unknown key: the key itself.
    assert_eq!(
        load_err("[render]\nwidth = 10\n  heigth = 10\n"),
        "t.toml:3:3: render has an unknown field `heigth` (did you mean `height`?); its fields \
         are `width`, `height`, `max_depth`, `samples`, `background`, `ambient_light` and \
         `shading`."
    );
    // A syntax error: where the parser stopped.
    let e = load_err("[render]\nwidth = 1.2.3\n");
    assert!(e.starts_with("t.toml:2:"), "{e}");
    assert!(e.contains("TOML syntax error"), "{e}");
    // Unicode before the error does not shift the column.
    assert_eq!(
        load_err("sphere = [{ name = \"ü\", radius = -2 }]\n")
            .split(": ")
            .next(),
        Some("t.toml:1:34")
    );
}

#[test]
fn validation_covers_every_rule() {
    let cases: &[(&str, &str)] = &[
        (
            "[render]\nheight = 16385",
            "render field `height` must be between 1 and 16384",
        ),
        (
            "[render]\nsamples = 0",
            "render field `samples` must be between 1 and 65536",
        ),
        (
            "[render]\nmax_depth = 65",
            "render field `max_depth` must be at most 64, got 65",
        ),
        (
            "[render]\nmax_depth = -1",
            "render field `max_depth` must be between 0 and 64",
        ),
        (
            "[render]\nwidth = 64.0",
            "render field `width` must be a whole number, got a float",
        ),
        (
            "[render]\nbackground = -1",
            "render field `background` must be at least 0",
        ),
        (
            "[camera]\nfov_y = 180",
            "camera field `fov_y` must be between 0 and 180 degrees",
        ),
        (
            "[camera]\nlook_at = [0, 0, 5]",
            "camera field `look_at` must be a point apart",
        ),
        (
            "[camera]\nup = [0, 0, 0]",
            "camera field `up` must not be the zero vector",
        ),
        (
            "[camera]\nup = [0, 0, 2]",
            "camera field `up` must not be parallel",
        ),
        (
            "[[light]]\nradius = -0.1",
            "light 1 field `radius` must be at least 0",
        ),
        (
            "[[light]]\ncolor = [1, -1, 1]",
            "light 1 field `color` must be at least 0",
        ),
        (
            "[[light]]\nname = \"a\"\n[[light]]\nname = \"a\"",
            "light 2 field `name` repeats",
        ),
        (
            "[[material]]\nior = 0",
            "material 1 field `ior` must be greater than 0",
        ),
        (
            "[[material]]\nshininess = -1",
            "material 1 field `shininess` must be at least 0",
        ),
        (
            "[[material]]\ndiffuse = [1, 2]",
            "must be a number or an array [r, g, b], got an",
        ),
        (
            "[[material]]\nname = \"\"",
            "material 1 field `name` must not be empty",
        ),
        (
            "[[sphere]]\nradius = 0",
            "sphere 1 field `radius` must be greater than 0, got 0",
        ),
        (
            "[[sphere]]\nmaterial = \"x\"",
            "names an unknown material \"x\"; no [[material]]",
        ),
        (
            "[[sphere]]\nname = \"s\"\n[[triangle]]\nname = \"s\"",
            "object names must be unique",
        ),
        (
            "[[triangle]]\nvertices = [[0, 0, 0], [1, 0, 0]]",
            "must be an array of 3 corners",
        ),
        (
            "[[triangle]]\nvertices = [[0,0,0], [1,0,0], [0,nan,0]]",
            "must be finite, got nan",
        ),
        (
            "[[mesh]]\nmaterial = \"default\"",
            "mesh 1 is missing the field `file`",
        ),
        (
            "[[mesh]]\nfile = \"x.obj\"\nscale = [1, 0, 1]",
            "field `scale` must not be 0",
        ),
        (
            "[sphere]\nradius = 1",
            "`sphere` must be written as [[sphere]]",
        ),
        (
            "render = 3",
            "`render` must be written as [render] (a table), got an integer",
        ),
        ("[[light]]\ncolour = 1", "(did you mean `color`?)"),
        (
            "[[sphere]]\ncenter = [0, 0, 1e39]",
            "must be finite, got 1e39",
        ),
    ];
    for (text, wanted) in cases {
        let e = load_err(text);
        assert!(e.contains(wanted), "{text:?}\n gave {e}\n not {wanted}");
        assert!(e.starts_with("t.toml:"), "{e}");
        assert_eq!(e.matches('\n').count(), 0, "one line: {e}");
        assert!(e.ends_with('.'), "{e}");
    }
}

#[test]
fn default_material_and_names_resolve() {
    let scene = load(
        r#"
        [[material]]
        name = "red"
        [[sphere]]
        material = "red"
        [[sphere]]
        material = "default"
        [[triangle]]
        vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
        [[sphere]]
        name = "sphere 1"
        "#,
    );
    assert_eq!(names(&scene), ["red", "default"]);
    let ids: Vec<u32> = scene.spheres.iter().map(|s| s.material.0).collect();
    assert_eq!(ids, [0, 1, 1]);
    assert_eq!(scene.triangles[0].material, MaterialId(1));
    // Objects keep file order across kinds; a default name steps around an explicit one.
    let object_names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        object_names,
        ["sphere 1 2", "sphere 2", "triangle 1", "sphere 1"]
    );
    assert_eq!(scene.triangles[0].object, ObjectId(2));
}

const ONE_TRIANGLE: &str = "v 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n";

#[test]
fn mesh_placement_scales_rotates_and_translates() {
    let resolve = files(&[("tri.obj", ONE_TRIANGLE)]);
    let text = r#"
        [[mesh]]
        file = "tri.obj"
        scale = 2
        rotate = [0, 0, 90]
        translate = [1, 2, 3]
    "#;
    let scene = load_scene_str_with(text, "t.toml", &resolve).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.triangles.len(), 1);
    // (1,0,0) ·2 → (2,0,0), 90° about z → (0,2,0), + (1,2,3) → (1,4,3).
    let v = scene.triangles[0].vertices[0];
    assert!(v.abs_diff_eq(Vec3::new(1.0, 4.0, 3.0), 1e-5), "{v}");
    assert_eq!(scene.objects[0].name, "tri");
    assert_eq!(
        scene.objects[0].source,
        ObjectSource::Mesh {
            file: "tri.obj".into(),
            material: None,
            translate: Vec3::new(1.0, 2.0, 3.0),
            rotate_deg: Vec3::new(0.0, 0.0, 90.0),
            scale: Vec3::splat(2.0),
            normals: raytree::scene::NormalsMode::File,
            crease_angle_deg: 60.0,
        }
    );
    assert_eq!(names(&scene), ["default"]);
}

#[test]
fn mirroring_scale_keeps_the_front_outside() {
    let resolve = files(&[("tri.obj", ONE_TRIANGLE)]);
    let normal = |scale: &str| {
        let text = format!("[[mesh]]\nfile = \"tri.obj\"\nscale = {scale}\n");
        let scene =
            load_scene_str_with(&text, "t.toml", &resolve).unwrap_or_else(|e| panic!("{e}"));
        let [a, b, c] = scene.triangles[0].vertices;
        (b - a).cross(c - a)
    };
    // The triangle faces (1,1,1) outward; mirrored in x it must face (-1,1,1).
    assert!(normal("1").dot(Vec3::ONE) > 0.0);
    assert!(normal("[-1, 1, 1]").dot(Vec3::new(-1.0, 1.0, 1.0)) > 0.0);
}

#[test]
fn degenerate_mesh_triangles_are_dropped_and_counted() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv nan 0 0\n\
               f 1 2 3\nf 1 2 4\nf 1 1 3\nf 1 2 5\nf 3 2 1\n";
    let resolve = files(&[("models/x.obj", obj)]);
    let scene = load_scene_str_with("[[mesh]]\nfile = \"models/x.obj\"\n", "t.toml", &resolve)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.triangles.len(), 2);
    assert_eq!(
        scene.warnings,
        ["models/x.obj: dropped 3 degenerate triangles (zero area or non-finite vertices)."]
    );
}

#[test]
fn mtl_maps_to_phong_materials() {
    let scene = load_scene_file(Path::new("tests/fixtures/models/materials.obj"))
        .unwrap_or_else(|e| panic!("{e}"));
    let d = Material::default();

    let plain = material(&scene, "materials/plain");
    assert_eq!(plain.ambient, Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(plain.diffuse, Vec3::new(0.4, 0.5, 0.6));
    assert_eq!(plain.specular, Vec3::new(0.7, 0.8, 0.9));
    assert_eq!(plain.shininess, 12.0);
    assert_eq!(plain.ior, 1.25);
    assert_eq!(plain.transparency, Vec3::splat(0.25), "1 - d");
    assert_eq!(plain.reflectivity, Vec3::ZERO, "illum 2 does not reflect");

    let mirror = material(&scene, "materials/mirror");
    assert_eq!(
        mirror.reflectivity,
        Vec3::splat(0.8),
        "illum 3: reflectivity = Ks"
    );
    assert_eq!(mirror.transparency, Vec3::ZERO);
    assert_eq!((mirror.ambient, mirror.shininess), (d.ambient, d.shininess));

    let glass = material(&scene, "materials/glass");
    assert_eq!(
        glass.reflectivity,
        Vec3::splat(0.2),
        "illum 7: reflectivity = Ks"
    );
    assert_eq!(glass.transparency, Vec3::splat(0.9), "illum 7 without d");
    assert_eq!(glass.ior, 1.5);

    let tr = material(&scene, "materials/tr");
    assert!(tr.transparency.abs_diff_eq(Vec3::splat(0.4), 1e-6), "Tr");

    let partial = material(&scene, "materials/partial");
    assert_eq!(
        *partial,
        Material {
            name: "materials/partial".into(),
            diffuse: Vec3::X,
            ..Material::default()
        }
    );

    // The face with an undefined `usemtl` uses the default material, with a warning.
    assert_eq!(
        names(&scene),
        [
            "materials/plain",
            "materials/mirror",
            "materials/glass",
            "materials/tr",
            "materials/partial",
            "default"
        ]
    );
    assert_eq!(scene.triangles[5].material, MaterialId(5));
    assert_eq!(
        scene.warnings,
        [
            "tests/fixtures/models/materials.obj: `usemtl` names materials that no material \
             library defines (`nowhere`); their faces use the default material."
        ]
    );
}

/// Maya's exporter writes `illum 4` (glass) and a `Tf` on every material, walls and windows
/// alike, `Tf` meaning opacity: read as plain materials, `Tf` below 1 as glass.
#[test]
fn mayas_illum_4_on_every_material_reads_tf_as_opacity() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = "mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wall\nf 1 2 3\nusemtl window\nf 1 2 3\nusemtl frosted\nf 1 2 3\n";
    let maya = |name: &str, tf: &str| {
        format!(
            "newmtl {name}\nillum 4\nKd 0.50 0.50 0.50\nKa 0.00 0.00 0.00\nTf {tf}\nNi 1.00\nKs 0.50 0.50 0.50\n\n"
        )
    };
    let library = maya("wall", "1.00 1.00 1.00")
        + &maya("window", "0.00 0.00 0.00")
        + &maya("frosted", "0.25 0.50 0.75");
    std::fs::write(dir.path().join("room.obj"), obj).expect("write");
    std::fs::write(dir.path().join("room.mtl"), &library).expect("write");
    let scene = load_scene_file(&dir.path().join("room.obj")).unwrap_or_else(|e| panic!("{e}"));
    let wall = material(&scene, "room/wall");
    assert_eq!(wall.transparency, Vec3::ZERO, "wall: opaque");
    assert_eq!(wall.reflectivity, Vec3::ZERO, "wall: no mirror");
    let window = material(&scene, "room/window");
    assert_eq!(window.transparency, Vec3::ONE, "window: clear");
    assert_eq!(
        window.reflectivity,
        Vec3::splat(0.5),
        "window: glass reflects Ks"
    );
    let frosted = material(&scene, "room/frosted");
    assert!(
        frosted.transparency.abs_diff_eq(Vec3::splat(0.5), 1e-6),
        "frosted: 1 − mean Tf, got {}",
        frosted.transparency
    );
    let note: Vec<&String> = scene
        .warnings
        .iter()
        .filter(|w| w.contains("Maya"))
        .collect();
    assert_eq!(note.len(), 1, "{:?}", scene.warnings);
    assert!(
        note[0].contains("all 3 materials")
            && note[0].contains("the 2 with `Tf` below 1 are glass"),
        "{}",
        note[0]
    );
    // One material with a `d` of its own: the library is no Maya export, and `illum 4`
    // without `d` stays glass.
    let library = maya("wall", "1.00 1.00 1.00")
        + &maya("window", "0.00 0.00 0.00")
        + "newmtl frosted\nKd 1 1 1\nd 1\nillum 2\n";
    std::fs::write(dir.path().join("room.mtl"), &library).expect("write");
    let scene = load_scene_file(&dir.path().join("room.obj")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(material(&scene, "room/wall").transparency, Vec3::splat(0.9));
    assert!(
        !scene.warnings.iter().any(|w| w.contains("Maya")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn material_override_ignores_the_mtl_and_missing_mtl_warns() {
    let obj = "mtllib gone.mtl\nusemtl shiny\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let resolve = files(&[("m/a.obj", obj)]);
    let text = "[[material]]\nname = \"red\"\n[[mesh]]\nfile = \"m/a.obj\"\nmaterial = \"red\"\n";
    let scene = load_scene_str_with(text, "t.toml", &resolve).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(names(&scene), ["red"]);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);

    let scene = load_scene_str_with("[[mesh]]\nfile = \"m/a.obj\"\n", "t.toml", &resolve)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(names(&scene), ["default"]);
    assert_eq!(
        scene.warnings,
        [
            "m/a.obj: cannot read the material library `gone.mtl` (m/gone.mtl: no such test \
             file); its faces use the default material."
        ]
    );
}

#[test]
fn scene_materials_override_mtl_materials_of_the_same_name() {
    let scene = load_scene_file(Path::new("tests/fixtures/models/materials.obj"))
        .unwrap_or_else(|e| panic!("{e}"));
    let text = "[[material]]\nname = \"gem/plain\"\ndiffuse = [0, 1, 0]\n\
                [[mesh]]\nname = \"gem\"\nfile = \"materials.obj\"\n";
    let resolve = raytree::scene::fs_resolver("tests/fixtures/models".into());
    let edited = load_scene_str_with(text, "t.toml", &resolve).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(material(&edited, "gem/plain").diffuse, Vec3::Y);
    assert_eq!(edited.materials.len(), scene.materials.len());
    assert_eq!(edited.triangles[0].material, MaterialId(0));
}

#[test]
fn bare_obj_is_framed_and_lit() {
    let path = Path::new("tests/fixtures/models/materials.obj");
    let scene = load_scene_file(path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.source.as_deref(), Some(path));
    // A low ambient light, so that `Ka 1` does not wash the model out.
    assert_eq!(
        scene.render,
        RenderParams {
            ambient_light: Vec3::splat(0.1),
            ..RenderParams::default()
        }
    );
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].name, "materials");
    assert_eq!(scene.triangles.len(), 6);

    let (lo, hi) = scene.bounds().expect("bounds");
    assert_eq!(
        (lo, hi),
        (Vec3::new(0.0, 0.0, -1.0), Vec3::new(7.0, 1.0, 1.0))
    );
    let c = &scene.camera;
    assert_eq!(c.look_at, 0.5 * (lo + hi));
    assert_eq!(c.fov_y_deg, 45.0);
    assert_eq!(c.up, Vec3::Y);
    let from_center = c.position - c.look_at;
    assert!(
        from_center.z > 0.0 && from_center.y > 0.0,
        "+z side, above: {from_center}"
    );
    // The whole model is in view, and fills it (framed on the bounding sphere, a long model
    // would be a third of the image wide).
    let forward = -from_center.normalize();
    let right = forward.cross(c.up).normalize();
    let up = right.cross(forward);
    let tan_v = (0.5 * c.fov_y_deg).to_radians().tan();
    let tan_h = tan_v * scene.render.width as f32 / scene.render.height as f32;
    let mut fill = 0.0f32;
    for i in 0..8 {
        let pick = |bit: usize, l: f32, h: f32| if i & bit != 0 { h } else { l };
        let corner = Vec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        );
        let d = corner - c.position;
        let z = d.dot(forward);
        assert!(z > 0.0, "corner {corner} behind the camera");
        let f = (d.dot(right).abs() / (z * tan_h)).max(d.dot(up).abs() / (z * tan_v));
        assert!(f <= 1.0, "corner {corner} out of view ({f})");
        fill = fill.max(f);
    }
    assert!(fill > 0.6, "not absurdly far: {fill}");

    assert_eq!(scene.lights.len(), 2);
    let key = &scene.lights[0];
    assert_eq!(
        (key.name.as_str(), key.color, key.radius),
        ("key", Vec3::splat(0.65), 0.0)
    );
    assert!(key.position.y > c.position.y, "above the camera");
    let head = &scene.lights[1];
    assert_eq!(
        (head.name.as_str(), head.position),
        ("headlight", c.position)
    );
}

#[test]
fn builtin_scenes_load_cleanly() {
    // (name, objects, spheres, triangles, lights, materials)
    let expected = [
        ("default", 4, 2, 128 + 576, 2, 5),
        ("quiz", 1, 0, 1, 1, 1),
        ("glass", 4, 1, 128 + 128 + 8, 2, 5),
        ("box", 3, 2, 12, 1, 6),
        ("smooth", 3, 0, 128 + 2 * 224, 2, 4),
        ("acne", 5, 3, 2, 1, 3),
        ("cracks", 1, 0, 128, 1, 1),
    ];
    assert_eq!(builtin::NAMES, expected.map(|e| e.0));
    for (name, objects, spheres, triangles, lights, materials) in expected {
        let scene = load_builtin(name).unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
        assert_eq!(scene.objects.len(), objects, "{name} objects");
        assert_eq!(scene.spheres.len(), spheres, "{name} spheres");
        assert_eq!(scene.triangles.len(), triangles, "{name} triangles");
        assert_eq!(scene.lights.len(), lights, "{name} lights");
        assert_eq!(
            scene.materials.len(),
            materials,
            "{name} materials: {:?}",
            names(&scene)
        );
        assert_eq!(scene.source, None);
        let r = &scene.render;
        assert!(
            r.width <= 640 && r.height <= 480 && r.samples == 1,
            "{name} renders fast"
        );

        // The same file from disk gives the same scene.
        let path = format!("assets/scenes/{name}.toml");
        let from_disk = load_scene_file(Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
        assert_scene_eq(&scene, &from_disk, &path);
        assert_eq!(from_disk.source.as_deref(), Some(Path::new(&path)));
    }
    let e = load_builtin("cornell").expect_err("unknown").to_string();
    assert_eq!(
        e,
        "there is no built-in scene \"cornell\"; the built-in scenes are \"default\", \"quiz\", \
         \"glass\", \"box\", \"smooth\", \"acne\" and \"cracks\"."
    );
}

#[test]
fn quiz_scene_is_the_lecture_quiz() {
    let scene = load_builtin("quiz").unwrap_or_else(|e| panic!("{e}"));
    let r = &scene.render;
    assert!(
        r.width % 2 == 1 && r.height % 2 == 1,
        "a centre pixel exists"
    );
    assert_eq!((r.ambient_light, r.background), (Vec3::ZERO, Vec3::ZERO));
    assert_eq!(r.shading, Shading::BlinnPhong);
    assert_eq!(scene.camera.position, Vec3::ZERO);
    assert_eq!(scene.camera.look_at, Vec3::new(0.0, 0.0, -1.0));
    assert!(
        (0.5 * scene.camera.fov_y_deg).to_radians().tan() > 1.0,
        "whole triangle in view"
    );
    let t = scene.triangles[0];
    let [a1, a2, a3] = t.vertices;
    assert_eq!(a1, Vec3::new(-1.0, -1.0, -1.0));
    assert_eq!(a2, Vec3::new(1.0, -1.0, -1.0));
    assert_eq!(a3, Vec3::new(0.0, 1.0, -1.0));
    assert!(
        (a2 - a1)
            .cross(a3 - a1)
            .normalize()
            .abs_diff_eq(Vec3::Z, 1e-6)
    );
    let m = scene.material(t.material);
    assert_eq!(m.ambient, Vec3::ZERO);
    assert_eq!(m.diffuse, Vec3::splat(std::f32::consts::FRAC_1_SQRT_2));
    assert_eq!(m.specular, Vec3::splat(std::f32::consts::FRAC_1_SQRT_2));
    assert_eq!(m.shininess, 1.0);
    assert_eq!((m.reflectivity, m.transparency), (Vec3::ZERO, Vec3::ZERO));
    let l = &scene.lights[0];
    assert_eq!((l.position, l.color, l.radius), (Vec3::X, Vec3::ONE, 0.0));
}

#[test]
fn scene_to_toml_round_trips_every_builtin_scene() {
    for name in builtin::NAMES {
        let scene = load_builtin(name).unwrap_or_else(|e| panic!("{e}"));
        let text = scene_to_toml(&scene);
        let back = raytree::scene::load_scene_str_with_files(
            &text,
            name,
            &builtin::resolve,
            &builtin::resolve_bytes,
        )
        .unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
        assert_scene_eq(&scene, &back, name);
        // Meshes are written as meshes, not as their triangles.
        let meshes = scene
            .objects
            .iter()
            .filter(|o| matches!(o.source, ObjectSource::Mesh { .. }))
            .count();
        assert_eq!(text.matches("[[mesh]]").count(), meshes, "{name}");
        // And writing again gives the same text.
        assert_eq!(scene_to_toml(&back), text, "{name}");
    }
}

#[test]
fn scene_to_toml_round_trips_odd_values() {
    let text = r#"
        [render]
        background = [0.1, 0.2, 0.30000001]
        [camera]
        fov_y = 33.333333
        [[light]]
        name = "quote \" and \\ and ü"
        [[material]]
        name = "tiny"
        diffuse = 1e-30
        shininess = 3.4e38
        [[triangle]]
        vertices = [[0, 0, 0], [1e-3, 0, 0], [0, 123456.79, 0]]
        material = "tiny"
        [[sphere]]
        center = [-0.0, 1, 2]
    "#;
    let scene = load(text);
    let back = load(&scene_to_toml(&scene));
    assert_scene_eq(&scene, &back, "odd values");
}

#[test]
fn file_kinds_and_missing_files() {
    let e = load_scene_file(Path::new("tests/fixtures/bad/not_a_scene.txt"))
        .expect_err("txt")
        .to_string();
    assert_eq!(
        e,
        "tests/fixtures/bad/not_a_scene.txt: cannot open this kind of file; a scene is a \
         `.toml` file or a bare `.obj` mesh."
    );
    // The extension is matched in any case.
    let e = load_scene_file(Path::new("tests/fixtures/NOPE.TOML"))
        .expect_err("missing")
        .to_string();
    assert_eq!(
        e,
        "tests/fixtures/NOPE.TOML: cannot read the scene file: No such file or directory."
    );
}

/// Every file in `tests/fixtures/bad` fails with one clear sentence; the snapshot is the list.
#[test]
fn bad_scenes_give_one_sentence_each() {
    let mut paths: Vec<_> = std::fs::read_dir("tests/fixtures/bad")
        .expect("fixtures")
        .map(|e| e.expect("entry").path())
        .collect();
    paths.sort();
    paths.push("tests/fixtures/bad/does_not_exist.toml".into());
    let mut report = String::new();
    for path in &paths {
        let name = path.file_name().expect("name").to_string_lossy();
        let message = match load_scene_file(path) {
            Ok(_) => panic!("{} loaded", path.display()),
            Err(e) => e.to_string(),
        };
        assert!(!message.contains('\n'), "{message}");
        assert!(
            message.starts_with(&format!("{}:", path.display())),
            "names the file: {message}"
        );
        report += &format!("{name} => {message}\n");
    }
    insta::assert_snapshot!(report);
}

/// An error in a named item calls it by its name, not by its place.
#[test]
fn an_error_names_a_material_or_light_by_its_name() {
    let err = load_err(
        "[[material]]\nname = \"plain\"\n\n[[material]]\nname = \"glass\"\nior = \"high\"\n",
    );
    assert!(err.contains("material `glass`"), "{err}");
    assert!(!err.contains("material 2"), "{err}");
    let err = load_err("[[light]]\nname = \"key\"\nposition = [0, 1]\n");
    assert!(err.contains("light `key`"), "{err}");
    // Without a name, the place.
    let err = load_err("[[material]]\nior = \"high\"\n");
    assert!(err.contains("material 1"), "{err}");
}

/// An OBJ of one textured triangle per material of `names`, side by side, from the library
/// `mtllib`.
fn textured_triangles(mtllib: &str, names: &[&str]) -> String {
    let mut obj = format!("mtllib {mtllib}\nvt 0 0\nvt 1 0\nvt 0 1\n");
    for (i, m) in names.iter().enumerate() {
        let x = 2.0 * i as f32;
        obj += &format!(
            "usemtl {m}\nv {x} 0 0\nv {} 0 0\nv {x} 1 0\nf {}/1 {}/2 {}/3\n",
            x + 1.0,
            3 * i + 1,
            3 * i + 2,
            3 * i + 3
        );
    }
    obj
}

/// A model copied from another machine: its MTL names textures by that machine's paths (a
/// Windows path, a relative path with `\`, another user's absolute path) and in another case
/// than the files have. Each is found next to the OBJ, with one note listing them; a texture
/// that is nowhere is the usual warning.
#[test]
fn textures_named_by_another_machine_are_found_next_to_the_obj() {
    let dir = tempfile::tempdir().expect("temp dir");
    let checker = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/models/checker.png");
    std::fs::create_dir(dir.path().join("Tex")).expect("folder");
    std::fs::copy(&checker, dir.path().join("Tex/Wood.png")).expect("copy");
    std::fs::copy(&checker, dir.path().join("stone.png")).expect("copy");
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl a\nmap_Kd C:\\Users\\me\\Desktop\\house\\tex\\wood.PNG\n\
         newmtl b\nmap_Kd Tex\\Wood.png\n\
         newmtl c\nmap_Kd /home/someone/house/stone.png\n\
         newmtl d\nmap_Kd TEX/WOOD.PNG\n\
         newmtl e\nmap_Kd nowhere/gone.png\n",
    )
    .expect("write");
    let obj = textured_triangles("m.mtl", &["a", "b", "c", "d", "e"]);
    let path = dir.path().join("m.obj");
    std::fs::write(&path, obj).expect("write");
    let scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    for m in ["a", "b", "c", "d"] {
        assert!(
            material(&scene, &format!("m/{m}")).diffuse_map.is_some(),
            "material {m} has its texture; warnings {:?}",
            scene.warnings
        );
    }
    assert!(material(&scene, "m/e").diffuse_map.is_none());
    // Wood in four spellings and stone, a copy of the same image: one texture in memory.
    assert_eq!(scene.textures.len(), 1, "{:?}", scene.warnings);
    let noted: Vec<&String> = (scene.warnings.iter())
        .filter(|w| w.contains("not where the material library says"))
        .collect();
    assert_eq!(noted.len(), 1, "{:?}", scene.warnings);
    assert!(
        noted[0].contains("3 textures are not where the material library says but found from the OBJ's folder: `C:\\Users\\me\\Desktop\\house\\tex\\wood.PNG` as `tex/wood.PNG` and 2 more"),
        "{}",
        noted[0]
    );
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.contains("cannot use the texture `nowhere/gone.png`")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn git_lfs_pointers_in_place_of_a_model_or_a_texture_are_named_as_such() {
    // A repository cloned without `git lfs` leaves these three lines where each file should be.
    let pointer = "version https://git-lfs.github.com/spec/v1\n\
        oid sha256:df14845c86933fbf75aa31c04c62ad78d18e5f1a72e43cf4d30c6d7353c12bcc\n\
        size 22342871\n";
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("big.obj"), pointer).expect("write");
    std::fs::write(dir.path().join("wood.png"), pointer).expect("write");
    std::fs::write(
        dir.path().join("q.mtl"),
        "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd wood.png\n",
    )
    .expect("write");
    std::fs::write(
        dir.path().join("q.obj"),
        "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n",
    )
    .expect("write");
    std::fs::write(dir.path().join("s.toml"), "[[mesh]]\nfile = \"big.obj\"\n").expect("write");
    let lfs = "it is a Git LFS pointer, not the file itself: the file (21.3 MiB) was never \
        downloaded; `git lfs pull` in its repository fetches it";
    // The model itself, opened directly and through a scene file: refused, saying why.
    for name in ["big.obj", "s.toml"] {
        let err = load_scene_file(&dir.path().join(name))
            .err()
            .unwrap_or_else(|| panic!("{name} loaded from a pointer"))
            .to_string();
        assert!(err.contains(lfs), "{name}: {err}");
    }
    // A texture: the model loads, the material keeps its flat colour, the warning says why.
    let scene = load_scene_file(&dir.path().join("q.obj")).unwrap_or_else(|e| panic!("{e}"));
    assert!(material(&scene, "q/a").diffuse_map.is_none());
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.contains("`wood.png`") && w.contains(lfs)),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn a_material_library_named_by_another_machine_is_found_next_to_the_obj() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("house.mtl"),
        "newmtl brick\nKd 0.7 0.2 0.1\n",
    )
    .expect("write");
    std::fs::write(
        dir.path().join("house.obj"),
        "mtllib C:\\Users\\me\\Desktop\\house\\House.MTL\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl brick\nf 1 2 3\n",
    )
    .expect("write");
    let scene = load_scene_file(&dir.path().join("house.obj")).unwrap_or_else(|e| panic!("{e}"));
    let brick = material(&scene, "house/brick");
    assert!(
        (brick.diffuse - glam::Vec3::new(0.7, 0.2, 0.1))
            .abs()
            .max_element()
            < 1e-6,
        "{brick:?}; warnings {:?}",
        scene.warnings
    );
    assert!(
        scene.warnings.iter().any(|w| w.contains(
            "the material library `C:\\Users\\me\\Desktop\\house\\House.MTL` is not where the OBJ says but found from its folder as `House.MTL`"
        )),
        "{:?}",
        scene.warnings
    );
    // One that is nowhere keeps the reason of the name as written.
    std::fs::write(
        dir.path().join("lost.obj"),
        "mtllib D:\\gone\\lost.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .expect("write");
    let lost = load_scene_file(&dir.path().join("lost.obj")).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        lost.warnings.iter().any(|w| w
            .contains("cannot read the material library `D:\\gone\\lost.mtl` (")
            && w.contains("No such file")),
        "{:?}",
        lost.warnings
    );
}

/// A model pack keeps its textures in a folder beside the models' (bullet3's `data/toys/` names
/// `E:\develop\bullet3\data\table\table.png`, the file being `data/table/table.png`): a tail
/// of the path that keeps its folder is found one or two folders up; a bare file name is not
/// looked for there.
#[test]
fn a_texture_in_a_folder_beside_the_models_is_found_by_its_folder() {
    let dir = tempfile::tempdir().expect("temp dir");
    let checker = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/models/checker.png");
    for folder in ["data/table", "data/toys/box", "elsewhere"] {
        std::fs::create_dir_all(dir.path().join(folder)).expect("folder");
    }
    std::fs::copy(&checker, dir.path().join("data/table/table.png")).expect("copy");
    std::fs::copy(&checker, dir.path().join("data/stray.png")).expect("copy");
    std::fs::write(
        dir.path().join("data/toys/box/sorter.mtl"),
        "newmtl a\nmap_Kd E:\\develop\\bullet3\\data\\table\\table.png\n\
         newmtl b\nmap_Kd C:\\stray.png\n",
    )
    .expect("write");
    let obj = textured_triangles("sorter.mtl", &["a", "b"]);
    let path = dir.path().join("data/toys/box/sorter.obj");
    std::fs::write(&path, obj).expect("write");
    let scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        material(&scene, "sorter/a").diffuse_map.is_some(),
        "{:?}",
        scene.warnings
    );
    assert!(material(&scene, "sorter/b").diffuse_map.is_none());
    assert!(
        scene.warnings.iter().any(|w| w.contains(
            "a texture is not where the material library says but found from the OBJ's folder: `E:\\develop\\bullet3\\data\\table\\table.png` as `../../table/table.png`"
        )),
        "{:?}",
        scene.warnings
    );
}

/// Game assets' textures: DDS files named by an MTL load, uncompressed to the texels a PNG of
/// the same image gives, BC1 to the colours its blocks hold, and a cube map as its first face;
/// one cut short is a warning with a reason, the flat colour staying.
#[test]
fn dds_textures_load_uncompressed_bc1_and_a_cube_maps_first_face() {
    use image_dds::ddsfile::DxgiFormat;
    let dir = tempfile::tempdir().expect("temp dir");
    let rgb = [255u8, 0, 0, 0, 128, 255, 10, 20, 30, 255, 255, 255];
    let png = image::RgbImage::from_raw(2, 2, rgb.to_vec()).expect("2x2");
    png.save(dir.path().join("plain.png")).expect("png");
    let rgba: Vec<u8> = rgb
        .chunks(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    let plain = common::dds(DxgiFormat::R8G8B8A8_UNorm_sRGB, (2, 2), false, rgba);
    // One BC1 block: colour 0 red (RGB565 F800), colour 1 blue (001F); two bits a texel, a
    // byte a row: rows 0 and 1 take colour 0, rows 2 and 3 colour 1.
    let block = [0x00, 0xF8, 0x1F, 0x00, 0x00, 0x00, 0x55, 0x55];
    let bc1 = common::dds(DxgiFormat::BC1_UNorm_sRGB, (4, 4), false, block.to_vec());
    // Six faces, the first all red (every index 0).
    let mut faces = vec![0x00, 0xF8, 0x1F, 0x00, 0, 0, 0, 0];
    for _ in 0..5 {
        faces.extend(block);
    }
    let cube = common::dds(DxgiFormat::BC1_UNorm, (4, 4), true, faces);
    let cut = bc1[..bc1.len() - 4].to_vec();
    for (name, bytes) in [
        ("plain.dds", plain),
        ("brick.DDS", bc1),
        ("sky.dds", cube),
        ("cut.dds", cut),
    ] {
        std::fs::write(dir.path().join(name), bytes).expect("write");
    }
    let mut mtl = String::new();
    let mut obj = String::from("mtllib m.mtl\nvt 0 0\nvt 1 0\nvt 0 1\n");
    let maps = ["plain.png", "plain.dds", "brick.DDS", "sky.dds", "cut.dds"];
    for (i, map) in maps.iter().enumerate() {
        mtl += &format!("newmtl m{i}\nKd 1 1 1\nmap_Kd {map}\n");
        let x = 2 * i;
        obj += &format!(
            "usemtl m{i}\nv {x} 0 0\nv {} 0 0\nv {x} 1 0\nf {}/1 {}/2 {}/3\n",
            x + 1,
            3 * i + 1,
            3 * i + 2,
            3 * i + 3
        );
    }
    std::fs::write(dir.path().join("m.mtl"), mtl).expect("write");
    std::fs::write(dir.path().join("m.obj"), obj).expect("write");
    let scene = load_scene_file(&dir.path().join("m.obj")).unwrap_or_else(|e| panic!("{e}"));
    let texture = |i: usize| {
        let id = material(&scene, &format!("m/m{i}"))
            .diffuse_map
            .unwrap_or_else(|| panic!("m{i} has its texture: {:?}", scene.warnings));
        scene.textures[id.0 as usize].clone()
    };
    let (png, plain) = (texture(0), texture(1));
    assert_eq!((plain.width, plain.height), (2, 2));
    assert_eq!(plain.texels, png.texels, "uncompressed DDS against the PNG");
    let brick = texture(2);
    assert_eq!((brick.width, brick.height), (4, 4));
    for (i, texel) in brick.texels.iter().enumerate() {
        let want = if i < 8 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        assert_eq!(*texel, want, "BC1 texel {i}");
    }
    let sky = texture(3);
    assert_eq!((sky.width, sky.height), (4, 4));
    assert!(
        sky.texels.iter().all(|&c| c == [1.0, 0.0, 0.0]),
        "the cube map's first face"
    );
    assert!(material(&scene, "m/m4").diffuse_map.is_none());
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.contains("cannot use the texture `cut.dds`") && w.contains("(cannot")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn several_material_libraries_on_one_mtllib_line_are_all_read() {
    // The format allows `mtllib a.mtl b.mtl`; a name with a space (`my model.mtl`, as Blender
    // writes it) is still one file when there is one.
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("a.mtl"), "newmtl red\nKd 1 0 0\n").expect("write");
    std::fs::write(dir.path().join("b.mtl"), "newmtl green\nKd 0 1 0\n").expect("write");
    std::fs::write(dir.path().join("my model.mtl"), "newmtl blue\nKd 0 0 1\n").expect("write");
    let faces = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl green\nf 1 3 2\n";
    std::fs::write(
        dir.path().join("two.obj"),
        format!("mtllib a.mtl b.mtl\n{faces}"),
    )
    .expect("write");
    let scene = load_scene_file(&dir.path().join("two.obj")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        material(&scene, "two/red").diffuse,
        Vec3::X,
        "{:?}",
        scene.warnings
    );
    assert_eq!(
        material(&scene, "two/green").diffuse,
        Vec3::Y,
        "{:?}",
        scene.warnings
    );
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // One of the two missing: the other's materials are used, the missing one is named.
    std::fs::write(
        dir.path().join("half.obj"),
        format!("mtllib a.mtl gone.mtl\n{faces}"),
    )
    .expect("write");
    let half = load_scene_file(&dir.path().join("half.obj")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(material(&half, "half/red").diffuse, Vec3::X);
    assert!(
        half.warnings
            .iter()
            .any(|w| w.contains("cannot read the material library `gone.mtl`")),
        "{:?}",
        half.warnings
    );
    std::fs::write(
        dir.path().join("spaced.obj"),
        "mtllib my model.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl blue\nf 1 2 3\n",
    )
    .expect("write");
    let spaced = load_scene_file(&dir.path().join("spaced.obj")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        material(&spaced, "spaced/blue").diffuse,
        Vec3::Z,
        "{:?}",
        spaced.warnings
    );
}

#[test]
fn windows_byte_order_marks_and_continued_lines_read_as_meant() {
    // Notepad and some exporters start a file with a UTF-8 byte-order mark; the OBJ format
    // lets a long face go on on the next line after a `\`. Both lost a vertex or the file.
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("m.mtl"),
        "\u{FEFF}newmtl red\r\nKd 1 0 0\r\n",
    )
    .expect("write");
    std::fs::write(
        dir.path().join("m.obj"),
        "\u{FEFF}v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\nmtllib m.mtl\r\nusemtl red\r\nf 1 2 \\\r\n 3 4\r\n",
    )
    .expect("write");
    let scene = load_scene_file(&dir.path().join("m.obj")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.triangles.len(), 2, "the quad over two lines");
    assert_eq!(
        material(&scene, "m/red").diffuse,
        Vec3::X,
        "{:?}",
        scene.warnings
    );
    assert!(
        scene.warnings.iter().all(|w| !w.contains("usemtl")),
        "{:?}",
        scene.warnings
    );
    // A scene file with a mark.
    std::fs::write(
        dir.path().join("s.toml"),
        "\u{FEFF}[render]\nwidth = 32\n[[mesh]]\nfile = \"m.obj\"\n",
    )
    .expect("write");
    let scene = load_scene_file(&dir.path().join("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.render.width, 32);
    // After a continued face, an error still names its own line (8).
    std::fs::write(
        dir.path().join("bad.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 \\\n 3 4\nv 1 2 3\nv 1 x 2\n",
    )
    .expect("write");
    let err = load_scene_file(&dir.path().join("bad.obj"))
        .expect_err("refused")
        .to_string();
    assert!(err.contains("bad.obj:8:"), "{err}");
}

#[test]
fn files_other_tools_write_read_as_meant() {
    let dir = tempfile::tempdir().expect("temp dir");
    // Writes `files` (name, bytes) and loads the last, an OBJ.
    let load = |files: &[(&str, Vec<u8>)]| -> Scene {
        for (name, bytes) in files {
            std::fs::write(dir.path().join(name), bytes).expect("write");
        }
        let obj = dir.path().join(files[files.len() - 1].0);
        load_scene_file(&obj).unwrap_or_else(|e| panic!("{e}"))
    };
    let text = |t: &str| t.as_bytes().to_vec();
    let diffuse = |scene: &Scene, name: &str, want: Vec3| {
        assert_eq!(material(scene, name).diffuse, want, "{:?}", scene.warnings);
    };

    // UTF-16 text (Notepad's "Unicode"), big- and little-endian, for the OBJ and its MTL.
    let utf16 = |text: &str, big: bool| -> Vec<u8> {
        let mut out = if big {
            vec![0xFE, 0xFF]
        } else {
            vec![0xFF, 0xFE]
        };
        for unit in text.encode_utf16() {
            out.extend(if big {
                unit.to_be_bytes()
            } else {
                unit.to_le_bytes()
            });
        }
        out
    };
    let scene = load(&[
        ("u.mtl", utf16("newmtl red\r\nKd 1 0 0\r\n", false)),
        (
            "u.obj",
            utf16(
                "mtllib u.mtl\r\nv 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nusemtl red\r\nf 1 2 3\r\n",
                true,
            ),
        ),
    ]);
    assert_eq!(scene.triangles.len(), 1);
    diffuse(&scene, "u/red", Vec3::X);

    // A material without a name (`newmtl` and `usemtl` alone), which tobj refuses.
    let scene = load(&[
        ("n.mtl", text("newmtl \nKd 0 0 1\n")),
        (
            "n.obj",
            text("mtllib n.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl \nf 1 2 3\n"),
        ),
    ]);
    diffuse(&scene, "n/(no name)", Vec3::Z);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);

    // Old Windows spellings of what is not a number: the face on such vertices is dropped as
    // any non-finite one, the rest shows.
    let scene = load(&[(
        "nan.obj",
        text(
            "v 1.#IND -1.#IND 1.#IND\nv 1.#INF -1.#INF 1.#INF\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 3 4 5\n",
        ),
    )]);
    assert_eq!(scene.triangles.len(), 1);
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.contains("dropped 1 degenerate triangle")),
        "{:?}",
        scene.warnings
    );

    // `mtllib` names with spaces written `\ `, beside a missing library.
    let scene = load(&[
        ("my mats.mtl", text("newmtl green\nKd 0 1 0\n")),
        (
            "e.obj",
            text(
                "mtllib gone.mtl my\\ mats.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl green\nf 1 2 3\n",
            ),
        ),
    ]);
    diffuse(&scene, "e/green", Vec3::Y);
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(
        scene.warnings[0].contains("`gone.mtl`")
            && scene.warnings[0].contains("the other libraries on its `mtllib` line are read"),
        "{:?}",
        scene.warnings
    );
}
