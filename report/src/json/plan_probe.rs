//! The probe plan report (`rtest plan --probe --json`): the probing poses of a touch-probe
//! kinematics calibration, the predicted uncertainty and valuation number of every parameter
//! and of every rotary axis, and how the number of positions per axis was chosen
//! (docs/probe-plan.md).
//!
//! ```json
//! {"machine": "seed-ac", "fingerprint": "…", "model": "reduced", "terms": ["XOW", …],
//!  "constraint": [], "probe": {"name": null, "tip_radius_mm": 1.5, "sphere_radius_mm": 12.5,
//!  "noise_um": 0.5, "centre_std_um": [0.2, 0.2, 0.3]}, "params_mm": {"Xa": 0.0, …},
//!  "per_axis": 3, "mode": "auto", "targets": {"um": 1.0, "urad": 5.0}, "min_valuation": 2.0,
//!  "sweeps": [{"axis": "A", "from_deg": -90.0, "to_deg": 90.0, "full_turn": false,
//!              "positions_deg": [-90.0, 0.0, 90.0]}, …],
//!  "poses": [{"label": "A-90", "axis": "A", "angle_deg": -90.0,
//!             "commands": {"X": 0.279, "A": -90.0, …}}, …],
//!  "skipped": [{"label": "C90", "axis": "C", "angle_deg": 90.0, "reason": "…"}],
//!  "samples": 6, "readings": 18,
//!  "parameters": [{"name": "YOA", "error": "YOA", "basis": "const", "owner": "shared",
//!                  "unit": "um", "determined": true, "fixed": false, "std": 0.24,
//!                  "valuation": 4.15, "grade": "4 or more"}, …],
//!  "rank": 11, "columns": 11, "condition": 3.1, "confounded": [],
//!  "axes": [{"axis": "A", "parameters": ["YOA", "ZOA", "BOA", "COA"], "valuation": 2.86,
//!            "parameter": "ZOA", "grade": "2 or more"}, …],
//!  "auto": {"met": true, "tried": [{"per_axis": 3, "valuation": 2.09, "parameter": "YOC"}],
//!           "below": []}}
//! ```
//!
//! `std` (µm or µrad) and `valuation` (target ÷ std) are `null` for a parameter the poses do
//! not determine or that the constraint holds at 0 (`fixed`); an axis's `valuation` is the least
//! among its determined parameters of interest, `null` when none is determined. `auto` is
//! `null` for a number of positions given. Every number is finite.

use super::{NonFinite, Ordered, finite, finite_opt};
use fitting::Constraint;
use fitting::plan::Targets;
use fitting::plan::probe::{Grade, ProbePlan, Tried, axis_valuations, valuations};
use model_spec::units::UM_PER_MM;
use model_spec::{AxisKind, Machine};
use serde::Serialize;
use simulation::model::Model;

/// The probe and what one pose's sphere fit gives.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProbeReport {
    /// The probe file's name, if it gives one.
    pub name: Option<String>,
    /// The stylus tip's radius, mm.
    pub tip_radius_mm: f64,
    /// The sphere's calibrated radius, mm.
    pub sphere_radius_mm: f64,
    /// The probe's σ along the approach, µm.
    pub noise_um: f64,
    /// The standard uncertainty of a pose's fitted centre along x, y, z of the probe frame
    /// (across and along the stylus), µm (the default pattern, free radius).
    pub centre_std_um: [f64; 3],
}

/// The interval an axis is stepped over and its positions.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepReport {
    /// The axis's letter.
    pub axis: String,
    /// The interval's start, degrees.
    pub from_deg: f64,
    /// Its end, degrees (for a full turn, the start plus 360°, not measured).
    pub to_deg: f64,
    /// Whether it is a full turn.
    pub full_turn: bool,
    /// The positions, degrees, skipped ones included.
    pub positions_deg: Vec<f64>,
}

/// One planned pose.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoseReport {
    /// Its label.
    pub label: String,
    /// The stepped axis's letter.
    pub axis: String,
    /// Its position, degrees.
    pub angle_deg: f64,
    /// Every axis's command (linear mm, rotary degrees), linear axes then rotary, ISO order
    /// (the columns of the path CSV).
    pub commands: Ordered<f64>,
}

/// A pose left out.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SkippedPoseReport {
    /// Its label.
    pub label: String,
    /// The stepped axis's letter.
    pub axis: String,
    /// Its position, degrees.
    pub angle_deg: f64,
    /// Why.
    pub reason: String,
}

/// One parameter of the planned campaign.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProbeParameterReport {
    /// Its name (`XOC`, `XOW[probe]`).
    pub name: String,
    /// The effect.
    pub error: String,
    /// The basis column.
    pub basis: String,
    /// `shared` (the machine's) or the label of its set-up.
    pub owner: String,
    /// `um` or `urad` (`ms` for a servo lag).
    pub unit: String,
    /// Whether the poses determine it.
    pub determined: bool,
    /// Held at 0 by the constraint.
    pub fixed: bool,
    /// Its predicted standard uncertainty in `unit`; `null` when not determined.
    pub std: Option<f64>,
    /// Its valuation number, target ÷ std; `null` when not determined.
    pub valuation: Option<f64>,
    /// The valuation's grade (`below 2`, `2 or more`, `4 or more`); `null` when not determined.
    pub grade: Option<String>,
}

/// The valuation of one rotary axis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisValuationReport {
    /// The axis's letter.
    pub axis: String,
    /// Its parameters of interest (its component and location errors in the model).
    pub parameters: Vec<String>,
    /// The least valuation among the determined ones; `null` when none is.
    pub valuation: Option<f64>,
    /// The parameter that has it.
    pub parameter: Option<String>,
    /// Its grade.
    pub grade: Option<String>,
}

/// One number of positions tried by `--per-axis auto`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TriedReport {
    /// Positions per rotary axis.
    pub per_axis: usize,
    /// The least valuation among the determined parameters of interest; `null` when the
    /// campaign had too few readings for its parameters or determined none of interest.
    pub valuation: Option<f64>,
    /// The parameter that has it.
    pub parameter: Option<String>,
}

/// How `auto` chose.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AutoReport {
    /// Whether the plan chosen gives every determined parameter of interest the valuation
    /// asked for.
    pub met: bool,
    /// Every number tried, in order.
    pub tried: Vec<TriedReport>,
    /// The determined parameters of interest below it in the plan chosen.
    pub below: Vec<String>,
}

/// The probe plan report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlanProbeReport {
    /// Machine name.
    pub machine: String,
    /// The machine's fingerprint.
    pub fingerprint: String,
    /// The model's label.
    pub model: String,
    /// The machine's model it starts from; absent for a list of terms only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_model: Option<String>,
    /// The terms, in order.
    pub terms: Vec<String>,
    /// The parameters held at 0 (the campaign's names).
    pub constraint: Vec<String>,
    /// The probe.
    pub probe: ProbeReport,
    /// The kinematic parameters, mm.
    pub params_mm: Ordered<f64>,
    /// Positions per rotary axis.
    pub per_axis: usize,
    /// `auto` or `given`.
    pub mode: String,
    /// The targets, µm and µrad (ms for servo lags).
    pub targets: super::plan::TargetsReport,
    /// The least valuation `auto` asks of every determined parameter of interest.
    pub min_valuation: f64,
    /// The rotary axes' intervals and positions.
    pub sweeps: Vec<SweepReport>,
    /// The poses kept, in measuring order.
    pub poses: Vec<PoseReport>,
    /// The poses skipped.
    pub skipped: Vec<SkippedPoseReport>,
    /// Samples (poses kept).
    pub samples: usize,
    /// Readings (3 per pose).
    pub readings: usize,
    /// Every parameter, in column order.
    pub parameters: Vec<ProbeParameterReport>,
    /// Numerical rank of the column-scaled H.
    pub rank: usize,
    /// Columns.
    pub columns: usize,
    /// Condition number; `null` at rank 0.
    pub condition: Option<f64>,
    /// Groups the poses cannot separate.
    pub confounded: Vec<Vec<String>>,
    /// The valuation of every rotary axis.
    pub axes: Vec<AxisValuationReport>,
    /// How `auto` chose; `null` for a number given.
    pub auto: Option<AutoReport>,
}

/// The probe of a plan, for the report.
#[derive(Clone, Copy, Debug)]
pub struct ProbeSource<'a> {
    /// The probe file's name, if any.
    pub name: Option<&'a str>,
    /// Tip radius, mm.
    pub tip_radius_mm: f64,
    /// Sphere radius, mm.
    pub sphere_radius_mm: f64,
    /// σ, mm.
    pub noise_mm: f64,
    /// A pose's centre covariance, bed frame, mm².
    pub centre_covariance_mm2: [[f64; 3]; 3],
}

/// How `auto` chose, for the report.
#[derive(Clone, Copy, Debug)]
pub struct AutoSource<'a> {
    /// Whether the valuation was met.
    pub met: bool,
    /// The numbers tried.
    pub tried: &'a [Tried],
    /// The columns below the valuation.
    pub below: &'a [usize],
}

/// What a probe plan report is made of.
#[derive(Clone, Copy, Debug)]
pub struct PlanProbeSource<'a> {
    /// The model's label.
    pub label: &'a str,
    /// The machine's model it starts from, if any.
    pub base_model: Option<&'a str>,
    /// The model.
    pub model: &'a Model,
    /// The probe.
    pub probe: ProbeSource<'a>,
    /// The kinematic parameters, mm.
    pub params: &'a [f64],
    /// The plan.
    pub plan: &'a ProbePlan,
    /// The targets.
    pub targets: &'a Targets,
    /// The least valuation asked.
    pub min_valuation: f64,
    /// How `auto` chose; `None` for a number given.
    pub auto: Option<AutoSource<'a>>,
}

fn grade(v: Option<f64>) -> Option<String> {
    v.map(|v| Grade::of(v).words().to_string())
}

impl PlanProbeReport {
    /// The report of `s` on machine `m`.
    ///
    /// # Errors
    /// [`NonFinite`] when a number is not finite.
    pub fn new(m: &Machine, s: PlanProbeSource) -> Result<PlanProbeReport, NonFinite> {
        let plan = s.plan;
        let p = &plan.prediction;
        let values = valuations(m, p, s.targets);
        let fixed: Vec<String> = match &plan.constraint {
            Constraint::Zero(names) => names.clone(),
            _ => Vec::new(),
        };
        let name = |j: usize| p.names[j].clone();
        let mut parameters = Vec::with_capacity(p.names.len());
        for (j, c) in p.layout.columns.iter().enumerate() {
            let f = c.term.display_factor(m);
            let basis = c.term.basis.column_names();
            let v = finite_opt(|| format!("parameters[{j}].valuation"), values[j])?;
            parameters.push(ProbeParameterReport {
                name: name(j),
                error: c.term.effect.name(m),
                basis: basis.get(c.component).unwrap_or(&basis[0]).clone(),
                owner: p.layout.owner_label(c.owner).to_string(),
                unit: c.term.unit(m).to_string(),
                determined: p.determined[j],
                fixed: fixed.contains(&p.names[j]),
                std: finite_opt(
                    || format!("parameters[{j}].std"),
                    p.std[j].filter(|_| p.determined[j]).map(|x| x * f),
                )?,
                valuation: v,
                grade: grade(v),
            });
        }
        let letter = |a: usize| m.axes[a].name.clone();
        let axes = axis_valuations(m, p, &values)
            .into_iter()
            .map(|a| {
                let v = a.least.map(|(_, v)| v);
                Ok(AxisValuationReport {
                    axis: letter(a.axis),
                    parameters: a.columns.iter().map(|&j| name(j)).collect(),
                    valuation: finite_opt(|| format!("axes.{}.valuation", letter(a.axis)), v)?,
                    parameter: a.least.map(|(j, _)| name(j)),
                    grade: grade(v),
                })
            })
            .collect::<Result<Vec<_>, NonFinite>>()?;
        let order = formats::csv::column_order(m);
        let commands = |q: &[f64], field: &str| -> Result<Ordered<f64>, NonFinite> {
            order
                .iter()
                .map(|&i| (&m.axes[i], q[i]))
                .map(|(a, x)| {
                    let shown = match a.kind {
                        AxisKind::Linear => x,
                        AxisKind::Rotary => x.to_degrees(),
                    };
                    Ok((
                        a.name.clone(),
                        finite(|| format!("{field}.{}", a.name), shown)?,
                    ))
                })
                .collect::<Result<Vec<_>, _>>()
                .map(Ordered)
        };
        let poses = plan
            .poses
            .poses
            .iter()
            .enumerate()
            .map(|(i, x)| {
                Ok(PoseReport {
                    label: x.label.clone(),
                    axis: letter(x.axis),
                    angle_deg: finite(|| format!("poses[{i}].angle_deg"), x.angle_deg)?,
                    commands: commands(&x.commands, &format!("poses[{i}].commands"))?,
                })
            })
            .collect::<Result<Vec<_>, NonFinite>>()?;
        let n = plan.poses.per_axis;
        let cov = s.probe.centre_covariance_mm2;
        let centre_std_um = [0, 1, 2].map(|k| cov[k][k].sqrt() * UM_PER_MM);
        for (k, x) in centre_std_um.iter().enumerate() {
            finite(|| format!("probe.centre_std_um[{k}]"), *x)?;
        }
        let auto = s.auto.map(|a| {
            Ok::<_, NonFinite>(AutoReport {
                met: a.met,
                tried: a
                    .tried
                    .iter()
                    .map(|t| {
                        Ok(TriedReport {
                            per_axis: t.per_axis,
                            valuation: finite_opt(
                                || format!("auto.tried[{}].valuation", t.per_axis),
                                t.least.map(|(_, v)| v),
                            )?,
                            parameter: t.least.map(|(j, _)| name(j)),
                        })
                    })
                    .collect::<Result<Vec<_>, NonFinite>>()?,
                below: a.below.iter().map(|&j| name(j)).collect(),
            })
        });
        Ok(PlanProbeReport {
            machine: m.name.clone(),
            fingerprint: m.fingerprint(),
            model: s.label.to_string(),
            base_model: s.base_model.map(str::to_string),
            terms: s.model.terms.iter().map(|t| t.spelling(m)).collect(),
            constraint: fixed,
            probe: ProbeReport {
                name: s.probe.name.map(str::to_string),
                tip_radius_mm: s.probe.tip_radius_mm,
                sphere_radius_mm: s.probe.sphere_radius_mm,
                noise_um: s.probe.noise_mm * UM_PER_MM,
                centre_std_um,
            },
            params_mm: Ordered(
                m.symbols
                    .iter()
                    .zip(s.params)
                    .map(|(sym, &x)| {
                        Ok((
                            sym.name.clone(),
                            finite(|| format!("params_mm.{}", sym.name), x)?,
                        ))
                    })
                    .collect::<Result<Vec<_>, NonFinite>>()?,
            ),
            per_axis: n,
            mode: if s.auto.is_some() { "auto" } else { "given" }.to_string(),
            targets: super::plan::TargetsReport {
                um: s.targets.um,
                urad: s.targets.urad,
                ms: s.targets.ms,
            },
            min_valuation: s.min_valuation,
            sweeps: plan
                .poses
                .sweeps
                .iter()
                .map(|w| SweepReport {
                    axis: letter(w.axis),
                    from_deg: w.from_deg,
                    to_deg: w.to_deg,
                    full_turn: w.full_turn,
                    positions_deg: w.angles_deg(n),
                })
                .collect(),
            poses,
            skipped: plan
                .poses
                .skipped
                .iter()
                .map(|x| SkippedPoseReport {
                    label: x.label.clone(),
                    axis: letter(x.axis),
                    angle_deg: x.angle_deg,
                    reason: x.reason.clone(),
                })
                .collect(),
            samples: p.samples,
            readings: 3 * p.samples,
            parameters,
            rank: p.rank,
            columns: p.names.len(),
            condition: finite_opt(|| "condition".into(), p.condition)?,
            confounded: p
                .confounded
                .iter()
                .map(|g| g.iter().map(|&j| name(j)).collect())
                .collect(),
            axes,
            auto: auto.transpose()?,
        })
    }
}
