//! The volumetric grid: the predicted tool-end error at every point of a regular grid over the
//! measured ranges, as a CSV for a controller's volumetric compensation table.
//!
//! ```text
//! # rtest volumetric grid: ...
//! X_mm,Y_mm,Z_mm,dx_um,dy_um,dz_um
//! -400,-300,-300,-3.2164,12.004,-1.5
//! ```
//!
//! - **What a row holds:** the grid point (commands, mm) and the predicted error `du` there
//!   (µm): the actual tool point minus the nominal one, along +x, +y, +z; the same sign as every
//!   error vector rtest writes (`dx_um` of the measurement CSV). Absolute per point (not a
//!   difference to the previous point), zero at the reference point.
//! - **What a controller does with it:** it moves the axes by `−du`. A controller that adds a
//!   table value to the command needs the negated values. `−du(u)` at the commanded point is
//!   the first-order correction; the corrected command `u_c = u − du(u_c)`
//!   ([`crate::volumetric::correct`]) differs from it by the slope of `du` times
//!   `du`, which docs/volumetric.md measures.
//! - **Order:** the first axis column varies slowest, the last fastest.
//! - **Numbers:** the shortest decimal that reads back to the same value (µm moved from mm in
//!   the decimal text).

use super::VolumetricError;
use super::laser::column_axes;
use super::model::VolumetricModel;
use model_spec::units::{compact, format_scaled};
use model_spec::{AxisId, Machine};
use nalgebra::Vector3;

/// The most points a grid may have (some 60 MB of CSV).
pub const MAX_GRID_POINTS: usize = 1_000_000;

/// A grid: the positions of each axis and the predicted error at every point.
#[derive(Clone, Debug, PartialEq)]
pub struct GridSpec {
    /// The pitch, mm.
    pub pitch_mm: f64,
    /// The axes in column order ([`column_axes`]) and their positions, mm.
    pub axes: Vec<(AxisId, Vec<f64>)>,
}

impl GridSpec {
    /// The grid of `model` at `pitch_mm` over each axis's measured range, from its first
    /// measured position.
    ///
    /// # Errors
    /// [`VolumetricError::Setup`] when the pitch is not a finite positive number, does not
    /// divide a measured range (to 1e-6 mm), or gives more than [`MAX_GRID_POINTS`] points.
    pub fn new(
        m: &Machine,
        model: &VolumetricModel,
        pitch_mm: f64,
    ) -> Result<GridSpec, VolumetricError> {
        if !(pitch_mm.is_finite() && pitch_mm > 0.0) {
            return Err(VolumetricError::Setup(format!(
                "the grid pitch must be a positive number of mm, not {}",
                compact(pitch_mm)
            )));
        }
        let mut axes = Vec::new();
        let mut total: f64 = 1.0;
        for a in column_axes(m) {
            let Some([lo, hi]) = model.measured_range(a) else {
                continue;
            };
            let steps = (hi - lo) / pitch_mm;
            let n = steps.round();
            if (steps - n).abs() * pitch_mm > 1e-6 || n < 1.0 {
                return Err(VolumetricError::Setup(format!(
                    "the grid pitch {} mm does not divide the measured range of {}, {} .. {} mm ({} mm long): choose a pitch that divides every measured range",
                    compact(pitch_mm),
                    m.axes[a].name,
                    compact(lo),
                    compact(hi),
                    compact(hi - lo)
                )));
            }
            total *= n + 1.0;
            if total > MAX_GRID_POINTS as f64 {
                return Err(VolumetricError::Setup(format!(
                    "a grid at a pitch of {} mm has more than {MAX_GRID_POINTS} points: choose a larger pitch",
                    compact(pitch_mm)
                )));
            }
            let n = n as usize;
            // Positions to the nanometre, the last one the end of the range exactly.
            let positions = (0..=n)
                .map(|i| {
                    if i == n {
                        hi
                    } else {
                        ((lo + i as f64 * pitch_mm) * 1e6).round() / 1e6
                    }
                })
                .map(|q| q.clamp(lo, hi))
                .collect();
            axes.push((a, positions));
        }
        Ok(GridSpec { pitch_mm, axes })
    }

    /// A lattice of `points` (at least 2) evenly spaced positions per axis over each measured
    /// range (no common pitch: [`GridSpec::pitch_mm`] is NaN).
    pub fn lattice(m: &Machine, model: &VolumetricModel, points: usize) -> GridSpec {
        let n = points.max(2);
        let axes = column_axes(m)
            .into_iter()
            .filter_map(|a| {
                let [lo, hi] = model.measured_range(a)?;
                let q = (0..n)
                    .map(|i| {
                        if i + 1 == n {
                            hi
                        } else {
                            lo + (hi - lo) * i as f64 / (n - 1) as f64
                        }
                    })
                    .collect();
                Some((a, q))
            })
            .collect();
        GridSpec {
            pitch_mm: f64::NAN,
            axes,
        }
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.axes.iter().map(|(_, p)| p.len()).product()
    }

    /// `true` when the grid has no point (never, for a grid built by [`GridSpec::new`]).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every point as a pose ([`Machine::axes`] order, `axes` commands), the first axis
    /// slowest.
    pub fn poses(&self, axes: usize) -> Vec<Vec<f64>> {
        let mut out = vec![vec![0.0; axes]];
        for (a, positions) in &self.axes {
            let mut next = Vec::with_capacity(out.len() * positions.len());
            for pose in &out {
                for &q in positions {
                    let mut p = pose.clone();
                    p[*a] = q;
                    next.push(p);
                }
            }
            out = next;
        }
        out
    }
}

/// The grid CSV of `grid` on machine `m` with the predicted errors `du` (one per pose of
/// [`GridSpec::poses`], mm): `comments` as `# ` lines, the header, one row per point.
pub fn format_grid(
    m: &Machine,
    grid: &GridSpec,
    du: &[Vector3<f64>],
    comments: &[String],
) -> String {
    let poses = grid.poses(m.axes.len());
    debug_assert_eq!(poses.len(), du.len());
    let mut out = formats::csv::comment_lines(comments);
    out.reserve(64 * poses.len());
    let mut header: Vec<String> = grid
        .axes
        .iter()
        .map(|(a, _)| format!("{}_mm", m.axes[*a].name))
        .collect();
    header.extend(["dx_um", "dy_um", "dz_um"].map(String::from));
    out += &header.join(",");
    out.push('\n');
    for (pose, d) in poses.iter().zip(du) {
        let mut fields: Vec<String> = grid
            .axes
            .iter()
            .map(|(a, _)| format_scaled(pose[*a], 0))
            .collect();
        fields.extend(d.iter().map(|&v| format_scaled(v, 3)));
        out += &fields.join(",");
        out.push('\n');
    }
    out
}
