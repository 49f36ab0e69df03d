//! Speed against accuracy (SPEC §7) and where methods fail (`STABILITY.md`), measured by the
//! same code for the command line (`raytree bench`, `raytree stability`), the tests and the
//! viewer:
//!
//! - [`bench`](mod@bench): the sweep of every knob that trades render time for image error, the Pareto
//!   front, and the accelerator scaling sweep whose crossovers set `AccelKind::Auto`;
//! - [`stability`]: the measurements of the stability matrix, naive against robust methods;
//! - [`rows`]: the matrix's rows built from them over log-spaced sweeps (table, charts, JSON);
//! - [`metrics`]: image error (FLIP, RMSE, PSNR, differing pixels);
//! - [`chart`]: charts as plain data, drawn to SVG and PNG;
//! - [`meshes`], [`rng`]: procedural closed meshes and the seeded generator the sweeps share.

pub mod bench;
pub mod chart;
pub mod meshes;
pub mod metrics;
pub mod rng;
pub mod rows;
pub mod stability;
