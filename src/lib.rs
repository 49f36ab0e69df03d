//! raytree: recursive (Whitted) ray tracing as in the lecture notes in `shared/seed`, with the
//! ray tracing tree of any pixel.
//!
//! Data flow: a scene file or OBJ → [`scene::Scene`] (or a [`scene::SceneError`]; callers keep
//! their old scene) → an accelerator ([`accel::Accel`]) over the scene's spheres and triangles →
//! [`trace::Tracer::trace`] per sample in worker threads ([`render`]) → a linear `f32` film → [`export`]
//! (PNG, EXR). A clicked pixel runs the same [`trace::Tracer::trace`] with a tree recorder instead of the
//! no-op one.

pub mod accel;
pub mod app;
pub mod experiments;
pub mod export;
pub mod geometry;
pub mod ray_tree;
pub mod render;
pub mod scene;
pub mod shade;
pub mod trace;
