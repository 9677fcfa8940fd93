//! `rtest identify`: the errors of a model from an R-test measurement, with uncertainties and
//! what the data cannot separate (solver::fitting, solver::fitting::refine, solver::io::json).

use super::data::{self, Identified};
use super::{CliError, CliResult, EXIT_CODES};
use model_spec::Machine;
use solver::fitting::hmatrix::Backend;
use solver::fitting::{Constraint, IdentifyOptions};
use solver::io::json::{display_factor, identify_json};
use std::path::PathBuf;

const LONG_ABOUT: &str = "\
Identifies the errors of a model from a measurement CSV (DESIGN.md: axis columns in mm and \
degrees, dx_um,dy_um,dz_um in µm): least squares on the column-scaled H matrix (gains from the \
generated code for built-in machines, from the in-process evaluator for machine files), with \
numerical rank, condition number, standard uncertainties from the residuals (σ̂), correlations, \
and what the data cannot separate. Values are in µm (translational errors, sensor offsets) and \
µrad (angular errors).

The model is --model NAME (the terms of a model of the machine: full, reduced, …), --terms LIST \
(NAME or NAME@BASIS: XOC, ECC@harmonic:2, EXX@reversal, EXX@poly:2, dx0@time:1), or both (the \
terms are added to the model).

A parameter the data cannot determine gets no number: it is printed as \"not determined: \
confounded with …\" and its value is null in the JSON, unless --constraint gives it one \
(min-norm: the minimum-norm solution, a convention; zero:NAME,NAME: those fixed to 0 before the \
fit). With --zeroed (readings zeroed at the first sample) the R-test zero offsets dx0 dy0 dz0 \
join the model and the report names the errors they swallow (those with a constant gain: XOC, \
YOA, ZOA on seed-ac).

By default the linear estimate is refined against the exact virtual machine (Gauss-Newton with \
H as Jacobian, two or three steps): that removes the second-order terms of a real machine \
(products of two errors with a lever arm, about 1e-3 µm for errors of tens of µm and µrad), \
which bias a purely first-order fit by that much. --first-order skips it.

--json writes {machine, model, parameters: [{error, basis, value, std, unit}], residual_rms_um, \
rank, condition, confounded, samples, zeroed, constraint, sigma_um, near_confounded, gains, \
notes} (docs/identification.md), atomically; `rtest validate --params` reads it.";

/// Flags of `rtest identify`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Identify a model's errors (µm, µrad) from a measurement CSV, with uncertainties",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct IdentifyArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// Model of the machine whose terms are identified (`reduced`, `full`, …); required
    /// unless --terms is given.
    #[arg(long, value_name = "NAME")]
    model: Option<String>,
    /// Terms to identify, added to --model or alone: comma list of NAME or NAME@BASIS
    /// (`ECC@harmonic:2,dx0@time:1`; bases const, harmonic:K, poly:K, reversal, time:K).
    #[arg(long, value_name = "LIST")]
    terms: Option<String>,
    /// The measurement CSV (axes in mm and degrees, dx_um,dy_um,dz_um in µm).
    #[arg(long, value_name = "FILE")]
    data: PathBuf,
    /// The readings were zeroed at the first sample: fit dx0 dy0 dz0 too and say which errors
    /// they swallow.
    #[arg(long)]
    zeroed: bool,
    /// Values for undetermined parameters: `none` (default: no value), `min-norm` (the
    /// minimum-norm solution), or `zero:NAME,NAME` (fix those to 0 before the fit).
    #[arg(long, value_name = "none|min-norm|zero:NAME,...")]
    constraint: Option<String>,
    /// Skip the refinement against the exact machine: keep the first-order least-squares
    /// values (biased by second-order terms, ~1e-3 µm at tens of µm/µrad).
    #[arg(long)]
    first_order: bool,
    /// Also write the result as JSON to FILE (atomically).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Read the measurement in blocks and fold them into an incremental QR: for long records
    /// (10^6 samples and more), memory bounded by the number of parameters. First order (the
    /// refinement needs the whole record).
    #[arg(long)]
    stream: bool,
    /// Samples per block with --stream.
    #[arg(long, value_name = "N", default_value_t = 4096, requires = "stream")]
    block: usize,
}

/// Runs `rtest identify`.
pub fn run(args: &IdentifyArgs) -> CliResult {
    let m = super::load_machine(&args.machine)?;
    let (label, model) = data::model(&m, args.model.as_deref(), args.terms.as_deref())?;
    let constraint = data::constraint(args.constraint.as_deref())?;
    let opts = IdentifyOptions::new()
        .zeroed(args.zeroed)
        .constraint(constraint);
    let data_name = args.data.display().to_string();
    let (result, first_reading_zero) = if args.stream {
        if args.block == 0 {
            return Err(CliError::usage("--block: must be at least 1 sample"));
        }
        let (ident, run) = solver::fitting::streaming::identify_file(
            &m, &model, &args.data, &opts, args.block,
        )
        .map_err(|e| match e {
            solver::fitting::streaming::StreamingError::Estimate(
                solver::fitting::EstimateError::UnknownParameter(name, names),
            ) => CliError::usage(format!(
                "--constraint: `{name}` is not a parameter of the model (parameters: {names})"
            )),
            other => CliError::failure(format!("--data: {other}")),
        })?;
        let note = format!(
            "Read in {} block(s) of at most {} samples folded into an incremental QR (first order; state {} numbers).\n",
            run.blocks,
            run.largest_block,
            (model.width() + 4) * (model.width() + 4)
        );
        print!("{note}");
        (
            data::Identified {
                ident,
                refinement: None,
            },
            false,
        )
    } else {
        let record = data::measurement("--data", &m, &args.data)?;
        let zero = data::looks_zeroed(&record);
        (
            data::identify(&m, &model, &record, &opts, !args.first_order)?,
            zero,
        )
    };
    let mut text = report(&m, &label, &data_name, &result);
    if first_reading_zero && !args.zeroed {
        text.push_str(
            "Note: the first reading is exactly 0: if the readings were zeroed at the first sample, give --zeroed.\n",
        );
    }
    if let Some(path) = &args.json {
        let json = identify_json(&m, &label, &result.ident);
        let body = serde_json::to_string_pretty(&json)
            .map_err(|e| CliError::failure(format!("--json: {e}")))?;
        super::write_atomic("--json", path, &(body + "\n"))?;
        text.push_str(&format!("Wrote {}\n", path.display()));
    }
    print!("{text}");
    Ok(())
}

/// The identification for people, like the seed's Table 4: one row per parameter (value ± std
/// in µm or µrad, or why there is none), then rank, condition number, residual RMS, σ̂, the
/// confounded groups, the nearly confounded pairs and what the zero offsets swallow.
pub fn report(m: &Machine, label: &str, data_name: &str, r: &Identified) -> String {
    let ident = &r.ident;
    let fit = &ident.fit;
    let id = &fit.identifiability;
    let n = fit.names.len();
    let mut out = format!(
        "Identification on {data_name} ({} samples, readings {}): machine {}, model {label} ({n} parameter{})\n",
        ident.samples,
        if ident.zeroed {
            "zeroed at the first sample"
        } else {
            "not zeroed"
        },
        m.name,
        if n == 1 { "" } else { "s" },
    );
    let gains = match ident.backend {
        Backend::Compiled => "the compiled (generated) code",
        Backend::Evaluator => "the in-process evaluator",
        Backend::Mixed => "the compiled code and the evaluator",
    };
    match &r.refinement {
        Some(rf) => {
            out.push_str(&format!(
                "Least squares on the column-scaled H (gains from {gains}), refined against the exact machine: {} Gauss-Newton step{}{}; residual RMS {} µm (first order) -> {} µm.\n",
                rf.iterations,
                if rf.iterations == 1 { "" } else { "s" },
                if rf.converged {
                    ", converged".to_string()
                } else {
                    format!(
                        ", NOT converged (last step {} µm)",
                        data::um(rf.steps_mm.last().copied().unwrap_or(f64::NAN))
                    )
                },
                data::um(rf.rms_mm.0),
                // The refined fit's residual (`rf.rms_mm.1` is that of the exact machine with
                // undetermined parameters at 0, which includes their whole effect).
                data::um(fit.residual_rms()),
            ));
        }
        None => out.push_str(&format!(
            "Least squares on the column-scaled H (gains from {gains}), first order (--first-order: not refined against the exact machine).\n"
        )),
    }
    if ident.zeroed {
        out.push_str(
            "Zeroed readings: the R-test zero offsets dx0 dy0 dz0 (constant, µm) are fitted with the model.\n",
        );
    }
    out.push('\n');

    // The table.
    let columns = ident.model.columns();
    let w = fit
        .names
        .iter()
        .map(|s| s.chars().count())
        .max()
        .unwrap_or(0);
    let w = w.max("parameter".len());
    out.push_str(&format!(
        "{:<w$}  {:>12}     {:>10}  unit\n",
        "parameter", "value", "std"
    ));
    out.push_str(&format!("{}\n", "-".repeat(w + 36)));
    for (j, &(t, _)) in columns.iter().enumerate() {
        let effect = ident.model.terms[t].effect;
        let f = display_factor(m, effect);
        let unit = data::unit(effect.unit(m));
        let name = &fit.names[j];
        let others = || -> Option<String> {
            let g = id.confounded.iter().find(|g| g.contains(&j))?;
            let o: Vec<&str> = g
                .iter()
                .filter(|&&k| k != j)
                .map(|&k| fit.names[k].as_str())
                .collect();
            Some(o.join(", "))
        };
        let why = || match others() {
            Some(o) if !o.is_empty() => format!("not determined: confounded with {o}"),
            _ => "not determined: these readings do not see it (no gain along this path)".into(),
        };
        let line = if fit.fixed[j] {
            format!(
                "{name:<w$}  {:>12}     {:>10}  {unit}  fixed to 0 by --constraint",
                "0", ""
            )
        } else {
            match fit.values[j] {
                None => format!("{name:<w$}  {}", why()),
                Some(v) => {
                    let std = fit.std[j].map_or("-".to_string(), |s| data::people(s * f));
                    let mut l = format!(
                        "{name:<w$}  {:>12}  ±  {std:>10}  {unit}",
                        data::people(v * f)
                    );
                    if !id.determined[j] {
                        l.push_str(&format!(
                            "  ({}; minimum-norm value, a convention, not a measurement)",
                            why()
                        ));
                    } else if fit.std[j].is_none() {
                        l.push_str("  (no degree of freedom left for an uncertainty)");
                    }
                    l
                }
            }
        };
        out.push_str(&line);
        out.push('\n');
    }
    out.push('\n');

    // The summary.
    let free = fit.fixed.iter().filter(|f| !**f).count();
    out.push_str(&format!(
        "rank {} of {free}{}; condition number {} (column-scaled H)\n",
        fit.rank,
        if free == n {
            String::new()
        } else {
            format!(" free parameters ({} fixed)", n - free)
        },
        fit.condition
            .map_or("undefined (rank 0)".into(), |c| format!("{c:.1}"))
    ));
    out.push_str(&format!(
        "residual RMS {} µm over {} readings; σ̂ = {} ({} degrees of freedom)\n",
        data::um(fit.residual_rms()),
        fit.rows(),
        fit.sigma
            .map_or("undefined".into(), |s| format!("{} µm", data::um(s))),
        fit.dof
    ));
    if id.confounded.is_empty() {
        out.push_str("confounded groups: none (every free parameter is determined)\n");
    } else {
        let groups: Vec<String> = id
            .confounded
            .iter()
            .map(|g| {
                let names: Vec<&str> = g.iter().map(|&k| fit.names[k].as_str()).collect();
                format!("[{}]", names.join(", "))
            })
            .collect();
        out.push_str(&format!(
            "confounded groups (the data cannot separate them{}): {}\n",
            if fit.constraint == Constraint::MinimumNorm {
                "; values above are minimum-norm"
            } else {
                "; no value without --constraint"
            },
            groups.join(" ")
        ));
    }
    if id.near_confounded.is_empty() {
        out.push_str("near-confounded pairs (|corr| > 0.99): none\n");
    } else {
        let pairs: Vec<String> = id
            .near_confounded
            .iter()
            .map(|p| {
                format!(
                    "{}-{} ({:+.4})",
                    fit.names[p.a], fit.names[p.b], p.correlation
                )
            })
            .collect();
        out.push_str(&format!(
            "near-confounded pairs (|corr| > 0.99: determined, but poorly separated): {}\n",
            pairs.join(", ")
        ));
    }
    if !ident.swallowed.is_empty() {
        let parts: Vec<String> = ident
            .swallowed
            .iter()
            .map(|s| {
                format!(
                    "{} swallows {}",
                    s.offsets.join(" and "),
                    if s.errors.is_empty() {
                        "nothing else (the offsets are confounded with each other)".into()
                    } else {
                        s.errors.join(", ")
                    }
                )
            })
            .collect();
        let swallowed: Vec<&str> = ident
            .swallowed
            .iter()
            .flat_map(|s| s.errors.iter().map(String::as_str))
            .collect();
        out.push_str(&format!(
            "zeroed readings: {} (constant gains: the zeroed R-test cannot tell them from its own zero{})\n",
            parts.join("; "),
            if swallowed.is_empty() {
                String::new()
            } else {
                format!(
                    "; --constraint zero:{} fixes those errors to 0 and determines the offsets",
                    swallowed.join(",")
                )
            }
        ));
    }
    out
}
