//! Named intermediate quantities: how the engine keeps expressions small on long chains.
//!
//! Carried through a chain as expanded polynomials, the entries of the partial rotations and
//! the lever arms double in size with every rotary axis. The derivation instead hands every
//! quantity it keeps (an entry of a partial rotation, a component of a lever arm) and every
//! product it forms to a namer: a polynomial of at most [`DeriveOptions::max_terms`]
//! terms stays as it is; a larger one becomes a new atom, an *intermediate*, defined by that
//! polynomial. Intermediates are numbered after the machine's atoms (intermediate `k` is atom
//! `first + k`), each defined in the atoms and earlier intermediates, so a gain is a small
//! polynomial over a DAG whose size grows with the chain, not exponentially.
//!
//! A chain short enough is not named at all ([`crate::GainModel::derive`] tries the expanded
//! form first, up to [`DeriveOptions::EXPAND_UP_TO`] terms): every built-in machine derives exactly the
//! expanded canonical polynomials of the seed's tables, and compiles to the same program.
//! Intermediates are named up to a constant factor (`p`, `−p` and `2p` share one), and a
//! polynomial named twice is one intermediate.

use crate::atoms::AtomTable;
use crate::hash::FxHashMap;
use crate::poly::{Atom, Monomial, Poly};
use crate::rational::Rational;
use std::sync::Arc;

/// How the derivation keeps its expressions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeriveOptions {
    /// The largest polynomial (number of terms) kept expanded; a larger quantity or product
    /// is named as an intermediate.
    pub max_terms: usize,
}

impl DeriveOptions {
    /// Everything expanded: the canonical polynomials of the seed's tables, at a cost that
    /// doubles with every rotary axis.
    pub const EXPANDED: DeriveOptions = DeriveOptions {
        max_terms: usize::MAX,
    };

    /// The default bound for chains too long to expand, 6 terms. A smaller bound names more and gives long chains fewer operations: the gains of the
    /// synthetic chain of 12 rotary axes take 1 856 operations at 6 terms, 2 132 at 8, 2 507 at
    /// 12 and 2 849 at 24 (`docs/codegen.md`, long chains).
    pub const DEFAULT_MAX_TERMS: usize = 6;

    /// The bound under which [`crate::GainModel::derive`] keeps a chain expanded, 32 terms:
    /// when no quantity or product of a chain exceeds it, nothing is named. Every built-in
    /// machine stays under it (the largest, the nutating head, reaches 20 terms; axes along
    /// x, y and z reach 7); the synthetic chains exceed it from 7 rotary axes on.
    pub const EXPAND_UP_TO: usize = 32;
}

impl Default for DeriveOptions {
    fn default() -> DeriveOptions {
        DeriveOptions {
            max_terms: DeriveOptions::DEFAULT_MAX_TERMS,
        }
    }
}

/// The canonical-form rules of a machine's atoms: `cos² = 1 − sin²` per rotary axis and
/// `√p² = p` per root.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Rules {
    /// `(sin, cos)` atom pairs.
    pub trig_pairs: Vec<(Atom, Atom)>,
    /// `(atom, p)` for every `√p` atom.
    pub roots: Vec<(Atom, u64)>,
}

impl Rules {
    /// The rules of the atoms `atoms`.
    pub fn of(atoms: &AtomTable) -> Rules {
        Rules {
            trig_pairs: atoms.trig_pairs(),
            roots: atoms.root_rules(),
        }
    }

    /// `p` in canonical form.
    pub fn canonical(&self, p: Poly) -> Poly {
        p.canonical(&self.trig_pairs, &self.roots)
    }
}

/// The named intermediates of a derivation: definitions in order, each a canonical
/// polynomial in the machine's atoms and the intermediates before it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Intermediates {
    first: Atom,
    definitions: Arc<[Poly]>,
    rules: Rules,
}

impl Intermediates {
    /// No intermediates, after the atoms of `atoms`.
    pub fn none(atoms: &AtomTable) -> Intermediates {
        Intermediates {
            first: atom_index(atoms.kinds.len()),
            definitions: Arc::from(Vec::new()),
            rules: Rules::of(atoms),
        }
    }

    /// The atom of the first intermediate: the number of the machine's atoms.
    pub fn first(&self) -> Atom {
        self.first
    }

    /// The definitions, in order: `definitions()[k]` is atom `first() + k`.
    pub fn definitions(&self) -> &[Poly] {
        &self.definitions
    }

    /// The number of intermediates.
    pub fn len(&self) -> usize {
        self.definitions.len()
    }

    /// `true` when there are none (every gain is an expanded polynomial in the atoms).
    pub fn is_empty(&self) -> bool {
        self.definitions.is_empty()
    }

    /// The canonical-form rules of the atoms.
    pub fn rules(&self) -> &Rules {
        &self.rules
    }

    /// `true` when `p` mentions an intermediate.
    pub fn mentioned_in(&self, p: &Poly) -> bool {
        p.terms()
            .any(|(m, _)| m.factors().iter().any(|&(a, _)| a >= self.first))
    }

    /// Appends the value of every intermediate to `values`, which holds the value of every
    /// atom of the machine ([`AtomTable::all_values`]).
    pub fn extend_values(&self, values: &mut Vec<f64>) {
        debug_assert_eq!(values.len(), usize::from(self.first));
        values.reserve(self.definitions.len());
        for d in self.definitions.iter() {
            let v = d.eval(values);
            values.push(v);
        }
    }

    /// An expander of polynomials in the atoms and these intermediates into canonical
    /// polynomials in the atoms alone. The size of an expansion grows exponentially with the
    /// number of rotary axes a quantity spans: cheap for the chains of five-axis machines,
    /// impractical beyond about ten rotary axes.
    pub fn expander(&self) -> Expander<'_> {
        Expander {
            of: self,
            expanded: Vec::with_capacity(self.definitions.len()),
        }
    }
}

/// Expands polynomials over the intermediates ([`Intermediates::expander`]), remembering the
/// expansion of every intermediate it met.
#[derive(Debug)]
pub struct Expander<'a> {
    of: &'a Intermediates,
    expanded: Vec<Poly>,
}

impl Expander<'_> {
    /// `p` with every intermediate replaced by its expansion, in canonical form.
    pub fn expand(&mut self, p: &Poly) -> Poly {
        let first = usize::from(self.of.first);
        let needed = p
            .atoms()
            .last()
            .map_or(0, |&a| (usize::from(a) + 1).saturating_sub(first));
        while self.expanded.len() < needed {
            let k = self.expanded.len();
            let e = self.substitute(&self.of.definitions[k].clone());
            self.expanded.push(e);
        }
        self.substitute(p)
    }

    /// `p` with the intermediates (already expanded) replaced.
    fn substitute(&self, p: &Poly) -> Poly {
        if !self.of.mentioned_in(p) {
            return p.clone();
        }
        let first = self.of.first;
        let mut out = Poly::zero();
        for (m, c) in p.terms() {
            let mut plain = Vec::new();
            let mut term = Poly::constant(Rational::ONE);
            for &(a, e) in m.factors() {
                if a < first {
                    plain.push((a, e));
                } else {
                    let x = &self.expanded[usize::from(a - first)];
                    for _ in 0..e {
                        term = self.of.rules.canonical(term.mul(x));
                    }
                }
            }
            let factor = Poly::term(Monomial::new(&plain), c);
            out = out.add(&self.of.rules.canonical(term.mul(&factor)));
        }
        out
    }
}

/// The atom index of position `i`, within the `u16` of [`Atom`]: a machine within the
/// limits of its description has a few hundred atoms and a few thousand intermediates.
fn atom_index(i: usize) -> Atom {
    Atom::try_from(i)
        .expect("atoms and intermediates of a machine within the description limits fit in u16")
}

/// Names the quantities of a derivation that exceed the bound ([`DeriveOptions`]).
#[derive(Debug)]
pub(crate) struct Namer {
    first: Atom,
    max_terms: usize,
    rules: Rules,
    definitions: Vec<Poly>,
    /// Monic polynomial (leading coefficient 1) → its intermediate.
    named: FxHashMap<Poly, Atom>,
    /// A trial that names nothing ([`Namer::trial`]).
    trial: bool,
    /// Set when a trial met a quantity beyond its bound.
    exceeded: bool,
}

impl Namer {
    /// A namer for the atoms `atoms`.
    pub(crate) fn new(atoms: &AtomTable, options: DeriveOptions) -> Namer {
        Namer {
            first: atom_index(atoms.kinds.len()),
            max_terms: options.max_terms.max(1),
            rules: Rules::of(atoms),
            definitions: Vec::new(),
            named: FxHashMap::default(),
            trial: false,
            exceeded: false,
        }
    }

    /// A namer that names nothing: a quantity beyond `max_terms` marks the trial as
    /// [`Namer::exceeded`] and becomes zero, so that the rest of the walk stays cheap (its
    /// result is then discarded).
    pub(crate) fn trial(atoms: &AtomTable, max_terms: usize) -> Namer {
        Namer {
            trial: true,
            ..Namer::new(atoms, DeriveOptions { max_terms })
        }
    }

    /// `true` when a trial met a quantity it would have had to name.
    pub(crate) fn exceeded(&self) -> bool {
        self.exceeded
    }

    /// `p` in canonical form.
    pub(crate) fn canonical(&self, p: Poly) -> Poly {
        self.rules.canonical(p)
    }

    /// `p` itself when it has at most the bound of terms, else `c · u` with `u` the
    /// intermediate of `p / c` (named now, or found).
    pub(crate) fn keep(&mut self, p: Poly) -> Poly {
        if p.len() <= self.max_terms {
            return p;
        }
        self.name(&p)
    }

    /// `c · u` with `u` the intermediate of `p / c`, `c` the leading coefficient of `p`
    /// (`p` itself when it is a constant or a single term).
    fn name(&mut self, p: &Poly) -> Poly {
        if p.len() <= 1 {
            return p.clone();
        }
        if self.trial {
            self.exceeded = true;
            return Poly::zero();
        }
        let lead = p.leading_coefficient();
        let scaled;
        let unit = if lead.is_one() {
            p
        } else {
            scaled = p.scale(Rational::new(lead.denom(), lead.numer()));
            &scaled
        };
        let atom = match self.named.get(unit) {
            Some(&a) => a,
            None => {
                let a = atom_index(usize::from(self.first) + self.definitions.len());
                self.definitions.push(unit.clone());
                self.named.insert(unit.clone(), a);
                a
            }
        };
        Poly::term(Monomial::atom(atom), lead)
    }

    /// `a · b` in canonical form; a factor is named first when the product would exceed the
    /// bound (the larger factor first).
    pub(crate) fn mul(&mut self, a: &Poly, b: &Poly) -> Poly {
        if a.is_zero() || b.is_zero() {
            return Poly::zero();
        }
        let max = self.max_terms;
        let too_large = |a: &Poly, b: &Poly| a.len().saturating_mul(b.len()) > max;
        if !too_large(a, b) {
            return self.canonical(a.mul(b));
        }
        let (named_a, named_b);
        let (mut a, mut b) = (a, b);
        if a.len() >= b.len() {
            named_a = self.name(a);
            a = &named_a;
        } else {
            named_b = self.name(b);
            b = &named_b;
        }
        if too_large(a, b) {
            let (x, y) = (self.name(a), self.name(b));
            return self.canonical(x.mul(&y));
        }
        self.canonical(a.mul(b))
    }

    /// The intermediates named so far.
    pub(crate) fn finish(self) -> Intermediates {
        Intermediates {
            first: self.first,
            definitions: Arc::from(self.definitions),
            rules: self.rules,
        }
    }
}
