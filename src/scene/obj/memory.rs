//! Whether an OBJ fits the memory budget ([`crate::scene::budget`]), from what its text holds
//! ([`Facts`]), before its models or triangles are made.

use super::parse::Facts;
use super::read::ObjProblem;
use crate::scene::budget::{MemoryLimit, memory_limit, mesh_memory_estimate};
use crate::scene::{NormalsMode, Scene};

/// Refuses an OBJ of `text_bytes` bytes and these `facts` whose triangles (with the scene's
/// before them), or those with the normals and texture coordinates kept for `normals`, would
/// not fit the memory budget.
pub(super) fn check_memory(
    scene: &Scene,
    text_bytes: usize,
    facts: &Facts,
    normals: NormalsMode,
) -> Result<(), ObjProblem> {
    check_mesh_memory(scene, text_bytes, facts, &memory_limit())
        .map_err(|reason| ObjProblem { line: None, reason })?;
    let attributes = attribute_memory_estimate(facts, normals);
    if attributes > 0 {
        let triangles = facts.triangles;
        let all = mesh_memory_estimate(
            text_bytes as u64,
            facts.vertices,
            triangles.saturating_add(scene.triangles.len() as u64),
        )
        .saturating_add(attributes);
        memory_limit()
            .check(
                format!("its {triangles} triangles with their normals and texture coordinates"),
                all,
            )
            .map_err(|e| ObjProblem {
                line: None,
                reason: e.to_string(),
            })?;
    }
    Ok(())
}

/// Bytes the per-vertex normals and texture coordinates of an OBJ may keep: the
/// file's `vn` and `vt` and an index triple per triangle for each, or computed normals (three
/// per triangle) for `normals = "smooth"`; 0 for a flat mesh without `vt`.
fn attribute_memory_estimate(facts: &Facts, normals: NormalsMode) -> u64 {
    let (vn, vt, faces) = (facts.normals, facts.texcoords, facts.triangles);
    let per_triangle_index = 12u64;
    let normal_bytes = match normals {
        NormalsMode::Flat => 0,
        NormalsMode::File if vn == 0 => 0,
        NormalsMode::File => vn * 12 + faces * per_triangle_index,
        NormalsMode::Smooth => faces * (36 + per_triangle_index),
    };
    let uv_bytes = if vt == 0 {
        0
    } else {
        vt * 8 + faces * per_triangle_index
    };
    normal_bytes.saturating_add(uv_bytes)
}

/// Refuses an OBJ of `text_bytes` bytes and these `facts` whose reading (with the triangles the
/// scene already has) would exceed `limit`, before the models or triangles are made.
fn check_mesh_memory(
    scene: &Scene,
    text_bytes: usize,
    facts: &Facts,
    limit: &MemoryLimit,
) -> Result<(), String> {
    let (vertices, triangles) = (facts.vertices, facts.triangles);
    let estimate = mesh_memory_estimate(
        text_bytes as u64,
        vertices,
        triangles.saturating_add(scene.triangles.len() as u64),
    );
    let noun = |n: u64, one: &'static str, many: &'static str| if n == 1 { one } else { many };
    let mut what = format!(
        "its {vertices} {} and {triangles} {}",
        noun(vertices, "vertex", "vertices"),
        noun(triangles, "triangle", "triangles")
    );
    if !scene.triangles.is_empty() {
        what += &format!(" (with the scene's {} before it)", scene.triangles.len());
    }
    limit.check(what, estimate).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::super::parse::{self, Polylines};
    use super::super::read::{obj_counts, slow_facts, without_polylines};
    use super::*;

    #[test]
    fn meshes_over_the_memory_limit_are_refused_before_reading() {
        let limit = MemoryLimit {
            bytes: 1 << 20,
            source: "a test".into(),
        };
        let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
        assert_eq!(obj_counts("f 1 2 3 4 5\nl 1 2\nf 1\nv 1 1 1\n"), (1, 4));
        let (stripped, n) = without_polylines("v 0 0 0\n l 1 2 3\nf 1 1 1\n");
        assert_eq!((stripped.as_ref(), n), ("v 0 0 0\n#\nf 1 1 1\n", 1));
        let check = |text: &str| {
            let facts = parse::scan(text, Polylines::Skip).expect("the fast reader takes it");
            assert_eq!(*facts.facts(), slow_facts(text));
            check_mesh_memory(&Scene::default(), text.len(), facts.facts(), &limit)
        };
        assert!(check(&text).is_ok());
        text += &"f 1 2 3\n".repeat(3000);
        let e = check(&text).expect_err("over 1 MiB");
        assert_eq!(
            e,
            "its 3 vertices and 3000 triangles would need about 1.3 MiB, more than the memory \
             limit of 1.0 MiB (a test)"
        );
    }
}
