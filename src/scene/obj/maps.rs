//! The textures an MTL material names (`map_Kd`, `map_Ka`): found next to the OBJ, decoded
//! ([`crate::scene::texture`]) within what the memory budget has left, each file loaded once
//! per scene; one that cannot be used is a warning and its material keeps its flat colour.

use std::sync::Arc;

use glam::Vec2;

use super::paths::{file_stem, sibling};
use super::read::quietly;
use super::request::MeshRequest;
use crate::scene::budget::{MemoryLimit, memory_limit};
use crate::scene::diag::{short, short_path};
use crate::scene::texture::decode_texture;
use crate::scene::{MapPlacement, Scene, Texture, TextureId};

/// The file a `map_Kd` value names and where the map lies (`-s`, `-o`, `-clamp`): the value
/// after its options (`-s 2 2 1 wood.png`, `-o 0.5 0 -bm 1 my wood.png`), each option taking
/// as many words after it as it may have (up to three numbers for `-s`, `-o`, `-t`; two for
/// `-mm`; one number, `on`/`off` or a name for the others, as `-colorspace sRGB`), so a file
/// name with spaces stays whole. An option this does not know takes the numbers that follow
/// it; `-t` (turbulence) and the others change nothing here.
pub(super) fn texture_statement(value: &str) -> (&str, MapPlacement) {
    let mut rest = value.trim();
    let mut place = MapPlacement::default();
    while let Some(option) = rest
        .strip_prefix('-')
        .and_then(|r| r.split_whitespace().next())
    {
        rest = rest[1 + option.len()..].trim_start();
        let most = match option {
            "s" | "o" | "t" => 3,
            "mm" => 2,
            "blendu" | "blendv" | "boost" | "texres" | "clamp" | "bm" | "imfchan" | "type"
            | "cc" | "colorspace" => 1,
            _ => 3,
        };
        let mut numbers = Vec::new();
        for _ in 0..most {
            let Some(word) = rest.split_whitespace().next() else {
                break;
            };
            let number = word.parse::<f32>().ok().filter(|n| n.is_finite());
            let switch =
                matches!(word, "on" | "off") || matches!(option, "imfchan" | "type" | "colorspace");
            if number.is_none() && !switch {
                break;
            }
            if option == "clamp" {
                place.clamp = word == "on";
            }
            // Nothing after it: it is the file (`-bm 1 2.png` names `2.png`).
            if rest[word.len()..].trim().is_empty() {
                break;
            }
            numbers.extend(number);
            rest = rest[word.len()..].trim_start();
        }
        let at = |i: usize, default: f32| numbers.get(i).copied().unwrap_or(default);
        match option {
            "s" if !numbers.is_empty() => place.scale = Vec2::new(at(0, 1.0), at(1, 1.0)),
            "o" if !numbers.is_empty() => place.offset = Vec2::new(at(0, 0.0), at(1, 0.0)),
            _ => {}
        }
    }
    (rest.trim(), place)
}

/// Where to look for a file `file` as a model names it (a texture in an MTL, a material
/// library in an OBJ), best first: as written, then,
/// for a path written on another machine (`C:\Users\me\model\tex\wood.png`, `tex\wood.png`,
/// `/home/me/model/tex/wood.png`), with `/` for `\` and each shorter tail of it down to the
/// file name, each next to the OBJ: a model copied from elsewhere keeps its textures beside it.
/// Last, each tail that keeps a folder (`tex/wood.png`) in the OBJ's folder's parent and its
/// parent's parent ([`ANCESTORS`]): a model pack whose textures sit in a folder beside the
/// models' (`data/toys/sorter.obj` naming `E:\dev\data\table\table.png`, found as
/// `../table/table.png`). A bare file name is not looked for there.
pub(super) fn candidates(file: &str) -> Vec<String> {
    let mut out = vec![file.to_string()];
    let slashed = file.replace('\\', "/");
    let parts: Vec<&str> = slashed
        .split('/')
        .filter(|p| !p.is_empty() && *p != "." && *p != ".." && !(p.len() == 2 && p.ends_with(':')))
        .collect();
    let tails: Vec<String> = (0..parts.len()).map(|i| parts[i..].join("/")).collect();
    let up = (1..=ANCESTORS).flat_map(|n| {
        let tails = &tails[..tails.len().saturating_sub(1)];
        tails.iter().map(move |t| format!("{}{t}", "../".repeat(n)))
    });
    for candidate in std::iter::once(slashed.clone())
        .chain(tails.iter().cloned())
        .chain(up)
    {
        if !out.contains(&candidate) {
            out.push(candidate);
        }
    }
    out
}

/// How many folders above the OBJ's [`candidates`] looks in.
const ANCESTORS: usize = 2;

/// Where material `material`'s `key` statement stands, as warnings name it ("`LIB` line N"):
/// the last line (the one tobj keeps) of that material's block in the first of the libraries
/// `mtl_texts` (name, text) that has one starting with `key` and holding `holding`, when
/// given; `None` when none does.
pub(super) fn statement_place(
    mtl_texts: &[(String, String)],
    material: &str,
    key: &str,
    holding: Option<&str>,
) -> Option<String> {
    mtl_texts.iter().find_map(|(mtl, text)| {
        let (mut inside, mut last) = (false, None);
        for (i, line) in text.lines().enumerate() {
            let Some(first) = line.split_whitespace().next() else {
                continue;
            };
            if first == "newmtl" {
                // The name as tobj reads it: the rest of the line, trimmed.
                inside = line.trim_start()[6..].trim() == material;
            } else if inside && first == key && holding.is_none_or(|h| line.contains(h)) {
                last = Some(i);
            }
        }
        last.map(|i| format!("`{mtl}` line {}", i + 1))
    })
}

/// The texture `value` of MTL statement `key` of material `material`, loaded once per scene
/// (materials that share a file share the texture); `None` with one warning naming the file
/// and the MTL line when it cannot be read, decoded, or fit in the memory budget. A file not
/// found where the MTL says is looked for as [`candidates`] lists; one found so goes into
/// `elsewhere` (as written, as found) for the caller's one note.
#[allow(clippy::too_many_arguments)]
pub(super) fn load_texture(
    scene: &mut Scene,
    req: &MeshRequest,
    material: &str,
    key: &str,
    value: &str,
    mtl_texts: &[(String, String)],
    warnings: &mut Vec<String>,
    elsewhere: &mut Vec<(String, String)>,
) -> Option<TextureId> {
    let file = texture_statement(value).0;
    let tails = candidates(file);
    let paths: Vec<String> = tails.iter().map(|c| sibling(req.key, c)).collect();
    let place = statement_place(mtl_texts, material, key, Some(file))
        .unwrap_or_else(|| "its material library".into());
    let fail = |reason: String, warnings: &mut Vec<String>| {
        warnings.push(format!(
            "{}: material `{}` ({place}): cannot use the texture `{}` of `{key}` ({reason}); its flat colour stays.",
            req.label,
            short(material),
            short_path(file)
        ));
        None
    };
    // The first candidate that can be read; the reason given otherwise is the written path's.
    let mut first_reason = None;
    let mut found = None;
    for (i, path) in paths.iter().enumerate() {
        if let Some(t) = scene.textures.iter().position(|t| t.name == *path) {
            return Some(TextureId(t as u32));
        }
        match (req.resolve_bytes)(path) {
            Ok(bytes) => {
                found = Some((i, bytes));
                break;
            }
            Err(reason) => {
                first_reason.get_or_insert(reason);
            }
        }
    }
    let Some((i, bytes)) = found else {
        return fail(first_reason.unwrap_or_default(), warnings);
    };
    let path = &paths[i];
    match add_texture(scene, path, &bytes) {
        Ok(id) => {
            if i > 0 {
                elsewhere.push((file.to_string(), tails[i].clone()));
            }
            Some(id)
        }
        Err(reason) => fail(reason, warnings),
    }
}

/// The image `bytes` read from `path` decoded into the scene's textures within what the memory
/// budget has left, or the reason it cannot be. One file named two ways (`Tex\Wood.png`,
/// `tex/wood.PNG`) or two copies of one image are one texture.
fn add_texture(scene: &mut Scene, path: &str, bytes: &[u8]) -> Result<TextureId, String> {
    let limit = memory_limit();
    let used: u64 = scene
        .textures
        .iter()
        .map(|t| Texture::bytes(t.width, t.height))
        .sum();
    let left = MemoryLimit {
        bytes: limit.bytes.saturating_sub(used),
        source: limit.source,
    };
    let texture = quietly(|| decode_texture(path, bytes, &left))
        .unwrap_or_else(|()| Err("the image reader failed on it".into()))?;
    let same = scene.textures.iter().position(|t| {
        (t.width, t.height) == (texture.width, texture.height) && t.texels == texture.texels
    });
    if let Some(t) = same {
        return Ok(TextureId(t as u32));
    }
    scene.textures.push(Arc::new(texture));
    Ok(TextureId(scene.textures.len() as u32 - 1))
}

/// The extensions tried for a texture named for its OBJ ([`named_diffuse`]).
const NAMED_DIFFUSE_EXTENSIONS: &[&str] = &["png", "tga", "jpg", "jpeg", "bmp"];

/// The diffuse texture a model pack ships beside an OBJ that names no material, named for the
/// OBJ: `<stem>_diffuse.<ext>` (tinyrenderer's `african_head_diffuse.tga`, raylib's
/// `castle_diffuse.png`), `ext` one of [`NAMED_DIFFUSE_EXTENSIONS`] (the resolver finds a file
/// whatever the case of its name, `.TGA` for `.tga`). Its id and file name, or `None` when
/// there is none; one found that cannot be used is a warning.
pub(super) fn named_diffuse(
    scene: &mut Scene,
    req: &MeshRequest,
    warnings: &mut Vec<String>,
) -> Option<(TextureId, String)> {
    let stem = file_stem(req.key)?;
    for e in NAMED_DIFFUSE_EXTENSIONS {
        let name = format!("{stem}_diffuse.{e}");
        let path = sibling(req.key, &name);
        if let Some(t) = scene.textures.iter().position(|t| t.name == path) {
            return Some((TextureId(t as u32), name));
        }
        let Ok(bytes) = (req.resolve_bytes)(&path) else {
            continue;
        };
        return match add_texture(scene, &path, &bytes) {
            Ok(id) => Some((id, name)),
            Err(reason) => {
                warnings.push(format!(
                    "{}: cannot use `{}`, the texture named for it, on its faces without a material ({reason}); they keep the default grey.",
                    req.label,
                    short_path(&name)
                ));
                None
            }
        };
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_options_give_the_file_and_the_placement() {
        let plain = MapPlacement::default();
        let s = |u, v| MapPlacement {
            scale: Vec2::new(u, v),
            ..plain
        };
        assert_eq!(texture_statement("wood.png"), ("wood.png", plain));
        assert_eq!(texture_statement("  my wood.png "), ("my wood.png", plain));
        assert_eq!(
            texture_statement("-s 4 2 1 floor.png"),
            ("floor.png", s(4.0, 2.0))
        );
        assert_eq!(
            texture_statement("-s 3 floor.png"),
            ("floor.png", s(3.0, 1.0))
        );
        assert_eq!(
            texture_statement("-o 0.5 0.25 -s 2 2 my floor tiles.png"),
            (
                "my floor tiles.png",
                MapPlacement {
                    scale: Vec2::splat(2.0),
                    offset: Vec2::new(0.5, 0.25),
                    clamp: false,
                }
            )
        );
        // Options that change nothing here, with their words; a number that is the file.
        assert_eq!(
            texture_statement("-bm 0.3 -imfchan l -type sphere -mm 0 1 bump.png"),
            ("bump.png", plain)
        );
        // A colour space is a name (tinyobjloader's and Blender's `-colorspace sRGB`).
        assert_eq!(
            texture_statement("-colorspace sRGB -o 0.1 diffuse.jpg"),
            (
                "diffuse.jpg",
                MapPlacement {
                    offset: Vec2::new(0.1, 0.0),
                    ..plain
                }
            )
        );
        let clamped = MapPlacement {
            clamp: true,
            ..plain
        };
        assert_eq!(
            texture_statement("-clamp on decal.png"),
            ("decal.png", clamped)
        );
        assert_eq!(
            texture_statement("-clamp off decal.png"),
            ("decal.png", plain)
        );
        assert_eq!(texture_statement("-bm 1 2.png"), ("2.png", plain));
        assert_eq!(texture_statement("-blendu off 7"), ("7", plain));
        // An option this does not know takes its numbers.
        assert_eq!(texture_statement("-halo 1 2 wood.png"), ("wood.png", plain));
        // A scale that is no finite number is not one.
        assert_eq!(
            texture_statement("-s nan wood.png"),
            ("nan wood.png", plain)
        );
    }

    #[test]
    fn another_machines_paths_are_tried_as_tails_with_slashes() {
        assert_eq!(candidates("wood.png"), ["wood.png"]);
        assert_eq!(
            candidates("tex/wood.png"),
            [
                "tex/wood.png",
                "wood.png",
                "../tex/wood.png",
                "../../tex/wood.png"
            ]
        );
        assert_eq!(
            candidates("C:\\Users\\me\\tex\\wood.png"),
            [
                "C:\\Users\\me\\tex\\wood.png",
                "C:/Users/me/tex/wood.png",
                "Users/me/tex/wood.png",
                "me/tex/wood.png",
                "tex/wood.png",
                "wood.png",
                "../Users/me/tex/wood.png",
                "../me/tex/wood.png",
                "../tex/wood.png",
                "../../Users/me/tex/wood.png",
                "../../me/tex/wood.png",
                "../../tex/wood.png",
            ]
        );
        assert_eq!(
            candidates("/home/u/m/./wood.png")[..5],
            [
                "/home/u/m/./wood.png",
                "home/u/m/wood.png",
                "u/m/wood.png",
                "m/wood.png",
                "wood.png"
            ]
        );
        // Written relative to a folder beside the OBJ's: as written, then as tails.
        assert_eq!(
            candidates("../maps/wood.png"),
            [
                "../maps/wood.png",
                "maps/wood.png",
                "wood.png",
                "../../maps/wood.png"
            ]
        );
    }
}
