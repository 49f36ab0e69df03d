//! Scene files (TOML): the sections and keys a file may have ([`keys`]), a strict reader that
//! places every error at its file, line and column (`reader`), and the builder that makes a
//! [`Scene`](crate::scene::Scene) of them (`build`). The format: docs/design.md, "Scene files".

mod build;
pub mod keys;
mod names;
pub(crate) mod reader;
mod sections;

pub use build::{load_scene_str_with, load_scene_str_with_files};
