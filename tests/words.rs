//! The repository speaks of the product, not of its making: no text under src/, tests/,
//! benches/, scripts/, docs/ or the README names a working session, an issue number, a sprint
//! or the date of a run (git history keeps those), and none cites a document that is not in
//! the repository. A comment says why the code is as it is, and points into docs/ for more.

use std::path::{Path, PathBuf};

/// Text files below `dir` (pictures, data and snapshots are not read).
fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries {
        let path = entry.expect("a readable entry").path();
        if path.is_dir() {
            text_files(&path, out);
        } else if path.extension().is_some_and(|e| {
            ["rs", "md", "sh", "c", "h", "toml", "wgsl", "py", "txt"]
                .contains(&e.to_str().unwrap_or(""))
        }) {
            out.push(path);
        }
    }
}

/// The word at byte `i` of `line` stands alone (no letter or digit right before it).
fn starts_word(line: &str, i: usize) -> bool {
    !line[..i]
        .chars()
        .next_back()
        .is_some_and(|c| c.is_alphanumeric() || c == '_')
}

/// What is wrong with `line`, if anything.
fn finding(line: &str) -> Option<&'static str> {
    let lower = line.to_lowercase();
    // "<word> 12", "<word> #12", "<word>12": a session or an issue by number.
    for word in ["session", "issue", "sprint"] {
        let mut from = 0;
        while let Some(k) = lower[from..].find(word) {
            let i = from + k;
            from = i + word.len();
            if !starts_word(&lower, i) {
                continue;
            }
            let rest = lower[from..].trim_start_matches([' ', '#', '-']);
            if word == "sprint" || rest.starts_with(|c: char| c.is_ascii_digit()) {
                return Some("names a session, an issue or a sprint");
            }
        }
    }
    // A date of the form 2026-12-03.
    let b = line.as_bytes();
    for i in 0..b.len().saturating_sub(9) {
        let d = |k: usize| b[i + k].is_ascii_digit();
        if b[i] == b'2'
            && d(1)
            && d(2)
            && d(3)
            && b[i + 4] == b'-'
            && d(5)
            && d(6)
            && b[i + 7] == b'-'
            && d(8)
            && d(9)
            && (i == 0 || !b[i - 1].is_ascii_digit())
        {
            return Some("gives the date of a run");
        }
    }
    if lower.contains("yesterday") || lower.contains("today's machine") {
        return Some("reads as a diary");
    }
    // Documents outside the repository.
    let mut from = 0;
    let spec = ["SP", "EC"].concat();
    while let Some(k) = line[from..].find(spec.as_str()) {
        let i = from + k;
        from = i + 4;
        let after = line[from..].chars().next();
        if starts_word(line, i) && !after.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            return Some("cites a document that is not in the repository");
        }
    }
    if line.contains(&["STABI", "LITY.md"].concat()) || line.contains(&["sha", "red/"].concat()) {
        return Some("cites a document that is not in the repository");
    }
    None
}

/// `line` and the line after it as one line of text: a phrase a comment or paragraph breaks
/// over two lines (the next line's indent and comment marks dropped).
fn joined(line: &str, next: &str) -> String {
    let next = next
        .trim_start()
        .trim_start_matches(['/', '!', '#', '*', '>'])
        .trim_start();
    format!("{} {next}", line.trim_end())
}

#[test]
fn no_history_and_no_outside_documents() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = vec![root.join("README.md")];
    for dir in [
        "src", "tests", "benches", "scripts", "docs", "shaders", "assets", ".ci",
    ] {
        text_files(&root.join(dir), &mut files);
    }
    let this = Path::new(file!()).file_name().expect("this file's name");
    let mut found = Vec::new();
    for file in &files {
        if file.file_name() == Some(this) {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        for (n, line) in lines.iter().enumerate() {
            let place = file.strip_prefix(root).unwrap_or(file).display();
            if let Some(why) = finding(line) {
                found.push(format!("{place}:{}: {why}: {}", n + 1, line.trim()));
            } else if let Some(next) = lines.get(n + 1)
                && finding(next).is_none()
            {
                let both = joined(line, next);
                if let Some(why) = finding(&both) {
                    found.push(format!("{place}:{}-{}: {why}: {both}", n + 1, n + 2));
                }
            }
        }
    }
    assert!(files.len() > 100, "only {} files read", files.len());
    assert!(
        found.is_empty(),
        "{} lines speak of the project's making or of outside documents:\n{}",
        found.len(),
        found.join("\n")
    );
}

#[test]
fn the_finder_finds_what_it_should_and_nothing_else() {
    // The samples are put together from pieces, so the repository itself holds no such line
    // for a search of the whole tree to find.
    let (spec, stability, shared) = (
        ["SP", "EC"].concat(),
        ["STABI", "LITY.md"].concat(),
        ["sha", "red/"].concat(),
    );
    for bad in [
        ["// measured in sess", "ion 12"].concat(),
        ["//! (iss", "ue 14.4)"].concat(),
        "issue #7".to_string(),
        "a sprint goal".to_string(),
        "Measured 2026-11-29 on main".to_string(),
        format!("see {spec} §3"),
        format!("({spec})"),
        format!("{stability} row T3"),
        format!("../{shared}seed"),
        "today's machine is slower than yesterday's".to_string(),
    ] {
        assert!(finding(&bad).is_some(), "{bad}");
    }
    let broken = joined(
        "/// fewer instructions (measured in session",
        "    /// 13) than 4×4",
    );
    assert!(finding(&broken).is_some(), "{broken}");
    for good in [
        "let session = Session::new();",
        "an issue with the file",
        "SPECULAR",
        "the sessions' figures",
        "Andersson et al. 2020",
        "version 0.37.0",
        "docs/stability.md, row T3",
    ] {
        assert!(finding(good).is_none(), "{good}");
    }
}
