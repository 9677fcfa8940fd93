//! The report of `rtest bench`: the four measurements run in order, as JSON (serde) and as
//! text for people. Times are medians on this computer, one core; ratios are measured in the
//! same run.

use crate::{FillBandwidth, IdentifyRun, MethodTime};
use serde::Serialize;

/// An identification of a long record (streamed, or in memory).
#[derive(Clone, Debug, Serialize)]
pub struct IdentifyReport {
    /// Samples.
    pub samples: usize,
    /// Generating and identifying, s.
    pub seconds: f64,
    /// Generating the synthetic record alone, s.
    pub data_generation_seconds: f64,
    /// Peak resident memory of the process during this run (reset before it), MB, what the
    /// process held before it included; `null` where the system does not say or cannot reset
    /// the peak (undetermined).
    pub peak_rss_mb: Option<f64>,
    /// Resident memory of the process just before this run, MB; `null` where unknown.
    pub rss_before_mb: Option<f64>,
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
    /// Streaming identification (blocks folded, the record never whole).
    pub streaming_identify: IdentifyReport,
    /// In-memory identification of the same record (the whole record and H).
    pub memory_identify: IdentifyReport,
    /// The in-memory identification's time over the streaming one's (same run).
    pub memory_over_streaming: f64,
    /// The gains at one pose, per method.
    pub gains_per_pose: Vec<MethodReport>,
    /// The H-matrix fills.
    pub h_fill: Vec<FillReport>,
    /// Code generation per built-in machine, ms.
    pub codegen_ms: Vec<(String, f64)>,
}

/// Runs the four measurements (10^6 samples and poses, or 10^5 with `quick`), the
/// identifications first, each with its own peak memory.
pub fn run(quick: bool) -> BenchReport {
    let n = if quick { 100_000 } else { 1_000_000 };
    let streaming = crate::streaming_identify(n);
    let memory = crate::memory_identify(n);
    let methods = crate::gain_methods(quick);
    let fills: Vec<FillBandwidth> = [4096, 65536]
        .iter()
        .map(|&b| crate::fill_bandwidth(n, b, if quick { 2 } else { 3 }))
        .collect();
    let codegen = crate::codegen_times(if quick { 3 } else { 9 });
    BenchReport {
        quick,
        streaming_identify: identify_report(&streaming),
        memory_identify: identify_report(&memory),
        memory_over_streaming: memory.total_seconds / streaming.total_seconds,
        gains_per_pose: methods.iter().map(method_report).collect(),
        h_fill: fills.iter().map(fill_report).collect(),
        codegen_ms: codegen.into_iter().map(|(m, s)| (m, s * 1e3)).collect(),
    }
}

fn identify_report(s: &IdentifyRun) -> IdentifyReport {
    IdentifyReport {
        samples: s.samples,
        seconds: s.total_seconds,
        data_generation_seconds: s.generate_seconds,
        peak_rss_mb: s.peak_rss_bytes.map(|b| b as f64 / 1e6),
        rss_before_mb: s.rss_before_bytes.map(|b| b as f64 / 1e6),
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
    let mut numbers: Vec<(String, f64)> = Vec::new();
    for (name, s) in [
        ("streaming_identify", &r.streaming_identify),
        ("memory_identify", &r.memory_identify),
    ] {
        numbers.push((format!("{name}.seconds"), s.seconds));
        numbers.push((
            format!("{name}.data_generation_seconds"),
            s.data_generation_seconds,
        ));
        numbers.push((format!("{name}.worst_z"), s.worst_z));
        numbers.extend(s.peak_rss_mb.map(|x| (format!("{name}.peak_rss_mb"), x)));
        numbers.extend(
            s.rss_before_mb
                .map(|x| (format!("{name}.rss_before_mb"), x)),
        );
    }
    numbers.push(("memory_over_streaming".into(), r.memory_over_streaming));
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
        "\nIdentification of the reduced model (11 parameters) from {} synthetic samples; peak memory of each run, the process's before it included:\n",
        s.samples
    ));
    out.push_str(&format!(
        "  {:<30} {:>8} {:>12} {:>12} {:>12} {:>8}\n",
        "run", "s", "generating", "peak memory", "before", "worst z"
    ));
    let mb = |x: Option<f64>| x.map_or("unknown".into(), |mb| format!("{mb:.0} MB"));
    for (label, s) in [
        ("streamed (blocks of 4096)", &r.streaming_identify),
        ("in memory (whole record, H)", &r.memory_identify),
    ] {
        out.push_str(&format!(
            "  {label:<30} {:>8.2} {:>10.2} s {:>12} {:>12} {:>8.1}\n",
            s.seconds,
            s.data_generation_seconds,
            mb(s.peak_rss_mb),
            mb(s.rss_before_mb),
            s.worst_z
        ));
    }
    out.push_str(&format!(
        "  in memory / streamed: {:.2} (times include generating the record; worst z: largest estimate error in standard uncertainties)\n",
        r.memory_over_streaming
    ));
    out.push_str("\nCode generation (every model, Rust source):\n");
    for (m, ms) in &r.codegen_ms {
        out.push_str(&format!("  {m:<16} {ms:.2} ms\n"));
    }
    out
}
