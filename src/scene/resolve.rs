//! How the loaders reach the files a scene names (meshes, material libraries, textures): through
//! a resolver given by the caller, so that built-in scenes read text compiled into the binary
//! and scene files read their folder.

/// Returns the text of a mesh or material library, given its path as written in the scene
/// (relative to the scene file's folder), or the reason it cannot, as a short phrase. Built-in
/// scenes resolve from strings compiled into the binary, files from the scene's folder.
pub type ResolveFn<'a> = dyn Fn(&str) -> Result<String, String> + 'a;

/// As [`ResolveFn`], for binary files (textures).
pub type ResolveBytesFn<'a> = dyn Fn(&str) -> Result<Vec<u8>, String> + 'a;

/// The binary resolver of scenes loaded without one: every texture is missing (a warning).
pub fn no_binary_files(path: &str) -> Result<Vec<u8>, String> {
    Err(format!("{path}: textures are not read for this scene"))
}
