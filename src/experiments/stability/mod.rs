//! The stability matrix: where the naive methods fail and what the robust ones reach
//! (docs/stability.md, by row id). One file per failure family, each holding its measurements
//! (functions of the method, the point of the sweep and a seeded [`Pcg`]) and its rows (the
//! sweep, a headline for the naive and the robust method, a verdict against the target, and a
//! chart of the failure rate against scale):
//!
//! - [`spheres`]: S1-S4, a far sphere, its hit point, a huge sphere as the ground, grazing rays;
//! - [`triangles`]: T1-T5, leaks and double hits in a closed mesh, tiny and needle triangles,
//!   bad triangles, small triangles far away;
//! - [`offsets`]: A1-A3, ray-origin offsets: acne, contact leaks, secondary self-hits;
//! - [`refraction`]: R1, total internal reflection and Snell's law;
//! - [`normals`]: N1-N3, shading normals: the terminator, wrong-side directions, light leaks;
//! - [`bvh`]: B2, BVH builds on pathological geometry.
//!
//! This file holds what they share: the options, the row and its verdict, [`rows`] (every row
//! in the table's order, each with its own seed), the table, the charts and the JSON form.
//! `raytree stability` prints the rows; `tests/stability.rs` and `tests/geometry.rs` call the
//! very same measurement functions with fewer rays and assert the documented points.
//!
//! Conventions: `f32` everywhere, the same `f32` inputs replayed in `f64` as the oracle
//! (`sphere_roots_f64`, `triangle_hit_f64`), log-spaced sweeps ([`log_sweep`]), a seeded
//! [`Pcg`].

use serde::Serialize;

use crate::experiments::chart::{Chart, Series, write_chart};
use crate::export::{ExportError, write_text};
use crate::geometry::next_float_up;
use crate::rng::Pcg;

pub mod bvh;
pub mod normals;
pub mod offsets;
pub mod refraction;
pub mod spheres;
pub mod triangles;

pub use bvh::*;
pub use normals::*;
pub use offsets::*;
pub use refraction::*;
pub use spheres::*;
pub use triangles::*;

/// The spacing of `f32` values at `|x|`.
pub fn ulp(x: f32) -> f32 {
    let x = x.abs();
    next_float_up(x) - x
}

/// `10^k` as `f32`.
pub fn p10(k: i32) -> f32 {
    10f32.powi(k)
}

/// `count` as a percentage of `of`.
pub fn pct(count: usize, of: usize) -> f64 {
    100.0 * count as f64 / of.max(1) as f64
}

/// `n` random trials of `trial`: each returns `None` when its setup is not one the oracle can
/// judge (skipped), else whether the method failed. Returns (trials judged, failures).
fn trials(
    n: usize,
    rng: &mut Pcg,
    mut trial: impl FnMut(&mut Pcg) -> Option<bool>,
) -> (usize, usize) {
    (0..n)
        .filter_map(|_| trial(rng))
        .fold((0, 0), |(tested, failed), f| {
            (tested + 1, failed + usize::from(f))
        })
}

/// How a row's robust method meets its target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Meets the target, and the naive method fails where documented.
    Yes,
    /// Meets it within a limit the row states (e.g. up to a sweep value).
    Partly,
    No,
}

/// One row of the matrix as measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    pub id: &'static str,
    pub failure: &'static str,
    pub naive_method: &'static str,
    pub robust_method: &'static str,
    pub sweep: String,
    /// Where and how the naive method fails, measured.
    pub naive: String,
    /// What the robust method reaches, measured.
    pub robust: String,
    pub target: &'static str,
    pub verdict: Verdict,
    /// Failure rate (or error) against scale; the measured figures, point by point.
    pub chart: Option<Chart>,
}

/// How much work a run of the rows does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StabilityOptions {
    /// Rays per cell (at least 10 000 for the table of docs/stability.md).
    pub rays: usize,
    /// Largest triangle count of the B2 builds.
    pub max_build: usize,
    pub seed: u64,
}

impl StabilityOptions {
    pub fn full() -> Self {
        Self {
            rays: 10_000,
            max_build: 100_000,
            seed: 2024,
        }
    }

    pub fn quick() -> Self {
        Self {
            rays: 1_000,
            max_build: 10_000,
            seed: 2024,
        }
    }
}

/// Every row, in the order of the table in docs/stability.md. `progress` gets each row's id before it runs.
pub fn rows(opts: &StabilityOptions, progress: &dyn Fn(&str)) -> Vec<Row> {
    type RowFn = fn(&StabilityOptions, &mut Pcg) -> Row;
    let all: [(&str, RowFn); 16] = [
        ("S1", spheres::row_s1),
        ("S2", spheres::row_s2),
        ("S3", spheres::row_s3),
        ("S4", spheres::row_s4),
        ("T1", triangles::row_t1),
        ("T2", triangles::row_t2),
        ("T3", triangles::row_t3),
        ("T4", triangles::row_t4),
        ("T5", triangles::row_t5),
        ("A1", offsets::row_a1),
        ("A2", offsets::row_a2),
        ("A3", offsets::row_a3),
        ("R1", refraction::row_r1),
        ("N1", normals::row_n1),
        ("N2", normals::row_n2),
        ("N3", normals::row_n3),
    ];
    let mut out: Vec<Row> = all
        .iter()
        .enumerate()
        .map(|(i, (id, f))| {
            progress(id);
            f(opts, &mut Pcg::new(opts.seed + i as u64))
        })
        .collect();
    progress("B2");
    out.push(bvh::row_b2(opts, &mut Pcg::new(opts.seed + 100)));
    out
}

/// Log-spaced values `10^(k/steps)` for `k` in `lo·steps..=hi·steps`.
pub fn log_sweep(lo: i32, hi: i32, steps_per_decade: i32) -> Vec<f32> {
    (lo * steps_per_decade..=hi * steps_per_decade)
        .map(|k| 10f32.powf(k as f32 / steps_per_decade as f32))
        .collect()
}

fn chart(title: &str, x_label: &str, y_label: &str, y_log: bool, series: Vec<Series>) -> Chart {
    Chart {
        title: title.into(),
        x_label: x_label.into(),
        y_label: y_label.into(),
        x_log: true,
        y_log,
        series,
    }
}

fn yes_if(ok: bool) -> Verdict {
    if ok { Verdict::Yes } else { Verdict::No }
}

fn fmt_g(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if (1e-2..1e4).contains(&v.abs()) {
        let s = format!("{v:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.1e}")
    }
}

/// The value at sweep point `x` of `points` (sweep value, value), or the default (0, an empty
/// cell) where the sweep has no such point. A point matches within 0.1%: [`log_sweep`] computes
/// `10^(k/steps)` in `f32`, which need not round to the literal `1e3`.
fn at<X: Copy + Into<f64>, T: Clone + Default>(points: &[(X, T)], x: f64) -> T {
    points
        .iter()
        .find(|(p, _)| ((*p).into() / x - 1.0).abs() < 1e-3)
        .map(|(_, v)| v.clone())
        .unwrap_or_default()
}

/// The rows as a Markdown table.
pub fn markdown_table(rows: &[Row]) -> String {
    let esc = |s: &str| s.replace('|', "\\|");
    let mut s = String::from(
        "| id | failure mode | naive method: where it fails (measured) | robust method: measured | target | ok |\n\
         |---|---|---|---|---|---|\n",
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | **{}**: {} | **{}**: {} | {} | {} |\n",
            r.id,
            esc(r.failure),
            esc(r.naive_method),
            esc(&r.naive),
            esc(r.robust_method),
            esc(&r.robust),
            esc(r.target),
            match r.verdict {
                Verdict::Yes => "yes",
                Verdict::Partly => "partly",
                Verdict::No => "**no**",
            }
        ));
    }
    s
}

/// Writes `stability.md` (the table) and one chart per row that has one (`s1.svg`, `s1.png`,
/// …) into `dir`.
pub fn write_stability(dir: &std::path::Path, rows: &[Row]) -> Result<(), ExportError> {
    write_text(&dir.join("stability.md"), &markdown_table(rows))?;
    for r in rows {
        if let Some(c) = &r.chart {
            write_chart(c, &dir.join(r.id.to_ascii_lowercase()))?;
        }
    }
    Ok(())
}
