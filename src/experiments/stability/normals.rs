//! N1-N3: shading normals on flat triangles (docs/stability.md, rows N1 to N3). The shadow
//! terminator, reflected and refracted directions that cross into the surface they leave,
//! light leaking through a wall whose normals face a light behind it.

use std::sync::Arc;

use glam::Vec3;
use serde::Serialize;

use super::{Row, StabilityOptions, chart, fmt_g, pct, yes_if};
use crate::accel::AccelKind;
use crate::experiments::chart::{Chart, Series};
use crate::experiments::meshes::octasphere;
use crate::geometry::{Methods, Ray, ShadingNormals};
use crate::rng::Pcg;
use crate::scene::{
    Light, Material, MaterialId, MeshAttributes, Object, ObjectId, ObjectSource, Scene, Triangle,
};
use crate::trace::{
    RayCounts, RayKind, Recorder, SampleInfo, ShadowTest, SurfaceHit, TraceSettings, Tracer,
};

// =============================================================================================
// What N1–N3 share: a smooth mesh and the first hit of a traced ray

/// What the measurements of N1–N3 need from one traced primary ray: its hit's normals, the
/// first light's shadow test, and the directions (and corrections) of its children. A
/// [`Recorder`] over the tracer's own code, so the measured behaviour is the renderer's.
#[derive(Default)]
struct FirstHit {
    depth: Vec<u32>,
    shading: Option<Vec3>,
    geometric: Option<Vec3>,
    shadow: Option<ShadowTest>,
    /// (reflected?, direction, corrected) of each child of the primary hit.
    children: Vec<(bool, Vec3, bool)>,
}

impl Recorder for FirstHit {
    const ENABLED: bool = true;
    fn enter(&mut self, kind: RayKind, depth: u32, ray: &Ray, _weight: Vec3) {
        self.depth.push(depth);
        if depth == 1 {
            self.children
                .push((kind == RayKind::Reflected, ray.dir, false));
        }
    }
    fn direction_corrected(&mut self) {
        if self.depth.last() == Some(&1)
            && let Some(c) = self.children.last_mut()
        {
            c.2 = true;
        }
    }
    fn hit(&mut self, hit: &SurfaceHit, _view: Vec3) {
        if self.depth.last() == Some(&0) {
            self.shading = Some(hit.normal);
            self.geometric = Some(hit.geometric_normal);
        }
    }
    fn shadow(&mut self, test: &ShadowTest) {
        if self.depth.last() == Some(&0) && self.shadow.is_none() {
            self.shadow = Some(*test);
        }
    }
    fn leave(&mut self, _color: Vec3) {
        self.depth.pop();
    }
}

/// A scene of one mesh given as vertices, triangles and unit vertex normals (shared by index),
/// material `material`, lit by white point light `light`, no ambient light, depth `max_depth`.
pub fn smooth_mesh_scene(
    verts: &[Vec3],
    tris: &[[usize; 3]],
    normals: &[Vec3],
    material: Material,
    light: Vec3,
    max_depth: u32,
) -> Scene {
    let mut scene = Scene {
        materials: vec![material],
        objects: vec![Object {
            name: "mesh".into(),
            source: ObjectSource::Triangle,
        }],
        lights: vec![Light {
            name: "light".into(),
            position: light,
            color: Vec3::ONE,
            radius: 0.0,
            follow_camera: false,
        }],
        ..Scene::default()
    };
    scene.render.ambient_light = Vec3::ZERO;
    scene.render.max_depth = max_depth;
    scene.triangles = tris
        .iter()
        .map(|t| Triangle {
            vertices: t.map(|i| verts[i]),
            material: MaterialId(0),
            object: ObjectId(0),
        })
        .collect::<Vec<_>>()
        .into();
    scene.attributes.push(Arc::new(MeshAttributes {
        first_triangle: 0,
        triangle_count: tris.len() as u32,
        normals: normals.to_vec(),
        normal_indices: tris.iter().map(|t| t.map(|i| i as u32)).collect(),
        ..MeshAttributes::default()
    }));
    scene
}

fn tracer_for(scene: Scene, shading_normals: ShadingNormals) -> Tracer {
    let settings = TraceSettings {
        accel: AccelKind::Bvh,
        methods: Methods {
            shading_normals,
            ..Methods::default()
        },
        cutoff: 0.0,
    };
    Tracer::new(Arc::new(scene), settings)
}

fn trace_first(tracer: &Tracer, ray: &Ray) -> (Vec3, FirstHit) {
    let mut rec = FirstHit::default();
    let mut counts = RayCounts::default();
    let mut info = SampleInfo::default();
    let c = tracer.trace(
        ray,
        RayKind::Primary,
        0,
        Vec3::ONE,
        &mut counts,
        &mut info,
        &mut rec,
    );
    (c, rec)
}

// =============================================================================================
// N1: the shadow terminator (Hanika 2021)

/// One cell of N1: a unit octasphere of `8·4^level` triangles with exact (radial) vertex
/// normals, diffuse only, lit by a distant light, sampled at `n` points spread uniformly over
/// the sphere (each ray aimed at the centre).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TerminatorCell {
    pub triangles: usize,
    /// Samples whose shading normal faces the light (`N·L > 0`).
    pub lit_by_normal: usize,
    /// Of those, the ones the mesh shadows itself (blocked by its own triangles, or — robust —
    /// counted as behind the geometric surface).
    pub self_shadowed: usize,
    /// The widest self-shadowed band: the largest `N·L` of a self-shadowed sample, as the angle
    /// above the terminator in degrees.
    pub band_deg: f64,
    /// The angle between neighbouring vertex normals (the facets' curvature error), degrees.
    pub facet_deg: f64,
    /// Mean |mesh − analytic sphere| of the diffuse value over all samples.
    pub mean_err: f64,
    /// The same for the shadow-free smooth mesh (`max(N·L, 0)`): the flat-free limit.
    pub limit_err: f64,
}

/// N1 at one tessellation level and light direction `to_light`.
pub fn terminator_cell(
    shading_normals: ShadingNormals,
    level: u32,
    to_light: Vec3,
    n: usize,
    rng: &mut Pcg,
) -> TerminatorCell {
    let (verts, tris) = octasphere(level, 1.0, Vec3::ZERO);
    let material = Material {
        ambient: Vec3::ZERO,
        diffuse: Vec3::ONE,
        specular: Vec3::ZERO,
        ..Material::default()
    };
    let l = to_light.normalize();
    let scene = smooth_mesh_scene(&verts, &tris, &verts, material, 1e3 * l, 0);
    let tracer = tracer_for(scene, shading_normals);
    let facet_deg = tris.first().map_or(0.0, |t| {
        verts[t[0]].angle_between(verts[t[1]]).to_degrees() as f64
    });
    let mut cell = TerminatorCell {
        triangles: tris.len(),
        facet_deg,
        ..TerminatorCell::default()
    };
    let (mut err, mut limit) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let q = rng.unit();
        let ray = Ray::new(3.0 * q, -q);
        let (c, rec) = trace_first(&tracer, &ray);
        // The analytic sphere's value where the same ray meets it (at q, normal q).
        let analytic = q.dot((1e3 * l - q).normalize()).max(0.0);
        err += f64::from((c.x - analytic).abs());
        let (Some(ns), Some(test)) = (rec.shading, rec.shadow) else {
            continue;
        };
        let ideal = ns.dot(test.to_light).max(0.0);
        limit += f64::from((ideal - analytic).abs());
        if ns.dot(test.to_light) > 0.0 {
            cell.lit_by_normal += 1;
            let shadowed = test.behind_surface || test.blocked_by == Some(ObjectId(0));
            if shadowed {
                cell.self_shadowed += 1;
                let above = f64::from(ns.dot(test.to_light))
                    .clamp(-1.0, 1.0)
                    .asin()
                    .to_degrees();
                cell.band_deg = cell.band_deg.max(above);
            }
        }
    }
    cell.mean_err = err / n.max(1) as f64;
    cell.limit_err = limit / n.max(1) as f64;
    cell
}

/// N1 sweeps the octasphere from 32 to 8192 triangles (levels 1…5; N2 takes levels 1, 3, 5).
const N_LEVELS: [u32; 5] = [1, 2, 3, 4, 5];

pub(super) fn row_n1(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let lights = [
        Vec3::new(0.3, 0.8, 0.5),
        Vec3::new(1.0, 0.1, 0.0),
        Vec3::new(-0.2, -0.5, 0.9),
    ];
    let mut series = Vec::new();
    let (mut naive_text, mut robust_ok, mut naive_fails) = (Vec::new(), true, true);
    let (mut worst_band, mut worst_ratio) = (0.0f64, 0.0f64);
    for (m, name) in [
        (ShadingNormals::Naive, "naive"),
        (ShadingNormals::Robust, "robust"),
    ] {
        let mut points = Vec::new();
        for &level in &N_LEVELS {
            let seed = rng.next_u32();
            let cells: Vec<TerminatorCell> = lights
                .iter()
                .map(|&l| terminator_cell(m, level, l, o.rays, &mut Pcg::new(u64::from(seed))))
                .collect();
            let lit: usize = cells.iter().map(|c| c.lit_by_normal).sum();
            let shadowed: usize = cells.iter().map(|c| c.self_shadowed).sum();
            let band = cells.iter().map(|c| c.band_deg).fold(0.0, f64::max);
            let err: f64 = cells.iter().map(|c| c.mean_err).sum::<f64>() / cells.len() as f64;
            let limit: f64 = cells.iter().map(|c| c.limit_err).sum::<f64>() / cells.len() as f64;
            let facet = cells[0].facet_deg;
            let tris = cells[0].triangles;
            points.push((tris as f64, pct(shadowed, lit)));
            match m {
                ShadingNormals::Naive => {
                    naive_fails &= shadowed > 0;
                    naive_text.push(format!(
                        "{tris} tris: {:.1}% self-shadowed, band {band:.1}° (facet {facet:.1}°), error {} vs limit {}",
                        pct(shadowed, lit),
                        fmt_g(err),
                        fmt_g(limit)
                    ));
                }
                ShadingNormals::Robust => {
                    robust_ok &= band <= facet && err <= 2.0 * limit + 1e-7;
                    worst_band = worst_band.max(band);
                    worst_ratio = worst_ratio.max(err / limit.max(1e-12));
                }
            }
        }
        series.push(Series::new(name, points));
    }
    Row {
        id: "N1",
        failure: "shadow terminator: the flat triangle shadows what its shading normal lights",
        naive_method: "shadow ray from the flat hit point",
        robust_method: "Hanika 2021: from the hit point projected on the vertex tangent planes",
        sweep: format!(
            "unit octaspheres of 32…8192 triangles with exact vertex normals, 3 light directions, {} rays each",
            o.rays
        ),
        naive: naive_text.join("; "),
        robust: format!(
            "widest self-shadowed band {worst_band:.1}°; error vs the analytic sphere at most {worst_ratio:.2}× the shadow-free limit"
        ),
        target: "no self-shadowed band wider than one facet's curvature error; error within 2× the flat-free limit",
        verdict: yes_if(robust_ok && naive_fails),
        chart: Some(chart(
            "N1: lit-by-shading-normal samples shadowed by their own mesh",
            "triangles",
            "% self-shadowed",
            false,
            series,
        )),
    }
}

// =============================================================================================
// N2: reflected and refracted directions on the wrong side

/// One cell of N2: reflected (or refracted) directions about the shading normal of a smooth
/// octasphere, for rays meeting it at `view_deg` from its (analytic) normal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SideCell {
    pub triangles: usize,
    pub view_deg: f32,
    pub children: usize,
    /// Children on the wrong side of the geometric plane of the surface they leave.
    pub wrong_side: usize,
    /// Children the tracer marked as corrected.
    pub corrected: usize,
}

/// N2 at one tessellation level and view angle from the shading normal; `refract`: a glass sphere (its refracted
/// children), else a mirror (its reflected children).
pub fn side_cell(
    shading_normals: ShadingNormals,
    level: u32,
    view_deg: f32,
    refract: bool,
    n: usize,
    rng: &mut Pcg,
) -> SideCell {
    let (verts, tris) = octasphere(level, 1.0, Vec3::ZERO);
    let material = Material {
        reflectivity: Vec3::splat(if refract { 0.0 } else { 1.0 }),
        transparency: Vec3::splat(if refract { 1.0 } else { 0.0 }),
        ior: 1.5,
        ..Material::default()
    };
    let scene = smooth_mesh_scene(&verts, &tris, &verts, material, Vec3::splat(100.0), 1);
    let tracer = tracer_for(scene, shading_normals);
    let mut cell = SideCell {
        triangles: tris.len(),
        view_deg,
        ..SideCell::default()
    };
    let theta = view_deg.to_radians();
    for _ in 0..n {
        // A point spread over the mesh, and a ray meeting it at `view_deg` from its shading
        // normal (from outside; a ray coming at the face from behind meets another first).
        let tri = tris[rng.below(tris.len())];
        let (mut b1, mut b2) = (rng.f32(), rng.f32());
        if b1 + b2 > 1.0 {
            (b1, b2) = (1.0 - b1, 1.0 - b2);
        }
        let b = [1.0 - b1 - b2, b1, b2];
        let p = b[0] * verts[tri[0]] + b[1] * verts[tri[1]] + b[2] * verts[tri[2]];
        let ns = p.normalize();
        let t = rng.perpendicular(ns);
        let d = -(theta.cos() * ns + theta.sin() * t);
        let ray = Ray::new(p - 3.0 * d, d);
        let (_, rec) = trace_first(&tracer, &ray);
        let Some(ng) = rec.geometric else { continue };
        for &(reflected, dir, corrected) in &rec.children {
            if reflected == refract {
                continue;
            }
            cell.children += 1;
            let side = dir.dot(ng);
            let wrong = if reflected { side <= 0.0 } else { side >= 0.0 };
            cell.wrong_side += usize::from(wrong);
            cell.corrected += usize::from(corrected);
        }
    }
    cell
}

pub(super) fn row_n2(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let views = [0.0f32, 30.0, 60.0, 75.0, 85.0, 89.0];
    let mut series = Vec::new();
    let mut naive_text = Vec::new();
    let (mut robust_wrong, mut naive_wrong, mut corrected) = (0usize, 0usize, 0usize);
    for level in [1u32, 3, 5] {
        // The same rays for both methods.
        let seeds: Vec<u64> = views.iter().map(|_| u64::from(rng.next_u32())).collect();
        for (m, name) in [
            (ShadingNormals::Naive, "naive"),
            (ShadingNormals::Robust, "robust"),
        ] {
            let mut points = Vec::new();
            let mut worst = (0.0f64, 0.0f32);
            for (&view, &seed) in views.iter().zip(&seeds) {
                let c = side_cell(m, level, view, false, o.rays, &mut Pcg::new(seed));
                let t = side_cell(m, level, view, true, o.rays / 4, &mut Pcg::new(seed));
                let wrong = c.wrong_side + t.wrong_side;
                let all = c.children + t.children;
                points.push((f64::from(90.0 - view), pct(wrong, all)));
                if pct(wrong, all) > worst.0 {
                    worst = (pct(wrong, all), view);
                }
                match m {
                    ShadingNormals::Naive => naive_wrong += wrong,
                    ShadingNormals::Robust => {
                        robust_wrong += wrong;
                        corrected += c.corrected + t.corrected;
                    }
                }
            }
            if m == ShadingNormals::Naive {
                naive_text.push(format!(
                    "{} tris: up to {:.1}% (at {}° from the normal)",
                    8 << (2 * level),
                    worst.0,
                    worst.1
                ));
            }
            series.push(Series::new(
                format!("{name}, {} tris", 8 << (2 * level)),
                points,
            ));
        }
    }
    Row {
        id: "N2",
        failure: "reflected/refracted direction crosses into the surface it leaves",
        naive_method: "R and T about the shading normal, as they come",
        robust_method: "mirrored back across the geometric plane; the tree marks it",
        sweep: format!(
            "octaspheres of 32, 512, 8192 triangles; view 0…89° from the shading normal; mirror ({} rays) and glass ({} rays)",
            o.rays,
            o.rays / 4
        ),
        naive: format!(
            "{}; refraction into glass never crosses",
            naive_text.join(", ")
        ),
        robust: format!(
            "{robust_wrong} on the wrong side; {corrected} bent back and marked corrected (naive: {naive_wrong} wrong)"
        ),
        target: "0% after correction; the tree says when a direction was corrected",
        // Same seeds for both methods: every naive crossing is a marked correction.
        verdict: yes_if(robust_wrong == 0 && naive_wrong > 0 && corrected == naive_wrong),
        chart: Some(Chart {
            x_log: false,
            ..chart(
                "N2: secondary directions on the wrong side of the geometric plane",
                "angle of the view above the surface (°)",
                "% of R and T",
                false,
                series,
            )
        }),
    }
}

// =============================================================================================
// N3: light leaking through a wall

/// One cell of N3: a large flat wall (the plane z = 0, seen from z > 0) whose vertex normals
/// are tilted by `tilt_deg`, and a light behind it at `below_deg` under its plane; the share
/// of the wall's samples that the light reaches through it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LeakCell3 {
    pub tilt_deg: f32,
    pub below_deg: f32,
    pub samples: usize,
    /// Samples whose shading normal faces the light (the candidates for a leak).
    pub facing: usize,
    /// Samples lit by the light behind the wall.
    pub leaks: usize,
}

/// N3 at one normal tilt and light angle.
pub fn leak_cell(
    shading_normals: ShadingNormals,
    tilt_deg: f32,
    below_deg: f32,
    n: usize,
    rng: &mut Pcg,
) -> LeakCell3 {
    // A 2×2 grid of quads over ±100, so the wall separates the light from every sample.
    let s = 100.0;
    let verts: Vec<Vec3> = (0..9)
        .map(|i| Vec3::new(((i % 3) as f32 - 1.0) * s, ((i / 3) as f32 - 1.0) * s, 0.0))
        .collect();
    let mut tris = Vec::new();
    for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let a = y * 3 + x;
        tris.push([a, a + 1, a + 4]);
        tris.push([a, a + 4, a + 3]);
    }
    // Normals tilted towards +x (alternating direction by vertex, as a badly exported file).
    let tilt = tilt_deg.to_radians();
    let normals: Vec<Vec3> = (0..9)
        .map(|i| {
            let sign = if i % 2 == 0 { 1.0 } else { 0.5 };
            Vec3::new(sign * tilt.sin(), 0.0, tilt.cos()).normalize()
        })
        .collect();
    let below = below_deg.to_radians();
    // The light behind the wall, towards +x: the tilted normals face it.
    let light = Vec3::new(20.0 * below.cos(), 0.0, -20.0 * below.sin());
    let scene = smooth_mesh_scene(&verts, &tris, &normals, Material::default(), light, 0);
    let tracer = tracer_for(scene, shading_normals);
    let mut cell = LeakCell3 {
        tilt_deg,
        below_deg,
        ..LeakCell3::default()
    };
    for _ in 0..n {
        let p = Vec3::new(rng.range(-20.0, 20.0), rng.range(-20.0, 20.0), 0.0);
        let ray = Ray::new(p + Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        let (_, rec) = trace_first(&tracer, &ray);
        let Some(test) = rec.shadow else { continue };
        cell.samples += 1;
        if test.terms.n_dot_l > 0.0 {
            cell.facing += 1;
            if test.blocked_by.is_none() && !test.behind_surface {
                cell.leaks += 1;
            }
        }
    }
    cell
}

pub(super) fn row_n3(o: &StabilityOptions, rng: &mut Pcg) -> Row {
    let mut series = Vec::new();
    let (mut naive_leaks, mut naive_facing, mut robust_leaks, mut robust_facing) = (0, 0, 0, 0);
    let belows = [0.5f32, 1.0, 2.0, 5.0, 10.0, 20.0, 40.0];
    for tilt in [5.0f32, 20.0, 45.0] {
        for (m, name) in [
            (ShadingNormals::Naive, "naive"),
            (ShadingNormals::Robust, "robust"),
        ] {
            let mut points = Vec::new();
            for &below in &belows {
                let seed = u64::from(rng.next_u32());
                let c = leak_cell(m, tilt, below, o.rays, &mut Pcg::new(seed));
                points.push((f64::from(below), pct(c.leaks, c.samples)));
                match m {
                    ShadingNormals::Naive => {
                        naive_leaks += c.leaks;
                        naive_facing += c.facing;
                    }
                    ShadingNormals::Robust => {
                        robust_leaks += c.leaks;
                        robust_facing += c.facing;
                    }
                }
            }
            series.push(Series::new(
                format!("{name}, normals tilted {tilt}°"),
                points,
            ));
        }
    }
    Row {
        id: "N3",
        failure: "light leaks: the shading normal faces a light behind the geometric surface",
        naive_method: "shadow ray offset to the light's side (through the surface)",
        robust_method: "shadow ray from the visible side (smooth surface), else the light adds nothing",
        sweep: format!(
            "a wall with vertex normals tilted 5°, 20°, 45°; light 0.5…40° behind its plane; {} rays each",
            o.rays
        ),
        naive: format!(
            "{:.1}% of samples lit from behind ({naive_leaks} of the {naive_facing} whose shading normal faces the light)",
            pct(naive_leaks, o.rays * belows.len() * 3)
        ),
        robust: format!("{robust_leaks} of {robust_facing} lit from behind"),
        target: "0%",
        verdict: yes_if(robust_leaks == 0 && naive_leaks > 0),
        chart: Some(chart(
            "N3: samples lit by a light behind the surface",
            "light angle below the surface (°)",
            "% of samples",
            false,
            series,
        )),
    }
}
