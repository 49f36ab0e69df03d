//! The viewer's progressive render session, headless: the converged image equals the batch
//! render bit for bit, and a restart in the middle of a pass never mixes generations.

use std::sync::Arc;
use std::time::{Duration, Instant};

use raytree::render::session::{Session, SessionEvent};
use raytree::render::{Image, render};
use raytree::scene::builtin::load_builtin;
use raytree::trace::{TraceSettings, Tracer};

fn tracer(name: &str, w: u32, h: u32, max_depth: u32) -> Arc<Tracer> {
    let mut s = load_builtin(name).expect("built-in scene");
    s.render.width = w;
    s.render.height = h;
    s.render.max_depth = max_depth;
    Arc::new(Tracer::new(Arc::new(s), TraceSettings::default()))
}

/// Collects tiles into an image until the generation finishes; checks every event's
/// generation on the way.
fn collect(session: &Session, generation: u64, w: u32, h: u32) -> (Image, Vec<u32>) {
    let mut img = Image::new(w, h);
    let mut passes = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        assert!(Instant::now() < deadline, "render did not finish");
        let Some(ev) = session.try_next() else {
            std::thread::sleep(Duration::from_millis(2));
            continue;
        };
        assert_eq!(
            ev.generation(),
            generation,
            "an event of another generation: {ev:?}"
        );
        match ev {
            SessionEvent::Tile(t) => {
                for j in 0..t.rect.height {
                    for i in 0..t.rect.width {
                        img.pixels[((t.rect.y + j) * w + t.rect.x + i) as usize] =
                            t.pixels[(j * t.rect.width + i) as usize];
                    }
                }
            }
            SessionEvent::PassDone { pass, .. } => {
                if let raytree::render::session::Pass::Samples(n) = pass {
                    passes.push(n);
                }
            }
            SessionEvent::Finished { .. } => return (img, passes),
            SessionEvent::Failed { message, .. } => panic!("{message}"),
        }
    }
}

#[test]
fn converged_progressive_image_equals_batch_render() {
    let t = tracer("default", 96, 72, 5);
    let mut session = Session::new(2).expect("pool");
    let generation = session.start(t.clone(), 6, None);
    let (img, passes) = collect(&session, generation, 96, 72);
    assert_eq!(passes, vec![1, 2, 4, 6]);
    let (batch, _) = render(&t, 6, 1, &|_, _| {}).expect("render");
    let differing = img
        .pixels
        .iter()
        .zip(&batch.pixels)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(differing, 0, "progressive and batch renders differ");
}

#[test]
fn restart_mid_pass_never_mixes_generations() {
    // A slow first generation (glass, deep, many samples) is replaced after its first tiles.
    let slow = tracer("glass", 200, 150, 12);
    let mut session = Session::new(2).expect("pool");
    let first = session.start(slow, 256, None);
    let deadline = Instant::now() + Duration::from_secs(60);
    let mut seen_first = 0;
    while seen_first < 3 {
        assert!(Instant::now() < deadline);
        match session.try_next() {
            Some(ev) => {
                assert_eq!(ev.generation(), first);
                seen_first += 1;
            }
            None => std::thread::sleep(Duration::from_millis(1)),
        }
    }
    let fast = tracer("glass", 200, 150, 0);
    let second = session.start(fast.clone(), 2, None);
    assert!(second > first);
    let (img, _) = collect(&session, second, 200, 150);
    let (batch, _) = render(&fast, 2, 0, &|_, _| {}).expect("render");
    assert!(
        img == batch,
        "the second generation's image holds foreign pixels"
    );
}
