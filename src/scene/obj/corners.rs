//! Which faces of an OBJ give a normal (`vn`) and a texture coordinate (`vt`) at every corner
//! (`normals = "file"`: the OBJ's `vn` where a face gives them, flat otherwise; docs/design.md,
//! "Scene files").
//!
//! tobj 4.0.5 (and [`super::parse`], which reads exactly as it does) fills a corner without
//! `vn` or `vt` with the previous corner's index (the first normal for the first corner), and
//! reads an index of 0, or a relative one that points one before the first, as "absent": a face
//! without normals in a smooth file would be shaded with a neighbour's normal, and `f 1//0 ...`
//! would load as if it were valid. This pass reads the face lines again, in tobj's order of
//! triangles, so that the loader shades such faces flat and refuses those indices as tobj
//! refuses every other index out of range.
//!
//! The parallel reader ([`super::parse`]) finds the same facts while it reads the faces
//! ([`super::parse::Scanned::take_face_corners`]) and never takes indices of 0 or relative
//! ones, so this second pass only runs on files it leaves to tobj.

/// A triangle's face gives a normal at every corner.
pub(crate) const ALL_NORMALS: u8 = 1;
/// A triangle's face gives a texture coordinate at every corner.
pub(crate) const ALL_UVS: u8 = 2;

use rayon::prelude::*;
use tobj::LoadError;

/// What [`face_corners`] found.
#[derive(Clone, Debug, Default, PartialEq)]
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

impl FaceCorners {
    /// The facts for a file that has `vt` only if `has_uvs` and `vn` only if `has_normals`
    /// (as [`face_corners`] gives them), from those found with both lists present: the
    /// indices into a list the file does not have are ignored, as tobj ignores them.
    pub(crate) fn only(mut self, has_uvs: bool, has_normals: bool) -> Self {
        let keep = match (has_uvs, has_normals) {
            (true, true) => return self,
            (true, false) => ALL_UVS,
            (false, true) => ALL_NORMALS,
            (false, false) => 0,
        };
        self.triangles.iter_mut().for_each(|f| *f &= keep);
        self.partial_uvs *= usize::from(has_uvs);
        self.partial_normals *= usize::from(has_normals);
        self
    }
}

/// The corners of every face of `text` (OBJ, polylines already removed, read by tobj without
/// an error), or the 1-based line and tobj's error for the first `vt` or `vn` index of 0 or
/// before the first one. `has_uvs`, `has_normals`: whether the file has any `vt`, `vn` (tobj
/// ignores the indices into a list the file does not have, and so does this). Chunks of lines
/// are read in parallel; a relative index is checked against the entries before it once the
/// chunks' counts are known.
pub(crate) fn face_corners(
    text: &str,
    has_uvs: bool,
    has_normals: bool,
) -> Result<FaceCorners, (usize, LoadError)> {
    let chunks = split_lines(text, CHUNK_BYTES);
    let parts: Vec<Part> = chunks
        .par_iter()
        .map(|c| read_chunk(c, [has_uvs, has_normals]))
        .collect();
    let mut out = FaceCorners::default();
    let (mut lines, mut counts) = (0usize, [0i64; 2]);
    for part in &parts {
        for &(line, list, relative) in &part.suspects {
            if relative.is_none_or(|r| counts[list] + r < 0) {
                return Err((lines + line, ERRORS[list]));
            }
        }
        lines += part.lines;
        counts[0] += part.counts[0];
        counts[1] += part.counts[1];
    }
    out.triangles
        .reserve(parts.iter().map(|p| p.triangles.len()).sum());
    for part in parts {
        out.triangles.extend_from_slice(&part.triangles);
        out.partial_uvs += part.partial[0];
        out.partial_normals += part.partial[1];
    }
    Ok(out)
}

/// Bytes of text per chunk read in parallel.
const CHUNK_BYTES: usize = 4 << 20;

/// tobj's errors for an index out of range, for `vt` and for `vn`.
const ERRORS: [LoadError; 2] = [TEXCOORD, NORMAL];
const TEXCOORD: LoadError = LoadError::FaceTexCoordOutOfBounds;
const NORMAL: LoadError = LoadError::FaceNormalOutOfBounds;

/// `text` cut after line ends into pieces of about `bytes` each.
fn split_lines(text: &str, bytes: usize) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = text;
    while rest.len() > bytes {
        let cut = rest.as_bytes()[bytes..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(rest.len(), |i| bytes + i + 1);
        let (head, tail) = rest.split_at(cut);
        out.push(head);
        rest = tail;
    }
    out.push(rest);
    out
}

/// One chunk, read.
#[derive(Default)]
struct Part {
    /// Lines in the chunk (as `str::lines` counts them).
    lines: usize,
    /// `vt` and `vn` statements in the chunk.
    counts: [i64; 2],
    triangles: Vec<u8>,
    /// Faces with `vt` (`vn`) at some corners only.
    partial: [usize; 2],
    /// Indices that may be out of range, in order: the 1-based line in the chunk, the list
    /// (0 `vt`, 1 `vn`) and, for a relative index, the chunk's count before it plus the index
    /// (out of range if negative once the earlier chunks' count is added); `None` for 0.
    suspects: Vec<(usize, usize, Option<i64>)>,
}

fn read_chunk(text: &str, lists: [bool; 2]) -> Part {
    let mut part = Part::default();
    for (i, line) in text.lines().enumerate() {
        part.lines = i + 1;
        // Split as tobj splits (Unicode whitespace, which has the vertical tab that
        // `split_ascii_whitespace` lacks).
        if read_line(line.split_whitespace(), i + 1, lists, &mut part).is_err() {
            break;
        }
    }
    part
}

/// Reads the words of line `line` into `part`; `Err` after an index of 0 (the file's error).
fn read_line<'a>(
    mut words: impl Iterator<Item = &'a str>,
    line: usize,
    lists: [bool; 2],
    part: &mut Part,
) -> Result<(), ()> {
    match words.next() {
        Some("vt") => part.counts[0] += 1,
        Some("vn") => part.counts[1] += 1,
        Some("f") => {
            let (mut corners, mut given) = (0usize, [0usize; 2]);
            for corner in words {
                corners += 1;
                let mut fields = corner.split('/').skip(1);
                for (list, field) in [fields.next(), fields.next()].into_iter().enumerate() {
                    if !lists[list] {
                        continue;
                    }
                    match index(field.unwrap_or("")) {
                        Index::Absent => {}
                        Index::Given => given[list] += 1,
                        Index::Zero => {
                            part.suspects.push((line, list, None));
                            return Err(());
                        }
                        Index::Relative(x) => {
                            given[list] += 1;
                            let r = part.counts[list] + x;
                            if r < 0 {
                                part.suspects.push((line, list, Some(r)));
                            }
                        }
                    }
                }
            }
            let all = |list: usize| corners > 0 && given[list] == corners;
            let mut flags = 0;
            if all(1) {
                flags |= ALL_NORMALS;
            }
            if all(0) {
                flags |= ALL_UVS;
            }
            for (partial, given) in part.partial.iter_mut().zip(given) {
                *partial += usize::from(given > 0 && given < corners);
            }
            let triangles = if corners >= 4 { corners - 2 } else { 1 };
            part.triangles.extend(std::iter::repeat_n(
                flags,
                triangles * usize::from(corners > 0),
            ));
        }
        _ => {}
    }
    Ok(())
}

/// A corner's `vt` or `vn` field, as tobj reads it.
enum Index {
    /// Empty, or not a number (tobj refuses the file itself).
    Absent,
    /// A positive index (one past the end is tobj's error).
    Given,
    /// 0: tobj reads it as absent.
    Zero,
    /// A negative (relative) index.
    Relative(i64),
}

fn index(field: &str) -> Index {
    let bytes = field.as_bytes();
    match bytes.first() {
        None => Index::Absent,
        Some(b'-' | b'+') => match field.parse::<i64>() {
            Ok(0) => Index::Zero,
            Ok(x) if x < 0 => Index::Relative(x),
            Ok(_) => Index::Given,
            Err(_) => Index::Absent,
        },
        Some(_) if bytes.iter().all(|&b| b == b'0') => Index::Zero,
        Some(_) if bytes.iter().all(u8::is_ascii_digit) => Index::Given,
        Some(_) => Index::Absent,
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
    fn chunks_give_what_one_pass_gives() {
        let mut text = String::from("v 0 0 0\nvn 0 0 1\nvt 0 0\n");
        for k in 0..300 {
            text += match k % 4 {
                0 => "f 1/1/1 1/1/1 1/1/1\n",
                1 => "vn 0 1 0\nf 1//-1 1//-2 1 1//1\n",
                2 => "vt 1 1\nf 1/-1 1/-2 1/1\n",
                _ => "f 1 1 1\n",
            };
        }
        let whole = face_corners(&text, true, true).expect("valid");
        assert_eq!(whole.triangles.len(), 375);
        assert_eq!((whole.partial_normals, whole.partial_uvs), (75, 0));
        let pieces = split_lines(&text, 100);
        assert!(pieces.len() > 20 && pieces.concat() == text);
        // A relative index valid only thanks to entries in earlier chunks, and an invalid one
        // in a late chunk: the line counts across chunks.
        let parts: Vec<Part> = pieces.iter().map(|c| read_chunk(c, [true, true])).collect();
        assert_eq!(parts.iter().map(|p| p.triangles.len()).sum::<usize>(), 375);
        assert!(parts.iter().any(|p| !p.suspects.is_empty()));
        let bad = format!("{text}f 1//-999 1//1 1//1\n");
        let lines = bad.lines().count();
        assert_eq!(face_corners(&bad, true, true), Err((lines, NORMAL)));
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

    /// The parallel reader's pass gives, per face, what this pass gives: on a file of several
    /// of its chunks whose faces give `vt` and `vn` at every corner, some, or none, with
    /// polylines between them, for a file with both lists, one of them, or neither.
    #[test]
    fn the_fast_readers_pass_gives_the_same_faces() {
        use super::super::parse::{Polylines, scan};
        let faces = [
            "f 1/1/1 2/1/1 3/1/1\n",
            "f 1 2 3 4\n",
            "f 1//1 2 3//1\n",
            "f 1/1 2/1 3/1 4/1 1/1\n",
            "f 1/1/1 2//1 3/1\n",
            "f 2\n",
            "f 1/1 2\n",
            "l 1 2 3\n",
            "f 1/1/1 2/1/1 3/1/1 4/1\n",
            "\tf  1//1 \x0b 2//1\x0c3//1\n",
        ];
        let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\n");
        let mut rng = crate::rng::Pcg::new(7);
        // More than 1 MiB: the reader cuts it into several chunks.
        while text.len() < 3 << 20 {
            text += faces[rng.below(faces.len())];
        }
        let found = scan(&text, Polylines::Skip)
            .expect("the fast reader takes it")
            .take_face_corners();
        assert!(found.partial_normals > 1000 && found.partial_uvs > 1000);
        for flags in [0, ALL_UVS, ALL_NORMALS, ALL_UVS | ALL_NORMALS] {
            assert!(found.triangles.contains(&flags), "{flags}");
        }
        for (uvs, normals) in [(true, true), (true, false), (false, true), (false, false)] {
            let again = face_corners(&text, uvs, normals).expect("valid");
            let fast = found.clone().only(uvs, normals);
            let first_difference =
                (fast.triangles.iter().zip(&again.triangles)).position(|(a, b)| a != b);
            assert_eq!(first_difference, None, "vt {uvs}, vn {normals}");
            assert_eq!(fast, again, "vt {uvs}, vn {normals}");
        }
    }
}
