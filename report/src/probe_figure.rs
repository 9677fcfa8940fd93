//! The figure of a touch probe's record: per pose (one sphere fit, one reading of the error
//! vector) the measured reading in x, y, z of the tool frame with its ±1σ bar, the identified
//! model's prediction and the residual, µm (`docs/report.md`, section 4).
//!
//! The numbers drawn are also on the `<figure>` as `data-*` attributes, for programs: `poses`
//! (how many), `abscissa` (each pose's abscissa, comma-separated), and `measured-um`,
//! `sigma-um`, `predicted-um`, `residual-um` (per pose `x,y,z`, poses separated by `;`, each
//! number the shortest decimal that reads back to the value drawn; `sigma-um` empty when the
//! record carries no uncertainty).

use crate::figures::figure_id;
use crate::inputs::Figure;
use model_spec::units::UM_PER_MM;
use plots::{PlotError, PoseFigure, PosePanel};

/// Rotary positions closer than this are one position, degrees (1 µdeg).
const SAME_DEG: f64 = 1e-6;

/// What a probe record's figure is made of.
#[derive(Clone, Debug)]
pub struct ProbePoses<'a> {
    /// The record's name (its file, as the report gives it).
    pub name: &'a str,
    /// Its role in the check (`fitted`, `validation`).
    pub role: &'a str,
    /// The label of the identified model (`reduced`).
    pub model: &'a str,
    /// Each rotary axis of the machine: its name and its position at each pose, degrees.
    pub rotary: Vec<(String, Vec<f64>)>,
    /// The measured reading per pose, mm (tool frame).
    pub measured_mm: &'a [[f64; 3]],
    /// The reading's covariance per pose, mm² (tool frame); empty when the record has none.
    pub covariance: &'a [[[f64; 3]; 3]],
    /// The identified model's prediction per pose, mm (tool frame).
    pub prediction_mm: &'a [[f64; 3]],
}

/// A number as the shortest decimal that reads back to it.
fn shortest(v: f64) -> String {
    format!("{v}")
}

/// An angle for a pose label: at most six decimals, trailing zeros dropped, a typographic
/// minus (`−30`, `12.5`).
fn degrees(v: f64) -> String {
    let v = if v.abs() < SAME_DEG / 2.0 { 0.0 } else { v };
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    s.replace('-', "\u{2212}")
}

/// `a,b,c;d,e,f`: per pose its three values.
fn triples(rows: &[[f64; 3]]) -> String {
    rows.iter()
        .map(|r| r.iter().map(|v| shortest(*v)).collect::<Vec<_>>().join(","))
        .collect::<Vec<_>>()
        .join(";")
}

/// The abscissa: the swept rotary axis's angle (degrees) when only one rotary axis moves over
/// the poses, else the pose's number (1, 2, …) with a label of every rotary axis's position;
/// with the abscissa's name and, for the swept angle, the other axes' positions for the caption.
fn abscissa(p: &ProbePoses<'_>, n: usize) -> (String, Vec<f64>, Vec<Vec<String>>, String) {
    let moving: Vec<&(String, Vec<f64>)> = p
        .rotary
        .iter()
        .filter(|(_, q)| {
            let lo = q.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = q.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            hi - lo > SAME_DEG
        })
        .collect();
    if let [(axis, q)] = moving.as_slice() {
        let held: Vec<String> = p
            .rotary
            .iter()
            .filter(|(a, _)| a != axis)
            .map(|(a, q)| format!("{a} at {}°", degrees(q.first().copied().unwrap_or(0.0))))
            .collect();
        let held = if held.is_empty() {
            String::new()
        } else {
            format!(" ({})", held.join(", "))
        };
        return (format!("{axis} (deg)"), q.clone(), Vec::new(), held);
    }
    let names: Vec<&str> = p.rotary.iter().map(|(a, _)| a.as_str()).collect();
    let ticks = (0..n)
        .map(|i| {
            p.rotary
                .iter()
                .map(|(a, q)| format!("{a} {}", degrees(q[i])))
                .collect()
        })
        .collect();
    let label = if names.is_empty() {
        "pose".to_string()
    } else {
        format!("pose ({} in deg)", names.join(", "))
    };
    (
        label,
        (1..=n).map(|i| i as f64).collect(),
        ticks,
        String::new(),
    )
}

/// A unique HTML id for `name`'s figure among `taken` (`low.csv` → `fig-low-poses`, then
/// `fig-low-poses-2`).
fn unique_id(name: &str, taken: &mut Vec<String>) -> String {
    let stem = crate::figures::record_name(name);
    let base = figure_id(&format!("{stem}-poses"));
    let mut id = base.clone();
    let mut k = 2;
    while taken.contains(&id) {
        id = format!("{base}-{k}");
        k += 1;
    }
    taken.push(id.clone());
    id
}

/// The figure of a probe record (module documentation); `taken` holds the ids already used.
///
/// # Errors
/// A series `plots` refuses (no pose, a non-finite number, lengths that differ).
pub fn probe_figure(p: &ProbePoses<'_>, taken: &mut Vec<String>) -> Result<Figure, PlotError> {
    let n = p.measured_mm.len();
    if p.prediction_mm.len() != n {
        return Err(PlotError::LengthMismatch {
            series: "predicted".into(),
            expected: n,
            found: p.prediction_mm.len(),
        });
    }
    let um = |rows: &[[f64; 3]]| -> Vec<[f64; 3]> {
        rows.iter()
            .map(|r| [r[0] * UM_PER_MM, r[1] * UM_PER_MM, r[2] * UM_PER_MM])
            .collect()
    };
    let measured = um(p.measured_mm);
    let predicted = um(p.prediction_mm);
    let residual: Vec<[f64; 3]> = measured
        .iter()
        .zip(&predicted)
        .map(|(m, q)| [m[0] - q[0], m[1] - q[1], m[2] - q[2]])
        .collect();
    let sigma: Vec<[f64; 3]> = p
        .covariance
        .iter()
        .map(|c| std::array::from_fn(|d| c[d][d].max(0.0).sqrt() * UM_PER_MM))
        .collect();
    let panels: Vec<PosePanel> = (0..3)
        .map(|d| PosePanel {
            name: ["x", "y", "z"][d].into(),
            measured: measured.iter().map(|r| r[d]).collect(),
            std: sigma.iter().map(|r| r[d]).collect(),
            predicted: predicted.iter().map(|r| r[d]).collect(),
        })
        .collect();
    let (x_label, x, ticks, held) = abscissa(p, n);
    let title = format!(
        "{} ({}): probe readings per pose and the prediction, µm",
        p.name, p.role
    );
    let predicted_label = format!("identified model ({})", p.model);
    let svg = plots::probe_poses(&PoseFigure {
        title: &title,
        x_label: &x_label,
        x: &x,
        ticks: &ticks,
        predicted_label: &predicted_label,
        panels: &panels,
    })?;
    let bars = if sigma.is_empty() {
        "without a bar: the record gives no uncertainty of its own (sphere centres without u_cx, u_cy, u_cz)"
            .to_string()
    } else {
        "with a bar of ±1σ, the sphere fit's centre uncertainty mapped to the tool frame (the square root of the diagonal of the reading's covariance)".to_string()
    };
    let caption = format!(
        "{} ({}): the touch probe's reading at each of its {n} poses, in x, y and z of the tool frame, µm: the sphere fit's centre offset from the nominal centre, e = −R_tool0ᵀ·(fitted − nominal centre). Dots: the measured reading, {bars}; open diamonds: the prediction of the identified model ({}), the exact virtual machine at the identified values at the pose's commands; squares: the residual, measured minus predicted; above each panel the residual's RMS. Abscissa: {x_label}{held}{}.",
        p.name,
        p.role,
        p.model,
        if ticks.is_empty() {
            ""
        } else {
            ", each pose labelled with the rotary axes' positions"
        }
    );
    let data = vec![
        ("record".to_string(), p.name.to_string()),
        ("poses".to_string(), n.to_string()),
        (
            "abscissa".to_string(),
            x.iter().map(|v| shortest(*v)).collect::<Vec<_>>().join(","),
        ),
        ("measured-um".to_string(), triples(&measured)),
        ("sigma-um".to_string(), triples(&sigma)),
        ("predicted-um".to_string(), triples(&predicted)),
        ("residual-um".to_string(), triples(&residual)),
    ];
    Ok(Figure {
        id: unique_id(p.name, taken),
        svg,
        caption,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Readings, covariances and predictions per pose, mm and mm².
    type Poses = (Vec<[f64; 3]>, Vec<[[f64; 3]; 3]>, Vec<[f64; 3]>);

    fn poses(rotary: Vec<(String, Vec<f64>)>) -> Poses {
        let n = rotary[0].1.len();
        let measured = (0..n).map(|i| [1e-3 * i as f64, -2e-3, 0.5e-3]).collect();
        let cov = (0..n)
            .map(|_| [[0.25e-6, 0.0, 0.0], [0.0, 1e-6, 0.0], [0.0, 0.0, 4e-6]])
            .collect();
        let predicted = (0..n)
            .map(|i| [1e-3 * i as f64 + 1e-4, -2e-3, 0.5e-3])
            .collect();
        (measured, cov, predicted)
    }

    #[test]
    fn a_swept_axis_is_the_abscissa_and_the_numbers_are_on_the_figure() {
        let rotary = vec![
            ("A".to_string(), vec![0.0; 4]),
            ("C".to_string(), vec![0.0, 60.0, 120.0, 180.0]),
        ];
        let (m, c, q) = poses(rotary.clone());
        let p = ProbePoses {
            name: "runs/low.csv",
            role: "fitted",
            model: "reduced",
            rotary,
            measured_mm: &m,
            covariance: &c,
            prediction_mm: &q,
        };
        let mut taken = Vec::new();
        let f = probe_figure(&p, &mut taken).unwrap();
        assert_eq!(f.id, "fig-low-poses");
        assert!(
            f.caption.contains("Abscissa: C (deg) (A at 0°)."),
            "{}",
            f.caption
        );
        let get = |k: &str| f.data.iter().find(|(n, _)| n == k).unwrap().1.clone();
        assert_eq!(get("poses"), "4");
        assert_eq!(get("abscissa"), "0,60,120,180");
        assert_eq!(get("sigma-um").split(';').next(), Some("0.5,1,2"));
        let predicted: Vec<f64> = get("predicted-um")
            .split([';', ','])
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(predicted.len(), 12);
        assert_eq!(predicted[3], q[1][0] * UM_PER_MM);
        // A second figure of the same record has its own id.
        assert_eq!(probe_figure(&p, &mut taken).unwrap().id, "fig-low-poses-2");
    }

    #[test]
    fn two_moving_axes_give_numbered_poses_labelled_with_their_positions() {
        let rotary = vec![
            ("A".to_string(), vec![0.0, -30.0, 0.0]),
            ("C".to_string(), vec![0.0, 0.0, 90.000_000_000_1]),
        ];
        let (m, _, q) = poses(rotary.clone());
        let p = ProbePoses {
            name: "p.csv",
            role: "validation",
            model: "reduced",
            rotary,
            measured_mm: &m,
            covariance: &[],
            prediction_mm: &q,
        };
        let f = probe_figure(&p, &mut Vec::new()).unwrap();
        assert!(
            f.caption
                .contains("Abscissa: pose (A, C in deg), each pose labelled")
        );
        assert!(f.caption.contains("without a bar"));
        assert!(
            f.svg.contains("A −30") && f.svg.contains("C 90\n"),
            "{}",
            f.svg
        );
        let get = |k: &str| f.data.iter().find(|(n, _)| n == k).unwrap().1.clone();
        assert_eq!(get("abscissa"), "1,2,3");
        assert_eq!(get("sigma-um"), "");
    }
}
