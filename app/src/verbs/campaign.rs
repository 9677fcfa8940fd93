//! What `identify`, `validate` and `diagnose` share: the records of `--data a.csv,b.csv` (each
//! its own set-up and its own R-test zero; one file is a campaign of one) or of
//! `--campaign FILE`, their checks, and the plausibility of a campaign's values.

use super::{Error, ReadFile, VerbResult};
use fitting::campaign::Layout;
use fitting::sanity::{ValueLimits, check_model_values};
use formats::campaign::{CampaignFile, labels_from_files, read_campaign_file};
use formats::csv::ReadOptions;
use model_spec::Machine;
use model_spec::instrument::{Instrument, ReadingsFrame};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::Model;
use std::path::{Path, PathBuf};

/// A campaign read from the command line, with the file of each record.
pub struct Loaded {
    /// The campaign.
    pub campaign: Campaign,
    /// Per record, its measurement file as given (for reports).
    pub files: Vec<String>,
    /// The campaign file, when the records came from one.
    pub source: Option<PathBuf>,
    /// The files as read: the campaign file (when there is one), then each record's file, with
    /// the digests of the bytes read.
    pub read: Vec<ReadFile>,
    /// Per record, what its sphere fits say when it was read through a touch probe.
    pub probe: Vec<Option<fitting::probe::ProbeSummary>>,
}

/// What the records' files hold and what turns them into error vectors.
#[derive(Clone, Copy, Debug)]
pub enum Through<'a> {
    /// Error vectors (`dx_um,dy_um,dz_um`): measurement CSVs read as they are.
    Errors,
    /// An R-test's sensor readings, turned into error vectors by its geometry, in the frame
    /// of its displacements.
    Sensors(&'a Instrument, ReadingsFrame),
    /// A touch probe's hits (or sphere centres), turned into error vectors by sphere fits.
    Probe(&'a formats::probe::ProbeInstrument),
}

impl<'a> Through<'a> {
    /// The records' reader from the loaded R-test instrument or probe (at most one is given:
    /// the flags conflict).
    pub fn of(
        instrument: &'a Option<super::args::Loaded>,
        probe: &'a Option<formats::probe::ProbeInstrument>,
    ) -> Through<'a> {
        match (instrument, probe) {
            (Some((i, f)), _) => Through::Sensors(i, *f),
            (None, Some(p)) => Through::Probe(p),
            (None, None) => Through::Errors,
        }
    }

    /// The R-test instrument, for the measurement CSV readers.
    pub fn sensors(self) -> Option<(&'a Instrument, ReadingsFrame)> {
        match self {
            Through::Sensors(i, f) => Some((i, f)),
            _ => None,
        }
    }

    /// `true` when an instrument declares the readings' noise (the sensors' σ, the probe's).
    pub fn declares_noise(self) -> bool {
        !matches!(self, Through::Errors)
    }

    /// The flag of the instrument, for messages (`--instrument`, `--probe`).
    pub fn flag(self) -> &'static str {
        match self {
            Through::Probe(_) => "--probe",
            _ => "--instrument",
        }
    }
}

/// The records of `files` (given by `flag`), each on a set-up of its own labelled by the
/// file's stem (made unique), at kinematic parameters `params` (mm), zeroed or not, read
/// through `instrument` when it is given.
pub fn from_files(
    flag: &str,
    m: &Machine,
    files: &[PathBuf],
    params: &[f64],
    zeroed: bool,
    read: &ReadOptions,
    instrument: Through,
) -> VerbResult<Loaded> {
    record_count(flag, files)?;
    let labels = labels_from_files(files);
    let mut records = Vec::with_capacity(files.len());
    let mut read_files = Vec::with_capacity(files.len());
    let mut probe = Vec::with_capacity(files.len());
    for (f, label) in files.iter().zip(&labels) {
        let (record, digest, summary) = super::read_record(flag, m, f, read, instrument, params)?;
        probe.push(summary);
        read_files.push(ReadFile::new(flag, f, digest));
        records.push(CampaignRecord::new(
            label.clone(),
            record,
            params.to_vec(),
            label.clone(),
            zeroed,
        ));
    }
    let campaign = Campaign::new(records).map_err(|e| Error::usage(format!("{flag}: {e}")))?;
    Ok(Loaded {
        campaign,
        files: files.iter().map(|f| f.display().to_string()).collect(),
        source: None,
        read: read_files,
        probe,
    })
}

/// Refuses more files in `flag`'s list than a campaign may have records, before any is read.
///
/// # Errors
/// A usage error naming `flag` and the limit.
pub fn record_count(flag: &str, files: &[PathBuf]) -> VerbResult<()> {
    simulation::campaign::check_record_count(files.len())
        .map_err(|e| Error::usage(format!("{flag}: {e}")))
}

/// The campaign file `path` (given by `flag`) for machine `m`, read once (its records not yet
/// read: [`from_file`]).
pub fn read_file(flag: &str, m: &Machine, path: &Path) -> VerbResult<(CampaignFile, ReadFile)> {
    let (file, digest) =
        read_campaign_file(path, m).map_err(|e| Error::input(format!("{flag}: {e}")))?;
    Ok((file, ReadFile::new(flag, path, digest)))
}

/// The campaign of the campaign file `path` (given by `flag`) as [`read_file`] read it (`read`
/// its digest), every record's CSV read at its kinematic parameters and through `instrument`
/// when it is given.
pub fn from_file(
    flag: &str,
    m: &Machine,
    path: &Path,
    (file, source): (CampaignFile, ReadFile),
    read: &ReadOptions,
    instrument: Through,
) -> VerbResult<Loaded> {
    let mut probe = Vec::with_capacity(file.records.len());
    let (campaign, digests) = file
        .load_with(m, |e| {
            let (record, digest, summary) =
                super::read_record_file(&e.path, m, &e.params, read, instrument)?;
            probe.push(summary);
            Ok((record, digest))
        })
        .map_err(|e| Error::input(format!("{flag}: {e}")))?;
    let mut read_files = vec![source];
    read_files.extend(
        file.records
            .iter()
            .zip(digests)
            .map(|(r, d)| ReadFile::new(flag, &r.path, d)),
    );
    Ok(Loaded {
        campaign,
        files: file
            .records
            .iter()
            .map(|r| r.path.display().to_string())
            .collect(),
        source: Some(path.to_path_buf()),
        read: read_files,
        probe,
    })
}

impl Loaded {
    /// Every input file: the campaign file and the records' files, for the check that no
    /// output names an input.
    pub fn inputs(&self) -> Vec<PathBuf> {
        self.source
            .iter()
            .cloned()
            .chain(self.files.iter().map(PathBuf::from))
            .collect()
    }

    /// Refuses a record without real times for a term that needs them, naming the record (of
    /// several) and its file.
    pub fn check_times(&self, flag: &str, m: &Machine, model: &Model) -> VerbResult<()> {
        let one = self.campaign.records.len() == 1;
        for (r, f) in self.campaign.records.iter().zip(&self.files) {
            let mut local = model.clone();
            if r.zeroed {
                local = fitting::with_offsets(&local);
            }
            let named = if one {
                flag.to_string()
            } else {
                format!("{flag} (record `{}`)", r.label)
            };
            super::check_times(&named, Path::new(f), m, &local, &r.record)?;
        }
        Ok(())
    }

    /// The note for every record whose first reading is exactly 0 but that is not declared
    /// zeroed.
    pub fn zeroed_notes(&self, hint: &str) -> String {
        let one = self.campaign.records.len() == 1;
        self.campaign
            .records
            .iter()
            .filter(|r| r.record.looks_zeroed() && !r.zeroed)
            .map(|r| {
                if one {
                    format!(
                        "Note: the first reading is exactly 0: if the readings were zeroed at the first sample, {hint}.\n"
                    )
                } else {
                    format!(
                        "Note: the first reading of record `{}` is exactly 0: if its readings were zeroed at the first sample, {hint}.\n",
                        r.label
                    )
                }
            })
            .collect()
    }
}

/// The layout's columns as a model (one term per column group, harmonics' two columns once),
/// for the plausibility check of its values.
pub fn columns_model(layout: &Layout) -> Model {
    Model {
        terms: layout
            .columns
            .iter()
            .filter(|c| c.component == 0)
            .map(|c| c.term)
            .collect(),
    }
}

/// Checks a campaign's values against the plausibility bounds.
///
/// # Errors
/// The offending parameters, named.
pub fn check_campaign_values(
    m: &Machine,
    layout: &Layout,
    values: &[Option<f64>],
    limits: &ValueLimits,
) -> Result<(), fitting::Implausible> {
    check_model_values(m, &columns_model(layout), &layout.names(), values, limits)
}
