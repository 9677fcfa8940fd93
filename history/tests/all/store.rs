//! The history database: a check read back as recorded, a version-1 file migrated, damaged and
//! foreign files refused and left byte for byte, several threads and processes recording at
//! once without losing a check, staged checks rolled back.

use crate::common;

use common::{TempDir, check};
use history::schema::{APPLICATION_ID, VERSION};
use history::{CheckKind, HistoryError, Store, Timestamp};
use rusqlite::Connection;
use std::path::Path;

fn dir(name: &str) -> TempDir {
    TempDir::new("store", name)
}

fn names_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_check_reads_back_as_recorded() {
    let d = dir("round-trip");
    let path = d.join("h.sqlite");
    let mut store = Store::open_or_create(&path).unwrap();
    let mut c = check("M123", 0, 10.25, 0.3);
    c.kind = CheckKind::Campaign;
    c.paths = vec!["k4".into(), "K1".into()];
    c.unidentifiable = vec![
        vec!["XOC".into(), "dx0".into()],
        vec!["YOA".into(), "dy0".into()],
    ];
    c.parameters[1].value = None;
    c.parameters[1].std = None;
    c.parameters[1].determined = false;
    c.parameters[0].owner = Some("shared".into());
    c.parameters[0].of = Some("k4".into());
    c.parameters[0].value = Some(0.1 + 0.2); // not a short decimal: kept to the bit
    c.condition = None;
    c.sigma_um = None;
    c.base_model = None;
    c.noise_model = None;
    let id = store.record(&c).unwrap();
    let other = check("M124", 1, 3.0, 0.4);
    let id2 = store.record(&other).unwrap();
    assert_eq!((id, id2), (1, 2));
    drop(store);

    let store = Store::open(&path).unwrap();
    let all = store.checks(None).unwrap();
    assert_eq!(all.len(), 2);
    assert_eq!(all[0].id, 1);
    assert_eq!(all[0].check, c);
    assert_eq!(all[1].check, other);
    let mine = store.checks(Some("M124")).unwrap();
    assert_eq!(mine.len(), 1);
    assert_eq!(mine[0].id, 2);
    let machines = store.machines().unwrap();
    assert_eq!(machines.len(), 2);
    assert_eq!(machines[0].machine_id, "M123");
    assert_eq!(machines[0].checks, 1);
    assert_eq!(store.count().unwrap(), 2);
    drop(store);
    // No temporary file, WAL file or shared-memory file is left once every connection closed.
    assert_eq!(names_in(&d), ["h.sqlite"]);
}

#[test]
fn a_new_database_is_versioned_and_in_wal_mode() {
    let d = dir("new");
    let path = d.join("h.sqlite");
    drop(Store::open_or_create(&path).unwrap());
    let conn = Connection::open(&path).unwrap();
    let v: i32 = conn
        .pragma_query_value(None, "user_version", |r| r.get(0))
        .unwrap();
    let app: i32 = conn
        .pragma_query_value(None, "application_id", |r| r.get(0))
        .unwrap();
    let mode: String = conn
        .pragma_query_value(None, "journal_mode", |r| r.get(0))
        .unwrap();
    assert_eq!((v, app, mode.as_str()), (VERSION, APPLICATION_ID, "wal"));
    assert_eq!(VERSION, 3);
    drop(conn);
    // Opening a database that does not exist is an error naming it, and creates nothing.
    let missing = d.join("missing.sqlite");
    let e = Store::open(&missing).unwrap_err();
    assert!(matches!(e, HistoryError::NotFound { .. }), "{e}");
    assert!(e.to_string().contains("missing.sqlite"), "{e}");
    assert!(!missing.exists());
    // Nor can one be made in a directory that does not exist.
    let e = Store::open_or_create(&d.join("no/such/h.sqlite")).unwrap_err();
    assert!(e.to_string().contains("does not exist"), "{e}");
}

/// The schema of version 1 as rtest wrote it: frozen here, as in a file an older rtest left.
const FROZEN_SCHEMA_1: &str = include_str!("../schema-1.sql");

#[test]
fn a_version_1_file_is_migrated() {
    // The crate's version-1 text must never change: files of that version exist.
    assert_eq!(history::schema::SCHEMA_1.trim(), FROZEN_SCHEMA_1.trim());
    let d = dir("migrate");
    let path = d.join("old.sqlite");
    {
        let conn = Connection::open(&path).unwrap();
        conn.pragma_update(None, "application_id", APPLICATION_ID)
            .unwrap();
        conn.execute_batch(FROZEN_SCHEMA_1).unwrap();
        conn.execute_batch(
            "INSERT INTO checks (machine_id, fingerprint, machine, model, base_model, recorded_at,
                 rtest_version, kind, rank, free_parameters, condition, residual_rms_um, sigma_um,
                 samples, dof, zeroed, constraint_text, refinement, noise_model)
             VALUES ('M123', 'fa038fe9e24c960a', 'seed-ac', 'reduced', 'reduced',
                 '2024-11-04T07:30:00Z', '0.1.0', 'record', 11, 11, 4.2, 0.49, 0.5, 241, 712, 0,
                 'none', 'exact', NULL);
             INSERT INTO check_terms VALUES (1, 0, 'XOC');
             INSERT INTO check_paths VALUES (1, 0, 'K4');
             INSERT INTO parameters VALUES (1, 0, 'XOC', 'XOC', 'const', NULL, NULL, 10.5, 0.05,
                 'um', 1, 0);
             PRAGMA user_version = 1;",
        )
        .unwrap();
        let mode: String = conn
            .pragma_query_value(None, "journal_mode", |r| r.get(0))
            .unwrap();
        assert_eq!(mode, "delete");
    }
    // Opened for reading, an older file is migrated first (reading needs the new column).
    let store = Store::open_for_reading(&path).unwrap();
    assert_eq!(store.checks(None).unwrap().len(), 1);
    drop(store);
    let mut store = Store::open(&path).unwrap();
    let checks = store.checks(None).unwrap();
    assert_eq!(checks.len(), 1);
    let c = &checks[0].check;
    assert_eq!(
        c.measured_at,
        Timestamp::parse("2024-11-04T07:30:00Z").unwrap()
    );
    assert_eq!(c.recorded_at, c.measured_at);
    assert_eq!(c.parameter("XOC").unwrap().value, Some(10.5));
    assert!(!c.recheck, "an older check is no re-check");
    // New checks go in beside the old one, a re-check among them.
    store.record(&check("M123", 60, 11.0, 0.05)).unwrap();
    let mut recheck = check("M123", 61, 11.2, 0.2);
    recheck.recheck = true;
    store.record(&recheck).unwrap();
    assert_eq!(store.count().unwrap(), 3);
    let flags: Vec<bool> = store
        .checks(None)
        .unwrap()
        .iter()
        .map(|c| c.check.recheck)
        .collect();
    assert_eq!(flags, [false, false, true]);
    drop(store);
    let conn = Connection::open(&path).unwrap();
    let v: i32 = conn
        .pragma_query_value(None, "user_version", |r| r.get(0))
        .unwrap();
    let mode: String = conn
        .pragma_query_value(None, "journal_mode", |r| r.get(0))
        .unwrap();
    assert_eq!((v, mode.as_str()), (3, "wal"));
}

/// A database with `n` checks, closed; its bytes.
fn database(path: &Path, n: i64) -> Vec<u8> {
    let mut store = Store::open_or_create(path).unwrap();
    for i in 0..n {
        store
            .record(&check("M123", 7 * i, 10.0 + 0.01 * i as f64, 0.3))
            .unwrap();
    }
    drop(store);
    std::fs::read(path).unwrap()
}

/// Reading a database writes nothing: its bytes stay and no file is left beside it. (Reading
/// one in a directory one may not write: `tests/cli_history.rs`.)
#[test]
fn reading_a_database_writes_nothing() {
    let d = dir("reading");
    let path = d.join("h.sqlite");
    let bytes = database(&path, 3);
    let store = Store::open_for_reading(&path).unwrap();
    assert_eq!(store.count().unwrap(), 3);
    assert_eq!(store.checks(Some("M123")).unwrap().len(), 3);
    drop(store);
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
    assert_eq!(names_in(&d), ["h.sqlite"]);
}

/// Opens `path` every way (to record, to create, to read); each refuses it with a message
/// naming the file and `needle`, and the file's bytes are unchanged.
fn refused(path: &Path, needle: &str) -> String {
    let before = std::fs::read(path).unwrap();
    let e = Store::open(path).unwrap_err().to_string();
    let e2 = Store::open_or_create(path).unwrap_err().to_string();
    assert_eq!(e, e2);
    let e3 = Store::open_for_reading(path).unwrap_err().to_string();
    assert_eq!(e, e3);
    assert!(e.contains(&path.display().to_string()), "{e}");
    assert!(e.contains(needle), "`{needle}` not in: {e}");
    assert_eq!(
        std::fs::read(path).unwrap(),
        before,
        "{} changed",
        path.display()
    );
    // Nothing beside it either: no write-ahead log, no shared-memory file.
    for side in ["-wal", "-shm", "-journal"] {
        let mut p = path.as_os_str().to_owned();
        p.push(side);
        assert!(!Path::new(&p).exists(), "{} left", Path::new(&p).display());
    }
    e
}

#[test]
fn damaged_and_foreign_files_are_refused_and_left_as_they_are() {
    let d = dir("damaged");
    let path = d.join("h.sqlite");
    let bytes = database(&path, 40);
    assert!(bytes.len() >= 8 * 4096, "{} bytes", bytes.len());

    // Truncated to half, and to a length that is not a whole number of pages.
    for len in [bytes.len() / 2, bytes.len() / 2 + 1000, 4096] {
        std::fs::write(&path, &bytes[..len]).unwrap();
        let e = refused(&path, "not a readable rtest history database");
        assert!(
            e.contains("truncated") || e.contains("damaged"),
            "{len}: {e}"
        );
        assert!(e.contains("the file was left as it is"), "{e}");
    }
    // Truncated inside the header.
    std::fs::write(&path, &bytes[..60]).unwrap();
    refused(&path, "not an SQLite database");
    // Empty.
    std::fs::write(&path, b"").unwrap();
    refused(&path, "empty");
    // Text.
    std::fs::write(&path, "machine_id,check\nM123,1\n".repeat(50)).unwrap();
    refused(&path, "not an SQLite database");
    // A page of the middle overwritten.
    let mut scrambled = bytes.clone();
    for b in &mut scrambled[2 * 4096..3 * 4096] {
        *b = 0xa5;
    }
    std::fs::write(&path, &scrambled).unwrap();
    refused(&path, "damaged");

    // Another program's SQLite database.
    let foreign = d.join("foreign.sqlite");
    {
        let c = Connection::open(&foreign).unwrap();
        c.execute_batch("CREATE TABLE t (x); INSERT INTO t VALUES (1);")
            .unwrap();
    }
    refused(&foreign, "another program");
    // A newer rtest's.
    let newer = d.join("newer.sqlite");
    database(&newer, 1);
    {
        let c = Connection::open(&newer).unwrap();
        c.pragma_update(None, "user_version", 99).unwrap();
    }
    refused(&newer, "schema version 99");
    // A directory.
    let e = Store::open(&d).unwrap_err().to_string();
    assert!(e.contains("directory"), "{e}");
}

#[test]
fn a_log_beside_the_database_that_is_not_a_regular_file_is_refused_every_way() {
    let d = dir("companions");
    let path = d.join("h.sqlite");
    let bytes = database(&path, 2);
    std::fs::create_dir(d.join("elsewhere")).unwrap();
    std::fs::write(d.join("elsewhere/log"), b"").unwrap();
    let cases = [
        ("-wal", "elsewhere/log", "write-ahead log"),
        ("-wal", "elsewhere/missing", "write-ahead log"),
        ("-shm", "elsewhere/log", "shared-memory file"),
        ("-journal", "elsewhere/log", "rollback journal"),
    ];
    for (suffix, target, what) in cases {
        let side = d.join(format!("h.sqlite{suffix}"));
        std::os::unix::fs::symlink(target, &side).unwrap();
        let want = format!(
            "SQLite's {what} beside it, `{}`, is a symbolic link (to `{target}`)",
            side.display()
        );
        for e in [
            Store::open(&path).err(),
            Store::open_or_create(&path).err(),
            Store::open_for_reading(&path).err(),
        ] {
            let e = e.expect("refused").to_string();
            assert!(e.contains(&want), "`{want}` not in: {e}");
        }
        std::fs::remove_file(&side).unwrap();
    }
    // A directory in the log's place.
    std::fs::create_dir(d.join("h.sqlite-wal")).unwrap();
    let e = Store::open_for_reading(&path)
        .expect_err("refused")
        .to_string();
    assert!(e.contains("is a directory"), "{e}");
    std::fs::remove_dir(d.join("h.sqlite-wal")).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
    assert_eq!(std::fs::read(d.join("elsewhere/log")).unwrap(), b"");
    assert_eq!(names_in(&d), ["elsewhere", "h.sqlite"]);
    assert_eq!(Store::open_for_reading(&path).unwrap().count().unwrap(), 2);
}

#[test]
fn threads_with_their_own_connections_lose_no_check() {
    let d = dir("threads");
    let path = d.join("h.sqlite");
    // The threads race to create the file too.
    let threads: Vec<_> = (0..4)
        .map(|t| {
            let path = path.clone();
            std::thread::spawn(move || {
                let mut store = Store::open_or_create(&path).unwrap();
                for i in 0..50 {
                    store
                        .record(&check(&format!("T{t}"), i, i as f64, 0.3))
                        .unwrap();
                }
            })
        })
        .collect();
    for t in threads {
        t.join().unwrap();
    }
    let store = Store::open(&path).unwrap();
    assert_eq!(store.count().unwrap(), 200);
    for t in 0..4 {
        let mine = store.checks(Some(&format!("T{t}"))).unwrap();
        assert_eq!(mine.len(), 50);
        // Every check whole: its parameters, terms and paths.
        for (i, c) in mine.iter().enumerate() {
            assert_eq!(c.check.parameter("XOC").unwrap().value, Some(i as f64));
            assert_eq!(c.check.parameters.len(), 2);
            assert_eq!(c.check.paths, ["K4"]);
        }
    }
    drop(store);
    assert_eq!(names_in(&d), ["h.sqlite"]);
}

/// The environment variable that makes [`child_records_fifty_checks`] record (in a child
/// process of [`processes_recording_at_once_lose_no_check`]).
const CHILD_DB: &str = "RTEST_HISTORY_TEST_CHILD_DB";

#[test]
fn child_records_fifty_checks() {
    let (Ok(db), Ok(id)) = (
        std::env::var(CHILD_DB),
        std::env::var("RTEST_HISTORY_TEST_CHILD_ID"),
    ) else {
        return; // Run as a test of its own: nothing to do.
    };
    let mut store = Store::open_or_create(Path::new(&db)).unwrap();
    for i in 0..50 {
        store.record(&check(&id, i, i as f64, 0.3)).unwrap();
    }
}

#[test]
fn processes_recording_at_once_lose_no_check() {
    let d = dir("processes");
    let path = d.join("h.sqlite");
    let exe = std::env::current_exe().unwrap();
    let children: Vec<_> = (0..3)
        .map(|p| {
            std::process::Command::new(&exe)
                .args([
                    "--exact",
                    "store::child_records_fifty_checks",
                    "--test-threads=1",
                ])
                .env(CHILD_DB, &path)
                .env("RTEST_HISTORY_TEST_CHILD_ID", format!("P{p}"))
                .stdout(std::process::Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect();
    for mut c in children {
        assert!(c.wait().unwrap().success());
    }
    let store = Store::open(&path).unwrap();
    assert_eq!(store.count().unwrap(), 150);
    for p in 0..3 {
        assert_eq!(store.checks(Some(&format!("P{p}"))).unwrap().len(), 50);
    }
}

#[test]
fn a_staged_check_is_recorded_only_when_committed() {
    let d = dir("staged");
    let path = d.join("h.sqlite");
    let mut store = Store::open_or_create(&path).unwrap();
    let staged = store.stage(&check("M1", 0, 1.0, 0.3)).unwrap();
    assert_eq!(staged.id(), 1);
    drop(staged);
    assert_eq!(store.count().unwrap(), 0);
    let id = store
        .stage(&check("M1", 0, 1.0, 0.3))
        .unwrap()
        .commit()
        .unwrap();
    assert_eq!(id, 1);
    assert_eq!(store.count().unwrap(), 1);
    // A check that cannot be recorded: refused, nothing written.
    for (edit, needle) in [
        (
            Box::new(|c: &mut history::Check| c.machine_id.clear())
                as Box<dyn Fn(&mut history::Check)>,
            "machine id is empty",
        ),
        (
            Box::new(|c: &mut history::Check| c.paths.clear()),
            "at least one test path",
        ),
        (
            Box::new(|c: &mut history::Check| c.paths = vec!["K4".into(), "k4".into()]),
            "given twice",
        ),
        (
            Box::new(|c: &mut history::Check| c.parameters[0].value = Some(f64::NAN)),
            "not finite",
        ),
    ] {
        let mut c = check("M1", 1, 1.0, 0.3);
        edit(&mut c);
        let e = store.record(&c).unwrap_err();
        assert!(matches!(e, HistoryError::Invalid { .. }), "{e}");
        assert!(e.to_string().contains(needle), "{e}");
        assert!(e.to_string().contains("h.sqlite"), "{e}");
    }
    assert_eq!(store.count().unwrap(), 1);
}
