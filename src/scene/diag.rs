//! What the scene loaders say about bad input: the error type, `FILE:LINE:COLUMN` places,
//! one-sentence phrasing, shortened user text and "did you mean" hints. Shared by the TOML
//! loader, the OBJ loader and the file reader.

use std::ops::Range;

/// A scene that could not be loaded: one sentence naming the file, the place and the field.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct SceneError(pub String);

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
    pub fn slice(&self, span: &Range<usize>) -> String {
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

/// How many names a warning spells out before it counts the rest.
const NAMED_AT_MOST: usize = 5;

/// Like [`list_and`], but past [`NAMED_AT_MOST`] items the rest are counted, so that a
/// warning about a file with forty materials stays one readable sentence:
/// `a`, `b`, `c`, `d`, `e` and 35 more.
pub(crate) fn list_some(items: &[String]) -> String {
    if items.len() <= NAMED_AT_MOST {
        return list_and(items);
    }
    let mut named = items[..NAMED_AT_MOST].to_vec();
    named.push(format!("{} more", items.len() - NAMED_AT_MOST));
    list_and(&named)
}

/// `warnings` with those that say the same of several materials ("FILE: material `a` has `Ns
/// 0`, which…", the same for `b`) said once, naming them ("FILE: materials `a` and `b` have
/// `Ns 0`, which…"; five named and the rest counted), where the first of them stood. A model
/// of many materials exported alike otherwise repeats one sentence for each.
pub(crate) fn fold_material_warnings(warnings: Vec<String>) -> Vec<String> {
    // "LABEL: material `NAME` has|is REST" as (LABEL, NAME, has|is, REST).
    fn parts(w: &str) -> Option<(&str, &str, &str, &str)> {
        let (label, after) = w.split_once(": material `")?;
        let (name, rest) = after.split_once("` ")?;
        let (verb, rest) = rest.split_once(' ')?;
        matches!(verb, "has" | "is").then_some((label, name, verb, rest))
    }
    let mut out: Vec<String> = Vec::with_capacity(warnings.len());
    /// Warnings alike: (label, verb, rest), the slot in `out` of the first, the names.
    type Group = ((String, String, String), usize, Vec<String>);
    let mut groups: Vec<Group> = Vec::new();
    for w in warnings {
        let Some((label, name, verb, rest)) = parts(&w) else {
            out.push(w);
            continue;
        };
        let key = (label.to_string(), verb.to_string(), rest.to_string());
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(group) => group.2.push(format!("`{name}`")),
            None => {
                groups.push((key, out.len(), vec![format!("`{name}`")]));
                out.push(w);
            }
        }
    }
    for ((label, verb, rest), slot, names) in groups {
        if names.len() > 1 {
            let plural = if verb == "has" { "have" } else { "are" };
            out[slot] = format!("{label}: materials {} {plural} {rest}", list_some(&names));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warnings_that_say_the_same_of_several_materials_are_said_once() {
        let w = |s: &str| s.to_string();
        let folded = fold_material_warnings(vec![
            w("a.obj: material `Base` has `Ns 0`, which would add all of `Ks`."),
            w("a.obj: first note."),
            w("a.obj: material `Site` has `Ns 0`, which would add all of `Ks`."),
            w("a.obj: material `Trim` has an invalid `Ni` 0; using 1.5."),
            w("b.obj: material `Base` has `Ns 0`, which would add all of `Ks`."),
            w("a.obj: material `Door` has `Ns 0`, which would add all of `Ks`."),
            w("a.obj: material `Glass` is black."),
        ]);
        assert_eq!(
            folded,
            [
                "a.obj: materials `Base`, `Site` and `Door` have `Ns 0`, which would add all of `Ks`.",
                "a.obj: first note.",
                "a.obj: material `Trim` has an invalid `Ni` 0; using 1.5.",
                "b.obj: material `Base` has `Ns 0`, which would add all of `Ks`.",
                "a.obj: material `Glass` is black.",
            ]
        );
    }

    #[test]
    fn long_lists_name_five_and_count_the_rest() {
        let names = |n: usize| (1..=n).map(|i| format!("`m{i}`")).collect::<Vec<_>>();
        assert_eq!(list_some(&names(1)), "`m1`");
        assert_eq!(
            list_some(&names(5)),
            "`m1`, `m2`, `m3`, `m4` and `m5`",
            "five are all named"
        );
        assert_eq!(
            list_some(&names(40)),
            "`m1`, `m2`, `m3`, `m4`, `m5` and 35 more"
        );
    }

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
        const KEYS: [&str; 4] = ["name", "center", "radius", "material"];
        assert_eq!(suggest("radus", KEYS), Some("radius"));
        assert_eq!(suggest("colour", ["name", "color"]), Some("color"));
        assert_eq!(suggest("zzz", KEYS), None);
    }

    #[test]
    fn sentences_are_one_line_with_a_full_stop() {
        assert_eq!(sentence("a\nb "), "a b.");
        assert_eq!(sentence("done."), "done.");
    }
}
