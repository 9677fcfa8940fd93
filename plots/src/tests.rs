use super::*;

/// A K1-like record: C from 0 to 360 deg, errors with a few harmonics, µm.
fn k1_like() -> (Vec<f64>, Vec<Panel>) {
    let x: Vec<f64> = (0..=360).map(f64::from).collect();
    let mut panels = Vec::new();
    for (k, dir) in ["x error", "y error", "z error"].iter().enumerate() {
        let ph = k as f64;
        let base: Vec<f64> = x
            .iter()
            .map(|c| {
                let t = c.to_radians();
                12.0 * (t + ph).sin() - 4.0
            })
            .collect();
        let extra: Vec<f64> = x
            .iter()
            .map(|c| 5.0 * (2.0 * c.to_radians() + ph).cos())
            .collect();
        let ext: Vec<f64> = base.iter().zip(&extra).map(|(b, e)| b + e).collect();
        let meas: Vec<f64> = ext
            .iter()
            .enumerate()
            .map(|(i, v)| v + 0.6 * ((i as f64 * 12.9898).sin() * 43758.5453).fract())
            .collect();
        panels.push(Panel {
            name: dir.to_string(),
            measured: Series::new("measured", meas),
            predictions: vec![
                Series::new("base model", base),
                Series::new("extended model", ext),
            ],
        });
    }
    (x, panels)
}

fn spectrum_rows() -> Vec<(String, f64, f64)> {
    let mut rows = Vec::new();
    for axis in ["A", "C"] {
        for k in 1..=4 {
            for d in ["x", "y", "z"] {
                let before = if axis == "C" && k == 2 && d == "y" {
                    6.1
                } else {
                    0.2 + 0.15 * ((k * 7 + d.len()) % 5) as f64
                };
                let after = if before > 5.0 { 0.31 } else { before * 0.9 };
                rows.push((format!("{axis} harmonic:{k} {d}"), before, after));
            }
        }
    }
    rows
}

/// Every `font-family="…"` attribute value in the SVG.
fn font_families(svg: &str) -> Vec<String> {
    svg.split("font-family=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap_or("").to_string())
        .collect()
}

fn assert_wellformed(svg: &str) {
    assert!(svg.starts_with("<svg"), "{}", &svg[..80.min(svg.len())]);
    assert!(svg.trim_end().ends_with("</svg>"));
    let fams = font_families(svg);
    assert!(!fams.is_empty(), "no text at all");
    assert!(
        fams.iter().all(|f| f == FONT_FAMILY),
        "font families other than the registered one: {fams:?}"
    );
    // Balanced tags, roughly: every `<text` is closed.
    assert_eq!(svg.matches("<text").count(), svg.matches("</text>").count());
}

#[test]
fn path_comparison_svg_has_title_legend_and_only_our_font() {
    let (x, panels) = k1_like();
    let svg = path_comparison("K1: measured & predicted", "C (deg)", &x, &panels).unwrap();
    assert_wellformed(&svg);
    assert!(svg.contains("K1: measured &amp; predicted"));
    for label in [
        "measured",
        "base model",
        "extended model",
        "x error (µm)",
        "z error (µm)",
        "C (deg)",
    ] {
        assert!(svg.contains(label), "missing {label}");
    }
    assert!(svg.contains("µm"));
}

#[test]
fn spectrum_svg_has_title_legend_and_rows() {
    let rows = spectrum_rows();
    let svg = spectrum("Residual spectrum", "base model", "extended model", &rows).unwrap();
    assert_wellformed(&svg);
    for label in [
        "Residual spectrum",
        "base model",
        "extended model",
        "C harmonic:2 y",
        "A harmonic:1 x",
        "residual amplitude (µm)",
        "6.10",
    ] {
        assert!(svg.contains(label), "missing {label}");
    }
    // Also accepts SpectrumRow directly.
    let rows2: Vec<SpectrumRow> = rows.iter().map(SpectrumRow::from).collect();
    let svg2 = spectrum("Residual spectrum", "base model", "extended model", &rows2).unwrap();
    assert_eq!(svg, svg2);
}

#[test]
fn nan_and_inf_are_named_errors() {
    let (x, mut panels) = k1_like();
    panels[1].predictions[0].values[17] = f64::NAN;
    let err = path_comparison("t", "C (deg)", &x, &panels).unwrap_err();
    match &err {
        PlotError::NonFinite { series, index, .. } => {
            assert_eq!(series, "y error: base model");
            assert_eq!(*index, 17);
        }
        other => panic!("unexpected {other:?}"),
    }
    let msg = err.to_string();
    assert!(
        msg.contains("y error: base model") && msg.contains("17"),
        "{msg}"
    );

    let (mut x, panels) = k1_like();
    x[3] = f64::INFINITY;
    assert!(matches!(
        path_comparison("t", "C (deg)", &x, &panels),
        Err(PlotError::NonFinite { ref series, index: 3, .. }) if series == "C (deg)"
    ));

    let mut rows = spectrum_rows();
    rows[5].2 = f64::NEG_INFINITY;
    let err = spectrum("t", "before", "after", &rows).unwrap_err();
    assert!(
        matches!(&err, PlotError::NonFinite { series, index: 5, .. } if series == &format!("{} (after)", rows[5].0)),
        "{err:?}"
    );
}

#[test]
fn empty_and_mismatched_inputs_are_errors() {
    let (x, mut panels) = k1_like();
    assert!(matches!(
        path_comparison("t", "i", &[], &panels),
        Err(PlotError::Empty { .. })
    ));
    assert!(matches!(
        path_comparison("t", "i", &x, &[]),
        Err(PlotError::Empty { .. })
    ));
    panels[2].measured.values.clear();
    assert!(
        matches!(path_comparison("t", "i", &x, &panels), Err(PlotError::Empty { ref what }) if what == "z error: measured")
    );
    let (x, mut panels) = k1_like();
    panels[0].predictions[1].values.pop();
    assert!(matches!(
        path_comparison("t", "i", &x, &panels),
        Err(PlotError::LengthMismatch {
            expected: 361,
            found: 360,
            ..
        })
    ));
    let no_rows: [(String, f64, f64); 0] = [];
    assert!(matches!(
        spectrum("t", "a", "b", &no_rows),
        Err(PlotError::Empty { .. })
    ));
}

#[test]
fn constant_and_single_sample_series_still_plot() {
    let x = vec![5.0; 4];
    let panels = vec![Panel {
        name: "x error".into(),
        measured: Series::new("measured", vec![3.0; 4]),
        predictions: vec![Series::new("model", vec![3.0; 4])],
    }];
    let svg = path_comparison("constant", "sample index", &x, &panels).unwrap();
    assert_wellformed(&svg);
    let svg = path_comparison(
        "one sample",
        "sample index",
        &[0.0],
        &[Panel {
            name: "x error".into(),
            measured: Series::new("measured", vec![0.0]),
            predictions: vec![],
        }],
    )
    .unwrap();
    assert_wellformed(&svg);
    let svg = spectrum("zeros", "a", "b", &[("k".to_string(), 0.0, 0.0)]).unwrap();
    assert_wellformed(&svg);
    let svg = spectrum("negative", "a", "b", &[("k".to_string(), -2.0, 1.0)]).unwrap();
    assert_wellformed(&svg);
}

#[test]
fn output_is_deterministic() {
    let (x, panels) = k1_like();
    let a = path_comparison("K1", "C (deg)", &x, &panels).unwrap();
    let b = path_comparison("K1", "C (deg)", &x, &panels).unwrap();
    assert_eq!(a, b);
    let rows = spectrum_rows();
    let a = spectrum("S", "before", "after", &rows).unwrap();
    let b = spectrum("S", "before", "after", &rows).unwrap();
    assert_eq!(a, b);
}

/// Renders the two example figures to `$PLOTS_EXAMPLE_DIR` (default: the system temp dir) for
/// a person to look at: `cargo test -p plots -- --ignored render_examples`.
#[test]
#[ignore]
fn render_examples() {
    let dir = std::env::var_os("PLOTS_EXAMPLE_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(std::env::temp_dir);
    let (x, panels) = k1_like();
    let svg = path_comparison(
        "K1 (held out): measured and predicted error",
        "C (deg)",
        &x,
        &panels,
    )
    .unwrap();
    std::fs::write(dir.join("plots-example-path.svg"), &svg).unwrap();
    let svg = spectrum(
        "K4: residual amplitude per harmonic and direction",
        "base model",
        "extended model",
        &spectrum_rows(),
    )
    .unwrap();
    std::fs::write(dir.join("plots-example-spectrum.svg"), &svg).unwrap();

    // Edge cases: a constant record and a spectrum with a negative value.
    let x: Vec<f64> = (0..50).map(f64::from).collect();
    let panels = vec![Panel {
        name: "x error".into(),
        measured: Series::new("measured", vec![3.0; 50]),
        predictions: vec![Series::new("model", vec![3.0; 50])],
    }];
    let svg = path_comparison("constant record", "sample index", &x, &panels).unwrap();
    std::fs::write(dir.join("plots-example-constant.svg"), &svg).unwrap();
    let rows = [
        ("signed coefficient".to_string(), -2.0, 0.5),
        ("zero".to_string(), 0.0, 0.0),
    ];
    let svg = spectrum("signed values", "before", "after", &rows).unwrap();
    std::fs::write(dir.join("plots-example-signed.svg"), &svg).unwrap();
}

#[test]
fn tick_labels_are_short_and_use_the_minus_sign() {
    assert_eq!(tick_label(0.0), "0");
    assert_eq!(tick_label(-0.0), "0");
    assert_eq!(tick_label(1e-12), "0");
    assert_eq!(tick_label(50.0), "50");
    assert_eq!(tick_label(-2.5), "\u{2212}2.5");
    assert_eq!(tick_label(0.125), "0.125");
    assert_eq!(tick_label(0.1 + 0.2), "0.3");
}
