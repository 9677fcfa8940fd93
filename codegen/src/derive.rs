//! First-order error gains of a machine, derived symbolically.
//!
//! The tool point and the workpiece point are carried through their chains (the steps of
//! [`model_spec::kinematics::chain_steps`], applied from the end towards the bed) as first-order
//! vectors `v0 + Σ εi·vi`: truncation is structural, a product `εi·εj` is never formed. The
//! same is done for the z direction of each end frame. Then, with `R0` the nominal rotation of
//! the tool frame,
//! - position gains: the first-order part of `R0ᵀ·(P_tool − P_work)`;
//! - orientation gains: `R0ᵀ·(δz_tool − δz_work)`, the seed's eqs. (14)–(16).
//!
//! At a pose where the nominal tool point is on the nominal workpiece point (every R-test sample,
//! every machining point) the position gains are the error in the actual tool frame; elsewhere
//! they leave out the product of the tool frame's small rotation with the nominal gap.

use crate::atoms::{AtomKind, AtomTable};
use crate::poly::{Atom, Poly};
use crate::rational::Rational;
use model_spec::kinematics::{FrameTurn, Step, chain_steps};
use model_spec::{AxisKind, ErrorId, Machine, Side, Value};
use std::collections::BTreeMap;

/// A polynomial 3-vector.
pub type Vec3 = [Poly; 3];

fn zero3() -> Vec3 {
    [Poly::zero(), Poly::zero(), Poly::zero()]
}

/// The coordinate unit vector `e_d`.
fn unit(d: usize) -> Vec3 {
    std::array::from_fn(|k| {
        if k == d {
            Poly::constant(Rational::ONE)
        } else {
            Poly::zero()
        }
    })
}

fn cross_unit(d: usize, v: &Vec3) -> Vec3 {
    // e_d × v
    match d {
        0 => [Poly::zero(), v[2].neg(), v[1].clone()],
        1 => [v[2].clone(), Poly::zero(), v[0].neg()],
        _ => [v[1].neg(), v[0].clone(), Poly::zero()],
    }
}

/// A nominal rotation about coordinate direction `d` by the angle whose sine is `s` and cosine
/// `c` (as polynomials), as a row-major 3×3 matrix.
fn rotation(d: usize, s: &Poly, c: &Poly) -> [[Poly; 3]; 3] {
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

fn mat_vec(r: &[[Poly; 3]; 3], v: &Vec3) -> Vec3 {
    std::array::from_fn(|i| {
        (0..3).fold(Poly::zero(), |acc, j| {
            if r[i][j].is_zero() || v[j].is_zero() {
                acc
            } else {
                acc.add(&r[i][j].mul(&v[j]))
            }
        })
    })
}

fn mat_t_vec(r: &[[Poly; 3]; 3], v: &Vec3) -> Vec3 {
    let t: [[Poly; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| r[j][i].clone()));
    mat_vec(&t, v)
}

fn mat_mul(a: &[[Poly; 3]; 3], b: &[[Poly; 3]; 3]) -> [[Poly; 3]; 3] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| (0..3).fold(Poly::zero(), |acc, k| acc.add(&a[i][k].mul(&b[k][j]))))
    })
}

/// What a carried vector is, so that each step acts on it as it should.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Carried {
    /// A point: offsets, motions and error translations move it, rotations turn it.
    Point,
    /// A direction: only rotations turn it.
    Direction,
    /// The small rotation of the end frame (a rotation vector, rad per unit of error): each
    /// error rotation adds its axis, and the nominal rotations turn the sum. Its nominal part
    /// is zero.
    Rotation,
}

/// A first-order vector: nominal part plus one vector per tracked error.
#[derive(Clone, Debug)]
struct FirstOrder {
    nominal: Vec3,
    kind: Carried,
    by_error: BTreeMap<usize, Vec3>,
}

impl FirstOrder {
    fn add_to(&mut self, slot: usize, v: Vec3) {
        let e = self.by_error.entry(slot).or_insert_with(zero3);
        for k in 0..3 {
            e[k] = e[k].add(&v[k]);
        }
    }
}

struct Deriver<'a> {
    m: &'a Machine,
    atoms: &'a AtomTable,
    /// Catalogue id → slot in the requested error list.
    slot: BTreeMap<ErrorId, usize>,
}

impl Deriver<'_> {
    fn value(&self, v: Value) -> Poly {
        match v {
            Value::Number(x) => {
                Poly::constant(Rational::from_decimal(x).expect("validated finite"))
            }
            Value::Symbol(s) => Poly::atom(self.atoms.find(AtomKind::Symbol(s))),
        }
    }

    fn sin_cos(&self, axis: usize) -> (Poly, Poly) {
        let sign = Rational::int(if self.m.axes[axis].direction.own.negative {
            -1
        } else {
            1
        });
        (
            Poly::atom(self.atoms.find(AtomKind::Sin(axis))).scale(sign),
            Poly::atom(self.atoms.find(AtomKind::Cos(axis))),
        )
    }

    /// The rotation of a [`Step::Frame`]: `Fᵀ` into the own frame, `F` back (rows of `F`:
    /// the axis's own `x' y' z'`).
    fn frame(&self, axis: usize, turn: FrameTurn) -> [[Poly; 3]; 3] {
        let inclined = self.m.axes[axis]
            .direction
            .inclined
            .expect("frame steps belong to inclined axes");
        let f = inclined
            .frame
            .axes
            .map(|row| row.map(|r| self.atoms.real(r)));
        match turn {
            FrameTurn::Into => std::array::from_fn(|i| std::array::from_fn(|j| f[j][i].clone())),
            FrameTurn::Back => f,
        }
    }

    /// The canonical form: `cos² = 1 − sin²` and `√p² = p`.
    fn canonical(&self, p: &Poly) -> Poly {
        p.reduce(&self.atoms.trig_pairs())
            .reduce_roots(&self.atoms.root_rules())
    }

    /// Applies one step: `v ← S·v`.
    fn apply(&self, step: &Step, v: &mut FirstOrder) {
        match step {
            Step::Offset(o) => {
                if v.kind == Carried::Point {
                    for (n, &value) in v.nominal.iter_mut().zip(o) {
                        *n = n.add(&self.value(value));
                    }
                }
            }
            Step::ErrorTranslation(ids) => {
                if v.kind == Carried::Point {
                    for (k, id) in ids.iter().enumerate() {
                        if let Some(&slot) = id.as_ref().and_then(|id| self.slot.get(id)) {
                            let mut t = zero3();
                            t[k] = Poly::constant(Rational::ONE);
                            v.add_to(slot, t);
                        }
                    }
                }
            }
            Step::ErrorRotation(ids) => {
                for (k, id) in ids.iter().enumerate() {
                    if let Some(&slot) = id.as_ref().and_then(|id| self.slot.get(id)) {
                        let d = match v.kind {
                            Carried::Rotation => unit(k),
                            _ => cross_unit(k, &v.nominal),
                        };
                        v.add_to(slot, d);
                    }
                }
            }
            Step::Frame { axis, turn } => {
                let r = self.frame(*axis, *turn);
                v.nominal = mat_vec(&r, &v.nominal).map(|p| self.canonical(&p));
                for e in v.by_error.values_mut() {
                    *e = mat_vec(&r, e).map(|p| self.canonical(&p));
                }
            }
            Step::Motion {
                axis,
                positioning_error,
            } => {
                let a = &self.m.axes[*axis];
                let d = a.direction.own.dir.index();
                match a.kind {
                    AxisKind::Linear => {
                        if v.kind == Carried::Point {
                            let q = Poly::atom(self.atoms.find(AtomKind::Command(*axis)));
                            let sign = Rational::int(if a.direction.own.negative { -1 } else { 1 });
                            v.nominal[d] = v.nominal[d].add(&q.scale(sign));
                        }
                    }
                    AxisKind::Rotary => {
                        if let Some(&slot) =
                            positioning_error.as_ref().and_then(|id| self.slot.get(id))
                        {
                            let dv = match v.kind {
                                Carried::Rotation => unit(d),
                                _ => cross_unit(d, &v.nominal),
                            };
                            v.add_to(slot, dv);
                        }
                        let (s, c) = self.sin_cos(*axis);
                        let r = rotation(d, &s, &c);
                        v.nominal = mat_vec(&r, &v.nominal);
                        for e in v.by_error.values_mut() {
                            *e = mat_vec(&r, e);
                        }
                    }
                }
            }
        }
    }

    fn end(&self, side: Side, kind: Carried) -> FirstOrder {
        let mut v = FirstOrder {
            nominal: match kind {
                Carried::Direction => unit(2),
                Carried::Point | Carried::Rotation => zero3(),
            },
            kind,
            by_error: BTreeMap::new(),
        };
        for step in chain_steps(self.m, side).iter().rev() {
            self.apply(step, &mut v);
        }
        v
    }

    /// The nominal rotation of the tool frame.
    fn tool_rotation(&self) -> [[Poly; 3]; 3] {
        self.rotation_of(Side::Tool)
    }

    /// The nominal rotation of the end frame of the chain on `side` (the product of its rotary
    /// motions, bed first).
    fn rotation_of(&self, side: Side) -> [[Poly; 3]; 3] {
        let one = Poly::constant(Rational::ONE);
        let mut r: [[Poly; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| if i == j { one.clone() } else { Poly::zero() })
        });
        for step in chain_steps(self.m, side) {
            match step {
                Step::Motion { axis, .. } if self.m.axes[axis].kind == AxisKind::Rotary => {
                    let (s, c) = self.sin_cos(axis);
                    let d = self.m.axes[axis].direction.own.dir.index();
                    r = mat_mul(&r, &rotation(d, &s, &c));
                }
                Step::Frame { axis, turn } => r = mat_mul(&r, &self.frame(axis, turn)),
                _ => {}
            }
        }
        r.map(|row| row.map(|p| self.canonical(&p)))
    }
}

/// The nominal kinematics compensation needs, as polynomials in the machine's atoms.
#[derive(Clone, Debug)]
pub struct NominalPose {
    /// The tool point in the frame of the last element of the work chain (the frame the work
    /// end's offset is given in), mm.
    pub tool_point_in_work: Vec3,
    /// The rotation from the tool frame to that work frame (row-major): a tool-frame vector
    /// `v` is `R·v` in work coordinates.
    pub tool_to_work: [[Poly; 3]; 3],
}

/// The nominal pose of the tool frame relative to the last frame of the work chain.
pub fn nominal_pose(m: &Machine) -> NominalPose {
    let atoms = AtomTable::new(m);
    let d = Deriver {
        m,
        atoms: &atoms,
        slot: BTreeMap::new(),
    };
    let tool = d.end(Side::Tool, Carried::Point).nominal;
    // The work frame's origin: the work chain without its end offset (and set-up errors).
    let steps = chain_steps(m, Side::Work);
    let end = steps
        .iter()
        .rposition(|s| matches!(s, Step::Offset(o) if *o == m.work.end_offset))
        .unwrap_or(steps.len());
    let mut origin = FirstOrder {
        nominal: zero3(),
        kind: Carried::Point,
        by_error: BTreeMap::new(),
    };
    for step in steps[..end].iter().rev() {
        d.apply(step, &mut origin);
    }
    let rw = d.rotation_of(Side::Work);
    let rt = d.rotation_of(Side::Tool);
    let gap: Vec3 = std::array::from_fn(|k| tool[k].sub(&origin.nominal[k]));
    let rw_t: [[Poly; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| rw[j][i].clone()));
    NominalPose {
        tool_point_in_work: mat_vec(&rw_t, &gap).map(|p| d.canonical(&p)),
        tool_to_work: mat_mul(&rw_t, &rt).map(|row| row.map(|p| d.canonical(&p))),
    }
}

/// The rotation gains of `errors`: for each, the small rotation of the tool frame relative to
/// the work frame per unit of the error, as a rotation vector in the nominal tool frame (rad per
/// mm for translational errors, rad per rad for angular ones). Unlike the orientation rows of
/// [`GainModel`] (the seed's change of the tool's z direction), these hold the rotation about
/// the tool axis too.
pub fn rotation_gains(m: &Machine, errors: &[ErrorId]) -> Vec<Vec3> {
    let atoms = AtomTable::new(m);
    let slot = errors.iter().enumerate().map(|(i, &e)| (e, i)).collect();
    let d = Deriver {
        m,
        atoms: &atoms,
        slot,
    };
    let (wt, ww) = (
        d.end(Side::Tool, Carried::Rotation),
        d.end(Side::Work, Carried::Rotation),
    );
    let r0 = d.tool_rotation();
    let z = zero3();
    (0..errors.len())
        .map(|i| {
            let (a, b) = (
                wt.by_error.get(&i).unwrap_or(&z),
                ww.by_error.get(&i).unwrap_or(&z),
            );
            let v: Vec3 = std::array::from_fn(|k| a[k].sub(&b[k]));
            mat_t_vec(&r0, &v).map(|p| d.canonical(&p))
        })
        .collect()
}

/// The symbolic first-order gains of a set of errors of one machine.
#[derive(Clone, Debug)]
pub struct GainModel {
    /// The machine's name.
    pub machine: String,
    /// The atoms the gains are written in.
    pub atoms: AtomTable,
    /// The errors, as catalogue ids of the machine.
    pub errors: Vec<ErrorId>,
    /// Their names (canonical).
    pub error_names: Vec<String>,
    /// `true` for angular errors (gains in mm/rad), `false` for translational ones (mm/mm).
    pub angular: Vec<bool>,
    /// For each error: `[gx, gy, gz, gi, gj, gk]`, position then orientation gains, in the tool
    /// frame, canonical polynomials.
    pub gains: Vec<[Poly; 6]>,
}

impl GainModel {
    /// Derives the gains of `errors` (catalogue ids of `m`, any order; kept in the given order).
    pub fn derive(m: &Machine, errors: &[ErrorId]) -> GainModel {
        let atoms = AtomTable::new(m);
        let slot = errors.iter().enumerate().map(|(i, &e)| (e, i)).collect();
        let d = Deriver {
            m,
            atoms: &atoms,
            slot,
        };
        let (pt, pw) = (
            d.end(Side::Tool, Carried::Point),
            d.end(Side::Work, Carried::Point),
        );
        let (zt, zw) = (
            d.end(Side::Tool, Carried::Direction),
            d.end(Side::Work, Carried::Direction),
        );
        let r0 = d.tool_rotation();
        let diff = |a: &FirstOrder, b: &FirstOrder, i: usize| -> Vec3 {
            let z = zero3();
            let (va, vb) = (
                a.by_error.get(&i).unwrap_or(&z),
                b.by_error.get(&i).unwrap_or(&z),
            );
            let v: Vec3 = std::array::from_fn(|k| va[k].sub(&vb[k]));
            mat_t_vec(&r0, &v).map(|p| d.canonical(&p))
        };
        let gains = (0..errors.len())
            .map(|i| {
                let [px, py, pz] = diff(&pt, &pw, i);
                let [ox, oy, oz] = diff(&zt, &zw, i);
                [px, py, pz, ox, oy, oz]
            })
            .collect();
        GainModel {
            machine: m.name.clone(),
            error_names: errors
                .iter()
                .map(|&e| m.catalogue[e].name.clone())
                .collect(),
            angular: errors
                .iter()
                .map(|&e| m.catalogue[e].is_angular())
                .collect(),
            errors: errors.to_vec(),
            atoms,
            gains,
        }
    }

    /// Numeric gains at a pose: `commands` per axis (linear mm, rotary rad), `params` per
    /// kinematic symbol (mm). One `[gx, gy, gz, gi, gj, gk]` per error (mm/mm or mm/rad for
    /// position rows, 1/mm or 1/rad for orientation rows).
    pub fn evaluate(&self, commands: &[f64], params: &[f64]) -> Vec<[f64; 6]> {
        let values = self.atoms.all_values(commands, params);
        self.gains
            .iter()
            .map(|g| std::array::from_fn(|k| g[k].eval(&values)))
            .collect()
    }

    /// The sub-model of the errors at positions `rows` of this one (same atoms).
    pub fn select(&self, rows: &[usize]) -> GainModel {
        GainModel {
            machine: self.machine.clone(),
            atoms: self.atoms.clone(),
            errors: rows.iter().map(|&i| self.errors[i]).collect(),
            error_names: rows.iter().map(|&i| self.error_names[i].clone()).collect(),
            angular: rows.iter().map(|&i| self.angular[i]).collect(),
            gains: rows.iter().map(|&i| self.gains[i].clone()).collect(),
        }
    }

    /// The atom used in the polynomials for `kind`.
    pub fn atom(&self, kind: AtomKind) -> Atom {
        self.atoms.find(kind)
    }
}
