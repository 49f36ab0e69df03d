//! One validation: the rules the viewer holds its edits to (`scene::rules::check_scene`) are
//! the rules the loader holds files to. Property test (proptest, seeded, deterministic): any
//! edit the viewer accepts saves a scene that loads back equal; any edit it refuses saves a
//! scene the loader refuses too, naming the same field. The edits reach every field a scene
//! file has: render, camera, each light's name, position, colour and radius, materials,
//! spheres, and each mesh's `normals` and `crease_angle`.

use std::cell::Cell;

use glam::Vec3;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use raytree::scene::builtin::{self, NAMES, load_builtin};
use raytree::scene::{Light, NormalsMode, ObjectSource, Scene, rules, scene_to_toml};

/// Numbers an edit may bring: ordinary ones, the edges of every rule, and hostile ones.
const NUMBERS: &[f32] = &[
    0.0,
    -0.0,
    0.5,
    1.0,
    -1.0,
    2.5,
    45.0,
    179.9,
    180.0,
    1e-30,
    -1e-30,
    1e15,
    -1e15,
    1.0000001e15,
    1e16,
    3e38,
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
];

/// Whole numbers an edit may bring to the `[render]` counts.
const COUNTS: &[u32] = &[
    0,
    1,
    2,
    7,
    64,
    65,
    640,
    16384,
    16385,
    65536,
    65537,
    u32::MAX,
];

#[derive(Clone, Debug)]
enum Edit {
    Count(usize, u32),
    RenderColor(usize, usize, f32),
    Camera(usize, usize, f32),
    Fov(f32),
    AddLight,
    Light(usize, usize, usize, f32),
    LightRadius(usize, f32),
    Material(usize, usize, usize, f32),
    MaterialScalar(usize, usize, f32),
    Sphere(usize, usize, f32),
    SphereRadius(usize, f32),
    LightName(usize, usize),
    MeshNormals(usize, usize),
    CreaseAngle(usize, f32),
}

/// Names a light may be given: unusual ones (escaping, blanks, another light's name), so that
/// saving quotes them right and a repeated name is refused by both sides.
const NAMES_FOR_LIGHTS: &[&str] = &[
    "",
    " ",
    "a \"quoted\" name",
    "back\\slash",
    "line\nbreak",
    "tab\there",
    "ünïcödé ☀",
    "[[light]]",
    "# not a comment",
    "key",
    "light 1",
    "added 2",
];

fn number() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => proptest::sample::select(NUMBERS),
        1 => -100.0f32..100.0,
    ]
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (0..4usize, proptest::sample::select(COUNTS)).prop_map(|(f, n)| Edit::Count(f, n)),
        (0..2usize, 0..3usize, number()).prop_map(|(f, c, x)| Edit::RenderColor(f, c, x)),
        (0..3usize, 0..3usize, number()).prop_map(|(f, c, x)| Edit::Camera(f, c, x)),
        number().prop_map(Edit::Fov),
        Just(Edit::AddLight),
        (0..4usize, 0..2usize, 0..3usize, number())
            .prop_map(|(i, f, c, x)| Edit::Light(i, f, c, x)),
        (0..4usize, number()).prop_map(|(i, x)| Edit::LightRadius(i, x)),
        (0..8usize, 0..5usize, 0..3usize, number())
            .prop_map(|(i, f, c, x)| Edit::Material(i, f, c, x)),
        (0..8usize, 0..2usize, number()).prop_map(|(i, f, x)| Edit::MaterialScalar(i, f, x)),
        (0..8usize, 0..3usize, number()).prop_map(|(i, c, x)| Edit::Sphere(i, c, x)),
        (0..8usize, number()).prop_map(|(i, x)| Edit::SphereRadius(i, x)),
        (0..4usize, 0..NAMES_FOR_LIGHTS.len()).prop_map(|(i, n)| Edit::LightName(i, n)),
        (0..4usize, 0..3usize).prop_map(|(i, m)| Edit::MeshNormals(i, m)),
        (0..4usize, number()).prop_map(|(i, x)| Edit::CreaseAngle(i, x)),
    ]
}

fn set(v: &mut Vec3, component: usize, x: f32) {
    v[component] = x;
}

/// Carries out `e` as the viewer's panels would (they edit the working copy in place).
fn apply(scene: &mut Scene, e: &Edit) {
    let r = &mut scene.render;
    match *e {
        Edit::Count(f, n) => {
            *[
                &mut r.width,
                &mut r.height,
                &mut r.max_depth,
                &mut r.samples,
            ][f] = n
        }
        Edit::RenderColor(f, c, x) => set([&mut r.background, &mut r.ambient_light][f], c, x),
        Edit::Camera(f, c, x) => {
            let cam = &mut scene.camera;
            set([&mut cam.position, &mut cam.look_at, &mut cam.up][f], c, x);
        }
        Edit::Fov(x) => scene.camera.fov_y_deg = x,
        Edit::AddLight => {
            let n = scene.lights.len() + 1;
            scene.lights.push(Light {
                name: format!("added {n}"),
                position: Vec3::new(1.0, 3.0, 2.0),
                color: Vec3::ONE,
                radius: 0.0,
                follow_camera: false,
            });
        }
        Edit::Light(i, f, c, x) => {
            let n = scene.lights.len();
            if let Some(l) = scene.lights.get_mut(i % n.max(1)) {
                set([&mut l.position, &mut l.color][f], c, x);
            }
        }
        Edit::LightRadius(i, x) => {
            let n = scene.lights.len();
            if let Some(l) = scene.lights.get_mut(i % n.max(1)) {
                l.radius = x;
            }
        }
        Edit::Material(i, f, c, x) => {
            let n = scene.materials.len();
            if let Some(m) = scene.materials.get_mut(i % n.max(1)) {
                let fields = [
                    &mut m.ambient,
                    &mut m.diffuse,
                    &mut m.specular,
                    &mut m.reflectivity,
                    &mut m.transparency,
                ];
                set(fields.into_iter().nth(f).expect("five fields"), c, x);
            }
        }
        Edit::MaterialScalar(i, f, x) => {
            let n = scene.materials.len();
            if let Some(m) = scene.materials.get_mut(i % n.max(1)) {
                *[&mut m.shininess, &mut m.ior][f] = x;
            }
        }
        Edit::Sphere(i, c, x) => {
            let n = scene.spheres.len();
            if let Some(s) = scene.spheres.get_mut(i % n.max(1)) {
                set(&mut s.center, c, x);
            }
        }
        Edit::SphereRadius(i, x) => {
            let n = scene.spheres.len();
            if let Some(s) = scene.spheres.get_mut(i % n.max(1)) {
                s.radius = x;
            }
        }
        Edit::LightName(i, name) => {
            let n = scene.lights.len();
            if let Some(l) = scene.lights.get_mut(i % n.max(1)) {
                l.name = NAMES_FOR_LIGHTS[name].to_string();
            }
        }
        Edit::MeshNormals(i, mode) => {
            if let Some(ObjectSource::Mesh { normals, .. }) = mesh(scene, i) {
                *normals = [NormalsMode::File, NormalsMode::Flat, NormalsMode::Smooth][mode];
            }
        }
        Edit::CreaseAngle(i, x) => {
            if let Some(ObjectSource::Mesh {
                crease_angle_deg, ..
            }) = mesh(scene, i)
            {
                *crease_angle_deg = x;
            }
        }
    }
}

/// The source of the `i`-th mesh object (modulo their number), if the scene has meshes.
fn mesh(scene: &mut Scene, i: usize) -> Option<&mut ObjectSource> {
    let mut meshes: Vec<&mut ObjectSource> = scene
        .objects
        .iter_mut()
        .map(|o| &mut o.source)
        .filter(|s| matches!(s, ObjectSource::Mesh { .. }))
        .collect();
    let n = meshes.len();
    (n > 0).then(|| meshes.swap_remove(i % n))
}

fn runner(cases: u32) -> TestRunner {
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &[11; 32]))
}

#[test]
fn an_edit_the_viewer_accepts_saves_a_scene_that_loads_and_a_refused_one_does_not() {
    let bases: Vec<(&str, Scene)> = NAMES
        .iter()
        .map(|&n| (n, load_builtin(n).expect("built-in scenes load")))
        .collect();
    let accepted = Cell::new(0u32);
    let refused = Cell::new(0u32);
    // Cases whose edits changed a mesh's `normals` or `crease_angle`, or a light's name.
    let sources_accepted = Cell::new(0u32);
    let sources_refused = Cell::new(0u32);
    let strategy = (0..bases.len(), proptest::collection::vec(edit(), 1..5));
    runner(3000)
        .run(&strategy, |(which, edits)| {
            let (name, base) = &bases[which];
            let mut scene = base.clone();
            for e in &edits {
                apply(&mut scene, e);
            }
            let text = scene_to_toml(&scene);
            let loaded = raytree::scene::load_scene_str_with_files(
                &text,
                name,
                &builtin::resolve,
                &builtin::resolve_bytes,
            );
            let changed = scene.objects != base.objects
                || scene
                    .lights
                    .iter()
                    .zip(&base.lights)
                    .any(|(a, b)| a.name != b.name);
            match rules::check_scene(&scene, true) {
                Ok(()) => {
                    accepted.set(accepted.get() + 1);
                    sources_accepted.set(sources_accepted.get() + u32::from(changed));
                    let back = loaded.map_err(|e| {
                        TestCaseError::fail(format!("accepted, but does not load: {e}\n{text}"))
                    })?;
                    prop_assert_eq!(&back.render, &scene.render);
                    prop_assert_eq!(&back.camera, &scene.camera);
                    prop_assert_eq!(&back.lights, &scene.lights);
                    prop_assert_eq!(&back.materials, &scene.materials);
                    prop_assert_eq!(&back.spheres, &scene.spheres);
                    prop_assert_eq!(&back.triangles, &scene.triangles);
                    prop_assert_eq!(&back.objects, &scene.objects);
                    // And the text is a fixed point.
                    prop_assert_eq!(scene_to_toml(&back), text);
                }
                Err(verdict) => {
                    refused.set(refused.get() + 1);
                    sources_refused.set(sources_refused.get() + u32::from(changed));
                    let error = match loaded {
                        Ok(_) => {
                            return Err(TestCaseError::fail(format!(
                                "refused ({verdict}), but its file loads:\n{text}"
                            )));
                        }
                        Err(e) => e.to_string(),
                    };
                    // Both name the same field of the same kind of section.
                    let field = verdict
                        .split('`')
                        .nth(1)
                        .expect("the verdict names a field");
                    prop_assert!(
                        error.contains(&format!("field `{field}`")),
                        "viewer: {}\nloader: {}",
                        verdict,
                        error
                    );
                }
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    // Both sides of the property were exercised, on every kind of edit.
    let (accepted, refused) = (accepted.get(), refused.get());
    assert!(
        accepted > 300 && refused > 300,
        "{accepted} accepted, {refused} refused"
    );
    let (sources_accepted, sources_refused) = (sources_accepted.get(), sources_refused.get());
    assert!(
        sources_accepted > 100 && sources_refused > 100,
        "edits of mesh normals and light names: {sources_accepted} accepted, {sources_refused} \
         refused"
    );
}
