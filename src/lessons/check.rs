//! Evaluating answers against the real trace, and validating lessons.
//!
//! [`evaluate`] is the one check the viewer and `raytree lesson answer` both call: it traces
//! the task's pixel with the step's setup (and, for a control task, the changed setting) by
//! the same recorder as `raytree tree`, and reads the answer off that tree. [`check_lesson`]
//! runs it over every task with answers it finds itself (a pixel searched on the image, coarse
//! grid first; every value of a control; the tree's own number or option), so a shipped
//! lesson is known to be solvable.

use std::sync::Arc;

use glam::Vec3;

use super::{
    Control, Event, Goal, Lesson, LessonError, NodeRef, Quantity, Question, Step, TaskKind,
    end_phrase, names_object, node_name,
};
use crate::choice::Choice;
use crate::geometry::OffsetMethod;
use crate::ray_tree::{self, Node, RayTree};
use crate::scene::{Scene, rules};
use crate::trace::{EndReason, RayKind, TraceSettings, Tracer, VisitQuery};

/// A student's answer.
#[derive(Clone, Debug, PartialEq)]
pub enum Answer {
    /// A clicked pixel (pixel tasks).
    Pixel([u32; 2]),
    /// A typed number (value tasks) or a control's new value (control tasks).
    Value(f64),
    /// An option's key or letter (choice tasks), or a named control's value (`offset`).
    Choice(String),
}

/// The outcome of one answer.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    pub correct: bool,
    /// One or two sentences on what the tree shows.
    pub message: String,
    /// The step's hint, given with a wrong answer.
    pub hint: Option<String>,
    /// The pixel whose tree the verdict reads (for a control task, traced with the answer).
    pub pixel: Option<[u32; 2]>,
    /// The node of that tree that shows why, as child indices from the root (the viewer's
    /// node path), and its `primary/T/R` name.
    pub node_path: Option<Vec<usize>>,
    pub node: Option<String>,
}

/// One option of a choice task.
#[derive(Clone, Debug, PartialEq)]
pub struct ChoiceOption {
    /// What `--choice` takes (the letter `a`, `b`, ... of its place works too).
    pub key: String,
    pub label: String,
}

/// What [`check_lesson`] found: problems (one sentence each; none means the lesson is good)
/// and, per task, an answer that passes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CheckReport {
    pub problems: Vec<String>,
    pub answers: Vec<String>,
}

fn err(step: &Step, text: impl AsRef<str>) -> LessonError {
    LessonError(format!("step {}: {}", step.number, text.as_ref()))
}

/// The tracer of a step: `scene` with the step's setup (`max_depth`, `offset`, `accel`).
fn step_tracer(step: &Step, scene: &Scene, settings: &TraceSettings) -> Tracer {
    let mut scene = scene.clone();
    let mut settings = *settings;
    step.setup.apply(&mut scene, &mut settings);
    Tracer::new(Arc::new(scene), settings)
}

fn tree_at(tracer: &Tracer, step: &Step, pixel: [u32; 2]) -> Result<RayTree, LessonError> {
    let (w, h) = (tracer.scene.render.width, tracer.scene.render.height);
    ray_tree::pixel_tree(tracer, pixel[0], pixel[1]).ok_or_else(|| {
        err(
            step,
            format!(
                "pixel ({}, {}) is outside the {w}x{h} image",
                pixel[0], pixel[1]
            ),
        )
    })
}

/// The tree of `pixel` as the step's task sees it (the step's setup applied to `scene`).
pub fn step_tree(
    step: &Step,
    scene: &Scene,
    settings: &TraceSettings,
    pixel: [u32; 2],
) -> Result<RayTree, LessonError> {
    tree_at(&step_tracer(step, scene, settings), step, pixel)
}

/// Evaluates `answer` to `step`'s task on `scene` (the lesson's scene, or the viewer's
/// current one) traced with `settings` and the step's setup. `Err` when the answer cannot be
/// evaluated: the step has no task, the answer is of another kind, a pixel is outside the
/// image, or the tree lacks the node the task names.
pub fn evaluate(
    step: &Step,
    answer: &Answer,
    scene: &Scene,
    settings: &TraceSettings,
) -> Result<Verdict, LessonError> {
    let Some(task) = &step.task else {
        return Err(err(step, "has no task to answer"));
    };
    let mut verdict = match (&task.kind, answer) {
        (TaskKind::Pixel { goal }, Answer::Pixel(p)) => {
            let tree = tree_at(&step_tracer(step, scene, settings), step, *p)?;
            goal_verdict(goal, &tree, None)
        }
        (
            TaskKind::Control {
                control,
                pixel,
                goal,
            },
            a,
        ) => evaluate_control(step, control, *pixel, goal, a, scene, settings)?,
        (
            TaskKind::Value {
                pixel,
                node,
                quantity,
                channel,
                light,
                tolerance,
            },
            Answer::Value(v),
        ) => {
            let tracer = step_tracer(step, scene, settings);
            let tree = tree_at(&tracer, step, *pixel)?;
            let (n, path) = find_node(step, node, &tree)?;
            let x =
                quantity_at(n, *quantity, *channel, light.as_deref(), &tracer).map_err(|why| {
                    err(
                        step,
                        format!("{node} of pixel ({}, {}) {why}", pixel[0], pixel[1]),
                    )
                })?;
            let correct = (v - x).abs() <= *tolerance;
            let message = if correct {
                format!("Right: {} at {node} is {x:.4}.", quantity.phrase())
            } else {
                format!(
                    "{v} is not {} at {node} of pixel ({}, {}) (to within ±{tolerance}); {}.",
                    quantity.phrase(),
                    pixel[0],
                    pixel[1],
                    look_at(*quantity)
                )
            };
            Verdict {
                correct,
                message,
                hint: None,
                pixel: Some(*pixel),
                node_path: Some(path),
                node: Some(node.to_string()),
            }
        }
        (
            TaskKind::Choice {
                pixel,
                node,
                question,
            },
            Answer::Choice(key),
        ) => evaluate_choice(step, *pixel, node, question, key, scene, settings)?,
        (kind, _) => {
            let wanted = match kind {
                TaskKind::Pixel { .. } => "a pixel (--pixel X,Y)",
                TaskKind::Value { .. } => "a number (--value V)",
                _ => "one of its options (--choice K)",
            };
            return Err(err(
                step,
                format!("its task is a {} task, answered with {wanted}", kind.name()),
            ));
        }
    };
    if !verdict.correct {
        verdict.hint = Some(task.hint.clone());
    }
    Ok(verdict)
}

/// Where the numbers behind a quantity are, for a wrong answer.
fn look_at(q: Quantity) -> &'static str {
    match q {
        Quantity::Local | Quantity::Diffuse | Quantity::Specular | Quantity::Ambient => {
            "look at that node's shadow rays (N·L, N·H, lit or blocked) and its material's ka, kd, ks and n"
        }
        Quantity::Color => {
            "look at that node's local intensity and its children's colours weighted by kr and kt"
        }
        Quantity::NDotL | Quantity::NDotH | Quantity::RDotV => {
            "look at that node's normal N, its shadow ray's direction L and the view direction V"
        }
        Quantity::T | Quantity::Barycentric => "look at that node's ray and the surface it hits",
        Quantity::IncidenceAngle => "look at that node's ray direction and the normal N at its hit",
        Quantity::RefractionAngle => {
            "look at the angle of incidence and the index of refraction at that node (Snell: sin θr = (ηi/ηr) sin θi)"
        }
        Quantity::Weight => "look at the kr and kt on the path from the primary ray to that node",
        Quantity::PrimitiveTests => {
            "look at the accelerator in use and how many objects that node's ray could meet"
        }
    }
}

fn find_node<'t>(
    step: &Step,
    node: &NodeRef,
    tree: &'t RayTree,
) -> Result<(&'t Node, Vec<usize>), LessonError> {
    node.find(tree).ok_or_else(|| {
        err(
            step,
            format!(
                "the tree of pixel ({}, {}) has no node {node}",
                tree.pixel[0], tree.pixel[1]
            ),
        )
    })
}

fn channel(v: Vec3, c: usize) -> f64 {
    f64::from(v.to_array()[c.min(2)])
}

fn degrees(cos: f32) -> f64 {
    f64::from(cos.clamp(-1.0, 1.0)).acos().to_degrees()
}

/// The quantity at `node`, or why the node has none ("has no hit", ...).
pub fn quantity_at(
    node: &Node,
    q: Quantity,
    c: usize,
    light: Option<&str>,
    tracer: &Tracer,
) -> Result<f64, String> {
    let local = || node.local.ok_or("is not shaded (its ray hits no surface)");
    let hit = || node.hit.as_ref().ok_or("has no hit");
    let shadow = || {
        let s = match light {
            Some(l) => node.shadow_rays.iter().find(|s| s.light == l),
            None => node.shadow_rays.first(),
        };
        s.ok_or(match light {
            Some(_) => "has no shadow ray to that light",
            None => "has no shadow ray",
        })
    };
    Ok(match q {
        Quantity::Local => channel(local()?.total, c),
        Quantity::Ambient => channel(local()?.ambient, c),
        Quantity::Diffuse => channel(local()?.diffuse, c),
        Quantity::Specular => channel(local()?.specular, c),
        Quantity::Color => channel(node.color, c),
        Quantity::NDotL => f64::from(shadow()?.n_dot_l),
        Quantity::NDotH => f64::from(shadow()?.n_dot_h),
        Quantity::RDotV => f64::from(shadow()?.r_dot_v),
        Quantity::T => f64::from(hit()?.t),
        Quantity::Barycentric => {
            let b = hit()?.barycentric.ok_or("hits no triangle")?;
            f64::from(b[c.min(2)])
        }
        Quantity::IncidenceAngle => degrees(-node.direction.dot(hit()?.normal)),
        Quantity::RefractionAngle => {
            let n = hit()?.normal;
            let t = node
                .children
                .iter()
                .find(|ch| ch.kind == RayKind::Refracted)
                .ok_or(if node.total_internal_reflection {
                    "has no refracted ray (total internal reflection)"
                } else {
                    "has no refracted ray"
                })?;
            degrees(-n.dot(t.direction))
        }
        Quantity::Weight => channel(node.weight, c),
        Quantity::PrimitiveTests => {
            hit()?;
            tracer
                .visits_of(node.origin, node.direction, VisitQuery::Closest)
                .prims
                .len() as f64
        }
    })
}

fn traced(node: &Node) -> bool {
    !matches!(
        node.end,
        Some(EndReason::MaxDepth | EndReason::Cutoff | EndReason::Budget)
    )
}

fn lit(s: &crate::ray_tree::ShadowRecord) -> bool {
    s.blocked_by.is_none() && !s.facing_away && !s.contributes_nothing && !s.behind_surface
}

/// Whether `event` happens at `node` (not below it).
pub fn event_at(event: Event, node: &Node) -> bool {
    match event {
        Event::TotalInternalReflection => node.total_internal_reflection,
        Event::ShadowBlocked => node.shadow_rays.iter().any(|s| s.blocked_by.is_some()),
        Event::SelfShadow => node.hit.as_ref().is_some_and(|h| {
            node.shadow_rays.iter().any(|s| {
                s.blocked_by
                    .as_deref()
                    .is_some_and(|b| object_of(b) == object_of(&h.object))
            })
        }),
        Event::ShadowLit => node.shadow_rays.iter().any(lit),
        Event::MaxDepth => node.end == Some(EndReason::MaxDepth),
        Event::Missed => node.end == Some(EndReason::NoHit),
        Event::HitLight => node.end == Some(EndReason::HitLight),
        Event::Reflected => node.kind == RayKind::Reflected && traced(node),
        Event::Refracted => node.kind == RayKind::Refracted && traced(node),
        Event::Hit => node.hit.is_some(),
        Event::Cutoff => node.end == Some(EndReason::Cutoff),
    }
}

/// The object part of a hit's name (`"kitchen"` of `"kitchen: Cabinet_3"`).
fn object_of(name: &str) -> &str {
    name.split_once(": ").map_or(name, |(o, _)| o)
}

fn filters_pass(goal: &Goal, node: &Node) -> bool {
    goal.ray.is_none_or(|r| node.kind == r)
        && goal.object.as_deref().is_none_or(|o| {
            node.hit
                .as_ref()
                .is_some_and(|h| names_object(&h.object, o))
        })
}

/// The first node (depth first, R before T) where the goal's event happens, as a path.
pub fn find_event(goal: &Goal, root: &Node) -> Option<Vec<usize>> {
    fn walk(goal: &Goal, node: &Node, path: &mut Vec<usize>) -> bool {
        if filters_pass(goal, node) && event_at(goal.event, node) {
            return true;
        }
        for (i, child) in node.children.iter().enumerate() {
            path.push(i);
            if walk(goal, child, path) {
                return true;
            }
            path.pop();
        }
        false
    }
    let mut path = Vec::new();
    walk(goal, root, &mut path).then_some(path)
}

/// Whether the tree meets the goal.
pub fn goal_met(goal: &Goal, tree: &RayTree) -> bool {
    find_event(goal, &tree.root).is_some() == goal.present
}

/// The deepest node that passes the goal's filters (its ray kind and object), else the deepest
/// node: where to look when the event is missing.
fn nearest(goal: &Goal, root: &Node) -> Vec<usize> {
    fn walk(goal: &Goal, node: &Node, path: &mut Vec<usize>, best: &mut (bool, usize, Vec<usize>)) {
        let key = (filters_pass(goal, node), path.len());
        if key > (best.0, best.1) {
            *best = (key.0, key.1, path.clone());
        }
        for (i, child) in node.children.iter().enumerate() {
            path.push(i);
            walk(goal, child, path, best);
            path.pop();
        }
    }
    let mut best = (filters_pass(goal, root), 0, Vec::new());
    walk(goal, root, &mut Vec::new(), &mut best);
    best.2
}

/// The goal in words: "a blocked shadow ray where the primary ray hits \"floor\"", "a
/// refracted ray that hits \"floor\"".
pub fn goal_phrase(goal: &Goal) -> String {
    let ray = goal.ray.map(|r| match r {
        RayKind::Primary => "the primary ray",
        RayKind::Reflected => "a reflected ray",
        _ => "a refracted ray",
    });
    let object = goal.object.as_ref().map(|o| format!("\"{o}\""));
    match goal.event {
        Event::Hit => format!(
            "{} that hits {}",
            ray.unwrap_or("a ray"),
            object.as_deref().unwrap_or("a surface")
        ),
        Event::Reflected | Event::Refracted if object.is_some() && goal.ray.is_none() => {
            format!(
                "{} that hits {}",
                goal.event.phrase(),
                object.as_deref().unwrap_or_default()
            )
        }
        e => match (ray, object) {
            (None, None) => e.phrase().to_string(),
            (Some(r), None) => format!("{} on {r}", e.phrase()),
            (r, Some(o)) => format!("{} where {} hits {o}", e.phrase(), r.unwrap_or("a ray")),
        },
    }
}

/// What the tree does have, for a wrong answer: the events met anywhere in it.
fn summary(tree: &RayTree) -> String {
    fn any(e: Event, n: &Node) -> bool {
        event_at(e, n) || n.children.iter().any(|c| any(e, c))
    }
    let found: Vec<String> = Event::ALL
        .into_iter()
        .filter(|e| !matches!(e, Event::Hit) && any(*e, &tree.root))
        .map(|e| e.phrase().to_string())
        .collect();
    let hit = tree
        .root
        .hit
        .as_ref()
        .map_or("meets nothing".to_string(), |h| {
            format!("hits \"{}\"", h.object)
        });
    if found.is_empty() {
        format!("its primary ray {hit}")
    } else {
        format!(
            "its primary ray {hit}, and it has {}",
            super::list_and(&found)
        )
    }
}

/// The verdict of a tree against a goal (`with` names a changed setting, for control tasks).
fn goal_verdict(goal: &Goal, tree: &RayTree, with: Option<&str>) -> Verdict {
    let [x, y] = tree.pixel;
    let found = find_event(goal, &tree.root);
    let correct = found.is_some() == goal.present;
    let (lead, lead_lower) = match with {
        Some(w) => (format!("With {w}, the"), format!("with {w}, the")),
        None => ("The".to_string(), "the".to_string()),
    };
    let phrase = goal_phrase(goal);
    let bare = phrase
        .trim_start_matches("a ")
        .trim_start_matches("an ")
        .trim_start_matches("the ");
    let (message, path) = match (&found, goal.present) {
        (Some(p), true) => (
            format!(
                "Right: {lead_lower} tree of pixel ({x}, {y}) has {phrase} at {}.",
                node_name(tree, p)
            ),
            p.clone(),
        ),
        (None, true) => (
            format!(
                "{lead} tree of pixel ({x}, {y}) has no {bare}; {}.",
                summary(tree)
            ),
            nearest(goal, &tree.root),
        ),
        (Some(p), false) => (
            format!(
                "{lead} tree of pixel ({x}, {y}) still has {phrase} at {}.",
                node_name(tree, p)
            ),
            p.clone(),
        ),
        (None, false) => (
            format!("Right: {lead_lower} tree of pixel ({x}, {y}) has no {bare}."),
            Vec::new(),
        ),
    };
    Verdict {
        correct,
        message,
        hint: None,
        pixel: Some([x, y]),
        node: Some(node_name(tree, &path)),
        node_path: Some(path),
    }
}

/// The scene and settings with a control set to the answer; `Ok(Err(why))` when the value is
/// not one the control takes (a wrong answer, with the reason).
fn set_control(
    step: &Step,
    control: &Control,
    answer: &Answer,
    scene: &mut Scene,
    settings: &mut TraceSettings,
) -> Result<Result<String, String>, LessonError> {
    if control.is_named() {
        let Answer::Choice(name) = answer else {
            return Err(err(
                step,
                format!(
                    "its task sets `{}`, answered with a name (--choice {})",
                    control.name(),
                    OffsetMethod::ALL
                        .iter()
                        .map(|o| o.name())
                        .collect::<Vec<_>>()
                        .join("|")
                ),
            ));
        };
        let Some(o) = OffsetMethod::from_name(name.trim()) else {
            return Ok(Err(format!(
                "`{name}` is not an offset method; they are {}",
                OffsetMethod::ALL
                    .iter()
                    .map(|o| o.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        };
        settings.methods.offset = o;
        return Ok(Ok(format!("offset = {}", o.name())));
    }
    let Answer::Value(v) = *answer else {
        return Err(err(
            step,
            format!(
                "its task sets `{}`, answered with a number (--value V)",
                control.name()
            ),
        ));
    };
    let x = v as f32;
    if !v.is_finite() {
        return Ok(Err(format!(
            "{v} is not a number {} can take",
            control.name()
        )));
    }
    match control {
        Control::MaxDepth => {
            if v.fract() != 0.0 || !(0.0..=f64::from(rules::MAX_DEPTH)).contains(&v) {
                return Ok(Err(format!(
                    "max_depth is a whole number from 0 to {}, not {v}",
                    rules::MAX_DEPTH
                )));
            }
            scene.render.max_depth = v as u32;
        }
        Control::Cutoff => {
            if let Some(phrase) = rules::number_phrase(x, rules::CUTOFF) {
                return Ok(Err(format!("the cutoff {phrase}, not {v}")));
            }
            settings.cutoff = x;
        }
        Control::Reflectivity(m) | Control::Transparency(m) | Control::Ior(m) => {
            let Some(material) = scene.materials.iter_mut().find(|mat| mat.name == *m) else {
                return Err(err(
                    step,
                    format!("its task changes the material \"{m}\", which the scene does not have"),
                ));
            };
            match control {
                Control::Reflectivity(_) => material.reflectivity = Vec3::splat(x),
                Control::Transparency(_) => material.transparency = Vec3::splat(x),
                _ => material.ior = x,
            }
            if let Err(violation) = rules::check_material(material) {
                return Ok(Err(format!(
                    "the material's {} {}, not {v}",
                    violation.field, violation.phrase
                )));
            }
        }
        Control::Offset => {}
    }
    let what = match control.material() {
        Some(m) => format!("{} of \"{m}\" = {v}", control.name()),
        None => format!("{} = {v}", control.name()),
    };
    Ok(Ok(what))
}

fn evaluate_control(
    step: &Step,
    control: &Control,
    pixel: [u32; 2],
    goal: &Goal,
    answer: &Answer,
    scene: &Scene,
    settings: &TraceSettings,
) -> Result<Verdict, LessonError> {
    let mut scene = scene.clone();
    let mut settings = *settings;
    step.setup.apply(&mut scene, &mut settings);
    let what = match set_control(step, control, answer, &mut scene, &mut settings)? {
        Ok(what) => what,
        Err(why) => {
            return Ok(Verdict {
                correct: false,
                message: format!("{why}."),
                hint: None,
                pixel: Some(pixel),
                node_path: None,
                node: None,
            });
        }
    };
    let tracer = Tracer::new(Arc::new(scene), settings);
    let tree = tree_at(&tracer, step, pixel)?;
    Ok(goal_verdict(goal, &tree, Some(&what)))
}

/// The options of a choice task, in the order shown (letters a, b, ... follow it).
pub fn choice_options(question: &Question) -> Vec<ChoiceOption> {
    let o = |key: &str, label: &str| ChoiceOption {
        key: key.into(),
        label: label.into(),
    };
    match question {
        Question::End => vec![
            o("missed", end_phrase(Some(EndReason::NoHit))),
            o("light", end_phrase(Some(EndReason::HitLight))),
            o("max_depth", end_phrase(Some(EndReason::MaxDepth))),
            o("surface", "none of them: it hits a surface and is shaded"),
        ],
        Question::Shadow { .. } => vec![
            o("lit", "lit: the shadow ray reaches the light"),
            o(
                "blocked",
                "blocked: an object lies between the point and the light",
            ),
            o(
                "facing_away",
                "facing away: the light is behind the surface (N·L ≤ 0)",
            ),
        ],
        Question::Children => vec![
            o("none", "no secondary rays"),
            o("r", "a reflected ray R only"),
            o("t", "a refracted ray T only"),
            o("rt", "both R and T"),
        ],
        Question::Object { options } => options.iter().map(|s| o(s, s)).collect(),
        Question::Fixed { options, .. } => options
            .iter()
            .enumerate()
            .map(|(i, s)| o(&letter(i).to_string(), s))
            .collect(),
    }
}

/// The key of the right option, read from the node; `Err(why)` when the tree's answer is
/// not among the options.
fn right_key(question: &Question, node: &Node) -> Result<String, String> {
    Ok(match question {
        Question::End => match node.end {
            None => "surface",
            Some(EndReason::NoHit) => "missed",
            Some(EndReason::HitLight) => "light",
            Some(EndReason::MaxDepth) => "max_depth",
            Some(other) => {
                return Err(format!(
                    "ends because {}, which is none of the options",
                    end_phrase(Some(other))
                ));
            }
        }
        .to_string(),
        Question::Shadow { light } => {
            let s = match light {
                Some(l) => node.shadow_rays.iter().find(|s| s.light == *l),
                None => node.shadow_rays.first(),
            };
            let Some(s) = s else {
                return Err(match light {
                    Some(l) => format!("has no shadow ray to the light \"{l}\""),
                    None => "has no shadow ray".into(),
                });
            };
            if s.facing_away || s.behind_surface {
                "facing_away"
            } else if s.blocked_by.is_some() {
                "blocked"
            } else if s.contributes_nothing {
                return Err(
                    "has a shadow ray that is not traced (the light adds nothing there)".into(),
                );
            } else {
                "lit"
            }
            .to_string()
        }
        Question::Children => {
            let r = node.children.iter().any(|c| c.kind == RayKind::Reflected);
            let t = node.children.iter().any(|c| c.kind == RayKind::Refracted);
            match (r, t) {
                (false, false) => "none",
                (true, false) => "r",
                (false, true) => "t",
                (true, true) => "rt",
            }
            .to_string()
        }
        Question::Object { options } => {
            let Some(hit) = &node.hit else {
                return Err("hits no object".into());
            };
            options
                .iter()
                .find(|o| names_object(&hit.object, o))
                .cloned()
                .ok_or_else(|| format!("hits \"{}\", which is none of the options", hit.object))?
        }
        Question::Fixed { answer, .. } => letter(*answer).to_string(),
    })
}

/// The letter of the option at place `i`: a, b, c, ...
fn letter(i: usize) -> char {
    (b'a' + (i % 26) as u8) as char
}

/// The option an answer names: its key (any case) or its letter.
fn pick<'o>(options: &'o [ChoiceOption], answer: &str) -> Option<&'o ChoiceOption> {
    let a = answer.trim();
    options
        .iter()
        .find(|o| o.key.eq_ignore_ascii_case(a))
        .or_else(|| {
            let mut chars = a.chars();
            let (Some(c), None) = (chars.next(), chars.next()) else {
                return None;
            };
            let i = (c.to_ascii_lowercase() as usize).checked_sub('a' as usize)?;
            options.get(i)
        })
}

#[allow(clippy::too_many_arguments)]
fn evaluate_choice(
    step: &Step,
    pixel: [u32; 2],
    node: &NodeRef,
    question: &Question,
    answer: &str,
    scene: &Scene,
    settings: &TraceSettings,
) -> Result<Verdict, LessonError> {
    let options = choice_options(question);
    let Some(chosen) = pick(&options, answer) else {
        let listed: Vec<String> = options
            .iter()
            .enumerate()
            .map(|(i, o)| format!("{} `{}`", letter(i), o.key))
            .collect();
        return Err(err(
            step,
            format!(
                "`{}` is none of the options {}",
                answer.trim(),
                super::list_and(&listed)
            ),
        ));
    };
    if let Question::Fixed { .. } = question {
        let right = right_key(question, &tree_less_node()).unwrap_or_default();
        let correct = chosen.key == right;
        return Ok(Verdict {
            correct,
            message: if correct {
                format!("Right: {}.", chosen.label)
            } else {
                format!("Not \"{}\".", chosen.label)
            },
            hint: None,
            pixel: None,
            node_path: None,
            node: None,
        });
    }
    let tree = step_tree(step, scene, settings, pixel)?;
    let (n, path) = find_node(step, node, &tree)?;
    let right = right_key(question, n).map_err(|why| {
        err(
            step,
            format!("{node} of pixel ({}, {}) {why}", pixel[0], pixel[1]),
        )
    })?;
    let correct = chosen.key == right;
    let what = match question {
        Question::End => "how it ended",
        Question::Shadow { .. } => "its shadow ray",
        Question::Children => "its children",
        _ => "the object its ray hits",
    };
    let message = if correct {
        format!("Right: at {node}, {}.", chosen.label)
    } else {
        format!(
            "Not \"{}\": look at {what} at {node} of pixel ({}, {}).",
            chosen.label, pixel[0], pixel[1]
        )
    };
    Ok(Verdict {
        correct,
        message,
        hint: None,
        pixel: Some(pixel),
        node_path: Some(path),
        node: Some(node.to_string()),
    })
}

/// A node for questions that do not read the tree.
fn tree_less_node() -> Node {
    Node::new(RayKind::Primary, 0, Vec3::ZERO, Vec3::Z, Vec3::ONE)
}

/// A pixel whose tree meets the goal: every 16th pixel first, then every 4th, then all.
pub fn search_pixel(goal: &Goal, tracer: &Tracer) -> Option<[u32; 2]> {
    let (w, h) = (tracer.scene.render.width, tracer.scene.render.height);
    for (stride, start) in [(16u32, 8u32), (4, 2), (1, 0)] {
        let start = if start < w.min(h) { start } else { 0 };
        for y in (start..h).step_by(stride as usize) {
            for x in (start..w).step_by(stride as usize) {
                if ray_tree::pixel_tree(tracer, x, y).is_some_and(|t| goal_met(goal, &t)) {
                    return Some([x, y]);
                }
            }
        }
    }
    None
}

/// The values a control is tried at by [`check_lesson`].
fn candidates(control: &Control) -> Vec<Answer> {
    let steps = |from: f64, to: f64, by: f64| {
        let n = ((to - from) / by).round() as usize;
        (0..=n)
            .map(|i| Answer::Value(((from + by * i as f64) * 1e6).round() / 1e6))
            .collect::<Vec<_>>()
    };
    match control {
        Control::MaxDepth => (0..=rules::MAX_DEPTH)
            .map(|d| Answer::Value(f64::from(d)))
            .collect(),
        Control::Reflectivity(_) | Control::Transparency(_) => steps(0.0, 1.0, 0.05),
        Control::Ior(_) => steps(1.0, 2.5, 0.05),
        Control::Cutoff => steps(0.0, 0.95, 0.05),
        Control::Offset => OffsetMethod::ALL
            .iter()
            .map(|o| Answer::Choice(o.name().into()))
            .collect(),
    }
}

fn answer_text(a: &Answer) -> String {
    match a {
        Answer::Pixel([x, y]) => format!("{x},{y}"),
        Answer::Value(v) => format!("{v}"),
        Answer::Choice(k) => k.clone(),
    }
}

/// Validates a lesson: the scene loads; every selected pixel is in the image; every task can
/// be evaluated and has at least one answer [`evaluate`] accepts (found here: a pixel, a
/// control value, the tree's number or option) — and, for value and choice tasks, that a
/// wrong answer is refused.
pub fn check_lesson(lesson: &Lesson) -> CheckReport {
    let mut report = CheckReport::default();
    let file = &lesson.file;
    let scene = match lesson.load_scene() {
        Ok(s) => s,
        Err(e) => {
            report
                .problems
                .push(format!("{file}: the lesson's scene does not load: {e}"));
            return report;
        }
    };
    let settings = TraceSettings::default();
    let (w, h) = (scene.render.width, scene.render.height);
    for step in &lesson.steps {
        let n = step.number;
        let mut problem = |text: String| {
            report
                .problems
                .push(format!("{file}:{}: step {n}: {text}", step.line))
        };
        if let Some([x, y]) = step.sets.select
            && (x >= w || y >= h)
        {
            problem(format!(
                "`select` = [{x}, {y}] is outside the {w}x{h} image"
            ));
        }
        let Some(task) = &step.task else {
            continue;
        };
        let found = match &task.kind {
            TaskKind::Pixel { goal } => {
                let tracer = step_tracer(step, &scene, &settings);
                match search_pixel(goal, &tracer) {
                    Some(p) => Ok(Answer::Pixel(p)),
                    None => Err(format!(
                        "no pixel of the {w}x{h} image has {}{}",
                        if goal.present { "" } else { "no longer " },
                        goal_phrase(goal)
                    )),
                }
            }
            TaskKind::Control { control, goal, .. } => {
                let mut passing = Vec::new();
                let mut failure = None;
                for a in candidates(control) {
                    match evaluate(step, &a, &scene, &settings) {
                        Ok(v) if v.correct => passing.push(a),
                        Ok(_) => {}
                        Err(e) => {
                            failure = Some(e.0);
                            break;
                        }
                    }
                }
                match (failure, passing.first()) {
                    (Some(e), _) => Err(e),
                    (None, Some(a)) => {
                        let listed: Vec<String> = passing.iter().map(answer_text).collect();
                        report.answers.push(format!(
                            "step {n}: {} passes ({} of the values tried pass: {})",
                            answer_text(a),
                            passing.len(),
                            short_list(&listed)
                        ));
                        continue;
                    }
                    (None, None) => Err(format!(
                        "no value of `{}` tried makes the tree have {}{}",
                        control.name(),
                        if goal.present { "" } else { "no " },
                        goal_phrase(goal)
                    )),
                }
            }
            TaskKind::Value {
                pixel,
                node,
                quantity,
                channel,
                light,
                tolerance,
            } => {
                let tracer = step_tracer(step, &scene, &settings);
                tree_at(&tracer, step, *pixel)
                    .map_err(|e| e.0)
                    .and_then(|tree| {
                        let (n, _) = find_node(step, node, &tree).map_err(|e| e.0)?;
                        quantity_at(n, *quantity, *channel, light.as_deref(), &tracer).map_err(
                            |why| format!("{node} of pixel ({}, {}) {why}", pixel[0], pixel[1]),
                        )
                    })
                    .and_then(|x| {
                        if x.is_finite() {
                            // A clearly wrong answer must be refused.
                            let wrong = Answer::Value(x + 10.0 * tolerance + 1.0);
                            match evaluate(step, &wrong, &scene, &settings) {
                                Ok(v) if !v.correct => Ok(Answer::Value((x * 1e4).round() / 1e4)),
                                Ok(_) => Err("a wrong number is accepted".into()),
                                Err(e) => Err(e.0),
                            }
                        } else {
                            Err(format!(
                                "{} at {node} is not a finite number",
                                quantity.phrase()
                            ))
                        }
                    })
            }
            TaskKind::Choice { question, .. } => {
                let options = choice_options(question);
                let mut right = None;
                let mut failure = None;
                for o in &options {
                    match evaluate(step, &Answer::Choice(o.key.clone()), &scene, &settings) {
                        Ok(v) if v.correct => right = right.or(Some(o.key.clone())),
                        Ok(_) => {}
                        Err(e) => {
                            failure = Some(e.0);
                            break;
                        }
                    }
                }
                match (failure, right) {
                    (Some(e), _) => Err(e),
                    (None, Some(k)) => Ok(Answer::Choice(k)),
                    (None, None) => Err("none of the options is right".into()),
                }
            }
        };
        match found.and_then(|a| match evaluate(step, &a, &scene, &settings) {
            Ok(v) if v.correct => Ok(a),
            Ok(v) => Err(format!(
                "the answer found, {}, is refused: {}",
                answer_text(&a),
                v.message
            )),
            Err(e) => Err(e.0),
        }) {
            Ok(a) => report
                .answers
                .push(format!("step {n}: {} passes", answer_text(&a))),
            Err(e) => problem(e.trim_start_matches(&format!("step {n}: ")).to_string()),
        }
    }
    report
}

fn short_list(items: &[String]) -> String {
    if items.len() <= 6 {
        items.join(", ")
    } else {
        format!(
            "{}, … {}",
            items[..3].join(", "),
            items[items.len() - 2..].join(", ")
        )
    }
}
