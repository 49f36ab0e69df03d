//! OBJ meshes and their MTL materials: positions, and the `vn` normals and `vt` coordinates a
//! scene uses, faces triangulated, the Phong material mapped from
//! `Ka`/`Kd`/`Ks`/`Ns`/`Ni`/`d`/`Tr`/`illum`, and the mesh placed by scale, rotation (X then Y
//! then Z, in degrees) and translation (docs/design.md, "Scene files"). A bare `.obj` opened as
//! a whole scene is in [`super::first_look`].
//!
//! - `request`: what to load (the mesh, its placement); `paths`: the files it names;
//! - `read`: OBJ text into tobj's models, through the parallel reader ([`parse`]) where it can,
//!   and which faces give `vn`/`vt` at every corner (`corners`) where tobj reads;
//! - `memory`: the memory budget, checked before anything is built;
//! - `mesh`: the steps of adding a mesh to a scene; `faces`: one model's faces placed;
//!   `attributes`: the mesh's normals (smooth ones from [`crate::geometry::normals`]) and
//!   texture coordinates;
//! - `mtl`: MTL libraries and materials; `maps`: their textures.

mod attributes;
mod corners;
mod explain;
mod faces;
mod maps;
mod memory;
mod mesh;
mod mtl;
pub mod parse;
mod paths;
mod polygons;
mod read;
mod request;

pub(crate) use mesh::add_mesh;
pub(crate) use paths::{file_stem, is_obj_path};
pub use request::MeshPlacement;
pub(crate) use request::MeshRequest;
