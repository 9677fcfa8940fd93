//! The gain tables as JSON (`rtest gains --format json`): the symbolic table of a model, and
//! the numbers at one pose.

use super::{NonFinite, Ordered, finite};
use codegen::GainModel;
use codegen::atoms::AtomKind;
use codegen::table::format_poly;
use model_spec::Machine;
use model_spec::units::short;
use serde::Serialize;

/// What the columns of a gain table mean.
pub const GAIN_UNITS: &str = "error vector = tool point minus workpiece point, tool frame, first order; dX dY dZ in mm per mm of a translational error or mm per rad of an angular error; dI dJ dK per mm or per rad";

/// The symbolic gain table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GainTableReport {
    /// Machine name.
    pub machine: String,
    /// The model's name; `null` for an explicit list of errors.
    pub model: Option<String>,
    /// What the columns mean ([`GAIN_UNITS`]).
    pub units: String,
    /// `dX dY dZ dI dJ dK`.
    pub columns: Vec<String>,
    /// What every atom of the formulas stands for.
    pub atoms: Ordered<String>,
    /// Per error, in model order: the six formulas.
    pub gains: Ordered<Vec<String>>,
}

/// What each atom of a model's formulas stands for (`Sa`: sine of the A command, `Zc`:
/// kinematic parameter, mm (default 29.794)).
pub fn atom_legend(m: &Machine, model: &GainModel) -> Vec<(String, String)> {
    model
        .atoms
        .kinds
        .iter()
        .zip(&model.atoms.names)
        .map(|(k, name)| {
            let meaning = match *k {
                AtomKind::Sin(a) => format!("sine of the {} command", m.axes[a].name),
                AtomKind::Cos(a) => format!("cosine of the {} command", m.axes[a].name),
                AtomKind::Command(a) => format!("{} command, mm", m.axes[a].name),
                AtomKind::Symbol(s) => format!(
                    "kinematic parameter, mm (default {})",
                    short(m.symbols[s].default)
                ),
                AtomKind::Root(p) => format!("the square root of {p} (an inclined axis's frame)"),
                AtomKind::Constant(bits) => format!(
                    "a numeric entry of an inclined axis's frame ({})",
                    short(f64::from_bits(bits))
                ),
            };
            (name.clone(), meaning)
        })
        .collect()
}

impl GainTableReport {
    /// The table of `model` of `m` (named `model_name`, `None` for a list of errors).
    pub fn new(m: &Machine, model_name: Option<&str>, model: &GainModel) -> GainTableReport {
        GainTableReport {
            machine: m.name.clone(),
            model: model_name.map(str::to_string),
            units: GAIN_UNITS.into(),
            columns: ["dX", "dY", "dZ", "dI", "dJ", "dK"]
                .map(String::from)
                .to_vec(),
            atoms: Ordered(atom_legend(m, model)),
            gains: Ordered(
                model
                    .error_names
                    .iter()
                    .zip(&model.gains)
                    .map(|(name, g)| {
                        let cells = g
                            .iter()
                            .map(|p| format_poly(p, &model.atoms.names, false))
                            .collect();
                        (name.clone(), cells)
                    })
                    .collect(),
            ),
        }
    }
}

/// The position gains at one pose: `{error: [gx, gy, gz]}` in model order (mm/mm or mm/rad).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(transparent)]
pub struct PoseGainsReport(pub Ordered<[f64; 3]>);

impl PoseGainsReport {
    /// The gains `gains` of the errors `names`.
    ///
    /// # Errors
    /// [`NonFinite`] when a gain is not finite.
    pub fn new(names: &[String], gains: &[[f64; 3]]) -> Result<PoseGainsReport, NonFinite> {
        let mut rows = Vec::with_capacity(names.len());
        for (n, g) in names.iter().zip(gains) {
            let mut out = [0.0; 3];
            for d in 0..3 {
                out[d] = finite(|| format!("{n}[{d}]"), g[d])?;
            }
            rows.push((n.clone(), out));
        }
        Ok(PoseGainsReport(Ordered(rows)))
    }
}
