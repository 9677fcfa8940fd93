//! The compensation programs in the flat IR: the nominal target of a commanded pose, and one
//! corrected-pose step (the nominal Jacobian's first-order inverse of the predicted error, with
//! damped least squares for the rotary axes).

use super::kinematics::Ingredients;
use crate::atoms::{AtomKind, AtomTable};
use crate::ir::{Input, Op, Output, Program, Var};
use crate::lower::{Builder, Signed, inputs_of};
use crate::poly::Poly;

/// The damping `μ0` of the rotary axes' least squares at a singular pose, (rad/rad)²: 2⁻¹²,
/// about (sin 0.9°)², a power of two so that it and `1/μ0²` are exact. The damping used is
/// `μ = μ0 / (1 + (w/μ0)²)`, `w` about the smallest squared singular value of the
/// orientation Jacobian: where the rotary axes turn the tool axis by more than about 1° per
/// radian in every direction it vanishes (one step is the exact inverse to within `(μ0/w)³`:
/// 5e-8 at 15° from the singular pose); at a singular pose (the
/// tool axis on the last rotary axis, `A = 0` on a table-table A/C machine) it is `μ0`, and
/// the orientation correction fades to zero instead of growing without bound.
pub const DAMPING: f64 = 1.0 / 4096.0;

/// A value under construction: a constant (folded) or an instruction up to sign.
#[derive(Clone, Copy, Debug)]
enum Val {
    Const(f64),
    Var(Signed),
}

/// The builder with constant folding on top of the hash-consed instructions.
struct Ctx {
    b: Builder,
}

impl Ctx {
    fn var(&mut self, x: Val) -> Signed {
        match x {
            Val::Var(s) => s,
            Val::Const(c) => (self.b.constant(c.abs()), c.is_sign_negative() && c != 0.0),
        }
    }

    fn poly(&mut self, p: &Poly) -> Val {
        if p.is_zero() {
            return Val::Const(0.0);
        }
        match p.as_constant() {
            Some(c) => Val::Const(c.to_f64()),
            None => Val::Var(self.b.poly(p)),
        }
    }

    fn neg(&mut self, x: Val) -> Val {
        match x {
            Val::Const(c) => Val::Const(-c),
            Val::Var((v, s)) => Val::Var((v, !s)),
        }
    }

    fn add(&mut self, x: Val, y: Val) -> Val {
        match (x, y) {
            (Val::Const(a), Val::Const(b)) => Val::Const(a + b),
            (Val::Const(c), v) | (v, Val::Const(c)) if c == 0.0 => v,
            _ => {
                let (a, b) = (self.var(x), self.var(y));
                let (v, neg) = match (a.1, b.1) {
                    (false, false) => (self.b.push(Op::Add(a.0, b.0)), false),
                    (true, true) => (self.b.push(Op::Add(a.0, b.0)), true),
                    (false, true) => (self.b.push(Op::Sub(a.0, b.0)), false),
                    (true, false) => (self.b.push(Op::Sub(b.0, a.0)), false),
                };
                Val::Var((v, neg))
            }
        }
    }

    fn sub(&mut self, x: Val, y: Val) -> Val {
        let y = self.neg(y);
        self.add(x, y)
    }

    fn mul(&mut self, x: Val, y: Val) -> Val {
        match (x, y) {
            (Val::Const(a), Val::Const(b)) => Val::Const(a * b),
            (Val::Const(c), v) | (v, Val::Const(c)) if c == 0.0 => {
                let _ = v;
                Val::Const(0.0)
            }
            (Val::Const(c), v) | (v, Val::Const(c)) if c.abs() == 1.0 => {
                if c < 0.0 {
                    self.neg(v)
                } else {
                    v
                }
            }
            _ => {
                let (a, b) = (self.var(x), self.var(y));
                Val::Var((self.b.push(Op::Mul(a.0, b.0)), a.1 ^ b.1))
            }
        }
    }

    fn div(&mut self, x: Val, y: Val) -> Val {
        match (x, y) {
            (Val::Const(a), Val::Const(b)) => Val::Const(a / b),
            (Val::Const(0.0), _) => Val::Const(0.0),
            _ => {
                let (a, b) = (self.var(x), self.var(y));
                Val::Var((self.b.push(Op::Div(a.0, b.0)), a.1 ^ b.1))
            }
        }
    }

    fn dot(&mut self, xs: &[Val], ys: &[Val]) -> Val {
        let mut acc = Val::Const(0.0);
        for (&x, &y) in xs.iter().zip(ys) {
            let p = self.mul(x, y);
            acc = self.add(acc, p);
        }
        acc
    }

    fn vec3(&mut self, p: &[Poly; 3]) -> [Val; 3] {
        [self.poly(&p[0]), self.poly(&p[1]), self.poly(&p[2])]
    }

    fn output(&mut self, x: Val) -> Output {
        match x {
            Val::Const(c) => Output::Const(c),
            Val::Var((v, false)) => Output::Var(v),
            Val::Var((v, true)) => Output::Neg(v),
        }
    }
}

fn cross(a: [Val; 3], b: [Val; 3], c: &mut Ctx) -> [Val; 3] {
    let term = |i: usize, j: usize, c: &mut Ctx| {
        let p = c.mul(a[i], b[j]);
        let q = c.mul(a[j], b[i]);
        c.sub(p, q)
    };
    [term(1, 2, c), term(2, 0, c), term(0, 1, c)]
}

/// Which program to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// Inputs pose and params; outputs the tool point in the work frame (3) and the tool axis
    /// in the work frame (3).
    Target,
    /// Inputs pose, params, values, target (6); outputs the change of every axis command and
    /// the residual (3 position, 2 tilt, 1 roll) at the input pose.
    Step,
    /// As `Step` from the commanded pose itself (the target is the pose's own): inputs pose,
    /// params, values.
    FirstStep,
    /// As `Step` with the rotary axes held: the linear axes alone remove the position
    /// residual (the host's refinement once the orientation is settled).
    PositionStep,
}

/// Builds one program over the atoms `atoms` of the original machine.
pub(crate) fn build(ing: &Ingredients, atoms: &AtomTable, kind: Kind) -> Program {
    let machine = &ing.machine;
    let mut inputs: Vec<Input> = inputs_of(machine, atoms);
    let n_inputs = atoms.input_count();
    let mut c = Ctx { b: Builder::new() };
    // The polynomials are in the atoms of `ing.machine`: the original machine's atoms with the
    // three work-point symbols among the kinematic symbols. Those three are computed (first
    // left unset, then the tool point); every other atom is an input or a constant of the
    // original machine.
    let own = AtomTable::new(machine);
    let work_point = |k: &AtomKind| matches!(k, AtomKind::Symbol(s) if ing.work_point.contains(s));
    c.b.atom_vars = own
        .kinds
        .iter()
        .map(|k| match k.constant_value() {
            _ if work_point(k) => Var::MAX,
            Some(value) => c.b.constant(value),
            None => c.b.push(Op::Input(u32::from(atoms.find(*k)))),
        })
        .collect();
    let tip = c.vec3(&ing.tool_point);
    let tip_vars: Vec<Var> = tip
        .iter()
        .map(|&t| {
            let s = c.var(t);
            if s.1 { c.b.push(Op::Neg(s.0)) } else { s.0 }
        })
        .collect();
    for (slot, &symbol) in ing.work_point.iter().enumerate() {
        let atom = own.find(AtomKind::Symbol(symbol));
        c.b.atom_vars[atom as usize] = tip_vars[slot];
    }
    let rot: Vec<[Val; 3]> = ing
        .tool_to_work
        .iter()
        .map(|row| [c.poly(&row[0]), c.poly(&row[1]), c.poly(&row[2])])
        .collect();
    if kind == Kind::Target {
        let axis = [rot[0][2], rot[1][2], rot[2][2]];
        let outputs = tip.iter().chain(&axis).map(|&v| c.output(v)).collect();
        return c.b.finish(inputs, outputs);
    }
    let mut next = n_inputs as u32;
    let mut input = |c: &mut Ctx, inputs: &mut Vec<Input>, name: String| {
        inputs.push(Input {
            field: name.clone(),
            name,
            parameter: false,
        });
        let v = c.b.push(Op::Input(next));
        next += 1;
        Val::Var((v, false))
    };
    let values: Vec<Val> = ing
        .error_names
        .iter()
        .map(|name| input(&mut c, &mut inputs, name.clone()))
        .collect();
    let target: Vec<Val> = match kind {
        Kind::Step | Kind::PositionStep => {
            ["tool_x", "tool_y", "tool_z", "axis_x", "axis_y", "axis_z"]
                .iter()
                .map(|name| input(&mut c, &mut inputs, name.to_string()))
                .collect()
        }
        _ => Vec::new(),
    };
    // The predicted error at this pose, tool frame.
    let mut delta = [Val::Const(0.0); 3];
    let mut omega = [Val::Const(0.0); 3];
    for (e, &v) in ing.errors.iter().zip(&values) {
        let (p, r) = (c.vec3(&e.0), c.vec3(&e.1));
        for k in 0..3 {
            let dp = c.mul(p[k], v);
            delta[k] = c.add(delta[k], dp);
            let dr = c.mul(r[k], v);
            omega[k] = c.add(omega[k], dr);
        }
    }
    // The residual: tool point and tool axis against the target, tool frame.
    let (position, b) = if matches!(kind, Kind::Step | Kind::PositionStep) {
        let gap: Vec<Val> = (0..3).map(|k| c.sub(tip[k], target[k])).collect();
        let col = |c: &mut Ctx, j: usize, v: &[Val]| {
            let column = [rot[0][j], rot[1][j], rot[2][j]];
            c.dot(&column, v)
        };
        let mut position = [Val::Const(0.0); 3];
        for (k, p) in position.iter_mut().enumerate() {
            let g = col(&mut c, k, &gap);
            *p = c.add(g, delta[k]);
        }
        let b = [col(&mut c, 0, &target[3..]), col(&mut c, 1, &target[3..])];
        (position, b)
    } else {
        (delta, [Val::Const(0.0); 2])
    };
    let tilt = [c.sub(omega[1], b[0]), {
        let t = c.neg(omega[0]);
        c.sub(t, b[1])
    }];
    let roll = omega[2];
    let columns: Vec<([Val; 3], [Val; 3])> = ing
        .columns
        .iter()
        .map(|(p, r)| (c.vec3(p), c.vec3(r)))
        .collect();
    let mut change = vec![Val::Const(0.0); machine.axes.len()];
    // Rotary axes: damped least squares on the tilt.
    let j: Vec<[Val; 2]> = ing
        .rotary
        .iter()
        .map(|&a| {
            let r = columns[a].1;
            [r[1], c.neg(r[0])]
        })
        .collect();
    let g: Vec<Val> = j.iter().map(|ji| c.dot(ji, &tilt)).collect();
    // Variable damping: `μ = μ0 / (1 + (w/μ0)²)` with `w` about the smallest squared singular
    // value (`det / (trace + μ0)` of `JᵀJ`): `μ0` at a singular pose, vanishing (as `μ0³/w²`)
    // away from it, so that one step is the exact inverse there. Branch-free.
    let mu0 = Val::Const(DAMPING);
    let inverse_square = Val::Const(1.0 / (DAMPING * DAMPING));
    let damping = |c: &mut Ctx, w: Val| {
        let w2 = c.mul(w, w);
        let scaled = c.mul(w2, inverse_square);
        let d = c.add(Val::Const(1.0), scaled);
        c.div(mu0, d)
    };
    let rotary_count = if kind == Kind::PositionStep {
        0
    } else {
        j.len()
    };
    match rotary_count {
        1 => {
            let m11 = c.dot(&j[0], &j[0]);
            let mu = damping(&mut c, m11);
            let m11 = c.add(m11, mu);
            let q = c.div(g[0], m11);
            change[ing.rotary[0]] = c.neg(q);
        }
        2 => {
            let m11 = c.dot(&j[0], &j[0]);
            let m22 = c.dot(&j[1], &j[1]);
            let m12 = c.dot(&j[0], &j[1]);
            let (p, q) = (c.mul(m11, m22), c.mul(m12, m12));
            let det0 = c.sub(p, q);
            let trace = c.add(m11, m22);
            let trace = c.add(trace, mu0);
            let w = c.div(det0, trace);
            let mu = damping(&mut c, w);
            let m11 = c.add(m11, mu);
            let m22 = c.add(m22, mu);
            let (p, q) = (c.mul(m11, m22), c.mul(m12, m12));
            let det = c.sub(p, q);
            let inv = c.div(Val::Const(1.0), det);
            let (a, b2) = (c.mul(m12, g[1]), c.mul(m22, g[0]));
            let d1 = c.sub(a, b2);
            change[ing.rotary[0]] = c.mul(d1, inv);
            let (a, b2) = (c.mul(m12, g[0]), c.mul(m11, g[1]));
            let d2 = c.sub(a, b2);
            change[ing.rotary[1]] = c.mul(d2, inv);
        }
        _ => {}
    }
    // Linear axes: remove the position residual and what the rotary change moves.
    let mut rhs = position;
    for &a in &ing.rotary {
        for (k, r) in rhs.iter_mut().enumerate() {
            let m = c.mul(columns[a].0[k], change[a]);
            *r = c.add(*r, m);
        }
    }
    let cols: Vec<[Val; 3]> = ing.linear.iter().map(|&a| columns[a].0).collect();
    let rows = [
        cross(cols[1], cols[2], &mut c),
        cross(cols[2], cols[0], &mut c),
        cross(cols[0], cols[1], &mut c),
    ];
    let det = c.dot(&cols[0], &rows[0]);
    let inv = c.div(Val::Const(-1.0), det);
    for (row, &a) in rows.iter().zip(&ing.linear) {
        let d = c.dot(row, &rhs);
        change[a] = c.mul(d, inv);
    }
    let outputs = change
        .iter()
        .chain(&position)
        .chain(&tilt)
        .chain(std::iter::once(&roll))
        .map(|&v| c.output(v))
        .collect();
    c.b.finish(inputs, outputs)
}
