//! The atoms of a machine's formulas: for every rotary axis the sine and cosine of its command,
//! for every linear axis its command (mm), and every kinematic symbol (mm). Their order is the
//! order of terms in tables and of inputs in generated code. A machine with inclined axes adds
//! constant atoms after them: the square root of each prime its exact directions need (`√2`,
//! reduced by `√p² = p`), and each numeric frame entry that has no exact form. Constant atoms
//! are no inputs: generated code holds their values.

use crate::poly::{Atom, Poly};
use crate::rational::Rational;
use model_spec::surd::Real;
use model_spec::{AxisId, AxisKind, Machine, SymbolId};

/// What an atom stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AtomKind {
    /// Sine of a rotary command.
    Sin(AxisId),
    /// Cosine of a rotary command.
    Cos(AxisId),
    /// A linear command, mm.
    Command(AxisId),
    /// A kinematic symbol, mm.
    Symbol(SymbolId),
    /// The square root of a prime (inclined axes with exact directions).
    Root(u64),
    /// A numeric constant (a frame entry of an inclined axis with no exact form), by its bits.
    Constant(u64),
}

impl AtomKind {
    /// The value of a constant atom, `None` for pose atoms and kinematic symbols.
    pub fn constant_value(self) -> Option<f64> {
        match self {
            AtomKind::Root(p) => Some((p as f64).sqrt()),
            AtomKind::Constant(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }
}

/// The primes of a square-free radicand, ascending (trial division; radicands of exact
/// directions have small prime factors or one large cofactor).
pub fn primes_of(mut n: u64) -> Vec<u64> {
    let mut out = Vec::new();
    let mut p = 2u64;
    while p.saturating_mul(p) <= n {
        if n.is_multiple_of(p) {
            out.push(p);
            n /= p;
        } else {
            p += if p == 2 { 1 } else { 2 };
        }
    }
    if n > 1 {
        out.push(n);
    }
    out
}

/// The constant atoms the inclined axes of `m` need, in a fixed order: roots by prime, then
/// numeric constants in order of appearance.
fn constant_atoms(m: &Machine) -> Vec<AtomKind> {
    let mut roots = Vec::new();
    let mut numeric = Vec::new();
    for a in &m.axes {
        let Some(inclined) = &a.direction.inclined else {
            continue;
        };
        for r in inclined.frame.axes.iter().flatten() {
            match *r {
                Real::Surd { radicand, .. } => roots.extend(primes_of(radicand)),
                Real::Numeric(x) => {
                    let k = AtomKind::Constant(x.abs().to_bits());
                    if x != 0.0 && !numeric.contains(&k) {
                        numeric.push(k);
                    }
                }
            }
        }
    }
    roots.sort_unstable();
    roots.dedup();
    roots
        .into_iter()
        .map(AtomKind::Root)
        .chain(numeric)
        .collect()
}

/// The atoms of one machine, with their names for people and for code.
#[derive(Clone, Debug, PartialEq)]
pub struct AtomTable {
    /// The atoms, in order.
    pub kinds: Vec<AtomKind>,
    /// Names in formulas, the seed's style: `Sa`, `Ca`, `Xm`, `Xw`.
    pub names: Vec<String>,
    /// Names in LaTeX: `S_a`, `C_a`, `X_m`, `X_{w}`.
    pub latex: Vec<String>,
}

fn latex_symbol(name: &str) -> String {
    let mut chars = name.chars();
    match chars.next() {
        Some(first) if name.len() > 1 => format!("{first}_{{{}}}", chars.as_str()),
        _ => name.to_string(),
    }
}

impl AtomTable {
    /// The atoms of `m`: sin/cos of the rotary axes, linear commands, then kinematic symbols.
    pub fn new(m: &Machine) -> AtomTable {
        let mut kinds = Vec::new();
        for i in m.rotary_axes() {
            kinds.push(AtomKind::Sin(i));
            kinds.push(AtomKind::Cos(i));
        }
        for i in m.linear_axes() {
            kinds.push(AtomKind::Command(i));
        }
        for s in 0..m.symbols.len() {
            kinds.push(AtomKind::Symbol(s));
        }
        kinds.extend(constant_atoms(m));
        let mut numbered = 0;
        let mut constant_name = |k: &AtomKind, latex: bool| match *k {
            AtomKind::Root(p) if latex => format!("\\sqrt{{{p}}}"),
            AtomKind::Root(p) => format!("√{p}"),
            _ => {
                numbered += 1;
                format!("k{}", numbered)
            }
        };
        let names = kinds
            .iter()
            .map(|k| match *k {
                AtomKind::Sin(a) => format!("S{}", m.axes[a].name.to_ascii_lowercase()),
                AtomKind::Cos(a) => format!("C{}", m.axes[a].name.to_ascii_lowercase()),
                AtomKind::Command(a) => format!("{}m", m.axes[a].name),
                AtomKind::Symbol(s) => m.symbols[s].name.clone(),
                AtomKind::Root(_) | AtomKind::Constant(_) => constant_name(k, false),
            })
            .collect();
        let latex = kinds
            .iter()
            .map(|k| match *k {
                AtomKind::Sin(a) => format!("S_{}", m.axes[a].name.to_ascii_lowercase()),
                AtomKind::Cos(a) => format!("C_{}", m.axes[a].name.to_ascii_lowercase()),
                AtomKind::Command(a) => format!("{}_m", m.axes[a].name),
                AtomKind::Symbol(s) => latex_symbol(&m.symbols[s].name),
                AtomKind::Root(_) | AtomKind::Constant(_) => constant_name(k, true),
            })
            .collect();
        debug_assert!(
            m.axes
                .iter()
                .all(|a| a.kind == AxisKind::Linear || a.kind == AxisKind::Rotary)
        );
        AtomTable {
            kinds,
            names,
            latex,
        }
    }

    /// The atom of `kind`.
    pub fn find(&self, kind: AtomKind) -> Atom {
        self.kinds
            .iter()
            .position(|&k| k == kind)
            .expect("every axis and symbol has its atoms") as Atom
    }

    /// `(sin, cos)` atom pairs of the rotary axes, for the canonical reduction.
    pub fn trig_pairs(&self) -> Vec<(Atom, Atom)> {
        self.kinds
            .iter()
            .enumerate()
            .filter_map(|(i, k)| match k {
                AtomKind::Sin(a) => Some((i as Atom, self.find(AtomKind::Cos(*a)))),
                _ => None,
            })
            .collect()
    }

    /// The number of pose atoms: sines and cosines of the rotary commands and the linear
    /// commands, which come before the kinematic symbols.
    pub fn pose_count(&self) -> usize {
        self.kinds
            .iter()
            .take_while(|k| !matches!(k, AtomKind::Symbol(_)))
            .count()
    }

    /// Writes the values of the pose atoms at `commands` (per axis: linear mm, rotary rad)
    /// into the first [`AtomTable::pose_count`] entries of `out`, in atom order; the kinematic
    /// symbols after them are left as they are.
    pub fn fill_pose(&self, commands: &[f64], out: &mut [f64]) {
        for (v, k) in out.iter_mut().zip(&self.kinds) {
            *v = match *k {
                AtomKind::Sin(a) => commands[a].sin(),
                AtomKind::Cos(a) => commands[a].cos(),
                AtomKind::Command(a) => commands[a],
                AtomKind::Symbol(_) | AtomKind::Root(_) | AtomKind::Constant(_) => break,
            };
        }
    }

    /// Numeric values of the input atoms at a pose, in the order of a compiled program's
    /// inputs: `commands` per axis (linear mm, rotary rad), then `params` per kinematic symbol
    /// (mm).
    pub fn values(&self, commands: &[f64], params: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.pose_count()];
        self.fill_pose(commands, &mut out);
        out.extend_from_slice(params);
        out
    }

    /// Numeric values of every atom, for evaluating polynomials: [`AtomTable::values`] followed
    /// by the constant atoms.
    pub fn all_values(&self, commands: &[f64], params: &[f64]) -> Vec<f64> {
        let mut out = self.values(commands, params);
        out.extend(self.kinds.iter().filter_map(|k| k.constant_value()));
        out
    }

    /// `(atom, p)` for every `√p` atom: the rule `√p² = p` of the canonical form.
    pub fn root_rules(&self) -> Vec<(Atom, u64)> {
        self.kinds
            .iter()
            .enumerate()
            .filter_map(|(i, k)| match *k {
                AtomKind::Root(p) => Some((i as Atom, p)),
                _ => None,
            })
            .collect()
    }

    /// The number of atoms that are inputs of generated code (pose atoms and kinematic
    /// symbols); the constant atoms come after them.
    pub fn input_count(&self) -> usize {
        self.kinds
            .iter()
            .take_while(|k| k.constant_value().is_none())
            .count()
    }

    /// The polynomial of an exact or numeric frame entry of an inclined axis, in this table's
    /// atoms.
    pub fn real(&self, r: Real) -> Poly {
        match r {
            Real::Surd { num, den, radicand } => primes_of(radicand).into_iter().fold(
                Poly::constant(Rational::new(num as i128, den as i128)),
                |acc, p| acc.mul(&Poly::atom(self.find(AtomKind::Root(p)))),
            ),
            Real::Numeric(0.0) => Poly::zero(),
            Real::Numeric(x) => {
                let atom = Poly::atom(self.find(AtomKind::Constant(x.abs().to_bits())));
                if x < 0.0 { atom.neg() } else { atom }
            }
        }
    }
}
