//! Strict TOML scene loading (SPEC §3): the file format's sections and keys, their defaults,
//! and every check a scene must pass before it reaches the tracer (finite numbers, positive
//! radii, known materials, a usable camera). The hot loop never validates anything, so this
//! module is where bad data stops.
//!
//! The document is parsed with `toml`'s spanned document tree ([`DeTable`]) rather than with
//! derived `Deserialize` impls: walking the tree by hand knows which section and field each
//! value belongs to, so every error is one sentence `FILE:LINE:COLUMN: what field `key` ...`
//! (serde's messages do not name the field of a wrong type, and `deny_unknown_fields` cannot
//! suggest the key that was meant). Unknown keys and sections are still errors.
//!
//! Mesh files are read through a resolver ([`ResolveFn`]) so that built-in scenes can take
//! their OBJ and MTL text from strings compiled into the binary.

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::Vec3;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::obj::{self, MeshPlacement};
use super::{
    Camera, Light, Material, MaterialId, Object, ObjectId, ObjectSource, RenderParams, Scene,
    Shading, Sphere, Triangle,
};

/// A scene that could not be loaded: one sentence naming the file, the place and the field.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct SceneError(pub String);

/// Returns the text of a mesh or material library, given its path as written in the scene
/// (relative to the scene file's folder), or the reason it cannot, as a short phrase.
pub type ResolveFn<'a> = dyn Fn(&str) -> Result<String, String> + 'a;

/// Loads a `.toml` scene or a bare `.obj` mesh (chosen by the extension, in any case). Meshes
/// and material libraries are resolved relative to the file's folder. Sets [`Scene::source`].
pub fn load_scene_file(path: &Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let is_obj = match extension.as_deref() {
        Some("toml") => false,
        Some("obj") => true,
        _ => {
            return Err(SceneError(format!(
                "{file}: cannot open this kind of file; a scene is a `.toml` file or a bare `.obj` mesh."
            )));
        }
    };
    let max_bytes = if is_obj {
        MAX_MESH_FILE_BYTES
    } else {
        MAX_SCENE_FILE_BYTES
    };
    let text = read_text(path, max_bytes)
        .map_err(|reason| SceneError(format!("{file}: cannot read the scene file: {reason}.")))?;
    let folder = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let resolve = fs_resolver(folder);
    let mut scene = if is_obj {
        let key = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| file.clone());
        obj::load_obj_scene(&text, &file, &key, &resolve)?
    } else {
        load_scene_str_with(&text, &file, &resolve)?
    };
    scene.source = Some(path.to_path_buf());
    Ok(scene)
}

/// Parses scene TOML; `name` stands for the file in messages. Meshes are resolved relative to
/// the current directory.
pub fn load_scene_str(text: &str, name: &str) -> Result<Scene, SceneError> {
    load_scene_str_with(text, name, &fs_resolver(PathBuf::new()))
}

/// Parses scene TOML, reading meshes and material libraries through `resolve`.
pub fn load_scene_str_with(
    text: &str,
    name: &str,
    resolve: &ResolveFn<'_>,
) -> Result<Scene, SceneError> {
    let src = Src { file: name, text };
    let root = DeTable::parse(text).map_err(|e| syntax_error(&src, &e))?;
    SceneBuilder {
        src: &src,
        resolve,
        scene: Scene::default(),
        user_materials: HashMap::new(),
    }
    .build(root.get_ref())
}

/// A resolver reading files relative to `folder`.
pub fn fs_resolver(folder: PathBuf) -> impl Fn(&str) -> Result<String, String> {
    move |path: &str| {
        read_text(&folder.join(path), MAX_MESH_FILE_BYTES)
            .map_err(|reason| format!("{}: {reason}", short_path(path)))
    }
}

/// Largest scene (`.toml`) file read. Hand-written and exported scenes are kilobytes; the TOML
/// tree takes several times the text, so the cap also bounds the parser's memory.
pub const MAX_SCENE_FILE_BYTES: u64 = 64 << 20;

/// Largest OBJ or MTL file read: about 20 million triangles of OBJ text. The memory a mesh
/// needs is estimated from its counts before it is parsed (see `obj`); this cap comes first,
/// so that a huge or endless file is refused before it is read at all.
pub const MAX_MESH_FILE_BYTES: u64 = 512 << 20;

/// Reads a text file of at most `max_bytes`, tolerating stray non-UTF-8 bytes (old MTL files
/// carry Latin-1 comments). Only regular files are read: a device such as `/dev/zero` or a
/// pipe would never end (or block), and a folder is never what was meant.
fn read_text(path: &Path, max_bytes: u64) -> Result<String, String> {
    use std::io::Read;
    let meta = std::fs::metadata(path).map_err(|e| os_reason(&e))?;
    if meta.is_dir() {
        return Err("it is a folder, not a file".into());
    }
    if !meta.is_file() {
        return Err("it is not a regular file (a device, a pipe or a socket)".into());
    }
    let too_big = |size: u64| {
        format!(
            "it is {}, more than the {} a file may have",
            crate::render::format_bytes(size),
            crate::render::format_bytes(max_bytes)
        )
    };
    if meta.len() > max_bytes {
        return Err(too_big(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(|e| os_reason(&e))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // `take` also stops a file that grows while it is read.
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| os_reason(&e))?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_big(bytes.len() as u64));
    }
    // Valid UTF-8 is taken as it is, without the copy `from_utf8_lossy` would make.
    Ok(String::from_utf8(bytes)
        .unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned()))
}

/// The OS's reason without the platform-specific "(os error N)" tail, for stable messages.
fn os_reason(e: &std::io::Error) -> String {
    let text = e.to_string();
    match text.find(" (os error") {
        Some(i) => text[..i].to_string(),
        None => text,
    }
}

/// The scene text and its name, to turn byte offsets into `FILE:LINE:COLUMN`.
pub(crate) struct Src<'a> {
    pub file: &'a str,
    pub text: &'a str,
}

impl Src<'_> {
    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &self.text[..offset];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let line = before.matches('\n').count() + 1;
        let column = before[line_start..].chars().count() + 1;
        (line, column)
    }

    /// An error at `span`: `FILE:LINE:COLUMN: message.`
    pub fn error(&self, span: &Range<usize>, message: impl AsRef<str>) -> SceneError {
        let (line, column) = self.line_col(span.start);
        SceneError(format!(
            "{}:{line}:{column}: {}",
            self.file,
            sentence(message.as_ref())
        ))
    }

    /// The source text of a value, as the user wrote it, for "got ..." in messages.
    /// At most 40 characters of it, so that a message stays a sentence.
    fn slice(&self, span: &Range<usize>) -> String {
        short(self.text.get(span.clone()).unwrap_or("?"))
    }
}

/// Makes one sentence of a message: one line, ending in a full stop.
pub(crate) fn sentence(message: &str) -> String {
    let mut s: String = message
        .trim()
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    if !s.ends_with(['.', '?', '!']) {
        s.push('.');
    }
    s
}

fn syntax_error(src: &Src, e: &toml::de::Error) -> SceneError {
    let span = e.span().unwrap_or(0..0);
    let mut reason = e.message().to_string();
    if reason == "duplicate key" {
        reason = format!("duplicate key `{}`", src.slice(&span));
    }
    src.error(&span, format!("TOML syntax error: {reason}"))
}

/// "a string", "an array of 2 items", ...: what a value is, for type errors.
fn describe(value: &DeValue) -> String {
    match value {
        DeValue::String(s) => format!("the string \"{}\"", short(s).escape_debug()),
        DeValue::Integer(_) => "an integer".into(),
        DeValue::Float(_) => "a float".into(),
        DeValue::Boolean(b) => format!("the boolean {b}"),
        DeValue::Datetime(_) => "a date-time".into(),
        DeValue::Array(a) => match a.len() {
            0 => "an empty array".into(),
            1 => "an array of 1 item".into(),
            n => format!("an array of {n} items"),
        },
        DeValue::Table(_) => "a table".into(),
    }
}

/// At most 40 characters of user text, so that a message stays a sentence.
pub(crate) fn short(text: &str) -> String {
    match text.char_indices().nth(40) {
        Some((i, _)) => format!("{}…", &text[..i]),
        None => text.to_string(),
    }
}

/// A path as written, cut to its last 80 characters: the file name is the part that matters.
pub(crate) fn short_path(path: &str) -> String {
    let count = path.chars().count();
    if count <= 80 {
        return path.to_string();
    }
    let tail: String = path.chars().skip(count - 79).collect();
    format!("…{tail}")
}

/// The closest of `known` to `word` if it is a plausible typo, for "did you mean" hints.
pub(crate) fn suggest<'k>(word: &str, known: impl IntoIterator<Item = &'k str>) -> Option<&'k str> {
    let word = word.to_ascii_lowercase();
    known
        .into_iter()
        .map(|k| (edit_distance(&word, &k.to_ascii_lowercase()), k))
        .filter(|&(d, k)| d <= 2.max(k.len() / 4) && d < k.len())
        .min_by_key(|&(d, _)| d)
        .map(|(_, k)| k)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = (diagonal + usize::from(ca != cb))
                .min(row[j] + 1)
                .min(above + 1);
            diagonal = above;
        }
    }
    row[b.len()]
}

/// `a`, `b` and `c` (each already formatted).
pub(crate) fn list_and(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// A check on one number after it is known to be finite: `None` if fine, else the phrase.
type Rule = fn(f32) -> Option<&'static str>;

const ANY: Rule = |_| None;
const NON_NEGATIVE: Rule = |x| (x < 0.0).then_some("must be at least 0");
const POSITIVE: Rule = |x| (x <= 0.0).then_some("must be greater than 0");
const NON_ZERO: Rule = |x| (x == 0.0).then_some("must not be 0");
/// Positions (and radii) must lie within this distance of the origin. The BVH's traversal is
/// exact only for scenes below about 1e17 in size (`accel/bvh.rs`), its build overflows to NaN
/// near `f32::MAX` (a mesh moved to x = 3e38 made it panic: `found_bvh_far.toml`), and at 1e15
/// an `f32` already cannot tell apart points 1e8 apart, so no meaningful scene is larger.
pub const MAX_COORDINATE: f32 = 1e15;
const COORDINATE: Rule = |x| {
    (x.abs() > MAX_COORDINATE).then_some("must be within ±1e15 (raytree's limit on scene size)")
};
const RADIUS: Rule = |x| match POSITIVE(x) {
    Some(problem) => Some(problem),
    None => COORDINATE(x),
};
const LIGHT_RADIUS: Rule = |x| match NON_NEGATIVE(x) {
    Some(problem) => Some(problem),
    None => COORDINATE(x),
};
const FOV: Rule =
    |x| (x <= 0.0 || x >= 180.0).then_some("must be between 0 and 180 degrees (both excluded)");

type Value<'i> = Spanned<DeValue<'i>>;

/// One table of the scene (`[render]`, the second `[[sphere]]`, ...) with what to call it in
/// messages ("render", "sphere 2").
struct Section<'s, 't, 'i> {
    src: &'s Src<'s>,
    what: String,
    table: &'t DeTable<'i>,
    span: Range<usize>,
}

impl<'s, 't, 'i> Section<'s, 't, 'i> {
    /// Checks that `value` is a table with only `keys` in it.
    fn new(
        src: &'s Src<'s>,
        what: String,
        value: &'t Value<'i>,
        keys: &[&str],
    ) -> Result<Self, SceneError> {
        let DeValue::Table(table) = value.get_ref() else {
            return Err(src.error(
                &value.span(),
                format!("{what} must be a table, got {}", describe(value.get_ref())),
            ));
        };
        for (key, _) in table.iter() {
            let key_text = key.get_ref().as_ref();
            if !keys.contains(&key_text) {
                let hint = suggest(key_text, keys.iter().copied())
                    .map(|k| format!(" (did you mean `{k}`?)"))
                    .unwrap_or_default();
                let known: Vec<String> = keys.iter().map(|k| format!("`{k}`")).collect();
                return Err(src.error(
                    &key.span(),
                    format!(
                        "{what} has an unknown field `{}`{hint}; its fields are {}",
                        short(key_text),
                        list_and(&known)
                    ),
                ));
            }
        }
        Ok(Self {
            src,
            what,
            table,
            span: value.span(),
        })
    }

    fn get(&self, key: &str) -> Option<&'t Value<'i>> {
        self.table
            .iter()
            .find(|(k, _)| k.get_ref().as_ref() == key)
            .map(|(_, v)| v)
    }

    fn error(&self, span: &Range<usize>, key: &str, phrase: impl AsRef<str>) -> SceneError {
        self.src.error(
            span,
            format!("{} field `{key}` {}", self.what, phrase.as_ref()),
        )
    }

    fn type_error(&self, key: &str, value: &Value, expected: &str) -> SceneError {
        self.error(
            &value.span(),
            key,
            format!("must be {expected}, got {}", describe(value.get_ref())),
        )
    }

    fn missing(&self, key: &str, hint: &str) -> SceneError {
        self.src.error(
            &self.span,
            format!("{} is missing the field `{key}` ({hint})", self.what),
        )
    }

    /// A number (integer or float), finite and passing `rule`; `expected` is for type errors.
    fn number(
        &self,
        key: &str,
        value: &Value,
        rule: Rule,
        expected: &str,
    ) -> Result<f32, SceneError> {
        let span = value.span();
        let parsed = match value.get_ref() {
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|i| i as f32),
            DeValue::Float(f) => f.as_str().parse::<f32>().ok(),
            _ => return Err(self.type_error(key, value, expected)),
        };
        let x = parsed.ok_or_else(|| {
            self.error(
                &span,
                key,
                format!("is not a number I can read, got {}", self.src.slice(&span)),
            )
        })?;
        let problem = if x.is_finite() {
            rule(x)
        } else {
            Some("must be finite")
        };
        match problem {
            Some(phrase) => Err(self.error(
                &span,
                key,
                format!("{phrase}, got {}", self.src.slice(&span)),
            )),
            None => Ok(x),
        }
    }

    fn f32(&self, key: &str, default: f32, rule: Rule) -> Result<f32, SceneError> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => self.number(key, v, rule, "a number"),
        }
    }

    /// `[x, y, z]` from an array value.
    fn vec3_of(&self, key: &str, value: &Value, rule: Rule) -> Result<Vec3, SceneError> {
        const EXPECTED: &str = "an array of 3 numbers [x, y, z]";
        let DeValue::Array(items) = value.get_ref() else {
            return Err(self.type_error(key, value, EXPECTED));
        };
        if items.len() != 3 {
            return Err(self.type_error(key, value, EXPECTED));
        }
        let mut out = [0.0; 3];
        for (o, item) in out.iter_mut().zip(items.iter()) {
            *o = self.number(key, item, rule, "a number")?;
        }
        Ok(Vec3::from_array(out))
    }

    fn vec3(&self, key: &str, default: Vec3, rule: Rule) -> Result<Vec3, SceneError> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => self.vec3_of(key, v, rule),
        }
    }

    /// A scalar (all three channels or axes alike) or an array of three.
    fn scalar_or_vec3(
        &self,
        key: &str,
        default: Vec3,
        rule: Rule,
        expected: &str,
    ) -> Result<Vec3, SceneError> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => match v.get_ref() {
                DeValue::Integer(_) | DeValue::Float(_) => {
                    Ok(Vec3::splat(self.number(key, v, rule, expected)?))
                }
                DeValue::Array(items) if items.len() == 3 => self.vec3_of(key, v, rule),
                _ => Err(self.type_error(key, v, expected)),
            },
        }
    }

    fn color(&self, key: &str, default: Vec3, rule: Rule) -> Result<Vec3, SceneError> {
        self.scalar_or_vec3(key, default, rule, "a number or an array [r, g, b]")
    }

    /// A whole number in `lo..=hi`.
    fn uint(&self, key: &str, default: u32, lo: u32, hi: u32) -> Result<u32, SceneError> {
        let Some(value) = self.get(key) else {
            return Ok(default);
        };
        let span = value.span();
        let DeValue::Integer(i) = value.get_ref() else {
            return Err(self.type_error(key, value, "a whole number"));
        };
        let parsed = i64::from_str_radix(i.as_str(), i.radix()).ok();
        match parsed.and_then(|n| u32::try_from(n).ok()) {
            Some(n) if (lo..=hi).contains(&n) => Ok(n),
            _ => {
                let phrase = match parsed {
                    Some(n) if n > i64::from(hi) && lo == 0 => format!("must be at most {hi}"),
                    Some(n) if n < i64::from(lo) && hi == u32::MAX => {
                        format!("must be at least {lo}")
                    }
                    _ => format!("must be between {lo} and {hi}"),
                };
                Err(self.error(
                    &span,
                    key,
                    format!("{phrase}, got {}", self.src.slice(&span)),
                ))
            }
        }
    }

    /// A string value with its span, or `None` when absent. Empty strings are errors.
    fn string(&self, key: &str) -> Result<Option<(String, Range<usize>)>, SceneError> {
        let Some(value) = self.get(key) else {
            return Ok(None);
        };
        let DeValue::String(s) = value.get_ref() else {
            return Err(self.type_error(key, value, "a string"));
        };
        if s.trim().is_empty() {
            return Err(self.error(&value.span(), key, "must not be empty"));
        }
        Ok(Some((s.to_string(), value.span())))
    }
}

const SECTIONS: &[&str] = &[
    "render", "camera", "light", "material", "sphere", "triangle", "mesh",
];
const RENDER_KEYS: &[&str] = &[
    "width",
    "height",
    "max_depth",
    "samples",
    "background",
    "ambient_light",
    "shading",
];
const CAMERA_KEYS: &[&str] = &["position", "look_at", "up", "fov_y"];
const LIGHT_KEYS: &[&str] = &["name", "position", "color", "radius"];
const MATERIAL_KEYS: &[&str] = &[
    "name",
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "reflectivity",
    "transparency",
    "ior",
];
const SPHERE_KEYS: &[&str] = &["name", "center", "radius", "material"];
const TRIANGLE_KEYS: &[&str] = &["name", "vertices", "material"];
const MESH_KEYS: &[&str] = &["name", "file", "material", "translate", "rotate", "scale"];

/// The limits of SPEC §3, also used by other code that edits scenes.
pub const MAX_IMAGE_SIZE: u32 = 16384;
pub const MAX_SAMPLES: u32 = 65536;
pub const MAX_DEPTH_LIMIT: u32 = 64;

/// `[section]` or `[[section]]`, as written in the format.
fn section_syntax(name: &str) -> String {
    if matches!(name, "render" | "camera") {
        format!("[{name}]")
    } else {
        format!("[[{name}]]")
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Sphere,
    Triangle,
    Mesh,
}

impl Kind {
    fn label(self) -> &'static str {
        match self {
            Kind::Sphere => "sphere",
            Kind::Triangle => "triangle",
            Kind::Mesh => "mesh",
        }
    }
}

struct SceneBuilder<'a> {
    src: &'a Src<'a>,
    resolve: &'a ResolveFn<'a>,
    scene: Scene,
    /// The `[[material]]` entries by name (MTL materials are not referable by name).
    user_materials: HashMap<String, MaterialId>,
}

/// Every top-level key must be a known section of the right shape (`[render]` a table,
/// `[[sphere]]` an array of tables).
fn check_sections(src: &Src, root: &DeTable) -> Result<(), SceneError> {
    for (key, value) in root.iter() {
        let name = key.get_ref().as_ref();
        if !SECTIONS.contains(&name) {
            let home = [("render", RENDER_KEYS), ("camera", CAMERA_KEYS)]
                .into_iter()
                .find(|(_, keys)| keys.contains(&name));
            let hint = match home {
                Some((section, _)) => format!(" (it belongs under [{section}])"),
                None => suggest(name, SECTIONS.iter().copied())
                    .map(|s| format!(" (did you mean `{}`?)", section_syntax(s)))
                    .unwrap_or_default(),
            };
            let what = match value.get_ref() {
                DeValue::Table(_) | DeValue::Array(_) => "unknown section",
                _ => "unknown top-level key",
            };
            let listed: Vec<String> = SECTIONS.iter().map(|s| section_syntax(s)).collect();
            return Err(src.error(
                &key.span(),
                format!(
                    "{what} `{}`{hint}; the sections are {}",
                    short(name),
                    list_and(&listed)
                ),
            ));
        }
        let wants_table = matches!(name, "render" | "camera");
        let shape_ok = match value.get_ref() {
            DeValue::Table(_) => wants_table,
            DeValue::Array(_) => !wants_table,
            _ => false,
        };
        if !shape_ok {
            let shape = if wants_table {
                "a table"
            } else {
                "an array of tables"
            };
            return Err(src.error(
                &value.span(),
                format!(
                    "`{name}` must be written as {} ({shape}), got {}",
                    section_syntax(name),
                    describe(value.get_ref())
                ),
            ));
        }
    }
    Ok(())
}

/// The names of `sections` (their `name` keys, unique), with `default(i)` for the others,
/// stepping around the names given explicitly.
fn unique_names(
    sections: &[&Section],
    kind: &str,
    default: impl Fn(usize) -> Result<String, SceneError>,
) -> Result<Vec<String>, SceneError> {
    let mut names = Names::default();
    let mut given = Vec::with_capacity(sections.len());
    for s in sections {
        let name = s.string("name")?;
        if let Some((name, span)) = &name {
            names.claim(s, name, span, kind)?;
        }
        given.push(name.map(|(name, _)| name));
    }
    given
        .into_iter()
        .enumerate()
        .map(|(i, name)| match name {
            Some(name) => Ok(name),
            None => Ok(names.fresh(&default(i)?)),
        })
        .collect()
}

impl SceneBuilder<'_> {
    fn build(mut self, root: &DeTable) -> Result<Scene, SceneError> {
        let src = self.src;
        check_sections(src, root)?;
        let get = |name: &str| {
            root.iter()
                .find(|(k, _)| k.get_ref().as_ref() == name)
                .map(|(_, v)| v)
        };
        let sections = |name: &str, keys: &[&str]| -> Result<Vec<Section>, SceneError> {
            let Some(DeValue::Array(items)) = get(name).map(|v| v.get_ref()) else {
                return Ok(Vec::new());
            };
            let what = |i: usize| format!("{name} {}", i + 1);
            items
                .iter()
                .enumerate()
                .map(|(i, v)| Section::new(src, what(i), v, keys))
                .collect()
        };

        if let Some(v) = get("render") {
            let section = Section::new(src, "render".into(), v, RENDER_KEYS)?;
            self.scene.render = parse_render(&section)?;
        }
        if let Some(v) = get("camera") {
            let section = Section::new(src, "camera".into(), v, CAMERA_KEYS)?;
            self.scene.camera = parse_camera(&section)?;
        }

        let lights = sections("light", LIGHT_KEYS)?;
        let refs: Vec<&Section> = lights.iter().collect();
        let names = unique_names(&refs, "light", |i| Ok(format!("light {}", i + 1)))?;
        for (s, name) in lights.iter().zip(names) {
            self.scene.lights.push(Light {
                name,
                // Without a position, a headlight: a light at the eye.
                position: s.vec3("position", self.scene.camera.position, COORDINATE)?,
                color: s.color("color", Vec3::ONE, NON_NEGATIVE)?,
                radius: s.f32("radius", 0.0, LIGHT_RADIUS)?,
            });
        }

        let materials = sections("material", MATERIAL_KEYS)?;
        let refs: Vec<&Section> = materials.iter().collect();
        let names = unique_names(&refs, "material", |i| Ok(format!("material {}", i + 1)))?;
        for (s, name) in materials.iter().zip(names) {
            let id = MaterialId(self.scene.materials.len() as u32);
            self.user_materials.insert(name.clone(), id);
            self.scene.materials.push(parse_material(s, name)?);
        }

        // Objects keep the order of the file, whatever their kind, so ids and names follow
        // what the author wrote.
        let mut objects: Vec<(Kind, Section)> = Vec::new();
        for (kind, keys) in [
            (Kind::Sphere, SPHERE_KEYS),
            (Kind::Triangle, TRIANGLE_KEYS),
            (Kind::Mesh, MESH_KEYS),
        ] {
            objects.extend(sections(kind.label(), keys)?.into_iter().map(|s| (kind, s)));
        }
        objects.sort_by_key(|(_, s)| s.span.start);
        let refs: Vec<&Section> = objects.iter().map(|(_, s)| s).collect();
        let names = unique_names(&refs, "object", |i| {
            let (kind, s) = &objects[i];
            default_object_name(*kind, s)
        })?;
        for ((kind, s), name) in objects.iter().zip(names) {
            let object = ObjectId(self.scene.objects.len() as u32);
            match kind {
                Kind::Sphere => self.add_sphere(s, name, object)?,
                Kind::Triangle => self.add_triangle(s, name, object)?,
                Kind::Mesh => self.add_mesh(s, name, object)?,
            }
        }
        Ok(self.scene)
    }

    /// The material named by `key`, or the shared default material when the key is absent.
    fn material(&mut self, s: &Section, key: &str) -> Result<MaterialId, SceneError> {
        let Some((name, span)) = s.string(key)? else {
            return Ok(default_material(&mut self.scene));
        };
        if let Some(&id) = self.user_materials.get(&name) {
            return Ok(id);
        }
        if name == "default" {
            return Ok(default_material(&mut self.scene));
        }
        let mut known: Vec<&str> = self
            .scene
            .materials
            .iter()
            .filter(|m| self.user_materials.contains_key(&m.name))
            .map(|m| m.name.as_str())
            .collect();
        let hint = suggest(&name, known.iter().copied())
            .map(|k| format!(" (did you mean \"{k}\"?)"))
            .unwrap_or_default();
        let listing = match known.len() {
            0 => "no [[material]] is defined".to_string(),
            1..=12 => {
                known.push("default");
                let quoted: Vec<String> = known.iter().map(|k| format!("\"{k}\"")).collect();
                format!("the known materials are {}", list_and(&quoted))
            }
            n => format!("{n} materials are defined"),
        };
        Err(s.error(
            &span,
            key,
            format!(
                "names an unknown material \"{}\"{hint}; {listing}",
                short(&name).escape_debug()
            ),
        ))
    }

    fn add_sphere(
        &mut self,
        s: &Section,
        name: String,
        object: ObjectId,
    ) -> Result<(), SceneError> {
        let center = s.vec3("center", Vec3::ZERO, COORDINATE)?;
        let radius = s.f32("radius", 1.0, RADIUS)?;
        let material = self.material(s, "material")?;
        self.scene.objects.push(Object {
            name,
            source: ObjectSource::Sphere,
        });
        self.scene.spheres.push(Sphere {
            center,
            radius,
            material,
            object,
        });
        Ok(())
    }

    fn add_triangle(
        &mut self,
        s: &Section,
        name: String,
        object: ObjectId,
    ) -> Result<(), SceneError> {
        const EXPECTED: &str = "an array of 3 corners [[x, y, z], [x, y, z], [x, y, z]]";
        let Some(value) = s.get("vertices") else {
            return Err(s.missing(
                "vertices",
                "three [x, y, z] corners, counter-clockwise seen from the front",
            ));
        };
        let corners = match value.get_ref() {
            DeValue::Array(items) if items.len() == 3 => items,
            _ => return Err(s.type_error("vertices", value, EXPECTED)),
        };
        let mut vertices = [Vec3::ZERO; 3];
        for (v, corner) in vertices.iter_mut().zip(corners.iter()) {
            *v = s.vec3_of("vertices", corner, COORDINATE)?;
        }
        if !obj::is_visible_triangle(&vertices) {
            return Err(s.error(
                &value.span(),
                "vertices",
                "gives a triangle of zero area, which would never be seen",
            ));
        }
        let material = self.material(s, "material")?;
        self.scene.objects.push(Object {
            name,
            source: ObjectSource::Triangle,
        });
        self.scene.triangles.push(Triangle {
            vertices,
            material,
            object,
        });
        Ok(())
    }

    fn add_mesh(&mut self, s: &Section, name: String, object: ObjectId) -> Result<(), SceneError> {
        let Some((file, file_span)) = s.string("file")? else {
            return Err(s.missing("file", "an OBJ path relative to the scene file"));
        };
        // Only OBJ files are meshes: a scene (or anything else) named here would be read as
        // OBJ text and make no sense, and scenes never include scenes, so there are no cycles.
        if !obj::is_obj_path(&file) {
            return Err(s.error(
                &file_span,
                "file",
                format!(
                    "must name an OBJ file (ending in `.obj`), got \"{}\"",
                    short_path(&file).escape_debug()
                ),
            ));
        }
        let override_name = s.string("material")?.map(|(n, _)| n);
        let material_override = match override_name {
            Some(_) => Some(self.material(s, "material")?),
            None => None,
        };
        let placement = MeshPlacement {
            translate: s.vec3("translate", Vec3::ZERO, COORDINATE)?,
            rotate_deg: s.vec3("rotate", Vec3::ZERO, ANY)?,
            scale: s.scalar_or_vec3(
                "scale",
                Vec3::ONE,
                NON_ZERO,
                "a number or an array [x, y, z]",
            )?,
        };
        let cannot =
            |problem: String| s.error(&file_span, "file", format!("cannot be loaded: {problem}"));
        let text = (self.resolve)(&file).map_err(cannot)?;
        self.scene.objects.push(Object {
            name: name.clone(),
            source: ObjectSource::Mesh {
                file: file.clone(),
                material: override_name,
                translate: placement.translate,
                rotate_deg: placement.rotate_deg,
                scale: placement.scale,
            },
        });
        let loaded = obj::add_mesh(
            &mut self.scene,
            &obj::MeshRequest {
                object,
                object_name: &name,
                label: &short_path(&file),
                key: &file,
                text: &text,
                resolve: self.resolve,
                material_override,
                placement: &placement,
            },
        )
        .map_err(|p| cannot(format!("{}{}", short_path(&file), p.with_line())))?;
        if loaded == 0 {
            self.scene.warnings.push(format!(
                "{}: the mesh has no triangles to show.",
                short_path(&file)
            ));
        }
        Ok(())
    }
}

/// The material named "default" (a `[[material]]` of that name, or [`Material::default`]
/// added once, when first needed).
pub(crate) fn default_material(scene: &mut Scene) -> MaterialId {
    if let Some(i) = scene.materials.iter().position(|m| m.name == "default") {
        return MaterialId(i as u32);
    }
    scene.materials.push(Material::default());
    MaterialId(scene.materials.len() as u32 - 1)
}

fn default_object_name(kind: Kind, s: &Section) -> Result<String, SceneError> {
    let number = s.what.rsplit(' ').next().unwrap_or("1");
    Ok(match kind {
        Kind::Mesh => match s.string("file")? {
            Some((file, _)) => obj::file_stem(&file).unwrap_or_else(|| s.what.clone()),
            None => s.what.clone(),
        },
        _ => format!("{} {number}", kind.label()),
    })
}

/// Names given so far, so that duplicates are errors and default names stay unique.
#[derive(Default)]
struct Names {
    taken: HashMap<String, String>,
}

impl Names {
    /// An explicit name (`name` of section `s`): an error if an earlier one is the same.
    fn claim(
        &mut self,
        s: &Section,
        name: &str,
        span: &Range<usize>,
        kind: &str,
    ) -> Result<(), SceneError> {
        if let Some(first) = self.taken.get(name) {
            return Err(s.error(
                span,
                "name",
                format!(
                    "repeats \"{}\", the name of {first}; {kind} names must be unique",
                    short(name).escape_debug()
                ),
            ));
        }
        self.taken.insert(name.to_string(), s.what.clone());
        Ok(())
    }

    /// `base`, or `base 2`, `base 3`, ... if taken.
    fn fresh(&mut self, base: &str) -> String {
        let mut name = base.to_string();
        let mut n = 2;
        while self.taken.contains_key(&name) {
            name = format!("{base} {n}");
            n += 1;
        }
        self.taken.insert(name.clone(), String::new());
        name
    }
}

fn parse_render(s: &Section) -> Result<RenderParams, SceneError> {
    let d = RenderParams::default();
    let shading = match s.get("shading") {
        None => d.shading,
        Some(v) => match v.get_ref() {
            DeValue::String(text) if text == "phong" => Shading::Phong,
            DeValue::String(text) if text == "blinn-phong" => Shading::BlinnPhong,
            _ => {
                return Err(s.type_error("shading", v, "\"phong\" or \"blinn-phong\""));
            }
        },
    };
    Ok(RenderParams {
        width: s.uint("width", d.width, 1, MAX_IMAGE_SIZE)?,
        height: s.uint("height", d.height, 1, MAX_IMAGE_SIZE)?,
        max_depth: s.uint("max_depth", d.max_depth, 0, MAX_DEPTH_LIMIT)?,
        samples: s.uint("samples", d.samples, 1, MAX_SAMPLES)?,
        background: s.color("background", d.background, NON_NEGATIVE)?,
        ambient_light: s.color("ambient_light", d.ambient_light, NON_NEGATIVE)?,
        shading,
    })
}

fn parse_camera(s: &Section) -> Result<Camera, SceneError> {
    let d = Camera::default();
    let camera = Camera {
        position: s.vec3("position", d.position, COORDINATE)?,
        look_at: s.vec3("look_at", d.look_at, COORDINATE)?,
        up: s.vec3("up", d.up, ANY)?,
        fov_y_deg: s.f32("fov_y", d.fov_y_deg, FOV)?,
    };
    if let Err(problem) = check_camera(&camera) {
        let key = match problem {
            CameraProblem::Eye => "look_at",
            CameraProblem::ZeroUp | CameraProblem::ParallelUp => "up",
        };
        // Point at what was written: the field itself if present, else what it clashes with.
        let order: &[&str] = match problem {
            CameraProblem::Eye => &["look_at", "position"],
            CameraProblem::ZeroUp | CameraProblem::ParallelUp => &["up", "look_at", "position"],
        };
        let span = order
            .iter()
            .find_map(|k| s.get(k).map(|v| v.span()))
            .unwrap_or_else(|| s.span.clone());
        let phrase = if key == "up" && s.get("up").is_none() {
            format!("(by default [0, 1, 0]) {}", problem.phrase())
        } else {
            problem.phrase().to_string()
        };
        return Err(s.error(&span, key, phrase));
    }
    Ok(camera)
}

/// Why a camera cannot make an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CameraProblem {
    Eye,
    ZeroUp,
    ParallelUp,
}

impl CameraProblem {
    pub fn phrase(self) -> &'static str {
        match self {
            CameraProblem::Eye => {
                "must be a point apart from `position` (at a distance f32 can represent)"
            }
            CameraProblem::ZeroUp => "must not be the zero vector",
            CameraProblem::ParallelUp => {
                "must not be parallel to the view direction from `position` to `look_at`"
            }
        }
    }
}

/// Position ≠ look_at (and the view direction normalisable), `up` usable.
pub(crate) fn check_camera(camera: &Camera) -> Result<(), CameraProblem> {
    let view = (camera.look_at - camera.position).normalize_or_zero();
    if view == Vec3::ZERO {
        return Err(CameraProblem::Eye);
    }
    let up = camera.up.normalize_or_zero();
    if up == Vec3::ZERO {
        return Err(CameraProblem::ZeroUp);
    }
    if view.cross(up).length() < 1e-4 {
        return Err(CameraProblem::ParallelUp);
    }
    Ok(())
}

fn parse_material(s: &Section, name: String) -> Result<Material, SceneError> {
    let d = Material::default();
    Ok(Material {
        name,
        ambient: s.color("ambient", d.ambient, NON_NEGATIVE)?,
        diffuse: s.color("diffuse", d.diffuse, NON_NEGATIVE)?,
        specular: s.color("specular", d.specular, NON_NEGATIVE)?,
        shininess: s.f32("shininess", d.shininess, NON_NEGATIVE)?,
        reflectivity: s.color("reflectivity", d.reflectivity, NON_NEGATIVE)?,
        transparency: s.color("transparency", d.transparency, NON_NEGATIVE)?,
        ior: s.f32("ior", d.ior, POSITIVE)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_characters_from_one() {
        let src = Src {
            file: "f",
            text: "ab\nçd = 1\n",
        };
        assert_eq!(src.line_col(0), (1, 1));
        assert_eq!(src.line_col(3), (2, 1));
        assert_eq!(src.line_col(5), (2, 2)); // after the two-byte 'ç'
    }

    #[test]
    fn suggestions_catch_typos_only() {
        assert_eq!(
            suggest("radus", SPHERE_KEYS.iter().copied()),
            Some("radius")
        );
        assert_eq!(suggest("colour", LIGHT_KEYS.iter().copied()), Some("color"));
        assert_eq!(suggest("zzz", SPHERE_KEYS.iter().copied()), None);
    }

    #[test]
    fn sentences_are_one_line_with_a_full_stop() {
        assert_eq!(sentence("a\nb "), "a b.");
        assert_eq!(sentence("done."), "done.");
    }
}
