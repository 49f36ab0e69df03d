//! What the hostile-input tests (`tests/hostile.rs`, `tests/fuzz.rs`) check of every scene the
//! loader accepts and every error it gives: the invariants of `Scene` (docs/design.md, "Scene
//! files"; docs/reliability.md) and the shape of an error (one line, naming the file).

#![allow(dead_code)] // each test crate uses its own part

use std::collections::HashSet;
use std::sync::Arc;

use glam::Vec3;
use raytree::render::render;
use raytree::scene::Scene;
use raytree::scene::rules::MAX_COORDINATE;
use raytree::trace::{TraceSettings, Tracer};

/// Every number finite, sizes in range, radii > 0, triangles of non-zero area, ids in range,
/// names unique, a usable camera; `Err` says which rule broke.
pub fn check_invariants(scene: &Scene) -> Result<(), String> {
    // Finite, and within raytree's limit on scene size (the BVH's arithmetic needs it).
    let finite = |v: Vec3| v.is_finite() && v.abs().max_element() <= MAX_COORDINATE;
    let colour = |v: Vec3| v.is_finite() && v.cmpge(Vec3::ZERO).all();
    let r = &scene.render;
    ensure((1..=16384).contains(&r.width), "width in 1..=16384")?;
    ensure((1..=16384).contains(&r.height), "height in 1..=16384")?;
    ensure((1..=65536).contains(&r.samples), "samples in 1..=65536")?;
    ensure(r.max_depth <= 64, "max_depth ≤ 64")?;
    ensure(colour(r.background), "background finite, ≥ 0")?;
    ensure(colour(r.ambient_light), "ambient light finite, ≥ 0")?;
    let c = &scene.camera;
    // A bare OBJ's camera is framed from outside its bounds, so it may be farther out.
    ensure(
        c.position.is_finite() && c.look_at.is_finite() && c.up.is_finite(),
        "camera finite",
    )?;
    ensure(
        c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0,
        "fov_y in (0, 180)",
    )?;
    let view = (c.look_at - c.position).normalize_or_zero();
    let up = c.up.normalize_or_zero();
    ensure(view != Vec3::ZERO, "position ≠ look_at")?;
    ensure(
        up != Vec3::ZERO && view.cross(up).length() >= 1e-4,
        "up usable",
    )?;
    for l in &scene.lights {
        // Like the camera: a bare OBJ's light is placed outside its bounds, so it may be
        // beyond ±1e15 (found by the long fuzz run); lights are not in the accelerator.
        ensure(l.position.is_finite() && colour(l.color), "light finite")?;
        ensure(
            l.radius.is_finite() && (0.0..=MAX_COORDINATE).contains(&l.radius),
            "light radius ≥ 0",
        )?;
    }
    for m in &scene.materials {
        for v in [
            m.ambient,
            m.diffuse,
            m.specular,
            m.reflectivity,
            m.transparency,
        ] {
            ensure(colour(v), "material coefficients finite, ≥ 0")?;
        }
        ensure(
            m.shininess.is_finite() && m.shininess >= 0.0,
            "shininess ≥ 0",
        )?;
        ensure(m.ior.is_finite() && m.ior > 0.0, "ior > 0")?;
    }
    let (n_materials, n_objects) = (scene.materials.len(), scene.objects.len());
    for s in &scene.spheres {
        ensure(finite(s.center), "sphere centre finite")?;
        ensure(s.radius > 0.0 && s.radius <= MAX_COORDINATE, "radius > 0")?;
        ensure((s.material.0 as usize) < n_materials, "sphere material id")?;
        ensure((s.object.0 as usize) < n_objects, "sphere object id")?;
    }
    for t in scene.triangles.iter() {
        let [a, b, c] = t.vertices;
        let cross = (b - a).cross(c - a);
        ensure(finite(a) && finite(b) && finite(c), "triangle finite")?;
        ensure(
            cross.is_finite() && cross != Vec3::ZERO,
            "triangle area > 0",
        )?;
        ensure(
            (t.material.0 as usize) < n_materials,
            "triangle material id",
        )?;
        ensure((t.object.0 as usize) < n_objects, "triangle object id")?;
    }
    let mut names = HashSet::new();
    for o in &scene.objects {
        ensure(names.insert(o.name.as_str()), "object names unique")?;
    }
    for w in &scene.warnings {
        ensure(is_one_line(w), "warnings are one line")?;
    }
    Ok(())
}

fn ensure(ok: bool, rule: &str) -> Result<(), String> {
    if ok { Ok(()) } else { Err(rule.to_string()) }
}

/// `message` with each "more than the memory limit of N (source)" spelled the same on every
/// machine: the default limit is three quarters of the machine's memory, so its figure and its
/// source vary (docs/reliability.md); what a test checks is the estimate and that the limit refused
/// it.
pub fn same_on_every_machine(message: &str) -> String {
    const LIMIT: &str = "more than the memory limit of ";
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(at) = rest.find(LIMIT) {
        out.push_str(&rest[..at + LIMIT.len()]);
        rest = &rest[at + LIMIT.len()..];
        // The figure, then the source in parentheses (which may nest one level).
        let Some(open) = rest.find(" (") else { break };
        let mut depth = 0;
        let mut end = None;
        for (i, c) in rest[open + 1..].char_indices() {
            match c {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        end = Some(open + 1 + i + 1);
                        break;
                    }
                }
                _ => {}
            }
        }
        let Some(end) = end else { break };
        out.push_str("LIMIT (SOURCE)");
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

/// One line, not empty, of a readable length.
pub fn is_one_line(message: &str) -> bool {
    !message.is_empty() && !message.contains(['\n', '\r']) && message.chars().count() <= 1000
}

/// Renders the scene at most 6×4 pixels, one sample, on one thread: whatever the loader
/// accepted must trace without a panic.
pub fn render_tiny(scene: &Scene) {
    let mut scene = scene.clone();
    scene.render.width = scene.render.width.min(6);
    scene.render.height = scene.render.height.min(4);
    // Deep glass between mirrors can cost 2^depth rays a pixel (see the README, Reliability);
    // depth is not what this checks.
    scene.render.max_depth = scene.render.max_depth.min(6);
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    if let Err(e) = render(&tracer, 1, 1, &|_, _| {}) {
        panic!("the tiny render failed: {e}");
    }
}
