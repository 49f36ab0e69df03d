//! Speed against accuracy (docs/speed-accuracy.md) and where methods fail (docs/stability.md),
//! measured by the same code for the command line (`raytree bench`, `raytree stability`), the
//! tests and the viewer:
//!
//! - [`sweep`]: the sweep of every knob that trades render time for image error;
//! - [`pareto`]: its Pareto front of time against error;
//! - [`scaling`]: the accelerator scaling sweep whose crossovers set `AccelKind::Auto`;
//! - [`measure`]: what both timed sweeps share (progress, cancel, median, value names);
//! - [`report`]: their CSV files, charts and summary lines;
//! - [`stability`]: the stability matrix, one file per failure family (spheres, triangles,
//!   ray-origin offsets, refraction, shading normals, BVH builds), each with its measurements
//!   (naive against robust methods) and its rows over log-spaced sweeps; the table, charts and
//!   JSON;
//! - [`metrics`]: image error (FLIP, RMSE, PSNR, differing pixels);
//! - [`chart`]: charts as plain data, drawn to SVG and PNG;
//! - [`labels`]: where a chart's point labels go, clear of one another;
//! - [`meshes`]: procedural closed meshes (random numbers from [`crate::rng`]).

pub mod chart;
pub mod labels;
pub mod measure;
pub mod meshes;
pub mod metrics;
pub mod pareto;
pub mod report;
pub mod scaling;
pub mod stability;
pub mod sweep;
