//! What is wrong with the OBJ statement a file stops loading at, in the file's own terms: the
//! statement quoted, then what it holds against what it should (`v 0 1` has two numbers where a
//! position needs three; `f 1 2 9` names vertex 9 where three are defined), instead of the
//! reader's "position parse error".

use tobj::LoadError;

use crate::scene::diag::short;

/// The reason for `error`, met at `line` (counted from 1) of `text`: the statement and what is
/// wrong with it, or the reader's own words when the statement cannot be found.
pub(super) fn explain(error: &LoadError, text: &str, line: Option<usize>) -> String {
    let Some(statement) = line
        .and_then(|n| text.lines().nth(n.checked_sub(1)?))
        .map(str::trim)
    else {
        return error.to_string();
    };
    let before = || text.lines().take(line.unwrap_or(1) - 1);
    let count = |key: &str| {
        before()
            .filter(|l| l.split_whitespace().next() == Some(key))
            .count()
    };
    let quoted = format!("`{}`", short(statement));
    let words: Vec<&str> = statement.split_whitespace().skip(1).collect();
    let not_a_number = words.iter().find(|w| w.parse::<f32>().is_err());
    let numbers = |needed: &str| match not_a_number {
        Some(w) => format!("{quoted}: `{}` is not a number", short(w)),
        None => format!(
            "{quoted} has {} {}; {needed}",
            words.len(),
            if words.len() == 1 {
                "number"
            } else {
                "numbers"
            }
        ),
    };
    let faces = [
        (0, count("v"), "vertex", "vertices", "v"),
        (
            1,
            count("vt"),
            "texture coordinate",
            "texture coordinates",
            "vt",
        ),
        (2, count("vn"), "normal", "normals", "vn"),
    ];
    let index = |kinds: &[usize]| {
        kinds.iter().find_map(|&k| {
            let (slot, defined, one, many, key) = faces[k];
            bad_index(&words, slot, defined).map(|bad| {
                let come = match defined {
                    0 => format!("no {many} (`{key}` lines) come before this face"),
                    1 => format!("1 {one} (a `{key}` line) comes before this face"),
                    n => format!("{n} {many} (`{key}` lines) come before this face"),
                };
                format!(
                    "{quoted} names {one} {}, which is not defined: {come} (OBJ numbers them from 1, and -1 is the last one)",
                    short(bad)
                )
            })
        })
    };
    let corners = || {
        format!(
            "{quoted}: a face needs at least three corners, each `v`, `v/vt`, `v//vn` or `v/vt/vn` with whole-number indices"
        )
    };
    match error {
        LoadError::PositionParseError => {
            numbers("a vertex position needs three (x y z, then an optional weight w)")
        }
        LoadError::ScalingByZeroError => format!("{quoted}: the vertex's weight w is 0"),
        LoadError::ColorParseError => numbers(
            "a vertex needs three numbers (x y z), then an optional weight w or three colour numbers (r g b)",
        ),
        LoadError::TexcoordParseError => {
            numbers("a texture coordinate needs two (u v, then an optional w)")
        }
        LoadError::NormalParseError => numbers("a normal needs three (x y z)"),
        LoadError::FaceParseError | LoadError::InvalidPolygon => {
            index(&[0, 1, 2]).unwrap_or_else(corners)
        }
        LoadError::FaceVertexOutOfBounds => index(&[0]).unwrap_or_else(corners),
        LoadError::FaceTexCoordOutOfBounds => index(&[1]).unwrap_or_else(corners),
        LoadError::FaceNormalOutOfBounds => index(&[2]).unwrap_or_else(corners),
        LoadError::FaceColorOutOfBounds => format!(
            "{quoted} uses vertices without a colour, while other `v` lines give one (`v x y z r g b`): every vertex needs a colour, or none"
        ),
        _ => format!("{quoted}: {error}"),
    }
}

/// The first index in the `slot` place (0 vertex, 1 texture coordinate, 2 normal) of a face's
/// corners `words` that does not name one of the `defined` items: 0, beyond them either way,
/// or too long a number to be an index.
fn bad_index<'a>(words: &[&'a str], slot: usize, defined: usize) -> Option<&'a str> {
    words.iter().find_map(|corner| {
        let index = corner.split('/').nth(slot).filter(|i| !i.is_empty())?;
        let digits = index.strip_prefix('-').unwrap_or(index);
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let fits = match index.parse::<i64>() {
            Ok(i) => i != 0 && i.unsigned_abs() <= defined as u64,
            Err(_) => false,
        };
        (!fits).then_some(index)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at_last_line(error: LoadError, text: &str) -> String {
        explain(&error, text, Some(text.lines().count()))
    }

    #[test]
    fn numbers_are_counted_or_the_word_named() {
        assert_eq!(
            at_last_line(LoadError::PositionParseError, "v 0 0 0\nv 0 1"),
            "`v 0 1` has 2 numbers; a vertex position needs three (x y z, then an optional weight w)"
        );
        assert_eq!(
            at_last_line(LoadError::PositionParseError, "v 0 x 1"),
            "`v 0 x 1`: `x` is not a number"
        );
        assert_eq!(
            at_last_line(LoadError::TexcoordParseError, "vt 0.5"),
            "`vt 0.5` has 1 number; a texture coordinate needs two (u v, then an optional w)"
        );
    }

    #[test]
    fn a_face_of_uncoloured_vertices_among_coloured_ones_says_so() {
        let text = "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3";
        assert_eq!(
            at_last_line(LoadError::FaceColorOutOfBounds, text),
            "`f 1 2 3` uses vertices without a colour, while other `v` lines give one (`v x y z r g b`): every vertex needs a colour, or none"
        );
    }

    #[test]
    fn a_face_names_its_undefined_index_and_what_is_defined() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1 2 5000000";
        assert_eq!(
            at_last_line(LoadError::FaceVertexOutOfBounds, text),
            "`f 1 2 5000000` names vertex 5000000, which is not defined: 3 vertices (`v` lines) come before this face (OBJ numbers them from 1, and -1 is the last one)"
        );
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//0";
        assert!(
            at_last_line(LoadError::FaceNormalOutOfBounds, text)
                .contains("names normal 0, which is not defined: 1 normal (a `vn` line) comes"),
        );
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999999";
        assert!(
            at_last_line(LoadError::FaceParseError, text).starts_with(
                "`f 1 2 99999999999999999999999` names vertex 99999999999999999999999,"
            ),
            "an index too long for a number is undefined too"
        );
        let text = "v 0 0 0\nv 1 0 0\nf 1 2";
        assert!(
            at_last_line(LoadError::InvalidPolygon, text)
                .starts_with("`f 1 2`: a face needs at least three corners"),
        );
        assert!(
            at_last_line(LoadError::FaceVertexOutOfBounds, "v 0 0 0\nf -1 -2 1")
                .contains("names vertex -2,"),
            "negative indices count back from the last vertex"
        );
    }

    #[test]
    fn without_the_line_the_reader_speaks() {
        assert_eq!(
            explain(&LoadError::PositionParseError, "v 0 1", None),
            "position parse error"
        );
    }
}
