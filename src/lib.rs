//! raytree: recursive (Whitted) ray tracing as in the lecture the model follows (its rules are in
//! docs/design.md), with the ray tracing tree of any pixel.
//!
//! Layers, bottom to top; a module imports only from the layers below it, never in a circle:
//! 1. [`choice`], [`rng`], [`sync`], [`plural`] and [`geometry`]: named options; the seeded
//!    random numbers; locks that outlive a panic; counted nouns in messages; rays, hits, ray-origin offsets, the sphere
//!    and triangle intersection methods.
//! 2. [`scene`]: plain scene data, the camera ([`scene::camera`]), the rules and limits every
//!    input is held to ([`scene::rules`]), TOML and OBJ loading, built-in scenes.
//! 3. [`accel`]: none / uniform grid / BVH behind one type.
//! 4. [`shade`], [`trace`], [`ray_tree`]: the local model, the one recursive trace, the tree.
//! 5. [`render`] (tiles, film, the viewer's worker session, statistics), [`export`],
//!    [`scene_view`] (the ray tree in 3D as segments every view draws alike) and [`diagram`]
//!    (the tree as the lecture's figure: layout, legend, SVG), [`lessons`] (the lecture as
//!    guided steps checked against the trace, and its pseudocode beside a tree).
//! 6. `experiments` (feature `lab`: sweeps, charts, image metrics) and `app` (feature `viewer`:
//!    the egui window; the only module that uses egui, eframe or wgpu).
//! 7. The `raytree` command (`src/main.rs`).
//!
//! Data flow: a scene file or OBJ → [`scene::Scene`] (or a [`scene::SceneError`]; callers keep
//! their old scene) → an accelerator ([`accel::Accel`]) over the scene's spheres and triangles →
//! [`trace::Tracer::trace`] per sample in worker threads ([`render`]) → a linear `f32` film → [`export`]
//! (PNG, EXR). A clicked pixel runs the same [`trace::Tracer::trace`] with a tree recorder instead of the
//! no-op one.

pub mod accel;
#[cfg(feature = "viewer")]
pub mod app;
pub mod choice;
pub mod diagram;
#[cfg(feature = "lab")]
pub mod experiments;
pub mod export;
pub mod geometry;
pub mod lessons;
pub mod plural;
pub mod ray_tree;
pub mod render;
pub mod rng;
pub mod scene;
pub mod scene_view;
pub mod shade;
pub mod sync;
pub mod trace;
