//! The factorisations of the fits that whiten rows: generalized least squares under a noise
//! model ([`WhitenedFactored`]), and the fits of [`crate::identify::fit_rows`] with per-sample
//! weights ([`RowsFactored`]). Every H they factorise (the ordinary, the weighted, the whitened)
//! is a [`Factored`]: its QR decomposition is folded in blocks of its rows, whitened rows folded
//! as whitened. Made for given readings (`for_readings`), each folds the readings it will fit
//! (whitened as its rows are) along with its H.

use super::Factored;
use crate::least_squares::{Constraint, EstimateError, Fit, Tolerances, WhitenedFit};
use crate::noise::{NoiseError, NoiseModel, SampleWhitening};
use nalgebra::{DMatrix, DVector};

/// What every factorisation of one fit shares: the parameter names, the constraint and the
/// tolerances.
#[derive(Clone, Copy, Debug)]
struct Setup<'b> {
    names: &'b [String],
    constraint: &'b Constraint,
    tol: &'b Tolerances,
}

impl Setup<'_> {
    /// The factorisation of `h` (all its rows real), with the readings `y` folded along.
    fn factor(
        &self,
        h: &DMatrix<f64>,
        y: Option<&DVector<f64>>,
    ) -> Result<Factored, EstimateError> {
        Factored::with_readings(h, y, self.names, self.constraint, self.tol, h.nrows())
    }
}

/// `y` whitened by `whiten`, when given.
fn whitened(
    y: Option<&DVector<f64>>,
    whiten: impl FnOnce(&mut DVector<f64>) -> Result<(), NoiseError>,
) -> Result<Option<DVector<f64>>, EstimateError> {
    let Some(y) = y else { return Ok(None) };
    let mut wy = y.clone();
    whiten(&mut wy)?;
    Ok(Some(wy))
}

/// The factorisations of a generalized least-squares fit under a noise model
/// ([`crate::least_squares_whitened`]): the ordinary H's, and the whitened H with its own
/// (none for a uniform white model, whose fit is the ordinary one).
#[derive(Clone, Debug)]
pub struct WhitenedFactored {
    /// The ordinary H's.
    ordinary: Factored,
    /// The whitened H and its factorisation.
    whitened: Option<(DMatrix<f64>, Factored)>,
}

impl WhitenedFactored {
    /// The factorisations of `h` (rows of records of `layout` samples) under `noise`.
    ///
    /// # Errors
    /// As [`Factored::new`]; [`EstimateError::Noise`] when the layout does not fit the rows, the
    /// model cannot whiten, or the whitened H has another rank or other undetermined parameters.
    pub fn new(
        h: &DMatrix<f64>,
        names: &[String],
        constraint: &Constraint,
        tol: &Tolerances,
        noise: &NoiseModel,
        layout: &[usize],
    ) -> Result<WhitenedFactored, EstimateError> {
        let setup = Setup {
            names,
            constraint,
            tol,
        };
        WhitenedFactored::whiten(setup.factor(h, None)?, setup, h, None, noise, layout)
    }

    /// [`WhitenedFactored::new`] for the fit of the readings `y` (mm): they are folded with H,
    /// and whitened with the whitened H.
    ///
    /// # Errors
    /// As [`WhitenedFactored::new`].
    pub(crate) fn for_readings(
        h: &DMatrix<f64>,
        y: &DVector<f64>,
        names: &[String],
        constraint: &Constraint,
        tol: &Tolerances,
        noise: &NoiseModel,
        layout: &[usize],
    ) -> Result<WhitenedFactored, EstimateError> {
        let setup = Setup {
            names,
            constraint,
            tol,
        };
        let ordinary = setup.factor(h, Some(y))?;
        WhitenedFactored::whiten(ordinary, setup, h, Some(y), noise, layout)
    }

    /// As [`WhitenedFactored::new`] with `ordinary` the factorisation of `h` that
    /// [`Factored::new`] makes with the same arguments (and `h.nrows()` rows): it is not made
    /// again.
    ///
    /// # Errors
    /// As [`WhitenedFactored::new`].
    pub fn with_ordinary(
        ordinary: Factored,
        h: &DMatrix<f64>,
        names: &[String],
        constraint: &Constraint,
        tol: &Tolerances,
        noise: &NoiseModel,
        layout: &[usize],
    ) -> Result<WhitenedFactored, EstimateError> {
        let setup = Setup {
            names,
            constraint,
            tol,
        };
        WhitenedFactored::whiten(ordinary, setup, h, None, noise, layout)
    }

    /// [`WhitenedFactored::with_ordinary`] with the readings `y` (when given) whitened and
    /// folded with the whitened H.
    fn whiten(
        ordinary: Factored,
        setup: Setup,
        h: &DMatrix<f64>,
        y: Option<&DVector<f64>>,
        noise: &NoiseModel,
        layout: &[usize],
    ) -> Result<WhitenedFactored, EstimateError> {
        if noise.is_uniform_white() {
            return Ok(WhitenedFactored {
                ordinary,
                whitened: None,
            });
        }
        let mut wh = h.clone();
        noise.whiten_matrix(layout, &mut wh)?;
        let wy = whitened(y, |v| noise.whiten_vector(layout, v))?;
        let w = setup.factor(&wh, wy.as_ref())?;
        if w.rank != ordinary.rank || w.determined() != ordinary.determined() {
            return Err(NoiseError::RankChanged {
                ordinary: ordinary.rank,
                whitened: w.rank,
            }
            .into());
        }
        Ok(WhitenedFactored {
            ordinary,
            whitened: Some((wh, w)),
        })
    }

    /// The generalized least-squares fit of `y` by `h` (the matrix factorised) under `noise`
    /// with `layout`, as [`crate::least_squares_whitened`] makes it.
    ///
    /// # Errors
    /// As [`Factored::fit`]; [`EstimateError::Noise`] when `y` cannot be whitened.
    pub fn fit(
        &self,
        h: &DMatrix<f64>,
        y: &DVector<f64>,
        noise: &NoiseModel,
        layout: &[usize],
    ) -> Result<WhitenedFit, EstimateError> {
        let ordinary = self.ordinary.fit(h, y, 0.0)?;
        let Some((wh, w)) = &self.whitened else {
            let s = noise.sigma_mm[0];
            return Ok(WhitenedFit {
                whitened_sigma: ordinary.sigma.filter(|_| s > 0.0).map(|x| x / s),
                fit: ordinary,
            });
        };
        let mut wy = y.clone();
        noise.whiten_vector(layout, &mut wy)?;
        let w = w.fit(wh, &wy, 0.0)?;
        let residual = y - h * DVector::from_column_slice(&w.solution);
        let rss = residual.norm_squared();
        let sigma = (ordinary.dof > 0).then(|| (rss / ordinary.dof as f64).sqrt());
        let mut identifiability = ordinary.identifiability;
        identifiability.near_confounded = w.identifiability.near_confounded;
        Ok(WhitenedFit {
            whitened_sigma: w.sigma,
            fit: Fit {
                values: w.values,
                solution: w.solution,
                std: w.std,
                covariance: w.covariance,
                correlation: w.correlation,
                identifiability,
                residual,
                rss,
                sigma,
                ..ordinary
            },
        })
    }
}

/// One factorisation of a fit of rows ([`crate::identify::fit_rows`]): ordinary, or
/// generalized under a noise model.
#[derive(Clone, Debug)]
enum Inner {
    Ordinary(Box<Factored>),
    Whitened(Box<WhitenedFactored>),
}

impl Inner {
    /// The factorisation of `h`, under `noise` when given, with the readings `y` folded along.
    fn new(
        setup: Setup,
        h: &DMatrix<f64>,
        y: Option<&DVector<f64>>,
        noise: Option<&NoiseModel>,
        layout: &[usize],
    ) -> Result<Inner, EstimateError> {
        let ordinary = setup.factor(h, y)?;
        Ok(match noise {
            None => Inner::Ordinary(Box::new(ordinary)),
            Some(n) => Inner::Whitened(Box::new(WhitenedFactored::whiten(
                ordinary, setup, h, y, n, layout,
            )?)),
        })
    }

    /// The factorisation whose rank and identifiability the fit reports.
    fn reported(&self) -> &Factored {
        match self {
            Inner::Ordinary(f) => f.as_ref(),
            Inner::Whitened(w) => &w.ordinary,
        }
    }

    /// The fit and its σ̂ (ordinary: the fit's own; generalized: the whitened residual's).
    fn fit(
        &self,
        h: &DMatrix<f64>,
        y: &DVector<f64>,
        noise: Option<&NoiseModel>,
        layout: &[usize],
    ) -> Result<(Fit, Option<f64>), EstimateError> {
        match (self, noise) {
            (Inner::Whitened(w), Some(n)) => {
                let w = w.fit(h, y, n, layout)?;
                Ok((w.fit, w.whitened_sigma))
            }
            (Inner::Ordinary(f), _) => {
                let f = f.fit(h, y, 0.0)?;
                let s = f.sigma;
                Ok((f, s))
            }
            (Inner::Whitened(w), None) => {
                let f = w.ordinary.fit(h, y, 0.0)?;
                let s = f.sigma;
                Ok((f, s))
            }
        }
    }
}

/// The factorisations of [`crate::identify::fit_rows`] for one H, noise model, layout and
/// per-sample weights: every fit of that H to other readings made from them.
#[derive(Clone, Debug)]
pub struct RowsFactored<'a> {
    /// The noise model of a generalized fit.
    noise: Option<&'a NoiseModel>,
    /// Samples per record, in row order.
    layout: &'a [usize],
    /// With per-sample weights: the weights, the ordinary H's factorisation and the weighted H.
    weighted: Option<(&'a SampleWhitening, Factored, DMatrix<f64>)>,
    /// The factorisation of H, or of the weighted H.
    inner: Inner,
}

impl<'a> RowsFactored<'a> {
    /// The factorisations of `h` (rows of records of `layout` samples) for the fits of
    /// [`crate::identify::fit_rows`] with the same arguments.
    ///
    /// # Errors
    /// As [`Factored::new`] and [`WhitenedFactored::new`]; [`EstimateError::Noise`] when the
    /// weights do not fit the rows or change the rank.
    pub fn new(
        h: &DMatrix<f64>,
        names: &[String],
        constraint: &Constraint,
        tol: &Tolerances,
        noise: Option<&'a NoiseModel>,
        layout: &'a [usize],
        weights: Option<&'a SampleWhitening>,
    ) -> Result<RowsFactored<'a>, EstimateError> {
        let setup = Setup {
            names,
            constraint,
            tol,
        };
        RowsFactored::build(setup, h, None, noise, layout, weights)
    }

    /// [`RowsFactored::new`] for the fit of the readings `y` (mm): every H factorised folds
    /// them along, whitened as its rows are, so that [`RowsFactored::fit`] of `y` makes no
    /// second pass over the rows.
    ///
    /// # Errors
    /// As [`RowsFactored::new`].
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn for_readings(
        h: &DMatrix<f64>,
        y: &DVector<f64>,
        names: &[String],
        constraint: &Constraint,
        tol: &Tolerances,
        noise: Option<&'a NoiseModel>,
        layout: &'a [usize],
        weights: Option<&'a SampleWhitening>,
    ) -> Result<RowsFactored<'a>, EstimateError> {
        let setup = Setup {
            names,
            constraint,
            tol,
        };
        RowsFactored::build(setup, h, Some(y), noise, layout, weights)
    }

    /// [`RowsFactored::new`], with the readings `y` folded along when given.
    fn build(
        setup: Setup,
        h: &DMatrix<f64>,
        y: Option<&DVector<f64>>,
        noise: Option<&'a NoiseModel>,
        layout: &'a [usize],
        weights: Option<&'a SampleWhitening>,
    ) -> Result<RowsFactored<'a>, EstimateError> {
        let Some(weights) = weights else {
            return Ok(RowsFactored {
                noise,
                layout,
                weighted: None,
                inner: Inner::new(setup, h, y, noise, layout)?,
            });
        };
        let mut wh = h.clone();
        weights.whiten_matrix(&mut wh)?;
        let wy = whitened(y, |v| weights.whiten_vector(v))?;
        let ordinary = setup.factor(h, y)?;
        let inner = Inner::new(setup, &wh, wy.as_ref(), noise, layout)?;
        let weighted = inner.reported();
        if weighted.rank != ordinary.rank || weighted.determined() != ordinary.determined() {
            return Err(NoiseError::RankChanged {
                ordinary: ordinary.rank,
                whitened: weighted.rank,
            }
            .into());
        }
        Ok(RowsFactored {
            noise,
            layout,
            weighted: Some((weights, ordinary, wh)),
            inner,
        })
    }

    /// The factorisations for the fits under `noise` of the H, layout and weights of `self`, an
    /// ordinary one ([`RowsFactored::new`] without a noise model, `h`, `names`, `constraint`
    /// and `tol` its arguments): as [`RowsFactored::new`] makes them with `noise`, the
    /// factorisation of the ordinary H (or the weighted H) taken from `self`, not made again.
    ///
    /// With the readings `y` (mm) of the fit to come, the whitened H folds them along
    /// (whitened), so that [`RowsFactored::fit`] of `y` makes no second pass over its rows
    /// (without per-sample weights; with them, `y` is folded when fitted).
    ///
    /// # Errors
    /// As [`WhitenedFactored::new`]; [`EstimateError::Shape`] when `self` is not ordinary.
    pub fn under(
        &self,
        h: &DMatrix<f64>,
        y: Option<&DVector<f64>>,
        names: &[String],
        constraint: &Constraint,
        tol: &Tolerances,
        noise: &'a NoiseModel,
    ) -> Result<RowsFactored<'a>, EstimateError> {
        let setup = Setup {
            names,
            constraint,
            tol,
        };
        let y = y.filter(|_| self.weighted.is_none());
        self.under_with(setup, h, y, noise)
    }

    /// [`RowsFactored::under`], with the readings `y` (of the H factorised) folded along
    /// when given.
    fn under_with(
        &self,
        setup: Setup,
        h: &DMatrix<f64>,
        y: Option<&DVector<f64>>,
        noise: &'a NoiseModel,
    ) -> Result<RowsFactored<'a>, EstimateError> {
        let (Inner::Ordinary(ordinary), None) = (&self.inner, self.noise) else {
            return Err(EstimateError::Shape(
                "a generalized fit's factorisations are made from an ordinary fit's".into(),
            ));
        };
        let h = self.weighted.as_ref().map_or(h, |(_, _, wh)| wh);
        let ordinary = ordinary.as_ref().clone();
        let whitened = WhitenedFactored::whiten(ordinary, setup, h, y, noise, self.layout)?;
        Ok(RowsFactored {
            noise: Some(noise),
            layout: self.layout,
            weighted: self.weighted.clone(),
            inner: Inner::Whitened(Box::new(whitened)),
        })
    }

    /// The fit of readings `y` (mm) by `h`, the matrix factorised, as
    /// [`crate::identify::fit_rows`] makes it.
    ///
    /// # Errors
    /// As [`Factored::fit`]; [`EstimateError::Noise`] when `y` cannot be whitened.
    pub fn fit(
        &self,
        h: &DMatrix<f64>,
        y: &DVector<f64>,
    ) -> Result<(Fit, Option<f64>), EstimateError> {
        let Some((weights, ordinary, wh)) = &self.weighted else {
            let (f, s) = self.inner.fit(h, y, self.noise, self.layout)?;
            return Ok((f, s.filter(|_| self.noise.is_some())));
        };
        let mut wy = y.clone();
        weights.whiten_vector(&mut wy)?;
        let ordinary = ordinary.fit(h, y, 0.0)?;
        let (weighted, whitened_sigma) = match self.noise {
            None => {
                let (f, _) = self.inner.fit(wh, &wy, None, self.layout)?;
                let s = f.sigma.map(|s| s / weights.scale_mm);
                (f, s)
            }
            Some(n) => self.inner.fit(wh, &wy, Some(n), self.layout)?,
        };
        let residual = y - h * DVector::from_column_slice(&weighted.solution);
        let rss = residual.norm_squared();
        let sigma = (ordinary.dof > 0).then(|| (rss / ordinary.dof as f64).sqrt());
        let mut identifiability = ordinary.identifiability;
        identifiability.near_confounded = weighted.identifiability.near_confounded;
        Ok((
            Fit {
                values: weighted.values,
                solution: weighted.solution,
                std: weighted.std,
                covariance: weighted.covariance,
                correlation: weighted.correlation,
                identifiability,
                residual,
                rss,
                sigma,
                ..ordinary
            },
            whitened_sigma,
        ))
    }
}
