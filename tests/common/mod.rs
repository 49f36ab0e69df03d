//! Hand-made test scenes shared by the integration tests.
#![allow(dead_code)]

use std::sync::Arc;

use glam::Vec3;
use raytree::accel::AccelKind;
use raytree::render::render;
use raytree::scene::{
    Camera, Light, Material, MaterialId, Object, ObjectId, ObjectSource, RenderParams, Scene,
    Shading, Sphere, Triangle,
};
use raytree::trace::{TraceSettings, Tracer};

pub fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

/// A scene builder for hand-made test scenes.
pub struct Build(pub Scene);

impl Build {
    pub fn new(camera: Camera, width: u32, height: u32) -> Self {
        Build(Scene {
            render: RenderParams {
                width,
                height,
                max_depth: 5,
                samples: 1,
                background: Vec3::new(0.05, 0.1, 0.15),
                ambient_light: Vec3::splat(0.5),
                shading: Shading::BlinnPhong,
            },
            camera,
            ..Scene::default()
        })
    }

    pub fn material(mut self, m: Material) -> Self {
        self.0.materials.push(m);
        self
    }

    pub fn light(mut self, position: Vec3, color: Vec3) -> Self {
        let name = format!("light {}", self.0.lights.len() + 1);
        self.0.lights.push(Light {
            name,
            position,
            color,
            radius: 0.0,
            follow_camera: false,
        });
        self
    }

    pub fn sphere(mut self, name: &str, center: Vec3, radius: f32, material: u32) -> Self {
        let object = ObjectId(self.0.objects.len() as u32);
        self.0.objects.push(Object {
            name: name.into(),
            source: ObjectSource::Sphere,
        });
        self.0.spheres.push(Sphere {
            center,
            radius,
            material: MaterialId(material),
            object,
        });
        self
    }

    pub fn quad(mut self, name: &str, corners: [Vec3; 4], material: u32) -> Self {
        let object = ObjectId(self.0.objects.len() as u32);
        self.0.objects.push(Object {
            name: name.into(),
            source: ObjectSource::Triangle,
        });
        for vertices in [
            [corners[0], corners[1], corners[2]],
            [corners[0], corners[2], corners[3]],
        ] {
            std::sync::Arc::make_mut(&mut self.0.triangles).push(Triangle {
                vertices,
                material: MaterialId(material),
                object,
            });
        }
        self
    }

    pub fn triangle(mut self, name: &str, vertices: [Vec3; 3], material: u32) -> Self {
        let object = ObjectId(self.0.objects.len() as u32);
        self.0.objects.push(Object {
            name: name.into(),
            source: ObjectSource::Triangle,
        });
        std::sync::Arc::make_mut(&mut self.0.triangles).push(Triangle {
            vertices,
            material: MaterialId(material),
            object,
        });
        self
    }

    pub fn visible_light(mut self, name: &str, position: Vec3, color: Vec3, radius: f32) -> Self {
        self.0.lights.push(Light {
            name: name.into(),
            position,
            color,
            radius,
            follow_camera: false,
        });
        self
    }

    pub fn tracer(&self) -> Tracer {
        Tracer::new(Arc::new(self.0.clone()), TraceSettings::default())
    }

    pub fn pixel(&self, x: u32, y: u32, accel: AccelKind) -> Vec3 {
        let tracer = Tracer::new(
            Arc::new(self.0.clone()),
            TraceSettings {
                accel,
                ..TraceSettings::default()
            },
        );
        let (image, _) = render(&tracer, 1, 1, &|_, _| {}).expect("render");
        image.get(x, y)
    }
}

pub fn looking(position: Vec3, look_at: Vec3, fov_y_deg: f32) -> Camera {
    Camera {
        position,
        look_at,
        up: Vec3::Y,
        fov_y_deg,
    }
}

pub fn mat(name: &str, ka: Vec3, kd: Vec3, ks: f32, n: f32, kr: f32) -> Material {
    Material {
        name: name.into(),
        ambient: ka,
        diffuse: kd,
        specular: Vec3::splat(ks),
        shininess: n,
        reflectivity: Vec3::splat(kr),
        transparency: Vec3::ZERO,
        ior: 1.5,
        ..Material::default()
    }
}

/// A square of half-size `half` in the plane z = `z`, counter-clockwise seen from +z (its front
/// faces +z) or from −z.
pub fn wall_z(z: f32, half: f32, front_towards_plus_z: bool) -> [Vec3; 4] {
    let (a, b) = (-half, half);
    if front_towards_plus_z {
        [
            Vec3::new(a, a, z),
            Vec3::new(b, a, z),
            Vec3::new(b, b, z),
            Vec3::new(a, b, z),
        ]
    } else {
        [
            Vec3::new(a, a, z),
            Vec3::new(a, b, z),
            Vec3::new(b, b, z),
            Vec3::new(b, a, z),
        ]
    }
}

/// The floor y = −1 facing up, 10 wide to either side and from z = 10 to z = −20.
pub fn floor() -> [Vec3; 4] {
    [
        Vec3::new(-10.0, -1.0, 10.0),
        Vec3::new(10.0, -1.0, 10.0),
        Vec3::new(10.0, -1.0, -20.0),
        Vec3::new(-10.0, -1.0, -20.0),
    ]
}

/// A DDS file of `format` and `width`×`height` (a cube map of six faces when `cube`), holding
/// `data`.
pub fn dds(
    format: image_dds::ddsfile::DxgiFormat,
    (width, height): (u32, u32),
    cube: bool,
    data: Vec<u8>,
) -> Vec<u8> {
    use image_dds::ddsfile::{AlphaMode, D3D10ResourceDimension, Dds, NewDxgiParams};
    let mut dds = Dds::new_dxgi(NewDxgiParams {
        height,
        width,
        depth: None,
        format,
        mipmap_levels: None,
        array_layers: None,
        caps2: None,
        is_cubemap: cube,
        resource_dimension: D3D10ResourceDimension::Texture2D,
        alpha_mode: AlphaMode::Straight,
    })
    .expect("a DDS header");
    dds.data = data;
    let mut out = Vec::new();
    dds.write(&mut out).expect("writes");
    out
}
