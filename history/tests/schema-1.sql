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
