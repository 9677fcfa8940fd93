//! Kinematic offsets as unknowns: the gain of a kinematic symbol of the description (`Zt`,
//! `Xw`, `Xc`), what its identified change does to the exact machine, and who owns it in a
//! campaign.
//!
//! **The gain.** A term `KinematicOffset(s)` has as coefficient the change `δ` (mm) of symbol
//! `s` from the value the record is modelled with. Its gain is the derivative of the
//! tool-minus-workpiece vector in the nominal tool frame with respect to the symbol, mm/mm:
//!
//! ```text
//! g_s = R_tool0ᵀ · (∂P_tool/∂s − ∂P_work/∂s),     ∂P/∂s = Σ over the offsets that use s: R_k · e_c
//! ```
//!
//! where `R_k` is the nominal rotation of the chain just before the offset (the product of the
//! rotary motions and of the turns into and out of inclined axes' own frames between the bed
//! and it, [`model_spec::kinematics::chain_steps`]) and `e_c` the
//! coordinate direction of the offset's entry that names `s`. Offsets only translate and no
//! rotation depends on a symbol, so the nominal chain is affine in its symbols: this gain is
//! exact, not a linearisation, at every pose (on or off the ball) and for any size of `δ`.
//! A symbol turns no frame, so its orientation gain is zero. The gain does not depend on the
//! symbols' values.
//!
//! **The exact machine.** The refinement and the exact prediction add each identified change
//! to its symbol's value ([`apply_kinematic_offsets`]): the exact chain then runs with the
//! identified lengths.
//!
//! **Campaigns.** A kinematic offset of the machine (a pivot length, the position of a rotary
//! axis) is one length of one machine, shared by every record: all records must be modelled
//! with the same value of it ([`check_shared_symbols`]), else one change would mean two
//! different lengths. A symbol of the workpiece set-up (one used only in the offset of the work
//! chain's end, `Xw Yw Zw`: [`model_spec::Machine::workpiece_symbols`]) is where one ball was
//! mounted: it belongs to a set-up like `XOW YOW ZOW` ([`is_setup_symbol`]), since a ball
//! mounted anew has a position of its own.

use model_spec::kinematics::{Step, chain_steps};
use model_spec::units::short;
use model_spec::{AxisKind, Machine, Side, SymbolId, Value};
use nalgebra::{Matrix3, Vector3};
use simulation::exact::{coordinate_rotation, frame_rotation};
use simulation::model::{Effect, Model};

/// The gains of a machine's kinematic symbols: both chains lowered once, so that evaluating
/// them along a path lowers nothing again.
#[derive(Clone, Debug)]
pub struct OffsetGains<'m> {
    machine: &'m Machine,
    work: Vec<Step>,
    tool: Vec<Step>,
}

impl<'m> OffsetGains<'m> {
    /// Lowers both chains of `m` with [`chain_steps`].
    pub fn new(m: &'m Machine) -> OffsetGains<'m> {
        OffsetGains {
            machine: m,
            work: chain_steps(m, Side::Work),
            tool: chain_steps(m, Side::Tool),
        }
    }

    /// `Σ R_k · e_c` over the offsets of the chain `steps` that use each symbol (mm/mm, bed
    /// frame), added into `out` with `sign`; returns the nominal rotation of the chain's end.
    fn walk(
        &self,
        steps: &[Step],
        commands: &[f64],
        sign: f64,
        out: &mut [Vector3<f64>],
    ) -> Matrix3<f64> {
        let m = self.machine;
        let mut r = Matrix3::identity();
        for step in steps {
            match step {
                Step::Offset(o) => {
                    for (c, v) in o.iter().enumerate() {
                        if let Value::Symbol(s) = v {
                            out[*s] += r.column(c) * sign;
                        }
                    }
                }
                Step::Motion { axis, .. } => {
                    let a = &m.axes[*axis];
                    if a.kind == AxisKind::Rotary {
                        let own = a.direction.own;
                        let q = own.sign() * commands[*axis];
                        r *= coordinate_rotation(own.dir, q).matrix();
                    }
                }
                // Into (or back out of) an inclined axis's own frame, as the exact chain has it.
                Step::Frame { axis, turn } => {
                    r *= frame_rotation(&m.axes[*axis].direction, *turn).matrix();
                }
                // Errors are zero in the nominal chain: identity.
                Step::ErrorTranslation(_) | Step::ErrorRotation(_) => {}
            }
        }
        r
    }

    /// The position gain `[gx, gy, gz]` (tool frame, mm/mm) of every kinematic symbol, in
    /// symbol order, at `commands` (one per axis: mm, rad).
    ///
    /// # Panics
    /// When `commands` does not have one entry per axis of the machine.
    pub fn gains(&self, commands: &[f64]) -> Vec<[f64; 3]> {
        let m = self.machine;
        assert_eq!(
            commands.len(),
            m.axes.len(),
            "machine `{}`: expected one command per axis ({}), got {}",
            m.name,
            m.axes.len(),
            commands.len()
        );
        let mut d = vec![Vector3::zeros(); m.symbols.len()];
        self.walk(&self.work, commands, -1.0, &mut d);
        let r_tool = self.walk(&self.tool, commands, 1.0, &mut d);
        d.iter()
            .map(|v| {
                let g = r_tool.transpose() * v;
                [g.x + 0.0, g.y + 0.0, g.z + 0.0]
            })
            .collect()
    }
}

/// `true` when symbol `s` of `m` places the workpiece of one set-up (it is used only in the
/// offset of the work chain's end: `Xw Yw Zw`), so that a campaign gives it one change per
/// set-up; `false` for a kinematic offset of the machine, shared by every record.
pub fn is_setup_symbol(m: &Machine, s: SymbolId) -> bool {
    m.workpiece_symbols().contains(&s)
}

/// `model` without its kinematic offsets, their `values` (one per model column, mm; `None`
/// as 0) added to the symbols of `params` (mm, symbol order): the model, the values of its
/// other columns and the kinematic parameters the exact machine runs with.
pub fn apply_kinematic_offsets(
    model: &Model,
    values: &[Option<f64>],
    params: &[f64],
) -> (Model, Vec<Option<f64>>, Vec<f64>) {
    let mut params = params.to_vec();
    let mut rest = Model::default();
    let mut kept = Vec::with_capacity(values.len());
    let mut at = 0;
    for t in &model.terms {
        let w = t.basis.width();
        match t.effect {
            Effect::KinematicOffset(s) => {
                for v in &values[at..at + w] {
                    params[s] += v.unwrap_or(0.0);
                }
            }
            _ => {
                rest.terms.push(*t);
                kept.extend_from_slice(&values[at..at + w]);
            }
        }
        at += w;
    }
    (rest, kept, params)
}

/// `true` when `model` has a kinematic offset.
pub fn has_kinematic_offsets(model: &Model) -> bool {
    model
        .terms
        .iter()
        .any(|t| matches!(t.effect, Effect::KinematicOffset(_)))
}

/// Checks that every kinematic offset of the machine in `model` (a symbol not of the workpiece
/// set-up, [`is_setup_symbol`]) has one value in every record: `records` gives each record's
/// label and kinematic parameters (mm, symbol order). A shared change of a length the records
/// are modelled with at different values would be two different lengths.
///
/// # Errors
/// A message naming the symbol and two records with their values.
pub fn check_shared_symbols(
    m: &Machine,
    model: &Model,
    records: &[(&str, &[f64])],
) -> Result<(), String> {
    for t in &model.terms {
        let Effect::KinematicOffset(s) = t.effect else {
            continue;
        };
        if is_setup_symbol(m, s) {
            continue;
        }
        let Some(&(first, p0)) = records.first() else {
            continue;
        };
        if let Some(&(other, p)) = records.iter().find(|(_, p)| p[s] != p0[s]) {
            return Err(format!(
                "kinematic offset `{}` is one length of the machine, identified as one change shared by every record, but records `{first}` and `{other}` are modelled with different values of it ({} and {} mm): give every record the same `{}`, or identify the campaign's records one by one",
                m.symbols[s].name,
                short(p0[s]),
                short(p[s]),
                m.symbols[s].name
            ));
        }
    }
    Ok(())
}

/// The value (mm) the change of each column is relative to, for the columns of `model` that
/// are kinematic offsets (`params[s]`, mm), `None` for the others: one entry per column.
pub fn nominal_of_columns(model: &Model, params: &[f64]) -> Vec<Option<f64>> {
    model
        .columns()
        .into_iter()
        .map(|(t, _)| model.terms[t].effect.symbol().map(|s| params[s]))
        .collect()
}
