//! How the materials panel names a material: by its file and the OBJ objects and groups
//! (`o`, `g`) that use it, "kitchen: White.001 (object Cabinet_3)", so a material of a big OBJ
//! is found by what it covers.

use std::collections::HashSet;

use super::{ObjectId, ObjectSource, Scene};

/// The title of one material in the materials panel, and the names of every OBJ object or
/// group that uses it (the title shows the first two).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MaterialTitle {
    pub title: String,
    pub users: Vec<String>,
}

/// Users named in a title before "+N" counts the rest.
pub const NAMED_USERS: usize = 2;

/// The titles of all of `scene`'s materials, in order: one pass over the mesh parts, so a file
/// with thousands of objects costs that many steps, not that many per material.
pub fn material_titles(scene: &Scene) -> Vec<MaterialTitle> {
    let mut users: Vec<Vec<(ObjectId, &str)>> = vec![Vec::new(); scene.materials.len()];
    let mut seen = HashSet::new();
    for p in scene.parts.iter() {
        let m = p.material.0 as usize;
        if m < users.len() && seen.insert((m, p.object, p.name.as_str())) {
            users[m].push((p.object, p.name.as_str()));
        }
    }
    scene
        .materials
        .iter()
        .zip(users)
        .map(|(m, users)| title(scene, &m.name, &users))
        .collect()
}

/// `name` as the panel shows it: an MTL material of mesh `kitchen` (named `kitchen/White.001`
/// in the scene) reads "kitchen: White.001"; with the mesh it came from, if any.
fn shown_name(scene: &Scene, name: &str) -> (String, Option<ObjectId>) {
    let mesh = scene.objects.iter().enumerate().find(|(_, o)| {
        matches!(o.source, ObjectSource::Mesh { .. })
            && name
                .strip_prefix(o.name.as_str())
                .is_some_and(|rest| rest.len() > 1 && rest.starts_with('/'))
    });
    match mesh {
        Some((i, o)) => (
            format!("{}: {}", o.name, &name[o.name.len() + 1..]),
            Some(ObjectId(i as u32)),
        ),
        None => (name.to_string(), None),
    }
}

fn title(scene: &Scene, name: &str, users: &[(ObjectId, &str)]) -> MaterialTitle {
    let (shown, owner) = shown_name(scene, name);
    // A part of the material's own mesh by its name alone; of another mesh, with the mesh's.
    let users: Vec<String> = users
        .iter()
        .map(
            |&(object, part)| match scene.objects.get(object.0 as usize) {
                Some(o) if Some(object) != owner => format!("{}: {part}", o.name),
                _ => part.to_string(),
            },
        )
        .collect();
    let named = users[..users.len().min(NAMED_USERS)].join(", ");
    let title = match users.len() {
        0 => shown,
        1 => format!("{shown} (object {named})"),
        n if n <= NAMED_USERS => format!("{shown} (objects {named})"),
        n => format!("{shown} (objects {named} +{})", n - NAMED_USERS),
    };
    MaterialTitle { title, users }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, MaterialId, MeshPart, NormalsMode, Object};
    use glam::Vec3;
    use std::sync::Arc;

    fn mesh(name: &str) -> Object {
        Object {
            name: name.into(),
            source: ObjectSource::Mesh {
                file: format!("{name}.obj"),
                material: None,
                translate: Vec3::ZERO,
                rotate_deg: Vec3::ZERO,
                scale: Vec3::ONE,
                normals: NormalsMode::File,
                crease_angle_deg: 60.0,
            },
        }
    }

    fn part(object: u32, material: u32, name: &str) -> MeshPart {
        MeshPart {
            first_triangle: 0,
            triangle_count: 1,
            object: ObjectId(object),
            material: MaterialId(material),
            name: name.into(),
        }
    }

    fn material(name: &str) -> Material {
        Material {
            name: name.into(),
            ..Material::default()
        }
    }

    #[test]
    fn materials_are_named_by_file_and_the_objects_that_use_them() {
        let mut scene = Scene {
            objects: vec![mesh("kitchen"), mesh("room")],
            materials: [
                "kitchen/White.001",
                "kitchen/Steel",
                "glass",
                "room/wall",
                "kitchen/",
            ]
            .map(material)
            .to_vec(),
            ..Scene::default()
        };
        let mut parts = vec![part(0, 0, "Cabinet_3")];
        for name in ["Door", "Cabinet_3", "Shelf", "Drawer", "Lamp", "Sink"] {
            // Cabinet_3 twice (two runs, as after a `usemtl` back and forth) counts once.
            parts.push(part(0, 1, name));
        }
        parts.push(part(0, 1, "Door"));
        parts.push(part(0, 2, "Window"));
        parts.push(part(1, 2, "pane"));
        scene.parts = Arc::new(parts);
        let titles: Vec<String> = material_titles(&scene)
            .into_iter()
            .map(|t| t.title)
            .collect();
        assert_eq!(
            titles,
            [
                "kitchen: White.001 (object Cabinet_3)",
                "kitchen: Steel (objects Door, Cabinet_3 +4)",
                // A scene material used by two meshes names each part with its mesh.
                "glass (objects kitchen: Window, room: pane)",
                // Used by no named part: the file and the material only.
                "room: wall",
                "kitchen/",
            ]
        );
        let steel = &material_titles(&scene)[1];
        assert_eq!(
            steel.users,
            ["Door", "Cabinet_3", "Shelf", "Drawer", "Lamp", "Sink"]
        );
    }
}
