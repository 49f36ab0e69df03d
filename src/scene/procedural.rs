//! The benchmark scene, generated rather than shipped: Whitted's picture with a
//! finely subdivided mesh. A bumpy torus of about `N` triangles stands behind a mirror sphere
//! and a glass sphere over a two-triangle floor, lit by two point lights; 640×480, 1 sample,
//! depth 4 below the primary ray.
//!
//! The scene is written as an ordinary scene file (`bench.toml`) and OBJ mesh
//! (`bench_mesh.obj`) and read back through the normal loader, so `raytree render` on the same
//! files reproduces the benchmark, the load phase is measured on the real path, and the peer
//! renderer (`benches/peer/`) is handed exactly the triangles raytree traces.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::{
    Camera, Light, Material, MaterialId, Object, ObjectId, ObjectSource, RenderParams, Scene,
    Shading, Sphere, Triangle, scene_to_toml,
};

/// Name of the scene file [`write_bench_scene`] writes.
pub const BENCH_SCENE_FILE: &str = "bench.toml";
/// Name of the mesh file it references.
pub const BENCH_MESH_FILE: &str = "bench_mesh.obj";

/// Grid of the torus for about `triangles` triangles: `(segments around the ring, segments
/// around the tube)`, with `2·nu·nv` triangles and `nu = 4·nv` (cells about square).
pub fn torus_grid(triangles: usize) -> (usize, usize) {
    let nv = ((triangles as f64 / 8.0).sqrt().round() as usize).max(3);
    (4 * nv, nv)
}

/// Triangles the torus of [`torus_grid`]`(triangles)` has.
pub fn torus_triangles(triangles: usize) -> usize {
    let (nu, nv) = torus_grid(triangles);
    2 * nu * nv
}

/// The mesh as OBJ text: a torus (ring radius 1.35, tube radius 0.5) with bumps on the
/// tube, tilted towards the camera; `nu·nv` shared vertices, faces counter-clockwise from
/// outside. Every coordinate is written as the shortest text that reads back as the same `f32`.
pub fn bumpy_torus_obj(triangles: usize) -> String {
    let (nu, nv) = torus_grid(triangles);
    let (ring, tube) = (1.35f64, 0.5f64);
    let (tilt_s, tilt_c) = 1.1f64.sin_cos();
    let center = [0.1f64, 1.25, -2.4];
    let mut out = String::with_capacity(nu * nv * 60);
    let _ = writeln!(
        out,
        "# raytree benchmark mesh: bumpy torus, {} triangles",
        2 * nu * nv
    );
    for i in 0..nu {
        let u = std::f64::consts::TAU * i as f64 / nu as f64;
        for j in 0..nv {
            let v = std::f64::consts::TAU * j as f64 / nv as f64;
            let r = tube * (1.0 + 0.12 * (9.0 * u).sin() * (6.0 * v).sin());
            let (su, cu) = u.sin_cos();
            let (sv, cv) = v.sin_cos();
            // Torus in the xz plane, then tilted about x so the hole faces the camera.
            let (x, y, z) = ((ring + r * cv) * cu, r * sv, (ring + r * cv) * su);
            let (y, z) = (y * tilt_c - z * tilt_s, y * tilt_s + z * tilt_c);
            let p = [
                (x + center[0]) as f32,
                (y + center[1]) as f32,
                (z + center[2]) as f32,
            ];
            let _ = writeln!(out, "v {:?} {:?} {:?}", p[0], p[1], p[2]);
        }
    }
    // OBJ indices start at 1.
    let index = |i: usize, j: usize| (i % nu) * nv + (j % nv) + 1;
    for i in 0..nu {
        for j in 0..nv {
            let (a, b) = (index(i, j), index(i + 1, j));
            let (c, d) = (index(i + 1, j + 1), index(i, j + 1));
            let _ = writeln!(out, "f {a} {d} {c}\nf {a} {c} {b}");
        }
    }
    out
}

/// The scene around the mesh (everything but the mesh's triangles, which live in the OBJ).
pub fn bench_scene_frame() -> Scene {
    let material = |name: &str, diffuse: Vec3, specular: f32, shininess: f32| Material {
        name: name.into(),
        ambient: diffuse * 0.5,
        diffuse,
        specular: Vec3::splat(specular),
        shininess,
        ..Material::default()
    };
    let materials = vec![
        material("clay", Vec3::new(0.75, 0.45, 0.3), 0.3, 40.0),
        material("floor", Vec3::splat(0.6), 0.1, 10.0),
        Material {
            name: "mirror".into(),
            ambient: Vec3::splat(0.02),
            diffuse: Vec3::splat(0.05),
            specular: Vec3::splat(0.8),
            shininess: 200.0,
            reflectivity: Vec3::splat(0.85),
            ..Material::default()
        },
        Material {
            name: "glass".into(),
            ambient: Vec3::ZERO,
            diffuse: Vec3::splat(0.02),
            specular: Vec3::splat(0.7),
            shininess: 200.0,
            reflectivity: Vec3::splat(0.08),
            transparency: Vec3::splat(0.9),
            ior: 1.5,
            ..Material::default()
        },
    ];
    let object = |name: &str, source: ObjectSource| Object {
        name: name.into(),
        source,
    };
    let objects = vec![
        object(
            "mesh",
            ObjectSource::Mesh {
                file: BENCH_MESH_FILE.into(),
                material: Some("clay".into()),
                translate: Vec3::ZERO,
                rotate_deg: Vec3::ZERO,
                scale: Vec3::ONE,
                normals: Default::default(),
                crease_angle_deg: super::DEFAULT_CREASE_ANGLE_DEG,
            },
        ),
        object("floor a", ObjectSource::Triangle),
        object("floor b", ObjectSource::Triangle),
        object("mirror sphere", ObjectSource::Sphere),
        object("glass sphere", ObjectSource::Sphere),
    ];
    let f = 12.0;
    let corners = [
        Vec3::new(-f, 0.0, f),
        Vec3::new(f, 0.0, f),
        Vec3::new(f, 0.0, -f),
        Vec3::new(-f, 0.0, -f),
    ];
    let floor = |vertices: [Vec3; 3], object: u32| Triangle {
        vertices,
        material: MaterialId(1),
        object: ObjectId(object),
    };
    Scene {
        render: RenderParams {
            width: 640,
            height: 480,
            max_depth: 4,
            samples: 1,
            background: Vec3::new(0.1, 0.12, 0.17),
            ambient_light: Vec3::splat(0.2),
            shading: Shading::BlinnPhong,
        },
        camera: Camera {
            position: Vec3::new(0.0, 1.7, 6.5),
            look_at: Vec3::new(0.0, 0.9, 0.0),
            up: Vec3::Y,
            fov_y_deg: 45.0,
        },
        lights: vec![
            Light {
                name: "key".into(),
                position: Vec3::new(-4.0, 6.0, 5.0),
                color: Vec3::splat(0.75),
                radius: 0.0,
                follow_camera: false,
            },
            Light {
                name: "fill".into(),
                position: Vec3::new(3.5, 5.0, 2.0),
                color: Vec3::splat(0.45),
                radius: 0.0,
                follow_camera: false,
            },
        ],
        materials,
        objects,
        spheres: vec![
            Sphere {
                center: Vec3::new(1.45, 1.0, -0.6),
                radius: 1.0,
                material: MaterialId(2),
                object: ObjectId(3),
            },
            Sphere {
                center: Vec3::new(-1.0, 0.75, 1.5),
                radius: 0.75,
                material: MaterialId(3),
                object: ObjectId(4),
            },
        ],
        triangles: std::sync::Arc::new(vec![
            floor([corners[0], corners[1], corners[2]], 1),
            floor([corners[0], corners[2], corners[3]], 2),
        ]),
        ..Scene::default()
    }
}

/// Writes [`BENCH_SCENE_FILE`] and [`BENCH_MESH_FILE`] with a mesh of about `triangles`
/// triangles into `dir`; returns the scene file's path.
pub fn write_bench_scene(dir: &Path, triangles: usize) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join(BENCH_MESH_FILE), bumpy_torus_obj(triangles))?;
    let path = dir.join(BENCH_SCENE_FILE);
    let text = format!(
        "# The benchmark scene, {} mesh triangles (generated by raytree::scene::procedural).\n{}",
        torus_triangles(triangles),
        scene_to_toml(&bench_scene_frame())
    );
    std::fs::write(&path, text)?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bench_scene_loads_with_every_triangle() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = write_bench_scene(dir.path(), 1000).expect("write");
        let scene = crate::scene::load_scene_file(&path).expect("load");
        assert_eq!(torus_grid(1000), (44, 11));
        assert_eq!(scene.triangles.len(), torus_triangles(1000) + 2);
        assert_eq!(scene.spheres.len(), 2);
        assert_eq!(scene.lights.len(), 2);
        assert_eq!(scene.render.max_depth, 4);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    }
}
