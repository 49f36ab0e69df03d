//! A parallel reader for the common part of OBJ (`v`, `vt`, `vn`, `f`, `l`, `o`, `g`, `usemtl`,
//! `mtllib`, comments), giving exactly what `tobj` 4.0.5 gives with the options
//! `triangulate: true, single_index: false` (the ones the loader gives tobj): the same models,
//! names, material ids, positions, normals, texture coordinates and the three index lists, in
//! the same order, bit for bit. It is about ten times faster than `tobj` on big meshes, which
//! spends its time hashing every face corner.
//!
//! How: the text is cut at line ends into one chunk per few megabytes; the chunks are read in
//! parallel (numbers by the standard library's `f32` parser, the one tobj uses), each into its
//! own vertex lists, triangle corners (polygons fanned as tobj fans them) and a list of the
//! statements that start a new model; then one sequential pass splits the corners into models
//! at those statements and renumbers each model's vertices in first-use order, as tobj does,
//! with flat lookup tables instead of hash maps.
//!
//! The same pass counts what the loader needs before it builds anything ([`Facts`]: vertices
//! and triangles for the memory budget, `vn` and `vt` for the attributes' share, polylines, and
//! the `usemtl` names for the unknown-material warning), so the mesh loader never scans the text
//! again: [`scan`] reads the chunks, the loader checks the budget with the facts, and
//! [`Scanned::assemble`] builds the models.
//!
//! Whatever this reader does not handle exactly as tobj does makes it give up ([`None`]), and
//! the caller then runs tobj: negative (relative) and zero indices, `v` lines with a `w` or
//! vertex colours, every line tobj would reject (a bad number, too few numbers, a corner out
//! of range, an empty `usemtl`), which also keeps tobj's error messages. Unknown statements
//! are skipped, as tobj skips them.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::corners::{ALL_NORMALS, ALL_UVS, FaceCorners};

/// An absent `vt` or `vn` in a face corner (`1//3`, `1`).
const MISSING: u32 = u32::MAX;

/// A statement that may end the current model, at the corner count where it appears.
struct Event {
    /// Corners (three per triangle) read before it, in the whole file.
    corner: usize,
    /// Positions, texture coordinates and normals read before it, in the whole file.
    counts: [usize; 3],
    kind: EventKind,
}

enum EventKind {
    /// `o` or `g`: the name of the following faces.
    Name(String),
    /// `usemtl`.
    UseMtl(String),
    /// `mtllib`.
    MtlLib(PathBuf),
}

/// One chunk of lines, read.
#[derive(Default)]
struct Chunk {
    positions: Vec<f32>,
    texcoords: Vec<f32>,
    normals: Vec<f32>,
    /// `(v, vt, vn)` of every triangle corner, 0-based, [`MISSING`] where absent.
    corners: Vec<[u32; 3]>,
    /// With chunk-local counts until [`scan`] makes them global.
    events: Vec<Event>,
    /// Triangles of `f` lines (not of polylines read as faces).
    face_triangles: u64,
    /// `l` lines skipped ([`Polylines::Skip`]).
    polylines: u64,
    /// `f` lines of five corners or more.
    ngons: u64,
    /// `usemtl` names as the loader's warning names them (see [`Facts::usemtl`]).
    usemtl: Vec<String>,
    /// For the triangles of the `f` lines, in runs of equal flags (most files have one run):
    /// [`ALL_UVS`] and [`ALL_NORMALS`] when the face gives `vt` (`vn`) at every corner, and
    /// how many triangles in a row have them.
    given: Vec<(u8, usize)>,
    /// `f` lines that give `vt` (`vn`) at some corners but not all.
    partial: [usize; 2],
    /// An `s` line names a smoothing group ([`smoothing_group`]).
    smoothing: bool,
}

/// What to do with polyline (`l`) statements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Polylines {
    /// Read as faces, as tobj reads them (`l 1 2 3` is a triangle).
    AsFaces,
    /// Skipped and counted, as if each were a comment: what the loader wants (a line has no
    /// surface), the same result as tobj on the text with its `l` lines commented out.
    Skip,
}

/// What the one pass of [`scan`] counted.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Facts {
    /// `v` statements.
    pub vertices: u64,
    /// `vt` statements.
    pub texcoords: u64,
    /// `vn` statements.
    pub normals: u64,
    /// Triangles of the `f` statements after triangulation (a face of one or two corners is
    /// one degenerate triangle, as tobj makes it).
    pub triangles: u64,
    /// `l` statements skipped ([`Polylines::Skip`]; 0 with [`Polylines::AsFaces`]).
    pub polylines: u64,
    /// `f` statements of five corners or more (n-gons, which may be concave).
    pub ngons: u64,
    /// The names of `usemtl` lines that start (after leading whitespace) with `usemtl` and a
    /// space or tab, trimmed, without empty ones.
    pub usemtl: BTreeSet<String>,
    /// An `s` statement names a smoothing group (a number other than 0, or a name other than
    /// `off`): the exporter meant those faces to shade smooth.
    pub smoothing: bool,
}

/// The smoothing group of every triangle of the `f` lines, in the file's order (tobj's
/// triangles are in that order too): 0 under `s off` or `s 0` and before any `s`, else an id
/// for the group's number (so `s 01` is `s 1`) or name. One serial pass, made only for a file
/// with groups ([`Facts::smoothing`]) and faces without `vn`.
pub(crate) fn smoothing_groups(text: &str) -> Vec<u32> {
    let mut ids: std::collections::HashMap<Result<u64, &str>, u32> = Default::default();
    let mut current = 0;
    let mut out = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("s") => {
                let word = words.next();
                current = match word {
                    Some(w) if smoothing_group(Some(w)) => {
                        let next = ids.len() as u32 + 1;
                        *ids.entry(w.parse::<u64>().map_err(|_| w)).or_insert(next)
                    }
                    _ => 0,
                };
            }
            Some("f") => {
                // Fanned as tobj fans them: a face of fewer than three corners is one triangle.
                let triangles = words.count().saturating_sub(2).max(1);
                out.extend(std::iter::repeat_n(current, triangles));
            }
            _ => {}
        }
    }
    out
}

/// Whether the word after `s` names a smoothing group: anything but `off` and 0.
pub(super) fn smoothing_group(word: Option<&str>) -> bool {
    word.is_some_and(|w| !w.eq_ignore_ascii_case("off") && w.parse::<u64>() != Ok(0))
}

/// The text read in chunks by [`scan`], not yet made into models.
pub struct Scanned {
    chunks: Vec<Chunk>,
    facts: Facts,
}

impl std::fmt::Debug for Scanned {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scanned")
            .field("chunks", &self.chunks.len())
            .field("facts", &self.facts)
            .finish()
    }
}

/// Words split at the whitespace `str::split_whitespace` knows in ASCII (space, tab, line
/// feed, vertical tab, form feed, carriage return); only used on ASCII lines, where it gives
/// the same words.
struct AsciiWords<'a> {
    line: &'a str,
    at: usize,
}

fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | 0x0B | 0x0C | b'\r')
}

impl<'a> Iterator for AsciiWords<'a> {
    type Item = &'a str;
    fn next(&mut self) -> Option<&'a str> {
        let bytes = self.line.as_bytes();
        let mut i = self.at;
        while i < bytes.len() && is_space(bytes[i]) {
            i += 1;
        }
        if i == bytes.len() {
            self.at = i;
            return None;
        }
        let start = i;
        while i < bytes.len() && !is_space(bytes[i]) {
            i += 1;
        }
        self.at = i;
        self.line.get(start..i)
    }
}

/// Reads OBJ text as tobj would (see the module documentation), calling `load_mtl` for each
/// `mtllib` in file order; `None` when tobj must read it instead. `load_mtl` may have been
/// called before `None` is returned. Polylines are read as faces, as tobj reads them.
pub fn parse(
    text: &str,
    load_mtl: impl FnMut(&Path) -> tobj::MTLLoadResult,
) -> Option<tobj::LoadResult> {
    scan(text, Polylines::AsFaces)?.assemble(load_mtl)
}

/// The parallel pass over `text`: every chunk read and counted; `None` when a line is one for
/// tobj (see the module documentation). Nothing is allocated beyond the chunks' own lists
/// (at most a few times the text's size); [`Scanned::assemble`] makes the models.
pub fn scan(text: &str, polylines: Polylines) -> Option<Scanned> {
    let mut chunks: Vec<Chunk> = split_lines(text)
        .par_iter()
        .map(|part| parse_chunk(part, polylines))
        .collect::<Option<Vec<Chunk>>>()?;

    // Chunk-local counts to whole-file ones.
    let mut base = (0usize, [0usize; 3]);
    let mut facts = Facts::default();
    for chunk in &mut chunks {
        for e in &mut chunk.events {
            e.corner += base.0;
            for k in 0..3 {
                e.counts[k] += base.1[k];
            }
        }
        base.0 += chunk.corners.len();
        base.1[0] += chunk.positions.len() / 3;
        base.1[1] += chunk.texcoords.len() / 2;
        base.1[2] += chunk.normals.len() / 3;
        facts.triangles += chunk.face_triangles;
        facts.polylines += chunk.polylines;
        facts.ngons += chunk.ngons;
        facts.usemtl.extend(std::mem::take(&mut chunk.usemtl));
        facts.smoothing |= chunk.smoothing;
    }
    facts.vertices = base.1[0] as u64;
    facts.texcoords = base.1[1] as u64;
    facts.normals = base.1[2] as u64;
    Some(Scanned { chunks, facts })
}

impl Scanned {
    /// What the pass counted.
    pub fn facts(&self) -> &Facts {
        &self.facts
    }

    /// Which faces of the `f` lines give `vt` and `vn` at every corner, and how many give them
    /// at some corners only: what [`super::corners::face_corners`] finds by reading the
    /// text again, for a file with both lists (see [`FaceCorners::only`]). Taken out: a second
    /// call gives nothing. With [`Polylines::AsFaces`] the polylines' triangles are not in it.
    pub(crate) fn take_face_corners(&mut self) -> FaceCorners {
        let mut out = FaceCorners {
            triangles: Vec::with_capacity(self.facts.triangles as usize),
            partial_uvs: 0,
            partial_normals: 0,
        };
        for chunk in &mut self.chunks {
            for (flags, n) in std::mem::take(&mut chunk.given) {
                out.triangles.extend(std::iter::repeat_n(flags, n));
            }
            out.partial_uvs += std::mem::take(&mut chunk.partial[0]);
            out.partial_normals += std::mem::take(&mut chunk.partial[1]);
        }
        out
    }

    /// The models and materials, exactly as tobj gives them, calling `load_mtl` for each
    /// `mtllib` in file order; `None` when a face names a vertex out of range (tobj's error).
    pub fn assemble(
        self,
        mut load_mtl: impl FnMut(&Path) -> tobj::MTLLoadResult,
    ) -> Option<tobj::LoadResult> {
        let chunks = self.chunks;
        let totals = [
            self.facts.vertices as usize,
            self.facts.texcoords as usize,
            self.facts.normals as usize,
        ];
        let join = |pick: fn(&Chunk) -> &Vec<f32>, chunks: &[Chunk]| -> Vec<f32> {
            let mut out = Vec::with_capacity(chunks.iter().map(|c| pick(c).len()).sum());
            for c in chunks {
                out.extend_from_slice(pick(c));
            }
            out
        };
        let positions = join(|c| &c.positions, &chunks);
        let texcoords = join(|c| &c.texcoords, &chunks);
        let normals = join(|c| &c.normals, &chunks);
        // The corners stay in their chunks (a copy would cost time and memory).
        let mut events = Vec::new();
        let mut parts = Vec::with_capacity(chunks.len());
        for c in chunks {
            events.extend(c.events);
            parts.push(c.corners);
        }
        let corners = Corners::new(parts);
        let mut out = Assembly {
            positions: &positions,
            texcoords: &texcoords,
            normals: &normals,
            maps: [
                vec![MISSING; totals[0]],
                vec![MISSING; totals[1]],
                vec![MISSING; totals[2]],
            ],
            models: Vec::new(),
        };
        let mut name = "unnamed_object".to_string();
        let mut mat_id: Option<usize> = None;
        let mut materials: Vec<tobj::Material> = Vec::new();
        let mut mat_map: HashMap<String, usize> = HashMap::new();
        let mut mtl_error: Option<tobj::LoadError> = None;
        let mut start = 0;
        for e in events {
            match e.kind {
                EventKind::Name(n) => {
                    if e.corner > start {
                        out.pop(
                            corners.range(start, e.corner),
                            e.corner - start,
                            e.counts,
                            &name,
                            mat_id,
                        )?;
                        start = e.corner;
                    }
                    name = n;
                }
                EventKind::MtlLib(path) => match load_mtl(&path) {
                    Ok((mut mats, map)) => {
                        let offset = materials.len();
                        materials.append(&mut mats);
                        for (k, v) in map {
                            mat_map.insert(k, v + offset);
                        }
                    }
                    Err(err) => mtl_error = Some(err),
                },
                EventKind::UseMtl(m) => {
                    let new = mat_map.get(&m).copied();
                    if mat_id != new && e.corner > start {
                        out.pop(
                            corners.range(start, e.corner),
                            e.corner - start,
                            e.counts,
                            &name,
                            mat_id,
                        )?;
                        start = e.corner;
                    }
                    mat_id = new;
                }
            }
        }
        // tobj always ends with a model, empty or not.
        out.pop(
            corners.range(start, corners.len),
            corners.len - start,
            totals,
            &name,
            mat_id,
        )?;
        let materials = match (materials.is_empty(), mtl_error) {
            (true, Some(err)) => Err(err),
            _ => Ok(materials),
        };
        Some(Ok((out.models, materials)))
    }
}

/// The text cut after line ends into pieces of at least about 1 MiB, at most four per thread
/// (so small files stay in one piece).
fn split_lines(text: &str) -> Vec<&str> {
    let pieces = (rayon::current_num_threads() * 4).max(1);
    let size = (text.len() / pieces).max(1 << 20);
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(pieces + 1);
    let mut from = 0;
    while from < text.len() {
        let mut to = (from + size).min(text.len());
        while to < text.len() && bytes[to - 1] != b'\n' {
            to += 1;
        }
        // `to` follows a `\n` (or is the end), so it is a character boundary.
        match text.get(from..to) {
            Some(piece) => out.push(piece),
            None => return vec![text],
        }
        from = to;
    }
    out
}

fn parse_chunk(text: &str, polylines: Polylines) -> Option<Chunk> {
    let mut chunk = Chunk::default();
    for line in text.split('\n') {
        let mut words = AsciiWords { line, at: 0 };
        match words.next() {
            None => {}
            // Unicode whitespace may hide in a non-ASCII first word (`\u{a0}v`); such a line
            // is split as tobj splits it. In the numbers, it makes them unreadable (`None`).
            Some(first) if !first.is_ascii() => {
                parse_line(line, line.split_whitespace(), polylines, &mut chunk)?;
            }
            Some(_) => parse_line(line, AsciiWords { line, at: 0 }, polylines, &mut chunk)?,
        }
    }
    Some(chunk)
}

/// Pushes `n` numbers from `words`; `None` when there are fewer or one is not a number. The
/// words after them are left unread (tobj ignores a `vt`'s third number).
fn numbers<'a>(
    words: &mut impl Iterator<Item = &'a str>,
    n: usize,
    out: &mut Vec<f32>,
) -> Option<()> {
    for _ in 0..n {
        out.push(words.next()?.parse::<f32>().ok()?);
    }
    Some(())
}

/// One face corner, `v`, `v/vt`, `v//vn` or `v/vt/vn`, 0-based, with [`MISSING`] for an
/// absent `vt` or `vn`; `None` for anything else (a zero, a sign, a fourth part, a letter).
fn corner(word: &str) -> Option<[u32; 3]> {
    let mut out = [MISSING; 3];
    let mut part = 0;
    let mut value: u64 = 0;
    let mut digits = 0;
    let mut finish = |part: usize, value: u64, digits: usize| -> Option<()> {
        if digits == 0 {
            // Only `vt` and `vn` may be left out.
            return (part > 0).then_some(());
        }
        // 0 and u32::MAX (kept for MISSING) are not plain indices.
        if value == 0 || value >= u64::from(u32::MAX) {
            return None;
        }
        out[part] = value as u32 - 1;
        Some(())
    };
    for b in word.bytes() {
        match b {
            b'0'..=b'9' => {
                value = value * 10 + u64::from(b - b'0');
                digits += 1;
                if digits > 10 {
                    return None;
                }
            }
            b'/' => {
                finish(part, value, digits)?;
                part += 1;
                if part > 2 {
                    return None;
                }
                value = 0;
                digits = 0;
            }
            _ => return None,
        }
    }
    finish(part, value, digits)?;
    Some(out)
}

fn parse_line<'a>(
    line: &'a str,
    mut words: impl Iterator<Item = &'a str>,
    polylines: Polylines,
    chunk: &mut Chunk,
) -> Option<()> {
    let Some(first) = words.next() else {
        return Some(());
    };
    match first {
        "v" => {
            numbers(&mut words, 3, &mut chunk.positions)?;
            // A `w` or vertex colours: tobj's business.
            if words.next().is_some() {
                return None;
            }
        }
        "vt" => numbers(&mut words, 2, &mut chunk.texcoords)?,
        "vn" => numbers(&mut words, 3, &mut chunk.normals)?,
        "l" if polylines == Polylines::Skip => chunk.polylines += 1,
        "s" => chunk.smoothing |= smoothing_group(words.next()),
        "f" => {
            let before = chunk.corners.len();
            let (corners, given) = face(words, &mut chunk.corners)?;
            let triangles = (chunk.corners.len() - before) / 3;
            chunk.face_triangles += triangles as u64;
            chunk.ngons += u64::from(corners >= 5);
            // The same facts as [`super::corners`] finds by reading the line again.
            let all = |list: usize| given[list] == corners;
            let flags = (u8::from(all(0)) * ALL_UVS) | (u8::from(all(1)) * ALL_NORMALS);
            for (partial, given) in chunk.partial.iter_mut().zip(given) {
                *partial += usize::from(given > 0 && given < corners);
            }
            match chunk.given.last_mut() {
                Some((f, n)) if *f == flags => *n += triangles,
                _ => chunk.given.push((flags, triangles)),
            }
        }
        "l" => {
            face(words, &mut chunk.corners)?;
        }
        "o" | "g" => {
            let size = line.chars().next().map_or(1, char::len_utf8);
            let name = line.get(size..).unwrap_or("").trim();
            let name = if name.is_empty() {
                "unnamed_object"
            } else {
                name
            };
            push_event(chunk, EventKind::Name(name.to_string()));
        }
        "mtllib" => {
            let path = line.split_once(' ').unwrap_or_default().1.trim();
            push_event(chunk, EventKind::MtlLib(PathBuf::from(path)));
        }
        "usemtl" => {
            let name = line.split_once(' ').unwrap_or_default().1.trim();
            if name.is_empty() {
                return None;
            }
            // The loader warns about names no library defines, named as this finds them.
            if let Some(rest) = line.trim_start().strip_prefix("usemtl")
                && rest.starts_with([' ', '\t'])
                && !rest.trim().is_empty()
            {
                chunk.usemtl.push(rest.trim().to_string());
            }
            push_event(chunk, EventKind::UseMtl(name.to_string()));
        }
        _ => {}
    }
    Some(())
}

/// The triangles of a face's corner `words`, fanned as tobj fans them (one corner: one
/// triangle `a a a`; two: `a b b`); `None` for no corners or a bad one. Returns the face's
/// corners and how many of them give a `vt` and a `vn`.
fn face<'a>(
    mut words: impl Iterator<Item = &'a str>,
    out: &mut Vec<[u32; 3]>,
) -> Option<(usize, [usize; 2])> {
    let mut given = [0usize; 2];
    let mut count = |c: [u32; 3]| {
        given[0] += usize::from(c[1] != MISSING);
        given[1] += usize::from(c[2] != MISSING);
        c
    };
    let a = count(corner(words.next()?)?);
    let Some(word) = words.next() else {
        out.extend([a, a, a]);
        return Some((1, given));
    };
    let mut b = count(corner(word)?);
    let mut corners = 2;
    for word in words {
        let c = count(corner(word)?);
        out.extend([a, b, c]);
        b = c;
        corners += 1;
    }
    if corners == 2 {
        out.extend([a, b, b]);
    }
    Some((corners, given))
}

fn push_event(chunk: &mut Chunk, kind: EventKind) {
    chunk.events.push(Event {
        corner: chunk.corners.len(),
        counts: [
            chunk.positions.len() / 3,
            chunk.texcoords.len() / 2,
            chunk.normals.len() / 3,
        ],
        kind,
    });
}

/// The triangle corners of the whole file, in their chunks.
struct Corners {
    parts: Vec<Vec<[u32; 3]>>,
    /// The whole-file index of each part's first corner.
    offsets: Vec<usize>,
    len: usize,
}

impl Corners {
    fn new(parts: Vec<Vec<[u32; 3]>>) -> Self {
        let mut offsets = Vec::with_capacity(parts.len());
        let mut len = 0;
        for p in &parts {
            offsets.push(len);
            len += p.len();
        }
        Self {
            parts,
            offsets,
            len,
        }
    }

    /// Corners `start..end` of the whole file.
    fn range(&self, start: usize, end: usize) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.parts
            .iter()
            .zip(&self.offsets)
            .flat_map(move |(part, &offset)| {
                let lo = start.saturating_sub(offset).min(part.len());
                let hi = end.saturating_sub(offset).min(part.len());
                part[lo..hi].iter().copied()
            })
    }
}

/// The models made so far and the whole file's vertex lists.
struct Assembly<'a> {
    positions: &'a [f32],
    texcoords: &'a [f32],
    normals: &'a [f32],
    /// For positions, texture coordinates and normals: the index in the current model of each
    /// file index it uses, [`MISSING`] elsewhere (reset after each model).
    maps: [Vec<u32>; 3],
    models: Vec<tobj::Model>,
}

impl Assembly<'_> {
    /// Ends a model of the `n` `corners`, with `counts` positions, texture coordinates and normals
    /// read so far (a corner may only use those); `None` when one is out of range.
    fn pop(
        &mut self,
        corners: impl Iterator<Item = [u32; 3]>,
        n: usize,
        counts: [usize; 3],
        name: &str,
        mat_id: Option<usize>,
    ) -> Option<()> {
        let mut mesh = tobj::Mesh {
            material_id: mat_id,
            indices: Vec::with_capacity(n),
            ..Default::default()
        };
        let [pos_map, tex_map, norm_map] = &mut self.maps;
        let mut positions = List::new(
            (self.positions, 3, counts[0]),
            pos_map,
            &mut mesh.positions,
            &mut mesh.indices,
        );
        // The indices into a list the file does not have (yet) are ignored, as tobj ignores them.
        let mut texcoords = (counts[1] > 0).then(|| {
            let (values, indices) = (&mut mesh.texcoords, &mut mesh.texcoord_indices);
            List::new((self.texcoords, 2, counts[1]), tex_map, values, indices)
        });
        let mut normals = (counts[2] > 0).then(|| {
            let (values, indices) = (&mut mesh.normals, &mut mesh.normal_indices);
            List::new((self.normals, 3, counts[2]), norm_map, values, indices)
        });
        for list in [&mut texcoords, &mut normals].into_iter().flatten() {
            list.indices.reserve(n);
        }
        let result = (|| {
            for [v, vt, vn] in corners {
                positions.push(v)?;
                if let Some(list) = &mut texcoords {
                    list.push_or_repeat(vt)?;
                }
                if let Some(list) = &mut normals {
                    list.push_or_repeat(vn)?;
                }
            }
            Some(())
        })();
        positions.reset();
        for list in [texcoords, normals].iter_mut().flatten() {
            list.reset();
        }
        result?;
        self.models.push(tobj::Model::new(mesh, name.to_string()));
        Some(())
    }
}

/// One of a model's lists (positions, texture coordinates or normals) while it is assembled.
struct List<'a> {
    /// The whole file's values, `width` floats each, of which the model may use the first
    /// `count` (those read before it ends).
    all: &'a [f32],
    width: usize,
    count: usize,
    /// The model's index of each file index it uses, [`MISSING`] elsewhere.
    map: &'a mut [u32],
    /// The model's values, copied on first use, and its corners' indices into them.
    values: &'a mut Vec<f32>,
    indices: &'a mut Vec<u32>,
    /// The file indices set in `map`.
    used: Vec<u32>,
}

impl<'a> List<'a> {
    /// The list of the file's values `all` (`width` floats each, the first `count` usable),
    /// filling `values` and `indices` through `map`.
    fn new(
        (all, width, count): (&'a [f32], usize, usize),
        map: &'a mut [u32],
        values: &'a mut Vec<f32>,
        indices: &'a mut Vec<u32>,
    ) -> Self {
        Self {
            all,
            width,
            count,
            map,
            values,
            indices,
            used: Vec::new(),
        }
    }

    /// Adds a corner's file index `i`; `None` when it is out of range.
    fn push(&mut self, i: u32) -> Option<()> {
        let slot = self
            .map
            .get_mut(i as usize)
            .filter(|_| (i as usize) < self.count)?;
        if *slot == MISSING {
            *slot = (self.values.len() / self.width) as u32;
            let from = i as usize * self.width;
            self.values
                .extend_from_slice(self.all.get(from..from + self.width)?);
            self.used.push(i);
        }
        self.indices.push(*slot);
        Some(())
    }

    /// Adds a corner's `vt` or `vn` index `i` as tobj does: an absent one ([`MISSING`]) repeats
    /// the previous corner's, and the model's first corner without one takes the file's first.
    fn push_or_repeat(&mut self, i: u32) -> Option<()> {
        match (i, self.indices.last()) {
            (MISSING, Some(&last)) => {
                self.indices.push(last);
                Some(())
            }
            (MISSING, None) => self.push(0),
            (i, _) => self.push(i),
        }
    }

    /// Clears `map` for the next model.
    fn reset(&mut self) {
        for &i in &self.used {
            self.map[i as usize] = MISSING;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_and_indices() {
        assert_eq!(corner("3"), Some([2, MISSING, MISSING]));
        assert_eq!(corner("3/4"), Some([2, 3, MISSING]));
        assert_eq!(corner("3//5"), Some([2, MISSING, 4]));
        assert_eq!(corner("3/4/5"), Some([2, 3, 4]));
        for bad in ["0", "-1", "+1", "/1", "1/2/3/4", "1/x", "", "99999999999"] {
            assert_eq!(corner(bad), None, "{bad}");
        }
    }

    #[test]
    fn lines_are_split_at_line_ends() {
        let text = "v 1 2 3\n".repeat(300_000);
        let parts = split_lines(&text);
        assert_eq!(parts.concat(), text);
        assert!(parts.iter().all(|p| p.ends_with('\n')));
        assert_eq!(split_lines(""), Vec::<&str>::new());
    }
}
