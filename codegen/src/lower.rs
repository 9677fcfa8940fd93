//! From canonical polynomials to the straight-line IR, with common subexpressions shared.
//!
//! Each polynomial is written in multivariate Horner form: split off the atom that occurs in the
//! most terms (ties: the first atom), `p = a·q + r`, and recurse on `q` and `r`. Every
//! polynomial met on the way is memoised up to a constant factor (its leading coefficient is
//! taken out, so `p` and `−p` and `2p` share one value), and every instruction is hash-consed
//! (operands of `+` and `×` sorted), so a sub-polynomial that occurs in many gains — the
//! position of the ball in a rotated frame, say — is computed once. Signs are carried as flags
//! and folded into `+`/`−`, so negations are rare. The result is deterministic: the same model
//! always gives the same program.

use crate::atoms::{AtomKind, AtomTable};
use crate::derive::GainModel;
use crate::hash::FxHashMap;
use crate::intermediates::Intermediates;
use crate::ir::{Input, Op, Output, Program, Var};
pub use crate::parts::{MAX_INSTRUCTIONS, Part, compile_parts};
use crate::poly::{Atom, Monomial, Poly};
use crate::rational::Rational;
use model_spec::Machine;

/// A value up to sign: `(var, negated)`.
pub(crate) type Signed = (Var, bool);

/// Builds one program: hash-consed instructions, polynomials memoised up to a constant factor.
pub(crate) struct Builder {
    ops: Vec<Op>,
    interned: FxHashMap<Op, Var>,
    memo: FxHashMap<Poly, Signed>,
    /// The value each atom of the polynomials stands for.
    pub(crate) atom_vars: Vec<Var>,
    /// The intermediates the polynomials may mention (atoms from `intermediates.first()`).
    intermediates: Intermediates,
    /// The value of each intermediate, once lowered.
    intermediate_vars: Vec<Option<Signed>>,
}

impl Builder {
    /// An empty program whose polynomials will read their atoms from `atom_vars` (set it once
    /// the inputs are pushed) and mention no intermediates.
    pub(crate) fn new() -> Builder {
        Builder::with(Intermediates::default())
    }

    /// An empty program whose polynomials may mention `intermediates`: each is lowered from
    /// its definition the first time a polynomial needs it.
    fn with(intermediates: Intermediates) -> Builder {
        Builder {
            ops: Vec::new(),
            interned: FxHashMap::default(),
            memo: FxHashMap::default(),
            atom_vars: Vec::new(),
            intermediate_vars: vec![None; intermediates.len()],
            intermediates,
        }
    }

    /// The value of atom `a`: an input, a constant, or an intermediate (lowered now, with the
    /// intermediates its definition needs, if it was not yet).
    fn atom(&mut self, a: Atom) -> Signed {
        let first = self.intermediates.first();
        if self.intermediates.is_empty() || a < first {
            return (self.atom_vars[usize::from(a)], false);
        }
        let k = usize::from(a - first);
        if let Some(v) = self.intermediate_vars[k] {
            return v;
        }
        // Every definition needed, found without recursion, then lowered in index order (a
        // definition mentions only earlier intermediates).
        let mut needed = std::collections::BTreeSet::from([k]);
        let mut stack = vec![k];
        while let Some(j) = stack.pop() {
            for b in self.intermediates.definitions()[j].atoms() {
                if b >= first {
                    let i = usize::from(b - first);
                    if self.intermediate_vars[i].is_none() && needed.insert(i) {
                        stack.push(i);
                    }
                }
            }
        }
        for j in needed {
            let definition = self.intermediates.definitions()[j].clone();
            let v = self.poly(&definition);
            self.intermediate_vars[j] = Some(v);
        }
        self.intermediate_vars[k].expect("just lowered")
    }

    /// Appends (or finds) an instruction.
    pub(crate) fn push(&mut self, op: Op) -> Var {
        let op = match op {
            Op::Add(a, b) if a > b => Op::Add(b, a),
            Op::Mul(a, b) if a > b => Op::Mul(b, a),
            other => other,
        };
        if let Some(&v) = self.interned.get(&op) {
            return v;
        }
        let v = self.ops.len() as Var;
        self.ops.push(op);
        self.interned.insert(op, v);
        v
    }

    pub(crate) fn constant(&mut self, c: f64) -> Var {
        self.push(Op::Const(c.to_bits()))
    }

    /// `x + y` for signed values.
    fn add(&mut self, x: Signed, y: Signed) -> Signed {
        match (x.1, y.1) {
            (false, false) => (self.push(Op::Add(x.0, y.0)), false),
            (true, true) => (self.push(Op::Add(x.0, y.0)), true),
            (false, true) => (self.push(Op::Sub(x.0, y.0)), false),
            (true, false) => (self.push(Op::Sub(y.0, x.0)), false),
        }
    }

    fn mul(&mut self, x: Signed, y: Signed) -> Signed {
        (self.push(Op::Mul(x.0, y.0)), x.1 ^ y.1)
    }

    /// `c · v` for a rational `c ≠ 0`.
    fn scale(&mut self, c: Rational, v: Signed) -> Signed {
        if c.abs().is_one() {
            return (v.0, v.1 ^ c.is_negative());
        }
        let k = self.constant(c.abs().to_f64());
        (self.push(Op::Mul(k, v.0)), v.1 ^ c.is_negative())
    }

    fn monomial(&mut self, m: &Monomial) -> Signed {
        // Powers by repeated multiplication, then the product left to right in atom order.
        let mut acc: Option<Signed> = None;
        for &(a, e) in m.factors() {
            let base = self.atom(a);
            let mut p = base;
            for _ in 1..e {
                p = self.mul(p, base);
            }
            acc = Some(match acc {
                None => p,
                Some(x) => self.mul(x, p),
            });
        }
        acc.unwrap_or_else(|| (self.constant(1.0), false))
    }

    /// The value of a non-zero polynomial.
    pub(crate) fn poly(&mut self, p: &Poly) -> Signed {
        let lead = p.leading_coefficient();
        if lead.is_one() {
            return self.unit(p);
        }
        let unit = p.scale(Rational::new(lead.denom(), lead.numer()));
        let v = self.unit(&unit);
        self.scale(lead, v)
    }

    /// The value of a polynomial whose leading coefficient is 1, memoised.
    fn unit(&mut self, p: &Poly) -> Signed {
        if let Some(&v) = self.memo.get(p) {
            return v;
        }
        let v = self.unit_poly(p);
        self.memo.insert(p.clone(), v);
        v
    }

    /// The value of a polynomial whose leading coefficient is 1.
    fn unit_poly(&mut self, p: &Poly) -> Signed {
        if p.len() == 1 {
            let (m, _) = p.terms().next().expect("one term");
            return self.monomial(m);
        }
        let atom = best_atom(p);
        let (q, r) = p.split_by(atom);
        let a = self.atom(atom);
        let aq = match q.as_constant() {
            Some(c) => self.scale(c, a),
            None => {
                let qv = self.poly(&q);
                self.mul(a, qv)
            }
        };
        if r.is_zero() {
            aq
        } else {
            let rv = self.poly(&r);
            self.add(aq, rv)
        }
    }
}

/// The value of every atom: an input for pose atoms and kinematic symbols, a constant for the
/// constant atoms of inclined axes.
pub(crate) fn atom_vars(b: &mut Builder, atoms: &AtomTable) -> Vec<Var> {
    let inputs = atoms.input_count();
    atoms
        .kinds
        .iter()
        .enumerate()
        .map(|(i, k)| match k.constant_value() {
            Some(c) => b.constant(c),
            None if i < inputs => b.push(Op::Input(i as u32)),
            None => unreachable!("constant atoms come after the inputs"),
        })
        .collect()
}

/// The atom that occurs in the most terms (the first such atom on a tie).
fn best_atom(p: &Poly) -> Atom {
    let mut counts: Vec<(Atom, usize)> = Vec::new();
    for (m, _) in p.terms() {
        for &(a, _) in m.factors() {
            match counts.iter_mut().find(|(x, _)| *x == a) {
                Some((_, n)) => *n += 1,
                None => counts.push((a, 1)),
            }
        }
    }
    counts
        .into_iter()
        .min_by(|x, y| y.1.cmp(&x.1).then(x.0.cmp(&y.0)))
        .expect("a polynomial of several terms has atoms")
        .0
}

/// The input descriptions of a machine's programs, in atom order: sines and cosines of the
/// rotary commands, linear commands (mm), kinematic parameters (mm).
pub fn inputs(m: &Machine, model: &GainModel) -> Vec<Input> {
    inputs_of(m, &model.atoms)
}

/// The input descriptions of the atoms `atoms` of `m`, in order.
pub(crate) fn inputs_of(m: &Machine, atoms: &AtomTable) -> Vec<Input> {
    atoms
        .kinds
        .iter()
        .zip(&atoms.names)
        .take(atoms.input_count())
        .map(|(k, name)| {
            let (field, parameter) = match *k {
                AtomKind::Sin(a) => (
                    format!("sin_{}", m.axes[a].name.to_ascii_lowercase()),
                    false,
                ),
                AtomKind::Cos(a) => (
                    format!("cos_{}", m.axes[a].name.to_ascii_lowercase()),
                    false,
                ),
                AtomKind::Command(a) => (m.axes[a].name.to_ascii_lowercase(), false),
                AtomKind::Symbol(s) => (m.symbols[s].name.clone(), true),
                AtomKind::Root(_) | AtomKind::Constant(_) => {
                    unreachable!("constant atoms come after the inputs")
                }
            };
            Input {
                name: name.clone(),
                field,
                parameter,
            }
        })
        .collect()
}

/// Compiles the gains of `model` (derived from `m`) into a straight-line program with six
/// outputs per error (`gx gy gz gi gj gk`, error after error).
pub fn compile(m: &Machine, model: &GainModel) -> Program {
    let polys: Vec<&Poly> = model.gains.shared().iter().flat_map(|g| g.iter()).collect();
    compile_polys(m, model, &polys)
}

/// Compiles the position gains only, direction-major: outputs `d·N + e` is the gain of error `e`
/// in direction `d` (x, y, z), the layout of three rows of an H matrix. The orientation rows
/// are not computed.
pub fn compile_position(m: &Machine, model: &GainModel) -> Program {
    let polys: Vec<&Poly> = (0..3)
        .flat_map(|d| model.gains.shared().iter().map(move |g| &g[d]))
        .collect();
    compile_polys(m, model, &polys)
}

/// One program with one output per polynomial, in order, sharing common subexpressions.
fn compile_polys(m: &Machine, model: &GainModel, polys: &[&Poly]) -> Program {
    let inputs = inputs(m, model);
    let mut b = Builder::with(model.gains.intermediates().clone());
    b.atom_vars = atom_vars(&mut b, &model.atoms);
    let outputs = polys
        .iter()
        .map(|p| match p.as_constant() {
            Some(c) => Output::Const(c.to_f64()),
            None => match b.poly(p) {
                (v, false) => Output::Var(v),
                (v, true) => Output::Neg(v),
            },
        })
        .collect();
    prune(Program {
        inputs,
        ops: b.ops,
        outputs,
    })
}

impl Builder {
    /// The finished program: `inputs`, the instructions, `outputs`, without the instructions
    /// no output depends on.
    pub(crate) fn finish(self, inputs: Vec<Input>, outputs: Vec<Output>) -> Program {
        prune(Program {
            inputs,
            ops: self.ops,
            outputs,
        })
    }
}

/// Drops the instructions no output depends on (unused inputs, say), renumbering the rest.
fn prune(p: Program) -> Program {
    let mut live = vec![false; p.ops.len()];
    for o in &p.outputs {
        if let Output::Var(v) | Output::Neg(v) = o {
            live[*v as usize] = true;
        }
    }
    for i in (0..p.ops.len()).rev() {
        if live[i] {
            match p.ops[i] {
                Op::Add(a, b) | Op::Sub(a, b) | Op::Mul(a, b) | Op::Div(a, b) => {
                    live[a as usize] = true;
                    live[b as usize] = true;
                }
                Op::Neg(a) => live[a as usize] = true,
                Op::Input(_) | Op::Const(_) => {}
            }
        }
    }
    let mut new_index = vec![0 as Var; p.ops.len()];
    let mut ops = Vec::new();
    for (i, op) in p.ops.iter().enumerate() {
        if live[i] {
            let r = |v: Var| new_index[v as usize];
            let renumbered = match *op {
                Op::Add(a, b) => Op::Add(r(a), r(b)),
                Op::Sub(a, b) => Op::Sub(r(a), r(b)),
                Op::Mul(a, b) => Op::Mul(r(a), r(b)),
                Op::Div(a, b) => Op::Div(r(a), r(b)),
                Op::Neg(a) => Op::Neg(r(a)),
                other => other,
            };
            new_index[i] = ops.len() as Var;
            ops.push(renumbered);
        }
    }
    let outputs = p
        .outputs
        .iter()
        .map(|o| match *o {
            Output::Var(v) => Output::Var(new_index[v as usize]),
            Output::Neg(v) => Output::Neg(new_index[v as usize]),
            c => c,
        })
        .collect();
    Program {
        inputs: p.inputs,
        ops,
        outputs,
    }
}
