//! The options of a diagnosis.

use super::dictionary::DictionaryOptions;
use super::plausible::Budget;
use fitting::noise::NoiseChoice;
use fitting::{Constraint, Tolerances};

/// Options of [`super::diagnose()`] (`DiagnoseOptions::default()`, then set the fields wanted;
/// new fields come with defaults that keep today's behaviour). The records carry their own
/// zeroing, set-ups and kinematic parameters ([`simulation::campaign::CampaignRecord`]).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct DiagnoseOptions {
    /// The candidate dictionary's extent.
    pub dictionary: DictionaryOptions,
    /// Significance level α of each step, after the correction for the candidates tried.
    pub alpha: f64,
    /// Most findings.
    pub max_findings: usize,
    /// Monte-Carlo draws for the corrected p-value when Bonferroni is not decisive.
    pub draws: usize,
    /// Seed of the Monte-Carlo draws.
    pub seed: u64,
    /// Rank and identifiability tolerances of the fits.
    pub tolerances: Tolerances,
    /// What the fits do with parameters the data cannot determine (as `identify
    /// --constraint`); held-out predictions that depend on them are flagged all the same.
    pub constraint: Constraint,
    /// The largest plausible size of a finding, per unit.
    pub budget: Budget,
    /// The noise model of the tests: estimated from the records (the default), declared, from
    /// a static record, or ordinary least squares (white, σ from the residual: no lack-of-fit
    /// test is then possible).
    pub noise: NoiseChoice,
    /// Bootstrap draws of the lack-of-fit test (default 400); 0: no test.
    pub adequacy_draws: usize,
    /// Grouped candidates after the findings ([`super::groups`]): the error groups of a
    /// calibration standard, each tested as one candidate and confirmed as a whole (default
    /// on).
    pub groups: bool,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            dictionary: DictionaryOptions::default(),
            alpha: 0.01,
            max_findings: 8,
            draws: 1000,
            seed: 0x5eed,
            tolerances: Tolerances::default(),
            constraint: Constraint::None,
            budget: Budget::default(),
            noise: NoiseChoice::Estimate,
            adequacy_draws: super::adequacy::DRAWS,
            groups: true,
        }
    }
}

impl DiagnoseOptions {
    /// The defaults.
    pub fn new() -> DiagnoseOptions {
        DiagnoseOptions::default()
    }

    /// With the dictionary's extent.
    pub fn dictionary(mut self, dictionary: DictionaryOptions) -> DiagnoseOptions {
        self.dictionary = dictionary;
        self
    }

    /// With the significance level of each step.
    pub fn alpha(mut self, alpha: f64) -> DiagnoseOptions {
        self.alpha = alpha;
        self
    }

    /// With at most `n` findings.
    pub fn max_findings(mut self, n: usize) -> DiagnoseOptions {
        self.max_findings = n;
        self
    }

    /// With `draws` Monte-Carlo draws.
    pub fn draws(mut self, draws: usize) -> DiagnoseOptions {
        self.draws = draws;
        self
    }

    /// With the grouped candidates on or off.
    pub fn groups(mut self, on: bool) -> DiagnoseOptions {
        self.groups = on;
        self
    }

    /// With the seed of the Monte-Carlo draws.
    pub fn seed(mut self, seed: u64) -> DiagnoseOptions {
        self.seed = seed;
        self
    }
}
