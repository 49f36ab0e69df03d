//! Where a chart's point labels go ([`place`]): beside their points, clear of one another, of
//! every other point's marker and of the legend, inside the plot. Labels of points that fall
//! on one spot become one label ([`merge`]); a label with no room next to its point moves
//! further out along one of eight directions and gets a leader line back to it. A label
//! also keeps off the series' lines where it can: crossing a line is allowed only where every
//! other place is worse. Pixel coordinates throughout, `y` down.

/// A pixel rectangle, `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    pub x0: i32,
    pub y0: i32,
    pub x1: i32,
    pub y1: i32,
}

impl Rect {
    /// The square of half-side `r` about `(x, y)`.
    pub fn around((x, y): (i32, i32), r: i32) -> Rect {
        Rect {
            x0: x - r,
            y0: y - r,
            x1: x + r + 1,
            y1: y + r + 1,
        }
    }

    pub fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    pub fn inside(&self, area: &Rect) -> bool {
        self.x0 >= area.x0 && self.y0 >= area.y0 && self.x1 <= area.x1 && self.y1 <= area.y1
    }

    fn grown(&self, by: i32) -> Rect {
        Rect {
            x0: self.x0 - by,
            y0: self.y0 - by,
            x1: self.x1 + by,
            y1: self.y1 + by,
        }
    }

    /// Whether the segment from `a` to `b` passes through the rectangle (clipped as the scene
    /// view clips its rays to the image).
    pub fn crossed_by(&self, (a, b): Segment) -> bool {
        let at = |(x, y): (i32, i32)| glam::Vec2::new((x - self.x0) as f32, (y - self.y0) as f32);
        let (w, h) = (
            (self.x1 - 1 - self.x0) as f32,
            (self.y1 - 1 - self.y0) as f32,
        );
        crate::scene_view::occlusion::clip_to_rect(at(a), at(b), w, h).is_some()
    }

    /// The point of the rectangle nearest to `p`.
    fn nearest(&self, (x, y): (i32, i32)) -> (i32, i32) {
        (x.clamp(self.x0, self.x1 - 1), y.clamp(self.y0, self.y1 - 1))
    }
}

/// A straight piece of a series' line, between two of its points' pixels.
pub type Segment = ((i32, i32), (i32, i32));

/// A label wanted at a point (its pixel).
#[derive(Clone, Debug, PartialEq)]
pub struct Wanted {
    pub anchor: (i32, i32),
    pub text: String,
}

/// A label where [`place`] put it: its text's box, and whether a leader line joins the box to
/// the point (the box is not next to it).
#[derive(Clone, Debug, PartialEq)]
pub struct Placed {
    pub anchor: (i32, i32),
    pub text: String,
    pub rect: Rect,
    /// The leader line's end on the box, when the box is away from its point.
    pub leader_to: Option<(i32, i32)>,
}

/// Points closer than this (in pixels, on both axes) are one spot: their labels are one.
pub const SAME_SPOT_PX: i32 = 4;

/// Whether two points are one spot.
fn same_spot(a: (i32, i32), b: (i32, i32)) -> bool {
    (a.0 - b.0).abs() <= SAME_SPOT_PX && (a.1 - b.1).abs() <= SAME_SPOT_PX
}

/// Half the side of the box a point's marker covers (the front's ring has radius 7).
pub const MARKER_PX: i32 = 8;

/// Labels whose points lie within [`SAME_SPOT_PX`] of the first of them become one label at
/// that first point, in the order given: the distinct texts joined by ", ", leaving out a
/// text that another of them contains (the front's "triangle watertight" already says the
/// method point's "watertight").
pub fn merge(wanted: &[Wanted]) -> Vec<Wanted> {
    let mut groups: Vec<(Wanted, Vec<String>)> = Vec::new();
    for w in wanted {
        match groups
            .iter_mut()
            .find(|(g, _)| same_spot(g.anchor, w.anchor))
        {
            Some((_, texts)) => texts.push(w.text.clone()),
            None => groups.push((w.clone(), vec![w.text.clone()])),
        }
    }
    groups
        .into_iter()
        .map(|(g, texts)| {
            let mut kept: Vec<&str> = Vec::new();
            for (i, t) in texts.iter().enumerate() {
                let said_elsewhere = texts
                    .iter()
                    .enumerate()
                    .any(|(j, o)| j != i && o.contains(t.as_str()) && (o != t || j < i));
                if !t.is_empty() && !said_elsewhere {
                    kept.push(t);
                }
            }
            Wanted {
                anchor: g.anchor,
                text: kept.join(", "),
            }
        })
        .filter(|w| !w.text.is_empty())
        .collect()
}

/// Where each label goes, in the order given (put the most important first: earlier labels
/// get the places next to their points). `size(text)` is a text's width and height in pixels;
/// `markers` are every point's pixel (a label covers none but its own); `obstacles` are
/// further boxes to keep clear (the legend); `lines` are the series' lines; `area` is the
/// plot. Each label takes the first candidate that is inside `area` and clear of everything
/// placed so far and of the lines, trying the eight places next to its point, then the eight
/// directions at growing distances (with a leader line); where none is clear it takes the
/// candidate inside `area` that covers the fewest boxes and, of those, crosses the fewest
/// lines, so every label is drawn.
pub fn place(
    wanted: &[Wanted],
    size: impl Fn(&str) -> (i32, i32),
    markers: &[(i32, i32)],
    obstacles: &[Rect],
    lines: &[Segment],
    area: Rect,
) -> Vec<Placed> {
    let mut placed: Vec<Placed> = Vec::new();
    for w in wanted {
        let (tw, th) = size(&w.text);
        let blockers: Vec<Rect> = markers
            .iter()
            .filter(|&&m| !same_spot(m, w.anchor))
            .map(|&m| Rect::around(m, MARKER_PX))
            .chain(obstacles.iter().copied())
            .chain(placed.iter().map(|p| p.rect.grown(2)))
            .collect();
        // Boxes covered weigh more than any number of lines crossed.
        let overlaps = |r: &Rect| {
            let grown = r.grown(1);
            blockers.iter().filter(|b| b.overlaps(r)).count() * 10_000
                + lines.iter().filter(|&&l| grown.crossed_by(l)).count()
        };
        let candidates = candidates(w.anchor, (tw, th));
        let mut best: Option<(usize, Rect, bool)> = None;
        for &(rect, away) in &candidates {
            if !rect.inside(&area) {
                continue;
            }
            let n = overlaps(&rect);
            if best.is_none_or(|(b, _, _)| n < b) {
                best = Some((n, rect, away));
            }
            if n == 0 {
                break;
            }
        }
        // Nothing inside the plot at all (a label wider than it): next to the point.
        let (rect, away) = best.map_or((candidates[0].0, false), |(_, r, a)| (r, a));
        placed.push(Placed {
            anchor: w.anchor,
            text: w.text.clone(),
            rect,
            leader_to: away.then(|| rect.nearest(w.anchor)),
        });
    }
    placed
}

/// The boxes a label of size `(w, h)` may take about its point, in order of preference, each
/// with whether it is away from the point (needs a leader line).
fn candidates((ax, ay): (i32, i32), (w, h): (i32, i32)) -> Vec<(Rect, bool)> {
    let rect = |x0: i32, y0: i32| Rect {
        x0,
        y0,
        x1: x0 + w,
        y1: y0 + h,
    };
    // Clear of the point's own ring (radius 7, 2 pixels wide) by a pixel.
    let gap = MARKER_PX + 1;
    // Next to the point: above right (where a reader looks first), below right, above left,
    // below left, above, below, right, left.
    let mut out = vec![
        (rect(ax + gap, ay - 2 - h), false),
        (rect(ax + gap, ay + 2), false),
        (rect(ax - gap - w, ay - 2 - h), false),
        (rect(ax - gap - w, ay + 2), false),
        (rect(ax - w / 2, ay - gap - 2 - h), false),
        (rect(ax - w / 2, ay + gap + 2), false),
        (rect(ax + gap + 3, ay - h / 2), false),
        (rect(ax - gap - 3 - w, ay - h / 2), false),
    ];
    // Further out: the box's corner (or side) nearest the point at distance `d` along each
    // of eight directions.
    const DIRECTIONS: [(i32, i32); 8] = [
        (1, -1),
        (1, 1),
        (-1, -1),
        (-1, 1),
        (0, -1),
        (0, 1),
        (1, 0),
        (-1, 0),
    ];
    for d in [22, 36, 54, 76, 100, 130] {
        for (ux, uy) in DIRECTIONS {
            // Diagonals at about the same distance as the axes.
            let (dx, dy) = if ux != 0 && uy != 0 {
                (d * 7 / 10, d * 7 / 10)
            } else {
                (d, d)
            };
            let x0 = match ux {
                1 => ax + dx,
                -1 => ax - dx - w,
                _ => ax - w / 2,
            };
            let y0 = match uy {
                1 => ay + dy,
                -1 => ay - dy - h,
                _ => ay - h / 2,
            };
            out.push((rect(x0, y0), true));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const AREA: Rect = Rect {
        x0: 0,
        y0: 0,
        x1: 800,
        y1: 500,
    };

    fn size(t: &str) -> (i32, i32) {
        (6 * t.chars().count() as i32, 12)
    }

    fn wanted(anchor: (i32, i32), text: &str) -> Wanted {
        Wanted {
            anchor,
            text: text.into(),
        }
    }

    #[test]
    fn labels_of_one_spot_become_one() {
        let merged = merge(&[
            wanted((100, 100), "triangle watertight"),
            wanted((101, 99), "watertight"),
            wanted((103, 100), "robust"),
            wanted((100, 104), "robust"),
            wanted((130, 100), "none"),
        ]);
        assert_eq!(
            merged,
            vec![
                wanted((100, 100), "triangle watertight, robust"),
                wanted((130, 100), "none"),
            ]
        );
    }

    #[test]
    fn a_crowded_row_of_points_gets_labels_that_cover_nothing() {
        // Twelve points 7 px apart on one line, as a sweep's methods of nearly equal time
        // and error lie, and the legend in the upper right.
        let points: Vec<(i32, i32)> = (0..12).map(|i| (300 + 7 * i, 250)).collect();
        let texts = [
            "robust",
            "lecture",
            "watertight",
            "moller-trumbore",
            "error-bound",
            "normal-scaled",
            "fixed",
            "grid",
            "bvh",
            "auto",
            "cutoff 0.01",
            "max_depth 3",
        ];
        let legend = Rect {
            x0: 620,
            y0: 5,
            x1: 795,
            y1: 160,
        };
        let w: Vec<Wanted> = points
            .iter()
            .zip(texts)
            .map(|(&p, t)| wanted(p, t))
            .collect();
        let placed = place(&w, size, &points, &[legend], &[], AREA);
        assert_eq!(placed.len(), texts.len(), "every label is drawn");
        for (i, p) in placed.iter().enumerate() {
            assert_eq!(p.text, texts[i]);
            assert!(p.rect.inside(&AREA), "{} leaves the plot", p.text);
            assert!(!p.rect.overlaps(&legend), "{} under the legend", p.text);
            for q in &placed[i + 1..] {
                assert!(!p.rect.overlaps(&q.rect), "{} covers {}", p.text, q.text);
            }
            for m in points.iter().filter(|&&m| m != p.anchor) {
                assert!(
                    !p.rect.overlaps(&Rect::around(*m, MARKER_PX)),
                    "{} covers the point at {m:?}",
                    p.text
                );
            }
            // A label away from its point says which point with a line ending on its box.
            if let Some(end) = p.leader_to {
                assert!(Rect::around(end, 0).overlaps(&p.rect));
            } else {
                let near = p.rect.grown(MARKER_PX + 4);
                assert!(near.overlaps(&Rect::around(p.anchor, 0)));
            }
        }
        // The first label keeps a place next to its point, above it (above right is under
        // the next point's marker, so above left), where a reader looks first.
        assert_eq!(placed[0].leader_to, None);
        assert!(placed[0].rect.y1 <= points[0].1, "{:?}", placed[0].rect);
        assert!(placed[0].rect.x1 <= points[0].0, "{:?}", placed[0].rect);
    }

    #[test]
    fn a_label_at_the_plot_edge_turns_inwards() {
        let p = (795, 3);
        let placed = place(&[wanted(p, "samples 64")], size, &[p], &[], &[], AREA);
        assert!(placed[0].rect.inside(&AREA));
        assert_eq!(placed[0].leader_to, None, "room next to it, below left");
    }

    #[test]
    fn a_segment_crosses_a_box_only_where_it_passes_through() {
        let r = Rect {
            x0: 10,
            y0: 10,
            x1: 20,
            y1: 20,
        };
        assert!(r.crossed_by(((0, 15), (30, 15))), "straight across");
        assert!(r.crossed_by(((12, 12), (14, 14))), "inside");
        assert!(r.crossed_by(((0, 0), (30, 30))), "the diagonal");
        assert!(!r.crossed_by(((0, 25), (30, 25))), "below");
        assert!(!r.crossed_by(((0, 12), (8, 0))), "beside a corner");
        assert!(!r.crossed_by(((22, 0), (22, 30))), "right of it");
        assert!(!r.crossed_by(((0, 9), (9, 0))), "past the corner");
    }

    #[test]
    fn a_label_keeps_off_its_own_series_lines() {
        // A point with its line leaving up-right and down-right, as a series' corner: the
        // two right-hand places are crossed, so the label goes left, still next to it.
        let p = (400, 250);
        let lines = [(p, (500, 150)), (p, (500, 350))];
        let placed = place(&[wanted(p, "max_depth 1")], size, &[p], &[], &lines, AREA);
        let r = placed[0].rect;
        assert_eq!(placed[0].leader_to, None, "{r:?}");
        assert!(r.x1 <= p.0, "{r:?}");
        for l in lines {
            assert!(!r.crossed_by(l), "{r:?} crosses {l:?}");
        }
        // Where every place is crossed, the label is still drawn next to its point.
        let star: Vec<Segment> = (0..16)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 16.0;
                (
                    p,
                    (
                        p.0 + (300.0 * a.cos()) as i32,
                        p.1 + (300.0 * a.sin()) as i32,
                    ),
                )
            })
            .collect();
        let placed = place(&[wanted(p, "samples 4")], size, &[p], &[], &star, AREA);
        assert!(placed[0].rect.inside(&AREA));
    }
}
