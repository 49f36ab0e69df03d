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
/// Points that show the baseline's image ([`SAME_IMAGE_FLIP`]: the accelerators, deeper
/// recursion than the scene needs, methods that change nothing visible in this scene) are one
/// setting as far as the image goes, and their times differ by little more than noise. They
/// count once, as the baseline's own point (or the first of them), at the median of their
/// times ([`front_secs`]), so the front never recommends a method for having been lucky with
/// the clock.
pub fn pareto_front<P: Tradeoff>(points: &[P], is_baseline: impl Fn(&P) -> bool) -> Vec<usize> {
    let rep = representative(points, &is_baseline);
    let key = |i: usize| (front_secs(points, &is_baseline, i), points[i].error());
    let candidates: Vec<usize> = (0..points.len())
        .filter(|&i| !same_image(&points[i]) || Some(i) == rep)
        .collect();
    let mut front: Vec<usize> = candidates
        .iter()
        .copied()
        .filter(|&i| {
            let (t, e) = key(i);
            !candidates.iter().any(|&j| {
                let (qt, qe) = key(j);
                qt <= t && qe <= e && (qt < t || qe < e)
            })
        })
        .collect();
    front.sort_by(|&a, &b| key(a).0.total_cmp(&key(b).0));
    front
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
            P(4.0, 0.1, false, false), // a tie is kept
        ];
        assert_eq!(pareto_front(&pts, is_baseline), vec![4, 0, 1, 3, 5]);
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
