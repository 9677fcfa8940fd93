//! Which hits of a pattern a probe can make at a pose: the stylus comes from the spindle, so a
//! hit below the sphere's equator seen along the tool axis would put the stylus's shank into
//! the sphere; and the sphere stands on a stem along the table normal, which no hit may come
//! near. The rules the probing programs follow and the probe plans skip poses by.

use nalgebra::Vector3;

/// The least angle between a hit's point (seen from the sphere's centre) and the sphere's stem
/// (the table normal reversed), degrees, by default.
pub const STEM_CLEARANCE_DEG: f64 = 30.0;

/// Why the hit whose point is `point` (from the sphere's centre, bed frame; any length) cannot
/// be probed with the tool axis `tool_axis` (unit, bed frame: from the tip towards the spindle)
/// over a sphere on a stem along `-table_normal` (the table normal unit, bed frame), at least
/// `stem_clearance_deg` from the stem; `None` when it can. Both rules:
/// [`below_equator`] and [`near_stem`].
pub fn unreachable(
    point: &Vector3<f64>,
    tool_axis: &Vector3<f64>,
    table_normal: &Vector3<f64>,
    stem_clearance_deg: f64,
) -> Option<String> {
    below_equator(point, tool_axis).or_else(|| near_stem(point, table_normal, stem_clearance_deg))
}

/// `(x, y, z)` of a vector for messages.
fn short(v: &Vector3<f64>) -> String {
    let s = |x: f64| model_spec::units::short(if x == 0.0 { 0.0 } else { x });
    format!("({}, {}, {})", s(v.x), s(v.y), s(v.z))
}

/// Why the hit at `point` lies below the sphere's equator seen along `tool_axis` (the stylus,
/// coming from the spindle, would meet the sphere); `None` when it does not.
pub fn below_equator(point: &Vector3<f64>, tool_axis: &Vector3<f64>) -> Option<String> {
    (point.dot(tool_axis) < -1e-9 * point.norm()).then(|| {
        format!(
            "the hit at {} from the centre (bed frame) lies below the sphere's equator seen along the tool axis {}: the stylus would meet the sphere",
            short(point),
            short(tool_axis)
        )
    })
}

/// Why the hit at `point` comes nearer than `stem_clearance_deg` to the sphere's stem (along
/// `-table_normal`); `None` when it does not.
pub fn near_stem(
    point: &Vector3<f64>,
    table_normal: &Vector3<f64>,
    stem_clearance_deg: f64,
) -> Option<String> {
    let stem = -table_normal;
    let from_stem = point.angle(&stem).to_degrees();
    (from_stem < stem_clearance_deg).then(|| {
        format!(
            "the hit at {} from the centre (bed frame) is {}° from the sphere's stem (the table normal reversed: {}), nearer than the {}° allowed",
            short(point),
            model_spec::units::short((from_stem * 1e6).round() / 1e6),
            short(&stem),
            model_spec::units::short(stem_clearance_deg)
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_equator_and_the_stem_bound_what_a_probe_reaches() {
        let up = Vector3::z();
        // Upright: every hit of the upper half, none below the equator.
        assert!(unreachable(&Vector3::x(), &up, &up, 30.0).is_none());
        assert!(unreachable(&Vector3::new(0.0, 1.0, 1.0), &up, &up, 30.0).is_none());
        let below = unreachable(&Vector3::new(1.0, 0.0, -0.1), &up, &up, 30.0).unwrap();
        assert!(below.contains("below the sphere's equator"), "{below}");
        // A table tilted 90° about y: its normal along x, the stem along −x.
        let normal = Vector3::x();
        let e = unreachable(&-Vector3::x(), &up, &normal, 30.0).unwrap();
        assert!(e.contains("0° from the sphere's stem"), "{e}");
        assert!(unreachable(&Vector3::x(), &up, &normal, 30.0).is_none());
    }
}
