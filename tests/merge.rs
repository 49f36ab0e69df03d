//! A render spread over machines, on one: `raytree render --region/--tile` parts equal the
//! same pixels of the full render bit for bit, `raytree merge` puts them back into the full
//! render exactly, refuses parts that do not belong together with one sentence naming the
//! part and writes nothing then; turntable frames are named and turned.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Output;

use assert_cmd::Command;
use raytree::export::{Pixels, StampedImage, read_stamped};

fn raytree() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytree"))
}

/// The scene and settings every part here uses: small, several samples (so sample offsets
/// matter), odd size (so bands differ in height).
const SCENE: &[&str] = &[
    "quiz",
    "--width",
    "97",
    "--height",
    "61",
    "--samples",
    "3",
    "-q",
];

/// Runs `raytree COMMAND ARGS -o OUT`.
fn run(command: &str, args: &[&OsStr], out: &Path) -> Output {
    raytree()
        .arg(command)
        .args(args)
        .arg("-o")
        .arg(out)
        .output()
        .expect("runs")
}

/// Runs `raytree render ARGS -o OUT`, expecting success.
fn rendered(args: &[&str], out: &Path) {
    let args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
    let output = run("render", &args, out);
    assert!(
        output.status.success(),
        "render {args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// Expects `output` to be a failure of one line that contains `needle`, and no `out` written.
fn one_line_refusal(output: &Output, out: &Path, needle: &str) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "must fail: `{needle}`");
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    assert!(stderr.contains(needle), "`{needle}` in: {stderr}");
    assert!(!out.exists(), "nothing written on refusal: {stderr}");
}

/// Renders [`SCENE`] with `extra` arguments to `dir/name`.
fn render(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    let out = dir.join(name);
    rendered(&[SCENE, extra].concat(), &out);
    out
}

fn read(path: &Path) -> StampedImage {
    read_stamped(path).unwrap_or_else(|e| panic!("{e}"))
}

fn linear(image: &StampedImage) -> Vec<[u32; 3]> {
    match &image.pixels {
        Pixels::Linear(px) => px
            .iter()
            .map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()])
            .collect(),
        Pixels::Srgb8(_) => panic!("expected an EXR"),
    }
}

/// Runs `raytree merge PARTS -o out`, expecting success.
fn merge(dir: &Path, parts: &[&Path], out: &str) -> PathBuf {
    let out = dir.join(out);
    let output = run("merge", &os(parts), &out);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    out
}

/// Runs `raytree merge PARTS -o refused.exr`, expecting a one-line refusal that contains
/// `needle`, and no file (nor temporary file) left behind.
fn refused(dir: &Path, parts: &[&Path], needle: &str) {
    let before: Vec<_> = std::fs::read_dir(dir).expect("list").collect();
    let out = dir.join("refused.exr");
    let output = run("merge", &os(parts), &out);
    one_line_refusal(&output, &out, needle);
    let after: Vec<_> = std::fs::read_dir(dir).expect("list").collect();
    assert_eq!(
        before.len(),
        after.len(),
        "no file left: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

fn os<'a>(paths: &[&'a Path]) -> Vec<&'a OsStr> {
    paths.iter().map(|p| p.as_os_str()).collect()
}

#[test]
fn a_region_is_bit_for_bit_the_same_pixels_of_the_full_render() {
    let dir = tempfile::tempdir().expect("temp dir");
    let full = read(&render(dir.path(), "full.exr", &[]));
    let (x0, y0, w, h) = (37u32, 23u32, 41u32, 29u32);
    let part = read(&render(
        dir.path(),
        "part.exr",
        &["--region", &format!("{x0},{y0},{w},{h}")],
    ));
    assert_eq!((part.width, part.height), (w, h));
    assert_eq!(part.get("raytree.region"), Some("37,23,41,29"));
    assert_eq!(full.get("raytree.region"), Some("0,0,97,61"));
    assert_eq!(
        part.get("raytree.scene_hash"),
        full.get("raytree.scene_hash")
    );
    let (fp, pp) = (linear(&full), linear(&part));
    let mut nonzero = 0;
    for y in 0..h {
        for x in 0..w {
            let a = fp[((y0 + y) * 97 + x0 + x) as usize];
            assert_eq!(
                pp[(y * w + x) as usize],
                a,
                "pixel ({}, {})",
                x0 + x,
                y0 + y
            );
            nonzero += usize::from(a != [0; 3]);
        }
    }
    assert!(
        nonzero > 100,
        "the region shows the scene ({nonzero} lit pixels)"
    );
}

#[test]
fn four_tiles_merge_to_the_full_render_bit_for_bit() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let full_exr = render(d, "full.exr", &[]);
    let full_png = render(d, "full.png", &[]);
    let mut exr_parts = Vec::new();
    let mut png_parts = Vec::new();
    for i in 0..4 {
        let tile = format!("{i}/4");
        exr_parts.push(render(d, &format!("t{i}.exr"), &["--tile", &tile]));
        png_parts.push(render(d, &format!("t{i}.png"), &["--tile", &tile]));
    }
    // Even row bands of 61 rows: 15, 15, 15, 16.
    let heights: Vec<u32> = exr_parts.iter().map(|p| read(p).height).collect();
    assert_eq!(heights, [15, 15, 15, 16]);
    // Any order of the parts.
    let exr: Vec<&Path> = exr_parts.iter().rev().map(PathBuf::as_path).collect();
    let merged = read(&merge(d, &exr, "merged.exr"));
    let full = read(&full_exr);
    assert_eq!((merged.width, merged.height), (97, 61));
    assert_eq!(
        linear(&merged),
        linear(&full),
        "merged EXR equals the full render"
    );
    assert_eq!(
        merged.text, full.text,
        "and carries the full render's stamp"
    );
    let png: Vec<&Path> = png_parts.iter().map(PathBuf::as_path).collect();
    let merged_png = merge(d, &png, "merged.png");
    assert!(
        std::fs::read(&merged_png).expect("merged") == std::fs::read(&full_png).expect("full"),
        "merged PNG equals the full render's PNG byte for byte"
    );
    // EXR parts to a PNG: the same bytes again.
    let from_exr = merge(d, &exr, "from_exr.png");
    assert!(
        std::fs::read(&from_exr).expect("merged") == std::fs::read(&full_png).expect("full"),
        "EXR parts merged to PNG equal the full render's PNG byte for byte"
    );
}

#[test]
fn parts_that_do_not_make_one_image_are_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let t: Vec<PathBuf> = (0..3)
        .map(|i| render(d, &format!("t{i}.exr"), &["--tile", &format!("{i}/3")]))
        .collect();
    // A missing part.
    refused(
        d,
        &[&t[0], &t[2]],
        "the parts leave 1940 of the 97x61 image's pixels uncovered, the first at (0, 20)",
    );
    // A part given twice.
    refused(d, &[&t[0], &t[1], &t[1], &t[2]], "t1.exr is given twice");
    // Overlapping parts.
    let over = render(d, "over.exr", &["--region", "0,10,97,10"]);
    refused(d, &[&t[0], &over, &t[1], &t[2]], "over.exr overlaps");
    // Another scene, another size, other samples: the scene of the others with one value
    // changed.
    for (name, from, to, needle) in [
        (
            "glass.exr",
            "quiz",
            "glass",
            "glass.exr was rendered with a different",
        ),
        (
            "taller.exr",
            "61",
            "62",
            "taller.exr is part of a 97x62 image",
        ),
        (
            "fewer.exr",
            "3",
            "2",
            "fewer.exr was rendered with a different samples",
        ),
    ] {
        assert_eq!(SCENE.iter().filter(|&&a| a == from).count(), 1, "{from}");
        let args: Vec<&str> = (SCENE.iter())
            .map(|&a| if a == from { to } else { a })
            .chain(["--tile", "1/3"])
            .collect();
        let part = d.join(name);
        rendered(&args, &part);
        refused(d, &[&t[0], &part, &t[2]], needle);
    }
    // Not a part at all, and a file that is not there.
    let plain = d.join("plain.exr");
    raytree::export::write_exr(&plain, &raytree::render::Image::new(4, 4)).expect("write");
    refused(d, &[&t[0], &plain], "plain.exr has no raytree stamp");
    refused(d, &[&t[0], &d.join("absent.exr")], "cannot read");
}

#[test]
fn a_region_outside_the_image_or_a_tile_out_of_range_is_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (args, needle) in [
        (
            ["--region", "90,0,8,10"],
            "the region 90,0,8,10 reaches outside the 97x61 image",
        ),
        (["--region", "0,0,0,10"], "the region 0,0,0,10 is empty"),
        (["--region", "1,2,3"], "expected X,Y,W,H"),
        (["--tile", "4/4"], "tile 4/4 does not exist"),
        (["--tile", "0/0"], "tile 0/0 does not exist"),
        (
            ["--tile", "0/62"],
            "cannot split the 61-row image into 62 tiles",
        ),
    ] {
        let out = dir.path().join("x.png");
        let args: Vec<&OsStr> = SCENE.iter().chain(&args).map(OsStr::new).collect();
        one_line_refusal(&run("render", &args, &out), &out, needle);
    }
}

#[test]
fn turntable_frames_are_numbered_and_turn_the_camera() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let spin = |name: &str, extra: &[&str]| {
        let base = ["default", "--width", "48", "--height", "32", "-q"];
        rendered(&[&base[..], extra].concat(), &d.join(name));
    };
    spin("spin.exr", &["--turntable", "4", "--frame-range", "1..3"]);
    spin("half_{frame}.exr", &["--turntable", "2", "--frame", "1"]);
    spin("still.exr", &[]);
    let names: Vec<String> = {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .expect("list")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    assert_eq!(
        names,
        [
            "half_0001.exr",
            "spin_0001.exr",
            "spin_0002.exr",
            "still.exr"
        ]
    );
    let f1 = read(&d.join("spin_0001.exr"));
    let f2 = read(&d.join("spin_0002.exr"));
    let half = read(&d.join("half_0001.exr"));
    let still = read(&d.join("still.exr"));
    assert_eq!(f2.get("raytree.frame"), Some("2/4"));
    // Frame 2 of 4 and frame 1 of 2 are the same half turn: the same image.
    assert!(linear(&f2) == linear(&half), "frame 2/4 equals frame 1/2");
    assert!(
        linear(&f1) != linear(&f2),
        "a quarter turn is not a half turn"
    );
    assert!(
        linear(&f2) != linear(&still),
        "a half turn moves the camera"
    );
    let lit = |i: &StampedImage| linear(i).iter().filter(|p| **p != [0; 3]).count();
    assert!(
        lit(&f1) > 100 && lit(&f2) > 100,
        "the turned frames show the scene"
    );
    assert_ne!(
        f2.get("raytree.scene_hash"),
        still.get("raytree.scene_hash"),
        "the camera is part of the scene's fingerprint"
    );
    // A frame past the turntable's end.
    let out = d.join("x.png");
    let args: Vec<&OsStr> = (SCENE.iter())
        .chain(&["--turntable", "4", "--frame", "4"])
        .map(OsStr::new)
        .collect();
    one_line_refusal(
        &run("render", &args, &out),
        &out,
        "--frame 4 does not exist",
    );
}

#[test]
fn a_grid_of_regions_merges_and_a_missing_corner_is_found() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let full = render(d, "full.exr", &[]);
    let grid = ["0,0,50,30", "50,0,47,30", "0,30,50,31", "50,30,47,31"];
    let parts: Vec<PathBuf> = grid
        .iter()
        .enumerate()
        .map(|(i, r)| render(d, &format!("g{i}.exr"), &["--region", r]))
        .collect();
    let all: Vec<&Path> = parts.iter().map(PathBuf::as_path).collect();
    let merged = merge(d, &all, "grid.exr");
    assert!(linear(&read(&merged)) == linear(&read(&full)));
    std::fs::remove_file(&merged).expect("remove");
    refused(
        d,
        &all[..3],
        "the parts leave 1457 of the 97x61 image's pixels uncovered, the first at (50, 30)",
    );
}
