//! Records of a touch probe: `--probe FILE` (the probe instrument) for the verbs that read
//! records, and a record's file (probe hits, or sphere centres another device fitted) read
//! through the probe's sphere fits into readings of the error vector (`docs/probe.md`).

use super::{Error, ReadFile, VerbResult};
use fitting::probe::{ProbeSettings, ProbeSummary, centre_record, probe_record};
use formats::csv::{CsvError, ReadOptions};
use formats::probe::{
    ProbeFile, ProbeInstrument, instrument::MAX_PROBE_INSTRUMENT_BYTES, parse_probe_instrument,
    read_probe_file, read_probe_from,
};
use model_spec::Machine;
use model_spec::sha256::Digest;
use simulation::record::Record;
use std::path::{Path, PathBuf};

/// The touch probe whose hits the records hold. For the verbs that read records.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ProbeArgs {
    /// The touch probe of the records: a probe instrument file (TOML: tip_radius_mm,
    /// sphere_radius_mm, noise_um; docs/probe.md). The records are then probe hits CSVs (pose,
    /// the axes, nx, ny, nz, t_s) or sphere centres CSVs (pose, the axes, cx, cy, cz, optionally
    /// u_cx, u_cy, u_cz and r), told apart by their headers; each pose's sphere fit gives one
    /// reading of the error vector, its covariance from the probe's σ.
    #[arg(long, value_name = "FILE", conflicts_with = "instrument")]
    pub probe: Option<PathBuf>,
}

impl ProbeArgs {
    /// The input file `--probe` names, for the check that no output names an input.
    pub fn input(&self) -> Option<(&'static str, &Path)> {
        self.probe.as_deref().map(|p| ("--probe", p))
    }

    /// The probe instrument, when `--probe` is given, with the file as read.
    ///
    /// # Errors
    /// The file's located problem (an input error).
    pub fn load_read(&self) -> VerbResult<(Option<ProbeInstrument>, Option<ReadFile>)> {
        let Some(path) = &self.probe else {
            return Ok((None, None));
        };
        let (text, digest) = model_spec::text::read_text_hashed(path, MAX_PROBE_INSTRUMENT_BYTES)
            .map_err(|e| Error::input(format!("--probe: {e}")))?;
        let probe = parse_probe_instrument(&path.display().to_string(), &text)
            .map_err(|e| Error::input(format!("--probe: {e}")))?;
        Ok((Some(probe), Some(ReadFile::new("--probe", path, digest))))
    }
}

/// The record of the probe file at `path` (hits or centres) on machine `m` at kinematic
/// parameters `params` (mm), through `probe`'s sphere fits, with the digest of the bytes read
/// and what the fits say.
///
/// # Errors
/// The file's located problem, or a pose the fits refuse (file, line, why).
pub fn read_probe_record(
    path: &Path,
    m: &Machine,
    params: &[f64],
    probe: &ProbeInstrument,
    opts: &ReadOptions,
) -> Result<(Record, Digest, ProbeSummary), CsvError> {
    let (content, digest) = read_probe_file(path, m)?;
    let file = path.display().to_string();
    let (record, summary) = fitted(&file, content, m, params, probe, opts)?;
    Ok((record, digest, summary))
}

/// The record of a probe file's `bytes` (named `file` in messages), read as
/// [`read_probe_record`] reads the file (`formats::probe::read_probe_from`: the same readers,
/// told apart by the header): for `rtest report`, which reads the records a report names once,
/// hashing them.
///
/// # Errors
/// As [`read_probe_record`].
pub fn probe_record_of_bytes(
    file: &str,
    bytes: &[u8],
    m: &Machine,
    params: &[f64],
    probe: &ProbeInstrument,
    opts: &ReadOptions,
) -> Result<(Record, ProbeSummary), CsvError> {
    let content = read_probe_from(file, bytes, m)?;
    fitted(file, content, m, params, probe, opts)
}

/// The record of a probe file's `content` (named `file`) through `probe`'s sphere fits, and
/// what the fits say.
fn fitted(
    file: &str,
    content: ProbeFile,
    m: &Machine,
    params: &[f64],
    probe: &ProbeInstrument,
    opts: &ReadOptions,
) -> Result<(Record, ProbeSummary), CsvError> {
    let settings = ProbeSettings::of(probe, opts.max_reading_mm);
    Ok(match content {
        ProbeFile::Hits(hits) => {
            let fitted = probe_record(file, m, params, &hits, &settings)?;
            let lines: Vec<Vec<usize>> = hits
                .poses
                .iter()
                .map(|p| p.hits.iter().map(|h| h.line).collect())
                .collect();
            let summary = ProbeSummary::of_hits(&fitted, &lines, probe.sphere_radius_mm);
            (fitted.record, summary)
        }
        ProbeFile::Centres(centres) => (
            centre_record(file, m, params, &centres, &settings)?,
            ProbeSummary::of_centres(&centres, probe.sphere_radius_mm),
        ),
    })
}
