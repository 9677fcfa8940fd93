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
use crate::ir::{Input, Op, Output, Program, Var};
use crate::poly::{Atom, Monomial, Poly};
use crate::rational::Rational;
use model_spec::Machine;
use std::collections::HashMap;

/// A value up to sign: `(var, negated)`.
pub(crate) type Signed = (Var, bool);

/// Builds one program: hash-consed instructions, polynomials memoised up to a constant factor.
pub(crate) struct Builder {
    ops: Vec<Op>,
    interned: HashMap<Op, Var>,
    memo: HashMap<Poly, Signed>,
    /// The value each atom of the polynomials stands for.
    pub(crate) atom_vars: Vec<Var>,
}

impl Builder {
    /// An empty program whose polynomials will read their atoms from `atom_vars` (set it once
    /// the inputs are pushed).
    pub(crate) fn new() -> Builder {
        Builder {
            ops: Vec::new(),
            interned: HashMap::new(),
            memo: HashMap::new(),
            atom_vars: Vec::new(),
        }
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

    fn monomial(&mut self, m: &Monomial) -> Var {
        // Powers by repeated multiplication, then the product left to right in atom order.
        let mut acc: Option<Var> = None;
        for &(a, e) in &m.0 {
            let base = self.atom_vars[a as usize];
            let mut p = base;
            for _ in 1..e {
                p = self.push(Op::Mul(p, base));
            }
            acc = Some(match acc {
                None => p,
                Some(x) => self.push(Op::Mul(x, p)),
            });
        }
        acc.unwrap_or_else(|| self.constant(1.0))
    }

    /// The value of a non-zero polynomial.
    pub(crate) fn poly(&mut self, p: &Poly) -> Signed {
        let lead = p.leading_coefficient();
        let unit = p.scale(Rational::new(lead.denom(), lead.numer()));
        let v = match self.memo.get(&unit) {
            Some(&v) => v,
            None => {
                let v = self.unit_poly(&unit);
                self.memo.insert(unit, v);
                v
            }
        };
        self.scale(lead, v)
    }

    /// The value of a polynomial whose leading coefficient is 1.
    fn unit_poly(&mut self, p: &Poly) -> Signed {
        if p.len() == 1 {
            let (m, _) = p.terms().next().expect("one term");
            return (self.monomial(m), false);
        }
        let atom = best_atom(p);
        let (q, r) = p.split_by(atom);
        let a = (self.atom_vars[atom as usize], false);
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
    let mut counts: HashMap<Atom, usize> = HashMap::new();
    for (m, _) in p.terms() {
        for &(a, _) in &m.0 {
            *counts.entry(a).or_default() += 1;
        }
    }
    let mut best: Vec<(Atom, usize)> = counts.into_iter().collect();
    best.sort_by(|x, y| y.1.cmp(&x.1).then(x.0.cmp(&y.0)));
    best[0].0
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
    let polys: Vec<&Poly> = model.gains.iter().flat_map(|g| g.iter()).collect();
    compile_polys(m, model, &polys)
}

/// Compiles the position gains only, direction-major: outputs `d·N + e` is the gain of error `e`
/// in direction `d` (x, y, z), the layout of three rows of an H matrix. The orientation rows
/// are not computed.
pub fn compile_position(m: &Machine, model: &GainModel) -> Program {
    let polys: Vec<&Poly> = (0..3)
        .flat_map(|d| model.gains.iter().map(move |g| &g[d]))
        .collect();
    compile_polys(m, model, &polys)
}

/// A part of a model compiled on its own: some of its errors, with their gains and position
/// gains programs.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// Positions of its errors in the model's error list, ascending.
    pub rows: Vec<usize>,
    /// Six outputs per error of the part ([`compile`] of the part).
    pub gains: Program,
    /// Position gains, direction-major over the part's errors ([`compile_position`]).
    pub position: Program,
}

/// The default bound on the instructions of one generated function.
pub const MAX_INSTRUCTIONS: usize = 4000;

/// Compiles a model into parts of at most `max_instructions` instructions each (one part when
/// the whole model fits): the errors are grouped by the axis they belong to (squareness,
/// set-up and sensor-offset errors by their kind), groups are added to a part while it stays
/// within the bound, and a group that alone exceeds it is split error by error. Each part has
/// its own common-subexpression elimination, so sharing across parts is lost: the bound trades
/// a little arithmetic for a bounded function size and compile time.
pub fn compile_parts(m: &Machine, model: &GainModel, max_instructions: usize) -> Vec<Part> {
    let build = |rows: Vec<usize>| {
        let sub = model.select(&rows);
        Part {
            gains: compile(m, &sub),
            position: compile_position(m, &sub),
            rows,
        }
    };
    let whole = build((0..model.errors.len()).collect());
    let size = |p: &Part| p.gains.ops.len().max(p.position.ops.len());
    if size(&whole) <= max_instructions {
        return vec![whole];
    }
    // Groups of consecutive errors with the same key (catalogue order keeps an axis together).
    let key = |i: usize| {
        let e = &m.catalogue[model.errors[i]];
        (e.axis(), std::mem::discriminant(&e.kind))
    };
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in 0..model.errors.len() {
        match groups.last_mut() {
            Some(g) if key(g[0]) == key(i) => g.push(i),
            _ => groups.push(vec![i]),
        }
    }
    let mut parts: Vec<Part> = Vec::new();
    let mut current: Vec<usize> = Vec::new();
    for g in groups {
        let mut trial = current.clone();
        trial.extend(&g);
        let candidate = build(trial.clone());
        if size(&candidate) <= max_instructions || current.is_empty() && g.len() == 1 {
            current = trial;
            continue;
        }
        if !current.is_empty() {
            parts.push(build(std::mem::take(&mut current)));
        }
        // The group alone, error by error if it does not fit either.
        for &i in &g {
            let mut t = current.clone();
            t.push(i);
            if current.is_empty() || size(&build(t.clone())) <= max_instructions {
                current = t;
            } else {
                parts.push(build(std::mem::replace(&mut current, vec![i])));
            }
        }
    }
    if !current.is_empty() {
        parts.push(build(current));
    }
    parts
}

/// One program with one output per polynomial, in order, sharing common subexpressions.
fn compile_polys(m: &Machine, model: &GainModel, polys: &[&Poly]) -> Program {
    let inputs = inputs(m, model);
    let mut b = Builder {
        ops: Vec::new(),
        interned: HashMap::new(),
        memo: HashMap::new(),
        atom_vars: Vec::new(),
    };
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
