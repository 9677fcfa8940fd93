//! Each finding confirmed on its own by records that were not fitted (docs/diagnosis.md §6).
//!
//! The records that judge are the held-out records, each predicted by the fit on the fitted
//! records ([`super::heldout::predict`]); when nothing is held out and several records are
//! fitted, every fitted record in turn, predicted by the fit on the others (leave one record
//! out: its set-up's errors refitted on it when no other record shares its set-up, its zero
//! and drifts always). Either way a model's "held-out residuals" are those predictions'
//! residuals, and everything below is computed from them alike.
//!
//! - **Who can judge.** A judging record judges a change of model only when the fit that
//!   predicts it determines what the change predicts there: the change over the standard
//!   uncertainty of that fit's prediction along it ([`heldout::determined_sd`]) above
//!   [`JUDGE_SD`], and no null direction of the fit that moves the added terms reaches the
//!   record. A record left out that alone determines a finding cannot judge it (the fit on the
//!   others predicts it from records that do not determine it). The gains below are over the
//!   records that can judge; a finding no record can judge enters the extended model on the
//!   fitted records alone when several records are fitted and its corrected p-value is below
//!   [`verdict::enters_unjudged`]'s bound (`Folds::enters_unjudged`).
//! - **Drop-one.** For every plausible finding, the extended model without it against with
//!   it: its held-out gain `Σ (r_without² − r_with²)` over the judging readings, in standard
//!   deviations of the gain of a spurious change of the predictions
//!   ([`verdict::gain_against_noise`], condition 5 of the verdict for the whole extension). A
//!   finding is confirmed when that exceeds [`verdict::CONFIRM_SD`]. Backwards: the findings
//!   not confirmed are taken out and the others judged again without them, until every finding
//!   left is confirmed.
//! - **Alternatives.** A finding that has alternatives has its first [`ALTERNATIVES_TRIED`]
//!   (most explaining on the fitted records first) fitted in its place, every other confirmed
//!   finding kept, and each one's gain measured the same way against the model of those
//!   findings (the finding itself measured so too). The alternative with the largest gain
//!   (mm²) replaces the finding when it is confirmed, plausible, and clearly better than the
//!   finding and than every other alternative the judging records tell from it: the two
//!   predictions differ by more than the noise hides (`Σ Δp²` above twice
//!   [`verdict::CONFIRM_SD`] standard deviations: were either right, the other would lose that
//!   much on average) and its gain over the other exceeds [`verdict::CONFIRM_SD`] of them.
//!   Alternatives the judging records cannot tell from it stay its alternatives; the finding
//!   itself must be told apart. The judging records chose it.
//! - **The extended model** then holds the confirmed findings only. When none is confirmed it
//!   keeps every plausible finding (and the verdict says that none is confirmed on its own).

use super::extend::{self, not_converged, term_values};
use super::heldout::{self, HeldOut};
use super::verdict::{self, CONFIRM_SD};
use super::{DiagnoseError, DiagnoseOptions, Finding, outliers, plausible};
use fitting::campaign::{CampaignIdentification, RecordValidation};
use fitting::noise::{NoiseChoice, NoiseModel};
use fitting::refine::RefineOptions;
use model_spec::Machine;
use simulation::campaign::Campaign;
use simulation::model::{Model, Term};
use std::collections::HashMap;

/// At most this many alternatives of a finding are tried in its place.
pub const ALTERNATIVES_TRIED: usize = 5;

/// A judging record judges a change of model when the fit predicting it determines the change
/// there to more than this many standard uncertainties ([`heldout::determined_sd`]): twice
/// [`CONFIRM_SD`], as two alternatives are told apart only when their predictions differ by
/// that many standard deviations of the noise's share of a gain. (At [`CONFIRM_SD`] the fit on
/// the full budget's campaign without K2 was taken to determine the A group's prediction of
/// K2, which it missed by 35.7 and 37.9 standard deviations at noise seeds 2 and 3.)
pub const JUDGE_SD: f64 = 2.0 * CONFIRM_SD;

/// The fits of the records left in, leaving one out, are refined until a step moves the
/// prediction by less than this share of the noise's σ (the fits on every fitted record, which
/// the extended model may take, as every fit of the diagnosis).
pub const LEFT_OUT_TOLERANCE: f64 = 1e-3;

/// Which records judge the findings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Judges {
    /// The held-out records, predicted by the fit on the fitted records.
    HeldOut,
    /// Every fitted record, predicted by the fit on the others (leave one record out).
    LeftOut,
}

/// What the judging records say of one finding.
#[derive(Clone, Debug, PartialEq)]
pub struct Confirmation {
    /// The records that judged.
    pub judges: Judges,
    /// Its held-out gain given every other finding of the extended model, in standard
    /// deviations of a spurious gain (for a finding chosen among the alternatives, given the
    /// confirmed findings).
    pub gain_sd: f64,
    /// In the extended model on the judging records' word: `gain_sd` above [`CONFIRM_SD`];
    /// or, when no judging record can judge it, its corrected p-value on the fit below
    /// [`verdict::enters_unjudged`]'s bound.
    pub confirmed: bool,
    /// Some judging record's fit determines what it predicts there (`gain_sd` is over those
    /// records); `false`: no record but those it was fitted on determines it.
    pub judged: bool,
    /// The judging records that cannot judge it: the fit that predicts them does not determine
    /// its part of their prediction to [`CONFIRM_SD`] standard uncertainties (the record left
    /// out is the one that determines it).
    pub unjudged: Vec<String>,
    /// When the held-out records chose this term among the alternatives of the selection's
    /// finding: that finding (now among its alternatives).
    pub replaces: Option<Term>,
    /// The terms tried in the finding's place (the finding first) and their held-out gains in
    /// standard deviations, given the confirmed findings; empty when none was tried.
    pub tried: Vec<(Term, f64)>,
}

/// One split of the records: fitted on `fitted`, judged on `judged`.
struct Fold {
    fitted: Campaign,
    judged: Campaign,
}

/// A model's fits (one per fold) and their predictions of the judging records.
struct Eval {
    fits: Vec<CampaignIdentification>,
    predictions: Vec<Vec<RecordValidation>>,
}

/// What the judging records say of a change of model: the gain over the records that can judge
/// it, its standard deviation were it spurious, and `Σ Δp²` (mm²,
/// [`verdict::gain_against_noise`]).
struct Judged {
    gain: f64,
    sd: f64,
    spread: f64,
    /// The judging records whose fit does not determine what the change predicts there.
    unjudged: Vec<String>,
    /// At least one record judges.
    judged: bool,
}

/// The judging records and the fits made for them, kept by model (the terms added to the base
/// model): a model is fitted once per fold.
pub(super) struct Folds<'a> {
    m: &'a Machine,
    o: &'a DiagnoseOptions,
    noise: &'a NoiseChoice,
    base: &'a Model,
    folds: Vec<Fold>,
    judges: Judges,
    refine: RefineOptions,
    cache: HashMap<Vec<Term>, Option<Eval>>,
    /// The outliers' samples of every judging record (folds in order), from the base model's
    /// prediction.
    drops: Vec<Vec<usize>>,
}

impl<'a> Folds<'a> {
    /// The judging records of a diagnosis of `base` fitted on `fitted` with `held_out` held out
    /// (fits under `noise`): the held-out records, or with none and several fitted records
    /// every fitted record left out in turn; `None` when nothing can judge (one fitted record,
    /// nothing held out). `base_fit` is the base model's fit on `fitted`.
    ///
    /// # Errors
    /// A fit or a prediction of the base model that fails.
    pub fn new(
        m: &'a Machine,
        o: &'a DiagnoseOptions,
        noise: &'a NoiseChoice,
        base: &'a Model,
        fitted: &Campaign,
        held_out: &Campaign,
        base_fit: &CampaignIdentification,
    ) -> Result<Option<Folds<'a>>, DiagnoseError> {
        let (folds, judges) = if !held_out.records.is_empty() {
            (
                vec![Fold {
                    fitted: fitted.clone(),
                    judged: held_out.clone(),
                }],
                Judges::HeldOut,
            )
        } else if fitted.records.len() > 1 {
            let folds = (0..fitted.records.len())
                .map(|j| Fold {
                    fitted: Campaign {
                        records: fitted
                            .records
                            .iter()
                            .enumerate()
                            .filter(|&(k, _)| k != j)
                            .map(|(_, r)| r.clone())
                            .collect(),
                    },
                    judged: Campaign {
                        records: vec![fitted.records[j].clone()],
                    },
                })
                .collect();
            (folds, Judges::LeftOut)
        } else {
            return Ok(None);
        };
        let mut out = Folds {
            m,
            o,
            noise,
            base,
            folds,
            judges,
            refine: match judges {
                Judges::HeldOut => RefineOptions::default(),
                Judges::LeftOut => RefineOptions::default().relative(LEFT_OUT_TOLERANCE),
            },
            cache: HashMap::new(),
            drops: Vec::new(),
        };
        if judges == Judges::HeldOut {
            out.seed(&[], base_fit)?;
        }
        if out.eval(&[])?.is_none() {
            return Err(DiagnoseError::Campaign(
                "the base model's fit on the records left in does not converge".into(),
            ));
        }
        let e = out.cache[&[][..]].as_ref().expect("evaluated");
        let drops = out
            .folds
            .iter()
            .zip(&e.predictions)
            .flat_map(|(f, p)| {
                f.judged.records.iter().zip(p).map(|(rec, v)| {
                    outliers::samples(&outliers::find_in(&rec.record, &v.validation.residual))
                })
            })
            .collect();
        out.drops = drops;
        Ok(Some(out))
    }

    /// Records `fit`, the fit of the base model plus `terms` on the fitted records, as the
    /// fit of the only fold (held-out records only).
    ///
    /// # Errors
    /// A prediction that cannot be made.
    pub fn seed(
        &mut self,
        terms: &[Term],
        fit: &CampaignIdentification,
    ) -> Result<(), DiagnoseError> {
        if self.judges == Judges::HeldOut && !self.cache.contains_key(terms) {
            let p = heldout::predict(self.m, fit, &self.folds[0].judged)?;
            self.cache.insert(
                terms.to_vec(),
                Some(Eval {
                    fits: vec![fit.clone()],
                    predictions: vec![p],
                }),
            );
        }
        Ok(())
    }

    /// The fits of the base model plus `terms` on every fold and their predictions; `None`
    /// when a fit does not converge.
    fn eval(&mut self, terms: &[Term]) -> Result<Option<&Eval>, DiagnoseError> {
        if !self.cache.contains_key(terms) {
            let mut model = self.base.clone();
            model.terms.extend_from_slice(terms);
            let mut e = Some(Eval {
                fits: Vec::new(),
                predictions: Vec::new(),
            });
            // The folds' fits are independent: made on every core, taken in fold order as a
            // loop over the folds would take them (the first that does not converge ends it).
            let fits = crate::parallel::map_in_order(&self.folds, |f| {
                extend::fit_refined(self.m, &model, &f.fitted, self.o, self.noise, &self.refine)
            });
            for (f, fit) in self.folds.iter().zip(fits) {
                match fit {
                    Ok(fit) => {
                        let p = heldout::predict(self.m, &fit, &f.judged)?;
                        if let Some(e) = e.as_mut() {
                            e.fits.push(fit);
                            e.predictions.push(p);
                        }
                    }
                    Err(err) if not_converged(&err).is_some() => {
                        e = None;
                        break;
                    }
                    Err(err) => return Err(err),
                }
            }
            self.cache.insert(terms.to_vec(), e);
        }
        Ok(self.cache.get(terms).and_then(Option::as_ref))
    }

    /// The fit of the base model plus `terms` on the fitted records when a fold's fitted
    /// records are all of them (held-out records), if made.
    pub fn whole(&self, terms: &[Term]) -> Option<CampaignIdentification> {
        match self.judges {
            Judges::HeldOut => self
                .cache
                .get(terms)
                .and_then(Option::as_ref)
                .map(|e| e.fits[0].clone()),
            Judges::LeftOut => None,
        }
    }

    /// The held-out gain of `with` over `without` (the terms added to the base model), judged
    /// by the records whose fit determines what the added terms predict there
    /// ([`heldout::determined_sd`] above [`CONFIRM_SD`]); `None` when a fit does not converge.
    fn gain(
        &mut self,
        without: &[Term],
        with: &[Term],
        noise: &NoiseModel,
    ) -> Result<Option<Judged>, DiagnoseError> {
        if self.eval(without)?.is_none() || self.eval(with)?.is_none() {
            return Ok(None);
        }
        let added: Vec<Term> = with
            .iter()
            .copied()
            .filter(|t| !without.contains(t))
            .collect();
        let (a, b) = (
            self.cache[without].as_ref().expect("evaluated"),
            self.cache[with].as_ref().expect("evaluated"),
        );
        let mut unjudged = Vec::new();
        let mut records = Vec::new();
        let mut at = 0;
        for (k, f) in self.folds.iter().enumerate() {
            for (i, rec) in f.judged.records.iter().enumerate() {
                let (before, after) = (
                    &a.predictions[k][i].validation.residual,
                    &b.predictions[k][i].validation.residual,
                );
                let dp: Vec<[f64; 3]> = before
                    .iter()
                    .zip(after)
                    .map(|(x, y)| [x[0] - y[0], x[1] - y[1], x[2] - y[2]])
                    .collect();
                let sd = heldout::determined_sd(self.m, &b.fits[k], rec, &added, &dp)?;
                if sd.is_none_or(|sd| sd > JUDGE_SD) {
                    records.push((
                        a.predictions[k][i].validation.residual.as_slice(),
                        b.predictions[k][i].validation.residual.as_slice(),
                        self.drops[at].clone(),
                    ));
                } else {
                    unjudged.push(rec.label.clone());
                }
                at += 1;
            }
        }
        let judged = !records.is_empty();
        let (gain, sd, spread) = verdict::gain_against_noise(noise, records);
        Ok(Some(Judged {
            gain,
            sd,
            spread,
            unjudged,
            judged,
        }))
    }

    /// Whether a change of model no judging record can judge, of corrected p-value `p` on the
    /// fitted records, enters the extended model: only when several records are fitted (each
    /// left out in turn judges), so that `p` is the evidence of several paths, and then below
    /// [`verdict::enters_unjudged`]'s bound. On one fitted path a look-alike fits as well as
    /// the effect (an effect outside the dictionary taken up by the component errors of Z and A
    /// on K4, which K1 and K2 held out could not judge), and the held-out records must judge.
    pub(super) fn enters_unjudged(&self, p: f64) -> bool {
        self.judges == Judges::LeftOut && verdict::enters_unjudged(p, self.o.alpha)
    }

    /// [`Folds::gain`] in standard deviations (0 when the change is nothing or a fit fails),
    /// `None` when no judging record determines what `with` adds; and the records that cannot
    /// judge it.
    pub(super) fn gain_sd(
        &mut self,
        without: &[Term],
        with: &[Term],
        noise: &NoiseModel,
    ) -> Result<(Option<f64>, Vec<String>), DiagnoseError> {
        Ok(match self.gain(without, with, noise)? {
            Some(j) if !j.judged => (None, j.unjudged),
            Some(j) if j.sd > 0.0 => (Some(j.gain / j.sd), j.unjudged),
            Some(j) => (Some(0.0), j.unjudged),
            None => (Some(0.0), Vec::new()),
        })
    }

    /// The rows of the judging records left out in turn, the base model against the base
    /// model plus `terms` (leave one record out only; empty otherwise, or when a fit does not
    /// converge).
    ///
    /// # Errors
    /// A prediction that cannot be made.
    pub fn left_out_rows(&mut self, terms: &[Term]) -> Result<Vec<HeldOut>, DiagnoseError> {
        if self.judges != Judges::LeftOut || self.eval(terms)?.is_none() {
            return Ok(Vec::new());
        }
        let (base, ext) = (
            self.cache[&[][..]].as_ref().expect("base evaluated"),
            self.cache[terms].as_ref().expect("evaluated"),
        );
        let mut rows = Vec::new();
        for (k, f) in self.folds.iter().enumerate() {
            rows.extend(heldout::held_out_gain(
                self.m,
                &base.fits[k],
                &base.predictions[k],
                &ext.fits[k],
                &f.judged,
            )?);
        }
        Ok(rows)
    }
}

/// Confirms every plausible finding of `findings` on its own with the judging records of
/// `folds` under `noise` (see the module documentation), trying alternatives in the place of
/// each; sets each one's [`Finding::confirmation`], swaps in the alternatives
/// the judging records chose, and returns the terms of the extended model (in the findings'
/// order).
///
/// # Errors
/// A fit or a prediction that fails otherwise than by not converging.
pub(super) fn confirm(
    folds: &mut Folds,
    findings: &mut [Finding],
    noise: &NoiseModel,
) -> Result<Vec<Term>, DiagnoseError> {
    let m = folds.m;
    let all: Vec<Term> = findings
        .iter()
        .filter(|f| f.plausible)
        .map(|f| f.term)
        .collect();
    let judges = folds.judges;
    // Drop-one, backwards: the findings not confirmed given the others are taken out, and
    // those left judged again without them (a look-alike that makes the predictions worse
    // would otherwise lend a gain to the finding that makes up for it), until every finding
    // left is confirmed.
    let mut set = all.clone();
    while !set.is_empty() {
        let mut out = Vec::new();
        for &t in &set {
            let without: Vec<Term> = set.iter().copied().filter(|&x| x != t).collect();
            let (z, unjudged) = folds.gain_sd(&without, &set, noise)?;
            let mut confirmed = z.is_some_and(|z| z > CONFIRM_SD);
            if let Some(f) = findings.iter_mut().find(|f| f.term == t) {
                confirmed |= z.is_none() && folds.enters_unjudged(f.p_value);
                f.confirmation = Some(Confirmation {
                    judges,
                    gain_sd: z.unwrap_or(0.0),
                    confirmed,
                    judged: z.is_some(),
                    unjudged,
                    replaces: None,
                    tried: Vec::new(),
                });
            }
            if !confirmed {
                out.push(t);
            }
        }
        if out.is_empty() {
            break;
        }
        set.retain(|t| !out.contains(t));
    }
    let confirmed = |f: &Finding| f.confirmation.as_ref().is_some_and(|c| c.confirmed);
    let in_model = |fs: &[Finding]| -> Vec<Term> {
        fs.iter()
            .filter(|f| f.plausible && confirmed(f))
            .map(|f| f.term)
            .collect()
    };
    for k in 0..findings.len() {
        if !findings[k].plausible || findings[k].alternatives.is_empty() {
            continue;
        }
        let original = findings[k].term;
        let reference: Vec<Term> = in_model(findings)
            .into_iter()
            .filter(|&t| t != original)
            .collect();
        // In the findings' order, `t` in this finding's place: the extended model's order.
        let before = in_model(&findings[..k]).len();
        let with = |t: Term| {
            let mut v = reference.clone();
            v.insert(before, t);
            v
        };
        // Each term's held-out gain over the reference: in standard deviations (reported) and
        // in mm² (which explains most).
        let mut tried = Vec::new();
        let mut raw = Vec::new();
        for &t in std::iter::once(&original).chain(
            findings[k]
                .alternatives
                .iter()
                .filter(|a| !all.contains(a))
                .take(ALTERNATIVES_TRIED),
        ) {
            let (gain, sd) = match folds.gain(&reference, &with(t), noise)? {
                Some(j) if j.judged => (j.gain, j.sd),
                _ => (f64::NEG_INFINITY, 0.0),
            };
            tried.push((t, if sd > 0.0 { gain / sd } else { 0.0 }));
            raw.push(gain);
        }
        // The first of the largest (the alternatives come most explaining on the fitted
        // records first).
        let Some(b) = (1..tried.len()).fold(None, |b: Option<usize>, i| match b {
            Some(j) if raw[j] >= raw[i] => Some(j),
            _ => Some(i),
        }) else {
            continue;
        };
        let (best, z) = tried[b];
        let mut chosen = z > CONFIRM_SD;
        if chosen {
            // Plausible at its values on the fitted records (the first fold's fit).
            let e = folds.eval(&with(best))?.expect("evaluated");
            let (values, _) = term_values(&e.fits[0], &best);
            let known: Vec<f64> = values.iter().map(|v| v.unwrap_or(0.0)).collect();
            let (size, limit) = plausible::size_and_limit(m, &best, &known, &folds.o.budget);
            chosen = size <= limit;
        }
        // Clearly better than the finding and than every other alternative the held-out
        // records tell from it (were either right, the other would lose twice the margin on
        // average): its gain over each is beyond the noise. Alternatives they cannot tell from
        // it stay its alternatives; the finding itself must be told apart.
        for &(other, _) in tried.iter().filter(|t| t.0 != best) {
            if !chosen {
                break;
            }
            chosen = match folds.gain(&with(other), &with(best), noise)? {
                Some(j) if j.judged && j.spread > 2.0 * CONFIRM_SD * j.sd => {
                    j.gain > CONFIRM_SD * j.sd
                }
                Some(_) => other != original,
                None => false,
            };
        }
        let f = &mut findings[k];
        if chosen {
            let mut alternatives = vec![original];
            alternatives.extend(f.alternatives.iter().copied().filter(|&a| a != best));
            f.alternatives = alternatives;
            f.term = best;
            f.description = best.describe(m);
            f.scan = None;
            f.confirmation = Some(Confirmation {
                judges,
                gain_sd: z,
                confirmed: true,
                judged: true,
                unjudged: Vec::new(),
                replaces: Some(original),
                tried,
            });
        } else if let Some(c) = f.confirmation.as_mut() {
            c.tried = tried;
        }
    }
    let kept = in_model(findings);
    Ok(if kept.is_empty() { all } else { kept })
}
