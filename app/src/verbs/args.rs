//! Flags shared by several verbs, parsed into library values: models and terms, constraints,
//! file lists, `NAME=VALUE` lists, and the plausibility bounds. Every error names its flag and
//! is a usage error (exit code 2).

use super::{Error, VerbResult};
use fitting::noise::{NoiseChoice, NoiseModel};
use fitting::{Constraint, ValueLimits};
use formats::csv::ReadOptions;
use model_spec::instrument::{Instrument, InstrumentLoadError, ReadingsFrame, load_instrument};
use model_spec::units::{UM_PER_MM, significant};
use model_spec::{ErrorId, Machine};
use simulation::model::{Effect, Model, Term};
use std::path::{Path, PathBuf};

/// The noise model of the tests and uncertainties: declared, from a static record, or
/// estimated (the default). For `identify` and `diagnose`.
#[derive(Debug, Clone, clap::Args)]
pub struct NoiseArgs {
    /// The noise the uncertainties and tests assume: `white:sigma=S` or `ar1:phi=F,sigma=S` (S
    /// the marginal standard deviation of a reading in µm, 0 ≤ F < 0.99), or `white` (ordinary
    /// least squares). Default: estimated from the records.
    #[arg(long, value_name = "SPEC", conflicts_with = "noise_record")]
    pub noise: Option<String>,
    /// A record of the machine standing still (a measurement CSV, at least 100 samples): the
    /// noise model's σ and φ per direction, by Yule-Walker.
    #[arg(long, value_name = "FILE")]
    pub noise_record: Option<PathBuf>,
}

impl NoiseArgs {
    /// The input file it reads, for the check that no output names an input.
    pub fn input(&self) -> Option<(&'static str, &std::path::Path)> {
        self.noise_record.as_deref().map(|p| ("--noise-record", p))
    }

    /// `--noise` as parsed (the static record is read by [`NoiseArgs::choice`]).
    pub fn declared(&self) -> VerbResult<NoiseChoice> {
        match self.noise.as_deref() {
            Some(spec) => {
                NoiseChoice::parse(spec).map_err(|e| Error::usage(format!("--noise: {e}")))
            }
            None => Ok(NoiseChoice::Estimate),
        }
    }

    /// The noise choice: `--noise`, or the model of the static record `--noise-record` (read
    /// through the records' `instrument`, when they have one), with the static record as read.
    /// A declared model is refused for records read through an instrument, whose sensors' σ
    /// declare the noise already.
    pub fn choice(
        &self,
        m: &Machine,
        read: &ReadOptions,
        instrument: super::campaign::Through,
    ) -> VerbResult<(NoiseChoice, Option<super::ReadFile>)> {
        let Some(path) = &self.noise_record else {
            // A probe's σ declares its readings' covariances, scale included (its sphere
            // fits check it): taken as declared unless --noise says otherwise.
            if self.noise.is_none() && matches!(instrument, super::campaign::Through::Probe(_)) {
                return Ok((NoiseChoice::Instrument, None));
            }
            let declared = self.declared()?;
            if instrument.declares_noise() && matches!(declared, NoiseChoice::Model(_)) {
                let what = match instrument {
                    super::campaign::Through::Probe(_) => {
                        "--probe, whose σ gives each pose's reading its covariance through the sphere fit"
                    }
                    _ => "--instrument, whose sensors' σ give each reading's covariance",
                };
                return Err(Error::usage(format!(
                    "--noise: the records are read through {what}: a declared noise model would declare the noise a second time; leave --noise out (estimated over time from the rows whitened by the covariances) or give --noise white (the covariances' shape, the residual's scale)"
                )));
            }
            return Ok((declared, None));
        };
        if let super::campaign::Through::Probe(_) = instrument {
            return Err(Error::usage(format!(
                "--noise-record {}: a record of the machine standing still is an R-test's; a probe's noise is its σ in the --probe file (noise_um), which the sphere fits check against their residuals",
                path.display()
            )));
        }
        let (still, digest, _) = super::read_record(
            "--noise-record",
            m,
            path,
            read,
            instrument,
            &m.default_parameters(),
        )?;
        let model = NoiseModel::from_static_record(&still)
            .map_err(|e| Error::input(format!("--noise-record: {}: {e}", path.display())))?;
        Ok((
            NoiseChoice::Model(model),
            Some(super::ReadFile::new("--noise-record", path, digest)),
        ))
    }
}

/// An instrument as loaded, with the frame of its displacements.
pub type Loaded = (Instrument, ReadingsFrame);

/// The instrument whose sensor readings the records hold. For the verbs that read or write
/// records.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct InstrumentArgs {
    /// The R-test instrument of the records: a preset (`rtest instrument list`) or a TOML file
    /// (docs/instrument.md). The records then hold its sensors' readings (columns s1_um,
    /// s2_um, … in µm) instead of dx_um,dy_um,dz_um; they are turned into error vectors by its
    /// exact geometry, each with the covariance of the sensors' noise, which weights the fits.
    #[arg(long, value_name = "NAME|FILE")]
    pub instrument: Option<String>,
    /// The frame of the instrument's displacements, overriding its `frame`: tool (the nest
    /// turns with the tool) or machine (rotated into the tool frame at each pose).
    #[arg(long, value_name = "tool|machine", requires = "instrument",
          value_parser = ["tool", "machine"])]
    pub readings_frame: Option<String>,
}

impl InstrumentArgs {
    /// The input file `--instrument` names, for the check that no output names an input.
    pub fn input(&self) -> Option<(&'static str, &std::path::Path)> {
        self.instrument
            .as_deref()
            .map(std::path::Path::new)
            .filter(|p| {
                p.exists() && model_spec::instrument::preset(&p.to_string_lossy()).is_none()
            })
            .map(|p| ("--instrument", p))
    }

    /// The instrument and the frame of its displacements, when `--instrument` is given.
    pub fn load(&self) -> VerbResult<Option<(Instrument, ReadingsFrame)>> {
        self.load_read().map(|(i, _)| i)
    }

    /// [`InstrumentArgs::load`], with the file as read when `--instrument` names one (read
    /// once).
    pub fn load_read(&self) -> VerbResult<(Option<Loaded>, Option<super::ReadFile>)> {
        let Some(name) = &self.instrument else {
            return Ok((None, None));
        };
        let (i, digest) =
            model_spec::instrument::load_instrument_hashed(name).map_err(|e| match e {
                InstrumentLoadError::NotFound(_) => Error::usage(format!("--instrument: {e}")),
                other => Error::input(format!("--instrument: {other}")),
            })?;
        let read = digest.map(|d| super::ReadFile::new("--instrument", Path::new(name), d));
        let frame = match self.readings_frame.as_deref() {
            Some(f) => ReadingsFrame::parse(f).ok_or_else(|| {
                Error::usage(format!("--readings-frame: `{f}` is not tool or machine"))
            })?,
            None => i.frame,
        };
        Ok((Some((i, frame)), read))
    }
}

/// The instrument `name` (a preset or a TOML file) given by `flag`: an unknown name is a usage
/// error, a file that cannot be read or does not validate a bad input.
pub fn instrument(name: &str, flag: &str) -> VerbResult<Instrument> {
    load_instrument(name).map_err(|e| match e {
        InstrumentLoadError::NotFound(_) => Error::usage(format!("{flag}: {e}")),
        other => Error::input(format!("{flag}: {other}")),
    })
}

/// What a record read must be: plausible readings, poses within the strokes. For the verbs
/// that read or write records.
#[derive(Debug, Clone, clap::Args)]
pub struct RecordLimits {
    /// Largest plausible reading, µm: a record with a larger |dx|, |dy| or |dz| is refused,
    /// naming its lines.
    #[arg(long, value_name = "UM", default_value = "1000", value_parser = positive)]
    pub max_reading_um: f64,
    /// Accept poses outside the machine's strokes and ranges (refused by default, naming the
    /// first offending lines).
    #[arg(long)]
    pub allow_off_stroke: bool,
}

impl RecordLimits {
    /// The options of the record readers.
    pub fn read_options(&self) -> ReadOptions {
        let mut o = ReadOptions::default();
        o.max_reading_mm = self.max_reading_um / UM_PER_MM;
        o.allow_off_stroke = self.allow_off_stroke;
        o
    }
}

/// The plausibility bounds of identified values. For the verbs that identify values or read
/// them.
#[derive(Debug, Clone, clap::Args)]
pub struct ValueBounds {
    /// Largest plausible identified translational value (errors and sensor offsets), µm.
    #[arg(long, value_name = "UM", default_value = "1000", value_parser = positive)]
    pub max_error_um: f64,
    /// Largest plausible identified angular value, µrad.
    #[arg(long, value_name = "URAD", default_value = "10000", value_parser = positive)]
    pub max_error_urad: f64,
}

impl ValueBounds {
    /// The bounds of identified values.
    pub fn values(&self) -> ValueLimits {
        ValueLimits::from_display(self.max_error_um, self.max_error_urad)
    }
}

/// A parser of a number from `lo` to `hi` (both included), for flags whose value drives a
/// computation that has no meaning beyond them: the message gives the range.
pub fn between(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync {
    move |s: &str| match s.trim().parse::<f64>() {
        Ok(x) if (lo..=hi).contains(&x) => Ok(x),
        _ => Err(format!(
            "`{}` is not a number from {} to {}",
            model_spec::text::quoted_start(s),
            significant(lo),
            significant(hi)
        )),
    }
}

/// `--decimals` of an NC program, when given: at most [`formats::nc::MAX_DECIMALS`].
///
/// # Errors
/// A usage error naming `--decimals` and the limit.
pub fn nc_decimals(d: Option<usize>) -> VerbResult<Option<usize>> {
    let max = formats::nc::MAX_DECIMALS;
    match d {
        Some(d) if d > max => Err(Error::usage(format!(
            "--decimals: {d} decimals asked for, at most {max}"
        ))),
        d => Ok(d),
    }
}

/// A finite number above zero (µm, µrad).
pub fn positive(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("`{s}` is not a finite number above zero")),
    }
}

/// A model chosen by `--model` and `--terms`, with a label for reports
/// (`reduced`, `reduced + ECC@harmonic:2`, `XOC + ECC@harmonic:2`).
pub fn model(m: &Machine, name: Option<&str>, terms: Option<&str>) -> VerbResult<(String, Model)> {
    let mut label = Vec::new();
    let mut model = Model::default();
    if let Some(name) = name {
        model = Model::of(m, name).ok_or_else(|| {
            Error::usage(format!(
                "--model: machine {} has no model `{name}` (models: {})",
                m.name,
                m.model_names().join(", ")
            ))
        })?;
        label.push(name.to_string());
    }
    let from_model = model.terms.len();
    if let Some(list) = terms {
        for (text, term) in parse_terms(m, list)? {
            if let Some(i) = model.terms.iter().position(|t| *t == term) {
                return Err(Error::usage(if i < from_model {
                    format!("--terms: `{text}` is already in model {}", label[0])
                } else {
                    format!("--terms: `{text}` is given twice")
                }));
            }
            model.terms.push(term);
            label.push(text);
        }
    }
    if model.terms.is_empty() {
        return Err(Error::usage(match name {
            Some(n) => format!(
                "--model: model `{n}` of machine {} has no terms (its `errors` list is empty): add terms with --terms (e.g. --terms XOC,ECC@harmonic:2)",
                m.name
            ),
            None => {
                "--model: give a model (e.g. --model reduced) or terms (--terms XOC,ECC@harmonic:2)"
                    .into()
            }
        }));
    }
    Ok((label.join(" + "), model))
}

/// Parses `--terms`: a comma list of `NAME` (constant) or `NAME@BASIS` terms
/// (`ECC@harmonic:2,dx0@time:1`; `NAME` may be a kinematic symbol of the machine, `Zt`, whose
/// change is identified in µm); each with its text as written (trimmed).
pub fn parse_terms(m: &Machine, list: &str) -> VerbResult<Vec<(String, Term)>> {
    let example = "expected a comma list of NAME or NAME@BASIS, e.g. ECC@harmonic:2,dx0@time:1";
    let mut out = Vec::new();
    for item in items("--terms", list, example)? {
        let term = Term::parse(m, item).map_err(|e| {
            let name = item.split_once('@').map_or(item, |(n, _)| n);
            let other_case = m
                .symbols
                .iter()
                .any(|s| s.name.eq_ignore_ascii_case(name.trim()));
            let hint = if Effect::parse_term(m, name).is_none() && !other_case {
                let symbols: Vec<&str> = m.symbols.iter().map(|s| s.name.as_str()).collect();
                format!(
                    " (its errors: `rtest machines --machine {}`{})",
                    m.name,
                    if symbols.is_empty() {
                        String::new()
                    } else {
                        format!(
                            "; its kinematic symbols, whose changes a term may identify too: {}",
                            symbols.join(" ")
                        )
                    }
                )
            } else {
                String::new()
            };
            Error::usage(format!("--terms: `{item}`: {e}{hint}"))
        })?;
        out.push((item.to_string(), term));
    }
    Ok(out)
}

/// The trimmed items of a comma list for `flag`, none empty (`example` shows the form).
pub fn items<'a>(flag: &str, list: &'a str, example: &str) -> VerbResult<Vec<&'a str>> {
    if list.trim().is_empty() {
        return Err(Error::usage(format!("{flag}: empty list ({example})")));
    }
    list.split(',')
        .map(|item| {
            let item = item.trim();
            if item.is_empty() {
                Err(Error::usage(format!(
                    "{flag}: empty item in `{}` ({example})",
                    model_spec::text::quoted_start(list)
                )))
            } else {
                Ok(item)
            }
        })
        .collect()
}

/// Parses `--constraint`: `none`, `min-norm` (or `minimum-norm`), or `zero:NAME,NAME`.
pub fn constraint(text: Option<&str>) -> VerbResult<Constraint> {
    let Some(text) = text else {
        return Ok(Constraint::None);
    };
    match text.trim() {
        "none" => return Ok(Constraint::None),
        "min-norm" | "minimum-norm" => return Ok(Constraint::MinimumNorm),
        _ => {}
    }
    let Some(list) = text.trim().strip_prefix("zero:") else {
        return Err(Error::usage(format!(
            "--constraint: `{text}` is not one of none, min-norm, zero:NAME,NAME (e.g. zero:XOC,YOA,ZOA)"
        )));
    };
    let mut names: Vec<String> = Vec::new();
    for item in items(
        "--constraint",
        list,
        "expected zero:NAME,NAME, e.g. zero:XOC,YOA,ZOA",
    )? {
        if names.iter().any(|n| n == item) {
            return Err(Error::usage(format!(
                "--constraint: `{item}` is given twice"
            )));
        }
        names.push(item.to_string());
    }
    Ok(Constraint::Zero(names))
}

/// Parses a comma list of files (`--validate`), none empty, none twice.
pub fn files(flag: &str, list: &str) -> VerbResult<Vec<PathBuf>> {
    let example = "expected a comma list of measurement CSV files, e.g. k1.csv,k2.csv";
    let mut out: Vec<PathBuf> = Vec::new();
    for item in items(flag, list, example)? {
        let p = PathBuf::from(item);
        if out.contains(&p) {
            return Err(Error::usage(format!("{flag}: `{item}` is given twice")));
        }
        out.push(p);
    }
    Ok(out)
}

/// The errors chosen by `--model` / `--errors` (default: the full model), with a label for
/// titles (`Some(model name)`, or `None` for an explicit list).
pub fn select_errors(
    m: &Machine,
    model: Option<&str>,
    errors: Option<&str>,
) -> VerbResult<(Option<String>, Vec<ErrorId>)> {
    if let Some(list) = errors {
        return parse_error_list(m, list).map(|ids| (None, ids));
    }
    let name = model.unwrap_or(model_spec::FULL_MODEL);
    Ok((Some(name.to_string()), model_errors(m, name)?))
}

/// The errors of the model `name` of `m`, or a usage error listing its models.
pub fn model_errors(m: &Machine, name: &str) -> VerbResult<Vec<ErrorId>> {
    m.model_errors(name)
        .map(<[ErrorId]>::to_vec)
        .ok_or_else(|| {
            Error::usage(format!(
                "--model: machine {} has no model `{name}` (models: {})",
                m.name,
                m.model_names().join(", ")
            ))
        })
}

/// Parses `--errors`: a comma list of catalogue names (digit-zero spelling accepted), kept in
/// the given order.
pub fn parse_error_list(m: &Machine, list: &str) -> VerbResult<Vec<ErrorId>> {
    let example = "expected a comma list of error names, e.g. XOC,YOC,BOA";
    let mut ids = Vec::new();
    for item in items("--errors", list, example)? {
        let Some(id) = m.error_by_name(item) else {
            let names: Vec<&str> = m.catalogue.iter().map(|e| e.name.as_str()).collect();
            return Err(Error::usage(format!(
                "--errors: machine {} has no error `{item}` (its errors: {})",
                m.name,
                names.join(" ")
            )));
        };
        if ids.contains(&id) {
            return Err(Error::usage(format!(
                "--errors: error {} given twice",
                m.catalogue[id].name
            )));
        }
        ids.push(id);
    }
    Ok(ids)
}
