//! Each finding confirmed on its own by records that were not fitted (docs/diagnosis.md §6).
//!
//! The records that judge are the held-out records, each predicted by the fit on the fitted
//! records ([`super::heldout::predict`]); when nothing is held out and several records are
//! fitted, every fitted record in turn, predicted by the fit on the others (leave one record
//! out: its set-up's errors refitted on it when no other record shares its set-up, its zero
//! and drifts always). Either way a model's "held-out residuals" are those predictions'
//! residuals, and everything below is computed from them alike.
//!
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
use crate::fitting::campaign::{Campaign, CampaignIdentification, RecordValidation};
use crate::fitting::noise::{NoiseChoice, NoiseModel};
use crate::fitting::refine::RefineOptions;
use crate::model::{Model, Term};
use model_spec::Machine;
use std::collections::HashMap;

/// At most this many alternatives of a finding are tried in its place.
pub const ALTERNATIVES_TRIED: usize = 5;

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
    /// `gain_sd` above [`CONFIRM_SD`]: the held-out records confirm it.
    pub confirmed: bool,
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
            for f in &self.folds {
                match extend::fit_refined(
                    self.m,
                    &model,
                    &f.fitted,
                    self.o,
                    self.noise,
                    &self.refine,
                ) {
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

    /// The held-out gain of `with` over `without` (the terms added to the base model), its
    /// standard deviation were it spurious and the gain were `with` right (mm²,
    /// [`verdict::gain_against_noise`]); `None` when a fit does not converge.
    fn gain(
        &mut self,
        without: &[Term],
        with: &[Term],
        noise: &NoiseModel,
    ) -> Result<Option<(f64, f64, f64)>, DiagnoseError> {
        if self.eval(without)?.is_none() || self.eval(with)?.is_none() {
            return Ok(None);
        }
        let residuals = |e: &'_ Eval| -> Vec<Vec<[f64; 3]>> {
            e.predictions
                .iter()
                .flatten()
                .map(|v| v.validation.residual.clone())
                .collect()
        };
        let (a, b) = (
            residuals(self.cache[without].as_ref().expect("evaluated")),
            residuals(self.cache[with].as_ref().expect("evaluated")),
        );
        Ok(Some(verdict::gain_against_noise(
            noise,
            a.iter()
                .zip(&b)
                .zip(&self.drops)
                .map(|((a, b), d)| (a.as_slice(), b.as_slice(), d.clone())),
        )))
    }

    /// [`Folds::gain`] in standard deviations (0 when the change is nothing or a fit fails).
    pub(super) fn gain_sd(
        &mut self,
        without: &[Term],
        with: &[Term],
        noise: &NoiseModel,
    ) -> Result<f64, DiagnoseError> {
        Ok(match self.gain(without, with, noise)? {
            Some((g, sd, _)) if sd > 0.0 => g / sd,
            _ => 0.0,
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
            let z = folds.gain_sd(&without, &set, noise)?;
            if let Some(f) = findings.iter_mut().find(|f| f.term == t) {
                f.confirmation = Some(Confirmation {
                    judges,
                    gain_sd: z,
                    confirmed: z > CONFIRM_SD,
                    replaces: None,
                    tried: Vec::new(),
                });
            }
            if z <= CONFIRM_SD {
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
            let g = folds.gain(&reference, &with(t), noise)?;
            let (gain, sd) = g.map_or((f64::NEG_INFINITY, 0.0), |g| (g.0, g.1));
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
                Some((gain, sd, spread)) if spread > 2.0 * CONFIRM_SD * sd => {
                    gain > CONFIRM_SD * sd
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
