//! Grouped candidates: the sets of errors metrologists name together, each tested as one
//! candidate of k directions after the selection (docs/diagnosis.md §6, "Error groups").
//!
//! A machine holding every error of its topology at once (a full error budget) leaves, after
//! the findings, a residual spread over many small terms none of which stands out on its own:
//! the one-term selection then stops at its limit, or names look-alikes. The groups are the
//! families of a calibration standard (ISO 230-1 and -7):
//!
//! - of every rotary axis, its six component error motions once per revolution
//!   (`harmonic:1`: radial and axial run-out, wobble, angular positioning);
//! - of every linear axis, its positioning and its two straightness errors over the stroke
//!   (`poly:1`, `poly:2`);
//! - of every linear axis, its three angular errors (`const`, `poly:1`);
//! - the squareness errors of the linear axes (`const`).
//!
//! A group's members that the model already holds or that do not vary on the fitted records
//! are left out of it. Each group is tested by the F-test of its directions given the
//! extended model (k = the number of directions its columns add), Bonferroni-corrected for the
//! groups tried at the step; the most significant is added, and the test is repeated given it,
//! until no group is significant at α. A group is then kept only when the judging records
//! (held out, or every fitted record left out in turn) confirm it as a whole, by backward
//! elimination from every group selected: each judged given every other group kept, by its
//! gain on the judging records that can judge it ([`super::confirm`]: a record whose fit does
//! not determine what the group changes in its prediction cannot) beyond
//! [`super::verdict::CONFIRM_SD`] standard deviations, or, when no record can judge it, by its
//! p-value ([`super::verdict::enters_unjudged`]); the worst of those not confirmed is taken out
//! and the others judged again, until every group left is
//! confirmed. A group is fitted with every
//! member; the campaign need not determine them all (the report lists which combinations it
//! does not, and `rtest identify --constraint min-norm` gives the values that carry the
//! determined ones only).

use super::columns::Columns;
use super::confirm::Folds;
use super::extend::fit;
use super::select::{Span, f_p_value, f_statistic};
use super::verdict::CONFIRM_SD;
use super::weights::Weights;
use super::{DiagnoseError, DiagnoseOptions};
use fitting::campaign::CampaignIdentification;
use fitting::noise::{NoiseChoice, NoiseModel};
use model_spec::basis::Basis;
use model_spec::terms::{Effect, Term};
use model_spec::{AxisKind, ErrorKind, Machine, Motion};
use nalgebra::{DMatrix, DVector};
use simulation::campaign::Campaign;
use simulation::model::Model;

/// A group of errors named together, with the members the extended model lacks.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorGroup {
    /// What it is, in the field's words (`component errors of C, once per revolution`).
    pub name: String,
    /// Its members the base model and the findings do not hold, in catalogue order.
    pub terms: Vec<Term>,
}

/// A group the diagnosis adds to the extended model.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupFinding {
    /// The group and the members added.
    pub group: ErrorGroup,
    /// The directions its columns add to the model on the fitted records (k of the F-test).
    pub directions: usize,
    /// Its H-matrix columns (the members' parameters).
    pub columns: usize,
    /// Share of the base model's residual sum of squares it explains given the model before it
    /// (whitened readings).
    pub fraction: f64,
    /// Its F statistic with `directions` and the residual's degrees of freedom.
    pub f: f64,
    /// Its p-value, Bonferroni-corrected for the groups tried at its step.
    pub p: f64,
    /// The groups tried at its step.
    pub tried: usize,
    /// Its held-out (or left-out) gain given every other group kept, over the judging records
    /// that can judge it, in standard deviations of a spurious gain; `None` when none can.
    pub gain_sd: Option<f64>,
    /// The judging records that cannot judge it: the fit that predicts them does not determine
    /// its part of their prediction ([`super::heldout::determined_sd`]).
    pub unjudged: Vec<String>,
    /// In the extended model: `gain_sd` above [`super::verdict::CONFIRM_SD`], or with no record
    /// to judge it, `p` below [`super::verdict::enters_unjudged`]'s bound.
    pub confirmed: bool,
    /// The names of its parameters that the extended model's fit on the fitted records does
    /// not determine (their values then need `--constraint min-norm`).
    pub undetermined: Vec<String>,
}

/// The groups of machine `m` ([module documentation](self)) without the members of
/// `model_terms`; groups left empty are not listed.
pub fn error_groups(m: &Machine, model_terms: &[Term]) -> Vec<ErrorGroup> {
    let mut out = Vec::new();
    let term = |e: usize, basis: Basis| Term {
        effect: Effect::Error(e),
        basis,
    };
    let component = |axis: usize, angular: bool| -> Vec<usize> {
        (0..m.catalogue.len())
            .filter(|&e| match m.catalogue[e].kind {
                ErrorKind::Component { axis: a, motion } => {
                    a == axis && matches!(motion, Motion::Rotation(_)) == angular
                }
                _ => false,
            })
            .collect()
    };
    for (a, axis) in m.axes.iter().enumerate() {
        match axis.kind {
            AxisKind::Rotary => {
                let terms = component(a, false)
                    .into_iter()
                    .chain(component(a, true))
                    .map(|e| term(e, Basis::Harmonic(1)))
                    .collect();
                out.push(ErrorGroup {
                    name: format!("component errors of {}, once per revolution", axis.name),
                    terms,
                });
            }
            AxisKind::Linear => {
                let terms = component(a, false)
                    .into_iter()
                    .flat_map(|e| [term(e, Basis::Poly(1)), term(e, Basis::Poly(2))])
                    .collect();
                out.push(ErrorGroup {
                    name: format!("positioning and straightness of {}", axis.name),
                    terms,
                });
                let terms = component(a, true)
                    .into_iter()
                    .flat_map(|e| [term(e, Basis::Const), term(e, Basis::Poly(1))])
                    .collect();
                out.push(ErrorGroup {
                    name: format!("angular errors of {}", axis.name),
                    terms,
                });
            }
        }
    }
    let squareness = (0..m.catalogue.len())
        .filter(|&e| matches!(m.catalogue[e].kind, ErrorKind::Squareness { .. }))
        .map(|e| term(e, Basis::Const))
        .collect();
    out.push(ErrorGroup {
        name: "squareness of the linear axes".into(),
        terms: squareness,
    });
    for g in &mut out {
        g.terms
            .retain(|t| !model_terms.contains(t) && t.check(m).is_ok());
    }
    out.retain(|g| !g.terms.is_empty());
    out
}

/// A group chosen by [`select`], before the judging records confirm it.
#[derive(Clone, Debug)]
pub(super) struct Selected {
    /// Index into the groups given.
    pub index: usize,
    /// Directions added.
    pub directions: usize,
    /// Share of `rss_base` it explains.
    pub fraction: f64,
    /// F statistic.
    pub f: f64,
    /// Bonferroni-corrected p-value.
    pub p: f64,
    /// Groups tried at its step.
    pub tried: usize,
}

/// Forward selection over the groups: given the model spanned by `span`, the groups whose
/// columns (`columns(g)`, whitened as `y`) add directions, the most significant added while
/// its Bonferroni-corrected p-value is below `alpha`. `rss_base` scales the shares.
pub(super) fn select(
    mut span: Span,
    y: &DVector<f64>,
    groups: usize,
    columns: &dyn Fn(usize) -> DMatrix<f64>,
    rss_base: f64,
    alpha: f64,
) -> Vec<Selected> {
    let n = y.len();
    let mut out: Vec<Selected> = Vec::new();
    loop {
        let r = span.project_out(y);
        let rss = r.norm_squared();
        let mut best: Option<(Selected, DMatrix<f64>)> = None;
        let mut tried = 0;
        for g in (0..groups).filter(|g| !out.iter().any(|s| s.index == *g)) {
            let d = span.new_directions(&columns(g));
            let k = d.ncols();
            if k == 0 {
                continue;
            }
            tried += 1;
            let delta = (d.transpose() * &r).norm_squared();
            let Some(f) = f_statistic(delta, rss, k, n, span.rank()) else {
                continue;
            };
            let p = f_p_value(f, k, n, span.rank());
            if best.as_ref().is_none_or(|(b, _)| p < b.p) {
                let s = Selected {
                    index: g,
                    directions: k,
                    fraction: delta / rss_base.max(f64::MIN_POSITIVE),
                    f,
                    p,
                    tried: 0,
                };
                best = Some((s, d));
            }
        }
        let Some((mut s, d)) = best else {
            break;
        };
        s.tried = tried;
        s.p = (s.p * tried as f64).min(1.0);
        if s.p >= alpha {
            break;
        }
        span.extend(&d);
        out.push(s);
    }
    out
}

/// Judges group `f` by the gain of `with` over `without` on the judging records that can judge
/// it; with none, it is confirmed on its p-value ([`Folds::enters_unjudged`]). Sets its gain, the
/// records that cannot judge it and whether it is confirmed, which it returns.
fn judge(
    folds: &mut Folds,
    f: &mut GroupFinding,
    without: &[Term],
    with: &[Term],
    g: &Grouped,
) -> Result<bool, DiagnoseError> {
    let (z, unjudged) = folds.gain_sd(without, with, g.whitening)?;
    f.gain_sd = z;
    f.unjudged = unjudged;
    f.confirmed = match z {
        Some(z) => z > CONFIRM_SD,
        None => folds.enters_unjudged(f.p),
    };
    Ok(f.confirmed)
}

/// The members of the confirmed groups, in order.
pub(super) fn group_terms(found: &[GroupFinding]) -> Vec<Term> {
    found
        .iter()
        .filter(|g| g.confirmed)
        .flat_map(|g| g.group.terms.iter().copied())
        .collect()
}

/// What the stage of grouped candidates works on.
pub(super) struct Grouped<'a> {
    /// The machine.
    pub m: &'a Machine,
    /// The diagnosis's options.
    pub o: &'a DiagnoseOptions,
    /// The base model.
    pub base: &'a Model,
    /// The candidates (every group member is one).
    pub candidates: &'a [Term],
    /// The candidates that vary on the fitted records.
    pub live: &'a [usize],
    /// The whitened columns and readings.
    pub cols: &'a Columns,
    /// The columns of a group of `cols` (base term `t < nb`, candidate `nb + c`).
    pub group: &'a dyn Fn(usize) -> DMatrix<f64>,
    /// The base model's residual sum of squares (whitened).
    pub rss_base: f64,
    /// The findings in the extended model.
    pub terms: &'a [Term],
    /// The fitted records, outliers left out.
    pub cleaned: &'a Campaign,
    /// The noise model of the fits.
    pub gls: &'a NoiseChoice,
    /// The noise model of the tests.
    pub whitening: &'a NoiseModel,
    /// The covariances of records read through an instrument.
    pub weights: &'a Weights,
}

/// The grouped candidates ([module documentation](self)) given the extended model of `g.terms`: selected on the
/// fitted records, confirmed as wholes by the judging records of `folds` (forwards, each given
/// the groups kept before it, then backwards, each given the others kept), and the extended
/// model's fit with the confirmed ones (`None` when none is).
pub(super) fn grouped(
    g: &Grouped,
    folds: &mut Folds,
) -> Result<(Vec<GroupFinding>, Option<CampaignIdentification>), DiagnoseError> {
    let Grouped {
        m,
        o,
        base,
        candidates,
        live,
        cols,
        group,
        ..
    } = *g;
    let n = cols.y.len();
    // Members that are candidates varying on the records.
    let mut all = error_groups(m, &[base.terms.as_slice(), g.terms].concat());
    for gr in &mut all {
        gr.terms.retain(|t| {
            candidates
                .iter()
                .position(|c| c == t)
                .is_some_and(|c| live.contains(&c))
        });
    }
    all.retain(|gr| !gr.terms.is_empty());
    let index = |t: &Term| candidates.iter().position(|c| c == t).expect("a candidate");
    let columns = |k: usize| -> DMatrix<f64> {
        let blocks: Vec<DMatrix<f64>> = all[k]
            .terms
            .iter()
            .map(|t| group(cols.nb + index(t)))
            .collect();
        let width = blocks.iter().map(|b| b.ncols()).sum();
        let mut out = DMatrix::zeros(n, width);
        let mut at = 0;
        for b in &blocks {
            out.columns_mut(at, b.ncols()).copy_from(b);
            at += b.ncols();
        }
        out
    };
    let mut span = Span::of_groups(n, 0..cols.nb, group);
    for &t in g.terms {
        let c = cols.term_columns(m, t, g.cleaned, g.weights, g.whitening)?;
        let d = span.new_directions(&c);
        span.extend(&d);
    }
    let selected = select(span, &cols.y, all.len(), &columns, g.rss_base, o.alpha);
    let mut found: Vec<GroupFinding> = selected
        .iter()
        .map(|s| GroupFinding {
            group: all[s.index].clone(),
            directions: s.directions,
            columns: all[s.index]
                .terms
                .iter()
                .map(|t| group(cols.nb + index(t)).ncols())
                .sum(),
            fraction: s.fraction,
            f: s.f,
            p: s.p,
            tried: s.tried,
            gain_sd: None,
            unjudged: Vec::new(),
            confirmed: true,
            undetermined: Vec::new(),
        })
        .collect();
    // Confirmed as wholes: forwards in the order of selection, each given the groups kept
    // before it; then backwards, each given every other group kept, until all are confirmed.
    // Confirmed as wholes by backward elimination: each judged given every other group kept,
    // the one judged worst of those not confirmed taken out, and the others judged again,
    // until every group left is confirmed.
    loop {
        let with: Vec<Term> = g.terms.iter().copied().chain(group_terms(&found)).collect();
        let mut worst: Option<(usize, f64)> = None;
        let judged: Vec<usize> = (0..found.len()).filter(|&k| found[k].confirmed).collect();
        for &k in &judged {
            let without: Vec<Term> = with
                .iter()
                .copied()
                .filter(|t| !found[k].group.terms.contains(t))
                .collect();
            if !judge(folds, &mut found[k], &without, &with, g)? {
                let z = found[k].gain_sd.unwrap_or(f64::NEG_INFINITY);
                if worst.is_none_or(|(_, w)| z < w) {
                    worst = Some((k, z));
                }
            }
        }
        let Some((out, _)) = worst else {
            break;
        };
        for k in judged {
            found[k].confirmed = k != out;
        }
    }
    let added = group_terms(&found);
    if added.is_empty() {
        return Ok((found, None));
    }
    let mut model = base.clone();
    model.terms.extend_from_slice(g.terms);
    model.terms.extend(added);
    let fit = fit(m, &model, g.cleaned, o, g.gls)?;
    for f in found.iter_mut().filter(|f| f.confirmed) {
        f.undetermined = (0..fit.layout.columns.len())
            .filter(|&j| f.group.terms.contains(&fit.layout.columns[j].term))
            .filter(|&j| fit.fit.values[j].is_none())
            .map(|j| fit.fit.names[j].clone())
            .collect();
    }
    Ok((found, Some(fit)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On `seed-ac` (X Y Z, A and C) with the reduced model: nine groups, the rotary axes'
    /// six component errors at harmonic 1, each linear axis's translational errors at orders 1
    /// and 2 and angular errors constant and linear, and the three squareness errors; a term
    /// the model holds is left out of its group.
    #[test]
    fn the_groups_of_seed_ac() {
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let reduced = simulation::model::Model::of(&m, "reduced").unwrap();
        let groups = error_groups(&m, &reduced.terms);
        let sizes: Vec<(String, usize)> = groups
            .iter()
            .map(|g| (g.name.clone(), g.terms.len()))
            .collect();
        assert_eq!(sizes.len(), 9, "{sizes:?}");
        for (name, size) in &sizes {
            assert_eq!(*size, if name.starts_with("squareness") { 3 } else { 6 });
        }
        let c = groups
            .iter()
            .find(|g| g.name == "component errors of C, once per revolution")
            .unwrap();
        let ecc = Term::parse(&m, "ECC@harmonic:1").unwrap();
        assert!(c.terms.contains(&ecc));
        let mut with = reduced.terms.clone();
        with.push(ecc);
        let fewer = error_groups(&m, &with);
        let c = fewer.iter().find(|g| g.name.contains(" of C")).unwrap();
        assert_eq!(c.terms.len(), 5);
        assert!(!c.terms.contains(&ecc));
    }
}
