//! The worked example of docs/diagnosis.md: the diagnosis of a built-in truth, with text
//! figures.
//!
//! ```sh
//! cargo run --release -p diagnosis --example diagnose_demo [TRUTH]   # default seed-ac-demo
//! ```
//!
//! The truth (`seed-ac-demo`, `seed-ac-budget`, or a truth file) is simulated on the exact
//! virtual machine of `seed-ac` along K4, K1 and K2 (noise seeds 1, 2, 3: the truth's seed plus
//! 0, 1, 2); the seed's reduced model is diagnosed on K4 with K1 and K2 held out, with the
//! default options. Printed: the residual structure, the findings, what is confounded, the gain,
//! and two figures: the K1 residual along C before and after, and its spectrum against C.

use diagnosis::{DiagnoseOptions, Diagnosis, diagnose, one_record};
use fitting::campaign::CampaignValues;
use fitting::{ValidateOptions, validate};
use formats::progress::Unwatched;
use model_spec::Machine;
use model_spec::basis::Basis;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::Model;
use simulation::record::Record;

fn main() {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let name = std::env::args().nth(1).unwrap_or("seed-ac-demo".into());
    let mut truth = formats::truth::load_truth(&name, &m).unwrap();
    println!("{}", truth.summary(&m));
    let mut rec = vec![];
    for p in ["K4", "K1", "K2"] {
        let path = simulation::paths::builtin_path(&m, p).unwrap().unwrap();
        rec.push((
            p.to_string(),
            simulation::readings::simulate(&m, &truth, &path).unwrap(),
        ));
        truth.seed += 1;
    }
    let base = Model::of(&m, "reduced").unwrap();
    let o = DiagnoseOptions::default();
    let t = std::time::Instant::now();
    let (fitted, held) = one_record(
        &rec[0].0,
        rec[0].1.clone(),
        rec[1..].to_vec(),
        m.default_parameters(),
        false,
    )
    .unwrap();
    let d = diagnose(&m, &base, &fitted, &held, &o, &Unwatched).unwrap();
    let elapsed = t.elapsed();
    let columns: usize = diagnosis::dictionary::dictionary(&m, &base.terms, &o.dictionary)
        .iter()
        .map(|t| t.basis.width())
        .sum();
    println!(
        "base model: reduced ({} terms); fitted on K4, held out K1, K2; dictionary {} candidates ({columns} columns); α = {}; {:.1} ms",
        base.terms.len(),
        d.dictionary_size,
        o.alpha,
        elapsed.as_secs_f64() * 1e3
    );

    println!("\nResidual structure of the base fit on K4 (largest amplitudes, µm):");
    structure(&d.structure_before);
    println!("\nFindings:");
    for (k, f) in d.findings.iter().enumerate() {
        // The term's own unit (µm, µrad; µm/s for a rate, ms for a lag), a rate to 4 places.
        let scale = f.term.display_factor(&m);
        let unit = f.term.unit(&m).replace("urad", "µrad").replace("um", "µm");
        let dp = if f.term.basis == Basis::Rate { 4 } else { 2 };
        let v: Vec<String> = f
            .values
            .iter()
            .zip(&f.stds)
            .map(|(v, s)| match (v, s) {
                (Some(v), Some(s)) => format!("{:.dp$} ± {:.dp$}", v * scale, s * scale),
                (Some(v), None) => format!("{:.dp$}", v * scale),
                _ => "not determined".into(),
            })
            .collect();
        println!(
            "{}. {}: {} {unit}{}",
            k + 1,
            f.description,
            v.join(", "),
            match (f.values.len(), f.plausible) {
                (2, true) => format!(" (amplitude {:.2} {unit})", f.size),
                (_, true) => String::new(),
                (_, false) => format!(
                    " (fits, but implausible: {:.2} {unit} beyond the budget of {:.2})",
                    f.size, f.limit
                ),
            }
        );
        println!(
            "   explains {:.1} % of the base residual; F = {:.1}, corrected p = {:.1e} ({:?}, {} candidates tried)",
            100.0 * f.explained_fraction,
            f.f,
            f.p_value,
            f.correction,
            f.candidates_tried
        );
        if !f.alternatives.is_empty() {
            println!(
                "   the data cannot tell it from: {}",
                f.alternatives
                    .iter()
                    .map(|t| t.spelling(&m))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    println!("stop: {}", d.stop.reason);
    println!(
        "\nConfounded ({}; the extended model spans them):",
        d.confounded.len()
    );
    for c in &d.confounded {
        println!(
            "   {} ~ {}",
            c.term.spelling(&m),
            c.with
                .iter()
                .map(|t| t.spelling(&m))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    println!(
        "Unexcited on K4 ({}): {}",
        d.unexcited.len(),
        d.unexcited
            .iter()
            .map(|t| t.spelling(&m))
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!(
        "\nExtended model: {}",
        d.extended
            .terms
            .iter()
            .map(|t| t.spelling(&m))
            .collect::<Vec<_>>()
            .join(" ")
    );
    println!("\nGain (residual RMS, µm):");
    println!("   record  base    extended");
    println!(
        "   K4 fit  {:6.3}  {:6.3}",
        d.fit_rms.0 * 1e3,
        d.fit_rms.1 * 1e3
    );
    for h in &d.validation {
        println!(
            "   {:7} {:6.3}  {:6.3}",
            h.name,
            h.before_rms * 1e3,
            h.after_rms * 1e3
        );
    }
    println!(
        "{}: {}",
        if d.recommendation.recommended {
            "Recommended"
        } else {
            "Not recommended"
        },
        d.recommendation.reasons.join("; ")
    );
    println!("\nResidual structure after the extension (largest amplitudes, µm):");
    structure(&d.structure_after);

    // Figures on K1 (C from 0° to 360° at A = 0°).
    let k1 = &rec[1].1;
    let before = residual(&m, &d, k1, false);
    let after = residual(&m, &d, k1, true);
    for (dir, axis) in ["x", "y", "z"].iter().enumerate() {
        println!(
            "\nFigure: K1 residual in {axis} (µm) against C (0°…360°); `o` base model, `*` extended model"
        );
        plot(
            &before.iter().map(|r| r[dir] * 1e3).collect::<Vec<_>>(),
            &after.iter().map(|r| r[dir] * 1e3).collect::<Vec<_>>(),
        );
    }
    println!(
        "\nFigure: spectrum of the K1 residual against C, amplitude √(x²+y²+z²) per harmonic (µm)"
    );
    spectrum(m.axis_by_name("C").unwrap(), k1, &before, &after);
}

/// The top components of a residual structure.
fn structure(s: &[diagnosis::structure::Component]) {
    for c in s.iter().take(6) {
        println!(
            "   {:>5} {:10} in {}: {:.2}",
            c.source,
            c.shape,
            ["x", "y", "z"][c.direction],
            c.explained_rms_um
        );
    }
}

/// Measured minus predicted (exact machine) on `record`, base or extended model, mm.
fn residual(m: &Machine, d: &Diagnosis, record: &Record, extended: bool) -> Vec<[f64; 3]> {
    let fit = if extended {
        &d.extended_fit
    } else {
        &d.base_fit
    };
    // The record on the fitted record's ball set-up, at the default kinematic parameters.
    let setup = fit.records[0].setup.clone();
    let r = CampaignRecord::new(
        "check",
        record.clone(),
        m.default_parameters(),
        setup,
        false,
    );
    let c = Campaign::new(vec![r]).unwrap();
    let o = ValidateOptions::new().exact(true);
    let v = validate(m, &CampaignValues::of(fit), &c, &o, &Unwatched).unwrap();
    v.records[0].validation.residual.clone()
}

/// A text plot of two series over the same samples: 72 columns, 13 rows.
fn plot(a: &[f64], b: &[f64]) {
    let (w, h) = (72usize, 13usize);
    let lim = a
        .iter()
        .chain(b)
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-9);
    let mut grid = vec![vec![' '; w]; h];
    let row = |v: f64| (((lim - v) / (2.0 * lim)) * (h - 1) as f64).round() as usize;
    for (series, mark) in [(a, 'o'), (b, '*')] {
        let columns: Vec<(usize, usize)> = (0..w)
            .map(|col| {
                // The sample at the middle of the column.
                let i = ((col as f64 + 0.5) / w as f64 * series.len() as f64) as usize;
                (col, row(series[i.min(series.len() - 1)]))
            })
            .collect();
        for (col, r) in columns {
            grid[r][col] = mark;
        }
    }
    for (r, line) in grid.iter().enumerate() {
        let label = if r == 0 {
            format!("{lim:+6.2}")
        } else if r == h / 2 {
            format!("{:+6.2}", 0.0)
        } else if r == h - 1 {
            format!("{:+6.2}", -lim)
        } else {
            String::new()
        };
        println!("{label:>7} |{}", line.iter().collect::<String>());
    }
    println!("        +{}", "-".repeat(w));
    let mut ticks = vec![' '; w + 4];
    for (k, label) in ["0", "90", "180", "270", "360"].iter().enumerate() {
        let at = (k * w / 4).min(w - label.len());
        for (j, ch) in label.chars().enumerate() {
            ticks[at + j] = ch;
        }
    }
    println!(
        "         {}  (C, degrees)",
        ticks.iter().collect::<String>().trim_end()
    );
}

/// Harmonic amplitudes of a residual against the rotary axis `axis` (Fourier coefficients per
/// direction over whole turns sampled evenly), k = 1…8, before and after, as bars.
fn spectrum(axis: usize, record: &Record, before: &[[f64; 3]], after: &[[f64; 3]]) {
    let c: Vec<f64> = record.samples.iter().map(|s| s.commands[axis]).collect();
    let amp = |r: &[[f64; 3]], k: f64| -> f64 {
        let n = c.len() as f64;
        (0..3)
            .map(|d| {
                // K1 covers whole turns evenly: the harmonics are orthogonal to the mean.
                let mean = r.iter().map(|v| v[d]).sum::<f64>() / n;
                let (a, b) = c.iter().zip(r).fold((0.0, 0.0), |(a, b), (t, v)| {
                    (
                        a + (v[d] - mean) * (k * t).cos(),
                        b + (v[d] - mean) * (k * t).sin(),
                    )
                });
                (2.0 * a / n).powi(2) + (2.0 * b / n).powi(2)
            })
            .sum::<f64>()
            .sqrt()
            * 1e3
    };
    let rows: Vec<(usize, f64, f64)> = (1..=8)
        .map(|k| (k, amp(before, k as f64), amp(after, k as f64)))
        .collect();
    let top = rows.iter().fold(1e-9f64, |m, r| m.max(r.1).max(r.2));
    for (k, b, a) in rows {
        let bar = |v: f64| "#".repeat((v / top * 40.0).round() as usize);
        println!("   k={k} base     {b:5.2} {}", bar(b));
        println!("       extended {a:5.2} {}", bar(a));
    }
}
