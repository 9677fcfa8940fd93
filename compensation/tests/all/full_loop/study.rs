//! The full calibration loop on a full error budget, on the exact virtual machine: a campaign of
//! `seed-ac-budget` diagnosed, identified with the reduced model, with the diagnosis's extended
//! model and with the truth's own terms, each compensated, and 200 random five-axis poses at a
//! ball position no record had, compensated and run on the exact machine
//! (docs/compensation.md, "The full loop on a full budget").
//!
//! - The campaign: K4, K1 and K2 with the ball at the description's position (set-up `low`) and
//!   K4 and K1 with the ball 50 mm higher (`Zw + 50`, set-up `high`); noise seed `s` gives the
//!   five records the generator seeds `5·(s − 1) + 1` … `5·s` in that order; noise, reading
//!   drift and set-up errors as the truth has them.
//! - The check: [`POSES`] random poses (A uniform in −90…0°, C in 0…360°, the linear axes on the
//!   ball by the nominal inverse kinematics) with the ball at `Zw + 25`, a new mounting. The
//!   machine's own error (the ball's position error in the tool frame, the ball's set-up errors,
//!   the reading drift and the noise left out) before and after compensation; after, also with
//!   the new set-up's errors fitted to it with the machine's values held, as an R-test on that
//!   ball sees it ([`compensation::verify::setup_refitted`]).
//! - The models: the reduced one; the diagnosis's extended model (identified under the
//!   `minimum-norm` constraint when the campaign does not determine it, as `rtest compensate`
//!   then asks); the truth's own terms with every confounded group made determined by fixing
//!   all members but one to zero; the truth's own terms under `minimum-norm`.

use compensation::run::{CommandedPose, compensate_poses};
use compensation::values::MachineErrors;
use compensation::verify::{SetupRefitted, setup_refitted};
use diagnosis::{DiagnoseOptions, Diagnosis, diagnose};
use fitting::campaign::{CampaignIdentification, CampaignValues, Owner};
use fitting::least_squares::Constraint;
use fitting::{IdentifyOptions, NoiseChoice, RefineOptions};
use formats::truth::builtin_truth;
use model_spec::Machine;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::exact::VirtualMachine;
use simulation::model::Model;
use simulation::rng::Rng;
use simulation::{Truth, builtin_path, simulate};

/// The random poses of the check.
pub const POSES: usize = 200;
/// The ball of the check above the description's position, mm (between the campaign's two).
pub const CHECK_RAISE_MM: f64 = 25.0;
/// The ball of the campaign's second set-up above the description's position, mm.
pub const HIGH_RAISE_MM: f64 = 50.0;
/// The seed of the random poses (the same poses at every noise seed).
pub const POSE_SEED: u64 = 230;

/// One figure: a model identified on the campaign, compensated, checked on the poses.
#[derive(Clone, Debug)]
pub struct Figure {
    /// What it is.
    pub name: String,
    /// The model (its terms' spellings joined, or its name).
    pub model: String,
    /// The machine's own error before compensation and after it, µm RMS over the three
    /// directions (no set-up refitted on either).
    pub before_um: f64,
    /// After compensation, µm.
    pub after_um: f64,
    /// After compensation with the new set-up's errors fitted, µm.
    pub after_refitted_um: f64,
    /// Before compensation with the new set-up's errors fitted, µm.
    pub before_refitted_um: f64,
    /// The parameters fixed to zero to make the fit determined (the oracle's).
    pub zeroed: Vec<String>,
    /// What the compensation leaves of each machine term (the truth's and the model's): the
    /// RMS over the poses of its first-order error `gains·(true − identified)`, µm, largest
    /// first.
    pub remains: Vec<(String, f64)>,
}

impl Figure {
    /// The fall with the set-up refitted, against the machine's error before: 0.9 is 90 % less.
    pub fn fall_refitted(&self) -> f64 {
        1.0 - self.after_refitted_um / self.before_um
    }

    /// The fall without the set-up refitted.
    pub fn fall(&self) -> f64 {
        1.0 - self.after_um / self.before_um
    }
}

/// The outcome at one noise seed.
pub struct Study {
    /// The noise seed.
    pub seed: u64,
    /// The diagnosis's findings (spellings), in order; plausible ones only.
    pub findings: Vec<String>,
    /// Whether the diagnosis recommends its extended model, and why (not).
    pub recommended: bool,
    /// The recommendation's reasons.
    pub reasons: Vec<String>,
    /// The campaign's residual RMS under the base and the extended model, µm.
    pub fit_rms_um: (f64, f64),
    /// Why the selection stopped; whether the extended model's residual is consistent with the
    /// noise (`None`: no test).
    pub stop: (String, Option<bool>),
    /// The extended model's shared parameters the campaign does not determine (then it is
    /// identified under the `minimum-norm` constraint).
    pub undetermined: Vec<String>,
    /// The reduced model; the diagnosis's extended model; the truth's own terms made
    /// determined by `zero:` on all but one member of each confounded group; the truth's own
    /// terms under the `minimum-norm` constraint.
    pub figures: Vec<Figure>,
}

/// Where the study is, with the time since it began (standard error; `FULL_LOOP_QUIET` set: no
/// output).
fn progress(what: &str) {
    use std::sync::OnceLock;
    static START: OnceLock<std::time::Instant> = OnceLock::new();
    let start = START.get_or_init(std::time::Instant::now);
    if std::env::var_os("FULL_LOOP_QUIET").is_none() {
        eprintln!("[{:7.1} s] {what}", start.elapsed().as_secs_f64());
    }
}

/// The built-in machine `seed-ac`.
pub fn seed_ac() -> Machine {
    model_spec::builtin("seed-ac").unwrap().unwrap()
}

/// The truth `seed-ac-budget`.
pub fn budget(m: &Machine) -> Truth {
    builtin_truth("seed-ac-budget", m).unwrap().unwrap()
}

/// `params` with `Zw` raised by `mm`.
fn raised(m: &Machine, params: &[f64], mm: f64) -> Vec<f64> {
    let mut p = params.to_vec();
    p[m.symbol_by_name("Zw").unwrap()] += mm;
    p
}

/// The campaign at noise seed `seed` (see the module documentation).
pub fn campaign(m: &Machine, truth: &Truth, seed: u64) -> Campaign {
    campaign_of(m, truth, seed, false)
}

/// The campaign at noise seed `seed`, with `k2_high` a sixth record: K2 with the ball at the
/// higher position (generator seed `1000 + seed`), so that A sweeps with C still on two records.
pub fn campaign_of(m: &Machine, truth: &Truth, seed: u64, k2_high: bool) -> Campaign {
    let mut paths = vec![
        ("K4", 0.0),
        ("K1", 0.0),
        ("K2", 0.0),
        ("K4", HIGH_RAISE_MM),
        ("K1", HIGH_RAISE_MM),
    ];
    if k2_high {
        paths.push(("K2", HIGH_RAISE_MM));
    }
    let records = paths
        .into_iter()
        .enumerate()
        .map(|(k, (path, raise))| {
            let params = raised(m, &m.default_parameters(), raise);
            let mut t = truth.clone();
            t.seed = if k < 5 {
                5 * (seed - 1) + k as u64 + 1
            } else {
                1000 + seed
            };
            t.params = raised(m, &truth.params, raise);
            let at = formats::campaign::machine_at(m, &params);
            let planned = builtin_path(&at, path).unwrap().unwrap();
            let record = simulate(&at, &t, &planned).unwrap();
            let (label, setup) = if raise > 0.0 {
                (format!("{}-high", path.to_lowercase()), "high")
            } else {
                (path.to_lowercase(), "low")
            };
            CampaignRecord::new(label, record, params, setup, false)
        })
        .collect();
    Campaign::new(records).unwrap()
}

/// The check's poses: [`POSES`] random poses with the ball at `Zw + CHECK_RAISE_MM` (commands
/// in mm and rad), and those parameters.
pub fn check_poses(m: &Machine) -> (Vec<Vec<f64>>, Vec<f64>) {
    let params = raised(m, &m.default_parameters(), CHECK_RAISE_MM);
    let vm = VirtualMachine::new(m);
    let a = m.axis_by_name("A").unwrap();
    let c = m.axis_by_name("C").unwrap();
    let mut rng = Rng::new(POSE_SEED);
    let mut out = Vec::with_capacity(POSES);
    while out.len() < POSES {
        let mut q = vec![0.0; m.axes.len()];
        q[a] = rng.uniform_in(-90.0, 0.0).to_radians();
        q[c] = rng.uniform_in(0.0, 360.0).to_radians();
        if vm.tool_centre_point_ik(&mut q, &params).is_ok() && m.check_pose(&q).is_ok() {
            out.push(q);
        }
    }
    (out, params)
}

/// `model` identified on `campaign` as `rtest identify` does (the noise estimated, refined
/// against the exact machine) under `constraint`.
fn identify(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    constraint: Constraint,
) -> CampaignIdentification {
    let opts = IdentifyOptions::new()
        .constraint(constraint)
        .noise(NoiseChoice::Estimate)
        .refined(RefineOptions::default());
    fitting::identify(m, model, campaign, &opts).unwrap()
}

/// The truth's model identified on `campaign` and made determined: in every confounded group
/// all members but the one the truth holds most of (the largest `|value|·‖column‖`, the size of
/// its effect on the readings) are fixed to zero (a group of one, a term the paths do not see,
/// is fixed to zero); again until no group is left. The identification and the names fixed.
fn identify_determined(
    m: &Machine,
    truth: &Truth,
    campaign: &Campaign,
) -> (CampaignIdentification, Vec<String>) {
    let model = &truth.model;
    let truth_columns = model.columns();
    let mut zero: Vec<String> = Vec::new();
    loop {
        let constraint = if zero.is_empty() {
            Constraint::None
        } else {
            Constraint::Zero(zero.clone())
        };
        let ident = identify(m, model, campaign, constraint);
        let fit = &ident.fit;
        progress(&format!("oracle: rank {} of {}", fit.rank, fit.names.len()));
        let groups = &fit.identifiability.confounded;
        if groups.is_empty() {
            return (ident, zero);
        }
        let size = |j: usize| {
            let c = &ident.layout.columns[j];
            let k = truth_columns
                .iter()
                .position(|&(t, comp)| model.terms[t] == c.term && comp == c.component)
                .expect("a column of the truth's model");
            truth.coefficients[k].abs() * fit.column_norms[j]
        };
        for g in groups {
            let keep = match g.as_slice() {
                [_] => None,
                _ => g
                    .iter()
                    .copied()
                    .max_by(|&a, &b| size(a).total_cmp(&size(b))),
            };
            zero.extend(
                g.iter()
                    .filter(|&&j| Some(j) != keep)
                    .map(|&j| fit.names[j].clone()),
            );
        }
    }
}

/// The names of the shared parameters of `ident` without a value.
fn undetermined(ident: &CampaignIdentification) -> Vec<String> {
    (0..ident.fit.names.len())
        .filter(|&j| {
            ident.layout.columns[j].owner == Owner::Shared && ident.fit.values[j].is_none()
        })
        .map(|j| ident.fit.names[j].clone())
        .collect()
}

/// The set-up terms of an identification's model: those the layout gives a set-up.
fn setup_model(ident: &CampaignIdentification) -> Model {
    let mut terms = Vec::new();
    for c in &ident.layout.columns {
        if matches!(c.owner, Owner::Setup(0)) && !terms.contains(&c.term) {
            terms.push(c.term);
        }
    }
    Model { terms }
}

/// The shared values of `ident` compensated on the check's poses, run on the exact machine.
fn figure(
    m: &Machine,
    truth: &Truth,
    ident: &CampaignIdentification,
    name: &str,
    label: String,
    zeroed: Vec<String>,
) -> Figure {
    let (poses, params) = check_poses(m);
    let values = CampaignValues::of(ident);
    let (errors, _left_out) = MachineErrors::from_values(m, &values, "campaign").unwrap();
    let commanded: Vec<CommandedPose> = poses
        .iter()
        .enumerate()
        .map(|(i, q)| CommandedPose {
            line: i + 1,
            commands: q.clone(),
        })
        .collect();
    let values_at = |c: &[f64], out: &mut [f64]| errors.values_at(m, c, out);
    let corrected = compensate_poses(
        m,
        errors.errors(),
        params.clone(),
        "check poses",
        &commanded,
        &values_at,
    )
    .unwrap()
    .poses;
    let setup = setup_model(ident);
    let before: SetupRefitted = setup_refitted(m, truth, &setup, &poses, &params).unwrap();
    let after: SetupRefitted = setup_refitted(m, truth, &setup, &corrected, &params).unwrap();
    Figure {
        name: name.into(),
        model: label,
        before_um: before.rms * 1e3,
        after_um: after.rms * 1e3,
        after_refitted_um: after.refitted_rms * 1e3,
        before_refitted_um: before.refitted_rms * 1e3,
        zeroed,
        remains: remains(m, truth, ident, &poses, &params),
    }
}

/// Per machine term of the truth or of `ident`'s model (set-up, sensor and time terms left
/// out, as compensation leaves them), the RMS over `poses` (at `params`) of the first-order
/// error `gains·(true − identified)` it leaves, µm, largest first.
fn remains(
    m: &Machine,
    truth: &Truth,
    ident: &CampaignIdentification,
    poses: &[Vec<f64>],
    params: &[f64],
) -> Vec<(String, f64)> {
    use fitting::hmatrix::{GainSource, h_matrix};
    use simulation::model::Effect;
    let machine_term = |t: &simulation::model::Term| {
        matches!(t.effect, Effect::Error(e)
            if !matches!(m.catalogue[e].kind, model_spec::ErrorKind::Setup { .. }))
            && !t.basis.of_time()
    };
    let mut terms: Vec<simulation::model::Term> = Vec::new();
    for t in truth.model.terms.iter().chain(&ident.model.terms) {
        if machine_term(t) && !terms.contains(t) {
            terms.push(*t);
        }
    }
    let model = Model { terms };
    let times = (0..poses.len()).map(|i| i as f64).collect();
    let record = simulation::paths::record_from_commands(poses.to_vec(), times);
    let mut source = GainSource::new(m, &model.errors(), params).unwrap();
    let h = h_matrix(m, &model, &record, &mut source).unwrap();
    let truth_columns = truth.model.columns();
    let mut out = Vec::new();
    for (j, (t, comp)) in model.columns().into_iter().enumerate() {
        let term = model.terms[t];
        let true_value = truth_columns
            .iter()
            .position(|&(u, c)| truth.model.terms[u] == term && c == comp)
            .map_or(0.0, |k| truth.coefficients[k]);
        let identified = ident
            .layout
            .columns
            .iter()
            .position(|c| c.owner == Owner::Shared && c.term == term && c.component == comp)
            .map_or(0.0, |k| ident.fit.values[k].unwrap_or(0.0));
        let d = true_value - identified;
        let rms = (h.column(j).norm_squared() / h.nrows() as f64).sqrt() * d.abs();
        out.push((fitting::hmatrix::parameter_name(m, &term, comp), rms * 1e3));
    }
    out.sort_by(|a, b| b.1.total_cmp(&a.1));
    out
}

/// The spellings of `model`'s terms.
fn spelled(m: &Machine, model: &Model) -> Vec<String> {
    model.terms.iter().map(|t| t.spelling(m)).collect()
}

/// The whole loop at noise seed `seed`, the diagnosis with its default options.
pub fn run(seed: u64) -> Study {
    run_with(seed, &DiagnoseOptions::default())
}

/// The campaign at noise seed `seed` diagnosed with options `o` (base model `reduced`, nothing
/// held out), the diagnosis's stages printed as they begin.
struct Diagnosed {
    m: Machine,
    truth: Truth,
    c: Campaign,
    reduced: Model,
    d: Diagnosis,
}

fn diagnosed(seed: u64, o: &DiagnoseOptions) -> Diagnosed {
    diagnosed_of(seed, o, false)
}

/// [`diagnosed`] on [`campaign_of`] (`k2_high`: with K2 at the higher ball position too).
fn diagnosed_of(seed: u64, o: &DiagnoseOptions, k2_high: bool) -> Diagnosed {
    let m = seed_ac();
    let truth = budget(&m);
    let c = campaign_of(&m, &truth, seed, k2_high);
    let reduced = Model::of(&m, "reduced").unwrap();
    let none = Campaign {
        records: Vec::new(),
    };
    progress(&format!("noise seed {seed}: diagnosis"));
    // The diagnosis's stages as they begin, with the time (its speed: BENCHMARKS.md §8).
    let stages = |what: &str, done: u64, _total: u64| {
        if what == "diagnosis" {
            let stage = diagnosis::STAGES.get(done as usize).unwrap_or(&"done");
            progress(&format!("noise seed {seed}: diagnosis: {stage}"));
        }
    };
    let d = diagnose(&m, &reduced, &c, &none, o, &stages).unwrap();
    Diagnosed {
        m,
        truth,
        c,
        reduced,
        d,
    }
}

/// The whole loop at noise seed `seed`, the diagnosis with options `o`.
pub fn run_with(seed: u64, o: &DiagnoseOptions) -> Study {
    let Diagnosed {
        m,
        truth,
        c,
        reduced,
        d,
    } = diagnosed(seed, o);
    let extended = d.extended_terms();
    let findings: Vec<String> = spelled(&m, &extended)[reduced.terms.len()..].to_vec();
    for g in &d.groups {
        progress(&format!(
            "group {} ({} terms, {} directions of {} columns): share {:.3}, F {:.2}, p {:.2e} of {} tried, left-out gain {:?} sd, confirmed {}, undetermined {}",
            g.group.name,
            g.group.terms.len(),
            g.directions,
            g.columns,
            g.fraction,
            g.f,
            g.p,
            g.tried,
            g.gain_sd,
            g.confirmed,
            g.undetermined.join(" ")
        ));
    }

    let mut figures = Vec::new();
    progress(&format!(
        "noise seed {seed}: reduced model (the diagnosis adds {})",
        findings.join(", ")
    ));
    let ident = identify(&m, &reduced, &c, Constraint::None);
    figures.push(figure(
        &m,
        &truth,
        &ident,
        "reduced",
        "reduced".into(),
        vec![],
    ));
    progress(&format!("noise seed {seed}: extended model"));
    let mut ident_ext = identify(&m, &extended, &c, Constraint::None);
    let undetermined = undetermined(&ident_ext);
    if !undetermined.is_empty() {
        // What `rtest compensate` asks for then: identify again with a constraint.
        progress(&format!(
            "noise seed {seed}: the campaign does not determine {}: identified again under minimum-norm",
            undetermined.join(", ")
        ));
        ident_ext = identify(&m, &extended, &c, Constraint::MinimumNorm);
    }
    figures.push(figure(
        &m,
        &truth,
        &ident_ext,
        "extended",
        d.extended_label(&m, "reduced"),
        vec![],
    ));
    progress(&format!("noise seed {seed}: oracle"));
    let oracle = truth.model.clone();
    let (ident_or, zeroed) = identify_determined(&m, &truth, &c);
    figures.push(figure(
        &m,
        &truth,
        &ident_or,
        "oracle, zero:",
        format!("the truth's {} terms", oracle.terms.len()),
        zeroed,
    ));
    progress(&format!("noise seed {seed}: oracle, minimum norm"));
    let ident_mn = identify(&m, &oracle, &c, Constraint::MinimumNorm);
    figures.push(figure(
        &m,
        &truth,
        &ident_mn,
        "oracle, minimum-norm",
        format!("the truth's {} terms", oracle.terms.len()),
        vec![],
    ));

    Study {
        seed,
        findings,
        recommended: d.recommendation.recommended,
        reasons: d.recommendation.reasons.clone(),
        fit_rms_um: (d.fit_rms.0 * 1e3, d.fit_rms.1 * 1e3),
        stop: (
            d.stop.reason.clone(),
            d.adequacy.as_ref().ok().map(|a| a.consistent_with_noise),
        ),
        undetermined,
        figures,
    }
}

/// What the diagnosis's extended model lacks, group by group: at noise seed `seed`, the
/// extended model with the truth's machine terms of one group added (identified under the
/// `minimum-norm` constraint, which the added terms need), compensated and checked like the
/// figures: (group, terms added, figure).
pub fn additions(seed: u64) -> Vec<(String, Vec<String>, Figure)> {
    use model_spec::ErrorKind;
    use simulation::model::Effect;
    let Diagnosed { m, truth, c, d, .. } = diagnosed(seed, &DiagnoseOptions::default());
    let extended = d.extended_terms();
    let axis_of = |e: usize| match m.catalogue[e].kind {
        ErrorKind::Component { axis, .. } => Some(m.axes[axis].name.clone()),
        _ => None,
    };
    let group_of = |t: &simulation::model::Term| -> Option<String> {
        let Effect::Error(e) = t.effect else {
            return None;
        };
        if t.basis.of_time() {
            return None;
        }
        match m.catalogue[e].kind {
            ErrorKind::Setup { .. } => None,
            ErrorKind::Squareness { .. } => Some("squareness".into()),
            ErrorKind::Component { .. } => {
                let a = axis_of(e).unwrap();
                let kind = if ["X", "Y", "Z"].contains(&a.as_str()) {
                    if t.effect.is_angular(&m) {
                        "angular"
                    } else {
                        "positioning, straightness"
                    }
                } else {
                    "component"
                };
                Some(format!("{a} {kind}"))
            }
            _ => Some("location".into()),
        }
    };
    let mut groups: Vec<(String, Vec<simulation::model::Term>)> = Vec::new();
    for t in &truth.model.terms {
        if extended.terms.contains(t) {
            continue;
        }
        if let Some(g) = group_of(t) {
            match groups.iter_mut().find(|(n, _)| *n == g) {
                Some((_, ts)) => ts.push(*t),
                None => groups.push((g, vec![*t])),
            }
        }
    }
    let all: Vec<simulation::model::Term> = groups.iter().flat_map(|(_, t)| t.clone()).collect();
    groups.push(("every missing machine term".into(), all));
    groups
        .into_iter()
        .map(|(g, ts)| {
            progress(&format!("noise seed {seed}: extended + {g}"));
            let mut model = extended.clone();
            model.terms.extend(ts.iter().copied());
            let ident = identify(&m, &model, &c, Constraint::MinimumNorm);
            let names = ts.iter().map(|t| t.spelling(&m)).collect();
            (
                g.clone(),
                names,
                figure(&m, &truth, &ident, &g, g.clone(), vec![]),
            )
        })
        .collect()
}

/// The study as text: the findings, the recommendation and the four figures.
pub fn text(s: &Study) -> String {
    let mut out = format!(
        "noise seed {}: the diagnosis finds {} ({}; {})\n",
        s.seed,
        if s.findings.is_empty() {
            "nothing".to_string()
        } else {
            s.findings.join(", ")
        },
        if s.recommended {
            "recommended"
        } else {
            "not recommended"
        },
        s.reasons.join("; ")
    );
    out.push_str(&format!(
        "  campaign residual {:.3} µm (reduced) → {:.3} µm (extended); {}; residual {}\n",
        s.fit_rms_um.0,
        s.fit_rms_um.1,
        s.stop.0,
        match s.stop.1 {
            Some(true) => "consistent with the noise",
            Some(false) => "not consistent with the noise",
            None => "not tested against the noise",
        }
    ));
    if !s.undetermined.is_empty() {
        out.push_str(&format!(
            "  the campaign does not determine {} of the extended model: identified under minimum-norm\n",
            s.undetermined.join(", ")
        ));
    }
    out.push_str(&format!(
        "  {:<28} {:>10} {:>10} {:>7} {:>12} {:>7}\n",
        "figure", "before µm", "after µm", "less", "set-up µm", "less"
    ));
    let row = |n: &str, f: &Figure, refitted: bool| {
        let (after, fall) = if refitted {
            (f.after_refitted_um, f.fall_refitted())
        } else {
            (f.after_um, f.fall())
        };
        format!(
            "  {:<28} {:>10.3} {:>10.3} {:>6.1}% {:>12} {:>7}\n",
            n,
            f.before_um,
            if refitted { f.after_um } else { after },
            100.0 * f.fall(),
            if refitted {
                format!("{after:.3}")
            } else {
                "—".into()
            },
            if refitted {
                format!("{:.1}%", 100.0 * fall)
            } else {
                "—".into()
            },
        )
    };
    let [reduced, recommended, oracle, minimum] = &s.figures[..] else {
        unreachable!("four identifications")
    };
    out.push_str(&row("1. reduced", reduced, true));
    out.push_str(&row("2. extended", recommended, true));
    out.push_str(&row("3a. oracle, zero:", oracle, true));
    out.push_str(&row("3b. oracle, minimum-norm", minimum, true));
    out.push_str(&row("4. extended, no refit", recommended, false));
    out.push_str(&format!("  model of 2: {}\n", recommended.model));
    for f in &s.figures {
        out.push_str(&format!(
            "  {} leaves (µm RMS, first order): {}\n",
            f.name,
            f.remains
                .iter()
                .take(10)
                .map(|(n, v)| format!("{n} {v:.2}"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    out.push_str(&format!(
        "  (before, with a set-up fitted to the uncompensated error: {:.3} µm; the oracle fixed {} to zero)\n",
        recommended.before_refitted_um,
        if oracle.zeroed.is_empty() {
            "nothing".to_string()
        } else {
            oracle.zeroed.join(", ")
        }
    ));
    out
}

/// The grouped candidates at noise seed `seed` ([`diagnosis::groups`]): the campaign
/// diagnosed with them on, each group the selection takes described (its members, directions,
/// F, corrected p, the left-out gain in standard deviations and whether it is confirmed), the
/// figure of the extended model the diagnosis then gives (its findings and confirmed groups,
/// under `minimum-norm` when the campaign does not determine it), and the figure of the diagnosis's extended model with **every** selected group's members added,
/// confirmed or not, identified under `minimum-norm`: what the groups would give were they
/// taken on the fitted records' significance alone. `k2_high`: on [`campaign_of`] with K2 at
/// the higher ball position as a sixth record.
pub fn groups(seed: u64, k2_high: bool) -> (Vec<String>, Figure, Figure) {
    let Diagnosed { m, truth, c, d, .. } =
        diagnosed_of(seed, &DiagnoseOptions::default().groups(true), k2_high);
    let recommended = d.extended_terms();
    let mut ident = identify(&m, &recommended, &c, Constraint::None);
    if !undetermined(&ident).is_empty() {
        ident = identify(&m, &recommended, &c, Constraint::MinimumNorm);
    }
    let with_confirmed = figure(
        &m,
        &truth,
        &ident,
        "extended, confirmed groups",
        d.extended_label(&m, "reduced"),
        vec![],
    );
    let mut model = recommended.clone();
    let mut described = Vec::new();
    for g in &d.groups {
        described.push(format!(
            "{} ({}): {} directions of {} columns, F {:.1}, p {:.1e} ({} groups tried), left-out gain {} sd{}, {}",
            g.group.name,
            g.group
                .terms
                .iter()
                .map(|t| t.spelling(&m))
                .collect::<Vec<_>>()
                .join(" "),
            g.directions,
            g.columns,
            g.f,
            g.p,
            g.tried,
            g.gain_sd.map_or("—".into(), |z| format!("{z:.1}")),
            if g.unjudged.is_empty() {
                String::new()
            } else {
                format!(" ({} cannot judge it)", g.unjudged.join(", "))
            },
            if g.confirmed { "confirmed" } else { "not confirmed" }
        ));
        for t in &g.group.terms {
            if !model.terms.contains(t) {
                model.terms.push(*t);
            }
        }
    }
    progress(&format!(
        "noise seed {seed}: extended model with every selected group"
    ));
    let ident = identify(&m, &model, &c, Constraint::MinimumNorm);
    let f = figure(
        &m,
        &truth,
        &ident,
        "extended + groups",
        format!("{} terms", model.terms.len()),
        vec![],
    );
    (described, with_confirmed, f)
}

/// Why the records left out in turn do not confirm the groups: at noise seed `seed`, with the
/// grouped candidates on, every record of the campaign predicted by the fit on the four others,
/// with the diagnosis's extended model and with it plus each selected group alone (µm RMS of
/// the prediction's residual, over the three directions; the rank and condition number of the
/// fit on the four). One line per record left out.
pub fn left_out(seed: u64) -> Vec<String> {
    let Diagnosed { m, c, d, .. } = diagnosed(seed, &DiagnoseOptions::default().groups(true));
    let extended = d.extended_terms();
    let mut models = vec![("extended".to_string(), extended.clone())];
    for g in &d.groups {
        let mut model = extended.clone();
        model.terms.extend(g.group.terms.iter().copied());
        models.push((format!("+ {}", g.group.name), model));
    }
    (0..c.records.len())
        .map(|j| {
            let fitted = Campaign {
                records: c
                    .records
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| *k != j)
                    .map(|(_, r)| r.clone())
                    .collect(),
            };
            let judged = Campaign {
                records: vec![c.records[j].clone()],
            };
            let mut line = format!("{} left out:", c.records[j].label);
            for (name, model) in &models {
                let ident = identify(&m, model, &fitted, Constraint::None);
                let p = diagnosis::heldout::predict(&m, &ident, &judged).unwrap();
                let r = &p[0].validation.residual;
                let ss: f64 = r.iter().flatten().map(|x| x * x).sum();
                line.push_str(&format!(
                    " {name} {:.3} µm (rank {} of {}, condition {:.0});",
                    (ss / (3 * r.len()) as f64).sqrt() * 1e3,
                    ident.fit.rank,
                    ident.fit.names.len(),
                    ident.fit.condition.unwrap_or(f64::NAN)
                ));
            }
            line
        })
        .collect()
}
