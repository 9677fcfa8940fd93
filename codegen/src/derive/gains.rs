//! The gains of a model in their two forms: shared (what code is compiled from) and expanded
//! (what people read).

use crate::intermediates::Intermediates;
use crate::poly::Poly;
use std::ops::Deref;
use std::sync::OnceLock;

/// The six gains of every error of a model (`[gx, gy, gz, gi, gj, gk]`), in two forms:
///
/// - **shared** ([`Gains::shared`]): canonical polynomials in the machine's atoms and the named
///   [`Intermediates`]; what [`crate::compile`] lowers and [`crate::GainModel::evaluate`]
///   evaluates. Its size grows with the length of the chain.
/// - **expanded** ([`Gains::expanded`], and what indexing or iterating a `Gains` gives):
///   canonical polynomials in the atoms alone, the form of the seed's tables. When there are
///   no intermediates (every built-in machine) it is the shared form itself; otherwise it is
///   computed on first use, at a cost that doubles with every rotary axis a gain spans
///   (milliseconds for five axes, seconds beyond about ten).
///
/// Both forms are the same functions, and the same gains are identically zero in both.
#[derive(Clone, Debug)]
pub struct Gains {
    shared: Vec<[Poly; 6]>,
    intermediates: Intermediates,
    expanded: OnceLock<Vec<[Poly; 6]>>,
}

impl Gains {
    /// The gains `shared` over `intermediates`.
    pub(crate) fn new(shared: Vec<[Poly; 6]>, intermediates: Intermediates) -> Gains {
        let expanded = OnceLock::new();
        if intermediates.is_empty() {
            expanded.set(shared.clone()).expect("a new cell is empty");
        }
        Gains {
            shared,
            intermediates,
            expanded,
        }
    }

    /// The shared form: per error, six canonical polynomials in the atoms and the
    /// intermediates.
    pub fn shared(&self) -> &[[Poly; 6]] {
        &self.shared
    }

    /// The intermediates the shared form is written in.
    pub fn intermediates(&self) -> &Intermediates {
        &self.intermediates
    }

    /// The expanded form: per error, six canonical polynomials in the atoms alone (computed
    /// on the first call when there are intermediates).
    pub fn expanded(&self) -> &[[Poly; 6]] {
        self.expanded.get_or_init(|| {
            let mut x = self.intermediates.expander();
            self.shared
                .iter()
                .map(|g| std::array::from_fn(|k| x.expand(&g[k])))
                .collect()
        })
    }

    /// The gains of the errors at positions `rows`, over the same intermediates.
    pub(crate) fn select(&self, rows: &[usize]) -> Gains {
        let pick = |all: &[[Poly; 6]]| rows.iter().map(|&i| all[i].clone()).collect();
        let expanded = OnceLock::new();
        if let Some(all) = self.expanded.get() {
            expanded.set(pick(all)).expect("a new cell is empty");
        }
        Gains {
            shared: pick(&self.shared),
            intermediates: self.intermediates.clone(),
            expanded,
        }
    }
}

impl Deref for Gains {
    type Target = [[Poly; 6]];

    /// The expanded form ([`Gains::expanded`]).
    fn deref(&self) -> &[[Poly; 6]] {
        self.expanded()
    }
}

impl<'a> IntoIterator for &'a Gains {
    type Item = &'a [Poly; 6];
    type IntoIter = std::slice::Iter<'a, [Poly; 6]>;

    /// The expanded form, error by error.
    fn into_iter(self) -> Self::IntoIter {
        self.expanded().iter()
    }
}
