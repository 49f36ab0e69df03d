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

/// The texture `value` of MTL statement `key` of material `material`, loaded once per scene
/// (materials that share a file share the texture); `None` with one warning naming the file
/// and the MTL line when it cannot be read, decoded, or fit in the memory budget.
pub(super) fn load_texture(
    scene: &mut Scene,
    req: &MeshRequest,
    material: &str,
    key: &str,
    value: &str,
    mtl_texts: &[(String, String)],
    warnings: &mut Vec<String>,
) -> Option<TextureId> {
    let file = texture_file(value);
    let path = sibling(req.key, file);
    if let Some(i) = scene.textures.iter().position(|t| t.name == path) {
        return Some(TextureId(i as u32));
    }
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
    let loaded = (req.resolve_bytes)(&path).and_then(|bytes| {
        quietly(|| decode_texture(&path, &bytes, &left))
            .unwrap_or_else(|()| Err("the image reader failed on it".into()))
    });
    match loaded {
        Ok(texture) => {
            scene.textures.push(Arc::new(texture));
            Some(TextureId(scene.textures.len() as u32 - 1))
        }
        Err(reason) => {
            warnings.push(format!(
                "{}: material `{}` ({place}): cannot use the texture `{}` of `{key}` ({reason}); its flat colour stays.",
                req.label,
                short(material),
                short_path(file)
            ));
            None
        }
    }
}
