//! Whole renders of the built-in scenes: accelerators give the identical image, the thread
//! count never changes a bit, the clicked-pixel tree equals the render, and golden images.
//!
//! Regenerate the golden images (after a deliberate change, looking at them first) with:
//! `RAYTREE_BLESS=1 cargo test --release --test render golden`

use std::path::PathBuf;
use std::sync::Arc;

use raytree::accel::AccelKind;
use raytree::export::srgb8_bytes;
use raytree::ray_tree::pixel_tree;
use raytree::render::{Image, render};
use raytree::scene::Scene;
use raytree::scene::builtin::{NAMES, load_builtin};
use raytree::trace::{TraceSettings, Tracer};

fn scene(name: &str, width: u32, height: u32) -> Scene {
    let mut s = load_builtin(name).unwrap_or_else(|e| panic!("built-in {name}: {e}"));
    s.render.width = width;
    s.render.height = height;
    s
}

fn render_with(scene: &Scene, accel: AccelKind, samples: u32, threads: usize) -> Image {
    let tracer = Tracer::new(
        Arc::new(scene.clone()),
        TraceSettings {
            accel,
            ..TraceSettings::default()
        },
    );
    render(&tracer, samples, threads, &|_, _| {})
        .expect("render")
        .0
}

#[test]
fn accelerators_give_the_identical_image() {
    for name in NAMES {
        let s = scene(name, 160, 120);
        let reference = render_with(&s, AccelKind::None, 1, 0);
        for accel in [AccelKind::Grid, AccelKind::Bvh, AccelKind::Auto] {
            let img = render_with(&s, accel, 1, 0);
            let differing = img
                .pixels
                .iter()
                .zip(&reference.pixels)
                .filter(|(a, b)| a != b)
                .count();
            assert_eq!(differing, 0, "{name}: {accel:?} differs from none");
        }
    }
}

#[test]
fn thread_count_never_changes_a_bit() {
    let s = scene("default", 96, 64);
    let one = render_with(&s, AccelKind::Bvh, 3, 1);
    for threads in [2, 8] {
        assert!(
            render_with(&s, AccelKind::Bvh, 3, threads) == one,
            "{threads} threads differ from 1"
        );
    }
}

#[test]
fn clicked_tree_colour_equals_the_render() {
    for name in NAMES {
        let s = scene(name, 64, 48);
        let tracer = Tracer::new(Arc::new(s.clone()), TraceSettings::default());
        let (image, _) = render(&tracer, 1, 0, &|_, _| {}).expect("render");
        for y in (0..48).step_by(3) {
            for x in (0..64).step_by(3) {
                let tree = pixel_tree(&tracer, x, y).expect("pixel inside");
                assert_eq!(tree.color, image.get(x, y), "{name} pixel ({x}, {y})");
                assert_eq!(tree.root.color, tree.color);
            }
        }
    }
}

fn golden_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.png"))
}

fn read_png(path: &PathBuf) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; regenerate with RAYTREE_BLESS=1 cargo test --release --test render golden",
            path.display()
        )
    });
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("golden PNG header");
    let mut buf = vec![0; reader.output_buffer_size().expect("size")];
    let info = reader.next_frame(&mut buf).expect("golden PNG data");
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// Golden images at 320×240, 4 samples. Tolerance: a channel may differ by at most 2/255 on
/// 99.5% of pixels and by any amount on the rest (different libm `powf`/`sqrt` rounding can
/// flip a shadow-edge pixel), and the mean absolute difference stays below 0.25/255.
#[test]
fn golden_images() {
    let bless = std::env::var_os("RAYTREE_BLESS").is_some();
    for name in NAMES {
        let s = scene(name, 320, 240);
        let img = render_with(&s, AccelKind::Auto, 4, 0);
        let path = golden_path(name);
        if bless {
            std::fs::create_dir_all(path.parent().expect("folder")).expect("mkdir");
            raytree::export::write_png(&path, &img, &[]).expect("write golden");
            continue;
        }
        let (w, h, want) = read_png(&path);
        assert_eq!((w, h), (img.width, img.height), "{name}: size");
        let got = srgb8_bytes(&img);
        let mut off_pixels = 0;
        let mut total_diff = 0u64;
        for (a, b) in got.chunks(3).zip(want.chunks(3)) {
            let d = a
                .iter()
                .zip(b)
                .map(|(x, y)| x.abs_diff(*y))
                .max()
                .unwrap_or(0);
            total_diff += a
                .iter()
                .zip(b)
                .map(|(x, y)| x.abs_diff(*y) as u64)
                .sum::<u64>();
            if d > 2 {
                off_pixels += 1;
            }
        }
        let n = (w * h) as f64;
        let mean = total_diff as f64 / (3.0 * n);
        if off_pixels as f64 > 0.005 * n || mean > 0.25 {
            let new = path.with_extension("new.png");
            raytree::export::write_png(&new, &img, &[]).expect("write new");
            panic!(
                "{name}: {off_pixels} pixels off by more than 2/255, mean difference {mean:.3}/255; \
                 see {}; regenerate with RAYTREE_BLESS=1 cargo test --release --test render golden",
                new.display()
            );
        }
    }
}
