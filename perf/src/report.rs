//! The report of `rtest bench`: the four measurements run in order, as JSON (serde) and as
//! text for people. Times are medians on this computer, one core; ratios are measured in the
//! same run.

use crate::{FillBandwidth, MethodTime, StreamingRun};
use serde::Serialize;

/// Streaming identification of a long record.
#[derive(Clone, Debug, Serialize)]
pub struct StreamingReport {
    /// Samples.
    pub samples: usize,
    /// Generating and identifying, s.
    pub seconds: f64,
    /// Generating the synthetic record alone, s.
    pub data_generation_seconds: f64,
    /// Peak resident memory, MB; `null` where the system does not say (undetermined).
    pub peak_rss_mb: Option<f64>,
    /// Largest estimate error against the values used, in standard uncertainties.
    pub worst_z: f64,
}

/// One method of computing the gains.
#[derive(Clone, Debug, Serialize)]
pub struct MethodReport {
    /// What it is.
    pub method: String,
    /// Median time per pose, ns.
    pub ns: f64,
    /// Its time over the generated code's.
    pub ratio_to_generated: f64,
}

/// One H-matrix fill.
#[derive(Clone, Debug, Serialize)]
pub struct FillReport {
    /// Poses filled.
    pub poses: usize,
    /// Poses per block.
    pub block_poses: usize,
    /// Fill bandwidth, GB/s.
    pub fill_gb_per_s: f64,
    /// Plain write of the same bytes, GB/s.
    pub plain_write_gb_per_s: f64,
    /// Fill bandwidth over plain-write bandwidth.
    pub fraction: f64,
}

/// The whole report.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Whether the quick sizes were used.
    pub quick: bool,
    /// Streaming identification.
    pub streaming_identify: StreamingReport,
    /// The gains at one pose, per method.
    pub gains_per_pose: Vec<MethodReport>,
    /// The H-matrix fills.
    pub h_fill: Vec<FillReport>,
    /// Code generation per built-in machine, ms.
    pub codegen_ms: Vec<(String, f64)>,
}

/// Runs the four measurements (10^6 samples and poses, or 10^5 with `quick`), streaming first
/// so that the peak memory is its own.
pub fn run(quick: bool) -> BenchReport {
    let n = if quick { 100_000 } else { 1_000_000 };
    let streaming = crate::streaming_identify(n);
    let methods = crate::gain_methods(quick);
    let fills: Vec<FillBandwidth> = [4096, 65536]
        .iter()
        .map(|&b| crate::fill_bandwidth(n, b, if quick { 2 } else { 3 }))
        .collect();
    let codegen = crate::codegen_times(if quick { 3 } else { 9 });
    BenchReport {
        quick,
        streaming_identify: streaming_report(&streaming),
        gains_per_pose: methods.iter().map(method_report).collect(),
        h_fill: fills.iter().map(fill_report).collect(),
        codegen_ms: codegen.into_iter().map(|(m, s)| (m, s * 1e3)).collect(),
    }
}

fn streaming_report(s: &StreamingRun) -> StreamingReport {
    StreamingReport {
        samples: s.samples,
        seconds: s.total_seconds,
        data_generation_seconds: s.generate_seconds,
        peak_rss_mb: s.peak_rss_bytes.map(|b| b as f64 / 1e6),
        worst_z: s.worst_z,
    }
}

fn method_report(m: &MethodTime) -> MethodReport {
    MethodReport {
        method: m.method.into(),
        ns: m.ns_per_pose,
        ratio_to_generated: m.ratio_to_generated,
    }
}

fn fill_report(f: &FillBandwidth) -> FillReport {
    FillReport {
        poses: f.poses,
        block_poses: f.block,
        fill_gb_per_s: f.bytes / f.fill_seconds / 1e9,
        plain_write_gb_per_s: f.bytes / f.write_seconds / 1e9,
        fraction: f.fraction(),
    }
}

/// The first number of the report that is not finite (a failed measurement: a zero time, an
/// empty run), named by its place; `None` when every number is finite.
pub fn non_finite(r: &BenchReport) -> Option<String> {
    let s = &r.streaming_identify;
    let mut numbers: Vec<(String, f64)> = vec![
        ("streaming_identify.seconds".into(), s.seconds),
        (
            "streaming_identify.data_generation_seconds".into(),
            s.data_generation_seconds,
        ),
        ("streaming_identify.worst_z".into(), s.worst_z),
    ];
    numbers.extend(
        s.peak_rss_mb
            .map(|x| ("streaming_identify.peak_rss_mb".into(), x)),
    );
    for m in &r.gains_per_pose {
        numbers.push((format!("gains_per_pose[{}].ns", m.method), m.ns));
        numbers.push((
            format!("gains_per_pose[{}].ratio_to_generated", m.method),
            m.ratio_to_generated,
        ));
    }
    for (i, f) in r.h_fill.iter().enumerate() {
        numbers.push((format!("h_fill[{i}].fill_gb_per_s"), f.fill_gb_per_s));
        numbers.push((
            format!("h_fill[{i}].plain_write_gb_per_s"),
            f.plain_write_gb_per_s,
        ));
        numbers.push((format!("h_fill[{i}].fraction"), f.fraction));
    }
    for (m, ms) in &r.codegen_ms {
        numbers.push((format!("codegen_ms[{m}]"), *ms));
    }
    numbers
        .into_iter()
        .find(|(_, x)| !x.is_finite())
        .map(|(name, x)| format!("`{name}` is {x}"))
}

/// The report for people.
pub fn text(r: &BenchReport) -> String {
    let mut out = format!(
        "rtest bench{}: medians on this computer, one core\n\n",
        if r.quick { " --quick" } else { "" }
    );
    out.push_str(
        "Gains of seed-ac, full model (44 errors x 6), per pose, sines and cosines included:\n",
    );
    out.push_str(&format!(
        "  {:<40} {:>12} {:>12}\n",
        "method", "ns/pose", "x generated"
    ));
    for m in &r.gains_per_pose {
        out.push_str(&format!(
            "  {:<40} {:>12.1} {:>12.1}\n",
            m.method, m.ns, m.ratio_to_generated
        ));
    }
    let poses = r.h_fill.first().map_or(0, |f| f.poses);
    out.push_str(&format!(
        "\nH matrix of the full model, {poses} poses (3 x 44 per pose, {:.0} MB in all):\n",
        poses as f64 * 3.0 * 44.0 * 8.0 / 1e6
    ));
    out.push_str(&format!(
        "  {:<34} {:>14} {:>18} {:>10}\n",
        "block", "fill GB/s", "plain write GB/s", "fraction"
    ));
    for f in &r.h_fill {
        let label = format!(
            "{} poses ({:.1} MB)",
            f.block_poses,
            (f.block_poses * 3 * 44 * 8) as f64 / 1e6
        );
        out.push_str(&format!(
            "  {label:<34} {:>14.2} {:>18.2} {:>9.0}%\n",
            f.fill_gb_per_s,
            f.plain_write_gb_per_s,
            100.0 * f.fraction
        ));
    }
    let s = &r.streaming_identify;
    out.push_str(&format!(
        "\nStreaming identification, reduced model, {} samples: {:.2} s ({:.2} s of it generating the synthetic record), peak memory {}; worst estimate {:.1} std from the values used\n",
        s.samples,
        s.seconds,
        s.data_generation_seconds,
        s.peak_rss_mb
            .map_or("unknown".into(), |mb| format!("{mb:.0} MB")),
        s.worst_z
    ));
    out.push_str("\nCode generation (every model, Rust source):\n");
    for (m, ms) in &r.codegen_ms {
        out.push_str(&format!("  {m:<16} {ms:.2} ms\n"));
    }
    out
}
