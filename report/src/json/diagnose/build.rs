//! The diagnosis report built from a diagnosis ([`DiagnosisReport::new`]) and what it says
//! besides the diagnosis ([`DiagnosisSource`]: the files, the options, the model written):
//! values in µm and µrad, every number checked finite.

use super::super::diagnose_records::{notes, records};
use super::super::verdict::{adequacy, outliers, unexplained};
use super::super::{NonFinite, finite, finite_opt};
use super::*;
use diagnosis::confirm::Judges;
use diagnosis::harmonic::harmonic;
use diagnosis::structure::Component;
use diagnosis::{Correction, DiagnoseOptions, Diagnosis};
use model_spec::Machine;
use model_spec::units::UM_PER_MM;
use simulation::model::{Basis, Carrier, Term};

/// What the report says besides the diagnosis: where things come from and go.
#[derive(Clone, Debug)]
pub struct DiagnosisSource<'a> {
    /// `--machine` as given.
    pub machine_source: &'a str,
    /// The base model's label.
    pub label: &'a str,
    /// The fitted records' files, one per record in order.
    pub data: Vec<String>,
    /// The held-out records' files, one per record in order.
    pub held_out: Vec<String>,
    /// The command-line words that give the fitted records to another command.
    pub data_arguments: Vec<String>,
    /// The options of the diagnosis.
    pub opts: &'a DiagnoseOptions,
    /// The extended machine description written: the model's name and the file.
    pub model_out: Option<(String, String)>,
}

impl DiagnosisSource<'_> {
    /// The file of the record labelled `label` (fitted or held out) in diagnosis `d`; the label
    /// itself when it has none.
    pub fn file_of(&self, d: &Diagnosis, label: &str) -> String {
        let fitted = d.records.iter().position(|r| r.label == label);
        let held = d.validation.iter().position(|h| h.name == label);
        match (fitted, held) {
            (Some(i), _) => self.data.get(i),
            (None, Some(i)) => self.held_out.get(i),
            (None, None) => None,
        }
        .cloned()
        .unwrap_or_else(|| label.to_string())
    }
}

/// The entries of [`Diagnosis::position_or_time`], with the `rtest plan` command of each: the
/// two terms planned on the axis's turn at the ball position of the first record on which the
/// axis moves monotonically (`--param` for what differs from the description's defaults).
fn position_or_time(
    m: &Machine,
    source: &DiagnosisSource,
    d: &Diagnosis,
) -> Result<Vec<PositionOrTimeReport>, NonFinite> {
    use diagnosis::separable::Verdict;
    let defaults = m.default_parameters();
    d.position_or_time
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let field = |what: &str| format!("position_or_time[{i}].{what}");
            let plan_command = (!e.plan_arguments.is_empty()).then(|| {
                let mut words = vec![
                    "rtest".to_string(),
                    "plan".into(),
                    "--machine".into(),
                    source.machine_source.to_string(),
                ];
                words.extend(e.plan_arguments.iter().cloned());
                let params = e
                    .monotonic
                    .first()
                    .and_then(|l| d.records.iter().find(|r| &r.label == l))
                    .map(|r| r.params.clone())
                    .unwrap_or_default();
                let changed: Vec<String> = m
                    .symbols
                    .iter()
                    .zip(&params)
                    .zip(&defaults)
                    .filter(|((_, x), y)| x.to_bits() != y.to_bits())
                    .map(|((s, x), _)| format!("{}={}", s.name, model_spec::units::short(*x)))
                    .collect();
                if !changed.is_empty() {
                    words.push("--param".into());
                    words.push(changed.join(","));
                }
                words.join(" ")
            });
            Ok(PositionOrTimeReport {
                position: e.position.spelling(m),
                time: e.time.spelling(m),
                chosen: e.chosen.spelling(m),
                verdict: match e.verdict {
                    Verdict::Undecided => "cannot be told apart",
                    Verdict::Position => "position preferred",
                    Verdict::Time => "time preferred",
                }
                .into(),
                axis: e.axis.clone(),
                monotonic: e.monotonic.iter().map(|l| source.file_of(d, l)).collect(),
                time_in_position: finite(|| field("time_in_position"), e.time_in_position)?,
                position_in_time: finite(|| field("position_in_time"), e.position_in_time)?,
                threshold: diagnosis::separable::COLLINEAR_COSINE,
                position_beyond_time_p: finite(
                    || field("position_beyond_time_p"),
                    e.position_beyond_time_p,
                )?,
                time_beyond_position_p: finite(
                    || field("time_beyond_position_p"),
                    e.time_beyond_position_p,
                )?,
                separating: e.separating.clone(),
                plan_command,
            })
        })
        .collect()
}

fn spell(m: &Machine, ts: &[Term]) -> Vec<String> {
    ts.iter().map(|t| t.spelling(m)).collect()
}

/// The largest components of `c`; with `after`, each with what the same shape explains there.
fn components(
    field: &str,
    c: &[Component],
    after: Option<&[Component]>,
) -> Result<Vec<ComponentReport>, NonFinite> {
    c.iter()
        .take(COMPONENTS_LISTED)
        .enumerate()
        .map(|(i, c)| {
            let same = |x: &&Component| {
                x.source == c.source && x.shape == c.shape && x.direction == c.direction
            };
            let extended = after.map(|a| a.iter().find(same).map_or(0.0, |x| x.explained_rms_um));
            Ok(ComponentReport {
                extended_rms_um: finite_opt(
                    || format!("structure.{field}[{i}].extended_rms_um"),
                    extended,
                )?,
                source: c.source.clone(),
                shape: c.shape.clone(),
                direction: ["x", "y", "z"][c.direction].into(),
                explained_rms_um: finite(
                    || format!("structure.{field}[{i}].explained_rms_um"),
                    c.explained_rms_um,
                )?,
            })
        })
        .collect()
}

fn gain_row(
    field: &str,
    data: &str,
    before: f64,
    after: f64,
    undetermined: Vec<Vec<String>>,
) -> Result<GainRow, NonFinite> {
    Ok(GainRow {
        estimable: undetermined.is_empty(),
        undetermined,
        data: data.into(),
        residual_rms_um_before: finite(
            || format!("{field}.residual_rms_um_before"),
            before * UM_PER_MM,
        )?,
        residual_rms_um_after: finite(
            || format!("{field}.residual_rms_um_after"),
            after * UM_PER_MM,
        )?,
    })
}

/// The gain rows of held-out (or left-out) records, each named by its file.
fn held_rows(
    field: &str,
    rows: &[diagnosis::heldout::HeldOut],
    file_of: &dyn Fn(&str) -> String,
) -> Result<Vec<GainRow>, NonFinite> {
    rows.iter()
        .enumerate()
        .map(|(i, h)| {
            let mut groups = h.undetermined_before.clone();
            for g in &h.undetermined_after {
                if !groups.contains(g) {
                    groups.push(g.clone());
                }
            }
            gain_row(
                &format!("{field}[{i}]"),
                &file_of(&h.name),
                h.before_rms,
                h.after_rms,
                groups,
            )
        })
        .collect()
}

impl DiagnosisReport {
    /// The report of `d` on machine `m`.
    ///
    /// # Errors
    /// [`NonFinite`] when a value or statistic is not finite.
    pub fn new(
        m: &Machine,
        source: &DiagnosisSource,
        d: &Diagnosis,
    ) -> Result<DiagnosisReport, NonFinite> {
        let o = source.opts;
        let mut findings = Vec::new();
        for (i, f) in d.findings.iter().enumerate() {
            let field = |what: &str| format!("findings[{i}].{what}");
            let k = f.term.display_factor(m);
            let h = harmonic(m, d, f);
            findings.push(FindingReport {
                error: f.term.effect.name(m),
                basis: f.term.basis.to_string(),
                description: f.description.clone(),
                axis: match f.term.effect.carrier(m) {
                    Carrier::Axis(a) => Some(m.axes[a].name.clone()),
                    Carrier::None => None,
                },
                values: f
                    .values
                    .iter()
                    .map(|v| finite_opt(|| field("values"), v.map(|v| v * k)))
                    .collect::<Result<_, _>>()?,
                stds: f
                    .stds
                    .iter()
                    .map(|s| finite_opt(|| field("stds"), s.map(|s| s * k)))
                    .collect::<Result<_, _>>()?,
                unit: f.term.unit(m).into(),
                columns: f.term.basis.column_names(),
                harmonic: match h {
                    Some(h) => Some(HarmonicReport {
                        amplitude: finite(|| field("amplitude"), h.amplitude)?,
                        amplitude_std: finite_opt(|| field("amplitude_std"), h.amplitude_std)?,
                        phase_deg: finite(|| field("phase_deg"), h.phase_deg)?,
                        phase_std_deg: finite_opt(|| field("phase_std_deg"), h.phase_std_deg)?,
                    }),
                    None => None,
                },
                explained_fraction: finite(|| field("explained_fraction"), f.explained_fraction)?,
                f: finite(|| field("f"), f.f)?,
                p_value: finite(|| field("p_value"), f.p_value)?,
                correction: match f.correction {
                    Correction::Bonferroni => "bonferroni",
                    Correction::MonteCarlo => "monte-carlo",
                }
                .into(),
                candidates_tried: f.candidates_tried,
                alternatives: spell(m, &f.alternatives),
                size: finite(|| field("size"), f.size)?,
                limit: f.limit,
                plausible: f.plausible,
                scan: f.scan.map(|sc| {
                    let (parameter, unit) = match f.term.basis {
                        Basis::Period(_) => ("P", "mm"),
                        Basis::Exp(_) | Basis::Warmup(_) => ("TAU", "s"),
                        Basis::Jump(_) => ("T", "s"),
                        _ => match f.term.effect.carrier(m) {
                            Carrier::Axis(a) if m.axes[a].kind == model_spec::AxisKind::Rotary => {
                                ("V", "deg")
                            }
                            _ => ("V", "mm"),
                        },
                    };
                    ScanReport {
                        parameter: parameter.into(),
                        value: sc.value,
                        low: sc.low,
                        high: sc.high,
                        unit: unit.into(),
                    }
                }),
                status: if !f.plausible {
                    "implausible"
                } else if f.is_jump() {
                    "jump"
                } else if d.is_cause(f) {
                    "cause"
                } else {
                    "not confirmed"
                }
                .into(),
                confirmation: match &f.confirmation {
                    Some(c) => Some(ConfirmationReport {
                        judged_by: match c.judges {
                            Judges::HeldOut => "held-out",
                            Judges::LeftOut => "left-out",
                        }
                        .into(),
                        gain_sd: finite(|| field("confirmation.gain_sd"), c.gain_sd)?,
                        confirmed: c.confirmed,
                        not_judged: !c.judged,
                        unjudged: c.unjudged.clone(),
                        replaces: c.replaces.map(|t| t.spelling(m)),
                        tried: c
                            .tried
                            .iter()
                            .map(|&(t, z)| {
                                Ok(TriedReport {
                                    term: t.spelling(m),
                                    gain_sd: finite(|| field("confirmation.tried.gain_sd"), z)?,
                                })
                            })
                            .collect::<Result<_, NonFinite>>()?,
                    }),
                    None => None,
                },
            });
        }
        let (name, file) = match &source.model_out {
            Some((n, f)) => (Some(n.clone()), Some(f.clone())),
            None => (None, None),
        };
        let fit = &d.base_fit.fit;
        let data = source.data.join(",");
        let file_of = |label: &str| source.file_of(d, label);
        Ok(DiagnosisReport {
            version: VERSION,
            machine: m.name.clone(),
            machine_source: source.machine_source.into(),
            data: data.clone(),
            data_arguments: source.data_arguments.clone(),
            samples: d.records.iter().map(|r| r.samples).sum(),
            held_out: d
                .validation
                .iter()
                .map(|h| (file_of(&h.name), h.samples))
                .collect(),
            records: records(m, d, &file_of)?,
            base_model: source.label.into(),
            zeroed: d.records.iter().any(|r| r.zeroed),
            alpha: o.alpha,
            draws: o.draws,
            dictionary_extent: [o.dictionary.harmonics, o.dictionary.poly, o.dictionary.time],
            base_fit: BaseFitReport {
                terms: spell(m, &d.base.terms),
                residual_rms_um: finite(
                    || "base_fit.residual_rms_um".into(),
                    d.fit_rms.0 * UM_PER_MM,
                )?,
                sigma_um: finite_opt(
                    || "base_fit.sigma_um".into(),
                    fit.sigma.map(|s| s * UM_PER_MM),
                )?,
                residual_rms_um_with_outliers: finite(
                    || "base_fit.residual_rms_um_with_outliers".into(),
                    d.fit_rms_with_outliers * UM_PER_MM,
                )?,
                dof: fit.dof,
            },
            structure: StructureReport {
                before: components("before", &d.structure_before, Some(&d.structure_after))?,
                after: components("after", &d.structure_after, None)?,
            },
            dictionary_size: d.dictionary_size,
            unexcited: spell(m, &d.unexcited),
            findings,
            stop: StopReport {
                reason: d.stop.reason.clone(),
                best_remaining: d.stop.best.map(|t| t.spelling(m)),
                p_value: finite(|| "stop.p_value".into(), d.stop.p_value)?,
            },
            confounded: d
                .confounded
                .iter()
                .map(|c| ConfoundedReport {
                    error: c.term.effect.name(m),
                    basis: c.term.basis.to_string(),
                    with: spell(m, &c.with),
                })
                .collect(),
            position_or_time: position_or_time(m, source, d)?,
            extended_model: ExtendedModelReport {
                label: d.extended_label(m, source.label),
                terms: spell(m, &d.extended_terms().terms),
                added: d
                    .findings
                    .iter()
                    .filter(|f| f.in_model)
                    .map(|f| f.term.spelling(m))
                    .collect(),
                name,
                file,
            },
            gain: GainReport {
                fit: gain_row("gain.fit", &data, d.fit_rms.0, d.fit_rms.1, Vec::new())?,
                validation: held_rows("gain.validation", &d.validation, &file_of)?,
                left_out: held_rows("gain.left_out", &d.left_out, &file_of)?,
            },
            outliers: outliers(d, &file_of)?,
            budget: BudgetReport {
                um: o.budget.um,
                urad: o.budget.urad,
                ms: o.budget.ms,
                fraction: o.budget.fraction,
                um_per_s: o.budget.um_per_s,
                urad_per_s: o.budget.urad_per_s,
            },
            recommended: d.recommendation.recommended,
            recommendation: d
                .recommendation_named(if d.validation.is_empty() {
                    &source.data
                } else {
                    &source.held_out
                })
                .reasons,
            noise_model: d.noise.to_string(),
            adequacy: match &d.adequacy {
                Ok(a) => Some(adequacy(a, &file_of)?),
                Err(_) => None,
            },
            adequacy_unavailable: d.adequacy.as_ref().err().cloned(),
            unexplained: d
                .unexplained
                .iter()
                .enumerate()
                .map(|(i, u)| unexplained(i, u, &file_of))
                .collect::<Result<_, _>>()?,
            groups: d
                .groups
                .iter()
                .enumerate()
                .map(|(i, g)| {
                    let field = |what: &str| format!("groups[{i}].{what}");
                    Ok(GroupReport {
                        name: g.group.name.clone(),
                        terms: g.group.terms.iter().map(|t| t.spelling(m)).collect(),
                        directions: g.directions,
                        f: finite(|| field("f"), g.f)?,
                        p_value: finite(|| field("p_value"), g.p)?,
                        gain_sd: finite_opt(|| field("gain_sd"), g.gain_sd)?,
                        unjudged: g.unjudged.clone(),
                        confirmed: g.confirmed,
                        undetermined: g.undetermined.clone(),
                    })
                })
                .collect::<Result<_, NonFinite>>()?,
            dropped: d
                .dropped
                .iter()
                .map(|x| DroppedReport {
                    term: x.term.spelling(m),
                    why: x.why.clone(),
                })
                .collect(),
            notes: notes(d),
        })
    }
}
