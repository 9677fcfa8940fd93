//! Whole reports from small hand-written reports (of version 1, as rtest wrote them before
//! reports had records): escaping, the Content-Security-Policy, no address anywhere, absent
//! sections said in one line.

use super::*;

/// An identification of machine `machine` (a JSON string literal's contents).
fn identification(machine: &str) -> String {
    format!(
        r#"{{"machine": "{machine}", "fingerprint": "fa038fe9e24c960a", "data": "k4.csv",
  "model": "reduced", "base_model": "reduced", "terms": ["XOC", "YOC", "dx0"],
  "parameters": [
    {{"name": "XOC", "error": "XOC", "basis": "const", "value": 12.3456, "std": 0.052,
      "unit": "um", "determined": true, "fixed": false}},
    {{"name": "YOC", "error": "YOC", "basis": "const", "value": null, "std": null,
      "unit": "um", "determined": false, "fixed": false}},
    {{"name": "dx0", "error": "dx0", "basis": "const", "value": null, "std": null,
      "unit": "um", "determined": false, "fixed": false}}],
  "residual_rms_um": 0.49, "rank": 2, "free_parameters": 3, "condition": 4.2,
  "confounded": [["YOC", "dx0"]], "samples": 241, "readings": 723, "dof": 721,
  "zeroed": false, "constraint": "none", "sigma_um": 0.5, "near_confounded": [],
  "swallowed": [], "gains": "compiled",
  "refinement": {{"method": "exact", "iterations": 2, "converged": true,
                  "steps_um": [1.0, 1e-10], "first_order_rms_um": 0.49}},
  "notes": ["YOC and dx0 have no value: confounded"]}}"#
    )
}

fn direction(rms: f64) -> String {
    format!(
        r#"{{"measured_rms_um": {rms}, "measured_max_um": 30.5, "residual_rms_um": 0.5, "residual_max_um": 1.6}}"#
    )
}

/// A validation of `data` on machine `machine` with model `model`.
fn validation(machine: &str, model: &str, data: &str) -> String {
    let d = direction(12.0);
    format!(
        r#"{{"machine": "{machine}", "model": "{model}", "params": "id.json", "data": "{data}",
  "samples": 361, "prediction": "exact", "measured_rms_um": 12.0, "measured_max_um": 30.5,
  "residual_rms_um": 0.5, "residual_max_um": 1.6,
  "per_direction": {{"x": {d}, "y": {d}, "z": {d}}}, "zeroed": false,
  "unidentified_set_to_zero": ["YOC"]}}"#
    )
}

fn inputs(docs: &[(&str, String)]) -> Result<Inputs, InputError> {
    let mut i = Inputs::new();
    for (file, text) in docs {
        i.add(file, inputs::classify(file, text)?)?;
    }
    Ok(i)
}

/// Every `src=`, `href=` and `url(` of `html`, with what follows: none may leave the page.
fn references(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for key in ["src=", "href=", "url(", "@import"] {
        for (at, _) in html.match_indices(key) {
            out.push(html[at..(at + 40).min(html.len())].to_string());
        }
    }
    out
}

/// Checks that `html` makes no request: CSP present, no address, every reference inline.
fn assert_self_contained(html: &str) {
    assert!(html.contains(&format!(
        "<meta http-equiv=\"Content-Security-Policy\" content=\"{CSP}\">"
    )));
    assert!(!html.contains("http://"), "an http:// address");
    assert!(!html.contains("https://"), "an https:// address");
    assert!(!html.contains("<script"), "a script");
    assert!(!html.contains("<link"), "a link element");
    for r in references(html) {
        assert!(
            r.starts_with("src=\"data:")
                || r.starts_with("url(\"data:")
                || r.starts_with("href=\"#"),
            "a reference that leaves the page: {r}"
        );
    }
}

#[test]
fn a_machine_name_with_markup_comes_out_escaped() {
    let i = inputs(&[("id.json", identification("<script>alert(1)</script> & co"))]).unwrap();
    let html = render(&i).unwrap();
    assert!(!html.contains("<script>alert"));
    assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt; &amp; co"));
    assert_self_contained(&html);
}

#[test]
fn a_report_is_self_contained_and_carries_the_font() {
    let i = inputs(&[
        ("id.json", identification("seed-ac")),
        ("v1.json", validation("seed-ac", "reduced", "k1.csv")),
        ("v2.json", validation("seed-ac", "reduced", "k2.csv")),
    ])
    .unwrap();
    let html = render(&i).unwrap();
    assert_self_contained(&html);
    assert!(html.contains("@font-face { font-family: \"DejaVu Sans\""));
    assert!(html.contains("src: url(\"data:font/ttf;base64,AAEAAA"));
    // One figure (validation), scalable, with its caption.
    assert_eq!(html.matches("<figure id=").count(), 1);
    assert!(html.contains("<figure id=\"fig-validation\">"));
    assert!(html.contains("viewBox=\""));
    assert!(html.contains("<figcaption>Residual RMS"));
    // Values with their uncertainty, the undetermined ones without a number.
    assert!(html.contains("12.346 ± 0.052"));
    assert!(html.contains("<li>YOC, dx0</li>"));
    // Absent parts said in one line each.
    assert!(html.contains("<p class=\"absent\">No diagnosis in this report"));
    assert!(html.contains("<p class=\"absent\">No compensation in this report"));
}

#[test]
fn reports_of_two_machines_disagree() {
    let e = inputs(&[
        ("id.json", identification("seed-ac")),
        ("v1.json", validation("head-table-bc", "reduced", "k1.csv")),
    ])
    .unwrap_err();
    let text = e.to_string();
    assert!(text.contains("v1.json and id.json disagree"), "{text}");
    assert!(text.contains("head-table-bc"), "{text}");
}

#[test]
fn a_validation_of_another_model_disagrees_in_either_order() {
    for order in [[0, 1], [1, 0]] {
        let docs = [
            ("id.json", identification("seed-ac")),
            ("v1.json", validation("seed-ac", "full", "k1.csv")),
        ];
        let e = inputs(&[docs[order[0]].clone(), docs[order[1]].clone()]).unwrap_err();
        assert!(e.to_string().contains("values of another model"), "{e}");
    }
}

#[test]
fn two_identifications_are_refused() {
    let e = inputs(&[
        ("a.json", identification("seed-ac")),
        ("b.json", identification("seed-ac")),
    ])
    .unwrap_err();
    assert!(
        e.to_string().contains("a second identification report"),
        "{e}"
    );
}

#[test]
fn unknown_and_malformed_reports_name_file_line_and_field() {
    let e = inputs::classify("k4.csv", "X,Y,Z\n1,2,3\n").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("k4.csv: not a report of rtest (not JSON: "),
        "{e}"
    );
    assert!(e.to_string().contains("line 1 column"), "{e}");
    let e = inputs::classify("g.json", "{\"rows\": []}").unwrap_err();
    assert!(
        e.to_string().contains("without the fields of any of them"),
        "{e}"
    );
    let e = inputs::classify(
        "v.json",
        &validation("m", "r", "k1").replace("\"samples\": 361", "\"samples\": \"many\""),
    )
    .unwrap_err();
    let text = e.to_string();
    assert!(text.starts_with("v.json: validation report: "), "{text}");
    assert!(text.contains("line 2"), "{text}");
    let e = inputs::classify(
        "i.json",
        &identification("m").replacen('{', "{\"version\": 3, ", 1),
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("i.json: identification report: field `version`: 3"),
        "{e}"
    );
}

#[test]
fn version_1_reports_of_one_record_gain_their_record() {
    let i = inputs(&[
        ("id.json", identification("seed-ac")),
        ("v1.json", validation("seed-ac", "reduced", "runs/k1.csv")),
    ])
    .unwrap();
    let (_, r) = i.identification.as_ref().unwrap();
    assert_eq!(r.version, 1);
    assert_eq!(r.records.len(), 1);
    assert_eq!(r.records[0].label, "k4");
    assert_eq!(r.records[0].data, "k4.csv");
    assert_eq!(r.setups[0].records, ["k4"]);
    let (_, v) = &i.validations[0];
    assert_eq!(v.records.len(), 1);
    assert_eq!(v.records[0].label, "k1");
    assert_eq!(v.records[0].unidentified_set_to_zero, ["YOC"]);
}

#[test]
fn nothing_to_report_is_an_error() {
    assert!(matches!(render(&Inputs::new()), Err(RenderError::Empty)));
}

/// The skeleton of a report: its headings, in order.
#[test]
fn the_section_skeleton() {
    let i = inputs(&[("id.json", identification("seed-ac"))]).unwrap();
    let html = render(&i).unwrap();
    let headings: Vec<&str> = html
        .lines()
        .filter(|l| l.starts_with("<h1>") || l.starts_with("<h2>") || l.starts_with("<h3>"))
        .collect();
    assert_eq!(
        headings,
        [
            "<h1>R-test check of seed-ac</h1>",
            "<h2>1. Machine and model</h2>",
            "<h2>2. Data</h2>",
            "<h2>3. Identified values</h2>",
            "<h3>What the data could not separate</h3>",
            "<h3>Notes of the identification</h3>",
            "<h2>4. Validation</h2>",
            "<h2>5. Diagnosis</h2>",
            "<h2>6. Compensation</h2>",
        ]
    );
}
