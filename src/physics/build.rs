//! Making a model from its kind. Apart from `model.rs`, so the trait and the
//! kinds import no model and no model imports back through them.
use super::auto::Auto;
use super::discrete::Discrete;
use super::exact::Exact;
use super::model::{Model, ModelKind};
use super::swept::Swept;

impl ModelKind {
    /// A fresh model of this kind.
    #[must_use]
    pub fn build(self) -> Box<dyn Model> {
        match self {
            ModelKind::Discrete => Box::new(Discrete::default()),
            ModelKind::Swept => Box::new(Swept::default()),
            ModelKind::Exact => Box::new(Exact::default()),
            ModelKind::Auto(t) => Box::new(Auto::new(t)),
        }
    }
}
