//! The campaign file: a TOML list of records (measurement CSVs), each with its label, its ball
//! set-up, its kinematic parameters, whether its readings were zeroed and, optionally, when it
//! started on a campaign clock (`docs/campaigns.md`).
//!
//! ```toml
//! machine = "seed-ac"                  # optional: the machine the campaign was measured on
//! description = "two ball heights"     # optional
//!
//! [[record]]
//! file = "k4-low.csv"                  # required; relative to this file's directory
//! label = "k4-low"                     # optional: the file's stem, made unique
//! setup = "low"                        # optional: the label (a set-up of its own)
//! params = { Zw = 211.537 }            # optional: kinematic symbols, mm; the others default
//! zeroed = false                       # optional: readings zeroed at the first sample
//! start = 0.0                          # optional: s on the campaign clock; all records or none
//! ```
//!
//! Every problem is reported with the file, the line, the column and the field. Each record's
//! CSV is read with its own kinematic parameters: its linear axes, when the file gives them,
//! must keep the sensor nest on the ball *at those parameters*, and when it does not give them
//! they are filled by the inverse kinematics at those parameters.

mod parse;

pub use parse::parse_campaign;

use crate::csv::{CsvError, ReadOptions};
use model_spec::Machine;
use model_spec::instrument::{Instrument, ReadingsFrame};
use model_spec::sha256::{Digest, HashingReader};
use model_spec::text::TextError;
use simulation::campaign::{Campaign, CampaignError, CampaignRecord, label_char};
use std::path::{Path, PathBuf};

/// The largest campaign file read (bytes): far above any real one.
pub const MAX_CAMPAIGN_BYTES: u64 = 4 << 20;

/// The keys of a campaign file, for messages.
pub(crate) const TOP_KEYS: &str = "machine, description, [[record]]";
/// The keys of a record, for messages.
pub(crate) const RECORD_KEYS: &str = "file, label, setup, params, zeroed, start";

/// Why a campaign cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum CampaignFileError {
    /// The file cannot be read, is too large or is not UTF-8.
    #[error(transparent)]
    Text(#[from] TextError),
    /// A malformed or wrong field, located.
    #[error("{file}:{line}:{column}: {message}")]
    Invalid {
        /// The campaign file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// What is wrong, naming the field.
        message: String,
    },
    /// A record's measurement CSV cannot be read (its own file, line and column are named).
    #[error("record `{label}` ({campaign}:{line}): {error}{at}")]
    Record {
        /// Where the record's kinematic parameters differ from the machine's defaults, what
        /// they are (the file was read at them): `; read at its kinematic parameters Zw = 300
        /// mm`; else empty.
        at: String,
        /// The campaign file.
        campaign: String,
        /// The line of the record's `file` field.
        line: usize,
        /// The record's label.
        label: String,
        /// What the CSV reader said.
        error: Box<CsvError>,
    },
    /// The records do not make a campaign (e.g. starts on some records only).
    #[error("{file}: {error}")]
    Campaign {
        /// The campaign file.
        file: String,
        /// What is wrong.
        error: CampaignError,
    },
}

impl From<crate::located::Located> for CampaignFileError {
    fn from(e: crate::located::Located) -> Self {
        CampaignFileError::Invalid {
            file: e.file,
            line: e.line,
            column: e.column,
            message: e.message,
        }
    }
}

/// One record of a campaign file, before its CSV is read.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignEntry {
    /// The CSV's path: the `file` field, relative to the campaign file's directory unless
    /// absolute.
    pub path: PathBuf,
    /// The label (given, or the file's stem made unique).
    pub label: String,
    /// The set-up label (given, or the label).
    pub setup: String,
    /// The kinematic parameters (mm, symbol order): the machine's defaults with `params`.
    pub params: Vec<f64>,
    /// Whether the readings were zeroed at the first sample.
    pub zeroed: bool,
    /// The record's time 0 on the campaign clock, s.
    pub start_s: Option<f64>,
    /// The line of the record's `file` field, for messages.
    pub line: usize,
}

/// A campaign file as read: its records, not yet loaded.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignFile {
    /// The file, as named in messages.
    pub file: String,
    /// What the campaign is, for people (may be empty).
    pub description: String,
    /// The records, in file order.
    pub records: Vec<CampaignEntry>,
}

/// A label from a file's stem: the characters a label may not hold replaced by `_`, `record`
/// when nothing is left.
pub fn stem_label(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let l: String = stem
        .chars()
        .map(|c| if label_char(c) { c } else { '_' })
        .collect();
    if l.is_empty() { "record".into() } else { l }
}

/// `label` made unique among `taken`: as it is, else with `-2`, `-3`, … appended.
pub fn unique_label(label: &str, taken: &[String]) -> String {
    if !taken.iter().any(|t| t == label) {
        return label.to_string();
    }
    (2..)
        .map(|k| format!("{label}-{k}"))
        .find(|l| !taken.iter().any(|t| t == l))
        .unwrap_or_else(|| label.to_string())
}

/// The labels of records read from `paths`: each file's stem ([`stem_label`]), made unique in
/// order ([`unique_label`]).
pub fn labels_from_files(paths: &[PathBuf]) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(paths.len());
    for p in paths {
        let l = unique_label(&stem_label(p), &out);
        out.push(l);
    }
    out
}

/// `m` with its symbols' defaults set to `params` (mm, symbol order): the machine a record
/// planned at those parameters is read with.
pub fn machine_at(m: &Machine, params: &[f64]) -> Machine {
    let mut at = m.clone();
    for (s, &v) in at.symbols.iter_mut().zip(params) {
        s.default = v;
    }
    at
}

/// Reads the measurement CSV at `path` planned at kinematic parameters `params` (mm): as
/// [`read_measurement`] with the machine's defaults replaced by `params`; with an `instrument`
/// (and the frame of its readings) a CSV of sensor readings turned into error vectors with
/// their covariances ([`crate::sensors::read_sensor_measurement`]). The file is opened
/// once; the [`Digest`] is that of the bytes read.
///
/// [`read_measurement`]: crate::csv::read_measurement
///
/// # Errors
/// As [`read_measurement`] and [`crate::sensors::read_sensor_measurement`].
pub fn read_record_at(
    path: &Path,
    m: &Machine,
    params: &[f64],
    opts: &ReadOptions,
    instrument: Option<(&Instrument, ReadingsFrame)>,
) -> Result<(simulation::record::Record, Digest), CsvError> {
    let (file, f) = crate::csv::open(path)?;
    let mut source = HashingReader::new(f);
    let record = parse_record_at(&file, &mut source, m, params, opts, instrument)?;
    Ok((record, source.digest()))
}

/// [`read_record_at`] of the bytes of `reader` (named `file` in messages).
///
/// # Errors
/// As [`read_record_at`].
pub fn parse_record_at(
    file: &str,
    reader: impl std::io::Read,
    m: &Machine,
    params: &[f64],
    opts: &ReadOptions,
    instrument: Option<(&Instrument, ReadingsFrame)>,
) -> Result<simulation::record::Record, CsvError> {
    let at = machine_at(m, params);
    match instrument {
        None => crate::csv::read_csv(file, reader, &at, crate::csv::Need::Measured, opts),
        Some((i, frame)) => {
            crate::sensors::read_sensor_measurement_from(file, reader, &at, i, frame, opts)
        }
    }
}

/// `; read at its kinematic parameters Zw = 300 mm (the machine's defaults for the others)`
/// when `params` differ from `m`'s defaults, else empty: what a message about a record read at
/// those parameters adds.
pub fn parameters_note(m: &Machine, params: &[f64]) -> String {
    let differ: Vec<String> = m
        .symbols
        .iter()
        .zip(params)
        .filter(|(s, v)| s.default != **v)
        .map(|(s, v)| format!("{} = {} mm", s.name, model_spec::units::short(*v)))
        .collect();
    if differ.is_empty() {
        String::new()
    } else {
        format!(
            "; read at its kinematic parameters {} (the machine's defaults for the others)",
            differ.join(", ")
        )
    }
}

/// Reads the campaign file at `path` for machine `m` (records not loaded), with the digest of
/// the bytes read (the file is opened once). The records are read by [`CampaignFile::load`].
///
/// # Errors
/// [`CampaignFileError::Text`] or [`CampaignFileError::Invalid`].
pub fn read_campaign_file(
    path: &Path,
    m: &Machine,
) -> Result<(CampaignFile, Digest), CampaignFileError> {
    let (text, digest) = model_spec::text::read_text_hashed(path, MAX_CAMPAIGN_BYTES)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    Ok((
        parse_campaign(&path.display().to_string(), &text, dir, m)?,
        digest,
    ))
}

impl CampaignFile {
    /// Reads every record's CSV at its kinematic parameters (with `opts`) into a campaign, with
    /// the digest of each record's bytes as read (in record order).
    ///
    /// # Errors
    /// [`CampaignFileError::Record`] naming the record and the CSV's own line;
    /// [`CampaignFileError::Campaign`] for records that do not make a campaign.
    pub fn load(
        &self,
        m: &Machine,
        opts: &ReadOptions,
        instrument: Option<(&Instrument, ReadingsFrame)>,
    ) -> Result<(Campaign, Vec<Digest>), CampaignFileError> {
        self.load_with(m, |e| {
            read_record_at(&e.path, m, &e.params, opts, instrument)
        })
    }

    /// [`CampaignFile::load`] with each record's file read by `read` (a record and the
    /// digest of the bytes read, or the reader's located error): for records that are not
    /// measurement CSVs (a touch probe's hits, read through its sphere fits).
    ///
    /// # Errors
    /// As [`CampaignFile::load`].
    pub fn load_with(
        &self,
        m: &Machine,
        mut read: impl FnMut(&CampaignEntry) -> Result<(simulation::record::Record, Digest), CsvError>,
    ) -> Result<(Campaign, Vec<Digest>), CampaignFileError> {
        let mut records = Vec::with_capacity(self.records.len());
        let mut digests = Vec::with_capacity(self.records.len());
        for e in &self.records {
            let (record, digest) = read(e).map_err(|error| CampaignFileError::Record {
                at: parameters_note(m, &e.params),
                campaign: self.file.clone(),
                line: e.line,
                label: e.label.clone(),
                error: Box::new(error),
            })?;
            if e.start_s.is_some() && !record.has_times() {
                return Err(CampaignFileError::Invalid {
                    file: self.file.clone(),
                    line: e.line,
                    column: 1,
                    message: format!(
                        "record `{}`: `start` puts the record on the campaign clock, but {} has no `t_s` column (its samples are only numbered): add the times in s",
                        e.label,
                        e.path.display()
                    ),
                });
            }
            let mut r = CampaignRecord::new(
                e.label.clone(),
                record,
                e.params.clone(),
                e.setup.clone(),
                e.zeroed,
            );
            r.start_s = e.start_s;
            records.push(r);
            digests.push(digest);
        }
        let campaign = Campaign::new(records).map_err(|error| CampaignFileError::Campaign {
            file: self.file.clone(),
            error,
        })?;
        Ok((campaign, digests))
    }
}
