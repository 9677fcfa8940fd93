//! Scenario helpers of the diagnosis tests: the seed machine, the base truth (the 11 reduced
//! errors of `seed-ac-reduced` with 0.5 µm noise), hidden effects, test paths (the built-in K1, K2,
//! K4 and reversing paths built here), simulation on the exact virtual machine and the diagnosis.
#![allow(dead_code)]

use diagnosis::{DiagnoseOptions, Diagnosis, diagnose, one_record};
use formats::progress::Unwatched;
use formats::truth::builtin_truth;
use model_spec::Machine;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::{Model, Term};
use simulation::paths::{builtin_path, fill_linear_ik, record_from_commands};
use simulation::readings::simulate;
use simulation::record::Record;
use simulation::truth::Truth;

/// Reading noise of every scenario, mm (0.5 µm).
pub const NOISE_MM: f64 = 0.5e-3;

/// The diagnosis options of the tests: the defaults (α = 0.01, 1000 Monte-Carlo draws).
pub fn options() -> DiagnoseOptions {
    DiagnoseOptions::new()
}

/// The seed machine.
pub fn machine() -> Machine {
    model_spec::builtin("seed-ac")
        .expect("built in")
        .expect("valid")
}

/// The seed's reduced model (Table 2), optionally without some of its errors.
pub fn base_model(m: &Machine, without: &[&str]) -> Model {
    let mut model = Model::of(m, "reduced").expect("reduced model");
    model
        .terms
        .retain(|t| !without.iter().any(|w| t.spelling(m) == *w));
    assert_eq!(
        model.terms.len(),
        11 - without.len(),
        "every removed term was in the model"
    );
    model
}

/// The base truth: the 11 reduced errors of `seed-ac-reduced` (10–30 µm and µrad), 0.5 µm noise.
pub fn base_truth(m: &Machine) -> Truth {
    let mut t = builtin_truth("seed-ac-reduced", m)
        .expect("built in")
        .expect("valid");
    t.noise_mm = NOISE_MM;
    t
}

/// A hidden effect: a term (`ECC@harmonic:2`) and its value(s) in the units people see (µm or
/// µrad; `[cos, sin]` for a harmonic).
#[derive(Clone, Debug)]
pub struct Hidden {
    /// `NAME@BASIS` as in a sub-model list.
    pub term: &'static str,
    /// µm or µrad.
    pub values: Vec<f64>,
}

/// `term` with values (µm or µrad).
pub fn hidden(term: &'static str, values: &[f64]) -> Hidden {
    Hidden {
        term,
        values: values.to_vec(),
    }
}

/// Parses `NAME@BASIS`.
pub fn term(m: &Machine, s: &str) -> Term {
    Term::parse(m, s).unwrap_or_else(|e| panic!("term {s}: {e}"))
}

/// `truth` with the hidden effects added (converted to mm or rad).
pub fn with_hidden(m: &Machine, truth: &Truth, effects: &[Hidden]) -> Truth {
    let mut t = truth.clone();
    for h in effects {
        let term = term(m, h.term);
        assert_eq!(h.values.len(), term.basis.width(), "{}", h.term);
        assert!(
            !t.model.terms.contains(&term),
            "{} is already in the truth",
            h.term
        );
        let scale = if term.effect.is_angular(m) {
            1e-6
        } else {
            1e-3
        };
        t.model.terms.push(term);
        t.coefficients.extend(h.values.iter().map(|v| v * scale));
    }
    t
}

/// `truth` without the term `name` (a term it has).
pub fn without_term(m: &Machine, truth: &Truth, name: &str) -> Truth {
    let drop = term(m, name);
    let mut t = truth.clone();
    let mut at = 0;
    let mut model = Model::default();
    let mut coefficients = Vec::new();
    for tt in &truth.model.terms {
        let w = tt.basis.width();
        if *tt != drop {
            model.terms.push(*tt);
            coefficients.extend_from_slice(&truth.coefficients[at..at + w]);
        }
        at += w;
    }
    assert_eq!(
        model.terms.len() + 1,
        truth.model.terms.len(),
        "{name} is in the truth"
    );
    t.model = model;
    t.coefficients = coefficients;
    t
}

/// A test path: built-in (`K1`, `K2`, `K4`) or one of the reversing paths of [`reversing`].
pub fn path(m: &Machine, name: &str) -> Record {
    if let Some(r) = builtin_path(m, name) {
        return r.expect("built-in path");
    }
    reversing(m, name)
}

/// Reversing paths (linear axes by the nominal inverse kinematics, one sample a second):
/// - `K4R`: K4 (C = 1.5·i°, A = −45·(1 − cos C)°) out to C = 360° and back to 0° on the same
///   curve (481 samples): C reverses once, A, X, Y, Z with it;
/// - `K1R`: C from 0° to 360° and back in 2° steps at A = −30° (361 samples).
pub fn reversing(m: &Machine, name: &str) -> Record {
    let rotary: Vec<(f64, f64)> = match name {
        "K4R" => (0..=480)
            .map(|i| {
                let c = 1.5 * if i <= 240 { i } else { 480 - i } as f64;
                (-45.0 * (1.0 - c.to_radians().cos()) + 0.0, c)
            })
            .collect(),
        "K1R" => (0..=360)
            .map(|i| (-30.0, 2.0 * if i <= 180 { i } else { 360 - i } as f64))
            .collect(),
        other => panic!("unknown path {other}"),
    };
    let (a, c) = (m.axis_by_name("A").unwrap(), m.axis_by_name("C").unwrap());
    let mut commands: Vec<Vec<f64>> = rotary
        .iter()
        .map(|&(da, dc)| {
            let mut q = vec![0.0; m.axes.len()];
            q[a] = da.to_radians();
            q[c] = dc.to_radians();
            q
        })
        .collect();
    fill_linear_ik(m, &m.default_parameters(), &mut commands).expect("inverse kinematics");
    let n = commands.len();
    record_from_commands(commands, (0..n).map(|i| i as f64).collect())
}

/// Simulated records of `truth` on the named paths, the noise seed `seed + k` on the k-th.
pub fn records(m: &Machine, truth: &Truth, paths: &[&str], seed: u64) -> Vec<(String, Record)> {
    paths
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let mut t = truth.clone();
            t.seed = seed.wrapping_mul(7919).wrapping_add(k as u64);
            (
                p.to_string(),
                simulate(m, &t, &path(m, p)).expect("simulate"),
            )
        })
        .collect()
}

/// The diagnosis of `base` on the first record, the others held out on its set-up.
pub fn run(m: &Machine, base: &Model, recs: &[(String, Record)], o: &DiagnoseOptions) -> Diagnosis {
    let (fitted, held) = one_record(
        &recs[0].0,
        recs[0].1.clone(),
        recs[1..].to_vec(),
        m.default_parameters(),
        false,
    )
    .expect("campaigns");
    diagnose(m, base, &fitted, &held, o, &Unwatched).expect("diagnosis")
}

/// The sample of K4 at which a knocked ball moves ([`knocked`]).
pub const KNOCK_AT: usize = 150;

/// `truth` with the term `name` (a ball set-up error `XOW`, `YOW`, `ZOW` of it) moved by `um`
/// µm.
pub fn moved(m: &Machine, truth: &Truth, name: &str, um: f64) -> Truth {
    let t = term(m, name);
    let mut out = truth.clone();
    let mut at = 0;
    for tt in &truth.model.terms {
        if *tt == t {
            out.coefficients[at] += um * 1e-3;
            return out;
        }
        at += tt.basis.width();
    }
    panic!("{name} is not in the truth");
}

/// K4, K1, K2 of `truth` (noise seeds `seed`, `seed + 1`, `seed + 2`), K4 with the ball
/// knocked by `um` µm along the set-up error `name` from sample [`KNOCK_AT`] on (the same noise
/// before and after); K1 and K2 on the set-up as it was at the start of K4.
pub fn knocked(
    m: &Machine,
    truth: &Truth,
    name: &str,
    um: f64,
    seed: u64,
) -> Vec<(String, Record)> {
    let mut recs: Vec<(String, Record)> = ["K4", "K1", "K2"]
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let mut t = truth.clone();
            t.seed = seed + k as u64;
            (
                p.to_string(),
                simulate(m, &t, &path(m, p)).expect("simulate"),
            )
        })
        .collect();
    let mut after = moved(m, truth, name, um);
    after.seed = seed;
    let shifted = simulate(m, &after, &path(m, "K4")).expect("simulate");
    recs[0].1.measured[KNOCK_AT..].copy_from_slice(&shifted.measured[KNOCK_AT..]);
    recs
}

/// The diagnosis of `base` on the first `fitted` records together (one set-up, the first's
/// label), the others held out on it.
pub fn run_fitted(
    m: &Machine,
    base: &Model,
    recs: &[(String, Record)],
    fitted: usize,
    o: &DiagnoseOptions,
) -> Diagnosis {
    let campaign = |rs: &[(String, Record)]| {
        Campaign::new(
            rs.iter()
                .map(|(label, r)| {
                    CampaignRecord::new(label, r.clone(), m.default_parameters(), &recs[0].0, false)
                })
                .collect(),
        )
        .expect("campaign")
    };
    let (fit, held) = (campaign(&recs[..fitted]), campaign(&recs[fitted..]));
    diagnose(m, base, &fit, &held, o, &Unwatched).expect("diagnosis")
}

/// Pooled residual RMS over the held-out records, before and after (µm): the square root of the
/// sample-weighted mean of the per-record mean squares.
pub fn held_out_rms(d: &Diagnosis, recs: &[(String, Record)]) -> (f64, f64) {
    let mut s = (0.0, 0.0, 0.0);
    for (h, (_, r)) in d.validation.iter().zip(&recs[1..]) {
        let n = r.samples.len() as f64;
        s.0 += n * h.before_rms * h.before_rms;
        s.1 += n * h.after_rms * h.after_rms;
        s.2 += n;
    }
    ((s.0 / s.2).sqrt() * 1e3, (s.1 / s.2).sqrt() * 1e3)
}

/// RMS (µm) of what the hidden effects alone add to the readings on a path (noise free, exact
/// machine): the signature's size before any fit.
pub fn signature_rms(m: &Machine, truth: &Truth, effects: &[Hidden], path_name: &str) -> f64 {
    let mut base = truth.clone();
    base.noise_mm = 0.0;
    let with = with_hidden(m, &base, effects);
    let p = path(m, path_name);
    let a = simulate(m, &base, &p).unwrap().measured;
    let b = simulate(m, &with, &p).unwrap().measured;
    let ss: f64 = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (0..3).map(|d| (x[d] - y[d]).powi(2)).sum::<f64>())
        .sum();
    (ss / (3 * a.len()) as f64).sqrt() * 1e3
}

/// One line for people: the findings (name, p-value, alternatives) and the gain.
pub fn summary(m: &Machine, d: &Diagnosis, recs: &[(String, Record)]) -> String {
    let f: Vec<String> = d
        .findings
        .iter()
        .map(|f| {
            let alts: Vec<String> = f.alternatives.iter().map(|t| t.spelling(m)).collect();
            format!(
                "{} (p {:.1e} {:?}{})",
                f.term.spelling(m),
                f.p_value,
                f.correction,
                if alts.is_empty() {
                    String::new()
                } else {
                    format!(", or {}", alts.join("/"))
                }
            )
        })
        .collect();
    let (hb, ha) = held_out_rms(d, recs);
    let per: Vec<String> = d
        .validation
        .iter()
        .map(|h| {
            format!(
                "{} {:.2}→{:.2}",
                h.name,
                h.before_rms * 1e3,
                h.after_rms * 1e3
            )
        })
        .collect();
    format!(
        "found [{}]; fit {:.2}→{:.2} µm; held out {hb:.2}→{ha:.2} µm ({})",
        f.join(", "),
        d.fit_rms.0 * 1e3,
        d.fit_rms.1 * 1e3,
        per.join(", ")
    )
}
