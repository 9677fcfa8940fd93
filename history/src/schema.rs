//! The database's schema and its migrations.
//!
//! The schema version is SQLite's `PRAGMA user_version`; [`MIGRATIONS`]`[k]` takes a database
//! from version `k` to version `k + 1`, and a database is brought to [`VERSION`] by running the
//! ones it lacks, in order, each in the transaction that also sets its version. A new database
//! runs them all. `PRAGMA application_id` is [`APPLICATION_ID`] (the bytes `rtst`): a SQLite
//! file of another program is refused, never changed.
//!
//! Version 1 (the first): `checks` (one row per check), `check_terms`, `check_paths`,
//! `check_inputs`, `parameters` and `unidentifiable` (one row per name of a group the data
//! could not separate). Version 2 adds `checks.measured_at`, the time of the measurement beside
//! the time it was recorded (filled with `recorded_at` in older checks), and an index on
//! `(machine_id, measured_at)`. Version 3 adds `checks.recheck` (1 for a re-check: a few poses
//! refitting the pivot and the preset with everything else held; 0 for every older check).

/// `PRAGMA application_id` of an rtest history database: `rtst` in ASCII.
pub const APPLICATION_ID: i32 = 0x7274_7374;

/// The schema version this rtest writes.
pub const VERSION: i32 = MIGRATIONS.len() as i32;

/// Version 1.
pub const SCHEMA_1: &str = "
CREATE TABLE checks (
    id               INTEGER PRIMARY KEY,
    machine_id       TEXT NOT NULL,
    fingerprint      TEXT NOT NULL,
    machine          TEXT NOT NULL,
    model            TEXT NOT NULL,
    base_model       TEXT,
    recorded_at      TEXT NOT NULL,
    rtest_version    TEXT NOT NULL,
    kind             TEXT NOT NULL CHECK (kind IN ('record', 'campaign')),
    rank             INTEGER NOT NULL,
    free_parameters  INTEGER NOT NULL,
    condition        REAL,
    residual_rms_um  REAL NOT NULL,
    sigma_um         REAL,
    samples          INTEGER NOT NULL,
    dof              INTEGER NOT NULL,
    zeroed           INTEGER NOT NULL,
    constraint_text  TEXT NOT NULL,
    refinement       TEXT NOT NULL,
    noise_model      TEXT
);
CREATE TABLE check_terms (
    check_id  INTEGER NOT NULL REFERENCES checks(id) ON DELETE CASCADE,
    position  INTEGER NOT NULL,
    term      TEXT NOT NULL,
    PRIMARY KEY (check_id, position)
);
CREATE TABLE check_paths (
    check_id  INTEGER NOT NULL REFERENCES checks(id) ON DELETE CASCADE,
    position  INTEGER NOT NULL,
    label     TEXT NOT NULL,
    PRIMARY KEY (check_id, position)
);
CREATE TABLE check_inputs (
    check_id  INTEGER NOT NULL REFERENCES checks(id) ON DELETE CASCADE,
    position  INTEGER NOT NULL,
    role      TEXT NOT NULL,
    path      TEXT NOT NULL,
    bytes     INTEGER NOT NULL,
    sha256    TEXT NOT NULL,
    PRIMARY KEY (check_id, position)
);
CREATE TABLE parameters (
    check_id    INTEGER NOT NULL REFERENCES checks(id) ON DELETE CASCADE,
    position    INTEGER NOT NULL,
    name        TEXT NOT NULL,
    error       TEXT NOT NULL,
    basis       TEXT NOT NULL,
    owner       TEXT,
    owner_of    TEXT,
    value       REAL,
    std         REAL,
    unit        TEXT NOT NULL,
    determined  INTEGER NOT NULL,
    fixed       INTEGER NOT NULL,
    PRIMARY KEY (check_id, position)
);
CREATE TABLE unidentifiable (
    check_id  INTEGER NOT NULL REFERENCES checks(id) ON DELETE CASCADE,
    grp       INTEGER NOT NULL,
    position  INTEGER NOT NULL,
    name      TEXT NOT NULL,
    PRIMARY KEY (check_id, grp, position)
);
CREATE INDEX checks_by_machine ON checks(machine_id, id);
";

/// Version 1 to 2: the time of the measurement.
pub const MIGRATION_2: &str = "
ALTER TABLE checks ADD COLUMN measured_at TEXT NOT NULL DEFAULT '';
UPDATE checks SET measured_at = recorded_at;
CREATE INDEX checks_by_time ON checks(machine_id, measured_at, id);
";

/// Version 2 to 3: re-checks (`checks.recheck`, 1 for a re-check, 0 for every older check).
/// `kind` keeps saying one record or several: a CHECK constraint of version 1 cannot change
/// without rebuilding the table, which its children's foreign keys forbid inside a migration.
pub const MIGRATION_3: &str = "
ALTER TABLE checks ADD COLUMN recheck INTEGER NOT NULL DEFAULT 0 CHECK (recheck IN (0, 1));
";

/// The migrations, in order: `MIGRATIONS[k]` takes version `k` to `k + 1`.
pub const MIGRATIONS: [&str; 3] = [SCHEMA_1, MIGRATION_2, MIGRATION_3];

/// The tables of the current version (a database at [`VERSION`] has exactly these).
pub const TABLES: [&str; 6] = [
    "check_inputs",
    "check_paths",
    "check_terms",
    "checks",
    "parameters",
    "unidentifiable",
];
