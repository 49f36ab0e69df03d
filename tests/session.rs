//! The viewer's progressive render session, headless: the converged image equals the batch
//! render bit for bit, a restart in the middle of a pass never mixes generations, and a worker
//! that panics, or a render thread that cannot be spawned, is reported without stopping the
//! session.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::time::{Duration, Instant};

use raytree::render::session::{Pass, Session, SessionEvent};
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

/// A worker that panics on one tile (through the session's tile hook) is reported as
/// `Failed`, naming the tile and the panic; the generation stops (no further pass or finish);
/// nothing deadlocks; and the next start, after an edit, renders the whole image exactly as
/// the batch render does.
#[test]
fn panicking_worker_is_reported_and_the_next_start_renders() {
    let t = tracer("default", 96, 72, 5);
    let mut session = Session::new(2).expect("pool");
    let armed = Arc::new(AtomicBool::new(true));
    let calls = Arc::new(AtomicU32::new(0));
    {
        let (armed, calls) = (armed.clone(), calls.clone());
        session.set_tile_hook(Some(Arc::new(move |pass, rect| {
            calls.fetch_add(1, Ordering::Relaxed);
            // Once, in the second full pass: the first pass and the preview went through.
            if pass == Pass::Samples(2)
                && (rect.x, rect.y) == (32, 32)
                && armed.swap(false, Ordering::SeqCst)
            {
                panic!("injected fault");
            }
        })));
    }
    let failed = session.start(t.clone(), 6, None);
    let deadline = Instant::now() + Duration::from_secs(60);
    let mut passes = Vec::new();
    let message = loop {
        assert!(
            Instant::now() < deadline,
            "no Failed event: the session hangs"
        );
        let Some(ev) = session.try_next() else {
            std::thread::sleep(Duration::from_millis(2));
            continue;
        };
        assert_eq!(ev.generation(), failed, "{ev:?}");
        match ev {
            SessionEvent::Failed { message, .. } => break message,
            SessionEvent::PassDone { pass, .. } => passes.push(pass),
            SessionEvent::Finished { .. } => panic!("finished despite the panic"),
            SessionEvent::Tile(_) => {}
        }
    };
    assert!(!armed.load(Ordering::SeqCst), "the hook never fired");
    assert_eq!(
        message,
        "a render worker failed on the tile at (32, 32): injected fault"
    );
    assert_eq!(passes, vec![Pass::Preview, Pass::Samples(1)]);
    // The failed generation stops: tiles already traced may still arrive, but no pass ends.
    let quiet = Instant::now() + Duration::from_millis(300);
    while Instant::now() < quiet {
        match session.try_next() {
            Some(SessionEvent::Tile(t)) => assert_eq!(t.generation, failed),
            Some(ev) => panic!("after the failure: {ev:?}"),
            None => std::thread::sleep(Duration::from_millis(2)),
        }
    }
    // An edit restarts the render with the hook still installed (now harmless).
    let before = calls.load(Ordering::Relaxed);
    let edited = tracer("default", 96, 72, 3);
    let next = session.start(edited.clone(), 4, None);
    assert!(next > failed);
    let (img, passes) = collect(&session, next, 96, 72);
    assert_eq!(passes, vec![1, 2, 4]);
    assert!(
        calls.load(Ordering::Relaxed) > before,
        "the restart bypassed the hook"
    );
    let (batch, _) = render(&edited, 4, 1, &|_, _| {}).expect("render");
    assert!(
        img == batch,
        "the render after the failure differs from the batch render"
    );
}

/// A start whose thread cannot be spawned (the spawn hook stands in for a system out of
/// threads) is reported as that generation's `Failed` with the reason, instead of a render that
/// waits for tiles forever; the next start, with threads to spare, renders as the batch does.
#[test]
fn a_failed_thread_spawn_is_reported_and_the_next_start_renders() {
    let t = tracer("default", 64, 48, 3);
    let mut session = Session::new(2).expect("pool");
    session.set_spawn_hook(Some(Arc::new(|| {
        Err(std::io::Error::other("injected spawn failure"))
    })));
    let failed = session.start(t.clone(), 2, None);
    match session.try_next() {
        Some(SessionEvent::Failed {
            generation,
            message,
        }) => {
            assert_eq!(generation, failed);
            assert_eq!(
                message,
                "cannot start the render thread: injected spawn failure"
            );
        }
        other => panic!("expected Failed at once, got {other:?}"),
    }
    assert!(session.try_next().is_none(), "a failed start sent more");
    session.set_spawn_hook(None);
    let next = session.start(t.clone(), 2, None);
    assert!(next > failed);
    let (img, passes) = collect(&session, next, 64, 48);
    assert_eq!(passes, vec![1, 2]);
    let (batch, _) = render(&t, 2, 1, &|_, _| {}).expect("render");
    assert!(img == batch, "the render after the failure differs");
}

/// A scene with a big mesh (its BVH build takes a good fraction of a second) at `w`×`h`.
fn big_scene(w: u32, h: u32) -> Arc<raytree::scene::Scene> {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = raytree::scene::procedural::write_bench_scene(dir.path(), 300_000).expect("write");
    let mut s = raytree::scene::load_scene_file(&path).expect("loads");
    s.render.width = w;
    s.render.height = h;
    Arc::new(s)
}

/// `start_build` returns at once and builds on the coordinator: the tracer is handed out once,
/// before the generation's first event, and the render equals the batch render of a tracer
/// built on the caller's thread.
#[test]
fn a_build_off_the_caller_thread_is_handed_out_before_its_first_tile() {
    let scene = big_scene(48, 32);
    let mut session = Session::new(2).expect("pool");
    let t = Instant::now();
    let generation = session.start_build(scene.clone(), TraceSettings::default(), 1, None);
    let returned = t.elapsed();
    assert!(session.building_for().is_some(), "building is reported");
    let deadline = Instant::now() + Duration::from_secs(120);
    let built = loop {
        assert!(Instant::now() < deadline, "the build never ended");
        if let Some(t) = session.take_built() {
            break t;
        }
        assert!(
            session.try_next().is_none(),
            "an event before the tracer was handed out"
        );
        std::thread::sleep(Duration::from_millis(2));
    };
    // The build took longer than the call: the call did not wait for it.
    assert!(built.build_secs > returned.as_secs_f64(), "{returned:?}");
    assert!(session.take_built().is_none(), "handed out once");
    assert!(session.building_for().is_none());
    assert!(Arc::ptr_eq(&built.scene, &scene));
    let (img, _) = collect(&session, generation, 48, 32);
    let direct = Tracer::new(scene, TraceSettings::default());
    let (batch, _) = render(&direct, 1, 1, &|_, _| {}).expect("render");
    assert!(
        img == batch,
        "the built tracer renders as one built directly"
    );
}

/// A second build (or a plain start, or a stop) while one is in flight supersedes it: the older
/// tracer is never handed out and none of its events arrive; the newer one is.
#[test]
fn a_build_in_flight_is_superseded_and_its_result_never_appears() {
    let big = big_scene(48, 32);
    let small = tracer("default", 48, 32, 3);
    let mut session = Session::new(2).expect("pool");
    let first = session.start_build(big.clone(), TraceSettings::default(), 1, None);
    let second = session.start_build(small.scene.clone(), TraceSettings::default(), 1, None);
    assert!(second > first);
    let deadline = Instant::now() + Duration::from_secs(120);
    let built = loop {
        assert!(Instant::now() < deadline, "the second build never ended");
        if let Some(t) = session.take_built() {
            break t;
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    assert!(
        Arc::ptr_eq(&built.scene, &small.scene),
        "the newer scene's tracer"
    );
    collect(&session, second, 48, 32);
    // Let the superseded build run out: it hands nothing out and sends nothing that arrives.
    let quiet = Instant::now() + Duration::from_secs(3);
    while Instant::now() < quiet {
        assert!(
            session.take_built().is_none(),
            "a superseded tracer appeared"
        );
        assert!(session.try_next().is_none(), "an event after the finish");
        std::thread::sleep(Duration::from_millis(5));
    }
    // A plain start and a stop supersede a build too.
    session.start_build(big.clone(), TraceSettings::default(), 1, None);
    let plain = session.start(small.clone(), 1, None);
    collect(&session, plain, 48, 32);
    session.start_build(big, TraceSettings::default(), 1, None);
    session.stop();
    let quiet = Instant::now() + Duration::from_secs(3);
    while Instant::now() < quiet {
        assert!(session.take_built().is_none(), "a stopped build appeared");
        assert!(session.try_next().is_none(), "an event of a stopped build");
        std::thread::sleep(Duration::from_millis(5));
    }
}
