//! Hostile input and faults (docs/reliability.md), as a user meets them: every file of the hostile
//! corpus (`tests/fixtures/hostile`) gives one sentence naming the file, the place and the field,
//! or loads with a warning; `raytree render` on each exits non-zero with exactly one stderr line
//! and writes nothing; sizes are refused by their memory estimate before anything is allocated;
//! recursion and trees stay bounded; a panicking worker is reported; failed writes leave no file
//! behind.
//!
//! Update the corpus snapshot after a deliberate change (look at it first):
//! `INSTA_UPDATE=always cargo test --release --test hostile`

mod hostile_support;
mod obj_compare;

use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use assert_cmd::Command;
use hostile_support::{check_invariants, is_one_line, render_tiny, same_on_every_machine};
use raytree::ray_tree::{MAX_NODES, Node, pixel_tree};
use raytree::render::{RenderError, render, render_with, trace_tile};
use raytree::scene::{Scene, load_builtin, load_scene_file, load_scene_str};
use raytree::trace::{MAX_RAYS_PER_SAMPLE, TraceSettings, Tracer};

const CORPUS: &str = "tests/fixtures/hostile";

/// The corpus entries (MTL files are read through the OBJ files that name them, and the
/// contents of the folder named like an OBJ are not scenes).
/// The file name of a corpus entry, as the messages print it.
fn file_name(path: &Path) -> String {
    path.file_name()
        .expect("name")
        .to_string_lossy()
        .to_string()
}

fn corpus() -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(CORPUS)
        .expect("the hostile corpus")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e != "mtl"))
        .collect();
    paths.sort();
    paths.push(Path::new(CORPUS).join("does_not_exist.obj"));
    paths
}

fn raytree() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytree"))
}

fn stderr_lines(output: &Output) -> Vec<String> {
    String::from_utf8_lossy(&output.stderr)
        .lines()
        .map(str::to_string)
        .collect()
}

/// Every file of the corpus: an error of one sentence that names the file (and the line,
/// column and field where there is one), or a scene that keeps every invariant and renders.
/// The snapshot is the list `name => message`.
#[test]
fn hostile_corpus_gives_one_sentence_each() {
    let mut report = String::new();
    for path in corpus() {
        let name = path.file_name().expect("name").to_string_lossy();
        let outcome = match load_scene_file(&path) {
            Err(e) => {
                let message = e.to_string();
                assert!(is_one_line(&message), "{name}: {message}");
                assert!(
                    message.starts_with(&format!("{}:", path.display())),
                    "{name}: the message does not name the file: {message}"
                );
                assert!(message.ends_with('.'), "{name}: not a sentence: {message}");
                same_on_every_machine(&message)
            }
            Ok(scene) => {
                if let Err(rule) = check_invariants(&scene) {
                    panic!("{name} loaded but breaks the rule: {rule}");
                }
                render_tiny(&scene);
                let mut line = format!(
                    "loads: {} triangles, {} spheres",
                    scene.triangles.len(),
                    scene.spheres.len()
                );
                for w in &scene.warnings {
                    assert!(w.ends_with('.'), "{name}: not a sentence: {w}");
                    line += &format!(" | warning: {}", same_on_every_machine(w));
                }
                line
            }
        };
        report += &format!("{name} => {outcome}\n");
    }
    insta::assert_snapshot!("hostile_corpus", report);
}

/// `raytree render` on each refused file: exit code 1, exactly the loader's sentence on one
/// stderr line, no output file. Files that load (with warnings) render and print each
/// warning on its own line.
#[test]
fn cli_refuses_each_hostile_file_with_one_line_and_no_output() {
    let dir = tempfile::tempdir().expect("temp dir");
    for path in corpus() {
        let name = file_name(&path);
        let out = dir.path().join(format!("{name}.png"));
        let output = raytree()
            // Depth 8: `glass_between_mirrors.toml` at its own 64 would take hours.
            .args(["render", "-q", "--max-depth", "8", "-o"])
            .arg(&out)
            .arg(&path)
            // 1 GiB: `all_maximum.toml` (16384², 10 GiB to render) is refused the same way on
            // every machine.
            .env("RAYTREE_MEMORY_LIMIT", "1024")
            // A hang guard, not a measure of speed: a render that never ends fails here.
            .timeout(Duration::from_secs(60))
            .output()
            .expect("runs");
        let lines = stderr_lines(&output);
        match load_scene_file(&path) {
            Err(e) => {
                assert_eq!(output.status.code(), Some(1), "{name}: {lines:?}");
                assert_eq!(lines, vec![format!("error: {e}")], "{name}");
                assert!(!out.exists(), "{name}: an output file was written");
            }
            Ok(scene) if name == "all_maximum.toml" => {
                assert_eq!(output.status.code(), Some(1), "{name}: {lines:?}");
                assert_eq!(
                    lines,
                    vec![
                        "error: a 16384x16384 render would need about 10.0 GiB, more than the \
                         memory limit of 1.0 GiB (set by RAYTREE_MEMORY_LIMIT=1024)"
                    ],
                    "{name}"
                );
                assert!(scene.warnings.is_empty());
                assert!(!out.exists(), "{name}: an output file was written");
            }
            Ok(scene) => {
                assert!(output.status.success(), "{name}: {lines:?}");
                // The CLI's memory limit is not the test's: compare without the limit.
                let expected: Vec<String> = scene
                    .warnings
                    .iter()
                    .map(|w| same_on_every_machine(&format!("warning: {w}")))
                    .collect();
                let lines: Vec<String> = lines.iter().map(|l| same_on_every_machine(l)).collect();
                assert_eq!(lines, expected, "{name}");
                assert!(out.exists(), "{name}: no image");
            }
        }
    }
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .expect("list")
        .map(|e| e.expect("entry").file_name())
        .filter(|n| n.to_string_lossy().starts_with(".raytree-"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

/// Mesh paths: absolute paths and `..` are allowed (a scene is the user's own file and may use
/// a model library anywhere); only `.obj` files are meshes, so a scene cannot include a scene
/// (no cycles); devices and folders are refused before they are read.
#[test]
fn mesh_paths_absolute_parent_and_non_obj() {
    let dir = tempfile::tempdir().expect("temp dir");
    let model = std::fs::canonicalize("tests/fixtures/models/materials.obj").expect("model");
    let scene = dir.path().join("absolute.toml");
    let text = format!("[[mesh]]\nfile = \"{}\"\n", model.display());
    std::fs::write(&scene, text).expect("write");
    let loaded = load_scene_file(&scene).expect("an absolute mesh path loads");
    assert!(!loaded.triangles.is_empty());

    // `..` as far up as it goes, then down to the model: the same file.
    let depth = dir.path().components().count() + 3;
    let up = "../".repeat(depth);
    let relative = format!(
        "{up}{}",
        model.display().to_string().trim_start_matches('/')
    );
    let text = format!("[[mesh]]\nfile = \"{relative}\"\n");
    std::fs::write(&scene, text).expect("write");
    let escaped = load_scene_file(&scene).expect("a path that climbs past / still resolves");
    assert_eq!(escaped.triangles, loaded.triangles);

    let e = load_scene_str("[[mesh]]\nfile = \"other.TOML\"\n", "t.toml")
        .expect_err("a scene is not a mesh")
        .to_string();
    assert_eq!(
        e,
        "t.toml:2:8: mesh 1 field `file` must name an OBJ file (ending in `.obj`), got \
         \"other.TOML\"."
    );
}

/// Bytes this thread has read so far (`rchar` of `/proc/thread-self/io`, Linux): per thread, so
/// what other tests read at the same time does not count.
fn bytes_read_by_this_thread() -> u64 {
    let io = std::fs::read_to_string("/proc/thread-self/io").expect("/proc/thread-self/io");
    io.lines()
        .find_map(|l| l.strip_prefix("rchar: "))
        .and_then(|n| n.parse().ok())
        .expect("an rchar line")
}

/// Files over the size caps are refused from their size alone, before a byte is read: a
/// sparse file of 600 MiB costs nothing to make and nothing to refuse.
#[test]
fn oversized_files_are_refused_before_reading() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cases = [
        (
            "huge.obj",
            600u64 << 20,
            "600.0 MiB, more than the 512.0 MiB",
        ),
        ("huge.toml", 65 << 20, "65.0 MiB, more than the 64.0 MiB"),
    ];
    for (name, size, expected) in cases {
        let path = dir.path().join(name);
        std::fs::File::create(&path)
            .and_then(|f| f.set_len(size))
            .expect("sparse file");
        let before = bytes_read_by_this_thread();
        let e = load_scene_file(&path).expect_err("too big").to_string();
        let read = bytes_read_by_this_thread() - before;
        // The loader reads on the calling thread. What this thread reads besides is the first
        // look at `/proc/thread-self/io` (a few hundred bytes), far below the file's size.
        assert!(read < 4096, "{read} bytes of {name} were read");
        assert!(
            e.contains(&format!(
                "cannot read the scene file: it is {expected} a file may have."
            )),
            "{e}"
        );
    }
    // The same cap holds for a mesh named by a scene.
    let scene = dir.path().join("s.toml");
    std::fs::write(&scene, "[[mesh]]\nfile = \"huge.obj\"\n").expect("write");
    let e = load_scene_file(&scene).expect_err("too big").to_string();
    assert!(
        e.ends_with(
            "s.toml:2:8: mesh 1 field `file` cannot be loaded: huge.obj: it is 600.0 MiB, \
             more than the 512.0 MiB a file may have."
        ),
        "{e}"
    );
}

/// The memory budget refuses a mesh from its counts, before tobj reads it, and an image from
/// its size, before the film is allocated; both say the estimate and the limit.
#[test]
fn memory_estimates_over_the_limit_are_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = dir.path().join("many.obj");
    let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    text += &"f 1 2 3\n".repeat(5000);
    std::fs::write(&obj, text).expect("write");
    let output = raytree()
        .args(["render", "-q", "-o"])
        .arg(dir.path().join("never.png"))
        .arg(&obj)
        .env("RAYTREE_MEMORY_LIMIT", "1")
        .output()
        .expect("runs");
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(
        stderr_lines(&output),
        vec![format!(
            "error: {}: cannot load the OBJ: its 3 vertices and 5000 triangles would need about \
             2.2 MiB, more than the memory limit of 1.0 MiB (set by RAYTREE_MEMORY_LIMIT=1).",
            obj.display()
        )]
    );

    // Refused before the film is allocated: with its address space limited to 1 GiB (`ulimit
    // -v`, a tenth of the estimate) the process would abort on the allocation, not exit with
    // the sentence. The refusal itself needs well under 64 MiB.
    let script = format!(
        "ulimit -v {}; exec \"$0\" render quiz --width 16384 --height 16384 -o '{}'",
        1 << 20,
        dir.path().join("never.png").display()
    );
    let output = Command::new("sh")
        .args(["-c", &script, env!("CARGO_BIN_EXE_raytree")])
        .env("RAYTREE_MEMORY_LIMIT", "2048")
        .output()
        .expect("runs");
    assert_eq!(output.status.code(), Some(1), "{:?}", stderr_lines(&output));
    assert_eq!(
        stderr_lines(&output),
        vec![
            "error: a 16384x16384 render would need about 10.0 GiB, more than the memory limit \
             of 2.0 GiB (set by RAYTREE_MEMORY_LIMIT=2048)"
        ]
    );
    assert_eq!(std::fs::read_dir(dir.path()).expect("list").count(), 1);
}

fn count_nodes(node: &Node) -> usize {
    1 + node.children.iter().map(count_nodes).sum::<usize>()
}

/// Recursion is bounded by `max_depth ≤ 64`, the tree by its node cap and the work by the ray
/// budget of a sample: the glass scene at depth 64 traces a pixel through the sphere and builds
/// a capped tree, and a render of it traces at most the budget per sample.
#[test]
fn glass_at_max_depth_64_is_bounded() {
    let mut scene = load_builtin("glass").expect("glass");
    scene.render.max_depth = 64;
    let e = load_scene_str("[render]\nmax_depth = 65\n", "t.toml").expect_err("65");
    assert!(e.to_string().contains("must be at most 64"), "{e}");
    let (w, h) = (scene.render.width, scene.render.height);
    let per_sample = sample_ray_bound(&scene);
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    // Through the glass sphere (left) and the prism (right).
    for (x, y) in [(w * 27 / 100, h * 55 / 100), (w * 70 / 100, h * 60 / 100)] {
        let tree = pixel_tree(&tracer, x, y).expect("a tree");
        let nodes = count_nodes(&tree.root);
        assert!(nodes <= MAX_NODES, "{nodes} nodes");
        assert!(nodes > 2, "the pixel misses the glass: {nodes} nodes");
        assert!(tree.root.color.is_finite());
        assert!(tree.rays.total() <= per_sample, "{:?}", tree.rays);
    }
    let mut small = (*tracer.scene).clone();
    small.render.width = 32;
    small.render.height = 24;
    let tracer = Tracer::new(Arc::new(small), TraceSettings::default());
    let (image, stats) = render(&tracer, 1, 0, &|_, _| {}).expect("render");
    assert!(image.pixels.iter().all(|p| p.is_finite()));
    assert!(
        stats.rays.total() <= 32 * 24 * per_sample,
        "{:?}",
        stats.rays
    );
}

/// The most rays one sample of `scene` may trace: the budget, plus the shadow rays of the hit
/// traced last before it ran out (the budget stops new rays, not the shading of a hit).
fn sample_ray_bound(scene: &Scene) -> u64 {
    u64::from(MAX_RAYS_PER_SAMPLE) + scene.lights.len() as u64
}

/// A worker that panics is caught: the render reports which tile and why, and no image with a
/// hole in it is returned.
#[test]
fn panicking_worker_is_caught_and_reported() {
    let mut scene = load_builtin("quiz").expect("quiz");
    scene.render.width = 96;
    scene.render.height = 64;
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let progress = AtomicU64::new(0);
    let result = render_with(
        &tracer,
        1,
        2,
        &|done, _| {
            progress.fetch_max(done, Ordering::Relaxed);
        },
        &|tracer, frame, rect, samples, sums| {
            if (rect.x, rect.y) == (32, 32) {
                panic!("injected fault");
            }
            trace_tile(tracer, frame, rect, samples, sums)
        },
    );
    match result {
        Err(RenderError::WorkerPanicked { x, y, message }) => {
            assert_eq!((x, y, message.as_str()), (32, 32, "injected fault"));
        }
        other => panic!("expected a caught panic, got {:?}", other.map(|_| ())),
    }
    // Every tile was still accounted for: the other workers carried on.
    assert_eq!(progress.load(Ordering::Relaxed), 96 * 64);
    let e = RenderError::WorkerPanicked {
        x: 32,
        y: 32,
        message: "injected fault".into(),
    };
    assert_eq!(
        e.to_string(),
        "a render worker failed on the tile at (32, 32): injected fault"
    );
}

/// True if this process can write into a folder without write permission (root can).
fn permissions_are_ignored(dir: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    let probe = dir.join("probe");
    std::fs::create_dir(&probe).expect("probe dir");
    std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o555)).expect("chmod");
    let writable = std::fs::write(probe.join("x"), "x").is_ok();
    std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    std::fs::remove_dir_all(&probe).expect("clean");
    writable
}

/// Writes that fail leave no file and say why: a parent that is a file, a read-only folder
/// (skipped as root, where permission bits do not stop writes), and a full disk, simulated by
/// a file-size limit (`ulimit -f`) with SIGXFSZ ignored so that the write returns EFBIG.
#[test]
fn failed_writes_leave_no_file_and_say_why() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("a_file");
    std::fs::write(&file, "not a folder").expect("write");
    let out = file.join("x.png");
    let output = raytree()
        .args([
            "render", "quiz", "--width", "8", "--height", "8", "-q", "-o",
        ])
        .arg(&out)
        .output()
        .expect("runs");
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(
        stderr_lines(&output),
        vec![format!(
            "error: cannot write {}: Not a directory",
            out.display()
        )]
    );

    if permissions_are_ignored(dir.path()) {
        eprintln!("running as root: the read-only folder case is not testable here");
    } else {
        use std::os::unix::fs::PermissionsExt;
        let locked = dir.path().join("locked");
        std::fs::create_dir(&locked).expect("dir");
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).expect("chmod");
        let output = raytree()
            .args([
                "render", "quiz", "--width", "8", "--height", "8", "-q", "-o",
            ])
            .arg(locked.join("x.png"))
            .output()
            .expect("runs");
        assert_eq!(output.status.code(), Some(1));
        assert!(
            stderr_lines(&output)[0].contains("Permission denied"),
            "{:?}",
            stderr_lines(&output)
        );
        assert_eq!(std::fs::read_dir(&locked).expect("list").count(), 0);
    }

    for name in ["full.png", "full.exr"] {
        let full = dir.path().join("full");
        std::fs::create_dir_all(&full).expect("dir");
        let out = full.join(name);
        let script = format!(
            "trap '' XFSZ; ulimit -f 4; exec \"$0\" render quiz --width 256 --height 256 -q -o '{}'",
            out.display()
        );
        let output = Command::new("sh")
            .args(["-c", &script, env!("CARGO_BIN_EXE_raytree")])
            .output()
            .expect("runs");
        assert_eq!(output.status.code(), Some(1), "{:?}", stderr_lines(&output));
        assert_eq!(
            stderr_lines(&output),
            vec![format!(
                "error: cannot write {}: File too large",
                out.display()
            )]
        );
        assert_eq!(
            std::fs::read_dir(&full).expect("list").count(),
            0,
            "a partial or temporary file was left"
        );
    }
}

/// Usage errors are one line too (exit code 2); help still prints in full.
#[test]
fn usage_errors_are_one_line() {
    for args in [
        vec!["render"],
        vec!["--bogus"],
        vec!["render", "quiz", "-o", "x.png", "--width", "abc"],
        vec!["render", "quiz", "-o", "x.png", "--widht", "8"],
        vec!["tree", "quiz", "--pixel", "1;2"],
        vec!["render", "quiz", "-o", "x.png", "--accel", "octree"],
    ] {
        let output = raytree().args(&args).output().expect("runs");
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        let lines = stderr_lines(&output);
        assert_eq!(lines.len(), 1, "{args:?}: {lines:?}");
        assert!(lines[0].starts_with("error: "), "{lines:?}");
        assert!(lines[0].ends_with("(see `raytree --help`)"), "{lines:?}");
    }
    let output = raytree().arg("--help").output().expect("runs");
    assert!(output.status.success());
    assert!(String::from_utf8_lossy(&output.stdout).lines().count() > 5);
}

/// Recursion is bounded by depth, and the work by a ray budget per sample: glass between
/// mirrors doubles its rays every few levels, so without the budget one click at depth 64
/// traced millions of rays on the UI thread.
#[test]
fn a_click_on_glass_between_mirrors_at_depth_64_stays_interactive() {
    let scene = load_scene_file(
        Path::new(CORPUS)
            .join("glass_between_mirrors.toml")
            .as_path(),
    )
    .expect("loads");
    let per_sample = sample_ray_bound(&scene);
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    let tree = pixel_tree(&tracer, 16, 12).expect("a tree");
    assert!(count_nodes(&tree.root) <= MAX_NODES);
    assert!(tree.truncated, "{} nodes", tree.nodes);
    // The budget is what stopped the click: without it the pixel traces millions of rays.
    let rays = tree.rays.total();
    assert!(
        (u64::from(MAX_RAYS_PER_SAMPLE)..=per_sample).contains(&rays),
        "{rays} rays"
    );
}

/// A texture whose header claims a huge image (a 100000×100000 PNG, a 65535×65535 JPEG) is
/// refused by the memory budget from its header, before the decoder allocates a texel: with
/// the process's address space limited to 1 GiB (`ulimit -v`) an allocation of the claimed
/// size would abort it. Each is one warning naming the file, the MTL line and the estimate;
/// the render goes on with the flat colours.
#[test]
fn huge_texture_headers_are_refused_before_decoding() {
    let dir = tempfile::tempdir().expect("temp dir");
    let corpus = Path::new(CORPUS);
    for name in ["huge_header.png", "huge_header.jpg"] {
        std::fs::copy(corpus.join("textures").join(name), dir.path().join(name)).expect("copy");
    }
    std::fs::write(
        dir.path().join("huge.mtl"),
        "newmtl png\nmap_Kd huge_header.png\nnewmtl jpg\nmap_Kd huge_header.jpg\n",
    )
    .expect("mtl");
    let obj = dir.path().join("huge.obj");
    std::fs::write(
        &obj,
        "mtllib huge.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\n\
         usemtl png\nf 1/1 2/1 3/1\nusemtl jpg\nf 2/1 4/1 3/1\n",
    )
    .expect("obj");
    let out = dir.path().join("out.png");
    let script = format!(
        "ulimit -v {}; exec \"$0\" render -q --width 8 --height 8 -o '{}' '{}'",
        1 << 20,
        out.display(),
        obj.display()
    );
    let output = Command::new("sh")
        .args(["-c", &script, env!("CARGO_BIN_EXE_raytree")])
        .env("RAYTREE_MEMORY_LIMIT", "512")
        .timeout(Duration::from_secs(60))
        .output()
        .expect("runs");
    let label = obj.display();
    assert_eq!(
        stderr_lines(&output),
        vec![
            format!(
                "warning: {label}: material `png` (`huge.mtl` line 2): cannot use the texture \
                 `huge_header.png` of `map_Kd` (its 100000x100000 texels would need about \
                 167.6 GiB, more than the memory limit of 512.0 MiB (set by \
                 RAYTREE_MEMORY_LIMIT=512)); its flat colour stays."
            ),
            format!(
                "warning: {label}: material `jpg` (`huge.mtl` line 4): cannot use the texture \
                 `huge_header.jpg` of `map_Kd` (its 65535x65535 texels would need about \
                 72.0 GiB, more than the memory limit of 512.0 MiB (set by \
                 RAYTREE_MEMORY_LIMIT=512)); its flat colour stays."
            ),
        ]
    );
    assert!(output.status.success());
    assert!(out.exists(), "the render goes on without the textures");
}

/// Runs `load` on another thread and gives its result, or fails after `secs` seconds: a hang
/// guard (opening a FIFO for reading blocks until a writer comes), not a measure of speed.
fn within<T: Send + 'static>(secs: u64, load: impl FnOnce() -> T + Send + 'static) -> T {
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(load());
    });
    receive
        .recv_timeout(Duration::from_secs(secs))
        .expect("the loader hangs on a FIFO")
}

/// A named pipe (FIFO) where a texture, a material library, a mesh or the scene itself is
/// expected: refused from its metadata, before it is opened (an open would block until a
/// writer came), with one sentence or one warning naming it; never a hang.
#[test]
fn a_fifo_anywhere_is_refused_without_a_hang() {
    let dir = tempfile::tempdir().expect("temp dir");
    for name in ["pipe.png", "pipe.mtl", "pipe.obj", "pipe.toml"] {
        let status = std::process::Command::new("mkfifo")
            .arg(dir.path().join(name))
            .status()
            .expect("mkfifo runs");
        assert!(status.success(), "mkfifo {name}");
    }
    let not_regular = "it is not a regular file (a device, a pipe or a socket)";
    std::fs::write(dir.path().join("t.mtl"), "newmtl t\nmap_Kd pipe.png\n").expect("mtl");
    let obj = dir.path().join("t.obj");
    std::fs::write(
        &obj,
        "mtllib t.mtl\nmtllib pipe.mtl\nusemtl t\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n",
    )
    .expect("obj");
    let path = obj.clone();
    let scene = within(20, move || load_scene_file(&path)).expect("loads with warnings");
    let label = obj.display();
    assert_eq!(
        scene.warnings,
        vec![
            format!(
                "{label}: cannot read the material library `pipe.mtl` (pipe.mtl: {not_regular}); its faces use the default material."
            ),
            format!(
                "{label}: material `t` (`t.mtl` line 2): cannot use the texture `pipe.png` of `map_Kd` ({not_regular}); its flat colour stays."
            ),
        ]
    );
    assert!(scene.textures.is_empty());

    let toml = dir.path().join("s.toml");
    std::fs::write(&toml, "[[mesh]]\nfile = \"pipe.obj\"\n").expect("toml");
    let e = within(20, move || load_scene_file(&toml)).expect_err("a FIFO is no mesh");
    assert!(
        e.to_string().ends_with(&format!(
            "s.toml:2:8: mesh 1 field `file` cannot be loaded: pipe.obj: {not_regular}."
        )),
        "{e}"
    );
    let pipe = dir.path().join("pipe.toml");
    let shown = pipe.display().to_string();
    let e = within(20, move || load_scene_file(&pipe)).expect_err("a FIFO is no scene");
    assert_eq!(
        e.to_string(),
        format!("{shown}: cannot read the scene file: {not_regular}.")
    );
}

/// The corpus's OBJs with hostile normals and texture coordinates go through raytree's fast OBJ
/// reader as well as through tobj, and both read them alike (bit for bit, or the fast reader
/// leaves the file to tobj, which then gives the sentence): the checks of `vn`, `vt` and face
/// corners behind the readers see the same data whichever read it.
#[test]
fn the_fast_reader_and_tobj_read_the_hostile_models_alike() {
    let mtl = |p: &Path| -> tobj::MTLLoadResult {
        let path = Path::new(CORPUS).join(p);
        match std::fs::metadata(&path) {
            Ok(m) if m.is_file() => {
                let text =
                    std::fs::read_to_string(path).map_err(|_| tobj::LoadError::OpenFileFailed)?;
                tobj::load_mtl_buf(&mut text.as_bytes())
            }
            _ => Err(tobj::LoadError::OpenFileFailed),
        }
    };
    let mut taken = Vec::new();
    for path in corpus() {
        let name = file_name(&path);
        let is_model =
            name.starts_with("vn_") || name.starts_with("vt_") || name == "textures_hostile.obj";
        if !is_model {
            continue;
        }
        let text = std::fs::read_to_string(&path).expect("a text OBJ");
        if obj_compare::check(&text, &mtl) {
            taken.push(name);
        }
    }
    // Files with valid indices are read by the fast reader; those with indices of 0, negative
    // or out of range are left to tobj.
    assert_eq!(
        taken,
        [
            "textures_hostile.obj",
            "vn_inf.obj",
            "vn_nan.obj",
            "vn_on_some_corners.obj",
            "vn_on_some_faces.obj",
            "vn_opposite.obj",
            "vn_zero.obj",
            "vt_nan.obj",
            "vt_on_some_corners.obj",
            "vt_on_some_faces.obj",
        ]
    );
}
