//! Lessons: the lecture's ideas as guided steps over a scene, each step optionally holding a
//! task checked against the real trace (docs/lessons.md has the file format, every key and an
//! example). Headless: the command line (`raytree lessons`, `raytree lesson check|answer`) and
//! the viewer call the same code.
//!
//! - this file: the types of a lesson and its parser, which places every error at its file,
//!   line and key as the scene loader does; the shipped lessons, compiled in;
//! - [`check`]: evaluating an answer ([`evaluate`]) and validating a whole lesson
//!   ([`check_lesson`]: the scene loads, every task can be evaluated and has a correct answer);
//! - [`pseudocode`]: the lecture's recursive procedure as numbered lines, and which of them a
//!   node of a tree executed with the values of its variables.

pub mod check;
pub mod pseudocode;

use std::ops::Range;
use std::path::{Path, PathBuf};

use toml::de::{DeTable, DeValue};

use crate::accel::AccelKind;
use crate::choice::Choice;
use crate::geometry::OffsetMethod;
use crate::ray_tree::{Node, RayTree};
use crate::scene::diag::{SceneError, Src, list_and, short, suggest};
use crate::scene::toml::reader::{Section, Value, describe, syntax_error};
use crate::scene::{self, Scene, rules};
use crate::trace::{EndReason, RayKind, TraceSettings};

pub use check::{
    Answer, CheckReport, ChoiceOption, Verdict, check_lesson, choice_options, evaluate,
    search_pixel, step_tree,
};

/// A lesson file that cannot be read or used: one sentence naming the file, the place and
/// the key.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct LessonError(pub String);

impl From<SceneError> for LessonError {
    fn from(e: SceneError) -> Self {
        LessonError(e.0)
    }
}

/// The lessons shipped with raytree (`assets/lessons`), compiled in, in the lecture's order:
/// name (the file's stem) and text.
pub const SHIPPED: &[(&str, &str)] = &[
    (
        "eye-rays",
        include_str!("../../assets/lessons/eye-rays.toml"),
    ),
    (
        "primary-rays",
        include_str!("../../assets/lessons/primary-rays.toml"),
    ),
    ("shadows", include_str!("../../assets/lessons/shadows.toml")),
    (
        "reflection",
        include_str!("../../assets/lessons/reflection.toml"),
    ),
    (
        "refraction",
        include_str!("../../assets/lessons/refraction.toml"),
    ),
    (
        "total-internal-reflection",
        include_str!("../../assets/lessons/total-internal-reflection.toml"),
    ),
    (
        "termination",
        include_str!("../../assets/lessons/termination.toml"),
    ),
    ("tree", include_str!("../../assets/lessons/tree.toml")),
    ("quiz", include_str!("../../assets/lessons/quiz.toml")),
    (
        "speed-accuracy",
        include_str!("../../assets/lessons/speed-accuracy.toml"),
    ),
];

/// Where a lesson's scene comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneRef {
    /// A built-in scene (`raytree scenes`).
    Builtin(String),
    /// A scene file (or OBJ), the path resolved against the lesson file's folder.
    File(PathBuf),
}

/// A pane the viewer shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    Render,
    Scene,
    Diagram,
    Tree,
    Pseudocode,
}

impl View {
    pub const ALL: [View; 5] = [
        View::Render,
        View::Scene,
        View::Diagram,
        View::Tree,
        View::Pseudocode,
    ];

    /// The name in lesson files.
    pub fn name(self) -> &'static str {
        match self {
            View::Render => "render",
            View::Scene => "scene",
            View::Diagram => "diagram",
            View::Tree => "tree",
            View::Pseudocode => "pseudocode",
        }
    }
}

/// What a step sets in the viewer when it is shown (each `None`/`false` leaves it as it is).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepState {
    /// Select this pixel (its tree is shown).
    pub select: Option<[u32; 2]>,
    pub max_depth: Option<u32>,
    pub view: Option<View>,
    /// Show the tree stepped to this depth.
    pub depth_step: Option<u32>,
    /// Start depth stepping's Play.
    pub play: bool,
    pub offset: Option<OffsetMethod>,
    pub accel: Option<AccelKind>,
}

/// What a step's task is evaluated under: the settings every step up to and including it set
/// (a later step keeps what an earlier one set, as the viewer does).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Setup {
    pub select: Option<[u32; 2]>,
    pub max_depth: Option<u32>,
    pub offset: Option<OffsetMethod>,
    pub accel: Option<AccelKind>,
}

impl Setup {
    /// The scene and trace settings with this setup's values in place.
    pub fn apply(&self, scene: &mut Scene, settings: &mut TraceSettings) {
        if let Some(d) = self.max_depth {
            scene.render.max_depth = d;
        }
        if let Some(o) = self.offset {
            settings.methods.offset = o;
        }
        if let Some(a) = self.accel {
            settings.accel = a;
        }
    }

    fn then(mut self, s: &StepState) -> Setup {
        self.select = s.select.or(self.select);
        self.max_depth = s.max_depth.or(self.max_depth);
        self.offset = s.offset.or(self.offset);
        self.accel = s.accel.or(self.accel);
        self
    }
}

/// Something that can happen in a tree, for pixel and control tasks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    /// A refraction turned into reflection (no T ray).
    TotalInternalReflection,
    /// A shadow ray met an object before its light.
    ShadowBlocked,
    /// A shadow ray was blocked by the very object it starts on (shadow acne on a convex
    /// object).
    SelfShadow,
    /// A shadow ray reached its light and the light adds diffuse or specular light.
    ShadowLit,
    /// A ray was not traced for being deeper than `max_depth`.
    MaxDepth,
    /// A ray met nothing (background).
    Missed,
    /// A ray ended on a visible light.
    HitLight,
    /// A reflected ray was traced.
    Reflected,
    /// A refracted ray was traced.
    Refracted,
    /// A ray met a surface.
    Hit,
    /// A ray was not traced for its weight being below the cutoff.
    Cutoff,
}

impl Event {
    pub const ALL: [Event; 11] = [
        Event::TotalInternalReflection,
        Event::ShadowBlocked,
        Event::SelfShadow,
        Event::ShadowLit,
        Event::MaxDepth,
        Event::Missed,
        Event::HitLight,
        Event::Reflected,
        Event::Refracted,
        Event::Hit,
        Event::Cutoff,
    ];

    /// The name in lesson files.
    pub fn name(self) -> &'static str {
        match self {
            Event::TotalInternalReflection => "total_internal_reflection",
            Event::ShadowBlocked => "shadow_blocked",
            Event::SelfShadow => "self_shadow",
            Event::ShadowLit => "shadow_lit",
            Event::MaxDepth => "max_depth",
            Event::Missed => "missed",
            Event::HitLight => "hit_light",
            Event::Reflected => "reflected",
            Event::Refracted => "refracted",
            Event::Hit => "hit",
            Event::Cutoff => "cutoff",
        }
    }

    /// In words, after "a ray ..." or "a tree with ...".
    pub fn phrase(self) -> &'static str {
        match self {
            Event::TotalInternalReflection => "a total internal reflection",
            Event::ShadowBlocked => "a blocked shadow ray",
            Event::SelfShadow => "a shadow ray blocked by the surface it starts on",
            Event::ShadowLit => "a shadow ray that reaches its light",
            Event::MaxDepth => "a ray stopped at the maximum depth",
            Event::Missed => "a ray that hits nothing",
            Event::HitLight => "a ray that ends on a light",
            Event::Reflected => "a traced reflected ray",
            Event::Refracted => "a traced refracted ray",
            Event::Hit => "a ray that hits a surface",
            Event::Cutoff => "a ray skipped below the cutoff",
        }
    }

    fn from_name(name: &str) -> Option<Event> {
        Event::ALL.into_iter().find(|e| e.name() == name)
    }
}

/// What must be true (or, with `present = false`, not true) of a pixel's tree.
#[derive(Clone, Debug, PartialEq)]
pub struct Goal {
    pub event: Event,
    /// Only where the ray's hit (for shadow events: the surface the shadow ray starts on) is
    /// this object: its name as the tree shows it, or the part before `": "` of a mesh's.
    pub object: Option<String>,
    /// Only on a ray of this kind.
    pub ray: Option<RayKind>,
    /// `false`: the tree must have no such event.
    pub present: bool,
}

/// A setting a control task asks the student to change.
#[derive(Clone, Debug, PartialEq)]
pub enum Control {
    MaxDepth,
    /// A material's `reflectivity` (kr), all three channels alike.
    Reflectivity(String),
    /// A material's `transparency` (kt), all three channels alike.
    Transparency(String),
    /// A material's index of refraction.
    Ior(String),
    /// The adaptive-depth weight cutoff.
    Cutoff,
    /// The ray-origin offset method (a named answer).
    Offset,
}

impl Control {
    /// The name in lesson files.
    pub fn name(&self) -> &'static str {
        match self {
            Control::MaxDepth => "max_depth",
            Control::Reflectivity(_) => "reflectivity",
            Control::Transparency(_) => "transparency",
            Control::Ior(_) => "ior",
            Control::Cutoff => "cutoff",
            Control::Offset => "offset",
        }
    }

    /// The material it changes, for the material controls.
    pub fn material(&self) -> Option<&str> {
        match self {
            Control::Reflectivity(m) | Control::Transparency(m) | Control::Ior(m) => Some(m),
            _ => None,
        }
    }

    /// Whether the answer is a name (`Answer::Choice`) rather than a number.
    pub fn is_named(&self) -> bool {
        matches!(self, Control::Offset)
    }
}

/// A number a value task asks for, read from one node of the tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// The local intensity `ambient + diffuse + specular` (one channel).
    Local,
    Ambient,
    Diffuse,
    Specular,
    /// The node's colour: local plus the weighted children (leaf-up shading).
    Color,
    /// `N·L` of the shadow ray to the task's light.
    NDotL,
    /// `N·H` of the shadow ray to the task's light.
    NDotH,
    /// `R·V` of the shadow ray to the task's light.
    RDotV,
    /// The distance along the ray to its hit.
    T,
    /// One barycentric coordinate of a triangle hit (`component` 1 to 3).
    Barycentric,
    /// The angle (degrees) between the incoming ray and the normal, θi.
    IncidenceAngle,
    /// The angle (degrees) between the refracted child and the reversed normal, θr.
    RefractionAngle,
    /// The product of kr/kt from the root (one channel).
    Weight,
    /// Primitives the node's closest-hit query tested under the setup's accelerator.
    PrimitiveTests,
}

impl Quantity {
    pub const ALL: [Quantity; 14] = [
        Quantity::Local,
        Quantity::Ambient,
        Quantity::Diffuse,
        Quantity::Specular,
        Quantity::Color,
        Quantity::NDotL,
        Quantity::NDotH,
        Quantity::RDotV,
        Quantity::T,
        Quantity::Barycentric,
        Quantity::IncidenceAngle,
        Quantity::RefractionAngle,
        Quantity::Weight,
        Quantity::PrimitiveTests,
    ];

    /// The name in lesson files.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Local => "local",
            Quantity::Ambient => "ambient",
            Quantity::Diffuse => "diffuse",
            Quantity::Specular => "specular",
            Quantity::Color => "color",
            Quantity::NDotL => "n_dot_l",
            Quantity::NDotH => "n_dot_h",
            Quantity::RDotV => "r_dot_v",
            Quantity::T => "t",
            Quantity::Barycentric => "barycentric",
            Quantity::IncidenceAngle => "incidence_angle",
            Quantity::RefractionAngle => "refraction_angle",
            Quantity::Weight => "weight",
            Quantity::PrimitiveTests => "primitive_tests",
        }
    }

    /// In words, for messages.
    pub fn phrase(self) -> &'static str {
        match self {
            Quantity::Local => "the local intensity",
            Quantity::Ambient => "the ambient term",
            Quantity::Diffuse => "the diffuse term",
            Quantity::Specular => "the specular term",
            Quantity::Color => "the node's colour",
            Quantity::NDotL => "N·L",
            Quantity::NDotH => "N·H",
            Quantity::RDotV => "R·V",
            Quantity::T => "the distance t to the hit",
            Quantity::Barycentric => "the barycentric coordinate",
            Quantity::IncidenceAngle => "the angle of incidence",
            Quantity::RefractionAngle => "the angle of refraction",
            Quantity::Weight => "the ray's weight",
            Quantity::PrimitiveTests => "the number of primitives tested",
        }
    }

    /// Whether it is read per colour channel (`channel` applies).
    pub fn has_channel(self) -> bool {
        matches!(
            self,
            Quantity::Local
                | Quantity::Ambient
                | Quantity::Diffuse
                | Quantity::Specular
                | Quantity::Color
                | Quantity::Weight
        )
    }

    /// Whether it is about one light's shadow ray (`light` applies).
    pub fn has_light(self) -> bool {
        matches!(self, Quantity::NDotL | Quantity::NDotH | Quantity::RDotV)
    }

    fn from_name(name: &str) -> Option<Quantity> {
        Quantity::ALL.into_iter().find(|q| q.name() == name)
    }
}

/// What a choice task asks; the right option is computed from the tree except for `Fixed`.
#[derive(Clone, Debug, PartialEq)]
pub enum Question {
    /// Which termination condition ended the node's ray (or none: it hit a surface)?
    End,
    /// Is the shadow ray to the light lit, blocked, or is the light behind the surface?
    Shadow { light: Option<String> },
    /// Which secondary rays does the node spawn: none, R, T, or both?
    Children,
    /// Which of these objects does the node's ray hit?
    Object { options: Vec<String> },
    /// A question the tree cannot answer (why rays start at the eye): the options and the
    /// index of the right one, as written in the file.
    Fixed { options: Vec<String>, answer: usize },
}

impl Question {
    pub fn name(&self) -> &'static str {
        match self {
            Question::End => "end",
            Question::Shadow { .. } => "shadow",
            Question::Children => "children",
            Question::Object { .. } => "object",
            Question::Fixed { .. } => "fixed",
        }
    }
}

/// A node of a pixel's tree, named by the kinds of rays from the primary one:
/// `primary/T/R` is the reflected child of the primary ray's refracted child.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeRef {
    pub kinds: Vec<RayKind>,
}

impl NodeRef {
    pub fn primary() -> NodeRef {
        NodeRef { kinds: Vec::new() }
    }

    /// Reads `primary`, `primary/R`, `primary/T/T`, ...; `None` if it is not of that form.
    pub fn parse(text: &str) -> Option<NodeRef> {
        let mut parts = text.trim().split('/').map(str::trim);
        if parts.next()? != "primary" {
            return None;
        }
        let kinds = parts
            .map(|p| match p {
                "R" => Some(RayKind::Reflected),
                "T" => Some(RayKind::Refracted),
                _ => None,
            })
            .collect::<Option<Vec<_>>>()?;
        Some(NodeRef { kinds })
    }

    /// The node in `tree` and its child-index path (as the viewer's node paths), if the tree
    /// has it.
    pub fn find<'t>(&self, tree: &'t RayTree) -> Option<(&'t Node, Vec<usize>)> {
        let mut node = &tree.root;
        let mut path = Vec::new();
        for &kind in &self.kinds {
            let i = node.children.iter().position(|c| c.kind == kind)?;
            path.push(i);
            node = &node.children[i];
        }
        Some((node, path))
    }
}

impl std::fmt::Display for NodeRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("primary")?;
        for k in &self.kinds {
            f.write_str(if *k == RayKind::Reflected { "/R" } else { "/T" })?;
        }
        Ok(())
    }
}

/// The `primary/T/R` name of the node at child-index `path` of `tree`.
pub fn node_name(tree: &RayTree, path: &[usize]) -> String {
    let mut node = &tree.root;
    let mut kinds = Vec::new();
    for &i in path {
        let Some(child) = node.children.get(i) else {
            break;
        };
        kinds.push(child.kind);
        node = child;
    }
    NodeRef { kinds }.to_string()
}

/// What a task asks, and how it is checked.
#[derive(Clone, Debug, PartialEq)]
pub enum TaskKind {
    /// Click a pixel whose tree meets the goal (answer: a pixel).
    Pixel { goal: Goal },
    /// Set the control so that the tree of `pixel` meets the goal (answer: the control's value,
    /// a number or, for `offset`, a name).
    Control {
        control: Control,
        pixel: [u32; 2],
        goal: Goal,
    },
    /// Type the quantity at a node of the tree of `pixel` (answer: a number), within
    /// `tolerance`.
    Value {
        pixel: [u32; 2],
        node: NodeRef,
        quantity: Quantity,
        /// 0, 1, 2 for r, g, b (or for barycentric, the coordinate).
        channel: usize,
        light: Option<String>,
        tolerance: f64,
    },
    /// Choose among options (answer: an option's key or its letter).
    Choice {
        pixel: [u32; 2],
        node: NodeRef,
        question: Question,
    },
}

impl TaskKind {
    pub fn name(&self) -> &'static str {
        match self {
            TaskKind::Pixel { .. } => "pixel",
            TaskKind::Control { .. } => "control",
            TaskKind::Value { .. } => "value",
            TaskKind::Choice { .. } => "choice",
        }
    }
}

/// A step's task.
#[derive(Clone, Debug, PartialEq)]
pub struct Task {
    pub kind: TaskKind,
    /// What to answer, shown beside the step's text (optional).
    pub prompt: Option<String>,
    /// Shown with a wrong answer.
    pub hint: String,
}

/// One step of a lesson.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// 1-based, as `raytree lesson answer NAME STEP` counts.
    pub number: usize,
    /// The line of its `[[step]]` in the file.
    pub line: usize,
    pub text: String,
    /// What the step sets when shown.
    pub sets: StepState,
    /// What its task is evaluated under (this step's and earlier steps' settings).
    pub setup: Setup,
    pub task: Option<Task>,
}

/// A lesson: a scene, an introduction and steps.
#[derive(Clone, Debug, PartialEq)]
pub struct Lesson {
    /// The file's stem (`shadows`), by which the command line names it.
    pub name: String,
    /// The file as messages name it.
    pub file: String,
    pub title: String,
    /// One line for lists (the first sentence of `intro` when not given).
    pub summary: String,
    pub scene: SceneRef,
    pub intro: String,
    pub steps: Vec<Step>,
}

impl Lesson {
    /// Reads a lesson file; a relative scene path is taken from the file's folder.
    pub fn load(path: &Path) -> Result<Lesson, LessonError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| LessonError(format!("cannot read the lesson {file}: {e}.")))?;
        let folder = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| file.clone());
        Lesson::parse(&text, &name, &file, Some(&folder))
    }

    /// A shipped lesson by name ([`SHIPPED`]).
    pub fn shipped(name: &str) -> Option<Result<Lesson, LessonError>> {
        let (name, text) = SHIPPED.iter().find(|(n, _)| *n == name)?;
        let file = format!("assets/lessons/{name}.toml");
        Some(Lesson::parse(text, name, &file, None))
    }

    /// Every shipped lesson, in order.
    pub fn all_shipped() -> Vec<Result<Lesson, LessonError>> {
        SHIPPED
            .iter()
            .filter_map(|(n, _)| Lesson::shipped(n))
            .collect()
    }

    /// A lesson file, or else a shipped lesson of that name.
    pub fn open(arg: &str) -> Result<Lesson, LessonError> {
        let path = Path::new(arg);
        if path.is_file() {
            return Lesson::load(path);
        }
        if let Some(lesson) = Lesson::shipped(arg) {
            return lesson;
        }
        let hint = suggest(arg, SHIPPED.iter().map(|(n, _)| *n))
            .map(|n| format!(" (did you mean `{n}`?)"))
            .unwrap_or_default();
        Err(LessonError(format!(
            "`{}` is neither a lesson file nor a shipped lesson{hint}; `raytree lessons` lists them.",
            short(arg)
        )))
    }

    /// Parses lesson text; `file` names it in messages, `folder` resolves a scene path
    /// (`None`: only built-in scenes, as for the shipped lessons).
    pub fn parse(
        text: &str,
        name: &str,
        file: &str,
        folder: Option<&Path>,
    ) -> Result<Lesson, LessonError> {
        let src = Src { file, text };
        let root = DeTable::parse(text).map_err(|e| syntax_error(&src, &e))?;
        let root = Value::new(0..text.len(), DeValue::Table(root.into_inner()));
        parse_lesson(&src, &root, name, folder).map_err(LessonError::from)
    }

    /// The lesson's scene, loaded.
    pub fn load_scene(&self) -> Result<Scene, LessonError> {
        let scene = match &self.scene {
            SceneRef::Builtin(name) => scene::load_builtin(name)?,
            SceneRef::File(path) => scene::load_scene_file(path)?,
        };
        Ok(scene)
    }

    /// The step numbered `number` (1-based).
    pub fn step(&self, number: usize) -> Option<&Step> {
        number.checked_sub(1).and_then(|i| self.steps.get(i))
    }
}

const LESSON_KEYS: &[&str] = &["title", "summary", "scene", "intro", "step"];
const STEP_KEYS: &[&str] = &[
    "text",
    "select",
    "max_depth",
    "view",
    "depth_step",
    "play",
    "offset",
    "accel",
    "task",
];
const TASK_KINDS: &[&str] = &["pixel", "control", "value", "choice"];
const PIXEL_KEYS: &[&str] = &[
    "kind", "prompt", "hint", "event", "object", "ray", "present",
];
const CONTROL_KEYS: &[&str] = &[
    "kind", "prompt", "hint", "control", "material", "pixel", "event", "object", "ray", "present",
];
const VALUE_KEYS: &[&str] = &[
    "kind",
    "prompt",
    "hint",
    "pixel",
    "node",
    "quantity",
    "channel",
    "component",
    "light",
    "tolerance",
];
const CHOICE_KEYS: &[&str] = &[
    "kind", "prompt", "hint", "pixel", "node", "question", "light", "options", "answer",
];
const CONTROLS: &[&str] = &[
    "max_depth",
    "reflectivity",
    "transparency",
    "ior",
    "cutoff",
    "offset",
];
const QUESTIONS: &[&str] = &["end", "shadow", "children", "object", "fixed"];

fn quoted(names: impl IntoIterator<Item = impl AsRef<str>>) -> String {
    let items: Vec<String> = names
        .into_iter()
        .map(|n| format!("\"{}\"", n.as_ref()))
        .collect();
    list_and(&items)
}

/// A string field that must be one of `names`.
fn one_of<'n>(
    s: &Section,
    key: &str,
    names: &[&'n str],
) -> Result<Option<(&'n str, Range<usize>)>, SceneError> {
    let Some((text, span)) = s.string(key)? else {
        return Ok(None);
    };
    match names.iter().find(|n| **n == text) {
        Some(n) => Ok(Some((n, span))),
        None => {
            let hint = suggest(&text, names.iter().copied())
                .map(|k| format!(" (did you mean \"{k}\"?)"))
                .unwrap_or_default();
            Err(s.error(
                &span,
                key,
                format!(
                    "is \"{}\"{hint}, which is none of {}",
                    short(&text).escape_debug(),
                    quoted(names)
                ),
            ))
        }
    }
}

fn required_string(s: &Section, key: &str, hint: &str) -> Result<String, SceneError> {
    match s.string(key)? {
        Some((text, _)) => Ok(text),
        None => Err(s.missing(key, hint)),
    }
}

/// `[x, y]`, two whole numbers.
fn pixel(s: &Section, key: &str) -> Result<Option<[u32; 2]>, SceneError> {
    let Some(value) = s.get(key) else {
        return Ok(None);
    };
    const EXPECTED: &str = "an array of 2 whole numbers [x, y]";
    let DeValue::Array(items) = value.get_ref() else {
        return Err(s.type_error(key, value, EXPECTED));
    };
    if items.len() != 2 {
        return Err(s.type_error(key, value, EXPECTED));
    }
    let mut out = [0u32; 2];
    for (o, item) in out.iter_mut().zip(items.iter()) {
        let parsed = match item.get_ref() {
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix()).ok(),
            _ => return Err(s.type_error(key, item, "a whole number")),
        };
        *o = parsed
            .and_then(|n| u32::try_from(n).ok())
            .ok_or_else(|| s.error(&item.span(), key, "must be a pixel coordinate, at least 0"))?;
    }
    Ok(Some(out))
}

fn uint_opt(
    s: &Section,
    key: &str,
    range: &std::ops::RangeInclusive<u32>,
) -> Result<Option<u32>, SceneError> {
    if s.get(key).is_none() {
        return Ok(None);
    }
    s.uint(key, 0, range).map(Some)
}

fn named<T: Choice>(s: &Section, key: &str) -> Result<Option<T>, SceneError> {
    let names: Vec<&'static str> = T::ALL.iter().map(|c| c.name()).collect();
    Ok(one_of(s, key, &names)?.and_then(|(n, _)| T::from_name(n)))
}

fn parse_lesson(
    src: &Src,
    root: &Value,
    name: &str,
    folder: Option<&Path>,
) -> Result<Lesson, SceneError> {
    let s = Section::new(src, "the lesson".into(), root, LESSON_KEYS)?;
    let title = required_string(&s, "title", "the lesson's name, shown in lists")?;
    let intro = required_string(&s, "intro", "what the lesson is about, shown first")?;
    let summary = match s.string("summary")? {
        Some((text, _)) => text,
        None => first_sentence(&intro),
    };
    let Some((scene_text, scene_span)) = s.string("scene")? else {
        return Err(s.missing(
            "scene",
            "a built-in scene such as \"default\", or a scene file's path relative to the lesson",
        ));
    };
    let scene = scene_ref(&s, &scene_text, &scene_span, folder)?;
    let Some(steps_value) = s.get("step") else {
        return Err(s.missing("step", "at least one [[step]] with its `text`"));
    };
    let DeValue::Array(items) = steps_value.get_ref() else {
        return Err(src.error(
            &steps_value.span(),
            format!(
                "`step` must be written as [[step]] (an array of tables), got {}",
                describe(steps_value.get_ref())
            ),
        ));
    };
    if items.is_empty() {
        return Err(s.error(
            &steps_value.span(),
            "step",
            "must have at least one [[step]]",
        ));
    }
    let mut steps = Vec::new();
    let mut setup = Setup::default();
    for (i, item) in items.iter().enumerate() {
        let step = parse_step(src, item, i + 1, setup)?;
        setup = step.setup;
        steps.push(step);
    }
    Ok(Lesson {
        name: name.to_string(),
        file: src.file.to_string(),
        title,
        summary,
        scene,
        intro,
        steps,
    })
}

/// A built-in scene name, or a path from the lesson's folder (a file there wins over a
/// built-in scene of the same name).
fn scene_ref(
    s: &Section,
    text: &str,
    span: &Range<usize>,
    folder: Option<&Path>,
) -> Result<SceneRef, SceneError> {
    let is_builtin = scene::builtin::NAMES.contains(&text);
    if let Some(folder) = folder {
        let path = folder.join(text);
        if path.is_file() || !is_builtin {
            if !path.is_file() {
                let hint = suggest(text, scene::builtin::NAMES.iter().copied())
                    .map(|k| format!(" (did you mean \"{k}\"?)"))
                    .unwrap_or_default();
                return Err(s.error(
                    span,
                    "scene",
                    format!(
                        "names \"{}\"{hint}, which is neither a built-in scene ({}) nor a file at {}",
                        short(text).escape_debug(),
                        quoted(scene::builtin::NAMES.iter()),
                        path.display()
                    ),
                ));
            }
            return Ok(SceneRef::File(path));
        }
    }
    if is_builtin {
        return Ok(SceneRef::Builtin(text.to_string()));
    }
    let hint = suggest(text, scene::builtin::NAMES.iter().copied())
        .map(|k| format!(" (did you mean \"{k}\"?)"))
        .unwrap_or_default();
    Err(s.error(
        span,
        "scene",
        format!(
            "names \"{}\"{hint}, which is not a built-in scene ({}); a shipped lesson uses built-in scenes only",
            short(text).escape_debug(),
            quoted(scene::builtin::NAMES.iter())
        ),
    ))
}

fn first_sentence(text: &str) -> String {
    let line = text.split_whitespace().collect::<Vec<_>>().join(" ");
    match line.find(". ") {
        Some(i) => line[..=i].to_string(),
        None => line,
    }
}

fn parse_step(src: &Src, value: &Value, number: usize, before: Setup) -> Result<Step, SceneError> {
    let s = Section::new(src, format!("step {number}"), value, STEP_KEYS)?;
    let text = required_string(&s, "text", "what the student looks at or does")?;
    let view = one_of(&s, "view", &View::ALL.map(View::name))?
        .and_then(|(n, _)| View::ALL.into_iter().find(|v| v.name() == n));
    let sets = StepState {
        select: pixel(&s, "select")?,
        max_depth: uint_opt(&s, "max_depth", &rules::DEPTH)?,
        view,
        depth_step: uint_opt(&s, "depth_step", &rules::DEPTH)?,
        play: s.boolean("play", false)?,
        offset: named::<OffsetMethod>(&s, "offset")?,
        accel: named::<AccelKind>(&s, "accel")?,
    };
    if sets.play
        && let Some(v) = s.get("depth_step")
    {
        return Err(s.error(
            &v.span(),
            "depth_step",
            "cannot be set together with `play = true` (Play steps through every depth)",
        ));
    }
    let setup = before.then(&sets);
    let task = match s.get("task") {
        None => None,
        Some(v) => Some(parse_task(src, v, number, &setup)?),
    };
    let (line, _) = src.line_col(value.span().start);
    Ok(Step {
        number,
        line,
        text,
        sets,
        setup,
        task,
    })
}

fn parse_task(src: &Src, value: &Value, number: usize, setup: &Setup) -> Result<Task, SceneError> {
    let what = format!("step {number} task");
    // The kind decides the other keys.
    let all: Vec<&str> = [PIXEL_KEYS, CONTROL_KEYS, VALUE_KEYS, CHOICE_KEYS].concat();
    let probe = Section::new(src, what.clone(), value, &all)?;
    let Some((kind, _)) = one_of(&probe, "kind", TASK_KINDS)? else {
        return Err(probe.missing("kind", "\"pixel\", \"control\", \"value\" or \"choice\""));
    };
    let keys = match kind {
        "pixel" => PIXEL_KEYS,
        "control" => CONTROL_KEYS,
        "value" => VALUE_KEYS,
        _ => CHOICE_KEYS,
    };
    let s = Section::new(src, format!("{what} ({kind})"), value, keys)?;
    let hint = required_string(&s, "hint", "shown when the answer is wrong")?;
    let prompt = s.string("prompt")?.map(|(t, _)| t);
    // Value and choice tasks read the tree of their `pixel`, or else of the selected one.
    let task_pixel = |s: &Section| -> Result<[u32; 2], SceneError> {
        match pixel(s, "pixel")?.or(setup.select) {
            Some(p) => Ok(p),
            None => Err(s.missing(
                "pixel",
                "the pixel whose tree it is about, unless this or an earlier step sets `select`",
            )),
        }
    };
    let node = |s: &Section| -> Result<NodeRef, SceneError> {
        match s.string("node")? {
            None => Ok(NodeRef::primary()),
            Some((text, span)) => NodeRef::parse(&text).ok_or_else(|| {
                s.error(
                    &span,
                    "node",
                    format!(
                        "is \"{}\", not a node path such as \"primary\", \"primary/R\" or \"primary/T/T\"",
                        short(&text).escape_debug()
                    ),
                )
            }),
        }
    };
    let kind = match kind {
        "pixel" => TaskKind::Pixel { goal: goal(&s)? },
        "control" => {
            let Some((control, span)) = one_of(&s, "control", CONTROLS)? else {
                return Err(s.missing("control", &format!("one of {}", quoted(CONTROLS))));
            };
            let material = s.string("material")?;
            let needs_material = matches!(control, "reflectivity" | "transparency" | "ior");
            let control = match (control, material) {
                ("max_depth", None) => Control::MaxDepth,
                ("cutoff", None) => Control::Cutoff,
                ("offset", None) => Control::Offset,
                ("reflectivity", Some((m, _))) => Control::Reflectivity(m),
                ("transparency", Some((m, _))) => Control::Transparency(m),
                ("ior", Some((m, _))) => Control::Ior(m),
                (c, None) if needs_material => {
                    return Err(s.error(
                        &span,
                        "control",
                        format!("is \"{c}\", which needs the `material` it changes"),
                    ));
                }
                (c, _) => {
                    let span = s.get("material").map_or(span, |v| v.span());
                    return Err(s.error(
                        &span,
                        "material",
                        format!("does not apply to the control \"{c}\""),
                    ));
                }
            };
            let Some(pixel) = pixel(&s, "pixel")?.or(setup.select) else {
                return Err(s.missing(
                    "pixel",
                    "the pixel whose tree must change, unless a step sets `select`",
                ));
            };
            TaskKind::Control {
                control,
                pixel,
                goal: goal(&s)?,
            }
        }
        "value" => {
            let Some((q, _)) = one_of(&s, "quantity", &Quantity::ALL.map(Quantity::name))? else {
                return Err(s.missing(
                    "quantity",
                    &format!("one of {}", quoted(Quantity::ALL.map(Quantity::name))),
                ));
            };
            let quantity = Quantity::from_name(q).unwrap_or(Quantity::Local);
            let channel = match (s.get("channel"), s.get("component")) {
                (Some(v), _) if !quantity.has_channel() => {
                    return Err(s.error(
                        &v.span(),
                        "channel",
                        format!("does not apply to the quantity \"{q}\""),
                    ));
                }
                (_, Some(v)) if quantity != Quantity::Barycentric => {
                    return Err(s.error(
                        &v.span(),
                        "component",
                        format!("applies only to \"barycentric\", not to \"{q}\""),
                    ));
                }
                (Some(_), _) => match one_of(&s, "channel", &["r", "g", "b"])? {
                    Some(("g", _)) => 1,
                    Some(("b", _)) => 2,
                    _ => 0,
                },
                (_, Some(_)) => s.uint("component", 1, &(1..=3))? as usize - 1,
                (None, None) if quantity == Quantity::Barycentric => {
                    return Err(s.missing("component", "1, 2 or 3: which barycentric coordinate"));
                }
                (None, None) => 0,
            };
            let light = s.string("light")?;
            if let (Some((_, span)), false) = (&light, quantity.has_light()) {
                return Err(s.error(
                    span,
                    "light",
                    format!("does not apply to the quantity \"{q}\""),
                ));
            }
            let tolerance = s.f32("tolerance", 0.01)?;
            if !(tolerance.is_finite() && tolerance > 0.0) {
                let span = s.get("tolerance").map_or(s.span.clone(), |v| v.span());
                return Err(s.error(&span, "tolerance", "must be a number greater than 0"));
            }
            TaskKind::Value {
                pixel: task_pixel(&s)?,
                node: node(&s)?,
                quantity,
                channel,
                light: light.map(|(l, _)| l),
                tolerance: f64::from(tolerance),
            }
        }
        _ => {
            let Some((q, qspan)) = one_of(&s, "question", QUESTIONS)? else {
                return Err(s.missing("question", &format!("one of {}", quoted(QUESTIONS))));
            };
            let options = string_list(&s, "options")?;
            let light = s.string("light")?;
            if let (Some((_, span)), false) = (&light, q == "shadow") {
                return Err(s.error(span, "light", "applies only to the question \"shadow\""));
            }
            let answer = s.get("answer");
            let question = match q {
                "object" | "fixed" => {
                    let Some(options) = options else {
                        return Err(s.missing("options", "the answers to choose from, as strings"));
                    };
                    if options.len() < 2 {
                        let span = s.get("options").map_or(qspan, |v| v.span());
                        return Err(s.error(&span, "options", "must offer at least 2 answers"));
                    }
                    if q == "object" {
                        if let Some(v) = answer {
                            return Err(s.error(
                                &v.span(),
                                "answer",
                                "is computed from the tree for the question \"object\"; remove it",
                            ));
                        }
                        Question::Object { options }
                    } else {
                        let Some(_) = answer else {
                            return Err(
                                s.missing("answer", "the number (1, 2, ...) of the right option")
                            );
                        };
                        let n = options.len() as u32;
                        let answer = s.uint("answer", 1, &(1..=n))? as usize - 1;
                        Question::Fixed { options, answer }
                    }
                }
                _ => {
                    for key in ["options", "answer"] {
                        if let Some(v) = s.get(key) {
                            return Err(s.error(
                                &v.span(),
                                key,
                                format!(
                                    "does not apply to the question \"{q}\": its options and answer come from the tree"
                                ),
                            ));
                        }
                    }
                    match q {
                        "end" => Question::End,
                        "shadow" => Question::Shadow {
                            light: light.map(|(l, _)| l),
                        },
                        _ => Question::Children,
                    }
                }
            };
            let (pixel, node) = if matches!(question, Question::Fixed { .. }) {
                (
                    pixel(&s, "pixel")?.or(setup.select).unwrap_or([0, 0]),
                    node(&s)?,
                )
            } else {
                (task_pixel(&s)?, node(&s)?)
            };
            TaskKind::Choice {
                pixel,
                node,
                question,
            }
        }
    };
    Ok(Task { kind, prompt, hint })
}

fn string_list(s: &Section, key: &str) -> Result<Option<Vec<String>>, SceneError> {
    let Some(value) = s.get(key) else {
        return Ok(None);
    };
    let DeValue::Array(items) = value.get_ref() else {
        return Err(s.type_error(key, value, "an array of strings"));
    };
    let mut out = Vec::new();
    for item in items.iter() {
        match item.get_ref() {
            DeValue::String(t) if !t.trim().is_empty() => out.push(t.to_string()),
            DeValue::String(_) => {
                return Err(s.error(&item.span(), key, "must not hold an empty string"));
            }
            _ => return Err(s.type_error(key, item, "a string")),
        }
    }
    Ok(Some(out))
}

fn goal(s: &Section) -> Result<Goal, SceneError> {
    let names = Event::ALL.map(Event::name);
    let Some((event, _)) = one_of(s, "event", &names)? else {
        return Err(s.missing("event", &format!("one of {}", quoted(names))));
    };
    let ray = one_of(s, "ray", &["primary", "reflected", "refracted"])?.map(|(r, _)| match r {
        "primary" => RayKind::Primary,
        "reflected" => RayKind::Reflected,
        _ => RayKind::Refracted,
    });
    Ok(Goal {
        event: Event::from_name(event).unwrap_or(Event::Hit),
        object: s.string("object")?.map(|(o, _)| o),
        ray,
        present: s.boolean("present", true)?,
    })
}

/// Whether the hit `name` (as the tree names it) is the object `want`: the same name, or a
/// part of the mesh `want` (`"kitchen: Cabinet_3"` is part of `"kitchen"`).
pub fn names_object(name: &str, want: &str) -> bool {
    name == want
        || name
            .strip_prefix(want)
            .is_some_and(|rest| rest.starts_with(": "))
}

/// Why a ray ended without being shaded, in the lecture's words.
pub fn end_phrase(end: Option<EndReason>) -> &'static str {
    match end {
        None => "it hits a surface and is shaded",
        Some(EndReason::NoHit) => "no intersection: it hits nothing",
        Some(EndReason::HitLight) => "it hits a light source",
        Some(EndReason::MaxDepth) => "it reaches the maximum depth",
        Some(EndReason::Cutoff) => "its weight is below the cutoff",
        Some(EndReason::Budget) => "the pixel's ray budget is used up",
    }
}
