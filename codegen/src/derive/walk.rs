//! The walk through the chains: where each error acts, and what it does to the tool point and
//! the tool axis, in the nominal tool frame.
//!
//! No product `R·Rᵀ` of a rotation with its own transpose is ever formed, so no gain relies on
//! `sin² + cos² = 1` between factors to come out right, and the partial products stay small:
//!
//! - **Tool chain, walked from the tool end towards the bed.** The state after the steps
//!   `S_i … S_n` is the rotation `Q` of the tool frame in the frame before `S_i`, and the lever
//!   `ℓ = Qᵀ·p` from that frame's origin to the tool point, in tool coordinates (`p` in the
//!   frame's own coordinates). An offset `o` adds `Qᵀ·o` to the lever, a rotation `R` turns `Q`
//!   into `R·Q` and leaves the lever alone. An error rotation about `e_k` there moves the tool
//!   point by `(Qᵀe_k) × ℓ` and turns the tool by `Qᵀe_k` (row `k` of `Q`), in the tool frame.
//! - **Work chain, walked both ways.** From the workpiece end towards the bed: the workpiece
//!   point `w` and the workpiece z axis `z_w` in each frame. From the bed outwards: the
//!   partial product `M = R_toolᵀ·R_work,<i`, the frame before step `i` seen from the tool
//!   frame (it starts at the transpose of the tool chain's whole rotation). An error rotation
//!   about `e_k` there moves the workpiece point by `M·(e_k × w)` and its z axis by
//!   `M·(e_k × z_w)`: the cross product is taken in the step's own frame, where it is one of the
//!   coordinates of `w` or `z_w`, and `M` and `w` depend on disjoint sets of axes.
//!
//! Every quantity kept (entries of `Q` and `M`, coordinates of the levers) and every product
//! formed goes through the [`Namer`], which names it as an intermediate when it exceeds the
//! bound of terms.

use super::Vec3;
use crate::atoms::{AtomKind, AtomTable};
use crate::intermediates::{Intermediates, Namer};
use crate::poly::Poly;
use crate::rational::Rational;
use model_spec::kinematics::{FrameTurn, Step, chain_steps};
use model_spec::{AxisKind, ErrorId, Machine, Side, Value};
use std::collections::BTreeMap;

/// A 3 × 3 matrix of polynomials, row-major.
pub(crate) type Mat3 = [[Poly; 3]; 3];

pub(crate) fn zero3() -> Vec3 {
    [Poly::zero(), Poly::zero(), Poly::zero()]
}

fn identity() -> Mat3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            if i == j {
                Poly::constant(Rational::ONE)
            } else {
                Poly::zero()
            }
        })
    })
}

/// A nominal rotation about coordinate direction `d` by the angle whose sine is `s` and cosine
/// `c`.
fn rotation(d: usize, s: &Poly, c: &Poly) -> Mat3 {
    let (o, z) = (Poly::constant(Rational::ONE), Poly::zero());
    match d {
        0 => [
            [o, z.clone(), z.clone()],
            [z.clone(), c.clone(), s.neg()],
            [z, s.clone(), c.clone()],
        ],
        1 => [
            [c.clone(), z.clone(), s.clone()],
            [z.clone(), o, z.clone()],
            [s.neg(), z, c.clone()],
        ],
        _ => [
            [c.clone(), s.neg(), z.clone()],
            [s.clone(), c.clone(), z.clone()],
            [z.clone(), z, o],
        ],
    }
}

/// `e_k × v`.
fn cross_unit(k: usize, v: &Vec3) -> Vec3 {
    match k {
        0 => [Poly::zero(), v[2].neg(), v[1].clone()],
        1 => [v[2].clone(), Poly::zero(), v[0].neg()],
        _ => [v[1].neg(), v[0].clone(), Poly::zero()],
    }
}

/// What one error does, per unit, in the nominal tool frame: the tool point minus the
/// workpiece point, the tool z axis minus the workpiece z axis (the seed's eqs. (14)–(16)),
/// and the rotation of the tool frame relative to the workpiece (a rotation vector).
#[derive(Clone, Debug)]
pub(crate) struct Contribution {
    pub(crate) position: Vec3,
    pub(crate) orientation: Vec3,
    pub(crate) rotation: Vec3,
}

/// The nominal pose the walk leaves behind, for compensation.
#[derive(Clone, Debug)]
pub(crate) struct Nominal {
    /// The tool point in the frame of the last element of the work chain (before its end
    /// offset), mm.
    pub(crate) tool_point_in_work: Vec3,
    /// The rotation from the tool frame to that frame.
    pub(crate) tool_to_work: Mat3,
}

/// One derivation: the machine, its atoms, the namer and the errors tracked.
pub(crate) struct Walk<'a> {
    m: &'a Machine,
    atoms: &'a AtomTable,
    namer: Namer,
    /// Catalogue id → slot in the requested error list.
    slot: BTreeMap<ErrorId, usize>,
    /// One contribution per requested error.
    out: Vec<Contribution>,
    /// Whether to carry the tool point for the nominal pose.
    nominal: bool,
}

impl<'a> Walk<'a> {
    /// A walk for the errors `errors` of `m`.
    pub(crate) fn new(
        m: &'a Machine,
        atoms: &'a AtomTable,
        namer: Namer,
        errors: &[ErrorId],
    ) -> Walk<'a> {
        Walk {
            m,
            atoms,
            namer,
            slot: errors.iter().enumerate().map(|(i, &e)| (e, i)).collect(),
            out: (0..errors.len())
                .map(|_| Contribution {
                    position: zero3(),
                    orientation: zero3(),
                    rotation: zero3(),
                })
                .collect(),
            nominal: false,
        }
    }

    /// The walk that also carries the tool point to the work frame ([`Walk::run`] then returns
    /// the nominal pose).
    pub(crate) fn with_nominal_pose(mut self) -> Walk<'a> {
        self.nominal = true;
        self
    }

    /// The contributions of the requested errors, in order, and the intermediates they are
    /// written in.
    pub(crate) fn finish(self) -> (Vec<Contribution>, Intermediates) {
        (self.out, self.namer.finish())
    }

    /// `true` when the walk ran on a trial namer that met a quantity beyond its bound
    /// ([`Namer::trial`]): its contributions are then not the gains.
    pub(crate) fn exceeded(&self) -> bool {
        self.namer.exceeded()
    }

    fn value(&self, v: Value) -> Poly {
        match v {
            Value::Number(x) => {
                Poly::constant(Rational::from_decimal(x).expect("validated finite"))
            }
            Value::Symbol(s) => Poly::atom(self.atoms.find(AtomKind::Symbol(s))),
        }
    }

    fn sign(&self, axis: usize) -> Rational {
        Rational::int(if self.m.axes[axis].direction.own.negative {
            -1
        } else {
            1
        })
    }

    /// The translation of a step: an offset, or a linear motion (`±q` along its direction).
    fn translation(&self, step: &Step) -> Option<Vec3> {
        match step {
            Step::Offset(o) => Some(o.map(|v| self.value(v))),
            Step::Motion { axis, .. } if self.m.axes[*axis].kind == AxisKind::Linear => {
                let mut t = zero3();
                let q = Poly::atom(self.atoms.find(AtomKind::Command(*axis)));
                t[self.m.axes[*axis].direction.own.dir.index()] = q.scale(self.sign(*axis));
                Some(t)
            }
            _ => None,
        }
    }

    /// The rotation of a step: a rotary motion, or the turn into or out of an inclined
    /// axis's frame (`Fᵀ` into the own frame, `F` back; rows of `F` the own `x' y' z'`).
    fn rotation(&self, step: &Step) -> Option<Mat3> {
        match *step {
            Step::Motion { axis, .. } if self.m.axes[axis].kind == AxisKind::Rotary => {
                let s = Poly::atom(self.atoms.find(AtomKind::Sin(axis))).scale(self.sign(axis));
                let c = Poly::atom(self.atoms.find(AtomKind::Cos(axis)));
                Some(rotation(
                    self.m.axes[axis].direction.own.dir.index(),
                    &s,
                    &c,
                ))
            }
            Step::Frame { axis, turn } => {
                let inclined = self.m.axes[axis]
                    .direction
                    .inclined
                    .expect("frame steps belong to inclined axes");
                let f = inclined
                    .frame
                    .axes
                    .map(|row| row.map(|r| self.atoms.real(r)));
                Some(match turn {
                    FrameTurn::Into => {
                        std::array::from_fn(|i| std::array::from_fn(|j| f[j][i].clone()))
                    }
                    FrameTurn::Back => f,
                })
            }
            _ => None,
        }
    }

    /// `Σ_j a_j · b_j`, each product through the namer, the sum kept.
    fn dot<'p>(&mut self, pairs: impl IntoIterator<Item = (&'p Poly, &'p Poly)>) -> Poly {
        let sum = self.sum_of_products(pairs);
        self.namer.keep(sum)
    }

    /// `Σ_j a_j · b_j`, each product through the namer (a gain: not kept).
    fn sum_of_products<'p>(
        &mut self,
        pairs: impl IntoIterator<Item = (&'p Poly, &'p Poly)>,
    ) -> Poly {
        let mut sum = Poly::zero();
        for (a, b) in pairs {
            if !a.is_zero() && !b.is_zero() {
                sum = sum.add(&self.namer.mul(a, b));
            }
        }
        sum
    }

    /// `a · b` (matrices).
    fn mat_mul(&mut self, a: &Mat3, b: &Mat3) -> Mat3 {
        let mut out: Mat3 = std::array::from_fn(|_| zero3());
        for (i, row) in out.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                *cell = self.dot((0..3).map(|k| (&a[i][k], &b[k][j])));
            }
        }
        out
    }

    /// `a · v`.
    fn mat_vec(&mut self, a: &Mat3, v: &Vec3) -> Vec3 {
        let mut out = zero3();
        for (i, cell) in out.iter_mut().enumerate() {
            *cell = self.dot((0..3).map(|k| (&a[i][k], &v[k])));
        }
        out
    }

    /// `aᵀ · v`.
    fn mat_t_vec(&mut self, a: &Mat3, v: &Vec3) -> Vec3 {
        let mut out = zero3();
        for (i, cell) in out.iter_mut().enumerate() {
            *cell = self.dot((0..3).map(|k| (&a[k][i], &v[k])));
        }
        out
    }

    /// `a × b` (a gain: not kept).
    fn cross(&mut self, a: &Vec3, b: &Vec3) -> Vec3 {
        let mut out = zero3();
        for (i, cell) in out.iter_mut().enumerate() {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let (p, q) = (self.namer.mul(&a[j], &b[k]), self.namer.mul(&a[k], &b[j]));
            *cell = p.sub(&q);
        }
        out
    }

    /// `m · v`, a gain: not kept.
    fn gain(&mut self, m: &Mat3, v: &Vec3) -> Vec3 {
        let mut out = zero3();
        for (i, cell) in out.iter_mut().enumerate() {
            *cell = self.sum_of_products((0..3).map(|k| (&m[i][k], &v[k])));
        }
        out
    }

    fn slot_of(&self, id: &Option<ErrorId>) -> Option<usize> {
        id.as_ref().and_then(|id| self.slot.get(id)).copied()
    }

    /// Adds `v` to `target` of error `slot`.
    fn add(&mut self, slot: usize, pick: fn(&mut Contribution) -> &mut Vec3, v: &Vec3) {
        let target = pick(&mut self.out[slot]);
        for (t, x) in target.iter_mut().zip(v) {
            *t = t.add(x);
        }
    }

    /// An error rotation about `e_k` of the tool chain, where the tool frame's rotation is `q`
    /// and the lever to the tool point `lever` (tool coordinates).
    fn tool_rotation_error(&mut self, slot: usize, k: usize, q: &Mat3, lever: &Vec3) {
        let omega = q[k].clone();
        let position = self.cross(&omega, lever);
        let orientation = [omega[1].clone(), omega[0].neg(), Poly::zero()];
        self.add(slot, |c| &mut c.position, &position);
        self.add(slot, |c| &mut c.orientation, &orientation);
        self.add(slot, |c| &mut c.rotation, &omega);
    }

    /// An error rotation about `e_k` of the work chain, where the frame seen from the tool
    /// frame is `m` and the workpiece point and z axis in it are `w` and `z`.
    fn work_rotation_error(&mut self, slot: usize, k: usize, m: &Mat3, (w, z): &(Vec3, Vec3)) {
        let position = self.gain(m, &cross_unit(k, w)).map(|p| p.neg());
        let orientation = self.gain(m, &cross_unit(k, z)).map(|p| p.neg());
        let rotation = std::array::from_fn(|i| m[i][k].neg());
        self.add(slot, |c| &mut c.position, &position);
        self.add(slot, |c| &mut c.orientation, &orientation);
        self.add(slot, |c| &mut c.rotation, &rotation);
    }

    /// Walks the tool chain from its end: records every tool error, and returns the tool
    /// frame's rotation in the bed frame and (for the nominal pose) the tool point in bed
    /// coordinates.
    fn tool_chain(&mut self) -> (Mat3, Vec3) {
        let mut q = identity();
        let mut lever = zero3();
        let mut point = zero3();
        for step in chain_steps(self.m, Side::Tool).iter().rev() {
            match step {
                Step::ErrorTranslation(ids) => {
                    for (k, id) in ids.iter().enumerate() {
                        if let Some(slot) = self.slot_of(id) {
                            let row = q[k].clone();
                            self.add(slot, |c| &mut c.position, &row);
                        }
                    }
                }
                Step::ErrorRotation(ids) => {
                    for (k, id) in ids.iter().enumerate() {
                        if let Some(slot) = self.slot_of(id) {
                            self.tool_rotation_error(slot, k, &q, &lever);
                        }
                    }
                }
                Step::Motion {
                    axis,
                    positioning_error,
                } if self.m.axes[*axis].kind == AxisKind::Rotary => {
                    // The positioning error acts inside the motion's rotation.
                    if let Some(slot) = self.slot_of(positioning_error) {
                        let d = self.m.axes[*axis].direction.own.dir.index();
                        self.tool_rotation_error(slot, d, &q, &lever);
                    }
                }
                _ => {}
            }
            if let Some(t) = self.translation(step) {
                let moved = self.mat_t_vec(&q, &t);
                for k in 0..3 {
                    lever[k] = self.namer.keep(lever[k].add(&moved[k]));
                    if self.nominal {
                        point[k] = self.namer.keep(point[k].add(&t[k]));
                    }
                }
            }
            if let Some(r) = self.rotation(step) {
                q = self.mat_mul(&r, &q);
                if self.nominal {
                    point = self.mat_vec(&r, &point);
                }
            }
        }
        (q, point)
    }

    /// Walks the work chain from its end: the workpiece point and z axis before each step
    /// (in the frame the step acts in), by step index.
    fn work_levers(&mut self, steps: &[Step]) -> Vec<(Vec3, Vec3)> {
        let mut w = zero3();
        let mut z = zero3();
        z[2] = Poly::constant(Rational::ONE);
        let mut before = vec![(zero3(), zero3()); steps.len()];
        for (i, step) in steps.iter().enumerate().rev() {
            before[i] = (w.clone(), z.clone());
            if let Some(t) = self.translation(step) {
                for k in 0..3 {
                    w[k] = self.namer.keep(w[k].add(&t[k]));
                }
            }
            if let Some(r) = self.rotation(step) {
                w = self.mat_vec(&r, &w);
                z = self.mat_vec(&r, &z);
            }
        }
        before
    }

    /// Walks both chains, recording every tracked error; returns the nominal pose of the tool
    /// relative to the last frame of the work chain when asked for
    /// ([`Walk::with_nominal_pose`]).
    pub(crate) fn run(&mut self) -> Option<Nominal> {
        let (tool_rotation, tool_point) = self.tool_chain();
        let steps = chain_steps(self.m, Side::Work);
        let levers = self.work_levers(&steps);
        // The work frame's origin: the work chain without its end offset (and set-up errors).
        let end = steps
            .iter()
            .rposition(|s| matches!(s, Step::Offset(o) if *o == self.m.work.end_offset))
            .unwrap_or(steps.len());
        let mut m: Mat3 =
            std::array::from_fn(|i| std::array::from_fn(|j| tool_rotation[j][i].clone()));
        let mut tip = tool_point;
        for (i, step) in steps.iter().enumerate() {
            match step {
                Step::ErrorTranslation(ids) => {
                    for (k, id) in ids.iter().enumerate() {
                        if let Some(slot) = self.slot_of(id) {
                            let column: Vec3 = std::array::from_fn(|r| m[r][k].neg());
                            self.add(slot, |c| &mut c.position, &column);
                        }
                    }
                }
                Step::ErrorRotation(ids) => {
                    for (k, id) in ids.iter().enumerate() {
                        if let Some(slot) = self.slot_of(id) {
                            self.work_rotation_error(slot, k, &m, &levers[i]);
                        }
                    }
                }
                _ => {}
            }
            if i < end
                && let Some(t) = self.translation(step)
            {
                for k in 0..3 {
                    tip[k] = self.namer.keep(tip[k].sub(&t[k]));
                }
            }
            if let Some(r) = self.rotation(step) {
                m = self.mat_mul(&m, &r);
                if self.nominal && i < end {
                    tip = self.mat_t_vec(&r, &tip);
                }
            }
            if let Step::Motion {
                axis,
                positioning_error,
            } = step
                && let Some(slot) = self.slot_of(positioning_error)
            {
                // Inside the motion's rotation: `m` has just been turned by it.
                let d = self.m.axes[*axis].direction.own.dir.index();
                self.work_rotation_error(slot, d, &m, &levers[i]);
            }
        }
        self.nominal.then(|| Nominal {
            tool_point_in_work: tip,
            tool_to_work: std::array::from_fn(|i| std::array::from_fn(|j| m[j][i].clone())),
        })
    }
}
