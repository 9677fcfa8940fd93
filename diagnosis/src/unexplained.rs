//! What remains unexplained, described: per direction of a residual that the noise does not
//! account for, what it follows and its shape.
//!
//! Sources (each varying on the record): the position of every axis that moves (degrees for a
//! rotary axis, mm for a linear one), time (s since the first sample), the velocity of every
//! axis that moves (per s, from central differences of the commands over time), and the
//! direction of motion of every axis that moves both ways.
//!
//! Shapes, each fitted with an intercept by least squares against one source:
//! - `smooth`: harmonics 1–4 of a rotary position, Legendre polynomials 1–4 of any other
//!   source normalised over its range (8 or 4 parameters);
//! - `periodic`: a sinusoid of a period scanned over a grid: for a linear position, time or a
//!   velocity, [`PERIODS`] periods on a geometric grid from three sample spacings to two thirds
//!   of the range; for a rotary position, the harmonics 5–24 (3 parameters with the scan);
//! - `step`: constant below a position, constant from it on, the position scanned over the
//!   values between the 5 % and 95 % quantiles of the source (3 parameters with the scan);
//! - `local`: a box over consecutive samples in record order, at most a seventh of the record
//!   long, its place and length scanned (3 parameters with the scan).
//!
//! The description is the (source, shape) with the smallest Bayesian information criterion
//! `n·ln(RSS/n) + k·ln n`, and only when it beats the intercept alone by more than `2·ln N`,
//! N the number of shapes tried (every scanned value counts: some 3000 on K4), so that the best
//! of many shapes fitted to noise is not taken for structure; otherwise the residual follows
//! nothing simple (`irregular`). Shapes of sources that move together (on K4 every axis
//! moves with C) can describe the same residual: the description names the best, which is an
//! indication of where to look, not a cause.

use model_spec::basis::legendre;
use model_spec::{AxisKind, Machine};
use nalgebra::{DMatrix, DVector};
use simulation::record::Record;

/// Number of scanned periods of a `periodic` shape of a linear position, time or velocity.
pub const PERIODS: usize = 80;

/// The shape of what remains.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Low-order harmonics or polynomials of the source.
    Smooth,
    /// A sinusoid of this period, in the source's unit (a rotary position: 360 / k degrees).
    Periodic {
        /// The period, in the source's unit.
        period: f64,
    },
    /// A jump at this value of the source.
    Step {
        /// Where, in the source's unit.
        at: f64,
    },
    /// A deviation over consecutive samples.
    Local {
        /// First sample (0-based, record order).
        first: usize,
        /// Last sample.
        last: usize,
    },
    /// Nothing simple: no shape beats the intercept alone.
    Irregular,
}

/// What remains in one direction, described.
#[derive(Clone, Debug, PartialEq)]
pub struct Unexplained {
    /// The record's name (fitted or held out).
    pub data: String,
    /// 0, 1, 2 for x, y, z.
    pub direction: usize,
    /// RMS of the residual in that direction, mm.
    pub rms_mm: f64,
    /// What the residual follows (`C`, `X`, `time`, `velocity of A`, `direction of motion of
    /// C`); `None` when irregular.
    pub follows: Option<String>,
    /// The unit of that source (`deg`, `mm`, `s`, `deg/s`, `mm/s`, `±1`).
    pub unit: String,
    /// Its shape.
    pub shape: Shape,
    /// RMS of what the shape explains (the fitted shape minus its mean), mm.
    pub explained_rms_mm: f64,
    /// For a step in a source that moves one way along the record (time, an axis turning one
    /// way): the first sample (0-based, record order) past the jump; `None` otherwise.
    pub sample: Option<usize>,
    /// `true` when this describes the base model's residual on a fitted record
    /// ([`describe_base`]); `false` for the extended model's residual.
    pub base: bool,
    /// The source's value per sample (record order), for a figure.
    pub x: Vec<f64>,
    /// The fitted shape per sample, mm.
    pub fitted: Vec<f64>,
}

/// One source: its name, unit, values, kind.
struct Source {
    name: String,
    unit: &'static str,
    x: Vec<f64>,
    rotary: bool,
    sign: bool,
}

fn sources(m: &Machine, record: &Record) -> Vec<Source> {
    let n = record.samples.len();
    let t: Vec<f64> = record
        .samples
        .iter()
        .map(|s| s.t - record.samples[0].t)
        .collect();
    let mut out = Vec::new();
    let varies = |x: &[f64]| {
        let (lo, hi) = range(x);
        hi - lo > 1e-9
    };
    for (a, axis) in m.axes.iter().enumerate() {
        let rotary = axis.kind == AxisKind::Rotary;
        let k = if rotary {
            180.0 / std::f64::consts::PI
        } else {
            1.0
        };
        let x: Vec<f64> = record.samples.iter().map(|s| s.commands[a] * k).collect();
        if !varies(&x) {
            continue;
        }
        let v: Vec<f64> = (0..n)
            .map(|i| {
                let (p, q) = (i.saturating_sub(1), (i + 1).min(n - 1));
                let dt = t[q] - t[p];
                if dt > 0.0 { (x[q] - x[p]) / dt } else { 0.0 }
            })
            .collect();
        let motion: Vec<f64> = record
            .samples
            .iter()
            .map(|s| f64::from(s.motion[a]))
            .collect();
        let unit = if rotary { "deg" } else { "mm" };
        out.push(Source {
            name: axis.name.clone(),
            unit,
            x,
            rotary,
            sign: false,
        });
        if varies(&v) {
            out.push(Source {
                name: format!("velocity of {}", axis.name),
                unit: if rotary { "deg/s" } else { "mm/s" },
                x: v,
                rotary: false,
                sign: false,
            });
        }
        if varies(&motion) {
            out.push(Source {
                name: format!("direction of motion of {}", axis.name),
                unit: "±1",
                x: motion,
                rotary: false,
                sign: true,
            });
        }
    }
    if varies(&t) {
        out.push(Source {
            name: "time".into(),
            unit: "s",
            x: t,
            rotary: false,
            sign: false,
        });
    }
    out
}

fn range(x: &[f64]) -> (f64, f64) {
    x.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        })
}

/// Least squares of `y` on an intercept and `cols`: the fitted values, `None` when singular.
fn fit(cols: &[Vec<f64>], y: &[f64]) -> Option<Vec<f64>> {
    let n = y.len();
    let k = cols.len() + 1;
    if n <= k {
        return None;
    }
    let a = DMatrix::from_fn(n, k, |i, j| if j == 0 { 1.0 } else { cols[j - 1][i] });
    let svd = a.clone().svd(true, true);
    let tol = svd.singular_values.max() * 1e-10;
    if svd.singular_values.iter().filter(|&&s| s > tol).count() < k {
        return None;
    }
    let b = svd.solve(&DVector::from_column_slice(y), tol).ok()?;
    Some((a * b).as_slice().to_vec())
}

fn rss(y: &[f64], f: &[f64]) -> f64 {
    y.iter().zip(f).map(|(a, b)| (a - b).powi(2)).sum()
}

/// A candidate description: shape, its parameters (with the scan), fitted values.
struct Tried {
    shape: Shape,
    params: usize,
    fitted: Vec<f64>,
    /// Shapes tried to find it (scanned values).
    tried: usize,
}

fn smooth(s: &Source, y: &[f64]) -> Option<Tried> {
    let (lo, hi) = range(&s.x);
    let cols: Vec<Vec<f64>> = if s.rotary {
        (1..=4)
            .flat_map(|k| {
                let f = |g: fn(f64) -> f64| {
                    s.x.iter()
                        .map(|v| g(k as f64 * v.to_radians()))
                        .collect::<Vec<f64>>()
                };
                [f(f64::cos), f(f64::sin)]
            })
            .collect()
    } else if s.sign {
        vec![s.x.clone()]
    } else {
        (1..=4)
            .map(|k| {
                s.x.iter()
                    .map(|v| legendre(k, 2.0 * (v - lo) / (hi - lo) - 1.0))
                    .collect()
            })
            .collect()
    };
    let params = cols.len() + 1;
    fit(&cols, y).map(|fitted| Tried {
        shape: Shape::Smooth,
        params,
        fitted,
        tried: 1,
    })
}

fn best(tries: impl Iterator<Item = Tried>, y: &[f64]) -> Option<Tried> {
    let mut count = 0;
    let mut b = tries
        .inspect(|_| count += 1)
        .min_by(|a, b| rss(y, &a.fitted).total_cmp(&rss(y, &b.fitted)))?;
    b.tried = count;
    Some(b)
}

fn periodic(s: &Source, y: &[f64]) -> Option<Tried> {
    if s.sign {
        return None;
    }
    let sine = |w: f64| -> Vec<Vec<f64>> {
        vec![
            s.x.iter().map(|v| (w * v).cos()).collect(),
            s.x.iter().map(|v| (w * v).sin()).collect(),
        ]
    };
    let tries: Vec<(f64, Vec<Vec<f64>>)> = if s.rotary {
        (5..=24)
            .map(|k| {
                (
                    360.0 / k as f64,
                    sine(k as f64 * std::f64::consts::PI / 180.0),
                )
            })
            .collect()
    } else {
        let (lo, hi) = range(&s.x);
        let mut sorted = s.x.clone();
        sorted.sort_by(f64::total_cmp);
        sorted.dedup();
        let mut gaps: Vec<f64> = sorted.windows(2).map(|w| w[1] - w[0]).collect();
        gaps.sort_by(f64::total_cmp);
        let spacing = gaps.get(gaps.len() / 2).copied().unwrap_or(0.0);
        let (p0, p1) = (3.0 * spacing, (hi - lo) / 1.5);
        if !(spacing > 0.0 && p1 > p0) {
            return None;
        }
        (0..PERIODS)
            .map(|i| {
                let p = p0 * (p1 / p0).powf(i as f64 / (PERIODS - 1) as f64);
                (p, sine(std::f64::consts::TAU / p))
            })
            .collect()
    };
    best(
        tries.into_iter().filter_map(|(period, cols)| {
            fit(&cols, y).map(|fitted| Tried {
                shape: Shape::Periodic { period },
                params: 3,
                fitted,
                tried: 1,
            })
        }),
        y,
    )
}

fn step(s: &Source, y: &[f64]) -> Option<Tried> {
    let mut sorted = s.x.clone();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let (a, b) = (n / 20, n - 1 - n / 20);
    let mut at: Vec<f64> = (a..b)
        .filter(|&i| sorted[i + 1] > sorted[i])
        .map(|i| 0.5 * (sorted[i] + sorted[i + 1]))
        .collect();
    at.dedup();
    let stride = at.len().div_ceil(60).max(1);
    best(
        at.iter().step_by(stride).filter_map(|&v| {
            let col: Vec<f64> = s.x.iter().map(|x| f64::from(u8::from(*x >= v))).collect();
            fit(&[col], y).map(|fitted| Tried {
                shape: Shape::Step { at: v },
                params: 2,
                fitted,
                tried: 1,
            })
        }),
        y,
    )
}

/// The box over consecutive samples that explains most: prefix sums give every window's mean.
fn local(y: &[f64]) -> Option<Tried> {
    let n = y.len();
    let longest = (n / 7).max(1);
    let mut prefix = vec![0.0; n + 1];
    for i in 0..n {
        prefix[i + 1] = prefix[i] + y[i];
    }
    let total = prefix[n];
    let mut best: Option<(f64, usize, usize)> = None;
    for first in 0..n {
        for len in 1..=longest.min(n - first - 1) {
            // Inside mean and outside mean: the gain over the intercept alone.
            let inside = prefix[first + len] - prefix[first];
            let (m_in, m_out) = (inside / len as f64, (total - inside) / (n - len) as f64);
            let mean = total / n as f64;
            let gain =
                len as f64 * (m_in - mean).powi(2) + (n - len) as f64 * (m_out - mean).powi(2);
            if best.is_none_or(|b| gain > b.0) {
                best = Some((gain, first, first + len - 1));
            }
        }
    }
    let tried = (0..n).map(|f| longest.min(n - f - 1)).sum();
    let (_, first, last) = best?;
    let col: Vec<f64> = (0..n)
        .map(|i| f64::from(u8::from(i >= first && i <= last)))
        .collect();
    fit(&[col], y).map(|fitted| Tried {
        shape: Shape::Local { first, last },
        params: 2,
        fitted,
        tried,
    })
}

/// The description of the residual `residual[i][direction]` (mm, samples of `record` in
/// order).
pub fn describe(
    m: &Machine,
    (data, record): (&str, &Record),
    residual: &[[f64; 3]],
    direction: usize,
) -> Unexplained {
    let y: Vec<f64> = residual.iter().map(|r| r[direction]).collect();
    let n = y.len().max(1) as f64;
    let mean = y.iter().sum::<f64>() / n;
    let rss0 = y.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
    let bic = |rss: f64, k: usize| n * (rss.max(f64::MIN_POSITIVE) / n).ln() + k as f64 * n.ln();
    let mut found: Option<(f64, String, &'static str, Vec<f64>, Tried)> = None;
    let mut tried = 0;
    for s in sources(m, record) {
        let tries = [smooth(&s, &y), periodic(&s, &y), step(&s, &y)];
        for t in tries.into_iter().flatten() {
            tried += t.tried;
            let b = bic(rss(&y, &t.fitted), t.params);
            if found.as_ref().is_none_or(|f| b < f.0) {
                found = Some((b, s.name.clone(), s.unit, s.x.clone(), t));
            }
        }
    }
    if let Some(t) = local(&y) {
        tried += t.tried;
        let b = bic(rss(&y, &t.fitted), t.params);
        if found.as_ref().is_none_or(|f| b < f.0) {
            let x: Vec<f64> = (0..y.len()).map(|i| i as f64).collect();
            found = Some((b, "sample".into(), "", x, t));
        }
    }
    let rms_mm = (y.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
    match found {
        Some((b, name, unit, x, t)) if b < bic(rss0, 1) - 2.0 * (tried.max(1) as f64).ln() => {
            let explained = ((rss0 - rss(&y, &t.fitted)).max(0.0) / n).sqrt();
            let sample = match t.shape {
                Shape::Step { at } => split_at(&x, at),
                _ => None,
            };
            Unexplained {
                data: data.to_string(),
                direction,
                rms_mm,
                follows: Some(name),
                unit: unit.into(),
                shape: t.shape,
                explained_rms_mm: explained,
                sample,
                base: false,
                x,
                fitted: t.fitted,
            }
        }
        _ => Unexplained {
            data: data.to_string(),
            direction,
            rms_mm,
            follows: None,
            unit: String::new(),
            shape: Shape::Irregular,
            explained_rms_mm: 0.0,
            sample: None,
            base: false,
            x: (0..y.len()).map(|i| i as f64).collect(),
            fitted: vec![mean; y.len()],
        },
    }
}

/// The first sample past a step at `at` of a source `x` that moves one way along the record
/// (every sample before it below `at`, every one from it on above, or the reverse); `None`
/// when the step does not split the record in two.
fn split_at(x: &[f64], at: f64) -> Option<usize> {
    let first = x.iter().position(|&v| (v >= at) != (x[0] >= at))?;
    let side = x[first] >= at;
    x[first..]
        .iter()
        .all(|&v| (v >= at) == side)
        .then_some(first)
}

/// What the base model leaves on the fitted records where the lack-of-fit test `a` of the
/// extended model fails (nothing when it passes): the findings may have absorbed on the fitted
/// records what the held-out records then mispredict (a look-alike of a jump, a bump), so the
/// base residual is described where it is, in every direction of a fitted record whose RMS is
/// more than [`super::adequacy::NOISE_MULTIPLE`] times the noise's σ, and kept when it follows
/// something (an irregular base residual adds nothing to the extended model's description).
/// `fitted`: name, record and base residual per sample (mm) of every fitted record.
pub fn describe_base(
    m: &Machine,
    a: &super::adequacy::Adequacy,
    fitted: &[(&str, &Record, Vec<[f64; 3]>)],
) -> Vec<Unexplained> {
    if a.consistent_with_noise {
        return Vec::new();
    }
    let Some(sigma) = a.records.first().map(|r| r.noise_sigma_mm) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (name, rec, res) in fitted {
        let n = res.len().max(1) as f64;
        for d in 0..3 {
            let rms = (res.iter().map(|v| v[d] * v[d]).sum::<f64>() / n).sqrt();
            if rms <= super::adequacy::NOISE_MULTIPLE * sigma[d] {
                continue;
            }
            let mut u = describe(m, (name, rec), res, d);
            if u.shape != Shape::Irregular {
                u.base = true;
                out.push(u);
            }
        }
    }
    out
}

/// What remains where the lack-of-fit test `a` fails (nothing when it passes): every (record,
/// direction) whose own p-value passes after a Bonferroni factor over all of them or whose
/// residual is more than [`super::adequacy::NOISE_MULTIPLE`] times the noise, and at least the
/// one with the smallest p-value. `records`: name, record and residual per sample (mm), in the
/// order of `a.records`.
pub fn describe_failures(
    m: &Machine,
    a: &super::adequacy::Adequacy,
    records: &[(&str, &Record, Vec<[f64; 3]>)],
    alpha: f64,
) -> Vec<Unexplained> {
    if a.consistent_with_noise {
        return Vec::new();
    }
    let tests = 3.0 * a.records.len() as f64;
    let smallest = a
        .records
        .iter()
        .flat_map(|r| r.p_values)
        .fold(f64::INFINITY, f64::min);
    let mut out = Vec::new();
    for (k, (r, (name, rec, res))) in a.records.iter().zip(records).enumerate() {
        let described = |d: usize| {
            tests * r.p_values[d] < alpha
                || r.p_values[d] == smallest
                || a.over_noise.contains(&(k, d))
        };
        for d in (0..3).filter(|&d| described(d)) {
            out.push(describe(m, (name, rec), res, d));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use simulation::paths::builtin_path;
    use simulation::rng::Rng;

    fn k4() -> (Machine, Record) {
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let r = builtin_path(&m, "K4").unwrap().unwrap();
        (m, r)
    }

    /// Residual rows: `f` of (sample index, commands in degrees/mm) in direction 1, plus 0.5 µm
    /// noise in every direction.
    fn residual(
        m: &Machine,
        r: &Record,
        seed: u64,
        f: impl Fn(usize, &[f64]) -> f64,
    ) -> Vec<[f64; 3]> {
        let mut rng = Rng::new(seed);
        r.samples
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let c: Vec<f64> = m
                    .axes
                    .iter()
                    .zip(&s.commands)
                    .map(|(a, v)| {
                        if a.kind == AxisKind::Rotary {
                            v.to_degrees()
                        } else {
                            *v
                        }
                    })
                    .collect();
                [
                    5e-4 * rng.normal(),
                    f(i, &c) + 5e-4 * rng.normal(),
                    5e-4 * rng.normal(),
                ]
            })
            .collect()
    }

    #[test]
    fn a_step_of_c_is_a_step_near_its_position() {
        let (m, r) = k4();
        let c = m.axis_by_name("C").unwrap();
        for seed in 1..=5 {
            let res = residual(&m, &r, seed, |_, q| if q[c] >= 90.0 { 5e-3 } else { 0.0 });
            let u = describe(&m, ("K4", &r), &res, 1);
            assert_eq!(u.follows.as_deref(), Some("C"), "seed {seed}: {u:?}");
            match u.shape {
                Shape::Step { at } => assert!((at - 90.0).abs() < 2.0, "seed {seed}: at {at}"),
                ref s => panic!("seed {seed}: {s:?}"),
            }
            // The step explains nearly all of the residual's spread.
            let y: Vec<f64> = res.iter().map(|v| v[1]).collect();
            let mean = y.iter().sum::<f64>() / y.len() as f64;
            let sd = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / y.len() as f64).sqrt();
            assert!(
                u.explained_rms_mm > 0.95 * sd,
                "seed {seed}: {} of {sd}",
                u.explained_rms_mm
            );
        }
    }

    #[test]
    fn a_ballscrew_period_of_x_is_periodic_with_its_period() {
        let (m, r) = k4();
        let x = m.axis_by_name("X").unwrap();
        for seed in 1..=5 {
            let res = residual(&m, &r, seed, |_, q| {
                2e-3 * (std::f64::consts::TAU * q[x] / 10.0).sin()
            });
            let u = describe(&m, ("K4", &r), &res, 1);
            assert_eq!(u.follows.as_deref(), Some("X"), "seed {seed}: {u:?}");
            match u.shape {
                Shape::Periodic { period } => {
                    assert!((period - 10.0).abs() < 0.3, "seed {seed}: period {period}")
                }
                ref s => panic!("seed {seed}: {s:?}"),
            }
        }
    }

    #[test]
    fn a_bump_over_a_few_samples_is_local() {
        let (m, r) = k4();
        for seed in 1..=5 {
            let res = residual(&m, &r, seed, |i, _| {
                if (100..106).contains(&i) { 1e-2 } else { 0.0 }
            });
            let u = describe(&m, ("K4", &r), &res, 1);
            match u.shape {
                Shape::Local { first, last } => {
                    assert_eq!((first, last), (100, 105), "seed {seed}")
                }
                // A box of samples 100..=105 is also a step pair of C; a step alone is not.
                ref s => panic!("seed {seed}: {s:?} following {:?}", u.follows),
            }
        }
    }

    #[test]
    fn a_knock_is_a_step_at_its_sample() {
        // The ball knocked 3 µm at sample 150 of K4: on K4 C turns one way, so whichever source
        // the step is found in (time or C), the sample past the jump is 150.
        let (m, r) = k4();
        for seed in 1..=5 {
            let res = residual(&m, &r, seed, |i, _| if i >= 150 { 3e-3 } else { 0.0 });
            let u = describe(&m, ("K4", &r), &res, 1);
            assert!(matches!(u.shape, Shape::Step { .. }), "seed {seed}: {u:?}");
            let at = u.sample.expect("a step that splits the record");
            assert!(at.abs_diff(150) <= 2, "seed {seed}: sample {at}");
        }
    }

    #[test]
    fn noise_follows_nothing() {
        let (m, r) = k4();
        let mut irregular = 0;
        for seed in 1..=20 {
            let res = residual(&m, &r, seed, |_, _| 0.0);
            let u = describe(&m, ("K4", &r), &res, 1);
            irregular += usize::from(u.shape == Shape::Irregular);
        }
        // The best of some 3000 shapes must beat the intercept by 2·ln N on top of the BIC.
        assert!(irregular >= 19, "{irregular} of 20 irregular");
    }
}
