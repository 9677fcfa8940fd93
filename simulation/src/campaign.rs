//! Campaigns: several records, each measured with its own set-up, fitted together
//! (`fitting::campaign` fits them). A campaign of one record is how a single record is
//! fitted, validated and diagnosed.

use crate::record::Record;
use model_spec::Machine;
use model_spec::units::short;

/// The label of the record of [`Campaign::of_record`] and of its set-up.
pub const SINGLE_LABEL: &str = "record";

/// One record of a campaign: its samples (and readings), the kinematic parameters it was
/// planned and is modelled with, its set-up and whether its readings were zeroed.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignRecord {
    /// The record's label (`k4`, `k4-high`): unique in the campaign; names its own parameters
    /// (`dx0[k4]`). Letters, digits and `- _ . + :`.
    pub label: String,
    /// The samples (commands in mm and rad) and, when measured, the readings (mm).
    pub record: Record,
    /// The kinematic parameters of this record, one per machine symbol in symbol order, mm:
    /// the ball's position (`Xw`, `Zw`, …) lives here. The gains and the exact machine of this
    /// record use them.
    pub params: Vec<f64>,
    /// The set-up label: records with the same label share the ball set-up errors (one ball
    /// mounting measured along several paths). Same character rules as the label.
    pub setup: String,
    /// The readings were zeroed at the first sample: the record's own `dx0 dy0 dz0` join the
    /// fit.
    pub zeroed: bool,
    /// When the record's time 0 (its samples' `t`, s) is on the campaign clock, s; `None`: the
    /// record has its own clock. Either every record of a campaign has a start or none has.
    pub start_s: Option<f64>,
}

impl CampaignRecord {
    /// A record labelled `label` with kinematic parameters `params` (mm, symbol order), on set-up
    /// `setup`, zeroed or not, on its own clock.
    pub fn new(
        label: impl Into<String>,
        record: Record,
        params: Vec<f64>,
        setup: impl Into<String>,
        zeroed: bool,
    ) -> CampaignRecord {
        CampaignRecord {
            label: label.into(),
            record,
            params,
            setup: setup.into(),
            zeroed,
            start_s: None,
        }
    }

    /// The record on its own set-up (its label), at the machine's default kinematic
    /// parameters, not zeroed: what `rtest identify --data a.csv,b.csv` makes of each file.
    pub fn on_own_setup(m: &Machine, label: impl Into<String>, record: Record) -> CampaignRecord {
        let label = label.into();
        CampaignRecord::new(label.clone(), record, m.default_parameters(), label, false)
    }

    /// With the record's time 0 at `start_s` on the campaign clock (s).
    pub fn starting_at(mut self, start_s: f64) -> CampaignRecord {
        self.start_s = Some(start_s);
        self
    }
}

/// A campaign: its records, in order (rows of the design matrix are the records' in this
/// order).
#[derive(Clone, Debug, PartialEq)]
pub struct Campaign {
    /// The records.
    pub records: Vec<CampaignRecord>,
}

/// A campaign that cannot be fitted as given.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct CampaignError(pub String);

/// The most records a campaign may hold. A real calibration campaign has some tens (tests ×
/// ball positions × repeats); the limit keeps a mistyped or hostile list from allocating the
/// design matrices of thousands of records.
pub const MAX_RECORDS: usize = 200;

/// The longest record or set-up label, in characters.
pub const MAX_LABEL_CHARS: usize = 256;

/// Refuses a campaign of more than [`MAX_RECORDS`] records (`n` of them), before any is read.
///
/// # Errors
/// [`CampaignError`] naming the count and the limit.
pub fn check_record_count(n: usize) -> Result<(), CampaignError> {
    if n > MAX_RECORDS {
        return Err(CampaignError(format!(
            "{n} records, more than {MAX_RECORDS}, the most a campaign may have"
        )));
    }
    Ok(())
}

/// `true` when `c` may appear in a record or set-up label: ASCII letters, digits and `- _ . + :`.
pub fn label_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || "-_.+:".contains(c)
}

/// Checks a record or set-up label (`what` names it in the message): not empty, at most
/// [`MAX_LABEL_CHARS`] characters, only [`label_char`]s.
///
/// # Errors
/// [`CampaignError`] naming `what`, the label and the first character not allowed.
pub fn check_label(what: &str, label: &str) -> Result<(), CampaignError> {
    if label.is_empty() {
        return Err(CampaignError(format!("{what}: the label is empty")));
    }
    let n = label.chars().count();
    if n > MAX_LABEL_CHARS {
        return Err(CampaignError(format!(
            "{what} `{}` has {n} characters, more than {MAX_LABEL_CHARS}, the longest a label may have",
            model_spec::text::quoted_start(label)
        )));
    }
    if let Some(c) = label.chars().find(|&c| !label_char(c)) {
        return Err(CampaignError(format!(
            "{what} `{label}`: `{c}` is not allowed in a label (letters, digits and - _ . + : only; a label names parameters, as in `dx0[k4]`)"
        )));
    }
    Ok(())
}

impl Campaign {
    /// The campaign of `records`, checked: at least one record, labels unique and well formed,
    /// set-up labels well formed, every start on the campaign clock finite, and either every
    /// record or none with a start.
    ///
    /// # Errors
    /// [`CampaignError`] naming the record.
    pub fn new(records: Vec<CampaignRecord>) -> Result<Campaign, CampaignError> {
        check_record_count(records.len())?;
        let c = Campaign { records };
        c.check_labels()?;
        Ok(c)
    }

    /// Refuses a campaign whose records carry per-sample covariances for `what` (a use that
    /// does not weight its rows by them yet).
    ///
    /// # Errors
    /// [`CampaignError`] naming the first such record.
    pub fn refuse_covariances(&self, what: &str) -> Result<(), CampaignError> {
        match self
            .records
            .iter()
            .find(|r| !r.record.covariance.is_empty())
        {
            Some(r) => Err(CampaignError(format!(
                "record `{}` was read through an instrument (per-sample covariances), which {what} does not weight yet: identify the campaign (which does), or validate and diagnose records of error vectors",
                r.label
            ))),
            None => Ok(()),
        }
    }

    /// `record` as a campaign of one: labelled and set up as `record`, at kinematic parameters
    /// `params` (mm, symbol order), zeroed or not, on its own clock. How a single record is
    /// identified, validated and diagnosed.
    pub fn of_record(record: Record, params: Vec<f64>, zeroed: bool) -> Campaign {
        Campaign {
            records: vec![CampaignRecord::new(
                SINGLE_LABEL,
                record,
                params,
                SINGLE_LABEL,
                zeroed,
            )],
        }
    }

    fn check_labels(&self) -> Result<(), CampaignError> {
        if self.records.is_empty() {
            return Err(CampaignError("a campaign needs at least one record".into()));
        }
        for (i, r) in self.records.iter().enumerate() {
            check_label("record", &r.label)?;
            check_label(&format!("record `{}`: set-up", r.label), &r.setup)?;
            if self.records[..i].iter().any(|o| o.label == r.label) {
                return Err(CampaignError(format!(
                    "record label `{}` is given twice: every record needs its own label",
                    r.label
                )));
            }
            if let Some(s) = r.start_s
                && !s.is_finite()
            {
                return Err(CampaignError(format!(
                    "record `{}`: its start on the campaign clock is not finite ({s})",
                    r.label
                )));
            }
        }
        let started = self.records.iter().filter(|r| r.start_s.is_some()).count();
        if started != 0 && started != self.records.len() {
            let without: Vec<&str> = self
                .records
                .iter()
                .filter(|r| r.start_s.is_none())
                .map(|r| r.label.as_str())
                .collect();
            return Err(CampaignError(format!(
                "{started} records have a start on the campaign clock and {} ({}) have none: give every record a start, or none",
                without.len(),
                without.join(", ")
            )));
        }
        Ok(())
    }

    /// Checks the campaign against machine `m`: the labels (as [`Campaign::new`]), one finite
    /// kinematic parameter per symbol within the machine's length limit, one command and one
    /// direction of motion per axis in every sample, and equal parameters within a set-up (one
    /// ball mounting has one position).
    ///
    /// # Errors
    /// [`CampaignError`] naming the record, the symbol or the sample.
    pub fn check(&self, m: &Machine) -> Result<(), CampaignError> {
        self.check_labels()?;
        for r in &self.records {
            if r.params.len() != m.symbols.len() {
                return Err(CampaignError(format!(
                    "record `{}`: {} kinematic parameters for the {} symbols of machine {}",
                    r.label,
                    r.params.len(),
                    m.symbols.len(),
                    m.name
                )));
            }
            for (s, &v) in r.params.iter().enumerate() {
                if !v.is_finite() || v.abs() > model_spec::limits::MAX_LENGTH_MM {
                    return Err(CampaignError(format!(
                        "record `{}`: kinematic parameter `{}` = {v} mm is not a finite length within ±{} mm",
                        r.label,
                        m.symbols[s].name,
                        model_spec::limits::MAX_LENGTH_MM
                    )));
                }
            }
            if r.record.samples.is_empty() {
                return Err(CampaignError(format!(
                    "record `{}` has no samples",
                    r.label
                )));
            }
            let n = m.axes.len();
            if let Some(i) = r
                .record
                .samples
                .iter()
                .position(|s| s.commands.len() != n || s.motion.len() != n)
            {
                return Err(CampaignError(format!(
                    "record `{}`: {} has {} commands for the {n} axes of machine {}",
                    r.label,
                    r.record.place(i),
                    r.record.samples[i].commands.len(),
                    m.name
                )));
            }
        }
        for (i, r) in self.records.iter().enumerate() {
            let Some(o) = self.records[..i].iter().find(|o| o.setup == r.setup) else {
                continue;
            };
            if let Some(s) = (0..r.params.len()).find(|&s| r.params[s] != o.params[s]) {
                return Err(CampaignError(format!(
                    "records `{}` and `{}` share set-up `{}` but have different kinematic parameters (`{}` = {} and {} mm): one ball set-up has one position; give them different set-up labels",
                    o.label,
                    r.label,
                    r.setup,
                    m.symbols[s].name,
                    short(o.params[s]),
                    short(r.params[s])
                )));
            }
        }
        Ok(())
    }

    /// The set-up labels in order of first appearance.
    pub fn setups(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for r in &self.records {
            if !out.contains(&r.setup) {
                out.push(r.setup.clone());
            }
        }
        out
    }

    /// `true` when every record has a start on the campaign clock.
    pub fn has_clock(&self) -> bool {
        !self.records.is_empty() && self.records.iter().all(|r| r.start_s.is_some())
    }

    /// Samples over all records.
    pub fn samples(&self) -> usize {
        self.records.iter().map(|r| r.record.samples.len()).sum()
    }
}
