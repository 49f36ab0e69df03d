//! The architecture, checked: the crate's modules form layers (src/lib.rs), and a module
//! imports only from the layers below it or from its own layer without a circle; within a
//! folder, no two files import each other, directly or round a longer circle.
//!
//! This reads the sources as text: a `crate::name` path anywhere outside a comment or a test
//! module is a dependency on top-level module `name`, and `super::name` naming a sibling file
//! is a dependency on that file. Cargo features keep egui and wgpu out of the core; this keeps
//! the rest of the order.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Bottom to top. A module may use those on lower rows, and those on its own row when that
/// makes no circle.
const LAYERS: &[&[&str]] = &[
    &["choice", "rng", "sync", "plural", "geometry"],
    &["scene"],
    &["accel"],
    &["shade", "trace", "ray_tree"],
    &["render", "export", "scene_view", "diagram", "lessons"],
    &["experiments", "app"],
    // The `raytree` binary's subcommands (src/main.rs and src/cli/ are the binary crate; they
    // use the library as `raytree::`).
    &["cli"],
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|row| row.contains(&module))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src is readable") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a file without comments, string contents and its test module (which clippy
/// keeps last), so that only real paths count.
fn code(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod tests") {
        Some(i) => &text[..i],
        None => text,
    };
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The identifiers that follow each `prefix::` in `code`, also inside `prefix::{a, b::c}`.
fn paths_after(code: &str, prefix: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let pattern = format!("{prefix}::");
    let mut rest = code;
    while let Some(i) = rest.find(&pattern) {
        let before = rest[..i].chars().last();
        rest = &rest[i + pattern.len()..];
        // `self::super::x` or `foo_crate::x` are not the paths we are after.
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        if let Some(group) = rest.strip_prefix('{') {
            let end = matching_brace(group);
            for item in split_top_level(&group[..end]) {
                let name: String = item
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    out.insert(name);
                }
            }
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                out.insert(name);
            }
        }
    }
    out
}

fn matching_brace(s: &str) -> usize {
    let mut depth = 0;
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => return i,
            '}' => depth -= 1,
            _ => {}
        }
    }
    s.len()
}

fn split_top_level(s: &str) -> Vec<&str> {
    let (mut depth, mut start, mut out) = (0, 0, Vec::new());
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                out.push(&s[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&s[start..]);
    out
}

/// A circle in `graph`, if there is one, as the nodes along it.
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(node.to_string(), 1);
        stack.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            match state.get(next.as_str()) {
                Some(1) => {
                    let from = stack.iter().position(|n| n == next).unwrap_or(0);
                    let mut cycle = stack[from..].to_vec();
                    cycle.push(next.clone());
                    return Some(cycle);
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(next, graph, state, stack) {
                        return Some(c);
                    }
                }
            }
        }
        stack.pop();
        state.insert(node.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in graph.keys() {
        if !state.contains_key(node.as_str())
            && let Some(c) = visit(node, graph, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

struct Source {
    /// Path below src/, e.g. `scene/toml/build.rs`.
    rel: String,
    code: String,
}

fn sources() -> Vec<Source> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    files
        .into_iter()
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n != "main.rs" && n != "lib.rs")
        })
        .map(|p| Source {
            rel: p
                .strip_prefix(&src)
                .expect("below src")
                .to_string_lossy()
                .replace('\\', "/"),
            code: code(&std::fs::read_to_string(&p).expect("readable")),
        })
        .collect()
}

#[test]
fn modules_import_only_downwards_and_never_in_a_circle() {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut upward = Vec::new();
    for s in sources() {
        let top = s.rel.split(['/', '.']).next().expect("a name").to_string();
        let own = layer_of(&top).unwrap_or_else(|| panic!("{top} is in no layer of LAYERS"));
        for dep in paths_after(&s.code, "crate") {
            if dep == top {
                continue;
            }
            let theirs = layer_of(&dep)
                .unwrap_or_else(|| panic!("src/{} uses crate::{dep}, which is in no layer", s.rel));
            if theirs > own {
                upward.push(format!(
                    "src/{} (layer {own}) uses crate::{dep} (layer {theirs})",
                    s.rel
                ));
            }
            graph.entry(top.clone()).or_default().insert(dep);
        }
    }
    assert!(upward.is_empty(), "imports upward:\n{}", upward.join("\n"));
    assert_eq!(
        find_cycle(&graph),
        None,
        "modules import each other in a circle"
    );
}

#[test]
fn files_of_a_folder_never_import_each_other_in_a_circle() {
    // Per folder: each file (a module other than the folder's mod.rs) and the siblings it
    // names through `super::`. The folder's mod.rs is the namespace the files share; its
    // re-exports are not dependencies.
    let mut folders: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for s in sources() {
        let (folder, file) = match s.rel.rsplit_once('/') {
            Some((d, f)) => (d.to_string(), f.to_string()),
            None => (String::new(), s.rel.clone()),
        };
        if file == "mod.rs" {
            continue;
        }
        let name = file.trim_end_matches(".rs").to_string();
        folders.entry(folder).or_default().insert(name, s.code);
    }
    let mut checked = Vec::new();
    for (folder, files) in &folders {
        if folder.is_empty() {
            continue;
        }
        let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (name, code) in files {
            let deps = paths_after(code, "super")
                .into_iter()
                .filter(|d| d != name && files.contains_key(d))
                .collect();
            graph.insert(name.clone(), deps);
        }
        assert_eq!(
            find_cycle(&graph),
            None,
            "files of src/{folder} import each other"
        );
        checked.push(folder.as_str());
    }
    // The folders exist: the test would pass vacuously on a misread tree.
    assert!(checked.len() >= 5, "only {} folders found", checked.len());
    for folder in [
        "scene",
        "scene/obj",
        "scene/toml",
        "geometry",
        "trace",
        "render",
        "experiments/stability",
        "app",
    ] {
        assert!(checked.contains(&folder), "src/{folder} was not checked");
    }
}

#[test]
fn the_checker_sees_paths_and_circles() {
    let code = code(
        "use crate::scene::{self, Scene};\nuse crate::{accel, trace::X};\n// crate::app\nlet x = crate::render::f();\n#[cfg(test)]\nmod tests { use crate::experiments; }",
    );
    let found: Vec<String> = paths_after(&code, "crate").into_iter().collect();
    assert_eq!(found, ["accel", "render", "scene", "trace"]);
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    g.entry("a".into()).or_default().insert("b".into());
    g.entry("b".into()).or_default().insert("c".into());
    assert_eq!(find_cycle(&g), None);
    g.entry("c".into()).or_default().insert("a".into());
    assert_eq!(
        find_cycle(&g),
        Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
    );
}
