//! Comparison of two OBJ reads (raytree's parallel reader against tobj), shared by
//! `tests/obj_parse.rs` and `tests/fuzz.rs`.

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

/// tobj's options in `scene::obj`.
pub fn options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    }
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A material as comparable text (its unknown parameters sorted).
fn material(m: &tobj::Material) -> String {
    let unknown: BTreeMap<_, _> = m.unknown_param.iter().collect();
    format!(
        "{} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {unknown:?}",
        m.name,
        m.ambient.map(|a| a.map(f32::to_bits)),
        m.diffuse.map(|a| a.map(f32::to_bits)),
        m.specular.map(|a| a.map(f32::to_bits)),
        m.shininess.map(f32::to_bits),
        m.dissolve.map(f32::to_bits),
        m.optical_density.map(f32::to_bits),
        m.illumination_model,
        m.diffuse_texture,
    )
}

/// `Ok` when both reads give the same models and materials, bit for bit; else what differs.
pub fn same(a: &tobj::LoadResult, b: &tobj::LoadResult) -> Result<(), String> {
    let (a, b) = match (a, b) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(x), Err(y)) if x == y => return Ok(()),
        _ => return Err(format!("one failed: {:?} / {:?}", a.is_ok(), b.is_ok())),
    };
    if a.0.len() != b.0.len() {
        return Err(format!("{} models / {}", a.0.len(), b.0.len()));
    }
    for (i, (x, y)) in a.0.iter().zip(&b.0).enumerate() {
        let (m, n) = (&x.mesh, &y.mesh);
        let checks = [
            ("name", x.name == y.name),
            ("positions", bits(&m.positions) == bits(&n.positions)),
            ("normals", bits(&m.normals) == bits(&n.normals)),
            ("texcoords", bits(&m.texcoords) == bits(&n.texcoords)),
            (
                "vertex_color",
                bits(&m.vertex_color) == bits(&n.vertex_color),
            ),
            ("indices", m.indices == n.indices),
            ("normal_indices", m.normal_indices == n.normal_indices),
            ("texcoord_indices", m.texcoord_indices == n.texcoord_indices),
            ("face_arities", m.face_arities == n.face_arities),
            ("material_id", m.material_id == n.material_id),
        ];
        for (what, ok) in checks {
            if !ok {
                return Err(format!(
                    "model {i} ({:?} / {:?}): {what} differ",
                    x.name, y.name
                ));
            }
        }
    }
    match (&a.1, &b.1) {
        (Ok(x), Ok(y)) => {
            let (x, y): (Vec<_>, Vec<_>) = (
                x.iter().map(material).collect(),
                y.iter().map(material).collect(),
            );
            if x != y {
                return Err(format!("materials differ: {x:?} / {y:?}"));
            }
        }
        (Err(x), Err(y)) if x == y => {}
        _ => return Err("the material results differ".into()),
    }
    Ok(())
}

/// Reads `text` with both readers (MTL files through `mtl`) and checks: the fast reader never
/// panics; where it gives a result, tobj gives the same; where tobj fails, it gives none. The
/// loader's way too ([`check_loader_pass`]). Returns whether the fast reader took the text.
pub fn check(text: &str, mtl: &dyn Fn(&Path) -> tobj::MTLLoadResult) -> bool {
    check_loader_pass(text, mtl);
    check_tobj_pass(text, mtl)
}

/// The text with each polyline (`l`) line made a comment, as the loader reads it.
pub fn without_polylines(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        if line.split_whitespace().next() == Some("l") {
            out.push('#');
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// What the loader's single pass must count, counted line by line here: `v`, `vt`, `vn`,
/// triangles of `f` (one for a face of fewer than three corners) and its n-gons, `l` lines, the names of
/// `usemtl` followed by a space or tab, and whether an `s` line names a group (not `off`, not
/// a number equal to 0).
pub fn facts_by_lines(text: &str) -> raytree::scene::obj::parse::Facts {
    let mut f = raytree::scene::obj::parse::Facts::default();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => f.vertices += 1,
            Some("vt") => f.texcoords += 1,
            Some("vn") => f.normals += 1,
            Some("l") => f.polylines += 1,
            Some("s") => {
                if let Some(group) = words.next() {
                    let off = matches!(group.as_bytes(), [b'o' | b'O', b'f' | b'F', b'f' | b'F'])
                        || group.parse::<u64>().is_ok_and(|n| n == 0);
                    f.smoothing |= !off;
                }
            }
            Some("f") => {
                let corners = words.count() as u64;
                f.triangles += corners.saturating_sub(2).max(1);
                f.ngons += u64::from(corners >= 5);
            }
            _ => {}
        }
        if let Some(rest) = line.trim_start().strip_prefix("usemtl")
            && rest.starts_with([' ', '\t'])
            && !rest.trim().is_empty()
        {
            f.usemtl.insert(rest.trim().to_string());
        }
    }
    f
}

/// The loader's pass (`scan` with polylines skipped, then `assemble`): never panics; where it
/// takes the text, its facts are the line-by-line counts and its models what tobj reads from
/// the text with its polylines commented out. Returns whether it took the text.
pub fn check_loader_pass(text: &str, mtl: &dyn Fn(&Path) -> tobj::MTLLoadResult) -> bool {
    use raytree::scene::obj::parse::{Polylines, scan};
    let scanned = catch_unwind(AssertUnwindSafe(|| scan(text, Polylines::Skip)))
        .unwrap_or_else(|_| panic!("the fast reader's scan panicked on {text:?}"));
    let Some(scanned) = scanned else {
        return false;
    };
    assert_eq!(
        *scanned.facts(),
        facts_by_lines(text),
        "the facts of {:?}",
        short(text)
    );
    let fast = catch_unwind(AssertUnwindSafe(|| scanned.assemble(mtl)))
        .unwrap_or_else(|_| panic!("the fast reader panicked on {text:?}"));
    let plain = without_polylines(text);
    let slow = catch_unwind(AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut plain.as_bytes(), &options(), mtl)
    }));
    match (fast, slow) {
        (Some(f), Ok(s)) => {
            assert!(f.is_ok(), "the fast reader gives only successes");
            if let Err(e) = same(&f, &s) {
                panic!(
                    "the readers differ without polylines ({e}) on {:?}",
                    short(text)
                );
            }
            true
        }
        (Some(_), Err(_)) => true,
        (None, _) => false,
    }
}

/// [`check`] for the reader as tobj reads (polylines as faces).
pub fn check_tobj_pass(text: &str, mtl: &dyn Fn(&Path) -> tobj::MTLLoadResult) -> bool {
    let fast = catch_unwind(AssertUnwindSafe(|| {
        raytree::scene::obj::parse::parse(text, mtl)
    }))
    .unwrap_or_else(|_| panic!("the fast reader panicked on {text:?}"));
    let slow = catch_unwind(AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &options(), mtl)
    }));
    match (fast, slow) {
        (Some(f), Ok(s)) => {
            assert!(f.is_ok(), "the fast reader gives only successes");
            if let Err(e) = same(&f, &s) {
                panic!("the readers differ ({e}) on {:?}", short(text));
            }
            true
        }
        // tobj panics on this (it has: 1- and 2-number colours); ours must not, whatever it gives.
        (Some(_), Err(_)) => true,
        (None, _) => false,
    }
}

fn short(text: &str) -> &str {
    match text.char_indices().nth(2000) {
        Some((i, _)) => &text[..i],
        None => text,
    }
}
