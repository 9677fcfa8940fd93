//! First-order error gains of a machine, derived symbolically.
//!
//! Every error is a small translation or rotation at one step of a chain
//! ([`model_spec::kinematics::chain_steps`]); its gains are what it does, per unit, to the tool
//! point minus the workpiece point and to the tool z axis minus the workpiece z axis, in the
//! nominal tool frame:
//! - position gains: the first-order change of `R0ᵀ·(P_tool − P_work)`, `R0` the nominal
//!   rotation of the tool frame;
//! - orientation gains: `R0ᵀ·(δz_tool − δz_work)`, the seed's eqs. (14)–(16).
//!
//! Truncation is structural: a product of two errors is never formed. The chains are walked so
//! that no product `R·Rᵀ` of a rotation with its own transpose is formed (no gain relies on
//! `sin² + cos² = 1` between factors to come out right) and the partial products stay small:
//!
//! - the **tool chain** from the tool end towards the bed, carrying the rotation `Q` of the
//!   tool frame in the current frame and the lever from the current frame's origin to the
//!   tool point in tool coordinates; an error rotation about `e_k` there moves the tool point
//!   by `(Qᵀe_k) × lever` and turns the tool by `Qᵀe_k`, both already in the tool frame;
//! - the **work chain** both ways: from the workpiece end, the workpiece point and z axis in
//!   each frame; from the bed, the partial product `M = R_toolᵀ·R_work,<i` (the frame seen
//!   from the tool frame). An error rotation about `e_k` moves the workpiece point by
//!   `M·(e_k × w)`, the cross product taken in the step's own frame.
//!
//! Quantities too large to keep expanded become named intermediates
//! ([`crate::intermediates`]); a gain over intermediates that vanishes identically is made an
//! exact zero ([`crate::identity`]).
//!
//! At a pose where the nominal tool point is on the nominal workpiece point (every R-test sample,
//! every machining point) the position gains are the error in the actual tool frame; elsewhere
//! they leave out the product of the tool frame's small rotation with the nominal gap.

mod gains;
mod walk;

pub use gains::Gains;

use crate::atoms::{AtomKind, AtomTable};
use crate::identity::ZeroTest;
use crate::intermediates::{DeriveOptions, Intermediates, Namer};
use crate::poly::{Atom, Poly};
use model_spec::{ErrorId, Machine};
use walk::Walk;

/// A polynomial 3-vector.
pub type Vec3 = [Poly; 3];

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

/// The nominal pose of the tool frame relative to the last frame of the work chain, expanded
/// (canonical polynomials in the machine's atoms).
pub fn nominal_pose(m: &Machine) -> NominalPose {
    let atoms = AtomTable::new(m);
    let mut w =
        Walk::new(m, &atoms, Namer::new(&atoms, DeriveOptions::default()), &[]).with_nominal_pose();
    let nominal = w.run().expect("the walk was asked for the nominal pose");
    let (_, inter) = w.finish();
    let mut x = inter.expander();
    NominalPose {
        tool_point_in_work: nominal.tool_point_in_work.map(|p| x.expand(&p)),
        tool_to_work: nominal.tool_to_work.map(|row| row.map(|p| x.expand(&p))),
    }
}

/// The rotation gains of `errors`: for each, the small rotation of the tool frame relative to
/// the work frame per unit of the error, as a rotation vector in the nominal tool frame (rad per
/// mm for translational errors, rad per rad for angular ones), expanded (canonical polynomials
/// in the machine's atoms). Unlike the orientation rows of [`GainModel`] (the seed's change of
/// the tool's z direction), these hold the rotation about the tool axis too.
pub fn rotation_gains(m: &Machine, errors: &[ErrorId]) -> Vec<Vec3> {
    let atoms = AtomTable::new(m);
    let mut w = Walk::new(
        m,
        &atoms,
        Namer::new(&atoms, DeriveOptions::default()),
        errors,
    );
    w.run();
    let (out, inter) = w.finish();
    let mut x = inter.expander();
    out.into_iter()
        .map(|c| c.rotation.map(|p| x.expand(&p)))
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
    /// frame. Indexing or iterating gives the expanded canonical polynomials in the atoms (the
    /// seed's tables; computed on first use when the model has intermediates, see [`Gains`]);
    /// [`Gains::shared`] the shared form code is compiled from.
    pub gains: Gains,
}

impl GainModel {
    /// Derives the gains of `errors` (catalogue ids of `m`, any order; kept in the given order).
    ///
    /// A chain whose every quantity and product stays within
    /// [`DeriveOptions::EXPAND_UP_TO`] terms is kept expanded: on such short chains the expanded
    /// polynomials compile to the fewest operations (a nutating head with its `√2` entries
    /// takes 228 operations expanded, 267 with the default bound). A longer chain is derived
    /// with the default bound ([`DeriveOptions::default`]), whose operations grow with the
    /// chain instead of doubling with every axis; the first attempt then costs one more
    /// derivation at the larger bound, itself bounded.
    pub fn derive(m: &Machine, errors: &[ErrorId]) -> GainModel {
        let atoms = AtomTable::new(m);
        let trial = Namer::trial(&atoms, DeriveOptions::EXPAND_UP_TO);
        GainModel::derive_in(m, errors, atoms, trial)
            .unwrap_or_else(|| GainModel::derive_with(m, errors, DeriveOptions::default()))
    }

    /// Derives the gains of `errors` keeping polynomials of at most `options.max_terms` terms
    /// expanded and naming larger ones as intermediates. Every bound gives the same functions;
    /// [`DeriveOptions::EXPANDED`] gives the expanded polynomials directly.
    ///
    /// A gain over intermediates that vanishes identically (by `sin² + cos² = 1` hidden in two
    /// intermediates, say) is made an exact zero ([`crate::identity`]), so the identically zero
    /// gains are the same whatever the bound.
    pub fn derive_with(m: &Machine, errors: &[ErrorId], options: DeriveOptions) -> GainModel {
        let atoms = AtomTable::new(m);
        let namer = Namer::new(&atoms, options);
        GainModel::derive_in(m, errors, atoms, namer)
            .expect("only a trial namer gives up, and this one names")
    }

    /// The gains derived with `namer`; `None` when it is a trial that met a quantity beyond
    /// its bound.
    fn derive_in(
        m: &Machine,
        errors: &[ErrorId],
        atoms: AtomTable,
        namer: Namer,
    ) -> Option<GainModel> {
        let mut w = Walk::new(m, &atoms, namer, errors);
        w.run();
        if w.exceeded() {
            return None;
        }
        let (out, inter) = w.finish();
        let mut shared: Vec<[Poly; 6]> = out
            .into_iter()
            .map(|c| {
                let [px, py, pz] = c.position;
                let [ox, oy, oz] = c.orientation;
                [px, py, pz, ox, oy, oz]
            })
            .collect();
        if !inter.is_empty()
            && let Some(test) = ZeroTest::new(&atoms, &inter)
        {
            for p in shared.iter_mut().flatten() {
                if inter.mentioned_in(p) && test.vanishes(p) {
                    *p = Poly::zero();
                }
            }
        }
        Some(GainModel {
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
            gains: Gains::new(shared, inter),
        })
    }

    /// Numeric gains at a pose: `commands` per axis (linear mm, rotary rad), `params` per
    /// kinematic symbol (mm). One `[gx, gy, gz, gi, gj, gk]` per error (mm/mm or mm/rad for
    /// position rows, 1/mm or 1/rad for orientation rows). Evaluates the shared form.
    pub fn evaluate(&self, commands: &[f64], params: &[f64]) -> Vec<[f64; 6]> {
        let mut values = self.atoms.all_values(commands, params);
        self.gains.intermediates().extend_values(&mut values);
        self.gains
            .shared()
            .iter()
            .map(|g| std::array::from_fn(|k| g[k].eval(&values)))
            .collect()
    }

    /// The sub-model of the errors at positions `rows` of this one (same atoms and
    /// intermediates).
    pub fn select(&self, rows: &[usize]) -> GainModel {
        GainModel {
            machine: self.machine.clone(),
            atoms: self.atoms.clone(),
            errors: rows.iter().map(|&i| self.errors[i]).collect(),
            error_names: rows.iter().map(|&i| self.error_names[i].clone()).collect(),
            angular: rows.iter().map(|&i| self.angular[i]).collect(),
            gains: self.gains.select(rows),
        }
    }

    /// The atom used in the polynomials for `kind`.
    pub fn atom(&self, kind: AtomKind) -> Atom {
        self.atoms.find(kind)
    }

    /// The named intermediates of the shared form (none for a chain short enough to expand).
    pub fn intermediates(&self) -> &Intermediates {
        self.gains.intermediates()
    }
}
