//! Scene input from disk: a `.toml` scene or a bare `.obj` mesh chosen by extension, meshes and
//! material libraries resolved next to the scene, size caps, regular files only; and the scene
//! argument of the CLI and the viewer (a file, or the name of a built-in scene).

use std::path::{Path, PathBuf};

use super::diag::{SceneError, short_path};
use super::rules::{MAX_MESH_FILE_BYTES, MAX_SCENE_FILE_BYTES};
use super::texture::fs_bytes_resolver;
use super::toml::load_scene_str_with_files;
use super::{Scene, builtin, first_look};

/// A scene file, OBJ, or built-in scene name, as given on the command line or to the viewer:
/// a file of that name wins over a built-in scene.
pub fn open_scene_arg(arg: &str) -> Result<Scene, SceneError> {
    let path = Path::new(arg);
    if !path.exists() && builtin::NAMES.contains(&arg) {
        return builtin::load_builtin(arg);
    }
    // Neither a file nor a scene file's name: most likely a built-in name mistyped.
    if !path.exists() && path.extension().is_none() {
        return Err(builtin::unknown(arg, "file or built-in scene"));
    }
    load_scene_file(path)
}

/// Loads a `.toml` scene or a bare `.obj` mesh (chosen by the extension, in any case). Meshes
/// and material libraries are resolved relative to the file's folder. Sets [`Scene::source`].
pub fn load_scene_file(path: &Path) -> Result<Scene, SceneError> {
    match load_scene_file_watched(path, &mut |_| true)? {
        Some(scene) => Ok(scene),
        // The watcher above never stops the load.
        None => Err(SceneError(format!(
            "{}: the load was cancelled.",
            path.display()
        ))),
    }
}

/// A step of [`load_scene_file_watched`], told as it happens.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadStep {
    /// `done` of the file's `total` bytes are read.
    Read { done: u64, total: u64 },
    /// The file is read; parsing begins (for a scene file this also reads its meshes and
    /// textures; for a bare OBJ it includes its materials and the first look).
    Parse,
}

/// Bytes read between two [`LoadStep::Read`] reports (and cancel checks).
const READ_CHUNK: usize = 4 << 20;

/// [`load_scene_file`], telling `watch` of each [`LoadStep`]; when `watch` answers false (the
/// caller cancelled), the load stops at that step and returns `Ok(None)`. The viewer opens
/// files in the background this way, with progress, and drops a superseded open early.
pub fn load_scene_file_watched(
    path: &Path,
    watch: &mut dyn FnMut(LoadStep) -> bool,
) -> Result<Option<Scene>, SceneError> {
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
    let text = match read_text_watched(path, max_bytes, watch) {
        Ok(Some(text)) => text,
        Ok(None) => return Ok(None),
        Err(reason) => {
            return Err(SceneError(format!(
                "{file}: cannot read the scene file: {reason}."
            )));
        }
    };
    if !watch(LoadStep::Parse) {
        return Ok(None);
    }
    let folder = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let resolve = fs_resolver(folder.clone());
    let resolve_bytes = fs_bytes_resolver(folder);
    let mut scene = if is_obj {
        let key = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| file.clone());
        first_look::load_obj_scene(&text, &file, &key, &resolve, &resolve_bytes)?
    } else {
        load_scene_str_with_files(&text, &file, &resolve, &resolve_bytes)?
    };
    scene.source = Some(path.to_path_buf());
    scene.warnings = super::diag::fold_material_warnings(std::mem::take(&mut scene.warnings));
    Ok(Some(scene))
}

/// Parses scene TOML; `name` stands for the file in messages. Meshes are resolved relative to
/// the current directory.
pub fn load_scene_str(text: &str, name: &str) -> Result<Scene, SceneError> {
    load_scene_str_with_files(
        text,
        name,
        &fs_resolver(PathBuf::new()),
        &fs_bytes_resolver(PathBuf::new()),
    )
}

/// A resolver reading files relative to `folder`; a name not found as written is matched
/// regardless of case (`disk_names::ignoring_case`).
pub fn fs_resolver(folder: PathBuf) -> impl Fn(&str) -> Result<String, String> {
    move |path: &str| {
        read_text(
            &super::disk_names::ignoring_case(&folder.join(path)),
            MAX_MESH_FILE_BYTES,
        )
        .map_err(|reason| format!("{}: {reason}", short_path(path)))
    }
}

/// Reads a text file of at most `max_bytes`, tolerating stray non-UTF-8 bytes (old MTL files
/// carry Latin-1 comments). Only regular files are read: a device such as `/dev/zero` or a
/// pipe would never end (or block), and a folder is never what was meant.
fn read_text(path: &Path, max_bytes: u64) -> Result<String, String> {
    read_text_watched(path, max_bytes, &mut |_| true).map(Option::unwrap_or_default)
}

/// [`read_text`] in chunks of [`READ_CHUNK`], telling `watch` the bytes read after each;
/// `Ok(None)` when `watch` answers false.
fn read_text_watched(
    path: &Path,
    max_bytes: u64,
    watch: &mut dyn FnMut(LoadStep) -> bool,
) -> Result<Option<String>, String> {
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
            super::budget::format_bytes(size),
            super::budget::format_bytes(max_bytes)
        )
    };
    if meta.len() > max_bytes {
        return Err(too_big(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(|e| os_reason(&e))?;
    let total = meta.len();
    let mut bytes = Vec::with_capacity(total as usize);
    // `take` also stops a file that grows while it is read.
    let mut reader = file.take(max_bytes + 1);
    if !watch(LoadStep::Read { done: 0, total }) {
        return Ok(None);
    }
    loop {
        let n = (&mut reader)
            .take(READ_CHUNK as u64)
            .read_to_end(&mut bytes)
            .map_err(|e| os_reason(&e))?;
        if n == 0 {
            break;
        }
        // A file that grew while it was read may pass its size: the report never goes past it.
        let done = (bytes.len() as u64).min(total);
        if !watch(LoadStep::Read { done, total }) {
            return Ok(None);
        }
    }
    if bytes.len() as u64 > max_bytes {
        return Err(too_big(bytes.len() as u64));
    }
    if let Some(reason) = super::lfs::pointer_reason(&bytes) {
        return Err(reason);
    }
    // A UTF-8 byte-order mark (Windows tools write one) is no part of the first line.
    if bytes.starts_with(BOM) {
        bytes.drain(..BOM.len());
    }
    // UTF-16 text (Windows tools save "Unicode" so), known by its byte-order mark.
    if let Some(text) = utf16_text(&bytes) {
        return Ok(Some(text));
    }
    // Valid UTF-8 is taken as it is, without the copy `from_utf8_lossy` would make.
    Ok(Some(String::from_utf8(bytes).unwrap_or_else(|e| {
        String::from_utf8_lossy(e.as_bytes()).into_owned()
    })))
}

/// The UTF-8 byte-order mark.
const BOM: &[u8] = b"\xEF\xBB\xBF";

/// The text of UTF-16 `bytes` that start with a byte-order mark (big- or little-endian), any
/// unpaired surrogate replaced; `None` for other bytes.
fn utf16_text(bytes: &[u8]) -> Option<String> {
    let big = match bytes {
        [0xFE, 0xFF, ..] => true,
        [0xFF, 0xFE, ..] => false,
        _ => return None,
    };
    let units = bytes[2..].chunks(2).map(|pair| {
        let pair = [pair[0], pair.get(1).copied().unwrap_or(0)];
        if big {
            u16::from_be_bytes(pair)
        } else {
            u16::from_le_bytes(pair)
        }
    });
    Some(
        char::decode_utf16(units)
            .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
            .collect(),
    )
}

/// The OS's reason without the platform-specific "(os error N)" tail, for stable messages.
fn os_reason(e: &std::io::Error) -> String {
    let text = e.to_string();
    match text.find(" (os error") {
        Some(i) => text[..i].to_string(),
        None => text,
    }
}
