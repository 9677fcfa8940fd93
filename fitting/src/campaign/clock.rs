//! The campaign clock: one time axis for every record, when every record says when it started.
//!
//! A record's samples carry their time since the record's start (`t`, s). With a start `s_r` on the
//! campaign clock ([`simulation::campaign::CampaignRecord::start_s`]) sample `i` of record `r` is
//! at `T = s_r + t_i` on the campaign clock. The campaign's span `[T₀, T₁]` runs from the first
//! sample of all records to the last; the campaign's start is `T = 0`, the instant the records'
//! starts count from. The time bases are then taken on that clock:
//!
//! ```text
//! time:K      P_K(τ),  τ = 2·(T − T₀)/(T₁ − T₀) − 1      (0 when T₁ = T₀)
//! exp:TAU     1 − exp(−(T − T₀)/TAU)
//! rate        T                                          (s since the campaign's start)
//! warmup:TAU  1 − exp(−T/TAU)
//! ```
//!
//! so that one coefficient describes one drift over the whole campaign (a warm-up that goes on
//! between the records, measured at known times).
//!
//! The exact machine evaluates time bases on a record's own clock. A term on the campaign clock
//! is, on record `r`, exactly a combination of terms on the record's own clock
//! ([`own_clock_terms`]): `τ = a·τ_r + b` is affine in the record's own normalised time `τ_r`,
//! so `P_K(a·τ_r + b) = Σ_{j≤K} c_j·P_j(τ_r)` (`P_0` the constant);
//! `1 − e^{−(T−T₀)/TAU} = (1 − e^{−δ/TAU}) + e^{−δ/TAU}·(1 − e^{−(t−t_first)/TAU})` with
//! `δ = s_r + t_first − T₀`; `T = s_r + t` is a constant plus the record's own `rate`; and
//! `1 − e^{−T/TAU} = (1 − e^{−s_r/TAU}) + e^{−s_r/TAU}·(1 − e^{−t/TAU})`, a constant plus the
//! record's own `warmup:TAU`. The refinement and the exact validation use that rewriting.

use simulation::model::{Basis, Model, Term};
use simulation::record::Record;

/// The campaign clock's span `(T₀, T₁)`, s: the first and last sample times of all records on
/// the campaign clock; `None` when some record has no start (or there are no samples).
pub fn span(records: &[(&Record, Option<f64>)]) -> Option<(f64, f64)> {
    let mut out: Option<(f64, f64)> = None;
    for (r, start) in records {
        let start = (*start)?;
        let (Some(a), Some(b)) = (r.samples.first(), r.samples.last()) else {
            continue;
        };
        let (lo, hi) = (start + a.t, start + b.t);
        out = Some(match out {
            None => (lo, hi),
            Some((x, y)) => (x.min(lo), y.max(hi)),
        });
    }
    out
}

/// `true` for a basis whose value depends on the clock (`time:K`, `exp:TAU`, `rate`,
/// `warmup:TAU`: [`Basis::of_time`]).
pub fn on_clock(b: Basis) -> bool {
    b.of_time()
}

/// `record` with every sample's time moved to the campaign clock (`t + start`, s).
pub fn shifted(record: &Record, start_s: f64) -> Record {
    let mut r = record.clone();
    for s in &mut r.samples {
        s.t += start_s;
    }
    r
}

/// The Legendre coefficients `c_0 … c_K` of `P_K(a·x + b)` in `P_0(x) … P_K(x)`: the
/// recurrence `(k+1)·P_{k+1}(y) = (2k+1)·y·P_k(y) − k·P_{k−1}(y)` with `y = a·x + b`, the
/// product `x·P_j = ((j+1)·P_{j+1} + j·P_{j−1})/(2j+1)` done in coefficients.
pub fn legendre_affine(k: u32, a: f64, b: f64) -> Vec<f64> {
    let k = k as usize;
    let times_y = |v: &[f64]| -> Vec<f64> {
        let mut out = vec![0.0; v.len() + 1];
        for (j, &c) in v.iter().enumerate() {
            if c == 0.0 {
                continue;
            }
            let jf = j as f64;
            out[j + 1] += a * c * (jf + 1.0) / (2.0 * jf + 1.0);
            if j > 0 {
                out[j - 1] += a * c * jf / (2.0 * jf + 1.0);
            }
            out[j] += b * c;
        }
        out
    };
    let mut prev = vec![1.0];
    if k == 0 {
        return prev;
    }
    let mut cur = times_y(&prev);
    for n in 1..k {
        let nf = n as f64;
        let mut next = times_y(&cur);
        for x in &mut next {
            *x *= (2.0 * nf + 1.0) / (nf + 1.0);
        }
        for (j, &c) in prev.iter().enumerate() {
            next[j] -= nf / (nf + 1.0) * c;
        }
        prev = cur;
        cur = next;
    }
    cur.resize(k + 1, 0.0);
    cur
}

/// The terms of `model` with coefficients `values` (one per column, mm or rad), whose time
/// bases are on the campaign clock of span `span`, rewritten onto the own clock of `record`
/// started at `start_s` on the campaign clock: the same effect at every sample of the record,
/// as a model and one coefficient per column. Terms off the clock are kept as they are; terms
/// that come out twice (a constant from a drift and the model's own constant) are added.
pub fn own_clock_terms(
    model: &Model,
    values: &[f64],
    record: &Record,
    start_s: f64,
    span: (f64, f64),
) -> (Model, Vec<f64>) {
    let (t0, t1) = span;
    let (tf, tl) = match (record.samples.first(), record.samples.last()) {
        (Some(a), Some(b)) => (a.t, b.t),
        _ => (0.0, 0.0),
    };
    let mut out = Model::default();
    let mut coef: Vec<f64> = Vec::new();
    let mut add = |term: Term, c: &[f64]| {
        let mut at = 0;
        for t in &out.terms {
            if *t == term {
                for (k, x) in c.iter().enumerate() {
                    coef[at + k] += x;
                }
                return;
            }
            at += t.basis.width();
        }
        out.terms.push(term);
        coef.extend_from_slice(c);
    };
    let mut at = 0;
    for t in &model.terms {
        let w = t.basis.width();
        let v = &values[at..at + w];
        at += w;
        let with = |basis: Basis| Term {
            effect: t.effect,
            basis,
        };
        match t.basis {
            Basis::Time(k) => {
                let (a, b) = if t1 > t0 {
                    let a = (tl - tf) / (t1 - t0);
                    (a, 2.0 * (start_s + tf - t0) / (t1 - t0) - 1.0 + a)
                } else {
                    (0.0, 0.0)
                };
                // A record without a time span has a = 0: its τ_r is 0 at every sample and
                // the term is the constant P_K(b).
                let c = legendre_affine(k, a, b);
                for (j, cj) in c.iter().enumerate() {
                    let basis = if j == 0 {
                        Basis::Const
                    } else {
                        Basis::Time(j as u32)
                    };
                    if *cj != 0.0 {
                        add(with(basis), &[v[0] * cj]);
                    }
                }
            }
            Basis::Exp(_) => {
                let tau = t.basis.tau_s().unwrap_or(1.0);
                let delta = start_s + tf - t0;
                let keep = (-delta / tau).exp();
                add(with(Basis::Const), &[v[0] * -(-delta / tau).exp_m1()]);
                add(with(t.basis), &[v[0] * keep]);
            }
            // T = s_r + t: the rate times the record's start, then the record's own rate.
            Basis::Rate => {
                add(with(Basis::Const), &[v[0] * start_s]);
                add(*t, v);
            }
            // 1 − e^{−(s_r + t)/TAU}: the part reached at the record's start, then the rest of
            // the warm-up, from the record's own time 0, scaled by what is left of it.
            Basis::Warmup(_) => {
                let tau = t.basis.tau_s().unwrap_or(1.0);
                add(with(Basis::Const), &[v[0] * -(-start_s / tau).exp_m1()]);
                add(*t, &[v[0] * (-start_s / tau).exp()]);
            }
            _ => add(*t, v),
        }
    }
    (out, coef)
}

#[cfg(test)]
mod tests {
    use super::legendre_affine;
    use model_spec::basis::legendre;

    #[test]
    fn affine_legendre_expansions_match_direct_evaluation() {
        for k in [1u32, 2, 3, 7, 12] {
            for (a, b) in [(1.0, 0.0), (0.3, -0.4), (0.0, 0.7), (-0.5, 0.25)] {
                let c = legendre_affine(k, a, b);
                assert_eq!(c.len(), k as usize + 1);
                for x in [-1.0, -0.3, 0.0, 0.45, 1.0] {
                    let direct = legendre(k, a * x + b);
                    let expanded: f64 = c
                        .iter()
                        .enumerate()
                        .map(|(j, cj)| cj * legendre(j as u32, x))
                        .sum();
                    assert!((direct - expanded).abs() < 1e-12, "P{k}({a}x+{b}) at {x}");
                }
            }
        }
    }
}
