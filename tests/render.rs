//! Whole renders of the built-in scenes: accelerators give the identical image, the thread
//! count never changes a bit, the clicked-pixel tree equals the render, and golden images.
//!
//! Regenerate the golden images (after a deliberate change, looking at them first) with:
//! `RAYTREE_BLESS=1 cargo test --release --test render golden`

use std::sync::Arc;

mod golden_support;

use golden_support::{golden_path, mismatch, read_png};
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

/// A tracer keeps its sums buffer from one batch render to the next: each render must start
/// from zero sums, whether the kept buffer is larger (a region after the full image) or the
/// same size, so the same tracer gives the same pixels every time.
#[test]
fn repeated_renders_on_one_tracer_give_the_same_pixels() {
    let s = scene("default", 96, 64);
    let tracer = Tracer::new(Arc::new(s), TraceSettings::default());
    let first = render(&tracer, 2, 2, &|_, _| {}).expect("render").0;
    assert!(
        first.pixels.iter().any(|p| p.max_element() > 0.05),
        "a dark image"
    );
    let region = raytree::render::Rect {
        x: 10,
        y: 7,
        width: 40,
        height: 30,
    };
    let part = raytree::render::region::render_region(&tracer, region, 2, 2, &|_, _| {})
        .expect("region")
        .0;
    for y in 0..region.height {
        for x in 0..region.width {
            let whole = first.pixels[((region.y + y) * 96 + region.x + x) as usize];
            assert_eq!(
                part.pixels[(y * region.width + x) as usize],
                whole,
                "({x}, {y})"
            );
        }
    }
    for _ in 0..2 {
        let again = render(&tracer, 2, 2, &|_, _| {}).expect("render").0;
        assert!(again == first, "a repeated render differs from the first");
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

/// Golden images at 320×240, 4 samples, within [`golden_support::mismatch`]'s tolerance.
const REGENERATE: &str = "RAYTREE_BLESS=1 cargo test --release --test render golden";

#[test]
fn golden_images() {
    let bless = std::env::var_os("RAYTREE_BLESS").is_some();
    for name in NAMES {
        let s = scene(name, 320, 240);
        let img = render_with(&s, AccelKind::Auto, 4, 0);
        let path = golden_path(&format!("{name}.png"));
        if bless {
            std::fs::create_dir_all(path.parent().expect("folder")).expect("mkdir");
            raytree::export::write_png(&path, &img, &[]).expect("write golden");
            continue;
        }
        let (w, h, want) = read_png(&path, png::ColorType::Rgb, REGENERATE);
        assert_eq!((w, h), (img.width, img.height), "{name}: size");
        if let Some(why) = mismatch(&srgb8_bytes(&img), &want, 3) {
            let new = path.with_extension("new.png");
            raytree::export::write_png(&new, &img, &[]).expect("write new");
            panic!(
                "{name}: {why}; see {}; regenerate with {REGENERATE}",
                new.display()
            );
        }
    }
}
