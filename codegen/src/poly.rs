//! Polynomials with exact rational coefficients in the atoms of a machine (linear commands, sine
//! and cosine of rotary commands, kinematic symbols), kept in a canonical form:
//! - terms in a deterministic order (total degree, then the atoms in atom order);
//! - no zero coefficients;
//! - reduced modulo `sin² + cos² = 1` for every rotary axis: every `cos²` is rewritten as
//!   `1 − sin²`, so two polynomials are equal as functions iff they are equal as data.

use crate::rational::Rational;
use std::collections::BTreeMap;
use std::collections::btree_map::Entry;

/// Index of an atom in the model's [`crate::atoms::AtomTable`].
pub type Atom = u16;

/// A product of atom powers, atoms ascending, exponents ≥ 1.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct Monomial(pub Vec<(Atom, u8)>);

impl Monomial {
    /// The monomial 1.
    pub fn one() -> Monomial {
        Monomial(Vec::new())
    }

    /// A single atom.
    pub fn atom(a: Atom) -> Monomial {
        Monomial(vec![(a, 1)])
    }

    /// Total degree.
    pub fn degree(&self) -> u32 {
        self.0.iter().map(|&(_, e)| e as u32).sum()
    }

    /// The exponent of `a`.
    pub fn exponent(&self, a: Atom) -> u8 {
        self.0.iter().find(|&&(x, _)| x == a).map_or(0, |&(_, e)| e)
    }

    /// The product of two monomials.
    pub fn mul(&self, o: &Monomial) -> Monomial {
        let mut out = Vec::with_capacity(self.0.len() + o.0.len());
        let (mut i, mut j) = (0, 0);
        while i < self.0.len() || j < o.0.len() {
            match (self.0.get(i), o.0.get(j)) {
                (Some(&(a, ea)), Some(&(b, eb))) if a == b => {
                    out.push((a, ea + eb));
                    i += 1;
                    j += 1;
                }
                (Some(&(a, ea)), Some(&(b, _))) if a < b => {
                    out.push((a, ea));
                    i += 1;
                }
                (Some(_), Some(&(b, eb))) | (None, Some(&(b, eb))) => {
                    out.push((b, eb));
                    j += 1;
                }
                (Some(&(a, ea)), None) => {
                    out.push((a, ea));
                    i += 1;
                }
                (None, None) => unreachable!(),
            }
        }
        Monomial(out)
    }

    /// This monomial with the exponent of `a` lowered by `k` (which must be present).
    pub fn divide(&self, a: Atom, k: u8) -> Monomial {
        Monomial(
            self.0
                .iter()
                .filter_map(|&(x, e)| match x == a {
                    true if e > k => Some((x, e - k)),
                    true => None,
                    false => Some((x, e)),
                })
                .collect(),
        )
    }
}

impl PartialOrd for Monomial {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Monomial {
    /// Lower degree first; then by the atom sequence.
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.degree()
            .cmp(&o.degree())
            .then_with(|| self.0.cmp(&o.0))
    }
}

/// A polynomial: a sum of monomials with non-zero rational coefficients.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct Poly {
    terms: BTreeMap<Monomial, Rational>,
}

fn add_coeff(terms: &mut BTreeMap<Monomial, Rational>, m: Monomial, c: Rational) {
    if c.is_zero() {
        return;
    }
    match terms.entry(m) {
        Entry::Vacant(v) => {
            v.insert(c);
        }
        Entry::Occupied(mut o) => {
            let sum = o
                .get()
                .checked_add(c)
                .expect("coefficients stay far below the i128 range");
            if sum.is_zero() {
                o.remove();
            } else {
                *o.get_mut() = sum;
            }
        }
    }
}

impl Poly {
    /// Zero.
    pub fn zero() -> Poly {
        Poly::default()
    }

    /// A constant.
    pub fn constant(c: Rational) -> Poly {
        let mut p = Poly::zero();
        add_coeff(&mut p.terms, Monomial::one(), c);
        p
    }

    /// A single atom.
    pub fn atom(a: Atom) -> Poly {
        Poly::term(Monomial::atom(a), Rational::ONE)
    }

    /// `c · m`.
    pub fn term(m: Monomial, c: Rational) -> Poly {
        let mut p = Poly::zero();
        add_coeff(&mut p.terms, m, c);
        p
    }

    /// `true` for the zero polynomial.
    pub fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }

    /// The terms in canonical order.
    pub fn terms(&self) -> impl Iterator<Item = (&Monomial, Rational)> {
        self.terms.iter().map(|(m, c)| (m, *c))
    }

    /// Number of terms.
    pub fn len(&self) -> usize {
        self.terms.len()
    }

    /// `true` when there are no terms (same as [`Poly::is_zero`]).
    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// The constant value, if the polynomial is a constant.
    pub fn as_constant(&self) -> Option<Rational> {
        match self.terms.len() {
            0 => Some(Rational::ZERO),
            1 => self.terms.get(&Monomial::one()).copied(),
            _ => None,
        }
    }

    /// `self + o`.
    pub fn add(&self, o: &Poly) -> Poly {
        let mut out = self.clone();
        for (m, c) in &o.terms {
            add_coeff(&mut out.terms, m.clone(), *c);
        }
        out
    }

    /// `self − o`.
    pub fn sub(&self, o: &Poly) -> Poly {
        self.add(&o.neg())
    }

    /// `−self`.
    pub fn neg(&self) -> Poly {
        self.scale(-Rational::ONE)
    }

    /// `c · self`.
    pub fn scale(&self, c: Rational) -> Poly {
        if c.is_zero() {
            return Poly::zero();
        }
        Poly {
            terms: self
                .terms
                .iter()
                .map(|(m, x)| (m.clone(), x.checked_mul(c).expect("bounded coefficients")))
                .collect(),
        }
    }

    /// `self · o`, not yet reduced modulo `sin² + cos² = 1`.
    pub fn mul(&self, o: &Poly) -> Poly {
        let mut out = BTreeMap::new();
        for (ma, ca) in &self.terms {
            for (mb, cb) in &o.terms {
                add_coeff(
                    &mut out,
                    ma.mul(mb),
                    ca.checked_mul(*cb).expect("bounded coefficients"),
                );
            }
        }
        Poly { terms: out }
    }

    /// Rewrites every `cos²` as `1 − sin²` for each `(sin, cos)` atom pair, giving the canonical
    /// form.
    pub fn reduce(&self, trig_pairs: &[(Atom, Atom)]) -> Poly {
        let mut cur = self.clone();
        for &(s, c) in trig_pairs {
            while let Some(m) = cur.terms.keys().find(|m| m.exponent(c) >= 2).cloned() {
                let coeff = cur.terms.remove(&m).expect("present");
                let rest = m.divide(c, 2);
                // rest · cos² = rest − rest · sin²
                add_coeff(&mut cur.terms, rest.clone(), coeff);
                add_coeff(&mut cur.terms, rest.mul(&Monomial(vec![(s, 2)])), -coeff);
            }
        }
        cur
    }

    /// Rewrites every `√p²` as `p` for each `(atom, p)` rule ([`crate::atoms::AtomTable::root_rules`]).
    pub fn reduce_roots(&self, rules: &[(Atom, u64)]) -> Poly {
        if rules.is_empty() {
            return self.clone();
        }
        let mut out = Poly::zero();
        for (m, &c) in &self.terms {
            let mut coeff = c;
            let mut mono = m.clone();
            for &(a, p) in rules {
                let e = mono.exponent(a);
                if e >= 2 {
                    mono = mono.divide(a, e - e % 2);
                    for _ in 0..e / 2 {
                        coeff = coeff
                            .checked_mul(Rational::int(p as i64))
                            .expect("bounded coefficients");
                    }
                }
            }
            add_coeff(&mut out.terms, mono, coeff);
        }
        out
    }

    /// The value at `atoms[a]` for every atom `a`.
    pub fn eval(&self, atoms: &[f64]) -> f64 {
        self.terms
            .iter()
            .map(|(m, c)| {
                m.0.iter().fold(c.to_f64(), |acc, &(a, e)| {
                    acc * atoms[a as usize].powi(e as i32)
                })
            })
            .sum()
    }

    /// The atoms that occur, ascending.
    pub fn atoms(&self) -> Vec<Atom> {
        let mut v: Vec<Atom> = self
            .terms
            .keys()
            .flat_map(|m| m.0.iter().map(|&(a, _)| a))
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Splits into `(q, r)` with `self = a · q + r`, where `r` has no term containing `a`.
    pub fn split_by(&self, a: Atom) -> (Poly, Poly) {
        let (mut q, mut r) = (Poly::zero(), Poly::zero());
        for (m, c) in &self.terms {
            if m.exponent(a) > 0 {
                add_coeff(&mut q.terms, m.divide(a, 1), *c);
            } else {
                add_coeff(&mut r.terms, m.clone(), *c);
            }
        }
        (q, r)
    }

    /// The coefficient of the first term (canonical order), or zero.
    pub fn leading_coefficient(&self) -> Rational {
        self.terms
            .values()
            .next()
            .copied()
            .unwrap_or(Rational::ZERO)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pythagoras_reduces_to_one() {
        let (s, c) = (0, 1);
        let p = Poly::atom(s)
            .mul(&Poly::atom(s))
            .add(&Poly::atom(c).mul(&Poly::atom(c)));
        assert_eq!(p.reduce(&[(s, c)]), Poly::constant(Rational::ONE));
        // x·c²·s + x·s³ = x·s
        let x = 2;
        let xs = Poly::atom(x).mul(&Poly::atom(s));
        let q = xs
            .mul(&Poly::atom(c))
            .mul(&Poly::atom(c))
            .add(&xs.mul(&Poly::atom(s)).mul(&Poly::atom(s)));
        assert_eq!(q.reduce(&[(s, c)]), xs);
    }

    #[test]
    fn cancellation_and_split() {
        let a = Poly::atom(0).add(&Poly::atom(1));
        assert!(a.sub(&a).is_zero());
        let p = Poly::atom(0).mul(&Poly::atom(1)).add(&Poly::atom(2));
        let (q, r) = p.split_by(0);
        assert_eq!(q, Poly::atom(1));
        assert_eq!(r, Poly::atom(2));
        assert_eq!(p.eval(&[2.0, 3.0, 5.0]), 11.0);
    }
}
