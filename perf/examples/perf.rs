//! Prints the in-process performance comparisons (the same as `rtest bench`).
fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    for r in perf::gain_methods(quick) {
        println!(
            "{:40} {:10.1} ns/pose  x{:.1}",
            r.method, r.ns_per_pose, r.ratio_to_generated
        );
    }
    let poses = if quick { 100_000 } else { 1_000_000 };
    for block in [4096, 65536] {
        let f = perf::fill_bandwidth(poses, block, 3);
        println!(
            "fill {} poses, block {block} ({:.1} MB): {:.3} s ({:.2} GB/s), plain write {:.3} s ({:.2} GB/s): {:.0} %",
            f.poses,
            (block * 3 * 44 * 8) as f64 / 1e6,
            f.fill_seconds,
            f.bytes / f.fill_seconds / 1e9,
            f.write_seconds,
            f.bytes / f.write_seconds / 1e9,
            100.0 * f.fraction()
        );
    }
    let s = perf::streaming_identify(poses);
    println!(
        "streaming {} samples: generate {:.3} s, generate+identify {:.3} s, peak RSS {:.1} MB, worst z {:.2}",
        s.samples,
        s.generate_seconds,
        s.total_seconds,
        s.peak_rss_bytes.unwrap_or(0) as f64 / 1e6,
        s.worst_z
    );
    for (m, t) in perf::codegen_times(5) {
        println!("codegen {m}: {:.2} ms", t * 1e3);
    }
}
