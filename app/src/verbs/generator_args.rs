//! The flags of the path generator that `rtest path` and `rtest plan` share: the step of the
//! turning axis, the sample period and the clearance checks, held once and turned into
//! [`GeneratorOptions`] with the flag at fault named.

use super::{Error, VerbResult};
use simulation::generator::{self, Clearance, GeneratorError, GeneratorOptions};

/// The generator's flags.
#[derive(Debug, Clone, clap::Args)]
pub struct GeneratorArgs {
    /// Step of the turning axis, degrees (default: each test's own: 1°, 1.5° for pair tests
    /// and K4); the step used divides the span into equal steps of at most this.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub step_deg: Option<f64>,
    /// Time between two samples, s.
    #[arg(long, value_name = "S", default_value_t = simulation::paths::SAMPLE_PERIOD_S,
          allow_negative_numbers = true)]
    pub period_s: f64,
    /// Largest angle between the tool axis and the table normal, degrees (0 to 180).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true,
          default_value_t = generator::clearance::DEFAULT_MAX_TILT_DEG)]
    pub max_tilt_deg: f64,
    /// Least height of the ball centre above the table face, mm: the reach of your nest.
    #[arg(long, value_name = "MM", allow_negative_numbers = true,
          default_value_t = generator::clearance::DEFAULT_MIN_BALL_HEIGHT_MM)]
    pub min_ball_height_mm: f64,
}

impl GeneratorArgs {
    /// The generator's options, each checked against its domain.
    ///
    /// # Errors
    /// A usage error naming the flag out of its domain.
    pub fn options(&self) -> VerbResult<GeneratorOptions> {
        let opts = GeneratorOptions {
            step_deg: self.step_deg,
            period_s: self.period_s,
            clearance: Clearance {
                max_tilt_deg: self.max_tilt_deg,
                min_ball_height_mm: self.min_ball_height_mm,
            },
        };
        generator::check_options(&opts).map_err(|e| match &e {
            GeneratorError::Option { option, .. } => {
                Error::usage(format!("{}: {e}", option_flag(option)))
            }
            _ => Error::usage(e.to_string()),
        })?;
        Ok(opts)
    }
}

/// The flag of the generator's option `option` as a [`GeneratorError::Option`] names it
/// (`"step"` → `--step-deg`).
pub fn option_flag(option: &str) -> &'static str {
    match option {
        "step" => "--step-deg",
        "period" => "--period-s",
        "max tilt" => "--max-tilt-deg",
        _ => "--min-ball-height-mm",
    }
}
