//! Files that are Git LFS pointers: a repository that keeps its models and textures in Git LFS,
//! cloned without `git lfs`, leaves in their place a text of three lines naming the real file's
//! hash and size. Read as a model it has no faces, and as a texture it is no image; the reader
//! says what it is instead.

/// The first line of every Git LFS pointer file.
const POINTER: &[u8] = b"version https://git-lfs.github.com/spec/v1";

/// Pointer files are short: the specification keeps them under 1024 bytes.
const MAX_POINTER_BYTES: usize = 1024;

/// When `bytes` are a Git LFS pointer, why the file cannot be read, with the real file's size
/// if the pointer gives it: "it is a Git LFS pointer, not the file itself: the file (21.3 MiB)
/// was never downloaded; `git lfs pull` in its repository fetches it".
pub(crate) fn pointer_reason(bytes: &[u8]) -> Option<String> {
    if bytes.len() > MAX_POINTER_BYTES || !bytes.starts_with(POINTER) {
        return None;
    }
    let text = String::from_utf8_lossy(bytes);
    let size = text
        .lines()
        .find_map(|line| line.strip_prefix("size "))
        .and_then(|n| n.trim().parse::<u64>().ok());
    let file = match size {
        Some(n) => format!("the file ({})", super::budget::format_bytes(n)),
        None => "the file".to_string(),
    };
    Some(format!(
        "it is a Git LFS pointer, not the file itself: {file} was never downloaded; \
         `git lfs pull` in its repository fetches it"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pointer_is_recognised_with_its_size_and_nothing_else_is() {
        let pointer = b"version https://git-lfs.github.com/spec/v1\n\
            oid sha256:df14845c86933fbf75aa31c04c62ad78d18e5f1a72e43cf4d30c6d7353c12bcc\n\
            size 22342871\n";
        let reason = pointer_reason(pointer).expect("a pointer");
        assert!(reason.contains("Git LFS pointer"), "{reason}");
        assert!(reason.contains("21.3 MiB"), "{reason}");
        assert!(reason.contains("git lfs pull"), "{reason}");
        // Without a size line it still is one.
        let bare = pointer_reason(&pointer[..60]).expect("a pointer");
        assert!(bare.contains("the file was never downloaded"), "{bare}");
        // An OBJ that mentions the line in a comment, or a long file that starts with it, is not.
        assert_eq!(
            pointer_reason(b"# version https://git-lfs.github.com/spec/v1\nv 0 0 0\n"),
            None
        );
        let mut long = pointer.to_vec();
        long.resize(4096, b' ');
        assert_eq!(pointer_reason(&long), None);
        assert_eq!(
            pointer_reason(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            None
        );
    }
}
