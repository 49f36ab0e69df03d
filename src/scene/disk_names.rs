//! Files as a model names them against the files on disk: a model written on Windows or macOS
//! names `tex/wood.png` where the file is `Tex/Wood.PNG`.

use std::path::{Path, PathBuf};

/// `path` itself when it exists, else the one file or folder on disk that matches it with each
/// missing name compared regardless of case (`Tex/Wood.PNG` for `tex/wood.png`, as a model
/// written on Windows or macOS names its files), else `path` unchanged (and the read that
/// follows says it is not there). Of several matches in one folder the first in sorted order.
pub(crate) fn ignoring_case(path: &Path) -> PathBuf {
    use std::path::Component;
    if path.exists() {
        return path.to_path_buf();
    }
    let mut found = PathBuf::new();
    for part in path.components() {
        let Component::Normal(name) = part else {
            found.push(part);
            continue;
        };
        let exact = found.join(name);
        if exact.exists() {
            found = exact;
            continue;
        }
        let folder = if found.as_os_str().is_empty() {
            Path::new(".")
        } else {
            &found
        };
        let wanted = name.to_string_lossy().to_lowercase();
        let Ok(entries) = std::fs::read_dir(folder) else {
            return path.to_path_buf();
        };
        let mut matches: Vec<_> = entries
            .filter_map(Result::ok)
            .map(|e| e.file_name())
            .filter(|n| n.to_string_lossy().to_lowercase() == wanted)
            .collect();
        matches.sort();
        match matches.first() {
            Some(m) => found.push(m),
            None => return path.to_path_buf(),
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_not_found_as_written_match_regardless_of_case() {
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::create_dir(dir.path().join("Tex")).expect("folder");
        std::fs::write(dir.path().join("Tex/Wood.PNG"), b"x").expect("write");
        let found = dir.path().join("Tex/Wood.PNG");
        assert_eq!(ignoring_case(&dir.path().join("tex/wood.png")), found);
        assert_eq!(ignoring_case(&found), found, "an exact path stays");
        let missing = dir.path().join("tex/stone.png");
        assert_eq!(
            ignoring_case(&missing),
            missing,
            "nothing matches: unchanged"
        );
    }
}
