//! Speed against accuracy (SPEC §7) and where methods fail (`STABILITY.md`), measured by the
//! same code for the command line (`raytree bench`, `raytree stability`), the tests and the
//! viewer:
//!
//! - [`sweep`]: the sweep of every knob that trades render time for image error;
//! - [`pareto`]: its Pareto front of time against error;
//! - [`scaling`]: the accelerator scaling sweep whose crossovers set `AccelKind::Auto`;
//! - [`measure`]: what both timed sweeps share (progress, cancel, median, value names);
//! - [`report`]: their CSV files, charts and summary lines;
//! - [`stability`]: the measurements of the stability matrix, naive against robust methods;
//! - [`rows`]: the matrix's rows built from them over log-spaced sweeps (table, charts, JSON);
//! - [`metrics`]: image error (FLIP, RMSE, PSNR, differing pixels);
//! - [`chart`]: charts as plain data, drawn to SVG and PNG;
//! - [`meshes`]: procedural closed meshes (random numbers from [`crate::rng`]).

pub mod chart;
pub mod measure;
pub mod meshes;
pub mod metrics;
pub mod pareto;
pub mod report;
pub mod rows;
pub mod scaling;
pub mod stability;
pub mod sweep;
