//! Reading text files for people (`model_spec::text`) and machine files through it: bounded in
//! size whatever the file is, UTF-8 with a located message, a byte-order mark dropped.
//!
//! Every file is made in a fresh directory of the system's temporary directory.

use model_spec::limits::MAX_FILE_BYTES;
use model_spec::text::{TextError, decode_text, read_text};
use model_spec::{BUILTIN, LoadError, load_machine};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A new, empty directory for one test; removed by [`Fresh::drop`].
struct Fresh(PathBuf);

impl Fresh {
    fn new(test: &str) -> Fresh {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_nanos();
        let dir =
            std::env::temp_dir().join(format!("model-spec-{test}-{}-{nanos}", std::process::id()));
        std::fs::create_dir(&dir).expect("a new directory");
        Fresh(dir)
    }

    fn file(&self, name: &str, contents: &[u8]) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, contents).unwrap();
        path
    }
}

impl Drop for Fresh {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn name(p: &Path) -> String {
    p.display().to_string()
}

#[test]
fn decode_drops_the_byte_order_mark() {
    assert_eq!(
        decode_text("a", b"\xef\xbb\xbfx = 1\n".to_vec()).unwrap(),
        "x = 1\n"
    );
    assert_eq!(decode_text("a", b"x = 1\n".to_vec()).unwrap(), "x = 1\n");
    assert_eq!(decode_text("a", Vec::new()).unwrap(), "");
    // Only one, and only at the start.
    assert_eq!(
        decode_text("a", b"\xef\xbb\xbf\xef\xbb\xbfx".to_vec()).unwrap(),
        "\u{feff}x"
    );
}

#[test]
fn decode_locates_the_first_bad_byte() {
    // Line 3, after 16 characters of which two are not ASCII (`é`, `µ`).
    let bytes = b"name = \"a\"\n\n# r\xc3\xa9sum\xc3\xa9 in \xc2\xb5m: \xff\xfe\n".to_vec();
    let e = decode_text("dir/m.toml", bytes).unwrap_err();
    assert_eq!(e.to_string(), "dir/m.toml:3:17: not UTF-8 text (byte 0xff)");
    match e {
        TextError::NotUtf8 {
            file,
            line,
            column,
            byte,
        } => assert_eq!(
            (file.as_str(), line, column, byte),
            ("dir/m.toml", 3, 17, 0xff)
        ),
        other => panic!("{other:?}"),
    }
    // The byte-order mark is not a column.
    let e = decode_text("m", b"\xef\xbb\xbfab\x80".to_vec()).unwrap_err();
    assert_eq!(e.to_string(), "m:1:3: not UTF-8 text (byte 0x80)");
    // A sequence cut short by the end of the file, and one by a newline.
    let e = decode_text("m", b"x\n\xe2\x82".to_vec()).unwrap_err();
    assert_eq!(e.to_string(), "m:2:1: not UTF-8 text (byte 0xe2)");
    let e = decode_text("m", b"\xe2\x82\nx".to_vec()).unwrap_err();
    assert_eq!(e.to_string(), "m:1:1: not UTF-8 text (byte 0xe2)");
    // A Latin-1 `é` on line 9, as in `docs/model-spec.md`.
    let latin1 = b"name = \"a\"\n\n\n\n\n\n\n\n# Kin\xe9matic symbols\n".to_vec();
    let e = decode_text("m.toml", latin1).unwrap_err();
    assert_eq!(e.to_string(), "m.toml:9:6: not UTF-8 text (byte 0xe9)");
    // UTF-16 (its byte-order mark is not UTF-8).
    let e = decode_text("m", b"\xff\xfen\x00".to_vec()).unwrap_err();
    assert_eq!(e.to_string(), "m:1:1: not UTF-8 text (byte 0xff)");
}

#[test]
fn read_within_and_at_the_limit() {
    let dir = Fresh::new("text-limit");
    let p = dir.file("a.txt", b"\xef\xbb\xbfhello\n");
    assert_eq!(read_text(&p, 100).unwrap(), "hello\n");
    // The limit counts the bytes of the file, the byte-order mark included.
    assert_eq!(read_text(&p, 9).unwrap(), "hello\n");
    let e = read_text(&p, 8).unwrap_err();
    assert!(matches!(e, TextError::TooLarge { limit: 8, .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        format!(
            "`{}` is larger than 8 bytes, the most this file may have",
            name(&p)
        )
    );
    let e = read_text(&p, 0).unwrap_err();
    assert!(matches!(e, TextError::TooLarge { limit: 0, .. }), "{e:?}");
    let empty = dir.file("empty.txt", b"");
    assert_eq!(read_text(&empty, 0).unwrap(), "");
    assert_eq!(read_text(&empty, u64::MAX).unwrap(), "");
    let e = read_text(&dir.file("b.txt", b"ok\n\xff"), 100).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}:2:1: not UTF-8 text (byte 0xff)",
            name(&dir.0.join("b.txt"))
        )
    );
}

#[test]
fn read_errors() {
    let dir = Fresh::new("text-io");
    let missing = dir.0.join("missing.txt");
    let e = read_text(&missing, 100).unwrap_err();
    assert!(matches!(e, TextError::Io { .. }), "{e:?}");
    assert!(
        e.to_string()
            .starts_with(&format!("cannot read `{}`: ", name(&missing))),
        "{e}"
    );
    // A directory opens but does not read.
    let e = read_text(&dir.0, 100).unwrap_err();
    assert!(matches!(e, TextError::Io { .. }), "{e:?}");
}

#[test]
fn a_huge_file_is_refused_without_reading_it() {
    let dir = Fresh::new("text-huge");
    let p = dir.0.join("huge.toml");
    // 64 GiB of zeros, stored sparse: reading it whole would take minutes and the memory.
    std::fs::File::create(&p)
        .unwrap()
        .set_len(64 << 30)
        .unwrap();
    let start = Instant::now();
    let e = read_text(&p, MAX_FILE_BYTES).unwrap_err();
    assert!(
        start.elapsed() < Duration::from_secs(10),
        "{:?}",
        start.elapsed()
    );
    assert!(
        matches!(e, TextError::TooLarge { limit, .. } if limit == MAX_FILE_BYTES),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        format!(
            "`{}` is larger than 1048576 bytes (1 MiB), the most this file may have",
            name(&p)
        )
    );
}

#[cfg(unix)]
#[test]
fn an_endless_pipe_is_refused() {
    use std::io::Write;
    let dir = Fresh::new("text-fifo");
    let p = dir.0.join("endless.toml");
    let made = std::process::Command::new("mkfifo").arg(&p).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo is not available: test skipped");
        return;
    }
    // A writer that writes until the reader closes the pipe.
    let writer = {
        let p = p.clone();
        std::thread::spawn(move || {
            let mut f = std::fs::OpenOptions::new().write(true).open(&p).unwrap();
            let block = vec![b'#'; 1 << 16];
            let mut written = 0u64;
            while f.write_all(&block).is_ok() {
                written += block.len() as u64;
                assert!(written < 1 << 30, "the reader read far beyond its limit");
            }
            written
        })
    };
    let e = read_text(&p, 100_000).unwrap_err();
    assert!(
        matches!(e, TextError::TooLarge { limit: 100_000, .. }),
        "{e:?}"
    );
    let written = writer.join().unwrap();
    assert!(written >= 100_000, "{written}");
}

#[test]
fn machine_files_are_read_through_it() {
    let dir = Fresh::new("text-machine");
    let text = BUILTIN[0].1;
    // A byte-order mark is dropped.
    let p = dir.file(
        "bom.toml",
        &[b"\xef\xbb\xbf".as_slice(), text.as_bytes()].concat(),
    );
    assert_eq!(load_machine(&name(&p)).unwrap().name, "seed-ac");
    // A byte that is not UTF-8 (Latin-1 `é` in a comment) is located.
    let latin1 = text.replacen("# Kinematic symbols", "# Kin\u{e9}matic symbols", 1);
    let latin1: Vec<u8> = latin1
        .chars()
        .map(|c| if c == 'é' { 0xe9 } else { c as u8 })
        .collect();
    let p = dir.file("latin1.toml", &latin1);
    let e = load_machine(&name(&p)).unwrap_err();
    assert!(
        matches!(e, LoadError::Io(TextError::NotUtf8 { .. })),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        format!("{}:9:6: not UTF-8 text (byte 0xe9)", name(&p))
    );
    // A file beyond the limit of a description, a comment padded.
    let mut big = text.as_bytes().to_vec();
    big.extend(std::iter::repeat_n(b'\n', MAX_FILE_BYTES as usize));
    let p = dir.file("big.toml", &big);
    let e = load_machine(&name(&p)).unwrap_err();
    assert!(
        matches!(e, LoadError::Io(TextError::TooLarge { .. })),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        format!(
            "`{}` is larger than 1048576 bytes (1 MiB), the most this file may have",
            name(&p)
        )
    );
}
