//! Which faces of an OBJ give a normal (`vn`) and a texture coordinate (`vt`) at every corner
//! (SPEC §3b: "the OBJ's `vn` where present, flat otherwise").
//!
//! tobj 4.0.5 (and [`super::obj_parse`], which reads exactly as it does) fills a corner without
//! `vn` or `vt` with the previous corner's index (the first normal for the first corner), and
//! reads an index of 0, or a relative one that points one before the first, as "absent": a face
//! without normals in a smooth file would be shaded with a neighbour's normal, and `f 1//0 ...`
//! would load as if it were valid. This pass reads the face lines again, in tobj's order of
//! triangles, so that the loader shades such faces flat and refuses those indices as tobj
//! refuses every other index out of range.

/// A triangle's face gives a normal at every corner.
pub(crate) const ALL_NORMALS: u8 = 1;
/// A triangle's face gives a texture coordinate at every corner.
pub(crate) const ALL_UVS: u8 = 2;

/// What [`face_corners`] found.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct FaceCorners {
    /// For every triangle, in the order tobj makes them (faces in file order, a face of `n ≥ 4`
    /// corners fanned into `n − 2`, one of 1 to 3 corners one triangle): [`ALL_NORMALS`] and
    /// [`ALL_UVS`].
    pub triangles: Vec<u8>,
    /// Faces that give normals at some corners but not all.
    pub partial_normals: usize,
    /// Faces that give texture coordinates at some corners but not all.
    pub partial_uvs: usize,
}

/// The corners of every face of `text` (OBJ, polylines already removed, read by tobj without
/// an error), or the 1-based line and tobj's words for the first `vt` or `vn` index of 0 or
/// before the first one. `has_uvs`, `has_normals`: whether the file has any `vt`, `vn` (tobj
/// ignores the indices into a list the file does not have, and so does this).
pub(crate) fn face_corners(
    text: &str,
    has_uvs: bool,
    has_normals: bool,
) -> Result<FaceCorners, (usize, &'static str)> {
    let mut out = FaceCorners::default();
    let (mut uvs, mut normals) = (0i64, 0i64);
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("vt") => uvs += 1,
            Some("vn") => normals += 1,
            Some("f") => {
                let (mut corners, mut with_uv, mut with_normal) = (0usize, 0usize, 0usize);
                for corner in words {
                    corners += 1;
                    let mut parts = corner.split('/').skip(1);
                    let uv = parts.next().unwrap_or("");
                    let normal = parts.next().unwrap_or("");
                    if has_uvs && given(uv, uvs).map_err(|()| (i + 1, TEXCOORD))? {
                        with_uv += 1;
                    }
                    if has_normals && given(normal, normals).map_err(|()| (i + 1, NORMAL))? {
                        with_normal += 1;
                    }
                }
                let flags = u8::from(corners > 0 && with_normal == corners) * ALL_NORMALS
                    | u8::from(corners > 0 && with_uv == corners) * ALL_UVS;
                out.partial_normals += usize::from(with_normal > 0 && with_normal < corners);
                out.partial_uvs += usize::from(with_uv > 0 && with_uv < corners);
                let triangles = if corners >= 4 { corners - 2 } else { 1 };
                out.triangles.extend(std::iter::repeat_n(
                    flags,
                    triangles * usize::from(corners > 0),
                ));
            }
            _ => {}
        }
    }
    Ok(out)
}

/// tobj's words for an index out of range.
const TEXCOORD: &str = "face texcoord index out of bounds";
const NORMAL: &str = "face normal index out of bounds";

/// Whether a corner's index `word` is given (`Ok(false)` when absent or not a number, which
/// tobj reports itself); `Err` for 0 or a relative index before the first of the `read_so_far`
/// entries, which tobj would silently read as absent.
fn given(word: &str, read_so_far: i64) -> Result<bool, ()> {
    if word.is_empty() {
        return Ok(false);
    }
    match word.parse::<i64>() {
        Ok(0) => Err(()),
        Ok(x) if x < 0 && read_so_far + x < 0 => Err(()),
        Ok(_) => Ok(true),
        Err(_) => Ok(false),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_are_flagged_per_triangle_in_tobj_order() {
        let text = "v 0 0 0\nvn 0 0 1\nvt 0 0\n\
            f 1/1/1 1/1/1 1/1/1\nf 1 1 1 1\nf 1//1 1 1//1\nf 1/1 1/1 1/1 1/1 1/1\nf 1\n";
        let c = face_corners(text, true, true).expect("valid");
        let both = ALL_NORMALS | ALL_UVS;
        assert_eq!(c.triangles, [both, 0, 0, 0, ALL_UVS, ALL_UVS, ALL_UVS, 0]);
        assert_eq!((c.partial_normals, c.partial_uvs), (1, 0));
    }

    #[test]
    fn zero_and_too_relative_indices_are_refused_with_their_line() {
        let e =
            face_corners("v 0 0 0\nvn 0 0 1\nf 1//1 1//0 1//1\n", false, true).expect_err("zero");
        assert_eq!(e, (3, NORMAL));
        let e = face_corners("vt 0 0\nf 1/-2 1/-1 1/-1\nvt 1 1\n", true, false)
            .expect_err("before the first");
        assert_eq!(e, (2, TEXCOORD));
        // Relative to what is read so far; a later `vt` does not help.
        assert!(face_corners("vt 0 0\nf 1/-1 1/-1 1/-1\n", true, false).is_ok());
        // A file without `vn` at all: its `vn` indices are ignored, as tobj ignores them.
        let c = face_corners("v 0 0 0\nf 1//0 1//0 1//0\n", false, false).expect("no vn at all");
        assert_eq!(c.triangles, [0]);
    }
}
