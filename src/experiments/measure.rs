//! What the timed sweeps ([`super::sweep`], [`super::scaling`]) share: the progress they report,
//! the cancel flag they obey, the error they stop with, the median of repeated runs, and the
//! names of the values they sweep.

use std::sync::atomic::{AtomicBool, Ordering};

use serde::Serialize;

use crate::render::RenderError;

/// Where a sweep is: step `step` of `steps`, doing `what`.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchProgress {
    pub step: usize,
    pub steps: usize,
    pub what: String,
}

/// Why a sweep stopped.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("the sweep was cancelled")]
    Cancelled,
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// The kebab-case name serde gives a unit enum value (`moller-trumbore`).
pub fn value_name<T: Serialize>(v: &T) -> String {
    serde_json::to_value(v)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// The median of `v` (0 for an empty list).
pub(super) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Stops a sweep between renders once `cancel` is set.
pub(super) fn check_cancel(cancel: &AtomicBool) -> Result<(), BenchError> {
    if cancel.load(Ordering::Relaxed) {
        Err(BenchError::Cancelled)
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::TriangleMethod;

    #[test]
    fn value_names_are_serde_names() {
        assert_eq!(
            value_name(&TriangleMethod::MollerTrumbore),
            "moller-trumbore"
        );
    }

    #[test]
    fn median_of_odd_even_and_empty_lists() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(Vec::new()), 0.0);
    }
}
