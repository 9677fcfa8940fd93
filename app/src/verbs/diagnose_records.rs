//! The records of `rtest diagnose`: the fitted ones (`--data` or `--campaign`) and the
//! held-out ones (`--validate` or `--validate-campaign`), read as its flags say.

use super::diagnose::DiagnoseArgs;
use super::{Error, ReadFile, VerbResult, campaign};
use formats::campaign::{labels_from_files, stem_label, unique_label};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::record::Record;
use std::path::PathBuf;

/// The files as read, and per record what a probe's sphere fits say.
type Read = (Vec<ReadFile>, Vec<Option<fitting::probe::ProbeSummary>>);

/// How `rtest diagnose` reads its records: on the machine `m`, at the kinematic parameters of
/// `--param` (mm), as the record flags say, through the instrument when one is given, each with
/// a progress bar while it is read (`shown`).
pub(super) struct Reader<'a> {
    pub(super) m: &'a model_spec::Machine,
    pub(super) args: &'a DiagnoseArgs,
    pub(super) params: Vec<f64>,
    pub(super) read: formats::csv::ReadOptions,
    pub(super) through: campaign::Through<'a>,
    pub(super) shown: bool,
}

impl Reader<'_> {
    /// The records of `files` (given by `flag`), and the files as read (with what a probe's
    /// sphere fits say).
    fn records(&self, flag: &str, files: &[PathBuf]) -> VerbResult<(Vec<Record>, Read)> {
        campaign::record_count(flag, files)?;
        let mut records = Vec::with_capacity(files.len());
        let mut read_files = Vec::with_capacity(files.len());
        let mut probe = Vec::with_capacity(files.len());
        for f in files {
            let (_bar, read) = super::progress::reading(self.shown, f, &self.read);
            let (record, digest, summary) =
                super::read_record(flag, self.m, f, &read, self.through, &self.params)?;
            records.push(record);
            read_files.push(ReadFile::new(flag, f, digest));
            probe.push(summary);
        }
        Ok((records, (read_files, probe)))
    }

    /// The fitted records: the `--campaign` file, or the `--data` `files`, each on a set-up of
    /// its own, labelled by its stem.
    pub(super) fn fitted(&self, files: &[PathBuf]) -> VerbResult<campaign::Loaded> {
        let (m, args) = (self.m, self.args);
        if let Some(path) = &args.campaign {
            let file = campaign::read_file("--campaign", m, path)?;
            return campaign::from_file("--campaign", m, path, file, &self.read, self.through);
        }
        let labels = labels_from_files(files);
        let (records, read_files) = self.records("--data", files)?;
        let records = records
            .into_iter()
            .zip(&labels)
            .map(|(r, l)| CampaignRecord::new(l, r, self.params.clone(), l, args.zeroed))
            .collect();
        loaded(records, files, read_files)
    }

    /// The held-out records: the `--validate-campaign` file, or the `--validate` `files`, on
    /// the fitted records' set-up when they have one (the ball not moved), else each on a
    /// set-up of its own; labelled by their stems, unique among the fitted records' labels.
    pub(super) fn held_out(
        &self,
        fitted: &campaign::Loaded,
        files: &[PathBuf],
    ) -> VerbResult<campaign::Loaded> {
        let (m, args) = (self.m, self.args);
        if let Some(path) = &args.validate_campaign {
            let file = campaign::read_file("--validate-campaign", m, path)?;
            return campaign::from_file(
                "--validate-campaign",
                m,
                path,
                file,
                &self.read,
                self.through,
            );
        }
        let setups = fitted.campaign.setups();
        let mut taken: Vec<String> = fitted
            .campaign
            .records
            .iter()
            .map(|r| r.label.clone())
            .collect();
        let mut labels = Vec::with_capacity(files.len());
        for f in files {
            let l = unique_label(&stem_label(f), &taken);
            taken.push(l.clone());
            labels.push(l);
        }
        let (records, read_files) = self.records("--validate", files)?;
        let records = records
            .into_iter()
            .zip(&labels)
            .map(|(r, l)| {
                let setup = match setups.as_slice() {
                    [one] => one.clone(),
                    _ => l.clone(),
                };
                CampaignRecord::new(l, r, self.params.clone(), setup, args.zeroed)
            })
            .collect();
        loaded(records, files, read_files)
    }
}

/// The campaign of `records` read from `files` (as `read` says; an empty campaign for no
/// records).
fn loaded(
    records: Vec<CampaignRecord>,
    files: &[PathBuf],
    (read, probe): Read,
) -> VerbResult<campaign::Loaded> {
    let campaign = if records.is_empty() {
        Campaign {
            records: Vec::new(),
        }
    } else {
        Campaign::new(records).map_err(|e| Error::usage(e.0))?
    };
    Ok(campaign::Loaded {
        campaign,
        files: files.iter().map(|f| f.display().to_string()).collect(),
        source: None,
        read,
        probe,
    })
}
