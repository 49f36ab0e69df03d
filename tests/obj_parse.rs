//! raytree's parallel OBJ reader (`scene::obj::parse`) gives exactly what tobj gives, on every
//! OBJ of the fixtures and assets, on hostile lines, on generated files big enough to be read in
//! several chunks, and on what it must leave to tobj (it gives up rather than differ). The
//! random OBJs of `tests/fuzz.rs` check the same property.

mod obj_compare;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use obj_compare::check;

/// MTL files next to `folder`'s OBJs, read by tobj (a missing one is tobj's error).
fn mtl_in(folder: PathBuf) -> impl Fn(&Path) -> tobj::MTLLoadResult {
    move |p: &Path| {
        // Regular files only: the hostile corpus names devices.
        let path = folder.join(p);
        if !std::fs::metadata(&path).is_ok_and(|m| m.is_file() && m.len() < 1 << 20) {
            return Err(tobj::LoadError::OpenFileFailed);
        }
        let text = std::fs::read_to_string(path).map_err(|_| tobj::LoadError::OpenFileFailed)?;
        // tobj panics on one-number colours; the corpus has such MTLs.
        std::panic::catch_unwind(|| tobj::load_mtl_buf(&mut text.as_bytes()))
            .unwrap_or(Err(tobj::LoadError::MaterialParseError))
    }
}

fn objs(folder: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(folder) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() && p.extension().is_none_or(|x| x != "obj") {
            objs(&p, out);
        } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("obj")) && p.is_file() {
            out.push(p);
        }
    }
}

#[test]
fn every_obj_of_the_fixtures_and_assets_reads_as_tobj_reads_it() {
    let mut files = Vec::new();
    objs(Path::new("tests/fixtures"), &mut files);
    objs(Path::new("assets"), &mut files);
    assert!(files.len() >= 20, "the corpus: {files:?}");
    let mut taken = 0;
    for file in &files {
        let bytes = std::fs::read(file).expect("read");
        let text = String::from_utf8_lossy(&bytes);
        let folder = file.parent().expect("a folder").to_path_buf();
        if check(&text, &mtl_in(folder)) {
            taken += 1;
        }
    }
    // The well-formed models (assets, fixtures/models, most hostile ones) take the fast path.
    assert!(
        taken >= 10,
        "only {taken} of {} files read by the fast reader",
        files.len()
    );
}

/// Lines that the fast reader must either read as tobj does or leave to it.
const HOSTILE: &[&str] = &[
    "f 1 2 3",
    "f 1/1/1 2/2/2 3/3/3",
    "f 1//1 2//2 3//3",
    "f 1/1 2/2 3/3",
    "f 1 2/2 3//3",
    "f 1",
    "f 1 2",
    "f",
    "f 1 2 3 4 5 6 7",
    "f 0 1 2",
    "f -1 -2 -3",
    "f +1 2 3",
    "f 1/2/3/4 2 3",
    "f 1/ 2/ 3/",
    "f 1// 2// 3//",
    "f 99 1 2",
    "f 1/99 2 3",
    "f 1//99 2 3",
    "f 1/2/3/ 2 3",
    "f 4294967296 1 2",
    "f 4294967295 1 2",
    "f 99999999999999999999 1 2",
    "f 1.5 2 3",
    "f a b c",
    "l 1 2",
    "l 1 2 3",
    "v 1 2 3",
    "v 1 2",
    "v 1 2 3 4",
    "v 1 2 3 0",
    "v 1 2 3 1 0 0",
    "v 1 2 3 4 5",
    "v nan inf -inf",
    "v 1e39 -0 1e-45",
    "v x y z",
    "vt 0.5 0.5",
    "vt 0.5",
    "vt 0.5 0.5 0.5",
    "vt 1 2 x",
    "vn 0 0 1",
    "vn 0 0",
    "vn 0 0 1 7",
    "o",
    "o part",
    "g",
    "g a b",
    "  o  spaced ",
    "\to tabbed",
    "o\tname",
    "usemtl",
    "usemtl red",
    "usemtl nowhere",
    "usemtl\tred",
    "usemtl  ",
    "mtllib m.mtl",
    "mtllib",
    "mtllib missing.mtl",
    "mtllib a b.mtl",
    "s 1",
    "s off",
    "# v 1 2 3",
    "#v",
    "p 1",
    "curv 0 1",
    "vp 1 2",
    "\u{a0}v 1 2 3",
    "v\u{a0}1 2 3",
    "v 1\u{a0}2 3",
    "f 1\u{2003}2 3",
    "o caf\u{e9}",
    "g \u{3000}x\u{3000}",
    "v 1 2 3\r",
    "f 1 2 3\r",
    "o x\r",
    "f 1 2 3 \\",
    "\\",
    "v 1 2 \\",
    "3",
    "\u{feff}v 1 2 3",
    "v 1 2 3 # comment",
    "f 1 2 3 # c",
    "vn 1 2 3 4 5",
    "v  1   2\t3  ",
    "\x0bv 1 2 3",
    "\x0cf 1 2 3",
];

#[test]
fn hostile_lines_read_as_tobj_reads_them_or_go_to_tobj() {
    let mtl = |p: &Path| -> tobj::MTLLoadResult {
        match p.to_str() {
            Some("m.mtl") => {
                tobj::load_mtl_buf(&mut "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n".as_bytes())
            }
            _ => Err(tobj::LoadError::OpenFileFailed),
        }
    };
    let base = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 0 1 0\nvn 1 0 0\n";
    let mut taken = 0;
    let mut total = 0;
    for line in HOSTILE {
        // Alone, after a well-formed start, between faces, twice, and without a final newline.
        for text in [
            format!("{line}\n"),
            format!("{base}{line}\n"),
            format!(
                "mtllib m.mtl\n{base}usemtl red\nf 1 2 3\n{line}\nf 2/2/2 3/3/3 4/1/1\nusemtl blue\nf 1 3 4\n"
            ),
            format!("{base}{line}\n{line}\nf 1 2 3\n"),
            format!("{base}f 1 2 3\n{line}"),
            format!("{base}{line}\r\nf 1/1 2/2 3\r\n"),
        ] {
            total += 1;
            if check(&text, &mtl) {
                taken += 1;
            }
        }
    }
    // Most of these are ordinary enough to be read by the fast reader.
    assert!(taken * 3 >= total, "only {taken} of {total} taken");
}

/// Seeded numbers: each call gives a number below `n`.
fn below(seed: u64) -> impl FnMut(u32) -> u32 {
    let mut pcg = raytree::rng::Pcg::new(seed);
    move |n: u32| pcg.below(n as usize) as u32
}

/// A file of many groups, materials and kinds of faces, over 1 MiB so that it is read in
/// several chunks, whose statements fall on both sides of the chunk boundaries.
fn big_file(seed: u32) -> String {
    let mut rnd = below(u64::from(seed));
    let mut out = String::from("mtllib m.mtl\n");
    let (mut v, mut vt, mut vn) = (0u32, 0u32, 0u32);
    while out.len() < 3 << 20 {
        match rnd(100) {
            0..=29 => {
                let _ = writeln!(
                    out,
                    "v {} {} {}",
                    rnd(1000) as f32 / 7.0,
                    rnd(999) as f32 * 0.13,
                    -(rnd(77) as f32)
                );
                v += 1;
            }
            30..=37 => {
                let _ = writeln!(out, "vt {} {}", rnd(100) as f32 / 100.0, rnd(3) as f32);
                vt += 1;
            }
            38..=45 => {
                let _ = writeln!(out, "vn 0 {} 1", rnd(5));
                vn += 1;
            }
            46..=90 if v > 0 => {
                let corners = 1 + rnd(6);
                out.push('f');
                let form = rnd(4);
                for _ in 0..corners {
                    let i = 1 + rnd(v);
                    let _ = match form {
                        0 => write!(out, " {i}"),
                        1 if vt > 0 => write!(out, " {i}/{}", 1 + rnd(vt)),
                        2 if vn > 0 => write!(out, " {i}//{}", 1 + rnd(vn)),
                        3 if vt > 0 && vn > 0 => {
                            write!(out, " {i}/{}/{}", 1 + rnd(vt), 1 + rnd(vn))
                        }
                        _ => write!(out, " {i}"),
                    };
                }
                out.push('\n');
            }
            91..=93 => {
                let _ = writeln!(out, "o object{}", rnd(9));
            }
            94..=95 => {
                let _ = writeln!(out, "g");
            }
            96..=98 => {
                let _ = writeln!(out, "usemtl {}", ["red", "blue", "none"][rnd(3) as usize]);
            }
            _ => out.push_str("# a comment\n\ns 1\n"),
        }
    }
    out
}

#[test]
fn big_files_in_several_chunks_read_as_tobj_reads_them() {
    let mtl = |_: &Path| {
        tobj::load_mtl_buf(&mut "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n".as_bytes())
    };
    for seed in 1..4 {
        let text = big_file(seed);
        assert!(
            check(&text, &mtl),
            "seed {seed}: the fast reader takes a well-formed file"
        );
    }
    // The benchmark torus too.
    let text = raytree::scene::procedural::bumpy_torus_obj(200_000);
    assert!(check(&text, &mtl));
}

/// A bare OBJ loaded through the whole loader gives the same scene as before the fast reader
/// (tobj only): the fast path is not just equal in isolation. With and without polylines (which
/// the loader skips and counts in its one pass), and with `usemtl` names no library defines
/// (which it collects in the same pass): the same triangles, materials and warnings.
#[test]
fn scenes_load_the_same_through_either_reader() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n",
    )
    .expect("write");
    let plain = big_file(9);
    let lines = plain.replacen("\nf ", "\nl 1 2 3\n  l 2 3\nf ", 3);
    for (text, warning) in [
        (
            &plain,
            "`usemtl` names materials that no material library defines (`none`)",
        ),
        (&lines, "ignored 6 polylines (`l`)"),
    ] {
        let path = dir.path().join("big.obj");
        std::fs::write(&path, text).expect("write");
        let fast = raytree::scene::load_scene_file(&path).expect("loads");
        // With a negative index at the end, the whole file goes to tobj; the index adds one face.
        let slow_text = format!("{text}f -1 -2 -3\n");
        std::fs::write(&path, &slow_text).expect("write");
        assert!(
            raytree::scene::obj::parse::parse(&slow_text, |_| Ok(Default::default())).is_none()
        );
        let slow = raytree::scene::load_scene_file(&path).expect("loads");
        assert!(fast.triangles.len() > 10_000);
        assert_eq!(
            slow.triangles.len(),
            fast.triangles.len() + 1,
            "{:?}",
            slow.warnings
        );
        for (a, b) in fast.triangles.iter().zip(slow.triangles.iter()) {
            assert_eq!(a.vertices, b.vertices);
            assert_eq!(a.material, b.material);
        }
        assert_eq!(fast.materials.len(), slow.materials.len());
        assert_eq!(fast.warnings, slow.warnings);
        assert!(
            fast.warnings.iter().any(|w| w.contains(warning)),
            "{warning}: {:?}",
            fast.warnings
        );
    }
}

/// The loader's pass skips polylines and counts what the memory budget and the warnings need,
/// in one pass over chunks: the same counts as line by line, on a file read in several chunks.
#[test]
fn the_loader_pass_counts_what_the_budget_and_warnings_need() {
    use raytree::scene::obj::parse::{Polylines, scan};
    let text = big_file(5).replacen("\nf ", "\nl 1 1\n\t usemtl  odd name \nf ", 40);
    let scanned = scan(&text, Polylines::Skip).expect("the fast reader takes it");
    let facts = scanned.facts().clone();
    assert_eq!(facts, obj_compare::facts_by_lines(&text));
    assert_eq!(facts.polylines, 40);
    let names: Vec<&str> = facts.usemtl.iter().map(String::as_str).collect();
    assert_eq!(names, ["blue", "none", "odd name", "red"]);
    assert!(facts.triangles > 50_000 && facts.vertices > 10_000);
    // As faces (tobj's way) the polylines are triangles of the models, not of the count.
    let as_faces = scan(&text, Polylines::AsFaces).expect("takes it");
    assert_eq!(as_faces.facts().polylines, 0);
    assert_eq!(as_faces.facts().triangles, facts.triangles);
    let corners = |s: raytree::scene::obj::parse::Scanned| -> usize {
        let (models, _) = s
            .assemble(|_| Ok(Default::default()))
            .expect("assembles")
            .expect("loads");
        models.iter().map(|m| m.mesh.indices.len()).sum()
    };
    assert_eq!(corners(as_faces), corners(scanned) + 3 * 40);
    assert!(obj_compare::check(&text, &|_| Ok(Default::default())));
}

/// Faces that give `vn` and `vt` at every corner, at some, or at none, mixed in one file read
/// in several chunks: the loader's fast path (whose reading pass flags the faces) and its tobj
/// path (which reads the face lines again for them) keep the same faces' normals and texture
/// coordinates, and give the same warnings.
#[test]
fn faces_with_mixed_corners_are_flagged_alike_on_either_path() {
    let dir = tempfile::tempdir().expect("temp dir");
    let checker = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/models/checker.png");
    std::fs::copy(checker, dir.path().join("checker.png")).expect("copy the texture");
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl t\nKd 1 1 1\nmap_Kd checker.png\n",
    )
    .expect("write");
    let mut rnd = below(12_345);
    let mut text = String::from("mtllib m.mtl\nusemtl t\n");
    for k in 0..400 {
        let a = k as f32 * 0.01;
        let _ = writeln!(text, "v {a} {} 0\nvt {a} 0.5\nvn 0 {a} 1", a * a);
    }
    while text.len() < 3 << 20 {
        let corners = 3 + rnd(3);
        text.push('f');
        // Mostly faces that give both everywhere, so that the others are scattered.
        let whole = rnd(3) > 0;
        for _ in 0..corners {
            let (v, t, n) = (1 + rnd(400), 1 + rnd(400), 1 + rnd(400));
            let _ = match if whole { 3 } else { rnd(4) } {
                0 => write!(text, " {v}"),
                1 => write!(text, " {v}/{t}"),
                2 => write!(text, " {v}//{n}"),
                _ => write!(text, " {v}/{t}/{n}"),
            };
        }
        text.push('\n');
    }
    let path = dir.path().join("m.obj");
    std::fs::write(&path, &text).expect("write");
    assert!(raytree::scene::obj::parse::parse(&text, |_| Ok(Default::default())).is_some());
    let fast = raytree::scene::load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    // A negative index sends the whole file to tobj; its face adds one triangle, flat.
    let slow_text = format!("{text}f -1 -2 -3\n");
    assert!(raytree::scene::obj::parse::parse(&slow_text, |_| Ok(Default::default())).is_none());
    std::fs::write(&path, &slow_text).expect("write");
    let slow = raytree::scene::load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));

    assert_eq!(slow.triangles.len(), fast.triangles.len() + 1);
    assert_eq!((fast.attributes.len(), slow.attributes.len()), (1, 1));
    let (a, b) = (&fast.attributes[0], &slow.attributes[0]);
    let (mut normals, mut uvs) = ([0usize; 2], [0usize; 2]);
    for i in 0..fast.triangles.len() {
        assert_eq!(a.normals_of(i), b.normals_of(i), "triangle {i}: normals");
        assert_eq!(
            a.uvs_of(i),
            b.uvs_of(i),
            "triangle {i}: texture coordinates"
        );
        normals[usize::from(a.normals_of(i).is_some())] += 1;
        uvs[usize::from(a.uvs_of(i).is_some())] += 1;
    }
    let last = fast.triangles.len();
    assert_eq!((b.normals_of(last), b.uvs_of(last)), (None, None));
    // Both kinds of face, many of each.
    assert!(
        normals.iter().chain(&uvs).all(|&n| n > 1000),
        "{normals:?} {uvs:?}"
    );
    assert_eq!(fast.warnings, slow.warnings);
    // The faces that repeat a vertex are dropped after the flags are read: the flags of the
    // faces after them must still be theirs.
    // The random normals lie against the winding of about a third of the faces, so those are
    // turned round, alike on both paths.
    assert_eq!(fast.warnings.len(), 4, "{:?}", fast.warnings);
    assert!(fast.warnings[0].contains("normals (`vn`) at some corners only"));
    assert!(fast.warnings[1].contains("texture coordinates (`vt`) at some corners only"));
    assert!(fast.warnings[2].contains("degenerate triangles"));
    assert!(fast.warnings[3].contains("faces are wound clockwise"));
}

#[test]
fn a_concave_face_is_cut_inside_its_outline_with_its_attributes() {
    // An L-shaped n-gon (area 3) as Blender writes a floor plan, from a corner whose fan
    // covers the notch [1, 2]², with a normal of its own at every corner (x, y, 4); and a
    // convex hexagon, whose fan stays.
    let text = "v 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\n\
        vn 2 1 4\nvn 1 1 4\nvn 1 2 4\nvn 0 2 4\nvn 0 0 4\nvn 2 0 4\n\
        f 1//1 2//2 3//3 4//4 5//5 6//6\n\
        v 5 0 0\nv 6 0 0\nv 7 1 0\nv 6 2 0\nv 5 2 0\nv 4 1 0\nf 7 8 9 10 11 12\n";
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("plan.obj");
    std::fs::write(&path, text).expect("write");
    let scene = raytree::scene::load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.triangles.len(), 8);
    let mut l_area = 0.0;
    for (i, t) in scene.triangles.iter().enumerate().take(4) {
        let [a, b, c] = t.vertices;
        let n = (b - a).cross(c - a);
        assert!(n.z > 0.0, "triangle {i} keeps the face's winding: {n}");
        l_area += 0.5 * n.z;
        let centre = (a + b + c) / 3.0;
        assert!(
            !(centre.x > 1.0 && centre.y > 1.0),
            "triangle {i} ({a}, {b}, {c}) lies in the notch"
        );
        // Each corner kept its own normal.
        let (attrs, local) = scene.attributes_of(i).expect("attributes");
        let normals = attrs.normals_of(local).expect("normals");
        for (p, n) in t.vertices.iter().zip(normals) {
            let want = glam::Vec3::new(p.x, p.y, 4.0).normalize();
            assert!((n - want).length() < 1e-6, "{p} has the normal {n}");
        }
    }
    assert!((l_area - 3.0).abs() < 1e-5, "the L's area {l_area}");
    let hex_area: f32 = scene.triangles[4..]
        .iter()
        .map(|t| {
            let [a, b, c] = t.vertices;
            0.5 * (b - a).cross(c - a).z
        })
        .sum();
    assert!(
        (hex_area - 4.0).abs() < 1e-5,
        "the hexagon's area {hex_area}"
    );
}
