//! Reading a measurement file in blocks gives exactly the slices of the whole-file record.

use formats::csv::{MeasurementBlocks, ReadOptions, format_record, parse_measurement};
use formats::truth::builtin_truth;
use model_spec::builtin;
use simulation::paths::{builtin_path, fill_linear_ik, record_from_commands};
use simulation::readings::simulate;
use simulation::record::Record;
use std::io::Cursor;

fn concatenated(text: &str, m: &model_spec::Machine, block: usize) -> Record {
    let mut out = Record::default();
    for (i, b) in MeasurementBlocks::new(
        "m.csv".into(),
        Cursor::new(text.as_bytes()),
        m,
        block,
        &ReadOptions::default(),
    )
    .unwrap()
    .enumerate()
    {
        let b = b.unwrap();
        assert!(
            i == 0 || b.samples.len() <= block,
            "later blocks hold at most {block} samples"
        );
        out.samples.extend(b.samples);
        out.measured.extend(b.measured);
        out.lines.extend(b.lines);
    }
    out
}

#[test]
fn blocks_equal_the_whole_record_with_reversals_and_without_times() {
    let m = builtin("seed-ac").unwrap().unwrap();
    // C goes forward then back, A swings: every block boundary sees motion continue or reverse.
    let (ia, ic) = (m.axis_by_name("A").unwrap(), m.axis_by_name("C").unwrap());
    let mut commands: Vec<Vec<f64>> = (0..300)
        .map(|i| {
            let mut c = vec![0.0; m.axes.len()];
            let k = if i < 150 { i } else { 300 - i } as f64;
            c[ic] = (2.0 * k).to_radians();
            c[ia] = (-20.0 * (k / 30.0).sin()).to_radians();
            c
        })
        .collect();
    fill_linear_ik(&m, &m.default_parameters(), &mut commands).unwrap();
    let times = (0..300).map(|i| i as f64 * 0.5).collect();
    let path = record_from_commands(commands, times);
    let truth = builtin_truth("seed-ac-demo", &m).unwrap().unwrap();
    let rec = simulate(&m, &truth, &path).unwrap();
    let text = format_record(&m, &rec, &[]).unwrap();
    let whole = parse_measurement("m.csv", &text, &m, &ReadOptions::default()).unwrap();
    for block in [1, 7, 64, 299, 300, 1000] {
        assert_eq!(concatenated(&text, &m, block), whole, "block {block}");
    }
    // Without the time and the linear columns: times are sample indices, linear axes by IK.
    let k4 = simulate(&m, &truth, &builtin_path(&m, "K4").unwrap().unwrap()).unwrap();
    let full = format_record(&m, &k4, &[]).unwrap();
    let header: Vec<&str> = full
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .split(',')
        .collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| !["X", "Y", "Z", "t_s"].contains(&header[i]))
        .collect();
    let reduced: String = full
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            keep.iter().map(|&i| f[i]).collect::<Vec<_>>().join(",") + "\n"
        })
        .collect();
    let whole = parse_measurement("m.csv", &reduced, &m, &ReadOptions::default()).unwrap();
    assert_eq!(concatenated(&reduced, &m, 50), whole);
    // The linear axes filled by the inverse kinematics move from the second sample on, like the
    // rotary ones: the first block does not look ahead.
    let sizes: Vec<usize> = MeasurementBlocks::new(
        "m.csv".into(),
        Cursor::new(reduced.as_bytes()),
        &m,
        50,
        &ReadOptions::default(),
    )
    .unwrap()
    .map(|b| b.unwrap().samples.len())
    .collect();
    assert_eq!(sizes, vec![50, 50, 50, 50, 41]);
}

#[test]
fn an_error_deep_in_the_file_names_its_line_and_column() {
    let m = builtin("seed-ac").unwrap().unwrap();
    // Every axis moves from the second sample on (the nest follows the ball), so the first
    // block does not look ahead.
    let (ia, ic) = (m.axis_by_name("A").unwrap(), m.axis_by_name("C").unwrap());
    let mut commands: Vec<Vec<f64>> = (0..100)
        .map(|i| {
            let mut c = vec![0.0; m.axes.len()];
            c[ia] = (0.5 * i as f64).to_radians();
            c[ic] = (i as f64).to_radians();
            c
        })
        .collect();
    fill_linear_ik(&m, &m.default_parameters(), &mut commands).unwrap();
    let path = record_from_commands(commands, (0..100).map(f64::from).collect());
    // The path's rows with zero readings instead of the time, then a bad reading.
    let mut text = String::from("X,Y,Z,A,C,dx_um,dy_um,dz_um\n");
    let mut last = String::new();
    for l in format_record(&m, &path, &[]).unwrap().lines().skip(1) {
        last = l.rsplit_once(',').unwrap().0.to_string();
        text += &format!("{last},0,0,0\n");
    }
    text += &format!("{last},6,seven,8\n");
    let mut blocks = MeasurementBlocks::new(
        "m.csv".into(),
        Cursor::new(text.as_bytes()),
        &m,
        30,
        &ReadOptions::default(),
    )
    .unwrap();
    let results: Vec<_> = blocks.by_ref().collect();
    assert_eq!(
        results.len(),
        4,
        "three good blocks, then the error, then nothing"
    );
    let e = results[3].as_ref().unwrap_err().to_string();
    assert!(e.starts_with("m.csv:102:"), "{e}");
    assert!(
        e.contains("dy_um") && e.contains("`seven` is not a number"),
        "{e}"
    );
    assert!(blocks.next().is_none());
    let header_only = MeasurementBlocks::new(
        "h.csv".into(),
        Cursor::new(&b"X,Y,Z,A,C,dx_um,dy_um,dz_um\n"[..]),
        &m,
        10,
        &ReadOptions::default(),
    )
    .unwrap()
    .next();
    assert!(
        header_only
            .unwrap()
            .unwrap_err()
            .to_string()
            .contains("header only")
    );
}
