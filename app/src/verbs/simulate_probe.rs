//! `rtest simulate --probe FILE`: touch-probe hits on the exact virtual machine at the poses
//! of a path, written as a probe hits CSV (`docs/probe-simulation.md`).

use super::{Error, VerbResult};
use crate::Done;
use formats::probe::{
    ProbeHit, ProbeHits, ProbeInstrument, ProbePose, format_probe_hits, parse_probe_hits,
    read_probe_instrument,
};
use model_spec::units::{degrees_for, format_scaled, short};
use model_spec::{AxisKind, Machine};
use output::{Outputs, Target};
use simulation::probe::{
    AZIMUTH_CYCLE_DEG, CLEARANCE_MM, HIT_CYCLE_S, PATTERN_HITS, POSE_CHANGE_S,
    PROBING_FEED_MM_PER_S, PatternAzimuth, PreTravel, ProbeError, ProbeRun, ProbeSettings,
    pose_label, simulate_probe, unused_terms,
};
use simulation::record::Record;
use simulation::truth::Truth;
use std::path::Path;

/// What `rtest simulate --probe` works on, read and checked by `simulate`.
pub struct ProbeRequest<'a> {
    /// The machine, at the plan's kinematic parameters (its defaults).
    pub machine: &'a Machine,
    /// `--path` as given.
    pub path_name: &'a str,
    /// The path: one pose per sample.
    pub path: &'a Record,
    /// The truth (its kinematic parameters moved with `--param`).
    pub truth: &'a Truth,
    /// `--probe`: the probe instrument file.
    pub probe_file: &'a Path,
    /// `--noise-um`, mm: the probe's noise σ, overriding the instrument's.
    pub noise_mm: Option<f64>,
    /// `--seed`, overriding the truth's.
    pub seed: Option<u64>,
    /// `-o`.
    pub output: &'a Target,
}

/// Runs `rtest simulate --probe`.
pub fn run(r: &ProbeRequest<'_>) -> VerbResult<Done> {
    let m = r.machine;
    let instrument =
        read_probe_instrument(r.probe_file).map_err(|e| Error::input(format!("--probe: {e}")))?;
    let settings = settings(&instrument, r);
    let poses: Vec<Vec<f64>> = r.path.samples.iter().map(|s| s.commands.clone()).collect();
    let run = simulate_probe(m, &m.default_parameters(), r.truth, &poses, &settings).map_err(
        |e| match e {
            e @ (ProbeError::Kinematics { .. } | ProbeError::Poses(_)) => {
                Error::input(format!("--path {}: {e}", r.path_name))
            }
            e @ ProbeError::Settings(_) => {
                Error::input(format!("--probe {}: {e}", r.probe_file.display()))
            }
            e @ ProbeError::Truth { .. } => Error::computation(format!("--truth: {e}")),
            e @ ProbeError::Contact { .. } => Error::computation(format!(
                "--truth {}: {e}; nothing is written",
                r.truth.source
            )),
            e => Error::computation(format!("--path {}: {e}; nothing is written", r.path_name)),
        },
    )?;
    let hits = hits_of(m, &run);
    let comments = provenance(r, &instrument, &settings, &run);
    let csv = format_probe_hits(m, &hits, &comments)
        .map_err(|e| Error::computation(format!("-o: {e}")))?;
    // What is written is what the probe readers read: read it back with their rules.
    let back = parse_probe_hits(&r.output.to_string(), &csv, m).map_err(|e| {
        Error::computation(format!(
            "-o: the simulated hits would not be read back, so they are not written: {e}"
        ))
    })?;
    if !same_hits(&back, &hits) {
        return Err(Error::computation(
            "-o: the probe hits CSV does not read back to the simulated hits; nothing is written",
        ));
    }
    let mut files = Outputs::new();
    files.add("-o", r.output.clone(), csv);
    let written = r.output.path().map(|p| p.display().to_string());
    let text = format!(
        "simulated probe hits on {} at the poses of {} (truth {}, probe {}, R_eff {} mm, noise {} µm, seed {}): {} poses, {} hits, {} on the machine{}\n",
        m.name,
        r.path_name,
        r.truth.source,
        instrument
            .name
            .clone()
            .unwrap_or_else(|| r.probe_file.display().to_string()),
        short(settings.effective_radius_mm()),
        format_scaled(settings.noise_mm, 3),
        settings.seed,
        run.poses.len(),
        run.hit_count(),
        duration(run.duration_s),
        written.map_or(String::new(), |f| format!("; wrote {f}")),
    );
    let unused = unused_terms(m, r.truth);
    let notes = if unused.is_empty() {
        String::new()
    } else {
        format!(
            "note: the truth's R-test instrument terms {} act on sensor readings a probe has not: not used\n",
            unused.join(", ")
        )
    };
    Ok(Done::new(text, files, matches!(r.output, Target::Stdout))
        .unlisted()
        .noting(notes))
}

/// The probe of the instrument file, with `--noise-um` and `--seed` (mm): the noise is the
/// flag's, else the file's `noise_um`, else 0; the seed the flag's, else the truth's.
fn settings(p: &ProbeInstrument, r: &ProbeRequest<'_>) -> ProbeSettings {
    let mm = |um: f64| um / 1000.0;
    ProbeSettings {
        tip_radius_mm: p.tip_radius_mm,
        sphere_radius_mm: p.sphere_radius_mm,
        pre_travel: PreTravel {
            constant_mm: mm(p.pre_travel_um.unwrap_or(0.0)),
            lobing_mm: p.lobing_um.unwrap_or([0.0, 0.0]).map(mm),
        },
        noise_mm: r.noise_mm.unwrap_or_else(|| mm(p.noise_um.unwrap_or(0.0))),
        seed: r.seed.unwrap_or(r.truth.seed),
        azimuth: PatternAzimuth::default(),
    }
}

/// The hits of `run` as the probe hits CSV holds them: labels `p1`, `p2`, …, axes in mm and
/// degrees, the approach direction (components below 1e-12 written as 0), the latch time.
fn hits_of(m: &Machine, run: &ProbeRun) -> ProbeHits {
    ProbeHits {
        poses: run
            .poses
            .iter()
            .enumerate()
            .map(|(i, pose)| ProbePose {
                label: pose_label(i),
                hits: pose
                    .hits
                    .iter()
                    .map(|h| ProbeHit {
                        line: 0,
                        axes: file_units(m, &h.latched),
                        direction: [h.approach.x, h.approach.y, h.approach.z].map(clean),
                        t_s: h.t_s,
                    })
                    .collect(),
            })
            .collect(),
    }
}

/// Commands in the file's units: linear axes in mm, rotary axes in the shortest degrees that
/// convert back to the same radians (`-30`, not `-29.999999999999996`).
fn file_units(m: &Machine, commands: &[f64]) -> Vec<f64> {
    m.axes
        .iter()
        .zip(commands)
        .map(|(a, &q)| match a.kind {
            AxisKind::Linear => q,
            AxisKind::Rotary => degrees_for(q),
        })
        .collect()
}

/// A component of an approach direction as written: the rounding of the pattern's cosines
/// (below 1e-12, e.g. 6e-17 for cos 90°) is written as 0, and no negative zero.
fn clean(x: f64) -> f64 {
    if x.abs() < 1e-12 { 0.0 } else { x }
}

/// Whether `back` (read from the text) holds the same hits as `hits`, bit for bit (the lines
/// aside).
fn same_hits(back: &ProbeHits, hits: &ProbeHits) -> bool {
    let bits = |h: &ProbeHit| {
        let mut v: Vec<u64> = h.axes.iter().map(|x| x.to_bits()).collect();
        v.extend(h.direction.iter().map(|x| x.to_bits()));
        v.push(h.t_s.to_bits());
        v
    };
    back.poses.len() == hits.poses.len()
        && back.poses.iter().zip(&hits.poses).all(|(a, b)| {
            a.label == b.label
                && a.hits.len() == b.hits.len()
                && a.hits.iter().zip(&b.hits).all(|(x, y)| bits(x) == bits(y))
        })
}

/// `2 min 42 s`, `1 h 3 min 7 s`, `36 s`.
fn duration(s: f64) -> String {
    let total = s.round() as u64;
    let (h, min, sec) = (total / 3600, total / 60 % 60, total % 60);
    match (h, min) {
        (0, 0) => format!("{sec} s"),
        (0, _) => format!("{min} min {sec} s"),
        _ => format!("{h} h {min} min {sec} s"),
    }
}

/// Comment lines of the probe hits CSV: what produced it, the machine, the path, the truth,
/// the probe, the pattern, the clock and the units.
fn provenance(
    r: &ProbeRequest<'_>,
    instrument: &ProbeInstrument,
    p: &ProbeSettings,
    run: &ProbeRun,
) -> Vec<String> {
    let m = r.machine;
    let um = |mm: f64| format_scaled(mm, 3);
    let mut lines = vec![
        format!(
            "simulated by rtest {} (exact virtual machine, simulation::probe)",
            env!("CARGO_PKG_VERSION")
        ),
        format!("machine: {}", m.name),
        format!(
            "path: {} ({} poses, labelled p1 to p{} in the path's order)",
            r.path_name,
            run.poses.len(),
            run.poses.len()
        ),
        format!(
            "truth {}: {} term(s); its zero offsets dx0 dy0 dz0 put the tip centre off the tool point (tool frame); its R-test reading noise, zeroing and instrument terms are not used",
            r.truth.source,
            r.truth.model.terms.len()
        ),
        format!(
            "probe: {}: tip radius {} mm, sphere radius {} mm (R_eff {} mm), pre-travel {} µm, lobing [{}, {}] µm, noise σ {} µm along the approach from seed {}",
            instrument.name.as_deref().unwrap_or("unnamed"),
            short(p.tip_radius_mm),
            short(p.sphere_radius_mm),
            short(p.effective_radius_mm()),
            um(p.pre_travel.constant_mm),
            um(p.pre_travel.lobing_mm[0]),
            um(p.pre_travel.lobing_mm[1]),
            um(p.noise_mm),
            p.seed
        ),
        format!(
            "pattern: {PATTERN_HITS} hits per pose about the nominal sphere centre (+x, +y, -x, -y of the probe at its height, four at R/2 above, the pole), defined in the probe's frame and turned by each pose's nominal tool rotation and by {}° about the stylus pose after pose, each from {CLEARANCE_MM} mm outside the sphere at {} mm/min",
            AZIMUTH_CYCLE_DEG.map(short).join(", "),
            PROBING_FEED_MM_PER_S * 60.0
        ),
        format!(
            "clock: {HIT_CYCLE_S} s per hit, {POSE_CHANGE_S} s per pose change; t_s is the nominal latch time; {} s in all",
            short(run.duration_s)
        ),
    ];
    lines.push(
        "units: linear axes mm, rotary axes degrees, nx ny nz the approach direction (unit, machine frame), t_s s"
            .into(),
    );
    lines
}
