//! A sphere centres file (centres another device fitted, one per pose) turned into a record.

use super::hits::ProbeSettings;
use super::pose::pose_frame;
use crate::sphere::RADIUS_LIMIT_MM;
use formats::csv::CsvError;
use formats::probe::SphereCentres;
use model_spec::Machine;
use nalgebra::{Matrix3, Vector3};
use simulation::exact::VirtualMachine;
use simulation::record::{Record, Sample};

/// Reads `centres` (from `file`) on machine `m` at kinematic parameters `params` (mm): per
/// pose, the centre (machine coordinates: the linear axes' positions that put the tip centre
/// on the sphere's centre) through the nominal chains into the bed frame, `c`, and the reading
/// `e = −R_tool0ᵀ·c` (tool frame, mm). With the files' uncertainties `u_cx,u_cy,u_cz` (taken
/// as independent, per machine coordinate) every reading gets its covariance; without them the
/// record has none (the kinematics fit then estimates one σ from its residuals). A given radius
/// more than [`RADIUS_LIMIT_MM`] from the calibrated one refuses the pose, as for hits; the
/// pose's linear commands must put the nominal tip centre within `settings.off_sphere_mm` of the
/// nominal sphere centre (they are the pose's nominal commands).
///
/// # Errors
/// [`CsvError::Format`] naming `file`, the pose's line and why.
pub fn centre_record(
    file: &str,
    m: &Machine,
    params: &[f64],
    centres: &SphereCentres,
    settings: &ProbeSettings,
) -> Result<Record, CsvError> {
    let at = |line: usize, label: &str, message: String| CsvError::Format {
        file: file.to_string(),
        line,
        column: None,
        message: format!("pose `{label}`: {message}"),
    };
    let vm = VirtualMachine::new(m);
    let mut record = Record::default();
    for p in &centres.poses {
        let bad = |message: String| at(p.line, &p.label, message);
        let geometry = pose_frame(&vm, &p.axes, params).map_err(|e| bad(e.to_string()))?;
        let commanded = geometry.gap(&vm, &p.axes, params).norm();
        if commanded > settings.off_sphere_mm {
            return Err(bad(format!(
                "its commands put the nominal tip centre {commanded:.3} mm from the nominal sphere centre (limit {} mm): give the pose's nominal commands, at the record's kinematic parameters",
                settings.off_sphere_mm
            )));
        }
        if let Some(r) = p.radius_mm
            && (r - settings.sphere_radius_mm).abs() > RADIUS_LIMIT_MM
        {
            return Err(bad(format!(
                "fitted radius {r} mm is {:.3} µm from the calibrated {} mm (limit {:.3} µm): a dirty hit, a wrong tip or sphere radius",
                (r - settings.sphere_radius_mm) * 1e3,
                settings.sphere_radius_mm,
                RADIUS_LIMIT_MM * 1e3
            )));
        }
        let mut at_centre = p.axes.clone();
        let linear: Vec<usize> = m.linear_axes().collect();
        for (k, &i) in linear.iter().enumerate() {
            at_centre[i] = p.centre[k];
        }
        let c = geometry.gap(&vm, &at_centre, params);
        let e = -geometry.to_tool(&c);
        if let Some(why) = super::hits::reading_beyond("centre", [e.x, e.y, e.z], settings) {
            return Err(bad(why));
        }
        if let Some(u) = p.uncertainty_mm {
            // The linear map from machine coordinates to the bed frame.
            let a = geometry.linear_map;
            let d = Matrix3::from_diagonal(&Vector3::new(u[0] * u[0], u[1] * u[1], u[2] * u[2]));
            let r = geometry.tool_rotation.matrix();
            let cov = r.transpose() * a * d * a.transpose() * r;
            record.covariance.push(std::array::from_fn(|i| {
                std::array::from_fn(|j| cov[(i, j)])
            }));
        }
        record.samples.push(Sample {
            commands: geometry.commands,
            t: record.samples.len() as f64,
            motion: vec![1; m.axes.len()],
            timed: false,
        });
        record.measured.push([e.x, e.y, e.z]);
        record.lines.push(p.line);
    }
    super::hits::set_rotary_motion(m, &mut record);
    Ok(record)
}
