//! The sections of a scene file and the keys each takes: the one list the loader holds a file
//! to (an unknown section or key is an error with a "did you mean" hint) and the fuzzer draws
//! its edits from. What each key means and its default: docs/design.md, "Scene files".

use toml::de::{DeTable, DeValue};

use super::reader::describe;
use crate::scene::diag::{SceneError, Src, list_and, short, suggest};

/// One section of a scene file and the keys it takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SectionKeys {
    /// The name in its header: `render` for `[render]`, `sphere` for `[[sphere]]`.
    pub name: &'static str,
    /// A single table (`[render]`), or else an array of tables (`[[sphere]]`).
    pub single: bool,
    /// Every key the section may have.
    pub keys: &'static [&'static str],
}

impl SectionKeys {
    /// The header as written in a file: `[render]` or `[[sphere]]`.
    pub fn header(&self) -> String {
        if self.single {
            format!("[{}]", self.name)
        } else {
            format!("[[{}]]", self.name)
        }
    }
}

pub(super) const RENDER_KEYS: &[&str] = &[
    "width",
    "height",
    "max_depth",
    "samples",
    "background",
    "ambient_light",
    "shading",
];
pub(super) const CAMERA_KEYS: &[&str] = &["position", "look_at", "up", "fov_y"];
pub(super) const LIGHT_KEYS: &[&str] = &["name", "position", "color", "radius", "follow_camera"];
pub(super) const MATERIAL_KEYS: &[&str] = &[
    "name",
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "reflectivity",
    "transparency",
    "ior",
];
pub(super) const SPHERE_KEYS: &[&str] = &["name", "center", "radius", "material"];
pub(super) const TRIANGLE_KEYS: &[&str] = &["name", "vertices", "material"];
pub(super) const MESH_KEYS: &[&str] = &[
    "name",
    "file",
    "material",
    "translate",
    "rotate",
    "scale",
    "normals",
    "crease_angle",
];

/// Every section a scene file may have, in the order the format lists them (and error
/// messages name them), each with the keys it takes. Nothing else is accepted.
pub const SECTIONS: &[SectionKeys] = &[
    SectionKeys {
        name: "render",
        single: true,
        keys: RENDER_KEYS,
    },
    SectionKeys {
        name: "camera",
        single: true,
        keys: CAMERA_KEYS,
    },
    SectionKeys {
        name: "light",
        single: false,
        keys: LIGHT_KEYS,
    },
    SectionKeys {
        name: "material",
        single: false,
        keys: MATERIAL_KEYS,
    },
    SectionKeys {
        name: "sphere",
        single: false,
        keys: SPHERE_KEYS,
    },
    SectionKeys {
        name: "triangle",
        single: false,
        keys: TRIANGLE_KEYS,
    },
    SectionKeys {
        name: "mesh",
        single: false,
        keys: MESH_KEYS,
    },
];

/// Every top-level key must be a known section of the right shape (`[render]` a table,
/// `[[sphere]]` an array of tables).
pub(super) fn check_sections(src: &Src, root: &DeTable) -> Result<(), SceneError> {
    for (key, value) in root.iter() {
        let name = key.get_ref().as_ref();
        let Some(section) = SECTIONS.iter().find(|s| s.name == name) else {
            let home = SECTIONS.iter().find(|s| s.single && s.keys.contains(&name));
            let hint = match home {
                Some(section) => format!(" (it belongs under [{}])", section.name),
                None => suggest(name, SECTIONS.iter().map(|s| s.name))
                    .and_then(|s| SECTIONS.iter().find(|k| k.name == s))
                    .map(|s| format!(" (did you mean `{}`?)", s.header()))
                    .unwrap_or_default(),
            };
            let what = match value.get_ref() {
                DeValue::Table(_) | DeValue::Array(_) => "unknown section",
                _ => "unknown top-level key",
            };
            let listed: Vec<String> = SECTIONS.iter().map(SectionKeys::header).collect();
            return Err(src.error(
                &key.span(),
                format!(
                    "{what} `{}`{hint}; the sections are {}",
                    short(name),
                    list_and(&listed)
                ),
            ));
        };
        let shape_ok = match value.get_ref() {
            DeValue::Table(_) => section.single,
            DeValue::Array(_) => !section.single,
            _ => false,
        };
        if !shape_ok {
            let shape = if section.single {
                "a table"
            } else {
                "an array of tables"
            };
            return Err(src.error(
                &value.span(),
                format!(
                    "`{name}` must be written as {} ({shape}), got {}",
                    section.header(),
                    describe(value.get_ref())
                ),
            ));
        }
    }
    Ok(())
}
