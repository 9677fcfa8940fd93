//! Is a gain over intermediates identically zero? A polynomial identity test in a prime field.
//!
//! A gain that mentions intermediates is a small polynomial over named quantities; it can
//! vanish as a function of the pose and the kinematic parameters although it is not the zero
//! polynomial over those names (a product of two entries of one partial rotation hides
//! `sin² + cos² = 1`). Such a gain must be an exact zero in the compiled program, not a float
//! of 1e-17: identifiability reads exact zero columns of H.
//!
//! The test evaluates the gain exactly, modulo a prime `q` near 2⁶², at two pseudo-random
//! points that satisfy every relation of the canonical form: for each rotary axis
//! `(sin, cos) = (2t/(1+t²), (1−t²)/(1+t²))` with `t` random (so `sin² + cos² = 1`), for each
//! `√p` a square root of `p` modulo `q` (`q` is chosen so that one exists), every other atom
//! (commands, kinematic parameters, numeric frame entries) random. A gain that is zero in the
//! canonical form's algebra is zero at every such point. A gain that is not is a non-zero
//! rational function of degree `d` (a few hundred at most) in the random numbers, which
//! vanishes at a random point with probability at most `d/q` (Schwartz–Zippel): below 10⁻¹⁶
//! per point, 10⁻³² for both. A non-zero value proves the gain is not zero, so the test can
//! only err by declaring zero a gain that is not, with that probability. The points are fixed
//! (a seeded generator): the result is deterministic.

use crate::atoms::{AtomKind, AtomTable};
use crate::hash::FxHashMap;
use crate::intermediates::Intermediates;
use crate::poly::Poly;
use crate::rational::Rational;
use std::cell::RefCell;

/// Arithmetic modulo an odd prime `q` below 2⁶³, in Montgomery form (`a` is held as
/// `a·2⁶⁴ mod q`), so that a product needs no division. Zero is zero in either form.
#[derive(Clone, Copy, Debug)]
struct Field {
    q: u64,
    /// `−q⁻¹ mod 2⁶⁴`.
    q_neg_inv: u64,
    /// `2¹²⁸ mod q`, to bring a number into Montgomery form.
    r2: u64,
    /// One, in Montgomery form (`2⁶⁴ mod q`).
    one: u64,
}

impl Field {
    fn new(q: u64) -> Field {
        let mut inv: u64 = 1;
        for _ in 0..6 {
            inv = inv.wrapping_mul(2u64.wrapping_sub(q.wrapping_mul(inv)));
        }
        let r = (u128::from(u64::MAX) % u128::from(q) + 1) % u128::from(q);
        let r2 = (r * r % u128::from(q)) as u64;
        Field {
            q,
            q_neg_inv: inv.wrapping_neg(),
            r2,
            one: r as u64,
        }
    }

    /// `t · 2⁻⁶⁴ mod q` for `t < q·2⁶⁴`.
    fn redc(self, t: u128) -> u64 {
        let m = (t as u64).wrapping_mul(self.q_neg_inv);
        let u = ((t + u128::from(m) * u128::from(self.q)) >> 64) as u64;
        if u >= self.q { u - self.q } else { u }
    }

    fn mul(self, a: u64, b: u64) -> u64 {
        self.redc(u128::from(a) * u128::from(b))
    }

    fn add(self, a: u64, b: u64) -> u64 {
        let s = a + b;
        if s >= self.q { s - self.q } else { s }
    }

    fn sub(self, a: u64, b: u64) -> u64 {
        if a >= b { a - b } else { a + self.q - b }
    }

    fn pow(self, mut a: u64, mut e: u64) -> u64 {
        let mut r = self.one;
        while e > 0 {
            if e & 1 == 1 {
                r = self.mul(r, a);
            }
            a = self.mul(a, a);
            e >>= 1;
        }
        r
    }

    /// `1/a`, `None` for zero.
    fn inv(self, a: u64) -> Option<u64> {
        (a != 0).then(|| self.pow(a, self.q - 2))
    }

    /// A non-negative integer below `q`, into Montgomery form.
    fn element(self, n: u64) -> u64 {
        self.mul(n % self.q, self.r2)
    }

    /// A random element.
    fn random(self, rng: &mut SplitMix) -> u64 {
        self.element(rng.next())
    }

    fn int(self, n: i128) -> u64 {
        let magnitude = match u64::try_from(n.unsigned_abs()) {
            Ok(m) => m % self.q,
            Err(_) => (n.unsigned_abs() % u128::from(self.q)) as u64,
        };
        let x = self.element(magnitude);
        if n < 0 { self.sub(0, x) } else { x }
    }

    /// A rational coefficient, `None` when its denominator is a multiple of `q`.
    fn rational(self, c: Rational) -> Option<u64> {
        if c.is_one() {
            return Some(self.one);
        }
        let n = self.int(c.numer());
        if c.denom() == 1 {
            return Some(n);
        }
        Some(self.mul(n, self.inv(self.int(c.denom()))?))
    }
}

/// `a·b mod n` (for the primality test only; the field arithmetic avoids the division).
fn mul_mod(a: u64, b: u64, n: u64) -> u64 {
    (u128::from(a) * u128::from(b) % u128::from(n)) as u64
}

fn pow_mod(mut a: u64, mut e: u64, n: u64) -> u64 {
    let mut r = 1 % n;
    a %= n;
    while e > 0 {
        if e & 1 == 1 {
            r = mul_mod(r, a, n);
        }
        a = mul_mod(a, a, n);
        e >>= 1;
    }
    r
}

/// Deterministic primality for `u64` (Miller–Rabin with the first twelve primes as bases).
fn is_prime(n: u64) -> bool {
    const BASES: [u64; 12] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37];
    if n < 2 {
        return false;
    }
    for p in BASES {
        if n.is_multiple_of(p) {
            return n == p;
        }
    }
    let (mut d, mut s) = (n - 1, 0);
    while d.is_multiple_of(2) {
        d /= 2;
        s += 1;
    }
    'bases: for a in BASES {
        let mut x = pow_mod(a, d, n);
        if x == 1 || x == n - 1 {
            continue;
        }
        for _ in 1..s {
            x = mul_mod(x, x, n);
            if x == n - 1 {
                continue 'bases;
            }
        }
        return false;
    }
    true
}

/// The largest prime `q < 2⁶²` with `q ≡ 3 (mod 4)` modulo which every `p` of `roots` is a
/// square (then `p^((q+1)/4)` is its square root).
fn field_for(roots: &[u64]) -> Field {
    let mut q = (1u64 << 62) - 1; // ≡ 3 (mod 4)
    loop {
        if is_prime(q)
            && roots
                .iter()
                .all(|&p| p % q != 0 && pow_mod(p, (q - 1) / 2, q) == 1)
        {
            return Field::new(q);
        }
        q -= 4;
    }
}

/// SplitMix64: the fixed pseudo-random points.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

/// The values of every atom and intermediate at one point, `None` where a coefficient's
/// denominator is a multiple of `q` (then the test abstains).
fn point(
    f: Field,
    atoms: &AtomTable,
    inter: &Intermediates,
    rng: &mut SplitMix,
    known: &Coefficients,
) -> Option<Vec<u64>> {
    let mut v = vec![0u64; atoms.kinds.len()];
    for (i, k) in atoms.kinds.iter().enumerate() {
        v[i] = match *k {
            AtomKind::Sin(a) => {
                let (s, c) = circle(f, rng);
                let cos = atoms.find(AtomKind::Cos(a));
                v[usize::from(cos)] = c;
                s
            }
            AtomKind::Cos(_) => continue,
            AtomKind::Root(p) => f.element(pow_mod(p, (f.q + 1) / 4, f.q)),
            AtomKind::Command(_) | AtomKind::Symbol(_) | AtomKind::Constant(_) => f.random(rng),
        };
    }
    for d in inter.definitions() {
        let x = eval(f, d, &v, known)?;
        v.push(x);
    }
    Some(v)
}

/// A random point of the unit circle modulo `q`: `(2t, 1 − t²) / (1 + t²)`.
fn circle(f: Field, rng: &mut SplitMix) -> (u64, u64) {
    loop {
        let t = f.random(rng);
        let t2 = f.mul(t, t);
        if let Some(d) = f.inv(f.add(f.one, t2)) {
            let two_t = f.add(t, t);
            return (f.mul(two_t, d), f.mul(f.sub(f.one, t2), d));
        }
    }
}

/// The field elements of the rational coefficients met so far (an inverse costs some hundred
/// multiplications, and few denominators recur).
type Coefficients = RefCell<FxHashMap<Rational, Option<u64>>>;

fn coefficient(f: Field, c: Rational, known: &Coefficients) -> Option<u64> {
    if c.denom() == 1 && i64::try_from(c.numer()).is_ok() {
        return f.rational(c);
    }
    *known.borrow_mut().entry(c).or_insert_with(|| f.rational(c))
}

fn eval(f: Field, p: &Poly, values: &[u64], known: &Coefficients) -> Option<u64> {
    let mut sum = 0;
    for (m, c) in p.terms() {
        let mut t = coefficient(f, c, known)?;
        for &(a, e) in m.factors() {
            let v = values[usize::from(a)];
            t = f.mul(t, if e == 1 { v } else { f.pow(v, u64::from(e)) });
        }
        sum = f.add(sum, t);
    }
    Some(sum)
}

/// The identity test of the polynomials over the atoms and intermediates of one model.
#[derive(Debug)]
pub struct ZeroTest<'a> {
    field: Field,
    atoms: &'a AtomTable,
    inter: &'a Intermediates,
    /// The values at the first point.
    first: Vec<u64>,
    /// The generator's state after the first point.
    rng: u64,
    /// The values at the second point, computed when a polynomial first vanishes at the first
    /// (a non-zero value already proves a polynomial non-zero).
    second: std::cell::OnceCell<Option<Vec<u64>>>,
    known: Coefficients,
}

impl<'a> ZeroTest<'a> {
    /// The test for the atoms `atoms` and the intermediates `inter`; `None` when a definition
    /// cannot be evaluated modulo the prime (a coefficient's denominator is a multiple of it:
    /// never for the numbers of a machine description).
    pub fn new(atoms: &'a AtomTable, inter: &'a Intermediates) -> Option<ZeroTest<'a>> {
        let roots: Vec<u64> = atoms.root_rules().iter().map(|&(_, p)| p).collect();
        let field = field_for(&roots);
        let mut rng = SplitMix(0x5eed_0f2e_207e_5700);
        let known = Coefficients::default();
        let first = point(field, atoms, inter, &mut rng, &known)?;
        Some(ZeroTest {
            known,
            field,
            atoms,
            inter,
            first,
            rng: rng.0,
            second: std::cell::OnceCell::new(),
        })
    }

    /// `true` when `p` (over the atoms and intermediates) is identically zero, to the
    /// probability the module documents; `false` when it is not, or cannot be evaluated.
    pub fn vanishes(&self, p: &Poly) -> bool {
        if eval(self.field, p, &self.first, &self.known) != Some(0) {
            return false;
        }
        let second = self.second.get_or_init(|| {
            let mut rng = SplitMix(self.rng);
            point(self.field, self.atoms, self.inter, &mut rng, &self.known)
        });
        second
            .as_ref()
            .is_some_and(|v| eval(self.field, p, v, &self.known) == Some(0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primes_and_square_roots() {
        assert!(is_prime((1u64 << 61) - 1));
        assert!(!is_prime((1u64 << 62) - 1));
        assert!(!is_prime(3_215_031_751)); // a strong pseudoprime to bases 2, 3, 5, 7
        let f = field_for(&[2, 3, 5, 7]);
        assert_eq!(f.q % 4, 3);
        assert!(is_prime(f.q));
        for p in [2, 3, 5, 7] {
            let r = pow_mod(p, (f.q + 1) / 4, f.q);
            assert_eq!(mul_mod(r, r, f.q), p);
        }
        let half = f.rational(Rational::new(1, 2)).unwrap();
        assert_eq!(f.mul(half, f.element(2)), f.one);
        let minus_three = f.rational(Rational::new(-3, 1)).unwrap();
        assert_eq!(f.add(minus_three, f.element(3)), 0);
        assert_eq!(f.redc(u128::from(f.element(12345))), 12345);
    }

    #[test]
    fn identities_hidden_in_intermediates_are_found() {
        use crate::intermediates::{DeriveOptions, Namer};
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let atoms = AtomTable::new(&m);
        let atom = |k| Poly::atom(atoms.find(k));
        let (sa, ca) = (atom(AtomKind::Sin(1)), atom(AtomKind::Cos(1)));
        let (x, y) = (atom(AtomKind::Symbol(0)), atom(AtomKind::Symbol(1)));
        let mut namer = Namer::new(&atoms, DeriveOptions { max_terms: 1 });
        // u = Sa·x + Ca·y and v = Ca·x − Sa·y, named: u² + v² − x² − y² vanishes by
        // sin² + cos² = 1, which the names hide.
        let u = namer.keep(sa.mul(&x).add(&ca.mul(&y)));
        let v = namer.keep(ca.mul(&x).sub(&sa.mul(&y)));
        let inter = namer.finish();
        assert_eq!(inter.len(), 2);
        let test = ZeroTest::new(&atoms, &inter).unwrap();
        let squares = u.mul(&u).add(&v.mul(&v));
        let hidden = squares.sub(&x.mul(&x)).sub(&y.mul(&y));
        assert!(!hidden.is_zero() && test.vanishes(&hidden));
        assert!(!test.vanishes(&squares.sub(&x.mul(&x))));
        assert!(!test.vanishes(&u.sub(&v)));
    }

    #[test]
    fn points_lie_on_the_unit_circle() {
        let f = field_for(&[]);
        let mut rng = SplitMix(1);
        for _ in 0..100 {
            let (s, c) = circle(f, &mut rng);
            assert_eq!(f.add(f.mul(s, s), f.mul(c, c)), f.one);
        }
    }
}
