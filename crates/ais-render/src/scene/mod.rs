//! Scene files: the Mitsuba 3 XML subset we read, and the typed description built from it.

mod cie1931;
mod description;
mod file_resolver;
mod instancing;
mod properties;
mod spectrum;
mod xml;

pub use description::{
    load_scene, parse_scene, CameraDescription, FovAxis, MeshFormat, Projection, SceneDescription,
    ShapeDescription, ShapeGeometry, ThinLens,
};
pub(crate) use description::{read_fov, warn_unknown};
pub use file_resolver::FileResolver;
pub use instancing::{InstanceDescription, ShapeGroup};
pub use properties::{LocatedProperty, Plugin, Property};
pub use spectrum::{ColourRole, SampledSpectrum, Spectrum};
pub use xml::look_at;
