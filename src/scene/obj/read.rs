//! Reading OBJ text into tobj's models: the parallel reader ([`super::parse`]) where it can,
//! tobj itself for the rest, with panics caught and polylines left out; what the text holds,
//! counted before it is read; and the line a file stops loading at, for its error.

use std::borrow::Cow;
use std::cell::{Cell, RefCell};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::Once;

use super::corners::FaceCorners;
use super::parse::{self, Facts, Polylines, Scanned};

/// Why an OBJ could not be read: the `tobj` reason and, when found, the line.
#[derive(Debug)]
pub(crate) struct ObjProblem {
    pub line: Option<usize>,
    pub reason: String,
}

impl ObjProblem {
    /// `:17: reason` or `: reason`, to follow a file name.
    pub fn with_line(&self) -> String {
        match self.line {
            Some(line) => format!(":{line}: {}", self.reason),
            None => format!(": {}", self.reason),
        }
    }
}

/// The name given to a material the files leave without one (`newmtl` or `usemtl` alone).
pub(super) const UNNAMED_MATERIAL: &str = "(no name)";

/// OBJ text the parallel reader gave up on, spelled so that it reads: a `usemtl` without a
/// name given one ([`name_unnamed_usemtl`]), old Windows spellings of non-finite numbers
/// read as such ([`spell_non_finite`]) and vertices without a colour among coloured ones
/// made white ([`colour_uncoloured`]); `None` when none applies, else the text and how many
/// vertices were made white. Only a text that reader refused is searched (it refuses all
/// three), so a file that reads pays nothing.
pub(super) fn respell(text: &str) -> Option<(String, usize)> {
    let named = name_unnamed_usemtl(text);
    let spelled = spell_non_finite(named.as_deref().unwrap_or(text)).or(named);
    colour_uncoloured(spelled.as_deref().unwrap_or(text)).or_else(|| spelled.map(|t| (t, 0)))
}

/// Whether `line` is a `v` statement of exactly `numbers` words after the `v`.
fn vertex_of(line: &str, numbers: usize) -> bool {
    let mut words = line.split_whitespace();
    words.next() == Some("v") && words.count() == numbers
}

/// A file whose vertices give colours (`v x y z r g b`, as scans and MeshLab write) on some
/// `v` lines only: the others (`v x y z`) are given white (`1 1 1`), so their faces show their
/// material's colour, where tobj refuses the file. `None` when the text has no such mix;
/// else the text and how many vertices were made white.
fn colour_uncoloured(text: &str) -> Option<(String, usize)> {
    let lines = || text.lines().map(str::trim_start);
    if !lines().any(|l| vertex_of(l, 6)) || !lines().any(|l| vertex_of(l, 3)) {
        return None;
    }
    let white = lines().filter(|l| vertex_of(l, 3)).count();
    let text = rewrite_lines(text, |line| {
        vertex_of(line.trim_start(), 3).then(|| format!("{} 1 1 1", line.trim_end()))
    });
    Some((text, white))
}

/// `text` with each line rewritten by `line` (given a line without its line break; `None`
/// keeps it), line breaks and so line numbers kept.
fn rewrite_lines(text: &str, line: impl Fn(&str) -> Option<String>) -> String {
    let mut out = String::with_capacity(text.len() + 64);
    for whole in text.split_inclusive('\n') {
        let body = whole.trim_end_matches(['\n', '\r']);
        match line(body) {
            Some(new) => {
                out.push_str(&new);
                out.push_str(&whole[body.len()..]);
            }
            None => out.push_str(whole),
        }
    }
    out
}

/// A `usemtl` without a name (some exporters write one for an unnamed material, with
/// `newmtl` alone in the MTL) names [`UNNAMED_MATERIAL`], as the MTL's `newmtl` alone does;
/// tobj refuses the file. `None` when the text has none.
fn name_unnamed_usemtl(text: &str) -> Option<String> {
    let alone = |line: &str| {
        let mut words = line.split_whitespace();
        words.next() == Some("usemtl") && words.next().is_none()
    };
    let any = text.match_indices("usemtl").any(|(i, _)| {
        let start = text[..i].rfind('\n').map_or(0, |n| n + 1);
        let end = text[i..].find('\n').map_or(text.len(), |n| i + n);
        alone(&text[start..end])
    });
    any.then(|| {
        rewrite_lines(text, |line| {
            alone(line).then(|| format!("usemtl {UNNAMED_MATERIAL}"))
        })
    })
}

/// Numbers in `v`, `vn`, `vt` and `vp` lines as old Microsoft C libraries print what is not
/// finite (`1.#IND`, `-1.#QNAN0`, `1.#INF00`) spelled `NaN` or `inf`, so the file reads and
/// the triangles on such vertices are dropped as any non-finite ones are, where the readers
/// stop at the first one. `None` when the text has none.
fn spell_non_finite(text: &str) -> Option<String> {
    if !text.contains(".#") {
        return None;
    }
    let spelled = |word: &str| -> Option<&'static str> {
        let (number, tail) = word.split_once(".#")?;
        let negative = number.starts_with('-');
        let digits = number.trim_start_matches(['-', '+']);
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let kind = tail.trim_end_matches(|c: char| c.is_ascii_digit());
        match (kind.to_ascii_uppercase().as_str(), negative) {
            ("INF", false) => Some("inf"),
            ("INF", true) => Some("-inf"),
            ("IND" | "QNAN" | "SNAN" | "NAN", _) => Some("NaN"),
            _ => None,
        }
    };
    let line = |line: &str| {
        if !line.contains(".#") {
            return None;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        let numbers = matches!(words.first(), Some(&("v" | "vn" | "vt" | "vp")));
        (numbers && words.iter().any(|w| spelled(w).is_some())).then(|| {
            words
                .iter()
                .map(|w| spelled(w).unwrap_or(w))
                .collect::<Vec<_>>()
                .join(" ")
        })
    };
    text.lines()
        .any(|l| line(l).is_some())
        .then(|| rewrite_lines(text, line))
}

/// OBJ text with its continued lines joined: a statement whose line ends in `\` goes on on the
/// next line (the format allows it, for long faces; tobj does not read it). The `\` and the
/// line break become a space, and the break is put back after the joined statement, so every
/// later line keeps its number in messages. Only statements of numbers and names continue
/// (`v`, `vt`, `vn`, `vp`, `f`, `fo`, `l`, `p`, `g`): a comment or a file name (`mtllib
/// C:\models\`) that ends in `\` does not swallow the next line.
pub(super) fn join_continued_lines(text: &str) -> Cow<'_, str> {
    const CONTINUE: [&str; 9] = ["v", "vt", "vn", "vp", "f", "fo", "l", "p", "g"];
    let ends_continued = |line: &str| line.trim_end_matches(['\n', '\r']).ends_with('\\');
    let starts_continuable = |line: &str| {
        line.split_whitespace()
            .next()
            .is_some_and(|word| CONTINUE.contains(&word))
    };
    if !text.as_bytes().contains(&b'\\')
        || !text
            .split_inclusive('\n')
            .any(|l| l.ends_with('\n') && ends_continued(l) && starts_continuable(l))
    {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    let mut owed = 0;
    for line in text.split_inclusive('\n') {
        let continuing = owed > 0 || starts_continuable(line);
        if continuing && line.ends_with('\n') && ends_continued(line) {
            let body = line.trim_end_matches(['\n', '\r']);
            out.push_str(&body[..body.len() - 1]);
            out.push(' ');
            owed += 1;
        } else {
            out.push_str(line);
            out.extend(std::iter::repeat_n('\n', owed));
            owed = 0;
        }
    }
    out.extend(std::iter::repeat_n('\n', owed));
    Cow::Owned(out)
}

/// One pass of the parallel reader over `text`: the pass (`None` when it leaves the text to
/// tobj), which faces give `vn`/`vt` at every corner as it saw them, and the [`Facts`] the budget
/// and the warnings need (counted line by line for a text left to tobj).
pub(super) fn scan(
    text: &str,
) -> Result<(Option<Scanned>, Option<FaceCorners>, Facts), ObjProblem> {
    let mut scanned = quietly(|| parse::scan(text, Polylines::Skip)).map_err(|()| ObjProblem {
        line: None,
        reason: "the OBJ reader failed on this file".into(),
    })?;
    let fast_corners = scanned.as_mut().map(Scanned::take_face_corners);
    let facts = match &scanned {
        Some(s) => s.facts().clone(),
        None => slow_facts(text),
    };
    Ok((scanned, fast_corners, facts))
}

/// The models and MTL materials of OBJ text, read as [`load_obj`] reads it, and whether the fast
/// reader read them; a file that cannot be read is a problem with its line when one is found.
pub(super) fn read_models(
    text: &str,
    scanned: Option<Scanned>,
    load_mtl: impl Fn(&Path) -> tobj::MTLLoadResult,
) -> Result<(Vec<tobj::Model>, Vec<tobj::Material>, bool), ObjProblem> {
    match load_obj(text, scanned, load_mtl) {
        Ok((Ok((models, materials)), fast)) => Ok((models, materials.unwrap_or_default(), fast)),
        Ok((Err(e), _)) => {
            let line = error_line(text);
            Err(ObjProblem {
                line,
                reason: super::explain::explain(&e, text, line),
            })
        }
        Err(reason) => Err(ObjProblem { line: None, reason }),
    }
}

fn load_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    }
}

thread_local! {
    /// Set while [`quietly`] runs: the panic hook then prints nothing.
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f` with panics caught and not printed. `tobj` is third-party code fed hostile files; a
/// panic in it must become one error sentence, not a crash or a second line on stderr
/// (docs/reliability.md). The panic hook is wrapped once, and stays silent only on this thread and
/// only while `f` runs, so every other panic is reported as before.
pub(super) fn quietly<T>(f: impl FnOnce() -> T) -> Result<T, ()> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let outcome = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    outcome.map_err(|_| ())
}

/// Reads OBJ text: the models of the parallel reader's pass `scanned` (the same result as `tobj`,
/// faster), or `tobj` itself on the text without its polylines when that reader left it to tobj;
/// with panics caught, since hostile files must never take the program down (docs/reliability.md).
/// Each `mtllib` reaches `load_mtl` once, even when the fast reader gives up after it: tobj then
/// gets the recorded results. The flag says whether the models are the fast reader's.
pub(super) fn load_obj(
    text: &str,
    scanned: Option<Scanned>,
    load_mtl: impl Fn(&Path) -> tobj::MTLLoadResult,
) -> Result<(tobj::LoadResult, bool), String> {
    let failed = |()| "the OBJ reader failed on this file".to_string();
    let recorded = RefCell::new(std::collections::VecDeque::new());
    if let Some(scanned) = scanned {
        let fast = quietly(|| {
            scanned.assemble(|path: &Path| {
                let result = load_mtl(path);
                recorded
                    .borrow_mut()
                    .push_back((path.to_path_buf(), result.clone()));
                result
            })
        })
        .map_err(failed)?;
        if let Some(loaded) = fast {
            return Ok((loaded, true));
        }
    }
    let replay = |path: &Path| {
        let mut recorded = recorded.borrow_mut();
        match recorded.front() {
            Some((p, _)) if p == path => match recorded.pop_front() {
                Some((_, result)) => result,
                None => load_mtl(path),
            },
            _ => load_mtl(path),
        }
    };
    let (text, _) = without_polylines(text);
    quietly(|| tobj::load_obj_buf(&mut text.as_bytes(), &load_options(), replay))
        .map(|loaded| (loaded, false))
        .map_err(failed)
}

/// Reads OBJ text without polylines, as the mesh loader reads it (the error search's reader).
fn read_plain(text: &str) -> Result<tobj::LoadResult, String> {
    let scanned = quietly(|| parse::scan(text, Polylines::Skip))
        .map_err(|()| "the OBJ reader failed on this file".to_string())?;
    load_obj(text, scanned, |_| Ok(Default::default())).map(|(loaded, _)| loaded)
}

/// True for a polyline (`l`) statement.
fn is_polyline(line: &str) -> bool {
    line.split_whitespace().next() == Some("l")
}

/// OBJ text without its polylines, and how many there were. A polyline has no surface to
/// trace, but tobj reads `l` like `f`, so `l 1 2 3` would be drawn as a triangle; each one
/// becomes an empty comment, so line numbers in messages stay right.
pub(super) fn without_polylines(text: &str) -> (Cow<'_, str>, usize) {
    if !text.lines().any(is_polyline) {
        return (Cow::Borrowed(text), 0);
    }
    let mut out = String::with_capacity(text.len());
    let mut count = 0;
    for line in text.lines() {
        if is_polyline(line) {
            out.push('#');
            count += 1;
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    (Cow::Owned(out), count)
}

/// Vertices (`v`) and triangles (after triangulation; a 1- or 2-corner face counts as one
/// degenerate triangle, as tobj makes it) of OBJ text, counted without parsing numbers.
pub(super) fn obj_counts(text: &str) -> (u64, u64) {
    let (mut vertices, mut triangles) = (0u64, 0u64);
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => vertices += 1,
            Some("f") => triangles += (words.count() as u64).saturating_sub(2).max(1),
            _ => {}
        }
    }
    (vertices, triangles)
}

/// The [`Facts`] of OBJ text that the parallel reader leaves to tobj, counted line by line as
/// that reader counts them (polylines skipped).
pub(super) fn slow_facts(text: &str) -> Facts {
    let (vertices, triangles) = obj_counts(text);
    let mut facts = Facts {
        vertices,
        triangles,
        ..Facts::default()
    };
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("s") => facts.smoothing |= super::parse::smoothing_group(words.next()),
            Some("vn") => facts.normals += 1,
            Some("vt") => facts.texcoords += 1,
            Some("l") => facts.polylines += 1,
            Some("f") => facts.ngons += u64::from(words.count() >= 5),
            _ => {}
        }
        if let Some(rest) = line.trim_start().strip_prefix("usemtl")
            && rest.starts_with([' ', '\t'])
            && !rest.trim().is_empty()
        {
            facts.usemtl.insert(rest.trim().to_string());
        }
    }
    facts
}

/// The first line at which the OBJ stops loading, found by bisecting prefixes (tobj's errors
/// carry no position; this runs only on the error path).
fn error_line(text: &str) -> Option<usize> {
    let ends: Vec<usize> = text
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .chain((!text.ends_with('\n')).then_some(text.len()))
        .collect();
    let fails = |lines: usize| {
        let prefix = &text[..ends[lines - 1]];
        !matches!(read_plain(prefix), Ok(Ok(_)))
    };
    let (mut lo, mut hi) = (1, ends.len());
    if hi == 0 || !fails(hi) {
        return None;
    }
    while lo < hi {
        let mid = (lo + hi) / 2;
        if fails(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    Some(lo)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unnamed_materials_and_old_windows_non_finite_numbers_are_spelled_for_the_readers() {
        let same = "v 1 2 3\nusemtl a\n# usemtl\nf 1 1 1\n";
        let respell = |text: &str| {
            respell(text).map(|(text, white)| {
                assert_eq!(white, 0, "{text:?}");
                text
            })
        };
        assert_eq!(respell(same), None);
        assert_eq!(
            respell("v 0 0 0\r\nusemtl \r\n  usemtl\nf 1 1 1").as_deref(),
            Some("v 0 0 0\r\nusemtl (no name)\r\nusemtl (no name)\nf 1 1 1")
        );
        assert_eq!(
            respell("v 1.#IND -1.#IND00 1.#INF\nvn -1.#INF00 1.#QNAN0 0\n# 1.#IND\nv 1 2 3\n")
                .as_deref(),
            Some("v NaN NaN inf\nvn -inf NaN 0\n# 1.#IND\nv 1 2 3\n")
        );
        assert_eq!(
            respell("usemtl\nv 1.#IND 0 0\n").as_deref(),
            Some("usemtl (no name)\nv NaN 0 0\n"),
            "both at once"
        );
        // Not such a number: left for the reader's error.
        assert_eq!(respell("v 1.#IX 0 0\nv a.#IND 0 0\n"), None);
    }

    #[test]
    fn vertices_without_a_colour_among_coloured_ones_are_made_white() {
        let text = "v 0 0 0\r\nv 0 0 1 0 0 1\n  v 0 1 0 \nv 1 0 0 1 0.6 0.3\nf 1 2 3\n";
        assert_eq!(
            respell(text),
            Some((
                "v 0 0 0 1 1 1\r\nv 0 0 1 0 0 1\n  v 0 1 0 1 1 1\nv 1 0 0 1 0.6 0.3\nf 1 2 3\n"
                    .to_string(),
                2
            ))
        );
        // Every vertex coloured, or none, or a weight `w` (four numbers): as it was.
        assert_eq!(respell("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\n"), None);
        assert_eq!(respell("v 0 0 0\nv 1 0 0 1\n"), None);
        // With an unnamed material too: both.
        assert_eq!(
            respell("usemtl\nv 0 0 0\nv 1 0 0 1 0 0\n"),
            Some((
                "usemtl (no name)\nv 0 0 0 1 1 1\nv 1 0 0 1 0 0\n".to_string(),
                1
            ))
        );
    }

    #[test]
    fn continued_lines_are_joined_and_later_lines_keep_their_numbers() {
        let join = |t| join_continued_lines(t).into_owned();
        // Nothing continued: the text itself, not a copy.
        for t in ["v 0 0 0\nf 1 2 3\n", "mtllib C:\\models\\m.mtl\n"] {
            assert!(matches!(join_continued_lines(t), Cow::Borrowed(_)), "{t:?}");
        }
        assert_eq!(
            join("v 0 0 0\nf 1 2 \\\n 3 4\nf 1 2 3\n"),
            "v 0 0 0\nf 1 2   3 4\n\nf 1 2 3\n"
        );
        // CRLF, a statement over three lines, and one that ends the file.
        assert_eq!(
            join("f 1 \\\r\n2 \\\r\n3\r\nv 0 0 0\r\n"),
            "f 1  2  3\r\n\n\nv 0 0 0\r\n"
        );
        assert_eq!(join("v 1 2 \\\n3"), "v 1 2  3\n");
        assert_eq!(join("v 0 0 0\nf 1 2 \\\n"), "v 0 0 0\nf 1 2  \n");
        // A comment or a file name ending in `\` does not take the next line.
        let kept = "# a note \\\nv 0 0 0\nmtllib C:\\models\\\nv 1 0 0\nf 1 2 \\\n3\n";
        assert_eq!(
            join(kept),
            "# a note \\\nv 0 0 0\nmtllib C:\\models\\\nv 1 0 0\nf 1 2  3\n\n"
        );
        for t in [
            "v 0 0 0\nf 1 2 \\\n 3 4\nf 1 2 3\n",
            "f 1 \\\r\n2 \\\r\n3\r\nv 0 0 0\r\n",
            kept,
        ] {
            assert_eq!(join(t).lines().count(), t.lines().count(), "{t:?}");
        }
    }

    #[test]
    fn error_lines_are_found() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 x\nf 1 2 3\n";
        assert_eq!(error_line(text), Some(4));
    }

    #[test]
    fn panics_in_quietly_are_caught_and_others_still_reported() {
        assert_eq!(quietly(|| 7), Ok(7));
        assert_eq!(quietly(|| -> i32 { panic!("hostile") }), Err(()));
        assert!(!QUIET.with(Cell::get), "the flag is reset after the panic");
    }
}
