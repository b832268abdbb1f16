//! # ais-render: a CPU renderer for studying adaptive importance sampling
//!
//! Reads Mitsuba 3 XML scenes (a documented subset) with OBJ, PLY and GLB meshes, builds an
//! obvhs CWBVH, and renders with a perspective camera onto a box-filtered film written as
//! EXR plus a tone-mapped PNG preview. Rendering is tiled over rayon with per-pixel seeds,
//! so images do not depend on the thread count.

#![warn(missing_docs)]

pub mod atomic_write;
pub mod bsdf;
pub mod camera;
pub mod default_scene;
pub mod error;
pub mod film;
pub mod geometry;
pub mod image_io;
pub mod integrators;
pub mod lights;
pub mod limits;
pub mod mesh;
pub mod render;
pub mod request;
pub mod scene;
pub mod shapes;
pub mod texture;
pub mod world;

pub use error::InputError;
