//! Object, light and material names: those given must be unique, and those left out get a
//! default (`sphere 2`, the mesh's file name) that steps around every name given.

use std::collections::HashMap;
use std::ops::Range;

use super::reader::Section;
use crate::scene::diag::{SceneError, short};

/// The names of `sections` (their `name` keys, unique), with `default(i)` for the others,
/// stepping around the names given explicitly.
pub(super) fn unique_names(
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
            return Err(s.error_at_place(
                span,
                "name",
                format!(
                    "repeats \"{}\", the name of {first}; {kind} names must be unique",
                    short(name).escape_debug()
                ),
            ));
        }
        self.taken.insert(name.to_string(), s.place.clone());
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
