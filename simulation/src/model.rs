//! What a model fits: its terms in order ([`Effect`] × basis, see `model_spec::terms`); its
//! H-matrix columns are the terms' columns in order.

pub use model_spec::basis::{Basis, BasisContext, Carrier};
pub use model_spec::terms::{Effect, Term, unknown_effect};
use model_spec::{ErrorId, Machine};

/// A model: terms in order; its columns are the terms' columns in order.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Model {
    /// The terms.
    pub terms: Vec<Term>,
}

impl Model {
    /// The model called `name` of machine `m` (`full`: every error of the machine, constant;
    /// a sub-model: its terms), or `None`.
    pub fn of(m: &Machine, name: &str) -> Option<Model> {
        if name == model_spec::FULL_MODEL {
            return Some(Model::constant(&m.errors));
        }
        m.models.get(name).map(|s| Model {
            terms: s.terms.clone(),
        })
    }

    /// Every error of `errors` with a constant basis.
    pub fn constant(errors: &[ErrorId]) -> Model {
        Model {
            terms: errors
                .iter()
                .map(|&e| Term {
                    effect: Effect::Error(e),
                    basis: Basis::Const,
                })
                .collect(),
        }
    }

    /// Number of H-matrix columns.
    pub fn width(&self) -> usize {
        self.terms.iter().map(|t| t.basis.width()).sum()
    }

    /// `(term index, component)` of every column, in order.
    pub fn columns(&self) -> Vec<(usize, usize)> {
        self.terms
            .iter()
            .enumerate()
            .flat_map(|(i, t)| (0..t.basis.width()).map(move |k| (i, k)))
            .collect()
    }

    /// The machine errors the model uses, ascending, without repeats.
    pub fn errors(&self) -> Vec<ErrorId> {
        model_spec::terms::errors_of(&self.terms)
    }
}
