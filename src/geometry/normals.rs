//! Vertex normals computed from a mesh's triangles: the smooth shading of a mesh whose file
//! gives none (`[[mesh]]` `normals = "smooth"`, docs/design.md, "Scene files").

use std::collections::HashMap;

use glam::Vec3;

/// Area-weighted vertex normals for `triangles`, whose corners `vertices` gives: at each
/// corner, the sum of the cross products (twice the area times the unit normal) of the
/// triangles that share the corner's position and whose normal is within `crease_angle_deg` of
/// this triangle's, normalised. Corners are shared by position, so a mesh split into groups or
/// materials is still smooth across them. With `groups` (an OBJ's smoothing groups, one per
/// triangle), a triangle averages only with triangles of its own group, and one of group 0
/// keeps its own normal (flat). Returns the normals and each triangle's indices.
pub fn smooth_normals<T>(
    triangles: &[T],
    vertices: impl Fn(&T) -> [Vec3; 3],
    crease_angle_deg: f32,
    groups: Option<&[u32]>,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let group = |k: usize| groups.map_or(1, |g| g.get(k).copied().unwrap_or(1));
    let key = |p: Vec3| p.to_array().map(|x| (x + 0.0).to_bits());
    let mut ids: HashMap<[u32; 3], u32> = HashMap::with_capacity(triangles.len());
    let corner_ids: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            vertices(t).map(|p| {
                let next = ids.len() as u32;
                *ids.entry(key(p)).or_insert(next)
            })
        })
        .collect();
    // The triangles around each position, as one flat list with offsets.
    let mut start = vec![0u32; ids.len() + 1];
    for c in corner_ids.iter().flatten() {
        start[*c as usize + 1] += 1;
    }
    for i in 0..ids.len() {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut around = vec![0u32; 3 * triangles.len()];
    for (k, c) in corner_ids.iter().enumerate() {
        for &id in c {
            around[fill[id as usize] as usize] = k as u32;
            fill[id as usize] += 1;
        }
    }
    let weighted: Vec<Vec3> = triangles
        .iter()
        .map(|t| {
            let v = vertices(t);
            (v[1] - v[0]).cross(v[2] - v[0])
        })
        .collect();
    let unit: Vec<Vec3> = weighted.iter().map(|w| w.normalize_or_zero()).collect();
    let cos_crease = crease_angle_deg.to_radians().cos();
    let mut normals = Vec::with_capacity(3 * triangles.len());
    let mut indices = Vec::with_capacity(triangles.len());
    for (k, c) in corner_ids.iter().enumerate() {
        let mut idx = [0u32; 3];
        for (slot, &id) in idx.iter_mut().zip(c) {
            let (a, b) = (start[id as usize] as usize, start[id as usize + 1] as usize);
            let mut sum = Vec3::ZERO;
            let own = group(k);
            for &other in &around[a..b] {
                let other_group = group(other as usize);
                let joined = other as usize == k || (own != 0 && other_group == own);
                if joined && unit[k].dot(unit[other as usize]) >= cos_crease {
                    sum += weighted[other as usize];
                }
            }
            // The triangle itself is always in its own sum, so this has a direction unless
            // the sum overflowed.
            let n = sum.normalize_or_zero();
            *slot = normals.len() as u32;
            normals.push(if n == Vec3::ZERO { unit[k] } else { n });
        }
        indices.push(idx);
    }
    (normals, indices)
}
