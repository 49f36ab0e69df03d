//! The paths of mesh files as a scene writes them: which name an OBJ, the object name a mesh
//! takes from its file, and the files an OBJ names next to itself (its MTL libraries, their
//! textures).

use std::path::Path;

/// True if `path` ends in `.obj`, in any case: the only files a `[[mesh]]` may name.
pub(crate) fn is_obj_path(path: &str) -> bool {
    Path::new(path)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// The file name without folder and extension (`models/gem.obj` → `gem`).
pub(crate) fn file_stem(path: &str) -> Option<String> {
    Path::new(path)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
}

/// `name` next to the file `path` (both as written, `/` or `\` separated): the MTL next to
/// its OBJ.
pub(crate) fn sibling(path: &str, name: &str) -> String {
    if name.starts_with('/') || Path::new(name).is_absolute() {
        return name.to_string();
    }
    match path.rfind(['/', '\\']) {
        Some(i) => format!("{}/{name}", &path[..i]),
        None => name.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn siblings_share_the_folder() {
        assert_eq!(sibling("models/a.obj", "a.mtl"), "models/a.mtl");
        assert_eq!(sibling("a.obj", "a.mtl"), "a.mtl");
        assert_eq!(sibling("../m/a.obj", "x/a.mtl"), "../m/x/a.mtl");
    }
}
