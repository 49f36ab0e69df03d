//! MTL materials: the libraries an OBJ names, read for tobj; each material mapped to a Phong
//! material named `<object>/<mtl name>` (a `[[material]]` of that name overrides its colours) with
//! its textures; and the warnings about invalid values and `usemtl` names no library defines.

use std::borrow::Cow;
use std::cell::RefCell;
use std::path::Path;

use glam::Vec3;

use super::maps::{candidates, load_texture, named_diffuse, statement_place, texture_statement};
use super::parse::Facts;
use super::paths::sibling;
use super::read::UNNAMED_MATERIAL;
use super::request::MeshRequest;
use crate::scene::diag::{list_some, short, short_path};
use crate::scene::{Material, MaterialId, Scene};

/// The material libraries (`mtllib`) of one OBJ as tobj asks for them: each read next to the
/// OBJ and made readable for tobj ([`mtl_for_tobj`]), with a warning for each that cannot be,
/// and the text of each that can, so that a texture's warning can name its line. A mesh with a
/// material override reads none.
pub(super) struct Libraries<'r> {
    req: &'r MeshRequest<'r>,
    warnings: RefCell<Vec<String>>,
    texts: RefCell<Vec<(String, String)>>,
}

impl<'r> Libraries<'r> {
    pub(super) fn new(req: &'r MeshRequest<'r>) -> Self {
        Self {
            req,
            warnings: RefCell::new(Vec::new()),
            texts: RefCell::new(Vec::new()),
        }
    }

    /// The library `path` (as the OBJ names it) read, for tobj; `mtllib a.mtl b.mtl` (several
    /// libraries on one line, as the format allows, a space within a name written `\ `) when
    /// no one file has that whole name.
    pub(super) fn load(&self, path: &Path) -> tobj::MTLLoadResult {
        if self.req.material_override.is_some() {
            return Ok(Default::default());
        }
        let written = path.to_string_lossy();
        let parts = library_names(&written);
        let whole = self.find(&written);
        let libraries = match whole {
            Err(_) if parts != [written.as_ref()] && parts.iter().any(|p| self.find(p).is_ok()) => {
                parts.iter().map(|p| (p.as_str(), self.find(p))).collect()
            }
            whole => vec![(written.as_ref(), whole)],
        };
        let several = libraries.len() > 1;
        let mut merged: Option<tobj::MTLLoadResult> = None;
        for (written, found) in libraries {
            let result = self.read(written, found, several);
            merged = Some(match (merged, result) {
                (Some(Ok((mut materials, mut names))), Ok((more, more_names))) => {
                    let offset = materials.len();
                    materials.extend(more);
                    names.extend(more_names.into_iter().map(|(k, i)| (k, i + offset)));
                    Ok((materials, names))
                }
                (Some(Ok(ok)), Err(_)) => Ok(ok),
                (_, result) => result,
            });
        }
        merged.unwrap_or_else(|| Ok(Default::default()))
    }

    /// The library `written` (as the OBJ names it): its text and, when it was found by
    /// [`candidates`] rather than as written, the name it was found as; or why it cannot be
    /// read (the reason for the name as written).
    fn find(&self, written: &str) -> Result<(Option<String>, String), String> {
        let req = self.req;
        let mut first_reason = None;
        for (i, candidate) in candidates(written).into_iter().enumerate() {
            match (req.resolve)(&sibling(req.key, &candidate)) {
                Ok(text) => return Ok(((i > 0).then_some(candidate), text)),
                Err(reason) => {
                    first_reason.get_or_insert(reason);
                }
            }
        }
        Err(first_reason.unwrap_or_default())
    }

    /// The library `written`, found (or not) by [`Libraries::find`], parsed for tobj, with a
    /// warning when it cannot be and a note when it was found elsewhere; `several` when it is
    /// one of several libraries on its `mtllib` line.
    fn read(
        &self,
        written: &str,
        found: Result<(Option<String>, String), String>,
        several: bool,
    ) -> tobj::MTLLoadResult {
        let req = self.req;
        let name = short_path(written);
        let outcome = if several {
            "the faces of its materials use the default material; the other libraries on its `mtllib` line are read"
        } else {
            "its faces use the default material"
        };
        let (elsewhere, text) = found.map_err(|reason| {
            self.warnings.borrow_mut().push(format!(
                "{}: cannot read the material library `{name}` ({reason}); {outcome}.",
                req.label
            ));
            tobj::LoadError::OpenFileFailed
        })?;
        if let Some(candidate) = elsewhere {
            self.warnings.borrow_mut().push(format!(
                "{}: the material library `{name}` is not where the OBJ says but found from its folder as `{}`.",
                req.label,
                short_path(&candidate)
            ));
        }
        self.texts.borrow_mut().push((name.clone(), text.clone()));
        let text = mtl_for_tobj(&text).map_err(|(line, reason)| {
            self.warnings.borrow_mut().push(format!(
                "{}: cannot read the material library `{name}` (line {line}: {reason}); {outcome}.",
                req.label
            ));
            tobj::LoadError::MaterialParseError
        })?;
        tobj::load_mtl_buf(&mut text.as_bytes()).inspect_err(|e| {
            self.warnings.borrow_mut().push(format!(
                "{}: cannot read the material library `{name}` ({e}); {outcome}.",
                req.label
            ));
        })
    }

    /// The warnings about the libraries, and the text of each library read (its name, its
    /// text).
    pub(super) fn finish(self) -> (Vec<String>, Vec<(String, String)>) {
        (self.warnings.into_inner(), self.texts.into_inner())
    }
}

/// The names of an `mtllib` line's value: split at white space, except where a `\` escapes it
/// (`my\ materials.mtl` is one name, with a space, as tinyobjloader and Blender's importer read
/// it); any other `\` stays (`C:\models\a.mtl`).
fn library_names(value: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut name = String::new();
    let mut chars = value.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek().is_some_and(|n| n.is_whitespace()) => {
                name.extend(chars.next());
            }
            c if c.is_whitespace() => {
                if !name.is_empty() {
                    names.push(std::mem::take(&mut name));
                }
            }
            c => name.push(c),
        }
    }
    if !name.is_empty() {
        names.push(name);
    }
    names
}

/// MTL text as `tobj` can take it, or the line and the reason it cannot. The MTL format lets
/// `Ka`, `Kd`, `Ks` and `Ke` give one number for all three channels (`Kd 0.8`); tobj 4.0.5
/// panics on that (and on zero or two numbers), so one number is spelled out three times here
/// and zero or two are refused with their line. A material without a name (`newmtl` alone,
/// as some exporters write for an unnamed material) is named [`UNNAMED_MATERIAL`], as the
/// OBJ's `usemtl` alone is, where tobj refuses the file.
fn mtl_for_tobj(text: &str) -> Result<Cow<'_, str>, (usize, String)> {
    let mut fixed: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let replaced = mtl_line_for_tobj(line).map_err(|reason| (i + 1, reason))?;
        if replaced.is_some() && fixed.is_none() {
            let mut head = String::with_capacity(text.len() + 64);
            for earlier in text.lines().take(i) {
                head.push_str(earlier);
                head.push('\n');
            }
            fixed = Some(head);
        }
        if let Some(out) = fixed.as_mut() {
            out.push_str(replaced.as_deref().unwrap_or(line));
            out.push('\n');
        }
    }
    Ok(fixed.map_or(Cow::Borrowed(text), Cow::Owned))
}

/// What [`mtl_for_tobj`] puts for one MTL line: `None` to keep it.
fn mtl_line_for_tobj(line: &str) -> Result<Option<String>, String> {
    let mut words = line.split_whitespace();
    match words.next() {
        Some("newmtl") if words.next().is_none() => Ok(Some(format!("newmtl {UNNAMED_MATERIAL}"))),
        Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) => {
            let values: Vec<&str> = words.collect();
            let parses = values.iter().all(|v| v.parse::<f32>().is_ok());
            match values.len() {
                1 | 2 if !parses => Ok(None), // tobj reports the bad number as an error
                0 | 2 => Err(format!(
                    "`{key}` needs one number or three (r g b), got {}",
                    values.len()
                )),
                1 => {
                    let v = values[0];
                    Ok(Some(format!("{key} {v} {v} {v}")))
                }
                _ => Ok(None),
            }
        }
        _ => Ok(None),
    }
}

/// `usemtl` names ([`Facts::usemtl`]) that no loaded library defines: tobj silently gives
/// those faces no material.
pub(super) fn warn_unknown_usemtl(
    label: &str,
    facts: &Facts,
    known: &[tobj::Material],
    warnings: &mut Vec<String>,
) {
    let unknown: Vec<&str> = facts
        .usemtl
        .iter()
        .map(String::as_str)
        .filter(|name| !known.iter().any(|m| m.name == *name))
        .collect();
    if !unknown.is_empty() {
        let names: Vec<String> = unknown.iter().map(|n| format!("`{}`", short(n))).collect();
        warnings.push(format!(
            "{label}: `usemtl` names materials that no material library defines ({}); their faces use the default material.",
            list_some(&names)
        ));
    }
}

/// `illum 4` with a `Tf` and no `d` or `Tr` on every material, as Maya's exporter writes
/// every material whatever it is: `illum 4` there is no glass and no mirror, and `Tf` is the
/// material's opacity (`Tf 1` opaque, `Tf 0` clear: walls and windows), where by the MTL
/// definition it filters light passing through. Each such material is read as a plain one
/// (`illum 2`) with `d` the mean of its `Tf`; one below 1 stays glass (`illum 4`), its
/// transparency `1 − Tf`. One note says so. Other libraries are left as they are.
pub(super) fn read_maya_illum(
    materials: &mut [tobj::Material],
    label: &str,
    warnings: &mut Vec<String>,
) {
    // The mean of a material's `Tf`, if it is written as Maya writes every material.
    let opacity = |m: &tobj::Material| -> Option<f32> {
        if m.illumination_model != Some(4)
            || m.dissolve.is_some()
            || m.unknown_param.contains_key("Tr")
        {
            return None;
        }
        let words: Vec<f32> = m
            .unknown_param
            .get("Tf")?
            .split_whitespace()
            .map(|w| w.parse::<f32>().ok().filter(|x| (0.0..=1.0).contains(x)))
            .collect::<Option<_>>()?;
        (!words.is_empty()).then(|| words.iter().sum::<f32>() / words.len() as f32)
    };
    let opacities: Option<Vec<f32>> = materials.iter().map(opacity).collect();
    let Some(opacities) = opacities.filter(|o| !o.is_empty()) else {
        return;
    };
    for (m, &opacity) in materials.iter_mut().zip(&opacities) {
        m.dissolve = Some(opacity);
        if opacity >= 1.0 {
            m.illumination_model = Some(2);
        }
    }
    let clear = opacities.iter().filter(|&&o| o < 1.0).count();
    let n = materials.len();
    let all = if n == 1 {
        "its one material".to_string()
    } else {
        format!("all {n} materials")
    };
    let glass = match clear {
        0 => String::new(),
        1 => "; the 1 with `Tf` below 1 is glass, its transparency 1 − Tf".to_string(),
        k => format!("; the {k} with `Tf` below 1 are glass, their transparency 1 − Tf"),
    };
    warnings.push(format!(
        "{label}: `illum 4` (glass) with `Tf` and no `d` on {all}, as Maya writes every material: read as plain materials, `Tf` as their opacity{glass}."
    ));
}

/// The scene material for an MTL material: `<object>/<mtl name>`, reusing a scene material of
/// that name if the scene file defines one (so edited materials survive a save and reload).
/// A new material whose `Kd` is black under a `map_Kd` that loads (Maya writes `Kd 0` under
/// every texture) takes `Kd 1`, the texture being its colour, as the texture would otherwise
/// never show; the second value says so, for the caller's note.
pub(super) fn mtl_material(
    scene: &mut Scene,
    req: &MeshRequest,
    m: &tobj::Material,
    mtl_texts: &[(String, String)],
    warnings: &mut Vec<String>,
    textures_elsewhere: &mut Vec<(String, String)>,
) -> (MaterialId, bool) {
    let name = format!("{}/{}", req.object_name, m.name);
    let (id, fresh) = match scene.materials.iter().position(|x| x.name == name) {
        Some(i) => (MaterialId(i as u32), false),
        None => {
            let material = material_from_mtl(m, name, req.label, mtl_texts, warnings);
            scene.materials.push(material);
            (MaterialId(scene.materials.len() as u32 - 1), true)
        }
    };
    // Textures come from the MTL even when a `[[material]]` of this name overrides its
    // colours (a scene file has no texture keys, so a saved scene keeps its textures).
    let mut texture = |key: &str, file: &Option<String>| {
        let file = file.as_deref()?;
        load_texture(
            scene,
            req,
            &m.name,
            key,
            file,
            mtl_texts,
            warnings,
            textures_elsewhere,
        )
    };
    let diffuse = texture("map_Kd", &m.diffuse_texture);
    let ambient = texture("map_Ka", &m.ambient_texture);
    let placement = |file: &Option<String>| {
        file.as_deref()
            .map(|f| texture_statement(f).1)
            .unwrap_or_default()
    };
    let material = &mut scene.materials[id.0 as usize];
    if material.diffuse_map.is_none() && diffuse.is_some() {
        material.diffuse_map = diffuse;
        material.diffuse_map_placement = placement(&m.diffuse_texture);
    }
    if material.ambient_map.is_none() && ambient.is_some() {
        material.ambient_map = ambient;
        material.ambient_map_placement = placement(&m.ambient_texture);
    }
    let brightened = fresh && diffuse.is_some() && material.diffuse == Vec3::ZERO;
    if brightened {
        material.diffuse = Vec3::ONE;
    }
    (id, brightened)
}

/// The material of an OBJ's textured faces that no material library gives one, when a texture
/// named for the OBJ lies beside it ([`named_diffuse`]): `<object>/<texture file>`, white under
/// the texture for both the diffuse and the ambient term (a `[[material]]` of that name sets
/// its colours, as for an MTL material), with a note saying where the texture came from.
pub(super) fn named_material(
    scene: &mut Scene,
    req: &MeshRequest,
    warnings: &mut Vec<String>,
) -> Option<MaterialId> {
    let (texture, file) = named_diffuse(scene, req, warnings)?;
    let name = format!("{}/{file}", req.object_name);
    let i = match scene.materials.iter().position(|m| m.name == name) {
        Some(i) => i,
        None => {
            scene.materials.push(Material {
                name,
                ambient: Vec3::ONE,
                diffuse: Vec3::ONE,
                ..Material::default()
            });
            scene.materials.len() - 1
        }
    };
    let material = &mut scene.materials[i];
    material.diffuse_map = Some(texture);
    material.ambient_map = Some(texture);
    warnings.push(format!(
        "{}: no material library gives its faces a material; `{}` beside it, named for it, is taken as their texture.",
        req.label,
        short_path(&file)
    ));
    Some(MaterialId(i as u32))
}

/// Maps an MTL material to the Phong material: Ka→ambient, Kd→diffuse, Ks→specular,
/// Ns→shininess, Ni→ior, transparency = 1 − d (or Tr); `illum` 3 and 5 (ray-traced
/// reflection) set reflectivity = Ks; 4, 6 and 7 (glass) set reflectivity = Ks and
/// transparency = 1 − d, or 0.9 without `d`. Missing or invalid values fall back to
/// [`Material::default`] (invalid ones with a warning).
fn material_from_mtl(
    m: &tobj::Material,
    name: String,
    label: &str,
    mtl_texts: &[(String, String)],
    warnings: &mut Vec<String>,
) -> Material {
    let d = Material::default();
    let mut values = Values {
        m,
        label,
        mtl_texts,
        warnings: &mut *warnings,
    };
    let ambient = values.rgb(m.ambient, "Ka", d.ambient);
    let diffuse = values.rgb(m.diffuse, "Kd", d.diffuse);
    let specular = values.rgb(m.specular, "Ks", d.specular);
    let shininess = values
        .scalar(m.shininess, "Ns", |x| x >= 0.0, d.shininess)
        .unwrap_or(d.shininess);
    // `Ns 0` with a `Ks` (MeshLab writes `Ns 0` and `Ks 1` meaning "no highlight"): an
    // exponent of 0 would add the whole `Ks` wherever the light falls and wash the model out.
    // The highlight is dropped; a mirror's reflectivity (`Ks`, below) is kept.
    let no_highlight = m.shininess.is_some() && shininess == 0.0 && specular != Vec3::ZERO;
    let ior = values
        .scalar(m.optical_density, "Ni", |x| x > 0.0, d.ior)
        .unwrap_or(d.ior);
    let glass = matches!(m.illumination_model, Some(4 | 6 | 7));
    let dissolve = values.dissolve(glass);
    if no_highlight {
        warnings.push(format!(
            "{label}: material `{}` has `Ns 0`, which would add all of `Ks` wherever light falls; shown without a highlight (`Ks 0`).",
            short(&m.name)
        ));
    }
    let mirror = glass || matches!(m.illumination_model, Some(3 | 5));
    let transparency = match dissolve {
        Some(dissolve) => 1.0 - dissolve,
        None if glass => 0.9,
        None => 0.0,
    };
    Material {
        name,
        ambient,
        diffuse,
        specular: if no_highlight { Vec3::ZERO } else { specular },
        shininess,
        reflectivity: if mirror { specular } else { Vec3::ZERO },
        transparency: Vec3::splat(transparency),
        ior,
        diffuse_map: None,
        ambient_map: None,
        diffuse_map_placement: Default::default(),
        ambient_map_placement: Default::default(),
    }
}

/// The values of one MTL material as they are read, with one warning for each invalid one.
struct Values<'a> {
    m: &'a tobj::Material,
    label: &'a str,
    /// The material libraries read (name, text), to say on which line a value stands.
    mtl_texts: &'a [(String, String)],
    warnings: &'a mut Vec<String>,
}

impl Values<'_> {
    fn invalid(&mut self, key: &str, got: String, fallback: String) {
        let place = statement_place(self.mtl_texts, &self.m.name, key, None)
            .map(|p| format!(" ({p})"))
            .unwrap_or_default();
        self.warnings.push(format!(
            "{}: material `{}`{place} has an invalid `{key}` {got}; using {fallback}.",
            self.label,
            short(&self.m.name)
        ));
    }

    /// A colour, or `fallback` when it is absent or invalid (not finite, or negative).
    fn rgb(&mut self, value: Option<[f32; 3]>, key: &str, fallback: Vec3) -> Vec3 {
        let Some(a) = value else {
            return fallback;
        };
        let v = Vec3::from_array(a);
        if v.is_finite() && v.cmpge(Vec3::ZERO).all() {
            v
        } else {
            self.invalid(key, format!("{a:?}"), format!("{fallback}"));
            fallback
        }
    }

    /// A finite number that passes `ok`, or `None` when it is absent or invalid (the warning
    /// names `fallback`, what the caller uses instead).
    fn scalar(
        &mut self,
        value: Option<f32>,
        key: &str,
        ok: fn(f32) -> bool,
        fallback: f32,
    ) -> Option<f32> {
        match value {
            Some(x) if x.is_finite() && ok(x) => Some(x),
            Some(x) => {
                self.invalid(key, x.to_string(), fallback.to_string());
                None
            }
            None => None,
        }
    }

    /// The opacity: `d`, else 1 − `Tr`, else `None`. `Tr 1` without `d` on a material that is
    /// not glass (`glass`) is opaque, with a warning: MeshLab and others write it meaning opaque
    /// (Tr as opacity); an invisible material is never what is meant.
    fn dissolve(&mut self, glass: bool) -> Option<f32> {
        let m = self.m;
        let in_unit = |x: f32| (0.0..=1.0).contains(&x);
        if let Some(d) = self.scalar(m.dissolve, "d", in_unit, 1.0) {
            return Some(d);
        }
        let tr = m
            .unknown_param
            .get("Tr")
            .and_then(|t| t.trim().parse::<f32>().ok());
        let tr = self.scalar(tr, "Tr", in_unit, 0.0)?;
        if tr == 1.0 && !glass {
            self.warnings.push(format!(
                "{}: material `{}` has `Tr 1` (fully transparent) without being glass; taken as opaque, as MeshLab means it.",
                self.label,
                short(&m.name)
            ));
            return Some(1.0);
        }
        Some(1.0 - tr)
    }
}

#[cfg(test)]
mod tests {
    use super::super::read::quietly;
    use super::*;

    #[test]
    fn a_statement_is_placed_on_its_materials_last_line_of_that_key() {
        let libs = vec![
            ("a.mtl".to_string(), "newmtl wood\nKd 1 1 1\n".to_string()),
            (
                "b.mtl".to_string(),
                "# b\nnewmtl  red paint \nKd 1 0 0\nmap_Kd r.png\n\nKd nan 0 0\nnewmtl blue\nKd 0 0 1\nNi 0\n"
                    .to_string(),
            ),
        ];
        // tobj keeps a material's last `Kd`: the line named is that one, in its own block.
        assert_eq!(
            statement_place(&libs, "red paint", "Kd", None).as_deref(),
            Some("`b.mtl` line 6")
        );
        assert_eq!(
            statement_place(&libs, "blue", "Ni", None).as_deref(),
            Some("`b.mtl` line 9")
        );
        assert_eq!(
            statement_place(&libs, "wood", "Kd", None).as_deref(),
            Some("`a.mtl` line 2")
        );
        assert_eq!(
            statement_place(&libs, "red paint", "map_Kd", Some("r.png")).as_deref(),
            Some("`b.mtl` line 4")
        );
        // Another material's key, a key the block lacks, a texture it does not name: nowhere.
        assert_eq!(statement_place(&libs, "wood", "Ni", None), None);
        assert_eq!(
            statement_place(&libs, "red paint", "map_Kd", Some("q.png")),
            None
        );
        assert_eq!(statement_place(&libs, "green", "Kd", None), None);
        // A key is a whole word: `Kd` is not `Kds`, nor found inside another word.
        let odd = vec![("c.mtl".to_string(), "newmtl x\nKds 1\n#Kd 1\n".to_string())];
        assert_eq!(statement_place(&odd, "x", "Kd", None), None);
    }

    #[test]
    fn mtl_colours_of_one_number_are_spelled_out_and_two_are_refused() {
        let text = "newmtl a\nKd 0.8\nKs 1 2 3\n";
        assert_eq!(
            mtl_for_tobj(text).expect("one number is valid MTL"),
            "newmtl a\nKd 0.8 0.8 0.8\nKs 1 2 3\n"
        );
        assert!(matches!(mtl_for_tobj("Ka 1 2 3\n"), Ok(Cow::Borrowed(_))));
        let e = mtl_for_tobj("newmtl a\n\nKa 1 2\n").expect_err("two numbers");
        assert_eq!(
            e,
            (3, "`Ka` needs one number or three (r g b), got 2".into())
        );
        assert!(mtl_for_tobj("Ke\n").is_err());
        // Not numbers: tobj's own error, not ours.
        assert!(mtl_for_tobj("Kd x y\n").is_ok());
        // tobj itself panics on these; through `mtl_for_tobj` it never sees them.
        for bad in ["newmtl a\nKd 1 2\n", "newmtl a\nKs\n"] {
            assert!(quietly(|| tobj::load_mtl_buf(&mut bad.as_bytes())).is_err());
        }
    }
}
