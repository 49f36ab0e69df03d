//! The viewer's progressive render session, headless: the converged image equals the batch
//! render bit for bit, a restart in the middle of a pass never mixes generations, and a worker
//! that panics, or a render thread that cannot be spawned, is reported without stopping the
//! session.

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use raytree::render::session::{Pass, Session, SessionEvent, Step};
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

/// The coordinators' steps as a test sees them: every (generation, step) the session's step
/// hook reports, and a gate that holds each build at its start while it is closed.
struct Steps {
    reported: Receiver<(u64, Step)>,
    /// Steps received but not yet waited for.
    seen: RefCell<Vec<(u64, Step)>>,
    /// Closed (`true`): builds wait at [`Step::Building`].
    gate: Arc<(Mutex<bool>, Condvar)>,
}

impl Steps {
    /// Installs the step hook on `session` (for its next starts), the gate open.
    fn install(session: &mut Session) -> Steps {
        let (sender, reported) = channel();
        let sender = Mutex::new(sender);
        let gate = Arc::new((Mutex::new(false), Condvar::new()));
        let held = gate.clone();
        session.set_step_hook(Some(Arc::new(move |generation, step| {
            let _ = raytree::sync::lock(&sender).send((generation, step));
            if step == Step::Building {
                let (closed, opened) = &*held;
                // A minute at most: a call that waited for its own build then fails its
                // assertions instead of hanging.
                let closed = raytree::sync::lock(closed);
                let _ = opened.wait_timeout_while(closed, Duration::from_secs(60), |c| *c);
            }
        })));
        Steps {
            reported,
            seen: RefCell::new(Vec::new()),
            gate,
        }
    }

    /// Closes (`true`) or opens the gate for builds.
    fn hold(&self, closed: bool) {
        let (gate, opened) = &*self.gate;
        *raytree::sync::lock(gate) = closed;
        opened.notify_all();
    }

    /// Waits, up to two minutes, until `generation` has reported `step`.
    fn wait_for(&self, generation: u64, step: Step) {
        let deadline = Instant::now() + Duration::from_secs(120);
        while !self.seen.borrow().contains(&(generation, step)) {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.reported.recv_timeout(left) {
                Ok(reported) => self.seen.borrow_mut().push(reported),
                Err(_) => panic!("generation {generation} never reported {step:?}"),
            }
        }
    }
}

/// Nothing is waiting in `session`: no tracer to hand out, no event (checked once a
/// generation has reported [`Step::Done`], after which it can send nothing).
fn assert_nothing_waits(session: &Session, what: &str) {
    assert!(session.take_built().is_none(), "a tracer {what}");
    assert!(session.try_next().is_none(), "an event {what}");
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
    let steps = Steps::install(&mut session);
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
    // Once its coordinator is done, everything it sent is waiting.
    steps.wait_for(failed, Step::Done);
    while let Some(ev) = session.try_next() {
        match ev {
            SessionEvent::Tile(t) => assert_eq!(t.generation, failed),
            ev => panic!("after the failure: {ev:?}"),
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

/// A scene with a big mesh (a real BVH build, a good fraction of a second) at `w`×`h`.
fn big_scene(w: u32, h: u32) -> Arc<raytree::scene::Scene> {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = raytree::scene::procedural::write_bench_scene(dir.path(), 300_000).expect("write");
    let mut s = raytree::scene::load_scene_file(&path).expect("loads");
    s.render.width = w;
    s.render.height = h;
    Arc::new(s)
}

/// `start_build` returns without waiting for the build, which runs on the coordinator: with the
/// build held at its start, the call has returned and nothing is handed out; once let go, the
/// tracer is handed out once, before the generation's first event, and the render equals the
/// batch render of a tracer built on the caller's thread.
#[test]
fn a_build_off_the_caller_thread_is_handed_out_before_its_first_tile() {
    let scene = big_scene(48, 32);
    let mut session = Session::new(2).expect("pool");
    let steps = Steps::install(&mut session);
    steps.hold(true);
    let generation = session.start_build(scene.clone(), TraceSettings::default(), 1, None);
    // Returned, and the build has started on the coordinator, where it waits.
    steps.wait_for(generation, Step::Building);
    assert!(session.building_for().is_some(), "building is reported");
    assert!(
        session.take_built().is_none(),
        "a tracer while its build is held: start_build waited for the build"
    );
    assert!(session.try_next().is_none(), "an event before the build");
    steps.hold(false);
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

/// A second build (or a plain start, or a stop) while one is in flight (held at its start)
/// supersedes it: the older tracer is never handed out and none of its events arrive; the
/// newer one is.
#[test]
fn a_build_in_flight_is_superseded_and_its_result_never_appears() {
    let big = big_scene(48, 32);
    let small = tracer("default", 48, 32, 3);
    let mut session = Session::new(2).expect("pool");
    let steps = Steps::install(&mut session);
    steps.hold(true);
    let first = session.start_build(big.clone(), TraceSettings::default(), 1, None);
    steps.wait_for(first, Step::Building);
    let second = session.start_build(small.scene.clone(), TraceSettings::default(), 1, None);
    assert!(second > first);
    steps.hold(false);
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
    // The superseded build has run out: it handed nothing out and sent nothing that arrives.
    steps.wait_for(first, Step::Done);
    assert_nothing_waits(&session, "from a superseded build");
    // A plain start and a stop supersede a build too.
    steps.hold(true);
    let third = session.start_build(big.clone(), TraceSettings::default(), 1, None);
    steps.wait_for(third, Step::Building);
    let plain = session.start(small.clone(), 1, None);
    steps.hold(false);
    collect(&session, plain, 48, 32);
    steps.wait_for(third, Step::Done);
    assert_nothing_waits(&session, "from a build superseded by a plain start");
    steps.hold(true);
    let fourth = session.start_build(big, TraceSettings::default(), 1, None);
    steps.wait_for(fourth, Step::Building);
    session.stop();
    steps.hold(false);
    steps.wait_for(fourth, Step::Done);
    assert_nothing_waits(&session, "from a stopped build");
}
