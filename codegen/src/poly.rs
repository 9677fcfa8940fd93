//! Polynomials with exact rational coefficients in the atoms of a machine (linear commands, sine
//! and cosine of rotary commands, kinematic symbols), kept in a canonical form:
//! - terms in a deterministic order (total degree, then the atoms in atom order);
//! - no zero coefficients;
//! - reduced modulo `sin² + cos² = 1` for every rotary axis: every `cos²` is rewritten as
//!   `1 − sin²`, so two polynomials are equal as functions iff they are equal as data.

use crate::rational::Rational;

/// Index of an atom in the model's [`crate::atoms::AtomTable`].
pub type Atom = u16;

/// The most factors a monomial holds without a heap allocation: every monomial of a shared
/// gain, and most of an expanded one.
const INLINE: usize = 7;

/// The factors of a monomial: up to [`INLINE`] in place, more on the heap.
#[derive(Clone)]
enum Factors {
    Inline(u8, [(Atom, u8); INLINE]),
    Heap(Vec<(Atom, u8)>),
}

impl Factors {
    fn as_slice(&self) -> &[(Atom, u8)] {
        match self {
            Factors::Inline(n, items) => &items[..usize::from(*n)],
            Factors::Heap(v) => v,
        }
    }

    /// The factors yielded by `it`, at most `bound` of them.
    fn collect(bound: usize, it: impl Iterator<Item = (Atom, u8)>) -> Factors {
        if bound <= INLINE {
            let mut items = [(0, 0); INLINE];
            let mut n = 0;
            for f in it {
                items[n] = f;
                n += 1;
            }
            Factors::Inline(n as u8, items)
        } else {
            let v: Vec<(Atom, u8)> = it.collect();
            if v.len() <= INLINE {
                Factors::collect(v.len(), v.into_iter())
            } else {
                Factors::Heap(v)
            }
        }
    }
}

/// A product of atom powers, atoms ascending, exponents ≥ 1.
#[derive(Clone)]
pub struct Monomial(Factors);

impl Monomial {
    /// The monomial of `factors`: `(atom, exponent)`, atoms ascending, exponents ≥ 1.
    pub fn new(factors: &[(Atom, u8)]) -> Monomial {
        debug_assert!(
            factors.windows(2).all(|w| w[0].0 < w[1].0) && factors.iter().all(|f| f.1 >= 1)
        );
        Monomial(Factors::collect(factors.len(), factors.iter().copied()))
    }

    /// The monomial 1.
    pub fn one() -> Monomial {
        Monomial(Factors::Inline(0, [(0, 0); INLINE]))
    }

    /// A single atom.
    pub fn atom(a: Atom) -> Monomial {
        Monomial::new(&[(a, 1)])
    }

    /// The factors `(atom, exponent)`, atoms ascending.
    pub fn factors(&self) -> &[(Atom, u8)] {
        self.0.as_slice()
    }

    /// `true` for the monomial 1.
    pub fn is_one(&self) -> bool {
        self.factors().is_empty()
    }

    /// Total degree.
    pub fn degree(&self) -> u32 {
        self.factors().iter().map(|&(_, e)| e as u32).sum()
    }

    /// The exponent of `a`.
    pub fn exponent(&self, a: Atom) -> u8 {
        self.factors()
            .iter()
            .find(|&&(x, _)| x == a)
            .map_or(0, |&(_, e)| e)
    }

    /// The product of two monomials.
    pub fn mul(&self, o: &Monomial) -> Monomial {
        let (x, y) = (self.factors(), o.factors());
        let (mut i, mut j) = (0, 0);
        let merged = std::iter::from_fn(|| match (x.get(i), y.get(j)) {
            (Some(&(a, ea)), Some(&(b, eb))) if a == b => {
                i += 1;
                j += 1;
                Some((a, ea + eb))
            }
            (Some(&(a, ea)), Some(&(b, _))) if a < b => {
                i += 1;
                Some((a, ea))
            }
            (_, Some(&f)) => {
                j += 1;
                Some(f)
            }
            (Some(&f), None) => {
                i += 1;
                Some(f)
            }
            (None, None) => None,
        });
        Monomial(Factors::collect(x.len() + y.len(), merged))
    }

    /// This monomial with the exponent of `a` lowered by `k` (which must be present).
    pub fn divide(&self, a: Atom, k: u8) -> Monomial {
        let f = self.factors();
        Monomial(Factors::collect(
            f.len(),
            f.iter().filter_map(|&(x, e)| match x == a {
                true if e > k => Some((x, e - k)),
                true => None,
                false => Some((x, e)),
            }),
        ))
    }
}

impl Default for Monomial {
    fn default() -> Monomial {
        Monomial::one()
    }
}

impl PartialEq for Monomial {
    fn eq(&self, o: &Monomial) -> bool {
        self.factors() == o.factors()
    }
}

impl Eq for Monomial {}

impl std::hash::Hash for Monomial {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        self.factors().hash(h);
    }
}

impl std::fmt::Debug for Monomial {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("Monomial").field(&self.factors()).finish()
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
            .then_with(|| self.factors().cmp(o.factors()))
    }
}

/// A polynomial: a sum of monomials with non-zero rational coefficients, held as its terms in
/// canonical order (a sorted vector: adding two polynomials is a merge).
#[derive(Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct Poly {
    terms: Vec<(Monomial, Rational)>,
}

fn sum(a: Rational, b: Rational) -> Rational {
    a.checked_add(b)
        .expect("coefficients stay far below the i128 range")
}

fn product(a: Rational, b: Rational) -> Rational {
    a.checked_mul(b).expect("bounded coefficients")
}

impl Poly {
    /// The polynomial of `terms` in any order, equal monomials added up, zeros dropped.
    fn from_terms(mut terms: Vec<(Monomial, Rational)>) -> Poly {
        terms.sort_by(|x, y| x.0.cmp(&y.0));
        let mut out: Vec<(Monomial, Rational)> = Vec::with_capacity(terms.len());
        for (m, c) in terms {
            match out.last_mut() {
                Some(last) if last.0 == m => last.1 = sum(last.1, c),
                _ => {
                    if out.last().is_some_and(|l| l.1.is_zero()) {
                        out.pop();
                    }
                    out.push((m, c));
                }
            }
        }
        if out.last().is_some_and(|l| l.1.is_zero()) {
            out.pop();
        }
        Poly { terms: out }
    }

    /// Zero.
    pub fn zero() -> Poly {
        Poly::default()
    }

    /// A constant.
    pub fn constant(c: Rational) -> Poly {
        Poly::term(Monomial::one(), c)
    }

    /// A single atom.
    pub fn atom(a: Atom) -> Poly {
        Poly::term(Monomial::atom(a), Rational::ONE)
    }

    /// `c · m`.
    pub fn term(m: Monomial, c: Rational) -> Poly {
        if c.is_zero() {
            return Poly::zero();
        }
        Poly {
            terms: vec![(m, c)],
        }
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
        match self.terms.as_slice() {
            [] => Some(Rational::ZERO),
            [(m, c)] if m.is_one() => Some(*c),
            _ => None,
        }
    }

    /// `self + s·o` with `s = ±1`, by merging.
    fn merge(&self, o: &Poly, negate: bool) -> Poly {
        let sign = |c: Rational| if negate { -c } else { c };
        let mut out = Vec::with_capacity(self.terms.len() + o.terms.len());
        let (mut i, mut j) = (0, 0);
        while i < self.terms.len() && j < o.terms.len() {
            let (a, b) = (&self.terms[i], &o.terms[j]);
            match a.0.cmp(&b.0) {
                std::cmp::Ordering::Less => {
                    out.push(a.clone());
                    i += 1;
                }
                std::cmp::Ordering::Greater => {
                    out.push((b.0.clone(), sign(b.1)));
                    j += 1;
                }
                std::cmp::Ordering::Equal => {
                    let c = sum(a.1, sign(b.1));
                    if !c.is_zero() {
                        out.push((a.0.clone(), c));
                    }
                    i += 1;
                    j += 1;
                }
            }
        }
        out.extend_from_slice(&self.terms[i..]);
        out.extend(o.terms[j..].iter().map(|(m, c)| (m.clone(), sign(*c))));
        Poly { terms: out }
    }

    /// `self + o`.
    pub fn add(&self, o: &Poly) -> Poly {
        if o.is_zero() {
            return self.clone();
        }
        if self.is_zero() {
            return o.clone();
        }
        self.merge(o, false)
    }

    /// `self − o`.
    pub fn sub(&self, o: &Poly) -> Poly {
        if o.is_zero() {
            return self.clone();
        }
        self.merge(o, true)
    }

    /// `−self`.
    pub fn neg(&self) -> Poly {
        Poly {
            terms: self.terms.iter().map(|(m, c)| (m.clone(), -*c)).collect(),
        }
    }

    /// `c · self`.
    pub fn scale(&self, c: Rational) -> Poly {
        if c.is_zero() {
            return Poly::zero();
        }
        if c.is_one() {
            return self.clone();
        }
        if (-c).is_one() {
            return self.neg();
        }
        Poly {
            terms: self
                .terms
                .iter()
                .map(|(m, x)| (m.clone(), product(*x, c)))
                .collect(),
        }
    }

    /// `self · o`, not yet reduced modulo `sin² + cos² = 1`.
    pub fn mul(&self, o: &Poly) -> Poly {
        let mut out = Vec::with_capacity(self.terms.len() * o.terms.len());
        for (ma, ca) in &self.terms {
            for (mb, cb) in &o.terms {
                out.push((ma.mul(mb), product(*ca, *cb)));
            }
        }
        Poly::from_terms(out)
    }

    /// Rewrites every `cos²` as `1 − sin²` for each `(sin, cos)` atom pair, giving the canonical
    /// form.
    pub fn reduce(&self, trig_pairs: &[(Atom, Atom)]) -> Poly {
        let mut terms = self.terms.clone();
        for &(s, c) in trig_pairs {
            if !terms.iter().any(|(m, _)| m.exponent(c) >= 2) {
                continue;
            }
            let mut next = Vec::with_capacity(terms.len());
            for (m, k) in terms {
                let e = m.exponent(c);
                if e < 2 {
                    next.push((m, k));
                    continue;
                }
                // rest · cos^(2j) = rest · (1 − sin²)^j = Σ_i C(j, i) (−1)^i rest · sin^(2i)
                let j = e / 2;
                let rest = m.divide(c, 2 * j);
                let mut binomial: i64 = 1;
                for i in 0..=j {
                    let sign = if i % 2 == 0 { 1 } else { -1 };
                    let power = if i == 0 {
                        rest.clone()
                    } else {
                        rest.mul(&Monomial::new(&[(s, 2 * i)]))
                    };
                    next.push((power, product(k, Rational::int(sign * binomial))));
                    binomial = binomial * i64::from(j - i) / i64::from(i + 1);
                }
            }
            terms = next;
        }
        Poly::from_terms(terms)
    }

    /// Rewrites every `√p²` as `p` for each `(atom, p)` rule ([`crate::atoms::AtomTable::root_rules`]).
    pub fn reduce_roots(&self, rules: &[(Atom, u64)]) -> Poly {
        if rules.is_empty() {
            return self.clone();
        }
        let mut out = Vec::with_capacity(self.terms.len());
        for (m, c) in &self.terms {
            let mut coeff = *c;
            let mut mono = m.clone();
            for &(a, p) in rules {
                let e = mono.exponent(a);
                if e >= 2 {
                    mono = mono.divide(a, e - e % 2);
                    for _ in 0..e / 2 {
                        coeff = product(coeff, Rational::int(p as i64));
                    }
                }
            }
            out.push((mono, coeff));
        }
        Poly::from_terms(out)
    }

    /// The canonical form: [`Poly::reduce`] and [`Poly::reduce_roots`], without copying a
    /// polynomial that has no `cos²` and no `√p²` to rewrite (a product of factors in different
    /// axes, the common case).
    pub fn canonical(self, trig_pairs: &[(Atom, Atom)], roots: &[(Atom, u64)]) -> Poly {
        let reducible =
            |a: Atom| trig_pairs.iter().any(|&(_, c)| c == a) || roots.iter().any(|&(r, _)| r == a);
        let needed = self
            .terms
            .iter()
            .any(|(m, _)| m.factors().iter().any(|&(a, e)| e >= 2 && reducible(a)));
        if needed {
            self.reduce(trig_pairs).reduce_roots(roots)
        } else {
            self
        }
    }

    /// The value at `atoms[a]` for every atom `a`.
    pub fn eval(&self, atoms: &[f64]) -> f64 {
        self.terms
            .iter()
            .map(|(m, c)| {
                m.factors().iter().fold(c.to_f64(), |acc, &(a, e)| {
                    acc * atoms[a as usize].powi(e as i32)
                })
            })
            .sum()
    }

    /// The atoms that occur, ascending.
    pub fn atoms(&self) -> Vec<Atom> {
        let mut v: Vec<Atom> = self
            .terms
            .iter()
            .flat_map(|(m, _)| m.factors().iter().map(|&(a, _)| a))
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Splits into `(q, r)` with `self = a · q + r`, where `r` has no term containing `a`.
    pub fn split_by(&self, a: Atom) -> (Poly, Poly) {
        let (mut q, mut r) = (Vec::new(), Vec::new());
        for (m, c) in &self.terms {
            if m.exponent(a) > 0 {
                q.push((m.divide(a, 1), *c));
            } else {
                r.push((m.clone(), *c));
            }
        }
        // Dividing by `a` can change the order of the quotient's monomials; the rest keeps it.
        (Poly::from_terms(q), Poly { terms: r })
    }

    /// The coefficient of the first term (canonical order), or zero.
    pub fn leading_coefficient(&self) -> Rational {
        self.terms.first().map_or(Rational::ZERO, |t| t.1)
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
