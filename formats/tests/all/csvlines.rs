//! The bounded line reader of every CSV reader: lines too long, text that is not UTF-8, a
//! byte-order mark, Windows line ends; endless input ends with an error after at most about
//! `max_line_bytes` and one buffer, from a reader and from a FIFO.

use crate::common;
use crate::csvfiles;

use common::{Scratch, builtin};
use csvfiles::{counting, k4_text, set_field};
use formats::csv::{
    CsvError, MeasurementBlocks, Need, READ_BUFFER_BYTES, ReadOptions, parse_measurement, read_csv,
    read_measurement,
};
use formats::paths::{parse_path, read_path};
use std::io::{Cursor, Read, Write};

fn opts() -> ReadOptions {
    ReadOptions::default()
}

/// The first error of the block reader on `bytes`, or `None` when every block reads.
fn blocks_error(bytes: &[u8], o: &ReadOptions) -> Option<String> {
    let m = builtin("seed-ac");
    match MeasurementBlocks::new("k4.csv".into(), Cursor::new(bytes), &m, 50, o) {
        Err(e) => Some(e.to_string()),
        Ok(mut blocks) => blocks.find_map(|b| b.err()).map(|e| e.to_string()),
    }
}

fn whole_error(bytes: &[u8], o: &ReadOptions) -> String {
    let m = builtin("seed-ac");
    read_csv("k4.csv", bytes, &m, Need::Measured, o)
        .unwrap_err()
        .to_string()
}

#[test]
fn a_line_longer_than_the_bound_is_refused_at_its_line() {
    let m = builtin("seed-ac");
    let text = k4_text(&m);
    let long = format!("# {}", "x".repeat(70_000));
    let with = |line: usize| -> String {
        let mut l: Vec<&str> = text.lines().collect();
        l.insert(line - 1, &long);
        l.join("\n") + "\n"
    };
    let want = "k4.csv:3: line longer than 65536 bytes: not a measurement CSV";
    let t = with(3);
    assert_eq!(
        parse_measurement("k4.csv", &t, &m, &opts())
            .unwrap_err()
            .to_string(),
        want
    );
    assert_eq!(blocks_error(t.as_bytes(), &opts()).unwrap(), want);
    let p = parse_path("k4.csv", &t, &m, &opts()).unwrap_err();
    assert_eq!(p.to_string(), want);
    // Before the header, in the header's place, as the last line without a line end.
    let t = with(1);
    assert_eq!(
        whole_error(t.as_bytes(), &opts()),
        "k4.csv:1: line longer than 65536 bytes: not a measurement CSV"
    );
    assert_eq!(
        blocks_error(t.as_bytes(), &opts()).unwrap(),
        "k4.csv:1: line longer than 65536 bytes: not a measurement CSV"
    );
    let last = text.lines().count() + 1;
    let t = format!("{text}{long}");
    assert_eq!(
        whole_error(t.as_bytes(), &opts()),
        format!("k4.csv:{last}: line longer than 65536 bytes: not a measurement CSV")
    );
    // The bound is on the text of a line, its end (`\n`, `\r\n`) not counted; a bound of
    // one's own. A 40-byte comment passes (the header then has no samples), 41 bytes do not.
    let mut o = opts();
    o.max_line_bytes = 40;
    let header = "X,Y,Z,A,C,dx_um,dy_um,dz_um,t_s";
    for end in ["\n", "\r\n"] {
        let t = format!("# {}{end}{header}{end}", "y".repeat(38));
        let e = read_csv("c.csv", t.as_bytes(), &m, Need::Measured, &o).unwrap_err();
        assert!(e.to_string().starts_with("c.csv:2: header only"), "{e}");
        let t = format!("# {}{end}{header}{end}", "y".repeat(39));
        let e = read_csv("c.csv", t.as_bytes(), &m, Need::Measured, &o).unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.csv:1: line longer than 40 bytes: not a measurement CSV"
        );
    }
}

#[test]
fn text_that_is_not_utf8_is_located_by_line_and_character() {
    let m = builtin("seed-ac");
    let text = k4_text(&m);
    // Line 3, the reading dy_um: `é` then the byte 0xff.
    let line3 = set_field(&text, 3, "dy_um", "é")
        .lines()
        .nth(2)
        .unwrap()
        .to_string();
    let column = line3.find('é').unwrap() + 2; // ASCII before `é`, `é`, then 0xff
    let at = text.match_indices('\n').nth(1).unwrap().0 + 1;
    let end = at + text[at..].find('\n').unwrap();
    let mut bytes = text.as_bytes()[..at].to_vec();
    bytes.extend_from_slice(line3.replace('é', "é\u{1}").as_bytes());
    let one = bytes.iter().rposition(|&b| b == 1).unwrap();
    bytes[one] = 0xff;
    bytes.extend_from_slice(&text.as_bytes()[end..]);
    let want = format!("k4.csv:3:{column}: not UTF-8 text (byte 0xff)");
    assert_eq!(whole_error(&bytes, &opts()), want);
    assert_eq!(blocks_error(&bytes, &opts()).unwrap(), want);
    let e = read_path("k4.csv", &bytes[..], &m, &opts()).unwrap_err();
    assert_eq!(e.to_string(), want);
    match read_csv("k4.csv", &bytes[..], &m, Need::Measured, &opts()).unwrap_err() {
        CsvError::Text(model_spec::text::TextError::NotUtf8 {
            line, column: c, ..
        }) => {
            assert_eq!((line, c), (3, column))
        }
        other => panic!("{other:?}"),
    }
    // In the header, in a comment, a lone continuation byte, a truncated sequence at the end.
    let e = whole_error(b"X,Y,Z,A,\xc3\x28C\n", &opts());
    assert_eq!(e, "k4.csv:1:9: not UTF-8 text (byte 0xc3)");
    let e = whole_error(b"# r\xe9sum\xe9\nA,C,dx_um,dy_um,dz_um\n", &opts());
    assert_eq!(e, "k4.csv:1:4: not UTF-8 text (byte 0xe9)");
    let e = blocks_error(b"# ok\n\x80\n", &opts()).unwrap();
    assert_eq!(e, "k4.csv:2:1: not UTF-8 text (byte 0x80)");
    let e = whole_error(b"A,C,dx_um,dy_um,dz_um\n0,0,0,0,0\xe2\x82", &opts());
    assert_eq!(e, "k4.csv:2:10: not UTF-8 text (byte 0xe2)");
}

#[test]
fn a_byte_order_mark_and_windows_line_ends_are_accepted() {
    let m = builtin("seed-ac");
    let text = k4_text(&m);
    let plain = parse_measurement("k4.csv", &text, &m, &opts()).unwrap();
    let bom = format!("\u{feff}{}", text.replace('\n', "\r\n"));
    assert_eq!(
        parse_measurement("k4.csv", &bom, &m, &opts()).unwrap(),
        plain
    );
    let mut blocks = simulation::record::Record::default();
    for b in MeasurementBlocks::new(
        "k4.csv".into(),
        Cursor::new(bom.as_bytes()),
        &m,
        20,
        &opts(),
    )
    .unwrap()
    {
        let b = b.unwrap();
        blocks.samples.extend(b.samples);
        blocks.measured.extend(b.measured);
    }
    assert_eq!(blocks, plain);
    // A mark before a comment; a mark elsewhere is text like any other.
    let commented = format!("\u{feff}# c\n{text}");
    assert_eq!(
        parse_measurement("k4.csv", &commented, &m, &opts()).unwrap(),
        plain
    );
    let e = parse_measurement("k4.csv", &format!("# c\n\u{feff}{text}"), &m, &opts()).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("k4.csv:2: column 1 `\u{feff}X`: unknown column"),
        "{e}"
    );
}

/// The largest number of bytes a reader may consume before it refuses a line that never ends.
fn bound(o: &ReadOptions) -> usize {
    o.max_line_bytes + READ_BUFFER_BYTES
}

#[test]
fn an_endless_line_is_refused_after_a_bounded_number_of_bytes() {
    let m = builtin("seed-ac");
    for max in [100, 65_536, 200_000] {
        let mut o = opts();
        o.max_line_bytes = max;
        let want = format!("k4.csv:1: line longer than {max} bytes: not a measurement CSV");
        // Zeros, and a header that never ends.
        let (r, n) = counting(std::io::repeat(0));
        let e = read_csv("k4.csv", r, &m, Need::Measured, &o).unwrap_err();
        assert_eq!(e.to_string(), want);
        assert!(n.get() <= bound(&o), "{} bytes read, max {max}", n.get());
        let (r, n) = counting(b"X,Y,Z,".chain(std::io::repeat(b'A')));
        let e = MeasurementBlocks::new("k4.csv".into(), r, &m, 10, &o)
            .err()
            .unwrap();
        assert_eq!(e.to_string(), want);
        assert!(n.get() <= bound(&o), "{} bytes read, max {max}", n.get());
        // After good lines (longer than 100 bytes): the line number of the endless one.
        if max < 1000 {
            continue;
        }
        let text = k4_text(&m);
        let (r, n) = counting(text.as_bytes().chain(std::io::repeat(b'7')));
        let e = read_path("k4.csv", r, &m, &o).unwrap_err();
        let line = text.lines().count() + 1;
        assert_eq!(
            e.to_string(),
            format!("k4.csv:{line}: line longer than {max} bytes: not a measurement CSV")
        );
        assert!(n.get() <= text.len() + bound(&o), "{} bytes read", n.get());
        let (r, n) = counting(text.as_bytes().chain(std::io::repeat(b'7')));
        let e = MeasurementBlocks::new("k4.csv".into(), r, &m, 1000, &o)
            .unwrap()
            .find_map(|b| b.err())
            .unwrap();
        assert!(
            e.to_string()
                .starts_with(&format!("k4.csv:{line}: line longer"))
        );
        assert!(n.get() <= text.len() + bound(&o), "{} bytes read", n.get());
    }
}

/// Makes a FIFO in `dir` and a thread that writes zeros into it until the reader closes it; the
/// thread returns how many bytes it wrote.
fn zeros_fifo(dir: &Scratch, name: &str) -> (std::path::PathBuf, std::thread::JoinHandle<usize>) {
    let fifo = dir.0.join(name);
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(status.success(), "mkfifo");
    let path = fifo.clone();
    let writer = std::thread::spawn(move || {
        // Opening blocks until the reader opens the other end.
        let mut f = std::fs::OpenOptions::new().write(true).open(&path).unwrap();
        let zeros = vec![0u8; 1 << 16];
        let mut written = 0;
        while let Ok(n) = f.write(&zeros) {
            written += n;
        }
        written
    });
    (fifo, writer)
}

#[test]
fn an_endless_stream_of_zeros_from_a_fifo_ends_with_the_line_error() {
    let m = builtin("seed-ac");
    let dir = Scratch::new("fifo");
    let want = "line longer than 65536 bytes: not a measurement CSV";
    let (fifo, writer) = zeros_fifo(&dir, "whole.csv");
    let e = read_measurement(&fifo, &m, &opts()).unwrap_err();
    assert_eq!(e.to_string(), format!("{}:1: {want}", fifo.display()));
    let written = writer.join().unwrap();
    // What the writer got into the pipe: what was read plus at most the pipe's buffer; only
    // checked to be finite here (the bound on what is read is tested with a counting reader).
    assert!(written > 65_536, "{written}");
    let (fifo, writer) = zeros_fifo(&dir, "blocks.csv");
    let e = MeasurementBlocks::open(&fifo, &m, 100, &opts())
        .err()
        .unwrap();
    assert_eq!(e.to_string(), format!("{}:1: {want}", fifo.display()));
    writer.join().unwrap();
}

#[test]
fn the_largest_line_bound_is_no_bound() {
    let m = builtin("seed-ac");
    let mut o = opts();
    o.max_line_bytes = usize::MAX;
    // A line that spans refills of the read buffer, and a last line without a line end.
    let text = k4_text(&m);
    let long = format!(
        "# {}\n{}",
        "x".repeat(2 * READ_BUFFER_BYTES),
        text.trim_end()
    );
    let want = parse_measurement("k4.csv", &text, &m, &opts()).unwrap();
    assert_eq!(
        read_csv("k4.csv", long.as_bytes(), &m, Need::Measured, &o).unwrap(),
        want
    );
    assert_eq!(blocks_error(long.as_bytes(), &o), None);
}
