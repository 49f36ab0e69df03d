//! The `raytree` command as a user runs it: renders, trees, errors and exit codes.

use assert_cmd::Command;

fn raytree() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytree"))
}

fn png_text(path: &std::path::Path) -> Vec<(String, String)> {
    let file = std::fs::File::open(path).expect("png exists");
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("valid png");
    reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect()
}

#[test]
fn renders_png_with_stats_and_stamps() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("quiz.png");
    let output = raytree()
        .args([
            "render",
            "quiz",
            "--width",
            "41",
            "--height",
            "31",
            "--samples",
            "2",
            "-o",
        ])
        .arg(&out)
        .output()
        .expect("runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("primary") && stdout.contains("shadow") && stdout.contains("Mrays/s"));
    // 41 × 31 pixels × 2 samples primary rays.
    assert!(
        stdout.contains(&format!("{} primary", 41 * 31 * 2)),
        "{stdout}"
    );
    let text = png_text(&out);
    assert!(
        text.iter()
            .any(|(k, v)| k == "raytree.samples" && v == "2/2"),
        "{text:?}"
    );
    assert!(
        text.iter()
            .any(|(k, v)| k == "raytree.settings" && v.contains("max_depth"))
    );
}

#[test]
fn renders_exr() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("glass.exr");
    raytree()
        .args([
            "render", "glass", "--width", "32", "--height", "24", "-q", "-o",
        ])
        .arg(&out)
        .assert()
        .success();
    let bytes = std::fs::read(&out).expect("exr written");
    assert_eq!(
        &bytes[..4],
        &[0x76, 0x2f, 0x31, 0x01],
        "OpenEXR magic number"
    );
}

/// `--stats-json`: every figure the peer bench reads, consistent with each other,
/// and `--threads` holding for the accelerator build too.
#[test]
fn stats_json_has_consistent_figures() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (out, stats) = (dir.path().join("box.png"), dir.path().join("s.json"));
    raytree()
        .args([
            "render",
            "box",
            "--width",
            "48",
            "--height",
            "36",
            "--threads",
            "1",
        ])
        .args(["--accel", "bvh", "--quiet", "-o"])
        .arg(&out)
        .arg("--stats-json")
        .arg(&stats)
        .assert()
        .success();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).expect("stats written"))
            .expect("stats are JSON");
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"));
    let s = &json["stats"];
    for key in ["build_secs", "render_secs"] {
        assert!(f(&s[key]) > 0.0, "{key} = {}", s[key]);
    }
    assert!(f(&json["load_secs"]) > 0.0);
    let rays: f64 = ["primary", "reflected", "refracted", "shadow"]
        .iter()
        .map(|k| f(&s["rays"][k]))
        .sum();
    assert_eq!(
        f(&s["rays"]["primary"]),
        48.0 * 36.0,
        "one camera ray a pixel"
    );
    assert!(f(&s["rays"]["shadow"]) > 0.0 && f(&s["rays"]["reflected"]) > 0.0);
    let mrays = rays / f(&s["render_secs"]) / 1e6;
    assert!((f(&json["mrays_per_sec"]) - mrays).abs() <= 1e-9 * mrays.max(1.0));
    assert_eq!(s["accel"], "bvh");
    assert_eq!(s["threads"], 1);
    assert_eq!(
        json["build_threads"], 1,
        "--threads 1 holds for the build too"
    );
    let m = &json["memory"];
    let triangles = f(&json["triangles"]);
    assert!(triangles > 0.0);
    assert!(f(&m["accel_bytes"]) > f(&m["scene_geometry_bytes"]) * 0.5);
    let per_tri = (f(&m["accel_bytes"]) + f(&m["scene_geometry_bytes"])) / triangles;
    assert!((f(&m["bytes_per_triangle"]) - per_tri).abs() < 1e-6 * per_tri);
    assert!(
        f(&m["peak_bytes"]) > f(&m["accel_bytes"]),
        "peak RSS holds the structure"
    );
}

/// `--frames K` (the peer bench's first and warm frames): one load and build, K
/// renders, each frame's render phase in the JSON, the statistics the first frame's, and the
/// image the same as a single frame's; `--frames 0` is refused.
#[test]
fn frames_render_several_times_after_one_build() {
    let dir = tempfile::tempdir().expect("temp dir");
    let run = |frames: &str, name: &str| {
        let (out, stats) = (
            dir.path().join(format!("{name}.png")),
            dir.path().join(format!("{name}.json")),
        );
        raytree()
            .args([
                "render", "glass", "--width", "40", "--height", "30", "--quiet",
            ])
            .args(["--threads", "1", "--frames", frames, "-o"])
            .arg(&out)
            .arg("--stats-json")
            .arg(&stats)
            .assert()
            .success();
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&stats).expect("stats written"))
                .expect("stats are JSON");
        (std::fs::read(&out).expect("image written"), json)
    };
    let (one_image, one) = run("1", "one");
    let (three_image, three) = run("3", "three");
    assert!(
        one.get("frame_render_secs").is_none(),
        "one frame: the JSON as before"
    );
    let frames = three["frame_render_secs"]
        .as_array()
        .expect("frame_render_secs is a list");
    assert_eq!(frames.len(), 3);
    assert!(frames.iter().all(|f| f.as_f64().is_some_and(|s| s > 0.0)));
    assert_eq!(frames[0], three["stats"]["render_secs"], "stats of frame 1");
    assert_eq!(
        one["stats"]["rays"], three["stats"]["rays"],
        "a frame's rays"
    );
    assert_eq!(one_image, three_image, "every frame is the same image");
    raytree()
        .args(["render", "glass", "--frames", "0", "-o"])
        .arg(dir.path().join("never.png"))
        .assert()
        .failure();
}

#[test]
fn bad_scene_is_one_sentence_and_no_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("bad.toml");
    std::fs::write(&scene, "[[sphere]]\ncenter = [0, 0, 0]\nradius = -1\n").expect("write");
    let out = dir.path().join("never.png");
    let output = raytree()
        .args(["render"])
        .arg(&scene)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("runs");
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("bad.toml:3:"), "{stderr}");
    assert!(stderr.contains("radius"), "{stderr}");
    assert!(!out.exists());
}

#[test]
fn unwritable_output_fails_cleanly() {
    let output = raytree()
        .args(["render", "quiz", "--width", "8", "--height", "8", "-q"])
        .args(["-o", "/nonexistent-folder/x.png"])
        .output()
        .expect("runs");
    // Refused before the render: 65536 samples a pixel of the default scene would take hours.
    let mut long = std::process::Command::new(env!("CARGO_BIN_EXE_raytree"))
        .args(["render", "default", "--samples", "65536", "-q"])
        .args(["-o", "/nonexistent-folder/long.png"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("runs");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    let status = loop {
        if let Some(status) = long.try_wait().expect("waits") {
            break status;
        }
        if std::time::Instant::now() > deadline {
            let _ = long.kill();
            panic!("the unwritable output was not refused before the render");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    assert!(!status.success());
    let mut stderr = String::new();
    std::io::Read::read_to_string(&mut long.stderr.take().expect("stderr"), &mut stderr)
        .expect("reads");
    assert!(
        stderr.starts_with("error: cannot write /nonexistent-folder/long.png"),
        "{stderr}"
    );
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.starts_with("error: cannot write /nonexistent-folder/x.png"),
        "{stderr}"
    );
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    let output = raytree()
        .args(["render", "quiz", "-o", "x.jpg"])
        .output()
        .expect("runs");
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains(".png"));
}

#[test]
fn out_of_range_options_are_refused() {
    for args in [["--max-depth", "65"], ["--width", "0"], ["--samples", "0"]] {
        raytree()
            .args(["render", "quiz", "-o", "x.png"])
            .args(args)
            .assert()
            .failure();
    }
    // A thread count past the bound is a usage error (exit 2) before any thread starts.
    for (command, output) in [("render", "-o"), ("bench", "--out")] {
        let out = raytree()
            .args([command, "quiz", "--threads", "99999999", output, "x.png"])
            .output()
            .expect("runs");
        assert_eq!(out.status.code(), Some(2), "{command}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--threads"), "{command}: {err}");
    }
}

#[test]
fn tree_prints_text_and_json() {
    // The quiz scene's centre pixel hits the triangle at P = (0, 0, −1).
    let output = raytree()
        .args(["tree", "quiz", "--pixel", "100,100", "--json"])
        .output()
        .expect("runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("json");
    let hit = &json["root"]["hit"];
    let point: Vec<f64> = serde_json::from_value(hit["point"].clone()).expect("point");
    assert!((point[2] + 1.0).abs() < 1e-6, "{point:?}");
    let bary: Vec<f64> = serde_json::from_value(hit["barycentric"].clone()).expect("bary");
    assert!((bary[2] - 0.5).abs() < 1e-6, "{bary:?}");
    assert_eq!(json["root"]["kind"], "primary");
    let text = raytree()
        .args(["tree", "quiz", "--pixel", "100,100"])
        .output()
        .expect("runs");
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("shadow ray to") && text.contains("barycentric"),
        "{text}"
    );
    raytree()
        .args(["tree", "quiz", "--pixel", "5000,1"])
        .assert()
        .failure();
}

#[test]
fn help_documents_the_options() {
    let output = raytree().args(["render", "--help"]).output().expect("runs");
    let help = String::from_utf8_lossy(&output.stdout);
    for flag in [
        "--width",
        "--height",
        "--samples",
        "--max-depth",
        "--threads",
        "--accel",
        "--sphere",
        "--triangle",
        "--offset",
        "--shading",
        "--cutoff",
    ] {
        assert!(help.contains(flag), "render --help lacks {flag}");
    }
}

/// `raytree … | head -1`: stdout closes while the program still writes. That is not an error
/// worth a panic (Rust ignores SIGPIPE, so every write after the close fails with BrokenPipe).
#[test]
fn closed_stdout_is_not_a_panic() {
    use std::io::{BufRead, BufReader};
    use std::process::{Command, Stdio};

    /// Exit code and stderr of a run, checked to be free of panics.
    fn check(what: &str, output: std::process::Output) {
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!stderr.contains("panicked"), "{what}: {stderr}");
        assert!(
            output.status.code().is_some_and(|c| c != 101),
            "{what}: {:?}, {stderr}",
            output.status
        );
    }

    // The first line is read, then the pipe closes. The tree of this pixel is cut at
    // MAX_NODES: megabytes of JSON, over 100 KB of text, far more than a pipe buffers (64 KiB
    // on Linux), so the program is still writing when the pipe closes.
    let tree = ["tree", "glass", "--pixel", "200,240", "--max-depth", "64"];
    for json in [true, false] {
        let args: Vec<&str> = tree
            .iter()
            .copied()
            .chain(json.then_some("--json"))
            .collect();
        let what = args.join(" ");
        let full = raytree().args(&args).output().expect("runs");
        assert!(full.status.success(), "{what}");
        assert!(full.stdout.len() > 100_000, "{what}: too short a test");
        let mut child = Command::new(env!("CARGO_BIN_EXE_raytree"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawns");
        let mut first = String::new();
        BufReader::new(child.stdout.take().expect("piped stdout"))
            .read_line(&mut first)
            .expect("reads the first line");
        // The reader (and so the pipe's read end) is dropped here.
        assert!(!first.is_empty(), "{what}: no output");
        check(&what, child.wait_with_output().expect("waits"));
    }

    // The read end closed before the program starts: its first write already fails.
    for args in [
        &["scenes"][..],
        &[
            "render", "quiz", "--width", "8", "--height", "8", "-q", "-o",
        ],
    ] {
        let dir = tempfile::tempdir().expect("temp dir");
        let (reader, writer) = std::io::pipe().expect("pipe");
        drop(reader);
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_raytree"));
        cmd.args(args);
        if args[0] == "render" {
            cmd.arg(dir.path().join("x.png"));
        }
        let output = cmd
            .stdout(writer)
            .stderr(Stdio::piped())
            .output()
            .expect("runs");
        check(&args.join(" "), output);
    }
}

/// `--help` and `raytree scenes` list the same built-in scenes (every one, `smooth` too), each
/// with its line of description.
#[test]
fn help_and_scenes_list_every_built_in_scene_with_its_description() {
    let out = raytree().arg("--help").output().expect("runs");
    let help = String::from_utf8_lossy(&out.stdout).to_string();
    let out = raytree().arg("scenes").output().expect("runs");
    assert!(out.status.success());
    let scenes = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(scenes.lines().count(), raytree::scene::builtin::NAMES.len());
    for name in raytree::scene::builtin::NAMES {
        let line = scenes
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("`raytree scenes` lists {name}:\n{scenes}"));
        let description = raytree::scene::builtin::describe(name).expect("described");
        assert!(line.contains(description), "{line}");
        assert!(help.contains(line.trim()), "--help lists {name}:\n{help}");
    }
}

/// A mistyped built-in name is answered with the closest names, not "cannot open this kind
/// of file".
#[test]
fn a_misspelled_built_in_scene_is_answered_with_the_closest_name() {
    let out = raytree()
        .args(["render", "glas", "-o", "/nonexistent/x.png"])
        .output()
        .expect("runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("did you mean \"glass\"?"), "{err}");
    assert!(!err.contains("kind of file"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}
