//! The textures an MTL material names (`map_Kd`, `map_Ka`): found next to the OBJ, decoded
//! ([`crate::scene::texture`]) within what the memory budget has left, each file loaded once
//! per scene; one that cannot be used is a warning and its material keeps its flat colour.

use std::sync::Arc;

use super::paths::sibling;
use super::read::quietly;
use super::request::MeshRequest;
use crate::scene::budget::{MemoryLimit, memory_limit};
use crate::scene::diag::{short, short_path};
use crate::scene::texture::decode_texture;
use crate::scene::{Scene, Texture, TextureId};

/// The file a `map_Kd` value names: the value, or its last word when it starts with options
/// (`-s 2 2 1 wood.png`).
fn texture_file(value: &str) -> &str {
    let value = value.trim();
    if value.starts_with('-') {
        value.split_whitespace().last().unwrap_or(value)
    } else {
        value
    }
}

/// Where to look for a file `file` as a model names it (a texture in an MTL, a material
/// library in an OBJ), best first: as written, then,
/// for a path written on another machine (`C:\Users\me\model\tex\wood.png`, `tex\wood.png`,
/// `/home/me/model/tex/wood.png`), with `/` for `\` and each shorter tail of it down to the
/// file name, each next to the OBJ: a model copied from elsewhere keeps its textures beside it.
pub(super) fn candidates(file: &str) -> Vec<String> {
    let mut out = vec![file.to_string()];
    let slashed = file.replace('\\', "/");
    let parts: Vec<&str> = slashed
        .split('/')
        .filter(|p| !p.is_empty() && *p != "." && !(p.len() == 2 && p.ends_with(':')))
        .collect();
    let tails = (0..parts.len()).map(|i| parts[i..].join("/"));
    for candidate in std::iter::once(slashed.clone()).chain(tails) {
        if !out.contains(&candidate) {
            out.push(candidate);
        }
    }
    out
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
    let file = texture_file(value);
    let tails = candidates(file);
    let paths: Vec<String> = tails.iter().map(|c| sibling(req.key, c)).collect();
    let place = mtl_texts
        .iter()
        .find_map(|(mtl, text)| {
            text.lines()
                .position(|l| {
                    let l = l.trim_start();
                    l.starts_with(key) && l.contains(file)
                })
                .map(|i| format!("`{mtl}` line {}", i + 1))
        })
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
    let decoded = quietly(|| decode_texture(path, &bytes, &left))
        .unwrap_or_else(|()| Err("the image reader failed on it".into()));
    match decoded {
        Ok(texture) => {
            if i > 0 {
                elsewhere.push((file.to_string(), tails[i].clone()));
            }
            // One file named two ways (`Tex\Wood.png`, `tex/wood.PNG`) or two copies of one
            // image: one texture.
            let same = scene.textures.iter().position(|t| {
                (t.width, t.height) == (texture.width, texture.height) && t.texels == texture.texels
            });
            if let Some(t) = same {
                return Some(TextureId(t as u32));
            }
            scene.textures.push(Arc::new(texture));
            Some(TextureId(scene.textures.len() as u32 - 1))
        }
        Err(reason) => fail(reason, warnings),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn another_machines_paths_are_tried_as_tails_with_slashes() {
        assert_eq!(candidates("wood.png"), ["wood.png"]);
        assert_eq!(candidates("tex/wood.png"), ["tex/wood.png", "wood.png"]);
        assert_eq!(
            candidates("C:\\Users\\me\\tex\\wood.png"),
            [
                "C:\\Users\\me\\tex\\wood.png",
                "C:/Users/me/tex/wood.png",
                "Users/me/tex/wood.png",
                "me/tex/wood.png",
                "tex/wood.png",
                "wood.png"
            ]
        );
        assert_eq!(
            candidates("/home/u/m/./wood.png"),
            [
                "/home/u/m/./wood.png",
                "home/u/m/wood.png",
                "u/m/wood.png",
                "m/wood.png",
                "wood.png"
            ]
        );
    }
}
