//! Property-based fuzzing on stable Rust (proptest, seeded, deterministic) of the three ways
//! input enters raytree (docs/reliability.md):
//!
//! - scene TOML: the built-in scenes and every fixture, mutated (bytes flipped, cut short,
//!   numbers replaced by huge, tiny, NaN and infinite ones, values swapped between keys, lines
//!   inserted with random keys and values, deleted, duplicated);
//! - OBJ and MTL text, generated line by line (faces of 0 to 8 corners, indices out of range,
//!   zero, negative or huge, NaN and infinite coordinates, `w` and colour columns, garbage;
//!   `vn` and `vt` that are NaN, infinite, zero or tiny, and faces that give them at every
//!   corner, some or none, with their indices out of range, zero or negative; `map_Kd` and
//!   `map_Ka` naming good, truncated, huge-headed, empty, missing and device textures; the
//!   `[[mesh]]` keys `normals` and `crease_angle` with hostile values), loaded both as a
//!   `[[mesh]]` of a scene and as a bare `.obj`;
//! - texture files: PNG, JPEG, TGA and DDS bytes mutated (bytes flipped, cut short, header sizes
//!   patched), decoded against a small memory budget;
//! - command lines of the real `raytree` binary (a bounded number of processes).
//!
//! The property: nothing panics (a panic caught inside the loader counts as a failure too);
//! every error is one line that names the file, with `LINE:COLUMN` for TOML and the line for
//! OBJ where there is one; every scene that loads keeps the invariants of `Scene` and renders.
//!
//! Short run (part of `cargo test --release`, a few seconds):
//! `cargo test --release --test fuzz`
//! Long run (cases per target; the CLI target runs a hundredth as many processes):
//! `RAYTREE_FUZZ_CASES=200000 cargo test --release --test fuzz -- --nocapture`
//! Another seed: `RAYTREE_FUZZ_SEED=7`. A failure prints the shrunk input; add it to
//! `tests/fixtures/hostile/` (every input that ever crashed is a fixture there).

mod common;
mod hostile_support;
mod obj_compare;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use hostile_support::{check_invariants, is_one_line, render_tiny};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use raytree::scene::budget::MemoryLimit;
use raytree::scene::builtin::{NAMES, scene_text};
use raytree::scene::texture::decode_texture;
use raytree::scene::toml::keys::{SECTIONS, SectionKeys};
use raytree::scene::{load_scene_file, load_scene_str_with, load_scene_str_with_files};

/// Cases per target in the short run.
const SHORT_TOML_CASES: u32 = 20000;
const SHORT_OBJ_CASES: u32 = 20000;
const SHORT_CLI_CASES: u32 = 200;
const SHORT_TEXTURE_CASES: u32 = 3000;

fn cases(short: u32, scale: u32) -> u32 {
    std::env::var("RAYTREE_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
        .map_or(short, |n| (n / scale).max(1))
}

/// A deterministic runner: the same seed gives the same cases on every machine.
fn runner(cases: u32, salt: u8) -> TestRunner {
    let seed: u64 = std::env::var("RAYTREE_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(6);
    let mut bytes = [salt; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 4096,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &bytes))
}

fn run<S: Strategy>(name: &str, cases: u32, salt: u8, strategy: S, test: impl Fn(S::Value))
where
    S::Value: std::fmt::Debug,
{
    let start = Instant::now();
    let mut runner = runner(cases, salt);
    let result = runner.run(&strategy, |value| {
        test(value);
        Ok(())
    });
    eprintln!(
        "fuzz {name}: {cases} cases in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    if let Err(e) = result {
        panic!("fuzz {name} failed: {e}");
    }
}

// ---------------------------------------------------------------------------------------------
// What errors look like.

/// `PREFIX` followed by `LINE:COLUMN: ` (or just `LINE: ` when `column` is false).
fn strip_place<'m>(message: &'m str, prefix: &str, column: bool) -> Option<&'m str> {
    let rest = message.strip_prefix(prefix)?;
    let digits = |s: &'m str| {
        let n = s.bytes().take_while(u8::is_ascii_digit).count();
        (n > 0).then(|| &s[n..])
    };
    let rest = digits(rest)?;
    let rest = if column {
        digits(rest.strip_prefix(':')?)?
    } else {
        rest
    };
    rest.strip_prefix(": ")
}

/// One line, a full stop, no panic caught on the way, and `FILE:LINE:COLUMN: ` in front.
fn check_toml_error(message: &str, file: &str) {
    assert!(is_one_line(message), "not one line: {message:?}");
    assert!(message.ends_with('.'), "not a sentence: {message}");
    assert!(
        !message.contains("reader failed"),
        "a panic was caught in the loader: {message}"
    );
    assert!(
        strip_place(message, &format!("{file}:"), true).is_some(),
        "no FILE:LINE:COLUMN: {message}"
    );
}

// ---------------------------------------------------------------------------------------------
// Scene TOML.

const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "0.5",
    "2",
    "1e39",
    "-1e39",
    "3.4e38",
    "-3.4e38",
    "1e-45",
    "nan",
    "-nan",
    "+nan",
    "inf",
    "-inf",
    "+inf",
    "180",
    "179.9999",
    "1e-30",
    "64",
    "65",
    "65536",
    "65537",
    "16384",
    "16385",
    "100000",
    "4294967296",
    "9223372036854775807",
    "-9223372036854775808",
    "99999999999999999999",
    "0x10",
    "0o7",
    "0b1",
    "1_000",
    "1e",
    ".",
    "--1",
];

const VALUES: &[&str] = &[
    "[0, 0, 0]",
    "[0, 1, 0]",
    "[nan, 0, 0]",
    "[inf, -inf, 0]",
    "[1e39, 0, 0]",
    "[3e38, 3e38, 3e38]",
    "[-3e38, 1, 3e38]",
    "[0, 0]",
    "[1, 2, 3, 4]",
    "[]",
    "[\"a\", 1, 2]",
    "[[0, 0, 0], [0, 0, 0], [0, 0, 0]]",
    "[[-1, -1, -1], [1, -1, -1], [0, 1, -1]]",
    "[[0, 0, 0], [3e38, 0, 0], [0, 3e38, 0]]",
    "[[nan, 0, 0], [1, 0, 0], [0, 1, 0]]",
    "\"glass\"",
    "\"default\"",
    "\"\"",
    "\" \"",
    "\"phong\"",
    "\"smooth\"",
    "\"flat\"",
    "\"file\"",
    "\"bogus\"",
    "\"blinn-phong\"",
    "\"m.obj\"",
    "\"M.OBJ\"",
    "\"m.toml\"",
    "\"/dev/zero\"",
    "\"../../../../m.obj\"",
    "\"/m.obj\"",
    "\"missing.obj\"",
    "true",
    "{}",
    "{ x = 1 }",
    "1979-05-27",
    "'''x'''",
];

/// Every key a scene file takes (the loader's own list, each key once), and some it does not.
fn keys() -> Vec<&'static str> {
    let mut keys: Vec<&'static str> = Vec::new();
    for key in SECTIONS.iter().flat_map(|s| s.keys.iter().copied()) {
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    keys.extend(["radus", "colour", "x", "\"quoted key\"", "a.b"]);
    keys
}

/// Every section header (the loader's own list), and some that are wrong.
fn headers() -> Vec<String> {
    let mut headers: Vec<String> = SECTIONS.iter().map(SectionKeys::header).collect();
    headers.extend(["[[render]]", "[sphere]", "[lights]", "[", "[[]]"].map(String::from));
    headers
}

#[derive(Clone, Debug)]
enum Edit {
    FlipByte(usize, u8),
    Truncate(usize),
    ReplaceNumber(usize, String),
    SwapValues(usize, usize),
    InsertLine(usize, String),
    DeleteLine(usize),
    DuplicateLine(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    let any_value = prop_oneof![
        proptest::sample::select(NUMBERS).prop_map(str::to_string),
        proptest::sample::select(VALUES).prop_map(str::to_string),
        any::<f32>().prop_map(|f| format!("{f:?}")),
        any::<i64>().prop_map(|i| i.to_string()),
    ];
    let line = prop_oneof![
        4 => (proptest::sample::select(keys()), any_value).prop_map(|(k, v)| format!("{k} = {v}")),
        1 => proptest::sample::select(headers()),
        1 => "[ -~]{0,20}",
    ];
    prop_oneof![
        2 => (any::<usize>(), any::<u8>()).prop_map(|(a, b)| Edit::FlipByte(a, b)),
        1 => any::<usize>().prop_map(Edit::Truncate),
        4 => (any::<usize>(), proptest::sample::select(NUMBERS))
            .prop_map(|(a, b)| Edit::ReplaceNumber(a, b.to_string())),
        3 => (any::<usize>(), any::<f32>())
            .prop_map(|(a, f)| Edit::ReplaceNumber(a, format!("{f:?}"))),
        2 => (any::<usize>(), -3i64..70)
            .prop_map(|(a, i)| Edit::ReplaceNumber(a, i.to_string())),
        2 => (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::SwapValues(a, b)),
        3 => (any::<usize>(), line).prop_map(|(a, l)| Edit::InsertLine(a, l)),
        1 => any::<usize>().prop_map(Edit::DeleteLine),
        1 => any::<usize>().prop_map(Edit::DuplicateLine),
    ]
}

/// Byte ranges of the number literals of `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit()
            || (matches!(b[i], b'-' | b'+') && b.get(i + 1).is_some_and(u8::is_ascii_digit));
        let fresh = i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if starts && fresh {
            let start = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || matches!(b[i], b'.' | b'_')) {
                i += 1;
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for e in edits {
        let s = String::from_utf8_lossy(&bytes).into_owned();
        let mut lines: Vec<String> = s.lines().map(str::to_string).collect();
        let relined = |lines: Vec<String>| (lines.join("\n") + "\n").into_bytes();
        match e {
            Edit::FlipByte(at, byte) if !bytes.is_empty() => {
                let at = at % bytes.len();
                bytes[at] = *byte;
            }
            Edit::Truncate(at) => bytes.truncate(at % (bytes.len() + 1)),
            Edit::ReplaceNumber(nth, with) => {
                let found = numbers(&s);
                if !found.is_empty() {
                    let (a, b) = found[nth % found.len()];
                    bytes = format!("{}{with}{}", &s[..a], &s[b..]).into_bytes();
                }
            }
            Edit::SwapValues(a, b) => {
                let with_value: Vec<usize> = (0..lines.len())
                    .filter(|&i| lines[i].contains('='))
                    .collect();
                if with_value.len() >= 2 {
                    let (i, j) = (
                        with_value[a % with_value.len()],
                        with_value[b % with_value.len()],
                    );
                    let split = |l: &str| {
                        let k = l.find('=').unwrap_or(0);
                        (l[..k].to_string(), l[k..].to_string())
                    };
                    let (ki, vi) = split(&lines[i]);
                    let (kj, vj) = split(&lines[j]);
                    lines[i] = format!("{ki}{vj}");
                    lines[j] = format!("{kj}{vi}");
                    bytes = relined(lines);
                }
            }
            Edit::InsertLine(at, line) => {
                let at = at % (lines.len() + 1);
                lines.insert(at, line.clone());
                bytes = relined(lines);
            }
            Edit::DeleteLine(at) if !lines.is_empty() => {
                let at = at % lines.len();
                lines.remove(at);
                bytes = relined(lines);
            }
            Edit::DuplicateLine(at) if !lines.is_empty() => {
                let at = at % lines.len();
                let copy = lines[at].clone();
                lines.insert(at, copy);
                bytes = relined(lines);
            }
            _ => {}
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

/// The seeds: every built-in scene and every TOML fixture.
fn toml_seeds() -> Vec<String> {
    let mut seeds: Vec<String> = NAMES
        .iter()
        .map(|n| scene_text(n).expect("built-in").to_string())
        .collect();
    for dir in ["tests/fixtures/bad", "tests/fixtures/hostile"] {
        let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
            .expect("fixtures")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        paths.sort();
        for p in paths {
            let bytes = std::fs::read(&p).expect("fixture");
            // Keep the seeds small: the deep-nesting fixtures are their own test.
            if bytes.len() < 16 << 10 {
                seeds.push(String::from_utf8_lossy(&bytes).into_owned());
            }
        }
    }
    seeds
}

/// The models the scenes name, by the path they name them with, plus `m.obj`/`m.mtl`.
fn model_files() -> HashMap<String, String> {
    let mut files = HashMap::new();
    for entry in std::fs::read_dir("assets/models").expect("models") {
        let path = entry.expect("entry").path();
        let name = path
            .file_name()
            .expect("name")
            .to_string_lossy()
            .to_string();
        // Textures (binary) are not text models.
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        files.insert(format!("../models/{name}"), text.clone());
        files.insert(name, text);
    }
    files.insert(
        "m.obj".into(),
        "mtllib m.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".into(),
    );
    files.insert("m.mtl".into(), "newmtl red\nKd 1 0 0\n".into());
    files
}

#[test]
fn fuzz_scene_toml() {
    let seeds = toml_seeds();
    let files = model_files();
    let resolve = |path: &str| {
        files
            .get(path)
            .cloned()
            .ok_or_else(|| format!("{path}: no such file"))
    };
    let strategy = (0..seeds.len(), proptest::collection::vec(edit(), 1..4));
    let loaded = AtomicU32::new(0);
    run(
        "scene TOML",
        cases(SHORT_TOML_CASES, 1),
        1,
        strategy,
        |(seed, edits)| {
            let text = apply(&seeds[seed], &edits);
            match load_scene_str_with(&text, "fuzz.toml", &resolve) {
                Err(e) => check_toml_error(&e.to_string(), "fuzz.toml"),
                Ok(scene) => {
                    if let Err(rule) = check_invariants(&scene) {
                        panic!("loaded, but breaks the rule: {rule}\n{text}");
                    }
                    render_tiny(&scene);
                    loaded.fetch_add(1, Ordering::Relaxed);
                }
            }
        },
    );
    eprintln!("  {} of the mutated scenes loaded", loaded.into_inner());
}

// ---------------------------------------------------------------------------------------------
// OBJ and MTL.

fn coordinate() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-8i32..8).prop_map(|i| i.to_string()),
        3 => any::<f32>().prop_map(|f| f.to_string()),
        2 => (-1.0f32..1.0).prop_map(|f| f.to_string()),
        2 => proptest::sample::select(&[
            "nan", "NaN", "inf", "-inf", "1e39", "3e38", "-3e38", "1e-45", "-0", "x", "", "1e",
        ][..])
        .prop_map(str::to_string),
    ]
}

fn corner() -> impl Strategy<Value = String> {
    let index = prop_oneof![
        6 => (-6i64..10).prop_map(|i| i.to_string()),
        1 => any::<i64>().prop_map(|i| i.to_string()),
        1 => proptest::sample::select(&[
            "99999999999999999999", "-9223372036854775808", "0", "-0", "", "a", "1.5",
        ][..])
        .prop_map(str::to_string),
    ];
    (index.clone(), index.clone(), index, 0..5u8).prop_map(|(v, t, n, form)| match form {
        0 | 1 => v,
        2 => format!("{v}/{t}"),
        3 => format!("{v}//{n}"),
        _ => format!("{v}/{t}/{n}"),
    })
}

fn obj_line() -> impl Strategy<Value = String> {
    let c = coordinate;
    prop_oneof![
        6 => (c(), c(), c()).prop_map(|(x, y, z)| format!("v {x} {y} {z}")),
        1 => (c(), c(), c(), c()).prop_map(|(x, y, z, w)| format!("v {x} {y} {z} {w}")),
        1 => (c(), c(), c(), c(), c(), c())
            .prop_map(|(x, y, z, r, g, b)| format!("v {x} {y} {z} {r} {g} {b}")),
        1 => (c(), c()).prop_map(|(u, v)| format!("vt {u} {v}")),
        1 => (c(), c(), c()).prop_map(|(x, y, z)| format!("vn {x} {y} {z}")),
        6 => proptest::collection::vec(corner(), 0..9).prop_map(|c| format!("f {}", c.join(" "))),
        1 => proptest::collection::vec(corner(), 0..4).prop_map(|c| format!("l {}", c.join(" "))),
        2 => proptest::sample::select(&[
            "o part", "g", "g group", "o", "s off", "s 1", "# comment", "", "usemtl red",
            "usemtl glass", "usemtl", "usemtl nowhere", "mtllib m.mtl", "mtllib missing.mtl",
            "mtllib m.obj", "mtllib", "mtllib /dev/zero", "p 1", "curv 0 1",
        ][..])
        .prop_map(str::to_string),
        1 => proptest::collection::vec(any::<u8>(), 0..24)
            .prop_map(|b| String::from_utf8_lossy(&b).replace(['\n', '\r'], " ")),
    ]
}

fn mtl_line() -> impl Strategy<Value = String> {
    let c = coordinate;
    let colour_key = proptest::sample::select(&["Ka", "Kd", "Ks", "Ke", "Tf"][..]);
    let scalar_key = proptest::sample::select(&["Ns", "Ni", "d", "Tr", "illum", "Ns"][..]);
    prop_oneof![
        2 => proptest::sample::select(&["newmtl red", "newmtl glass", "newmtl", "newmtl  "][..])
            .prop_map(str::to_string),
        5 => (colour_key, proptest::collection::vec(c(), 0..5))
            .prop_map(|(k, v)| format!("{k} {}", v.join(" "))),
        3 => (scalar_key, c()).prop_map(|(k, v)| format!("{k} {v}")),
        1 => (0..12i32).prop_map(|i| format!("illum {i}")),
        2 => (proptest::sample::select(&["map_Kd", "map_Ka"][..]), proptest::sample::select(TEXTURE_NAMES))
            .prop_map(|(k, t)| format!("{k} {t}")),
        1 => proptest::sample::select(&["map_Kd", "map_Kd -s 1 1 1 good.png", "bump", "# c", ""][..])
            .prop_map(str::to_string),
        1 => proptest::collection::vec(any::<u8>(), 0..24)
            .prop_map(|b| String::from_utf8_lossy(&b).replace(['\n', '\r'], " ")),
    ]
}

/// The textures an MTL of the OBJ target may name (files of the hostile corpus, written next
/// to the OBJ), and names that are missing, a folder or a device.
const TEXTURE_NAMES: &[&str] = &[
    "good.png",
    "good.png",
    "truncated.png",
    "truncated.jpg",
    "huge_header.png",
    "huge_header.jpg",
    "zero_size.png",
    "empty.png",
    "not_an_image.png",
    "missing.png",
    "folder.png",
    "/dev/zero",
    "m.obj",
];

/// The texture files of the hostile corpus, by the names of [`TEXTURE_NAMES`].
fn texture_files() -> HashMap<String, Vec<u8>> {
    let corpus = Path::new("tests/fixtures/hostile/textures");
    TEXTURE_NAMES
        .iter()
        .filter_map(|name| {
            // Only the corpus's regular files: a device (`/dev/zero`, or a link to it) is named in
            // the MTLs, never read here (reading `/dev/zero` would fill the memory).
            let path = corpus.join(name);
            if Path::new(name).is_absolute() || !std::fs::metadata(&path).ok()?.is_file() {
                return None;
            }
            let bytes = std::fs::read(path).ok()?;
            Some((name.to_string(), bytes))
        })
        .collect()
}

#[derive(Clone, Debug)]
struct MeshCase {
    obj: String,
    mtl: String,
    /// `scale`, `rotate` and `material` lines for the `[[mesh]]`.
    placement: String,
}

/// A mostly well-formed mesh (vertices, then faces whose indices are mostly in range, colours
/// of three numbers) with a few hostile lines mixed in, so that cases get past the parser to
/// the checks behind it; `hostile` lines alone rarely would.
fn mesh_case() -> impl Strategy<Value = MeshCase> {
    let placement = proptest::sample::select(
        &[
            "",
            "",
            "scale = -1\n",
            "scale = [1, -2, 3]\n",
            "rotate = [90, 45, 1e30]\n",
            "scale = 3e38\n",
            "translate = [3e38, 0, 0]\n",
            "material = \"default\"\n",
            "normals = \"smooth\"\n",
            "normals = \"smooth\"\ncrease_angle = 0\n",
            "normals = \"smooth\"\ncrease_angle = 180\n",
            "normals = \"flat\"\n",
            "normals = \"file\"\nscale = [1, -1, 1e-20]\n",
            "normals = \"bogus\"\n",
            "crease_angle = nan\n",
            "crease_angle = -1\n",
            "normals = \"smooth\"\ncrease_angle = 1e39\n",
        ][..],
    );
    let mostly_numbers = || {
        prop_oneof![
            12 => (-4i32..5).prop_map(|i| i.to_string()),
            6 => (-2.0f32..2.0).prop_map(|f| f.to_string()),
            1 => coordinate(),
        ]
    };
    let vertex = (mostly_numbers(), mostly_numbers(), mostly_numbers())
        .prop_map(|(x, y, z)| format!("v {x} {y} {z}"));
    // Normals and texture coordinates: mostly usable, some NaN, infinite, zero or tiny.
    let hostile_number = || {
        prop_oneof![
            8 => mostly_numbers(),
            1 => proptest::sample::select(&["nan", "inf", "-inf", "0", "1e-45", "3e38"][..])
                .prop_map(str::to_string),
        ]
    };
    let normal = (hostile_number(), hostile_number(), hostile_number())
        .prop_map(|(x, y, z)| format!("vn {x} {y} {z}"));
    let uv = (hostile_number(), hostile_number()).prop_map(|(u, v)| format!("vt {u} {v}"));
    // Faces index the vertices, normals and texture coordinates there are, mostly (the counts
    // are known when the faces are drawn); a corner names a `vt`, a `vn`, both or neither.
    let faces = |n: i64, normals: i64, uvs: i64| {
        let index = |n: i64| {
            // Rarely out of range: one such index refuses the whole file, and most files
            // should get past the reader to the checks behind it.
            prop_oneof![
                150 => (1..=n.max(1)).prop_map(|i| i.to_string()),
                25 => (-n.max(1)..0).prop_map(|i| i.to_string()),
                1 => proptest::sample::select(&["0", "-99", "99"][..]).prop_map(str::to_string),
                1 => corner(),
            ]
        };
        let form = |(v, t, m): (String, String, String), form: u8| match form {
            0 | 1 => v,
            2 => format!("{v}/{t}"),
            3 => format!("{v}//{m}"),
            _ => format!("{v}/{t}/{m}"),
        };
        // Most faces use one form at every corner; some mix them.
        let face = (
            proptest::collection::vec((index(n), index(uvs), index(normals), 0..6u8), 1..8),
            0..6u8,
            proptest::bool::weighted(0.2),
        )
            .prop_map(move |(corners, face_form, mixed)| {
                let corners: Vec<String> = corners
                    .into_iter()
                    .map(|(v, t, m, f)| form((v, t, m), if mixed { f } else { face_form }))
                    .collect();
                format!("f {}", corners.join(" "))
            });
        proptest::collection::vec(face, 0..16)
    };
    let colour = (
        proptest::sample::select(&["Ka", "Kd", "Ks"][..]),
        mostly_numbers(),
        mostly_numbers(),
        mostly_numbers(),
    )
        .prop_map(|(k, r, g, b)| format!("{k} {r} {g} {b}"));
    let geometry = (1i64..12, 0i64..6, 0i64..6).prop_flat_map(move |(n, normals, uvs)| {
        (
            proptest::collection::vec(vertex.clone(), n as usize),
            proptest::collection::vec(normal.clone(), normals as usize),
            proptest::collection::vec(uv.clone(), uvs as usize),
            faces(n, normals, uvs),
        )
    });
    (
        geometry,
        proptest::collection::vec((any::<usize>(), obj_line()), 0..2),
        proptest::collection::vec(colour, 0..4),
        (
            proptest::collection::vec(mtl_line(), 0..3),
            proptest::option::of(proptest::sample::select(TEXTURE_NAMES)),
        ),
        any::<bool>(),
        placement,
    )
        .prop_map(
            |(
                (vertices, normals, uvs, faces),
                hostile,
                colours,
                (mtl_extra, texture),
                use_mtl,
                placement,
            )| {
                let mut obj = Vec::new();
                if use_mtl {
                    obj.push("mtllib m.mtl".to_string());
                    obj.push("usemtl red".to_string());
                }
                obj.extend(vertices);
                obj.extend(normals);
                obj.extend(uvs);
                obj.extend(faces);
                for (at, line) in hostile {
                    obj.insert(at % (obj.len() + 1), line);
                }
                let mut mtl = vec!["newmtl red".to_string()];
                mtl.extend(colours);
                mtl.extend(texture.map(|t| format!("map_Kd {t}")));
                mtl.extend(mtl_extra);
                MeshCase {
                    obj: obj.join("\n") + "\n",
                    mtl: mtl.join("\n") + "\n",
                    placement: placement.to_string(),
                }
            },
        )
}

#[test]
fn fuzz_obj_and_mtl() {
    // Two small files are written per case: in memory where the system offers it.
    let shm = Path::new("/dev/shm");
    let dir = if shm.is_dir() {
        tempfile::tempdir_in(shm)
    } else {
        tempfile::tempdir()
    }
    .expect("temp dir");
    let obj_path = dir.path().join("m.obj");
    let obj_file = obj_path.display().to_string();
    let textures = texture_files();
    assert!(
        textures.len() >= 8,
        "the corpus textures: {:?}",
        textures.keys()
    );
    for (name, bytes) in &textures {
        std::fs::write(dir.path().join(name), bytes).expect("write texture");
    }
    std::fs::create_dir(dir.path().join("folder.png")).expect("a folder named like a texture");
    let resolve_bytes = |path: &str| {
        textures
            .get(path)
            .cloned()
            .ok_or_else(|| format!("{path}: no such file"))
    };
    let (as_mesh, bare) = (AtomicU32::new(0), AtomicU32::new(0));
    // Loaded scenes that kept normals or texture coordinates, and that have a texture.
    let (with_attributes, textured) = (AtomicU32::new(0), AtomicU32::new(0));
    run(
        "OBJ and MTL",
        cases(SHORT_OBJ_CASES, 1),
        2,
        mesh_case(),
        |case| {
            // As a mesh of a scene, through the resolver.
            let resolve = |path: &str| match path {
                "m.obj" => Ok(case.obj.clone()),
                "m.mtl" => Ok(case.mtl.clone()),
                other => Err(format!("{other}: no such file")),
            };
            let toml = format!("[[mesh]]\nfile = \"m.obj\"\n{}", case.placement);
            match load_scene_str_with_files(&toml, "fuzz.toml", &resolve, &resolve_bytes) {
                Err(e) => {
                    let e = e.to_string();
                    check_toml_error(&e, "fuzz.toml");
                    let rest = e
                        .strip_prefix("fuzz.toml:2:8: mesh 1 field `file` cannot be loaded: m.obj");
                    // The placement and normals keys are on lines 3 and 4.
                    let placement = e.starts_with("fuzz.toml:3:") || e.starts_with("fuzz.toml:4:");
                    assert!(rest.is_some() || placement, "{e}");
                }
                Ok(scene) => {
                    if let Err(rule) = check_invariants(&scene) {
                        panic!("loaded, but breaks the rule: {rule}");
                    }
                    check_warnings(&scene.warnings);
                    render_tiny(&scene);
                    if !scene.attributes.is_empty() {
                        with_attributes.fetch_add(1, Ordering::Relaxed);
                    }
                    if !scene.textures.is_empty() {
                        textured.fetch_add(1, Ordering::Relaxed);
                    }
                    if !scene.triangles.is_empty() {
                        as_mesh.fetch_add(1, Ordering::Relaxed);
                    }
                }
            }
            // As a bare OBJ from disk: the camera is framed on it.
            std::fs::write(&obj_path, &case.obj).expect("write obj");
            std::fs::write(dir.path().join("m.mtl"), &case.mtl).expect("write mtl");
            match load_scene_file(&obj_path) {
                Err(e) => {
                    let e = e.to_string();
                    assert!(is_one_line(&e) && e.ends_with('.'), "{e:?}");
                    assert!(!e.contains("reader failed"), "a caught panic: {e}");
                    let placed = strip_place(&e, &format!("{obj_file}:"), false).is_some();
                    assert!(placed || e.starts_with(&format!("{obj_file}: ")), "{e}");
                }
                Ok(scene) => {
                    if let Err(rule) = check_invariants(&scene) {
                        panic!("loaded, but breaks the rule: {rule}");
                    }
                    check_warnings(&scene.warnings);
                    render_tiny(&scene);
                    bare.fetch_add(1, Ordering::Relaxed);
                }
            }
        },
    );
    eprintln!(
        "  {} loaded with triangles as a mesh ({} with normals or texture coordinates, {} \
         textured), {} as a bare OBJ",
        as_mesh.load(Ordering::Relaxed),
        with_attributes.load(Ordering::Relaxed),
        textured.load(Ordering::Relaxed),
        bare.into_inner()
    );
    // The cases reach the normals and textures, not only the reader's refusals.
    let n = cases(SHORT_OBJ_CASES, 1);
    assert!(
        with_attributes.into_inner() > n / 50 && textured.into_inner() > n / 400,
        "too few cases reach normals and textures"
    );
}

/// Warnings are sentences, and none says a panic was caught in a reader or decoder.
fn check_warnings(warnings: &[String]) {
    for w in warnings {
        assert!(is_one_line(w) && w.ends_with('.'), "{w:?}");
        assert!(!w.contains("reader failed"), "a caught panic: {w}");
    }
}

/// raytree's parallel OBJ reader against tobj on the same random OBJs (well-formed meshes with
/// hostile lines mixed in, and hostile lines alone): where it reads a file, tobj reads the same
/// models bit for bit; where tobj fails, it leaves the file to tobj. (Through the loader, the
/// target above runs it too.)
#[test]
fn fuzz_fast_obj_reader_equals_tobj() {
    let taken = AtomicU32::new(0);
    // Well-formed files of every kind of corner, group and material change.
    let clean_line = |n: u32| {
        let i = move || (1..=n).prop_map(|i| i.to_string());
        let corner = (i(), i(), i(), 0..4u8).prop_map(|(v, t, m, form)| match form {
            0 => v,
            1 => format!("{v}/{t}"),
            2 => format!("{v}//{m}"),
            _ => format!("{v}/{t}/{m}"),
        });
        prop_oneof![
            4 => proptest::collection::vec(corner, 1..7).prop_map(|c| format!("f {}", c.join(" "))),
            1 => proptest::sample::select(&[
                "o a", "g b", "g", "usemtl red", "usemtl none", "s 1", "# c", "", "mtllib m.mtl",
            ][..]).prop_map(str::to_string),
        ]
    };
    let clean = (1u32..8).prop_flat_map(move |n| {
        let numbers = |k: usize| {
            proptest::collection::vec(-3.0f32..3.0, k)
                .prop_map(|v| v.iter().map(f32::to_string).collect::<Vec<_>>().join(" "))
        };
        (
            proptest::collection::vec(numbers(3).prop_map(|v| format!("v {v}")), n as usize),
            proptest::collection::vec(numbers(2).prop_map(|v| format!("vt {v}")), n as usize),
            proptest::collection::vec(numbers(3).prop_map(|v| format!("vn {v}")), n as usize),
            proptest::collection::vec(clean_line(n), 0..20),
            any::<bool>(),
        )
            .prop_map(|(v, t, m, faces, crlf)| {
                let text = [v, t, m, faces].concat().join("\n") + "\n";
                if crlf {
                    text.replace('\n', "\r\n")
                } else {
                    text
                }
            })
    });
    let case = prop_oneof![
        2 => clean,
        2 => mesh_case().prop_map(|c| c.obj),
        1 => proptest::collection::vec(obj_line(), 0..24).prop_map(|l| l.join("\n")),
    ];
    run(
        "fast OBJ reader",
        cases(SHORT_OBJ_CASES / 2, 1),
        4,
        case,
        |obj| {
            let load_mtl = |p: &Path| -> tobj::MTLLoadResult {
                if p == Path::new("m.mtl") {
                    tobj::load_mtl_buf(&mut "newmtl red\nKd 1 0 0\n".as_bytes())
                } else {
                    Err(tobj::LoadError::OpenFileFailed)
                }
            };
            if obj_compare::check(&obj, &load_mtl) {
                taken.fetch_add(1, Ordering::Relaxed);
            }
        },
    );
    let taken = taken.into_inner();
    eprintln!("  {taken} read by the fast reader");
    assert!(
        taken > cases(SHORT_OBJ_CASES / 2, 1) / 4,
        "the fast path is exercised"
    );
}

// ---------------------------------------------------------------------------------------------
// Texture files.

#[derive(Clone, Debug)]
enum ByteEdit {
    Flip(usize, u8),
    Truncate(usize),
    /// A 32-bit big-endian number (PNG's width and height) written at a byte.
    Word(usize, u32),
    /// A 16-bit big-endian number (JPEG's sizes and segment lengths) written at a byte.
    Half(usize, u16),
    Insert(usize, Vec<u8>),
}

fn byte_edit() -> impl Strategy<Value = ByteEdit> {
    let near_the_start = 0..64usize;
    prop_oneof![
        4 => (any::<usize>(), any::<u8>()).prop_map(|(a, b)| ByteEdit::Flip(a, b)),
        2 => (near_the_start.clone(), any::<u8>()).prop_map(|(a, b)| ByteEdit::Flip(a, b)),
        2 => any::<usize>().prop_map(ByteEdit::Truncate),
        2 => (
            near_the_start.clone(),
            prop_oneof![Just(0u32), Just(1), Just(65535), Just(100_000), Just(u32::MAX), any::<u32>()],
        )
            .prop_map(|(a, w)| ByteEdit::Word(a, w)),
        2 => (any::<usize>(), prop_oneof![Just(0u16), Just(1), Just(65535), any::<u16>()])
            .prop_map(|(a, h)| ByteEdit::Half(a, h)),
        1 => (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(a, b)| ByteEdit::Insert(a, b)),
    ]
}

fn edit_bytes(mut bytes: Vec<u8>, edits: &[ByteEdit]) -> Vec<u8> {
    for e in edits {
        let n = bytes.len();
        match e {
            ByteEdit::Flip(at, b) if n > 0 => bytes[at % n] = *b,
            ByteEdit::Truncate(at) => bytes.truncate(at % (n + 1)),
            ByteEdit::Word(at, w) if n >= 4 => {
                let at = at % (n - 3);
                bytes[at..at + 4].copy_from_slice(&w.to_be_bytes());
            }
            ByteEdit::Half(at, h) if n >= 2 => {
                let at = at % (n - 1);
                bytes[at..at + 2].copy_from_slice(&h.to_be_bytes());
            }
            ByteEdit::Insert(at, b) => {
                let at = at % (n + 1);
                bytes.splice(at..at, b.iter().copied());
            }
            _ => {}
        }
    }
    bytes
}

/// PNG, JPEG, TGA and DDS files (the corpus's good, truncated and huge-headed ones, and larger
/// ones made here) with bytes flipped, cut, inserted and sizes patched, decoded against a 64 MiB budget:
/// never a panic; a texture has the texels its size says, all finite in [0, 1]; a refusal is
/// one phrase.
#[test]
fn fuzz_textures() {
    let corpus = Path::new("tests/fixtures/hostile/textures");
    let mut seeds: Vec<Vec<u8>> = [
        "good.png",
        "truncated.png",
        "truncated.jpg",
        "huge_header.png",
        "huge_header.jpg",
    ]
    .iter()
    .map(|n| std::fs::read(corpus.join(n)).expect("a corpus texture"))
    .collect();
    let gradient = image::RgbaImage::from_fn(24, 16, |x, y| {
        image::Rgba([x as u8 * 10, y as u8 * 15, 99, 200])
    });
    for format in [
        image::ImageFormat::Png,
        image::ImageFormat::Jpeg,
        image::ImageFormat::Tga,
    ] {
        let mut bytes = Vec::new();
        let img = image::DynamicImage::ImageRgba8(gradient.clone());
        let img = if format == image::ImageFormat::Jpeg {
            image::DynamicImage::ImageRgb8(img.to_rgb8())
        } else {
            img
        };
        img.write_to(&mut std::io::Cursor::new(&mut bytes), format)
            .expect("encodes");
        seeds.push(bytes);
    }
    // DDS: the gradient uncompressed, and BC1 blocks (colours and indices from the gradient).
    let rgba = gradient.as_raw().clone();
    let blocks: Vec<u8> = rgba
        .chunks(4)
        .take(6 * 4 * 8)
        .map(|p| p[0] ^ p[1])
        .collect();
    for (format, data) in [
        (image_dds::ddsfile::DxgiFormat::R8G8B8A8_UNorm, rgba),
        (image_dds::ddsfile::DxgiFormat::BC1_UNorm_sRGB, blocks),
    ] {
        seeds.push(common::dds(format, (24, 16), false, data));
    }
    let limit = MemoryLimit {
        bytes: 64 << 20,
        source: "the fuzz target".into(),
    };
    let decoded = AtomicU32::new(0);
    let strategy = (0..seeds.len(), proptest::collection::vec(byte_edit(), 0..4));
    run(
        "textures",
        cases(SHORT_TEXTURE_CASES, 10),
        5,
        strategy,
        |(seed, edits)| {
            let bytes = edit_bytes(seeds[seed].clone(), &edits);
            match decode_texture("t", &bytes, &limit) {
                Ok(t) => {
                    assert_eq!(
                        t.texels.len() as u64,
                        u64::from(t.width) * u64::from(t.height)
                    );
                    assert!(t.width > 0 && t.height > 0);
                    assert!(
                        t.texels
                            .iter()
                            .flatten()
                            .all(|c| c.is_finite() && (0.0..=1.0).contains(c))
                    );
                    decoded.fetch_add(1, Ordering::Relaxed);
                }
                Err(phrase) => assert!(is_one_line(&phrase), "{phrase:?}"),
            }
        },
    );
    let decoded = decoded.into_inner();
    eprintln!("  {decoded} of the mutated textures decoded");
    assert!(decoded > 0, "some mutated textures still decode");
}

// ---------------------------------------------------------------------------------------------
// Command lines.

fn pick(options: &'static [&'static str]) -> BoxedStrategy<String> {
    proptest::sample::select(options)
        .prop_map(str::to_string)
        .boxed()
}

/// A flag and its value (or none): mostly valid values, small enough that renders stay cheap,
/// and now and then an invalid one.
fn flag() -> impl Strategy<Value = Vec<String>> {
    let with =
        |name: &'static str, valid: &'static [&'static str], invalid: &'static [&'static str]| {
            prop_oneof![4 => pick(valid), 1 => pick(invalid)]
                .prop_map(move |v| vec![name.to_string(), v])
        };
    let bad_size = &["0", "16385", "-1", "abc", "", "1e3", "4294967296", " 8"][..];
    prop_oneof![
        with("--width", &["1", "3", "8", "17"], bad_size),
        with("--height", &["1", "2", "8", "13"], bad_size),
        with("--samples", &["1", "2", "3"], &["0", "65537", "x", "-3"]),
        with("--max-depth", &["0", "5", "64"], &["65", "-1", "x"]),
        with(
            "--threads",
            &["0", "1", "2"],
            &["1025", "-1", "x", "99999999999999999999"]
        ),
        with(
            "--cutoff",
            &["0", "0.5", "0.01"],
            &["1", "-1", "nan", "inf", "x"]
        ),
        with("--accel", &["auto", "none", "grid", "bvh"], &["octree", ""]),
        with("--sphere", &["lecture", "robust"], &["x"]),
        with(
            "--triangle",
            &["watertight", "moller-trumbore", "plane"],
            &["x"]
        ),
        with("--offset", &["fixed", "normal", "error-bound"], &["x"]),
        with("--shading", &["phong", "blinn-phong"], &["gouraud"]),
        with("--stats-json", &["OUT/s.json"], &["OUT/no/s.json", "OUT"]),
        with("--frames", &["1", "2"], &["0", "1001", "x"]),
        with(
            "--region",
            &["0,0,1,1", "0,1,2,2"],
            &["0,0,0,1", "99999,0,1,1", "1,2,3"]
        ),
        with("--tile", &["0/1", "0/2", "1/2"], &["2/2", "0/0", "x", "1"]),
        with("--turntable", &["1", "3"], &["0", "x"]),
        with("--frame", &["0", "1"], &["-1", "x"]),
        with("--frame-range", &["0..1", "1..3"], &["1..1", "2..1", "x"]),
        pick(&["--bogus", "-", "--", "-x", "--help"]).prop_map(|f| vec![f]),
    ]
}

/// Scenes that load fast at their own size, scenes that fail, and things that are no scene.
const CLI_SCENES: &[&str] = &[
    "quiz",
    "quiz",
    "tests/fixtures/hostile/empty.toml",
    "tests/fixtures/hostile/one_and_two_vertex_faces.obj",
    "tests/fixtures/hostile/mtl_nan.obj",
    "tests/fixtures/hostile/found_bvh_far_scale.toml",
    "tests/fixtures/hostile/nan_center.toml",
    "tests/fixtures/hostile/binary_garbage.obj",
    "tests/fixtures/hostile/zero_device.obj",
    "tests/fixtures/bad/broken_mesh.toml",
    "nope",
    "",
    "-",
    ".",
    "/dev/zero",
];

fn command_line() -> impl Strategy<Value = Vec<String>> {
    let flags = |n: usize| proptest::collection::vec(flag(), 0..n);
    let render = (
        pick(CLI_SCENES),
        prop_oneof![
            6 => pick(&["OUT/a.png", "OUT/a.exr", "OUT/a.PNG"]),
            1 => pick(&["OUT/a.jpg", "OUT/", "OUT/no/a.png", "", "/dev/full"]),
        ],
        any::<bool>(),
        flags(4),
    )
        .prop_map(|(scene, out, quiet, flags)| {
            let mut args = vec!["render".to_string(), scene, "-o".into(), out];
            if quiet {
                args.push("-q".into());
            }
            args.extend(flags.into_iter().flatten());
            args
        });
    let tree = (
        pick(CLI_SCENES),
        prop_oneof![
            4 => pick(&["0,0", "3,3", "100,100", "200,200"]),
            1 => pick(&["5000,1", "1;2", "-1,0", "", "1,", ",1", "x,y", "4294967296,0"]),
        ],
        any::<bool>(),
        flags(3),
    )
        .prop_map(|(scene, pixel, json, flags)| {
            let mut args = vec!["tree".to_string(), scene, "--pixel".into(), pixel];
            if json {
                args.push("--json".into());
            }
            args.extend(flags.into_iter().flatten());
            args
        });
    // Anything in any order. Never a command that opens the viewer on a loadable scene (no
    // window in a test): a first word that is no subcommand is taken as a scene name, and
    // these fail to load.
    let noise = (
        pick(&["render", "tree", "scenes", "rendr", "help", "RENDER"]),
        pick(CLI_SCENES),
        flags(6),
        any::<bool>(),
    )
        .prop_map(|(sub, scene, flags, scene_last)| {
            let mut args = vec![sub];
            if !scene_last {
                args.push(scene.clone());
            }
            args.extend(flags.into_iter().flatten());
            if scene_last {
                args.push(scene);
            }
            args
        });
    prop_oneof![4 => render, 2 => tree, 2 => noise]
}

#[test]
fn fuzz_command_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().display().to_string();
    let codes = [(); 3].map(|()| AtomicU32::new(0));
    run(
        "command line",
        cases(SHORT_CLI_CASES, 100),
        3,
        command_line(),
        |args| {
            let args: Vec<String> = args.iter().map(|a| a.replace("OUT", &out)).collect();
            // A subcommand other than render/tree/scenes is taken as a scene for the viewer;
            // only names that fail to load are generated, and no display is offered anyway.
            let output = assert_cmd::Command::new(env!("CARGO_BIN_EXE_raytree"))
                .args(&args)
                .current_dir(env!("CARGO_MANIFEST_DIR"))
                .env_remove("DISPLAY")
                .env_remove("WAYLAND_DISPLAY")
                .env("RAYTREE_MEMORY_LIMIT", "2048")
                .timeout(Duration::from_secs(60))
                .output()
                .expect("runs");
            let stderr = String::from_utf8_lossy(&output.stderr);
            let lines: Vec<&str> = stderr.lines().collect();
            let code = output.status.code();
            if let Some(c @ 0..=2) = code {
                codes[c as usize].fetch_add(1, Ordering::Relaxed);
            }
            assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
            match code {
                Some(0) => assert!(
                    lines.iter().all(|l| l.starts_with("warning: ")),
                    "{args:?}: {stderr}"
                ),
                Some(1 | 2) => {
                    let (last, before) = lines.split_last().expect("an error line");
                    assert!(last.starts_with("error: "), "{args:?}: {stderr}");
                    assert!(is_one_line(last), "{args:?}: {stderr}");
                    assert!(
                        before.iter().all(|l| l.starts_with("warning: ")),
                        "{args:?}: {stderr}"
                    );
                }
                other => panic!("{args:?}: exit {other:?} (killed or timed out?): {stderr}"),
            }
            // Nothing half-written: no temporary files, ever.
            for entry in std::fs::read_dir(Path::new(&out)).expect("list") {
                let name = entry.expect("entry").file_name();
                assert!(
                    !name.to_string_lossy().starts_with(".raytree-"),
                    "{args:?} left {name:?}"
                );
            }
        },
    );
    let [ok, failed, usage] = codes.map(AtomicU32::into_inner);
    eprintln!("  exit codes: {ok} succeeded, {failed} refused, {usage} usage errors");
}
