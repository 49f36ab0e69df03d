//! Procedural closed meshes for the sweeps: an octahedron subdivided onto a sphere. Every
//! shared vertex is one `f32` value used by all its triangles (indexed), so the mesh is closed
//! exactly as a mesh loaded from a file is: any ray that slips between two triangles is the
//! intersection method's fault (docs/stability.md, row T1), not the mesh's.

use std::collections::HashMap;

use glam::{DVec3, Vec3};

/// An octahedron subdivided `levels` times (each triangle into four), its vertices pushed onto
/// the sphere of radius `scale` around `center`: `8·4^levels` triangles, counter-clockwise
/// seen from outside. Vertices are computed in `f64` on the unit sphere and rounded once.
pub fn octasphere(levels: u32, scale: f32, center: Vec3) -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let mut verts: Vec<DVec3> = vec![
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];
    let mut tris: Vec<[usize; 3]> = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    for _ in 0..levels {
        let mut mid: HashMap<(usize, usize), usize> = HashMap::with_capacity(tris.len() * 2);
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let mut m = |x: usize, y: usize| {
                *mid.entry((x.min(y), x.max(y))).or_insert_with(|| {
                    verts.push(((verts[x] + verts[y]) * 0.5).normalize());
                    verts.len() - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        tris = next;
    }
    let verts = verts.iter().map(|v| center + v.as_vec3() * scale).collect();
    (verts, tris)
}

/// The triangles of an indexed mesh as vertex triples.
pub fn triangles(verts: &[Vec3], tris: &[[usize; 3]]) -> Vec<[Vec3; 3]> {
    tris.iter().map(|t| t.map(|i| verts[i])).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octasphere_is_closed_and_outward() {
        let (verts, tris) = octasphere(2, 2.0, Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(tris.len(), 128);
        // Closed: every edge is shared by exactly two triangles, in opposite directions.
        let mut edges = HashMap::new();
        for t in &tris {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1);
            assert_eq!(edges.get(&(b, a)), Some(&1));
        }
        for v in triangles(&verts, &tris) {
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            let c = (v[0] + v[1] + v[2]) / 3.0 - Vec3::new(1.0, 0.0, 0.0);
            assert!(n.dot(c) > 0.0, "faces outward");
        }
    }
}
