//! Lessons: every shipped lesson is solvable on its scene; each kind of task takes a right and
//! a wrong answer through the same `evaluate` the viewer calls, and through the command line
//! with its exit codes; the quiz lesson checks the lecture's quiz numbers; a broken lesson file
//! is one sentence naming its file, line and key; the pseudocode follows a real tree.

use assert_cmd::Command;
use raytree::lessons::pseudocode::{self, LINES};
use raytree::lessons::{
    self, Answer, Event, Goal, Lesson, SHIPPED, TaskKind, Verdict, check_lesson,
};
use raytree::ray_tree::{self, Node, RayTree};
use raytree::scene;
use raytree::trace::{RayKind, TraceSettings, Tracer};

fn raytree() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytree"))
}

fn shipped(name: &str) -> Lesson {
    Lesson::shipped(name)
        .expect("a shipped lesson")
        .expect("it parses")
}

/// The verdict of `answer` to step `step` of the shipped lesson `name`.
fn answer(name: &str, step: usize, answer: Answer) -> Verdict {
    let lesson = shipped(name);
    let scene = lesson.load_scene().expect("the scene loads");
    let step = lesson.step(step).expect("the step exists");
    lessons::evaluate(step, &answer, &scene, &TraceSettings::default()).expect("evaluable")
}

fn assert_right(v: &Verdict) {
    assert!(v.correct, "{v:?}");
    assert!(v.message.starts_with("Right"), "{}", v.message);
    assert_eq!(v.hint, None);
}

/// A wrong verdict carries the step's hint (the text in the file) and, where a tree is read,
/// the node that shows why.
fn assert_wrong(v: &Verdict, lesson: &str, step: usize) {
    assert!(!v.correct, "{v:?}");
    let l = shipped(lesson);
    let hint = &l
        .step(step)
        .and_then(|s| s.task.as_ref())
        .expect("a task")
        .hint;
    assert_eq!(v.hint.as_ref(), Some(hint));
    assert!(!v.message.is_empty());
}

#[test]
fn every_shipped_lesson_passes_check() {
    assert!(SHIPPED.len() >= 8, "at least eight lessons");
    for (name, _) in SHIPPED {
        let lesson = shipped(name);
        let report = check_lesson(&lesson);
        assert!(report.problems.is_empty(), "{name}: {:?}", report.problems);
        let tasks = lesson.steps.iter().filter(|s| s.task.is_some()).count();
        assert!(tasks > 0, "{name} has tasks");
        assert_eq!(report.answers.len(), tasks, "{name}: {:?}", report.answers);
    }
    // Each shipped file is the compiled-in text, so the files on disk check the same.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/lessons");
    for (name, text) in SHIPPED {
        let on_disk = std::fs::read_to_string(dir.join(format!("{name}.toml"))).expect("file");
        assert_eq!(&on_disk, text);
    }
}

#[test]
fn shipped_lessons_cover_the_lecture_in_order() {
    let names: Vec<&str> = SHIPPED.iter().map(|(n, _)| *n).collect();
    let order = [
        "eye-rays",
        "primary-rays",
        "shadows",
        "reflection",
        "refraction",
        "total-internal-reflection",
        "termination",
        "tree",
        "quiz",
        "speed-accuracy",
    ];
    assert_eq!(names, order);
    // Every kind of task appears.
    let mut kinds = std::collections::BTreeSet::new();
    for (name, _) in SHIPPED {
        for s in shipped(name).steps {
            if let Some(t) = s.task {
                kinds.insert(t.kind.name());
            }
        }
    }
    assert_eq!(
        kinds.into_iter().collect::<Vec<_>>(),
        ["choice", "control", "pixel", "value"]
    );
}

#[test]
fn pixel_task_right_and_wrong() {
    // shadows step 1: a floor pixel with a blocked shadow ray. (380, 300) lies behind the
    // mirror sphere as the fill light sees it; (100, 100) is sky.
    let right = answer("shadows", 1, Answer::Pixel([380, 300]));
    assert_right(&right);
    assert_eq!(right.pixel, Some([380, 300]));
    assert_eq!(right.node.as_deref(), Some("primary"));
    let wrong = answer("shadows", 1, Answer::Pixel([100, 100]));
    assert_wrong(&wrong, "shadows", 1);
    assert!(
        wrong.message.contains("has no blocked shadow ray"),
        "{}",
        wrong.message
    );
    assert!(wrong.message.contains("meets nothing"), "{}", wrong.message);
    assert_eq!(wrong.node_path, Some(vec![]));
}

#[test]
fn pixel_task_points_at_the_tree_part() {
    // total-internal-reflection step 1 on a floor pixel: no TIR; the pointer is a node of the
    // tree that pixel has.
    let lesson = shipped("total-internal-reflection");
    let scene = lesson.load_scene().expect("scene");
    let step = lesson.step(1).expect("step");
    let v = lessons::evaluate(
        step,
        &Answer::Pixel([430, 240]),
        &scene,
        &Default::default(),
    )
    .expect("evaluable");
    assert_right(&v);
    // The TIR is at primary/T: the child of index 1 (R first, then T).
    assert_eq!(v.node.as_deref(), Some("primary/T"));
    assert_eq!(v.node_path, Some(vec![1]));
    let tree = lessons::step_tree(step, &scene, &Default::default(), [430, 240]).expect("tree");
    assert!(tree.root.children[1].total_internal_reflection);
}

#[test]
fn control_task_right_and_wrong() {
    // termination step 5: the floor through the glass at (230, 230) needs the ray that leaves
    // the sphere, depth 2.
    assert_right(&answer("termination", 5, Answer::Value(2.0)));
    assert_right(&answer("termination", 5, Answer::Value(7.0)));
    let wrong = answer("termination", 5, Answer::Value(1.0));
    assert_wrong(&wrong, "termination", 5);
    assert!(
        wrong.message.starts_with("With max_depth = 1"),
        "{}",
        wrong.message
    );
    // Not a depth at all: wrong, with the reason.
    let bad = answer("termination", 5, Answer::Value(2.5));
    assert!(!bad.correct);
    assert!(bad.message.contains("whole number"), "{}", bad.message);
    // The material controls: kt = 0 makes the glass opaque, kt = 0.5 does not.
    assert_right(&answer("refraction", 5, Answer::Value(0.0)));
    assert_wrong(
        &answer("refraction", 5, Answer::Value(0.5)),
        "refraction",
        5,
    );
    // A lower ior lifts the critical angle above the prism's 45°.
    assert_right(&answer("total-internal-reflection", 4, Answer::Value(1.3)));
    assert_wrong(
        &answer("total-internal-reflection", 4, Answer::Value(1.5)),
        "total-internal-reflection",
        4,
    );
    // The named control: the offset method.
    assert_right(&answer(
        "speed-accuracy",
        2,
        Answer::Choice("error-bound".into()),
    ));
    assert_wrong(
        &answer("speed-accuracy", 2, Answer::Choice("fixed".into())),
        "speed-accuracy",
        2,
    );
}

#[test]
fn value_task_right_and_wrong() {
    // refraction step 3: θr by Snell from the tree's own θi and ior 1.5.
    let lesson = shipped("refraction");
    let scene = lesson.load_scene().expect("scene");
    let tree = lessons::step_tree(
        lesson.step(3).expect("step"),
        &scene,
        &Default::default(),
        [240, 300],
    )
    .expect("tree");
    let n = tree.root.hit.as_ref().expect("hit").normal;
    let cos_i = f64::from(-tree.root.direction.dot(n));
    let sin_r = (1.0 - cos_i * cos_i).sqrt() / 1.5;
    let theta_r = sin_r.asin().to_degrees();
    assert_right(&answer("refraction", 3, Answer::Value(theta_r)));
    // θi itself is the classic mistake.
    let theta_i = cos_i.acos().to_degrees();
    assert!(theta_i - theta_r > 2.0);
    let wrong = answer("refraction", 3, Answer::Value(theta_i));
    assert_wrong(&wrong, "refraction", 3);
    assert!(wrong.message.contains("Snell"), "{}", wrong.message);
    assert_eq!(wrong.node.as_deref(), Some("primary"));
}

#[test]
fn quiz_lessons_check_the_lecture_quiz_numbers() {
    let s2 = std::f64::consts::FRAC_1_SQRT_2;
    // Quiz 2: s = 1; quiz 3: barycentric (1/4, 1/4, 1/2).
    assert_right(&answer("primary-rays", 3, Answer::Value(1.0)));
    assert_right(&answer("primary-rays", 4, Answer::Value(0.5)));
    assert_wrong(
        &answer("primary-rays", 4, Answer::Value(0.25)),
        "primary-rays",
        4,
    );
    // Quiz 1: N = (0, 0, 1) is option b.
    assert_right(&answer("primary-rays", 2, Answer::Choice("b".into())));
    assert_wrong(
        &answer("primary-rays", 2, Answer::Choice("c".into())),
        "primary-rays",
        2,
    );
    // Quiz 4: L = (1/√2, 0, 1/√2), so N·L = 1/√2; the diffuse half of I is 1/2.
    assert_right(&answer("quiz", 1, Answer::Value(s2)));
    assert_wrong(&answer("quiz", 1, Answer::Value(1.0)), "quiz", 1);
    assert_right(&answer("quiz", 2, Answer::Value(0.5)));
    // With the tree's V = (0, 0, 1): H = normalize(L + V), N·H = (1 + 1/√2) / |L + V|, and
    // I = (1/√2)(N·L) + (1/√2)(N·H); the quiz's I = 1 (its V lies in the plane) is wrong here.
    let n_dot_h = (1.0 + s2) / (0.5 + (1.0 + s2) * (1.0 + s2)).sqrt();
    assert_right(&answer("quiz", 3, Answer::Value(n_dot_h)));
    assert_right(&answer("quiz", 5, Answer::Value(0.5 + s2 * n_dot_h)));
    assert_wrong(&answer("quiz", 5, Answer::Value(1.0)), "quiz", 5);
}

#[test]
fn choice_task_right_and_wrong() {
    // termination: the sky ends with no intersection, the fill light as a light source, and
    // at max_depth 1 the ray primary/T/T is past the maximum depth.
    assert_right(&answer("termination", 1, Answer::Choice("missed".into())));
    assert_right(&answer("termination", 1, Answer::Choice("A".into())));
    let wrong = answer("termination", 1, Answer::Choice("light".into()));
    assert_wrong(&wrong, "termination", 1);
    assert_eq!(wrong.node.as_deref(), Some("primary"));
    assert_right(&answer("termination", 2, Answer::Choice("light".into())));
    assert_right(&answer(
        "termination",
        3,
        Answer::Choice("max_depth".into()),
    ));
    assert_wrong(
        &answer("termination", 3, Answer::Choice("surface".into())),
        "termination",
        3,
    );
    // The right option comes from the tree: the shadow ray to fill is blocked, to key lit.
    assert_right(&answer("shadows", 2, Answer::Choice("blocked".into())));
    assert_right(&answer("shadows", 3, Answer::Choice("lit".into())));
    // A written answer, for what a tree cannot say.
    assert_right(&answer("eye-rays", 2, Answer::Choice("b".into())));
    assert_wrong(
        &answer("eye-rays", 2, Answer::Choice("a".into())),
        "eye-rays",
        2,
    );
}

#[test]
fn answers_of_the_wrong_kind_are_not_evaluated() {
    let lesson = shipped("termination");
    let scene = lesson.load_scene().expect("scene");
    let step = lesson.step(1).expect("step");
    let e = lessons::evaluate(step, &Answer::Value(1.0), &scene, &Default::default())
        .expect_err("a number for a choice");
    assert!(e.0.contains("choice task"), "{e}");
    let e = lessons::evaluate(
        step,
        &Answer::Choice("x".into()),
        &scene,
        &Default::default(),
    )
    .expect_err("no such option");
    assert!(e.0.contains("none of the options"), "{e}");
}

/// Writes `text` as a lesson file and returns the parse error.
fn parse_error(text: &str) -> String {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, text).expect("write");
    let e = Lesson::load(&path).expect_err("a broken lesson");
    let msg = e.0;
    assert_eq!(msg.lines().count(), 1, "one line: {msg}");
    assert!(msg.ends_with('.'), "a sentence: {msg}");
    assert!(msg.contains("bad.toml:"), "names the file: {msg}");
    msg
}

const GOOD_HEAD: &str =
    "title = \"t\"\nscene = \"quiz\"\nintro = \"i\"\n\n[[step]]\ntext = \"a\"\n";

#[test]
fn malformed_lessons_give_one_sentence_naming_file_line_and_key() {
    let msg = parse_error(&format!("{GOOD_HEAD}max_depth = \"deep\"\n"));
    assert!(msg.contains("bad.toml:7:"), "{msg}");
    assert!(
        msg.contains("step 1 field `max_depth` must be a whole number"),
        "{msg}"
    );

    let msg = parse_error(&format!("{GOOD_HEAD}slect = [1, 2]\n"));
    assert!(msg.contains(":7:1:"), "{msg}");
    assert!(
        msg.contains("unknown field `slect` (did you mean `select`?)"),
        "{msg}"
    );

    let msg = parse_error(&format!(
        "{GOOD_HEAD}\n[step.task]\nkind = \"pixel\"\nevent = \"tir\"\nhint = \"h\"\n"
    ));
    assert!(msg.contains(":10:"), "{msg}");
    assert!(msg.contains("field `event`"), "{msg}");
    assert!(msg.contains("\"total_internal_reflection\""), "{msg}");

    let msg = parse_error(&format!(
        "{GOOD_HEAD}\n[step.task]\nkind = \"value\"\nquantity = \"local\"\npixel = [1, 1]\n"
    ));
    assert!(msg.contains(":8:"), "{msg}");
    assert!(msg.contains("missing the field `hint`"), "{msg}");

    let msg = parse_error(&format!(
        "{GOOD_HEAD}\n[step.task]\nkind = \"choice\"\nquestion = \"end\"\nnode = \"primary/X\"\npixel = [1, 1]\nhint = \"h\"\n"
    ));
    assert!(msg.contains(":11:"), "{msg}");
    assert!(msg.contains("field `node`"), "{msg}");

    let msg =
        parse_error("title = \"t\"\nscene = \"quizz\"\nintro = \"i\"\n[[step]]\ntext = \"a\"\n");
    assert!(msg.contains(":2:"), "{msg}");
    assert!(msg.contains("field `scene`"), "{msg}");
    assert!(msg.contains("did you mean \"quiz\"?"), "{msg}");

    let msg = parse_error("title = \"t\"\nscene = \"quiz\"\nintro = \"i\"\n");
    assert!(msg.contains(":1:1:"), "{msg}");
    assert!(msg.contains("missing the field `step`"), "{msg}");

    let msg = parse_error("title = \"t\"\nscene = \"quiz\"\nintro = \"i\n");
    assert!(msg.contains("TOML syntax error"), "{msg}");
}

#[test]
fn a_lesson_file_with_a_relative_scene_path_loads_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::create_dir(dir.path().join("scenes")).expect("dir");
    let quiz = scene::builtin::scene_text("quiz").expect("quiz text");
    std::fs::write(dir.path().join("scenes/mine.toml"), quiz).expect("write");
    let path = dir.path().join("mine.toml");
    std::fs::write(
        &path,
        "title = \"Mine\"\nscene = \"scenes/mine.toml\"\nintro = \"A teacher's lesson.\"\n\n[[step]]\ntext = \"Click the triangle.\"\n\n[step.task]\nkind = \"pixel\"\nevent = \"hit\"\nobject = \"A1A2A3\"\nhint = \"The middle.\"\n",
    )
    .expect("write");
    let lesson = Lesson::load(&path).expect("loads");
    assert_eq!(lesson.name, "mine");
    assert_eq!(lesson.summary, "A teacher's lesson.");
    let report = check_lesson(&lesson);
    assert!(report.problems.is_empty(), "{:?}", report.problems);
    // An impossible task is a problem `check` names.
    std::fs::write(
        &path,
        "title = \"Mine\"\nscene = \"scenes/mine.toml\"\nintro = \"i\"\n\n[[step]]\ntext = \"t\"\n\n[step.task]\nkind = \"pixel\"\nevent = \"total_internal_reflection\"\nhint = \"h\"\n",
    )
    .expect("write");
    let report = check_lesson(&Lesson::load(&path).expect("loads"));
    assert_eq!(report.problems.len(), 1, "{:?}", report.problems);
    assert!(
        report.problems[0]
            .contains("step 1: no pixel of the 201x201 image has a total internal reflection"),
        "{:?}",
        report.problems
    );
}

#[test]
fn cli_lists_checks_and_answers_with_exit_codes() {
    let out = raytree().arg("lessons").output().expect("runs");
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.lines().count(), SHIPPED.len(), "{text}");
    assert!(text.lines().next().expect("a line").starts_with("eye-rays"));

    let names: Vec<&str> = SHIPPED.iter().map(|(n, _)| *n).collect();
    let out = raytree()
        .args(["lesson", "check"])
        .args(&names)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("shadows: step 1: "), "{text}");
    assert!(text.contains("quiz: good"), "{text}");

    // Right: 0, the message on stdout.
    let out = raytree()
        .args(["lesson", "answer", "quiz", "2", "--value", "0.5"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("Right"));
    // Wrong: 1, with the hint and the node.
    let out = raytree()
        .args(["lesson", "answer", "shadows", "1", "--pixel", "100,100"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("hint: Look on the floor"), "{text}");
    assert!(
        text.contains("see: node primary of the tree of pixel (100, 100)"),
        "{text}"
    );
    let out = raytree()
        .args([
            "lesson",
            "answer",
            "termination",
            "3",
            "--choice",
            "surface",
        ])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    let out = raytree()
        .args(["lesson", "answer", "termination", "5", "--value", "3"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(0));
    // Not evaluable: 2, one line on stderr.
    for args in [
        &["lesson", "answer", "quiz", "9", "--value", "1"][..],
        &["lesson", "answer", "quiz", "1", "--pixel", "1,1"],
        &["lesson", "answer", "no-such-lesson", "1", "--value", "1"],
        &["lesson", "answer", "shadows", "1", "--pixel", "999,1"],
    ] {
        let out = raytree().args(args).output().expect("runs");
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("error: "), "{err}");
    }
    // Two answers at once: a usage error.
    let out = raytree()
        .args([
            "lesson", "answer", "quiz", "1", "--value", "1", "--choice", "a",
        ])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));

    // A broken file: check exits 1 with one sentence.
    let dir = tempfile::tempdir().expect("temp dir");
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, format!("{GOOD_HEAD}view = \"diagramm\"\n")).expect("write");
    let out = raytree()
        .args(["lesson", "check"])
        .arg(&bad)
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("bad.toml:7:"), "{err}");
    assert!(err.contains("did you mean \"diagram\"?"), "{err}");
}

fn node_at<'a>(root: &'a Node, path: &[usize]) -> &'a Node {
    path.iter().fold(root, |n, &i| &n.children[i])
}

fn ids(lines: &[pseudocode::Executed]) -> Vec<&'static str> {
    lines.iter().map(|e| e.line).collect()
}

#[test]
fn pseudocode_follows_the_quiz_tree() {
    assert!(LINES.iter().all(|l| !l.text.is_empty()));
    let tracer = Tracer::new(
        std::sync::Arc::new(scene::load_builtin("quiz").expect("quiz")),
        TraceSettings::default(),
    );
    let tree = ray_tree::pixel_tree(&tracer, 100, 100).expect("tree");
    let walk = pseudocode::walk(&tree);
    assert_eq!(
        ids(&walk),
        [
            "signature",
            "max_depth",
            "intersect",
            "light",
            "no_hit",
            "normal",
            "reflect_dir",
            "refract_dir",
            "local",
            "shadow",
            "trace_r",
            "trace_t",
            "return"
        ]
    );
    assert!(walk.iter().all(|e| e.depth == 0 && e.node.is_empty()));
    let var = |line: &str, name: &str| {
        walk.iter()
            .find(|e| e.line == line)
            .and_then(|e| e.vars.iter().find(|(n, _)| *n == name))
            .map(|(_, v)| v.clone())
            .unwrap_or_default()
    };
    assert_eq!(var("signature", "step"), "0");
    assert_eq!(var("intersect", "q"), "(0.0000, 0.0000, -1.0000)");
    assert_eq!(var("normal", "n"), "(0.0000, 0.0000, 1.0000)");
    assert_eq!(var("shadow", "N·L"), "0.7071");
    assert_eq!(var("shadow", "shadow"), "lit");
    assert_eq!(var("trace_r", "reflected"), "not traced (kr = 0)");
    let local = walk
        .iter()
        .find(|e| e.line == "local")
        .and_then(|e| e.sum)
        .expect("sum");
    assert_eq!(local, tree.root.local.expect("local").total);
    let last = walk.last().expect("lines");
    assert!(last.returns);
    assert_eq!(last.sum, Some(tree.color));
    assert_eq!(
        pseudocode::current_line(&tree, &[]).map(|e| e.line),
        Some("return")
    );
}

/// Whether the tree has a node with R and T children, a total internal reflection and a
/// blocked shadow ray.
fn rich(tree: &RayTree) -> bool {
    fn any(n: &Node, f: &dyn Fn(&Node) -> bool) -> bool {
        f(n) || n.children.iter().any(|c| any(c, f))
    }
    let both = |n: &Node| {
        n.children.iter().any(|c| c.kind == RayKind::Reflected)
            && n.children.iter().any(|c| c.kind == RayKind::Refracted)
    };
    any(&tree.root, &both)
        && any(&tree.root, &|n| n.total_internal_reflection)
        && any(&tree.root, &|n| {
            n.shadow_rays.iter().any(|s| s.blocked_by.is_some())
        })
}

#[test]
fn pseudocode_follows_a_tree_with_r_t_tir_and_a_blocked_shadow_ray() {
    let tracer = Tracer::new(
        std::sync::Arc::new(scene::load_builtin("glass").expect("glass")),
        TraceSettings::default(),
    );
    // The lessons' own search finds a pixel with a total internal reflection; a few rows of
    // the prism then give one with everything.
    let goal = Goal {
        event: Event::TotalInternalReflection,
        object: Some("prism".into()),
        ray: None,
        present: true,
    };
    assert!(lessons::search_pixel(&goal, &tracer).is_some());
    let tree = (200..300)
        .step_by(7)
        .flat_map(|y| (380..620).step_by(7).map(move |x| (x, y)))
        .filter_map(|(x, y)| ray_tree::pixel_tree(&tracer, x, y))
        .find(rich)
        .expect("a pixel with R, T, TIR and a blocked shadow ray");
    let walk = pseudocode::walk(&tree);
    // One call per node, each starting at the signature and returning once.
    let calls = walk.iter().filter(|e| e.line == "signature").count();
    assert_eq!(calls, tree.nodes);
    assert_eq!(walk.iter().filter(|e| e.returns).count(), tree.nodes);
    let mut seen_tir = false;
    let mut seen_blocked = false;
    let mut seen_both = false;
    for (i, e) in walk.iter().enumerate() {
        let node = node_at(&tree.root, &e.node);
        assert_eq!(e.depth, node.depth);
        match e.line {
            "refract_dir" if node.total_internal_reflection => {
                seen_tir = true;
                assert!(
                    e.vars
                        .iter()
                        .any(|(_, v)| v.contains("total internal reflection"))
                );
                let t = walk[i..]
                    .iter()
                    .find(|x| x.node == e.node && x.line == "trace_t")
                    .expect("its trace_t line");
                assert!(t.vars.iter().any(|(_, v)| v.contains("kt went to kr")));
            }
            "shadow" if e.vars.iter().any(|(_, v)| v.starts_with("blocked by")) => {
                seen_blocked = true;
            }
            "trace_t" if node.children.len() == 2 => {
                seen_both = true;
                // The sum so far: local + kr·R + kt·T, the node's colour.
                let kr = node.kr.expect("kr");
                let kt = node.kt.expect("kt");
                let sum = node.local.expect("local").total
                    + kr * node.children[0].color
                    + kt * node.children[1].color;
                assert!((e.sum.expect("sum") - sum).abs().max_element() < 1e-6);
                assert!((sum - node.color).abs().max_element() < 1e-5);
                // The child T's call ran just before this line and ended in its return.
                let child = walk[..i].iter().rev().find(|x| x.returns).expect("child");
                let mut path = e.node.clone();
                path.push(1);
                assert_eq!(child.node, path);
            }
            "return" => assert_eq!(e.sum, Some(node.color)),
            _ => {}
        }
    }
    assert!(seen_tir && seen_blocked && seen_both);
    // The highlighted line of a node past the maximum depth is its termination test.
    let mut cut = tree.clone();
    fn first_max_depth(n: &Node, path: &mut Vec<usize>) -> bool {
        if n.end == Some(raytree::trace::EndReason::MaxDepth) {
            return true;
        }
        for (i, c) in n.children.iter().enumerate() {
            path.push(i);
            if first_max_depth(c, path) {
                return true;
            }
            path.pop();
        }
        false
    }
    let mut path = Vec::new();
    if first_max_depth(&cut.root, &mut path) {
        let e = pseudocode::current_line(&cut, &path).expect("line");
        assert_eq!(e.line, "max_depth");
    }
    cut.settings.max_depth = 0;
    assert!(pseudocode::current_line(&cut, &[9, 9]).is_none());
}

#[test]
fn every_task_kind_is_read_from_the_file() {
    let lesson = shipped("termination");
    let step = lesson.step(5).expect("step 5");
    let Some(TaskKind::Control { pixel, .. }) = step.task.as_ref().map(|t| &t.kind) else {
        panic!("step 5 is a control task");
    };
    assert_eq!(*pixel, [230, 230]);
    // Step 3 set max_depth 1; later steps keep it, as the viewer does.
    assert_eq!(lesson.step(3).expect("3").sets.max_depth, Some(1));
    assert_eq!(lesson.step(4).expect("4").sets.max_depth, None);
    assert_eq!(lesson.step(4).expect("4").setup.max_depth, Some(1));
}
