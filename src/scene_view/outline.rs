//! The scene view's outlines. Where a surface ends, against the background or in front of a
//! farther surface, or folds, its pixel is drawn at least as light as [`OUTLINE_LEVEL`], so
//! the unlit side of a model (the outer walls of a room lit from inside, the back of a box
//! against a black background) keeps its shape. A lit surface, lighter than that, is drawn as
//! it is: the outline shows only where the picture would otherwise be dark on dark. The
//! viewer's scene view and `raytree tree --scene-view` outline by these rules, from the
//! distance and normal of each pixel's centre ray.

use glam::Vec3;

/// The least luminance (linear, Rec. 709 weights) of a pixel on an outline.
pub const OUTLINE_LEVEL: f32 = 0.05;

/// The cosine of the least angle between neighbouring pixels' normals that is a fold (40°).
const FOLD_COS: f32 = 0.766;

/// How far in front of its two neighbours a pixel must stand to lie on a near edge: its
/// inverse distance above their mean by this share of itself. A plane's inverse depth changes
/// linearly across the image, and its inverse distance along the rays nearly so (from pixel to
/// pixel far within this share), so a plane seen at a grazing angle has no edge inside it.
const EDGE_STEP: f32 = 0.04;

/// What one pixel's centre ray met.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Seen {
    /// Not traced yet (or not at this resolution): no outline is drawn beside it.
    Unknown,
    /// Nothing: the background.
    Background,
    /// A surface at distance `t`, with its unit normal (zero on a visible light).
    Surface { t: f32, normal: Vec3 },
}

impl Seen {
    /// A pixel's facts as the renderer keeps them: distance `t` (INFINITY for nothing) and
    /// normal.
    pub fn of(t: f32, normal: Vec3) -> Seen {
        if t.is_finite() && t > 0.0 {
            Seen::Surface { t, normal }
        } else {
            Seen::Background
        }
    }
}

/// Whether pixel (`x`, `y`) of a `width × height` view lies on an outline, `at(x, y)` giving
/// what each pixel's centre ray met: a surface pixel next to the background, standing in front
/// of the line through its neighbours' inverse distances across or down, or whose normal turns
/// by more than 40° to the pixel right of or below it, that one not in front of it.
pub fn on_outline(width: u32, height: u32, x: u32, y: u32, at: impl Fn(u32, u32) -> Seen) -> bool {
    let Seen::Surface { t, normal } = at(x, y) else {
        return false;
    };
    let look = |dx: i64, dy: i64| {
        let (nx, ny) = (i64::from(x) + dx, i64::from(y) + dy);
        if nx < 0 || ny < 0 || nx >= i64::from(width) || ny >= i64::from(height) {
            Seen::Unknown
        } else {
            at(nx as u32, ny as u32)
        }
    };
    let w = 1.0 / t;
    for (before, after) in [(look(-1, 0), look(1, 0)), (look(0, -1), look(0, 1))] {
        if before == Seen::Background || after == Seen::Background {
            return true;
        }
        if let (Seen::Surface { t: ta, .. }, Seen::Surface { t: tb, .. }) = (before, after)
            && 1.0 / ta + 1.0 / tb - 2.0 * w < -EDGE_STEP * w
        {
            return true;
        }
        // A fold on a continuous surface; where the next pixel stands in front, the edge is
        // its own.
        if let Seen::Surface {
            t: tn,
            normal: next,
        } = after
            && 1.0 / tn <= w * (1.0 + EDGE_STEP)
            && normal != Vec3::ZERO
            && next != Vec3::ZERO
            && normal.dot(next) < FOLD_COS
        {
            return true;
        }
    }
    false
}

/// `color` (linear) lifted to at least [`OUTLINE_LEVEL`] of luminance, by adding the same grey
/// to each channel; lighter colours unchanged.
pub fn lift(color: Vec3) -> Vec3 {
    let luminance = color.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    color + Vec3::splat((OUTLINE_LEVEL - luminance).max(0.0))
}

/// Lifts every outline pixel of the row-major `pixels` of a `width × height` view whose
/// centre rays met `seen`.
pub fn outline(pixels: &mut [Vec3], width: u32, height: u32, seen: &[Seen]) {
    let at = |x: u32, y: u32| seen[(y * width + x) as usize];
    for y in 0..height {
        for x in 0..width {
            if on_outline(width, height, x, y, at) {
                let i = (y * width + x) as usize;
                pixels[i] = lift(pixels[i]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: u32 = 12;
    const H: u32 = 8;

    fn outlined(seen: &[Seen]) -> Vec<bool> {
        let at = |x: u32, y: u32| seen[(y * W + x) as usize];
        (0..H)
            .flat_map(|y| (0..W).map(move |x| (x, y)))
            .map(|(x, y)| on_outline(W, H, x, y, at))
            .collect()
    }

    /// A plane seen at a grazing angle (its inverse distance linear down the image, from far
    /// at the top to near at the bottom), with a box standing on it in columns 4..8, rows 2..6.
    fn floor_and_box() -> Vec<Seen> {
        let mut seen = Vec::new();
        for y in 0..H {
            for x in 0..W {
                let floor = 1.0 / (0.01 + 0.05 * y as f32);
                let on_box = (4..8).contains(&x) && (2..6).contains(&y);
                seen.push(if on_box {
                    Seen::Surface {
                        t: 3.0,
                        normal: Vec3::Z,
                    }
                } else {
                    Seen::Surface {
                        t: floor,
                        normal: Vec3::Y,
                    }
                });
            }
        }
        seen
    }

    #[test]
    fn a_grazing_plane_has_no_outline_and_a_box_in_front_of_it_has_one_round_it() {
        let seen = floor_and_box();
        let on = outlined(&seen);
        for y in 0..H {
            for x in 0..W {
                let on_box = (4..8).contains(&x) && (2..6).contains(&y);
                let edge = on_box && (x == 4 || x == 7 || y == 2 || y == 5);
                // The box's rim is outlined, on the box's side: the floor's pixels beside it,
                // whose normals turn 90° to the box's, are behind it.
                assert_eq!(on[(y * W + x) as usize], edge, "pixel ({x}, {y})");
            }
        }
    }

    #[test]
    fn a_surface_next_to_the_background_is_outlined_and_the_background_is_not() {
        let mut seen = vec![Seen::Background; (W * H) as usize];
        for y in 3..5 {
            for x in 3..9 {
                seen[(y * W + x) as usize] = Seen::of(2.0, Vec3::Z);
            }
        }
        let on = outlined(&seen);
        for (i, &o) in on.iter().enumerate() {
            assert_eq!(o, seen[i] != Seen::Background, "pixel {i}");
        }
        // Unknown neighbours (not yet traced, or past the image's edge) outline nothing.
        let mut unknown = vec![Seen::Unknown; (W * H) as usize];
        unknown[(4 * W + 5) as usize] = Seen::of(2.0, Vec3::Z);
        assert!(outlined(&unknown).iter().all(|&o| !o));
    }

    #[test]
    fn a_fold_is_outlined_once_and_a_gentle_curve_is_not() {
        // Two walls meeting in a room's corner: the left half faces +x, the right half −x·z.
        let mut seen = Vec::new();
        for _ in 0..H {
            for x in 0..W {
                let normal = if x < 6 {
                    Vec3::X
                } else {
                    Vec3::new(-0.6, 0.0, 0.8)
                };
                seen.push(Seen::Surface { t: 5.0, normal });
            }
        }
        let on = outlined(&seen);
        for y in 0..H {
            for x in 0..W {
                assert_eq!(on[(y * W + x) as usize], x == 5, "pixel ({x}, {y})");
            }
        }
        // Normals turning 10° from pixel to pixel: no fold.
        let curve: Vec<Seen> = (0..W * H)
            .map(|i| {
                let a = ((i % W) as f32 * 10.0).to_radians();
                Seen::Surface {
                    t: 5.0,
                    normal: Vec3::new(a.sin(), 0.0, a.cos()),
                }
            })
            .collect();
        assert!(outlined(&curve).iter().all(|&o| !o));
    }

    #[test]
    fn lifting_brings_dark_colours_to_the_level_and_keeps_light_ones() {
        let lifted = lift(Vec3::ZERO);
        assert!((lifted - Vec3::splat(OUTLINE_LEVEL)).abs().max_element() < 1e-6);
        let dark_red = lift(Vec3::new(0.1, 0.0, 0.0));
        let luminance = dark_red.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        assert!((luminance - OUTLINE_LEVEL).abs() < 1e-6);
        assert!(dark_red.x > dark_red.y, "the hue stays: {dark_red}");
        let light = Vec3::new(0.5, 0.4, 0.3);
        assert_eq!(lift(light), light);
        let mut pixels = vec![Vec3::ZERO; (W * H) as usize];
        let seen = floor_and_box();
        outline(&mut pixels, W, H, &seen);
        let on = outlined(&seen);
        for (i, p) in pixels.iter().enumerate() {
            assert_eq!(*p != Vec3::ZERO, on[i], "pixel {i}");
        }
    }
}
