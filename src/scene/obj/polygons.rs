//! Faces of more than three corners cut into triangles as their shape asks. Both readers fan a
//! face from its first corner, as tobj does; for a concave face (an L-shaped floor, a letter, a
//! room's outline from Blender, which writes its n-gons as they are) part of that fan lies
//! outside the face and covers its notch. Such a face is cut again here by ear clipping in its
//! own plane, into the same number of triangles in the same places, with the same winding, so
//! every per-triangle fact the readers found (materials, corners, smoothing groups) still holds.

use glam::{DVec2, DVec3};

/// Faces of more corners than this keep their fan: ear clipping costs up to the cube of the
/// corners (their square for a face with few reflex corners, as floor plans and letters are).
const MAX_CORNERS: usize = 256;

/// The corners of each `f` statement in file order (the order of the readers' triangles).
fn face_corners(text: &str) -> Vec<usize> {
    text.lines()
        .filter_map(|line| {
            let mut words = line.split_whitespace();
            (words.next() == Some("f")).then(|| words.count())
        })
        .collect()
}

/// Re-cuts the concave faces of four or more corners among `models` (the readers' models of
/// `text`, in file order); returns how many were cut. Left as they are when the faces of the
/// text do not add up to the models' triangles (they do for every file the readers take).
pub(super) fn cut_concave_faces(models: &mut [tobj::Model], text: &str) -> usize {
    let faces = face_corners(text);
    let triangles: usize = faces.iter().map(|&n| n.saturating_sub(2).max(1)).sum();
    let read: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    if triangles != read {
        return 0;
    }
    let mut faces = faces.into_iter();
    let mut cut = 0;
    for model in models {
        let mesh = &mut model.mesh;
        let count = mesh.indices.len() / 3;
        let mut t = 0;
        while t < count {
            let Some(n) = faces.next() else { return cut };
            let fan = n.saturating_sub(2).max(1);
            if n >= 4 && t + fan <= count && n <= MAX_CORNERS && recut(mesh, t, n) {
                cut += 1;
            }
            t += fan;
        }
    }
    cut
}

/// Re-cuts the face whose fan is triangles `t..t + n − 2` of `mesh`, if it is concave; true
/// when it was.
fn recut(mesh: &mut tobj::Mesh, t: usize, n: usize) -> bool {
    let Some(ring) = corners_of(&mesh.indices, t, n) else {
        return false;
    };
    let at = |i: u32| {
        let i = 3 * i as usize;
        mesh.positions
            .get(i..i + 3)
            .map(|p| DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
    };
    let Some(points) = ring.iter().map(|&i| at(i)).collect::<Option<Vec<_>>>() else {
        return false;
    };
    let Some(order) = ear_clip(&points) else {
        return false;
    };
    // Each index list with one entry per corner gets the new triangles in the fan's slots.
    let slots = 3 * t..3 * (t + n - 2);
    let len = mesh.indices.len();
    for list in [
        &mut mesh.indices,
        &mut mesh.texcoord_indices,
        &mut mesh.normal_indices,
    ] {
        if list.len() != len {
            continue;
        }
        let Some(ring) = corners_of(list, t, n) else {
            continue;
        };
        for (slot, &k) in slots.clone().zip(order.iter().flatten()) {
            list[slot] = ring[k];
        }
    }
    true
}

/// The `n` corners of the face fanned into triangles `t..t + n − 2` of `list`: (a, b, c),
/// (a, c, d), … give a, b, c, d, …; `None` when the triangles are not such a fan.
fn corners_of(list: &[u32], t: usize, n: usize) -> Option<Vec<u32>> {
    let fan = list.get(3 * t..3 * (t + n - 2))?;
    let mut ring = vec![fan[0], fan[1]];
    for (k, tri) in fan.chunks_exact(3).enumerate() {
        if tri[0] != fan[0] || tri[1] != ring[k + 1] {
            return None;
        }
        ring.push(tri[2]);
    }
    Some(ring)
}

/// The triangles (corner positions in `points`, in the polygon's winding) of the polygon
/// `points` cut by ear clipping in its plane (its Newell normal's), or `None` when its fan
/// from the first corner is right already (it is convex), or when it has no plane or cannot
/// be cut (it crosses itself).
fn ear_clip(points: &[DVec3]) -> Option<Vec<[usize; 3]>> {
    let n = points.len();
    let normal = (0..n).fold(DVec3::ZERO, |sum, i| {
        let (p, q) = (points[i], points[(i + 1) % n]);
        sum + (p - q).cross(p + q)
    });
    // In the plane, seen from the normal's side: the polygon is counter-clockwise there.
    let axis = normal.abs().max_position();
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let sign = normal[axis].signum();
    if normal[axis] == 0.0 || !normal.is_finite() {
        return None;
    }
    let flat: Vec<DVec2> = points
        .iter()
        .map(|p| DVec2::new(p[u], sign * p[v]))
        .collect();
    let turn = |a: usize, b: usize, c: usize| (flat[b] - flat[a]).perp_dot(flat[c] - flat[b]);
    if (0..n).all(|i| turn(i, (i + 1) % n, (i + 2) % n) >= 0.0) {
        return None;
    }
    let inside = |p: DVec2, a: usize, b: usize, c: usize| {
        let side = |x: usize, y: usize| (flat[y] - flat[x]).perp_dot(p - flat[x]);
        side(a, b) > 0.0 && side(b, c) > 0.0 && side(c, a) > 0.0
    };
    let mut ring: Vec<usize> = (0..n).collect();
    // Only a reflex corner can lie inside an ear, and corners only turn convex as ears go: the
    // test of an ear looks at the reflex corners left (none in most of a floor plan's fan).
    let mut reflex: Vec<usize> = (0..n)
        .filter(|&i| turn((i + n - 1) % n, i, (i + 1) % n) <= 0.0)
        .collect();
    let mut out = Vec::with_capacity(n - 2);
    // The search for the next ear starts where the last was cut, where one usually is.
    let mut start = 0;
    while ring.len() > 3 {
        let m = ring.len();
        let ear = (0..m).map(|k| (start + k) % m).find(|&i| {
            let (a, b, c) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
            turn(a, b, c) > 0.0
                && reflex
                    .iter()
                    .filter(|&&k| k != a && k != b && k != c)
                    .all(|&k| !inside(flat[k], a, b, c))
        })?;
        let (a, b, c) = (ring[(ear + m - 1) % m], ring[ear], ring[(ear + 1) % m]);
        out.push([a, b, c]);
        ring.remove(ear);
        // The ear's neighbours have new neighbours of their own.
        let m = ring.len();
        let (ia, ic) = ((ear + m - 1) % m, ear % m);
        let convex = |i: usize| turn(ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]) > 0.0;
        let (a_convex, c_convex) = (convex(ia), convex(ic));
        reflex.retain(|&k| k != b && !(k == a && a_convex) && !(k == c && c_convex));
        start = ia;
    }
    out.push([ring[0], ring[1], ring[2]]);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(points: &[(f64, f64)]) -> Vec<DVec3> {
        points.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()
    }

    /// Twice the signed area of triangle `t` of `points` seen from +z.
    fn area2(points: &[DVec3], t: [usize; 3]) -> f64 {
        let [a, b, c] = t.map(|i| points[i].truncate());
        (b - a).perp_dot(c - a)
    }

    #[test]
    fn a_convex_face_keeps_its_fan_and_a_concave_one_is_cut_inside_itself() {
        // A square and a convex pentagon: the fan is right.
        assert_eq!(
            ear_clip(&plane(&[(0., 0.), (1., 0.), (1., 1.), (0., 1.)])),
            None
        );
        let pentagon = plane(&[(0., 0.), (2., 0.), (3., 1.), (1., 2.), (-1., 1.)]);
        assert_eq!(ear_clip(&pentagon), None);
        // An L of area 3 whose first corner is the inner one's neighbour: its fan from (2, 1)
        // covers the notch [1, 2]².
        let l = plane(&[(2., 1.), (1., 1.), (1., 2.), (0., 2.), (0., 0.), (2., 0.)]);
        let cut = ear_clip(&l).expect("concave");
        assert_eq!(cut.len(), 4);
        let area: f64 = cut.iter().map(|&t| 0.5 * area2(&l, t)).sum();
        assert!((area - 3.0).abs() < 1e-12, "area {area}");
        for &t in &cut {
            assert!(area2(&l, t) > 0.0, "{t:?} keeps the winding");
            let c = t.iter().map(|&i| l[i]).sum::<DVec3>() / 3.0;
            assert!(!(c.x > 1.0 && c.y > 1.0), "{t:?} lies in the notch");
        }
        // The same L wound the other way, and standing in the yz plane: cut alike.
        let mut back = l.clone();
        back.reverse();
        let cut = ear_clip(&back).expect("concave");
        assert!(
            cut.iter().all(|&t| area2(&back, t) < 0.0),
            "keeps its winding"
        );
        let upright: Vec<DVec3> = l.iter().map(|p| DVec3::new(0.0, p.x, p.y)).collect();
        assert_eq!(ear_clip(&upright).map(|c| c.len()), Some(4));
        // No plane (all corners on a line): left as it is.
        assert_eq!(
            ear_clip(&plane(&[(0., 0.), (1., 0.), (2., 0.), (3., 0.)])),
            None
        );
    }

    #[test]
    fn a_star_of_many_points_is_cut_into_its_area() {
        // 128 points (256 corners, every other one reflex), and a comb of 40 teeth.
        let star: Vec<(f64, f64)> = (0..256)
            .map(|i| {
                let a = std::f64::consts::TAU * f64::from(i) / 256.0;
                let r = if i % 2 == 0 { 1.0 } else { 0.6 };
                (r * a.cos(), r * a.sin())
            })
            .collect();
        let mut comb = vec![(0.0, 0.0), (40.0, 0.0)];
        for t in (0..40).rev() {
            let x = f64::from(t);
            comb.extend([(x + 1.0, 3.0), (x + 0.5, 3.0), (x + 0.5, 1.0), (x, 1.0)]);
        }
        comb.pop();
        comb.push((0.0, 3.0));
        for (what, outline) in [("star", star), ("comb", comb)] {
            let points = plane(&outline);
            let n = points.len();
            let shoelace: f64 = (0..n)
                .map(|i| {
                    let (p, q) = (points[i], points[(i + 1) % n]);
                    0.5 * (p.x * q.y - q.x * p.y)
                })
                .sum();
            let cut = ear_clip(&points).unwrap_or_else(|| panic!("{what} is concave"));
            assert_eq!(cut.len(), n - 2, "{what}");
            assert!(
                cut.iter().all(|&t| area2(&points, t) > 0.0),
                "{what}: winding"
            );
            let area: f64 = cut.iter().map(|&t| 0.5 * area2(&points, t)).sum();
            assert!(
                (area - shoelace).abs() < 1e-9 * shoelace,
                "{what}: {area} against {shoelace}"
            );
        }
    }

    #[test]
    fn the_fans_corners_are_read_back_and_other_shapes_are_not() {
        // Corners 7 3 5 9 fanned: (7 3 5) (7 5 9).
        assert_eq!(
            corners_of(&[7, 3, 5, 7, 5, 9], 0, 4),
            Some(vec![7, 3, 5, 9])
        );
        assert_eq!(corners_of(&[7, 3, 5, 8, 5, 9], 0, 4), None);
        assert_eq!(corners_of(&[7, 3, 5], 0, 4), None);
    }
}
