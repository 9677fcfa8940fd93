//! `rtest identify --stream`: the same estimates as the in-memory first-order fit, from a file
//! read in blocks.

use crate::common::{self, run};
use serde_json::Value;

fn dir(name: &str) -> common::TempDir {
    common::temp_dir_tagged("stream", name)
}

#[test]
fn streaming_identify_equals_the_in_memory_fit() {
    let d = dir("equal");
    let o = run(
        Some(&d),
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K4",
            "--truth",
            "seed-ac-demo",
            "--zeroed",
            "-o",
            "k4.csv",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let terms = "ECC@harmonic:2,dz0@time:1";
    let common = [
        "identify",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--terms",
        terms,
        "--data",
        "k4.csv",
        "--zeroed",
    ];
    let a = run(
        Some(&d),
        // Ordinary least squares, as --stream fits.
        &[
            &common[..],
            &["--first-order", "--noise", "white", "--json", "a.json"],
        ]
        .concat(),
    );
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let b = run(
        Some(&d),
        &[
            &common[..],
            &["--stream", "--block", "17", "--json", "b.json"],
        ]
        .concat(),
    );
    assert!(b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    let text = String::from_utf8_lossy(&b.stdout);
    assert!(text.contains("blocks of up to 17 samples"), "{text}");
    assert!(
        text.contains("dx0 swallows XOC"),
        "the identifiability analysis is the same: {text}"
    );
    let read = |f: &str| -> Value {
        serde_json::from_str(&std::fs::read_to_string(d.join(f)).unwrap()).unwrap()
    };
    let (ja, jb) = (read("a.json"), read("b.json"));
    assert_eq!(ja["rank"], jb["rank"]);
    assert_eq!(ja["confounded"], jb["confounded"]);
    let rms = |j: &Value| j["residual_rms_um"].as_f64().unwrap();
    assert!((rms(&ja) - rms(&jb)).abs() < 1e-9 * rms(&ja));
    let (pa, pb) = (
        ja["parameters"].as_array().unwrap(),
        jb["parameters"].as_array().unwrap(),
    );
    assert_eq!(pa.len(), pb.len());
    for (x, y) in pa.iter().zip(pb) {
        assert_eq!(x["error"], y["error"]);
        assert_eq!(x["basis"], y["basis"]);
        match (x["value"].as_f64(), y["value"].as_f64()) {
            (Some(u), Some(v)) => assert!((u - v).abs() < 1e-9 * u.abs().max(1.0), "{x} vs {y}"),
            (None, None) => {}
            other => panic!("{other:?}: {x} vs {y}"),
        }
    }
    let bad = run(
        Some(&d),
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--stream",
            "--block",
            "0",
        ],
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--block"));
}
