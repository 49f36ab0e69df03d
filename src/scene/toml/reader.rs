//! A strict reader over `toml`'s spanned document tree: sections with only known keys, typed
//! values (numbers, vectors, colours, whole numbers, strings), and errors placed on the value
//! they are about.
//!
//! The document is walked by hand rather than through derived `Deserialize` impls: walking the
//! tree knows which section and field each value belongs to, so every error is one sentence
//! `FILE:LINE:COLUMN: what field `key` ...` (serde's messages do not name the field of a wrong
//! type, and `deny_unknown_fields` cannot suggest the key that was meant). What each field must
//! be is not decided here but in [`crate::scene::rules`]; `Section::verdict` places its verdicts.

use std::ops::{Range, RangeInclusive};

use glam::Vec3;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use crate::scene::diag::{SceneError, Src, list_and, short, suggest};
use crate::scene::rules::{self, Violation};

pub(crate) fn syntax_error(src: &Src, e: &toml::de::Error) -> SceneError {
    let span = e.span().unwrap_or(0..0);
    let mut reason = e.message().to_string();
    if reason == "duplicate key" {
        reason = format!("duplicate key `{}`", src.slice(&span));
    }
    src.error(&span, format!("TOML syntax error: {reason}"))
}

/// "a string", "an array of 2 items", ...: what a value is, for type errors.
pub(crate) fn describe(value: &DeValue) -> String {
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

pub(crate) type Value<'i> = Spanned<DeValue<'i>>;

/// One table of the scene (`[render]`, the second `[[sphere]]`, ...) with what to call it in
/// messages ("render", "sphere 2").
pub(crate) struct Section<'s, 't, 'i> {
    src: &'s Src<'s>,
    pub what: String,
    /// Its place ("material 2"), for messages where the name itself is in question.
    pub place: String,
    table: &'t DeTable<'i>,
    pub span: Range<usize>,
}

impl<'s, 't, 'i> Section<'s, 't, 'i> {
    /// Checks that `value` is a table with only `keys` in it.
    pub(crate) fn new(
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
            place: what.clone(),
            what,
            table,
            span: value.span(),
        })
    }

    pub(crate) fn get(&self, key: &str) -> Option<&'t Value<'i>> {
        self.table
            .iter()
            .find(|(k, _)| k.get_ref().as_ref() == key)
            .map(|(_, v)| v)
    }

    pub(crate) fn error(
        &self,
        span: &Range<usize>,
        key: &str,
        phrase: impl AsRef<str>,
    ) -> SceneError {
        self.error_as(&self.what, span, key, phrase.as_ref())
    }

    /// [`Self::error`] naming the section by its place, not its name.
    pub(crate) fn error_at_place(
        &self,
        span: &Range<usize>,
        key: &str,
        phrase: impl AsRef<str>,
    ) -> SceneError {
        self.error_as(&self.place, span, key, phrase.as_ref())
    }

    fn error_as(&self, who: &str, span: &Range<usize>, key: &str, phrase: &str) -> SceneError {
        self.src
            .error(span, format!("{who} field `{key}` {phrase}"))
    }

    pub(crate) fn type_error(&self, key: &str, value: &Value, expected: &str) -> SceneError {
        self.error(
            &value.span(),
            key,
            format!("must be {expected}, got {}", describe(value.get_ref())),
        )
    }

    pub(crate) fn missing(&self, key: &str, hint: &str) -> SceneError {
        self.src.error(
            &self.span,
            format!("{} is missing the field `{key}` ({hint})", self.what),
        )
    }

    /// A number (integer or float), as `f32`; `expected` is for type errors. Whether it may be
    /// infinite, NaN or anything else is the field's rule, checked with the rest of the section
    /// afterwards ([`Section::verdict`]), in the same order as for a viewer edit.
    pub(crate) fn number(
        &self,
        key: &str,
        value: &Value,
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
        parsed.ok_or_else(|| {
            self.error(
                &span,
                key,
                format!("is not a number I can read, got {}", self.src.slice(&span)),
            )
        })
    }

    pub(crate) fn f32(&self, key: &str, default: f32) -> Result<f32, SceneError> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => self.number(key, v, "a number"),
        }
    }

    /// `[x, y, z]` from an array value.
    pub(crate) fn vec3_of(&self, key: &str, value: &Value) -> Result<Vec3, SceneError> {
        const EXPECTED: &str = "an array of 3 numbers [x, y, z]";
        let DeValue::Array(items) = value.get_ref() else {
            return Err(self.type_error(key, value, EXPECTED));
        };
        if items.len() != 3 {
            return Err(self.type_error(key, value, EXPECTED));
        }
        let mut out = [0.0; 3];
        for (o, item) in out.iter_mut().zip(items.iter()) {
            *o = self.number(key, item, "a number")?;
        }
        Ok(Vec3::from_array(out))
    }

    pub(crate) fn vec3(&self, key: &str, default: Vec3) -> Result<Vec3, SceneError> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => self.vec3_of(key, v),
        }
    }

    /// A scalar (all three channels or axes alike) or an array of three.
    pub(crate) fn scalar_or_vec3(
        &self,
        key: &str,
        default: Vec3,
        expected: &str,
    ) -> Result<Vec3, SceneError> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => match v.get_ref() {
                DeValue::Integer(_) | DeValue::Float(_) => {
                    Ok(Vec3::splat(self.number(key, v, expected)?))
                }
                DeValue::Array(items) if items.len() == 3 => self.vec3_of(key, v),
                _ => Err(self.type_error(key, v, expected)),
            },
        }
    }

    pub(crate) fn color(&self, key: &str, default: Vec3) -> Result<Vec3, SceneError> {
        self.scalar_or_vec3(key, default, "a number or an array [r, g, b]")
    }

    /// `true` or `false`.
    pub(crate) fn boolean(&self, key: &str, default: bool) -> Result<bool, SceneError> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => match v.get_ref() {
                DeValue::Boolean(b) => Ok(*b),
                _ => Err(self.type_error(key, v, "true or false")),
            },
        }
    }

    /// A whole number in `range`.
    pub(crate) fn uint(
        &self,
        key: &str,
        default: u32,
        range: &RangeInclusive<u32>,
    ) -> Result<u32, SceneError> {
        let Some(value) = self.get(key) else {
            return Ok(default);
        };
        let span = value.span();
        let DeValue::Integer(i) = value.get_ref() else {
            return Err(self.type_error(key, value, "a whole number"));
        };
        let parsed = i64::from_str_radix(i.as_str(), i.radix()).ok();
        match rules::count_phrase(parsed, range) {
            None => Ok(parsed
                .and_then(|n| u32::try_from(n).ok())
                .unwrap_or(default)),
            Some(phrase) => Err(self.error(
                &span,
                key,
                format!("{phrase}, got {}", self.src.slice(&span)),
            )),
        }
    }

    /// A broken rule of this section, placed on the number it is about (`got` what was
    /// written) or on the field as a whole; on the section when the file does not have the
    /// field (its default broke the rule).
    pub(crate) fn verdict(&self, v: &Violation) -> SceneError {
        let Some(value) = self.get(v.field) else {
            return self.error(&self.span, v.field, &v.phrase);
        };
        match v.index {
            Some(i) => {
                let mut leaves = Vec::new();
                numbers(value, &mut leaves);
                let span = leaves
                    .get(i)
                    .or(leaves.last())
                    .cloned()
                    .unwrap_or_else(|| value.span());
                self.error(
                    &span,
                    v.field,
                    format!("{}, got {}", v.phrase, self.src.slice(&span)),
                )
            }
            None => self.error(&value.span(), v.field, &v.phrase),
        }
    }

    /// A string value with its span, or `None` when absent. Empty strings are errors.
    pub(crate) fn string(&self, key: &str) -> Result<Option<(String, Range<usize>)>, SceneError> {
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

/// The spans of the numbers in `value`, in file order (a scalar is one, `[x, y, z]` three,
/// nested arrays flattened).
fn numbers(value: &Value, out: &mut Vec<Range<usize>>) {
    match value.get_ref() {
        DeValue::Array(items) => items.iter().for_each(|item| numbers(item, out)),
        _ => out.push(value.span()),
    }
}
