//! The data of the diagnosis figures, as plain series for a plotting library: per record, the
//! measured error against the base and extended predictions along the path (x, y, z), and the
//! residual components before and after the extension, and what remains unexplained against what
//! it follows.

use super::heldout::estimable;
use super::structure::{self, Component};
use super::{DiagnoseOptions, Diagnosis};
use fitting::campaign::validate_record;
use fitting::{ValidateError, ValidateOptions, Validation};
use model_spec::{AxisKind, Machine};
use simulation::campaign::Campaign;
use simulation::record::Record;
use std::path::Path;

/// How many components a spectrum figure shows.
pub const SPECTRUM_ROWS: usize = 12;

/// One named series of values.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Its legend.
    pub label: String,
    /// One value per abscissa point.
    pub values: Vec<f64>,
}

/// One panel of a path figure: a direction of the error vector.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// `x error`, `y error`, `z error`.
    pub name: String,
    /// The measured error, µm.
    pub measured: Series,
    /// The predictions, µm: base model, then extended model.
    pub predictions: Vec<Series>,
}

/// Measured against predicted error along a path.
#[derive(Clone, Debug, PartialEq)]
pub struct PathFigure {
    /// The file name it is written to (`k4-path.svg`).
    pub file_name: String,
    /// What it shows, for a list of files.
    pub what: String,
    /// Its title.
    pub title: String,
    /// What the abscissa is, with its unit: the axis that moves most (`C (deg)`, `X (mm)`;
    /// see [`abscissa`]), or what a residual follows.
    pub x_label: String,
    /// The abscissa.
    pub x: Vec<f64>,
    /// x, y and z.
    pub panels: Vec<Panel>,
}

/// The largest residual components before the extension, each with its size after.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectrumFigure {
    /// The file name it is written to (`k4-spectrum.svg`).
    pub file_name: String,
    /// What it shows, for a list of files.
    pub what: String,
    /// Its title.
    pub title: String,
    /// The legend of the bars before (base model).
    pub before_label: String,
    /// The legend of the bars after (extended model).
    pub after_label: String,
    /// Component label (`C harmonic:2 y`), RMS before and after, µm.
    pub rows: Vec<(String, f64, f64)>,
}

/// The figures of a diagnosis.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Figures {
    /// One per record.
    pub paths: Vec<PathFigure>,
    /// One per record with residual structure.
    pub spectra: Vec<SpectrumFigure>,
}

/// `C harmonic:2 y`.
pub fn component_label(c: &Component) -> String {
    format!("{} {} {}", c.source, c.shape, ["x", "y", "z"][c.direction])
}

/// The largest `n` components of `before`, each with its explained RMS in `after` (0 if gone).
pub fn component_rows(
    before: &[Component],
    after: &[Component],
    n: usize,
) -> Vec<(String, f64, f64)> {
    before
        .iter()
        .take(n)
        .map(|c| {
            let a = after
                .iter()
                .find(|x| x.source == c.source && x.shape == c.shape && x.direction == c.direction)
                .map_or(0.0, |x| x.explained_rms_um);
            (component_label(c), c.explained_rms_um, a)
        })
        .collect()
}

/// A file stem for a record's figures: the file's stem with unsafe characters replaced,
/// unique among `taken`.
fn stem(name: &str, taken: &mut Vec<String>) -> String {
    let raw = Path::new(name)
        .file_stem()
        .map_or("data".to_string(), |s| s.to_string_lossy().into_owned());
    let mut s: String = raw
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        s = "data".into();
    }
    let mut out = s.clone();
    let mut i = 2;
    while taken.contains(&out) {
        out = format!("{s}-{i}");
        i += 1;
    }
    taken.push(out.clone());
    out
}

/// The abscissa of a path figure: the position of the axis that moves most along the path,
/// in degrees for a rotary axis and mm for a linear one, labelled with the axis and unit
/// (`C (deg)`, `X (mm)`).
///
/// "Most" is the share of its own travel an axis sweeps on the path: the range of its
/// commands over the width of its stroke (linear) or range (rotary, at most one turn; a
/// rotary axis without limits counts one turn). An axis that moves one way (never reverses)
/// comes before one that reverses, whatever their shares: an abscissa that turns back folds
/// the curves onto themselves. Equal shares go to the rotary axis, then to the first axis
/// in the machine's order. Only a path on which no axis moves falls back to the sample
/// index, and its label says so. A touch probe's record (its poses, each one reading through
/// its sphere fit) is drawn over its poses' numbers, and its label says so.
pub fn abscissa(m: &Machine, record: &Record) -> (String, Vec<f64>) {
    // A touch probe's record is no path: one reading per pose, numbered in order.
    if !record.probe.is_empty() {
        return (
            "pose (a touch probe's record: one reading per pose, not a path)".into(),
            (1..=record.samples.len()).map(|i| i as f64).collect(),
        );
    }
    // (one way?, share, rotary?, axis), compared lexicographically; the first axis wins ties.
    let mut best: Option<(bool, f64, bool, usize)> = None;
    for (a, axis) in m.axes.iter().enumerate() {
        let q: Vec<f64> = record.samples.iter().map(|s| s.commands[a]).collect();
        let (lo, hi) = q
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        let rotary = axis.kind == AxisKind::Rotary;
        // Range on the path and width of the axis's travel, in the units people read.
        let (range, travel) = if rotary {
            let width = (axis.limits[1] - axis.limits[0]).min(360.0);
            (
                (hi - lo).to_degrees(),
                if width.is_finite() { width } else { 360.0 },
            )
        } else {
            (hi - lo, axis.limits[1] - axis.limits[0])
        };
        // Commands that differ by less than this are rounding, not motion (1 nm, 1 µdeg).
        if range.is_nan() || range <= 1e-6 {
            continue;
        }
        let share = if travel.is_finite() && travel > 0.0 {
            range / travel
        } else {
            1.0
        };
        let one_way = q.windows(2).all(|w| w[1] >= w[0]) || q.windows(2).all(|w| w[1] <= w[0]);
        let better = match best {
            None => true,
            Some((w, s, r, _)) => (one_way, share, rotary) > (w, s, r),
        };
        if better {
            best = Some((one_way, share, rotary, a));
        }
    }
    match best {
        Some((_, _, rotary, a)) => {
            let axis = &m.axes[a];
            let unit = if rotary { "deg" } else { "mm" };
            let x = record
                .samples
                .iter()
                .map(|s| {
                    if rotary {
                        s.commands[a].to_degrees()
                    } else {
                        s.commands[a]
                    }
                })
                .collect();
            (format!("{} ({unit})", axis.name), x)
        }
        None => (
            "sample index (no axis moves on this path)".into(),
            (0..record.samples.len()).map(|i| i as f64).collect(),
        ),
    }
}

/// The measured error of a validation: its prediction plus its residual (mm per sample).
fn measured(v: &Validation) -> Vec<[f64; 3]> {
    v.prediction
        .iter()
        .zip(&v.residual)
        .map(|(p, r)| [p[0] + r[0], p[1] + r[1], p[2] + r[2]])
        .collect()
}

/// The x, y and z panels of a record (µm): the measured error (mm per sample) against each
/// labelled prediction (mm per sample).
fn panels(measured: &[[f64; 3]], predictions: &[(String, &[[f64; 3]])]) -> Vec<Panel> {
    let um = |v: &[[f64; 3]], k: usize| v.iter().map(|r| r[k] * 1e3).collect::<Vec<f64>>();
    (0..3)
        .map(|k| Panel {
            name: format!("{} error", ["x", "y", "z"][k]),
            measured: Series {
                label: "measured".into(),
                values: um(measured, k),
            },
            predictions: predictions
                .iter()
                .map(|(label, p)| Series {
                    label: label.clone(),
                    values: um(p, k),
                })
                .collect(),
        })
        .collect()
}

/// Measured against predicted error along the path of `record` (named `name`, its `role`
/// such as `fitted` or `validation`), from the validation `v` of the model labelled `label`
/// on it: the figure of a validation, drawn against the axis that moves most ([`abscissa`]).
/// `taken` holds the file stems already used, so that two records never share a file name.
pub fn validation_figure(
    m: &Machine,
    name: &str,
    role: &str,
    record: &Record,
    v: &Validation,
    label: &str,
    taken: &mut Vec<String>,
) -> PathFigure {
    let (x_label, x) = abscissa(m, record);
    let s = stem(name, taken);
    PathFigure {
        file_name: format!("{s}-path.svg"),
        what: "figure: measured and predicted error along the path, x, y, z".into(),
        title: format!("{name} ({role}): measured and predicted error, µm"),
        x_label,
        x,
        panels: panels(
            &measured(v),
            &[(format!("identified model ({label})"), &v.prediction)],
        ),
    }
}

/// A record's path figure and spectrum: `measured` against the base and extended predictions,
/// the residual components `before` and `after` (base and extended model).
#[allow(clippy::too_many_arguments)]
fn record_figures(
    m: &Machine,
    out: &mut Figures,
    taken: &mut Vec<String>,
    (name, role): (&str, &str),
    record: &Record,
    measured: &[[f64; 3]],
    predictions: [&[[f64; 3]]; 2],
    (before, after): (Vec<Component>, Vec<Component>),
    (label, ext_label): (&str, &str),
) {
    let (x_label, x) = abscissa(m, record);
    let panels = panels(
        measured,
        &[
            (format!("base model ({label})"), predictions[0]),
            (format!("extended model ({ext_label})"), predictions[1]),
        ],
    );
    let s = stem(name, taken);
    out.paths.push(PathFigure {
        file_name: format!("{s}-path.svg"),
        what:
            "figure: measured and predicted error along the path (base and extended model), x, y, z"
                .into(),
        title: format!("{name} ({role}): measured and predicted error, µm"),
        x_label,
        x,
        panels,
    });
    let rows = component_rows(&before, &after, SPECTRUM_ROWS);
    if !rows.is_empty() {
        out.spectra.push(SpectrumFigure {
            file_name: format!("{s}-spectrum.svg"),
            what: "figure: residual components before and after the extension".into(),
            title: format!("{name} ({role}): residual components, µm"),
            before_label: format!("base model ({label})"),
            after_label: format!("extended model ({ext_label})"),
            rows,
        });
    }
}

/// The figures of diagnosis `d` of the model labelled `label` on the records of `fitted` and
/// `held_out` (as given to [`super::diagnose`]), named `names` (the fitted records', then the
/// held-out records', in order: their files): per record the measured error against the base
/// and extended predictions (a fitted record: the fits' own prediction, outliers drawn; a
/// held-out record: the predictions the gain was measured with) and its residual components;
/// then what remains unexplained, against what it follows.
///
/// # Errors
/// A prediction that fails.
pub fn figures(
    m: &Machine,
    d: &Diagnosis,
    label: &str,
    o: &DiagnoseOptions,
    fitted: &Campaign,
    held_out: &Campaign,
    names: &[String],
) -> Result<Figures, ValidateError> {
    let mut out = Figures::default();
    let mut taken = Vec::new();
    let ext_label = d.extended_label(m, label);
    let name = |i: usize| names.get(i).cloned().unwrap_or_else(|| "data".into());
    let k = &o.dictionary;
    let analyse = |record: &Record, r: &[[f64; 3]]| {
        structure::analyse(m, record, r, k.harmonics, k.poly, k.time)
    };
    let exact = ValidateOptions::new().exact(true);
    let (base, extended) = (estimable(&d.base_fit), estimable(&d.extended_fit));
    for (r, rec) in fitted.records.iter().enumerate() {
        // The fits' own prediction (the minimum-norm solution, so that confounded groups keep
        // their combined effect), on every sample, outliers included.
        let before = validate_record(m, &base, rec, &exact)?.validation;
        let after = validate_record(m, &extended, rec, &exact)?.validation;
        let drop = d
            .records
            .get(r)
            .map_or(Vec::new(), |x| super::outliers::samples(&x.outliers));
        let cleaned = rec.record.without(&drop);
        let components = (
            analyse(&cleaned, &d.base_fit.record_residual(r)),
            analyse(&cleaned, &d.extended_fit.record_residual(r)),
        );
        record_figures(
            m,
            &mut out,
            &mut taken,
            (&name(r), "fitted"),
            &rec.record,
            &measured(&before),
            [&before.prediction, &after.prediction],
            components,
            (label, &ext_label),
        );
    }
    for (h, (rec, v)) in held_out.records.iter().zip(&d.validation).enumerate() {
        let minus = |res: &[[f64; 3]]| -> Vec<[f64; 3]> {
            rec.record
                .measured
                .iter()
                .zip(res)
                .map(|(y, e)| std::array::from_fn(|k| y[k] - e[k]))
                .collect()
        };
        let components = (
            analyse(&rec.record, &v.residual_before),
            analyse(&rec.record, &v.residual_after),
        );
        record_figures(
            m,
            &mut out,
            &mut taken,
            (&name(fitted.records.len() + h), "held out"),
            &rec.record,
            &rec.record.measured,
            [&minus(&v.residual_before), &minus(&v.residual_after)],
            components,
            (label, &ext_label),
        );
    }
    // What remains unexplained, against what it follows (sorted by it).
    for u in &d.unexplained {
        let fitted_at = d.records.iter().position(|r| r.label == u.data);
        let held_at = d.validation.iter().position(|h| h.name == u.data);
        let (residual, data): (Vec<f64>, String) = match (fitted_at, held_at) {
            (Some(r), _) => (
                d.extended_fit
                    .record_residual(r)
                    .iter()
                    .map(|v| v[u.direction])
                    .collect(),
                name(r),
            ),
            (None, Some(h)) => (
                d.validation[h]
                    .residual_after
                    .iter()
                    .map(|v| v[u.direction])
                    .collect(),
                name(fitted.records.len() + h),
            ),
            (None, None) => continue,
        };
        if residual.len() != u.x.len() {
            continue;
        }
        let mut order: Vec<usize> = (0..u.x.len()).collect();
        order.sort_by(|&a, &b| u.x[a].total_cmp(&u.x[b]));
        let dir = ["x", "y", "z"][u.direction];
        let follows = u.follows.clone().unwrap_or_else(|| "sample".into());
        let base = Path::new(&data)
            .file_stem()
            .map_or("data".to_string(), |s| s.to_string_lossy().into_owned());
        let s = stem(&format!("{base}-unexplained-{dir}"), &mut taken);
        out.paths.push(PathFigure {
            file_name: format!("{s}.svg"),
            what: format!("figure: what remains in {dir} on {data}, against {follows}"),
            title: format!("{data}: residual in {dir} of the extended model against {follows}, µm"),
            x_label: if u.unit.is_empty() {
                follows.clone()
            } else {
                format!("{follows} ({})", u.unit)
            },
            x: order.iter().map(|&i| u.x[i]).collect(),
            panels: vec![Panel {
                name: format!("{dir} residual"),
                measured: Series {
                    label: "residual of the extended model".into(),
                    values: order.iter().map(|&i| residual[i] * 1e3).collect(),
                },
                predictions: vec![Series {
                    label: "the shape described".into(),
                    values: order.iter().map(|&i| u.fitted[i] * 1e3).collect(),
                }],
            }],
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::abscissa;
    use model_spec::Machine;
    use simulation::paths::record_from_commands;

    fn seed_ac() -> Machine {
        model_spec::builtin("seed-ac").unwrap().unwrap()
    }

    /// A path of seed-ac (axes X A C Y Z) from per-sample commands (mm, degrees).
    fn path(rows: &[[f64; 5]]) -> simulation::record::Record {
        let commands = rows
            .iter()
            .map(|r| vec![r[0], r[1].to_radians(), r[2].to_radians(), r[3], r[4]])
            .collect();
        record_from_commands(commands, (0..rows.len()).map(|i| i as f64).collect())
    }

    #[test]
    fn a_probes_record_is_drawn_over_its_poses() {
        let rows: Vec<[f64; 5]> = (0..4)
            .map(|i| [10.0 * i as f64, -30.0 * i as f64, 0.0, 0.0, 0.0])
            .collect();
        let mut record = path(&rows);
        record.probe = vec![Vec::new(); rows.len()];
        let (label, x) = abscissa(&seed_ac(), &record);
        assert!(label.starts_with("pose (a touch probe's record"), "{label}");
        assert_eq!(x, [1.0, 2.0, 3.0, 4.0]);
    }

    #[test]
    fn a_turning_table_is_drawn_against_its_angle() {
        let rows: Vec<[f64; 5]> = (0..9)
            .map(|i| {
                let c = 45.0 * i as f64;
                [
                    -217.5 * c.to_radians().cos(),
                    -30.0,
                    c,
                    217.5 * c.to_radians().sin(),
                    0.0,
                ]
            })
            .collect();
        let (label, x) = abscissa(&seed_ac(), &path(&rows));
        assert_eq!(label, "C (deg)");
        assert!((x[8] - 360.0).abs() < 1e-9, "{x:?}");
    }

    #[test]
    fn a_linear_sweep_is_drawn_against_the_linear_axis_in_mm() {
        // C stands still, A dithers back and forth by a degree, X sweeps one way.
        let rows: Vec<[f64; 5]> = (0..5)
            .map(|i| {
                [
                    -100.0 + 50.0 * i as f64,
                    if i % 2 == 0 { 0.0 } else { 1.0 },
                    90.0,
                    0.0,
                    0.0,
                ]
            })
            .collect();
        let (label, x) = abscissa(&seed_ac(), &path(&rows));
        assert_eq!(label, "X (mm)");
        assert_eq!(x, vec![-100.0, -50.0, 0.0, 50.0, 100.0]);
    }

    #[test]
    fn the_larger_share_of_travel_wins_among_axes_that_move_one_way() {
        // A sweeps 60 of its 240 degrees (0.25), Y 100 of its 800 mm (0.125).
        let rows: Vec<[f64; 5]> = (0..4)
            .map(|i| [0.0, -20.0 * i as f64, 0.0, 100.0 / 3.0 * i as f64, 0.0])
            .collect();
        assert_eq!(abscissa(&seed_ac(), &path(&rows)).0, "A (deg)");
        // Y 400 of 800 mm (0.5) now beats A.
        let rows: Vec<[f64; 5]> = (0..4)
            .map(|i| [0.0, -20.0 * i as f64, 0.0, 400.0 / 3.0 * i as f64, 0.0])
            .collect();
        assert_eq!(abscissa(&seed_ac(), &path(&rows)).0, "Y (mm)");
    }

    #[test]
    fn only_a_path_where_nothing_moves_falls_back_and_says_so() {
        let rows = [[10.0, -30.0, 45.0, 0.0, 5.0]; 3];
        let (label, x) = abscissa(&seed_ac(), &path(&rows));
        assert_eq!(label, "sample index (no axis moves on this path)");
        assert_eq!(x, vec![0.0, 1.0, 2.0]);
    }
}
