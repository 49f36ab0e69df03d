//! The Pareto front of a speed-against-accuracy sweep: the settings that no other beats in both
//! time and error, with every setting that shows the baseline's own image counted once.

use super::measure::median;

/// Mean FLIP against the baseline below which a point shows the same image (FLIP's authors
/// put the threshold of a visible difference around 0.01 for a pair of images seen in
/// alternation; a tenth of that is far below it).
pub const SAME_IMAGE_FLIP: f64 = 1e-3;

/// What the front reads of a measured setting.
pub trait Tradeoff {
    /// Seconds per image (lower is better).
    fn secs(&self) -> f64;
    /// Error against the converged reference (lower is better).
    fn error(&self) -> f64;
    /// Mean FLIP against the baseline render.
    fn flip_vs_baseline(&self) -> f64;
}

/// Whether `p` shows the baseline's image ([`SAME_IMAGE_FLIP`]).
pub fn same_image(p: &impl Tradeoff) -> bool {
    p.flip_vs_baseline() <= SAME_IMAGE_FLIP
}

/// Indices of the points no other point beats in both time and error (lower is better in
/// both), sorted by time; `is_baseline` tells the point rendered with the baseline's settings.
///
/// Built monotone: the candidates are sorted by time (then error), and a point joins the front
/// only when its error is strictly below every faster point's, so the front's time rises and its
/// error falls at every step. Of points tied in both, the first (by index) stands for them.
///
/// Points that show the baseline's image ([`SAME_IMAGE_FLIP`]: the accelerators, deeper
/// recursion than the scene needs, methods that change nothing visible in this scene) are one
/// setting as far as the image goes, and their times differ by little more than noise. They
/// count once, as the baseline's own point (or the first of them), at the median of their
/// times ([`front_secs`]), so the front never recommends a method for having been lucky with
/// the clock.
pub fn pareto_front<P: Tradeoff>(points: &[P], is_baseline: impl Fn(&P) -> bool) -> Vec<usize> {
    let rep = representative(points, &is_baseline);
    let keyed: Vec<(f64, f64, usize)> = (0..points.len())
        .filter(|&i| !same_image(&points[i]) || Some(i) == rep)
        .map(|i| (front_secs(points, &is_baseline, i), points[i].error(), i))
        .filter(|(t, e, _)| !t.is_nan() && !e.is_nan())
        .collect();
    monotone_front(keyed)
}

/// The staircase of `(time, error, id)` triples: sorted by time, then error, then id, keeping
/// each one whose error is strictly below the best error of those before it. Returns the ids.
pub fn monotone_front(mut keyed: Vec<(f64, f64, usize)>) -> Vec<usize> {
    keyed.sort_by(|a, b| {
        a.0.total_cmp(&b.0)
            .then(a.1.total_cmp(&b.1))
            .then(a.2.cmp(&b.2))
    });
    let mut best = f64::INFINITY;
    let mut front = Vec::new();
    for (_, e, i) in keyed {
        if e < best {
            best = e;
            front.push(i);
        }
    }
    front
}

/// The corners of the staircase through `front` (points `[time, error]` sorted by time with
/// falling error): from each point, across at its error to the next one's time, then down.
/// A line through them never doubles back and encloses nothing.
pub fn staircase(front: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out = Vec::with_capacity(front.len() * 2);
    for (k, p) in front.iter().enumerate() {
        if k > 0 {
            out.push([p[0], front[k - 1][1]]);
        }
        out.push(*p);
    }
    out
}

/// The point that stands for all those with the baseline's image.
fn representative<P: Tradeoff>(points: &[P], is_baseline: &impl Fn(&P) -> bool) -> Option<usize> {
    let same: Vec<usize> = (0..points.len())
        .filter(|&i| same_image(&points[i]))
        .collect();
    same.iter()
        .copied()
        .find(|&i| is_baseline(&points[i]))
        .or(same.first().copied())
}

/// The time the Pareto front uses for point `i`: its own, or for the baseline's image the
/// median over every point with that image.
pub fn front_secs<P: Tradeoff>(points: &[P], is_baseline: impl Fn(&P) -> bool, i: usize) -> f64 {
    if !same_image(&points[i]) || representative(points, &is_baseline) != Some(i) {
        return points[i].secs();
    }
    median(
        points
            .iter()
            .filter(|p| same_image(*p))
            .map(|p| p.secs())
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A measured point: seconds, error, whether it shows the baseline's image, whether it is
    /// the baseline.
    struct P(f64, f64, bool, bool);

    impl Tradeoff for P {
        fn secs(&self) -> f64 {
            self.0
        }
        fn error(&self) -> f64 {
            self.1
        }
        fn flip_vs_baseline(&self) -> f64 {
            if self.2 { 0.0 } else { 0.1 }
        }
    }

    fn is_baseline(p: &P) -> bool {
        p.3
    }

    #[test]
    fn pareto_front_keeps_the_undominated_points_by_time() {
        let pts = vec![
            P(1.0, 0.5, false, false),
            P(2.0, 0.2, false, false),
            P(2.5, 0.3, false, false), // dominated by (2.0, 0.2)
            P(4.0, 0.1, false, false),
            P(0.5, 0.9, false, false),
            P(4.0, 0.1, false, false), // a tie in both: the first stands for it
            P(2.0, 0.25, false, false), // same time as (2.0, 0.2), worse error
            P(3.0, 0.2, false, false), // same error as (2.0, 0.2), slower
            P(5.0, 0.1, false, false), // slower than (4.0, 0.1), no better
        ];
        let front = pareto_front(&pts, is_baseline);
        assert_eq!(front, vec![4, 0, 1, 3]);
        // Monotone: time rises and error strictly falls along the front.
        for w in front.windows(2) {
            assert!(pts[w[0]].0 < pts[w[1]].0);
            assert!(pts[w[0]].1 > pts[w[1]].1);
        }
        // No point of the set beats a front point in both.
        for &i in &front {
            assert!(!pts.iter().any(|q| q.0 < pts[i].0 && q.1 < pts[i].1));
        }
    }

    #[test]
    fn the_front_of_an_empty_or_nan_set() {
        let none: Vec<P> = Vec::new();
        assert!(pareto_front(&none, is_baseline).is_empty());
        let pts = vec![P(f64::NAN, 0.1, false, false), P(1.0, 0.2, false, false)];
        assert_eq!(pareto_front(&pts, is_baseline), vec![1]);
    }

    #[test]
    fn the_staircase_goes_across_then_down() {
        let front = [[0.0, 3.0], [1.0, 2.0], [3.0, 0.5]];
        assert_eq!(
            staircase(&front),
            vec![[0.0, 3.0], [1.0, 3.0], [1.0, 2.0], [3.0, 2.0], [3.0, 0.5]]
        );
        // Never back in time, never up in error.
        let s = staircase(&front);
        for w in s.windows(2) {
            assert!(w[1][0] >= w[0][0] && w[1][1] <= w[0][1]);
        }
        assert!(staircase(&[]).is_empty());
    }

    #[test]
    fn the_baseline_image_counts_once_at_its_median_time() {
        let pts = vec![
            P(1.0, 0.5, false, false),
            P(0.7, 0.4, true, false), // lucky clock, same image as the baseline
            P(1.1, 0.4, true, true),
            P(0.9, 0.4, true, false),
            P(3.0, 0.1, false, false),
        ];
        // The baseline (index 2) stands for the three at their median, 0.9 s.
        assert_eq!(pareto_front(&pts, is_baseline), vec![2, 4]);
        assert_eq!(front_secs(&pts, is_baseline, 2), 0.9);
        assert_eq!(front_secs(&pts, is_baseline, 1), 0.7);
    }
}
