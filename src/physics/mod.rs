//! The physics: spheres in a cube, the collision models, the broad phase.
//! It knows nothing of threads (it is handed an [`exec::Exec`]) or terminals.
pub mod auto;
pub mod broad;
mod build;
pub mod contact;
mod detect;
pub(crate) mod discrete;
pub mod edit;
pub mod exact;
pub mod exec;
pub mod flight;
pub(crate) mod free_space;
pub(crate) mod huge_pages;
mod kind;
mod model;
pub mod overlap;
pub(crate) mod prefetch;
pub mod reference;
pub mod relax;
pub mod sphere;
pub mod swept;
pub(crate) mod wide;
pub(crate) mod world;

pub use exec::{Exec, Serial};
pub use model::{Model, ModelKind};
pub use sphere::Sphere;
pub use world::{Counters, World};
