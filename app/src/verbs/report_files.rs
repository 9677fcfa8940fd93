//! The files the JSON reports of a check name (its records, its machine), as `rtest report`
//! finds and reads them: relative to each report's directory (or `--data-dir`), never outside
//! it, regular files only, bounded, each hashed as read.

use super::{Error, VerbResult};
use model_spec::sha256::Digest;
use report::{InputFile, Inputs};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The bytes of the records `rtest report` read (and of the identification's probe file), by
/// (JSON report, name the report gives), or why a file was not read.
pub(super) type Records = BTreeMap<(String, String), Result<Vec<u8>, String>>;

/// The field of an identification report that names its probe file.
pub(super) const PROBE_FIELD: &str = "probe.file";

/// A file a report names: the report (its file as given), the field, the role in the check,
/// the name, where it is looked for, and the most bytes a file of its kind may have.
pub(super) struct Named {
    json: String,
    field: String,
    role: &'static str,
    name: String,
    at: PathBuf,
    max_bytes: u64,
}

/// Every file the reports name, in the order of the report (identification, validations,
/// diagnosis, compensation), each looked for relative to the directory of its report, or to
/// `data_dir` when it is given.
///
/// # Errors
/// A bad input naming the report, the field and the name, for an absolute name or one that
/// leaves the directory (`..`).
pub(super) fn named_files(inputs: &Inputs, data_dir: Option<&Path>) -> VerbResult<Vec<Named>> {
    use formats::poses::MAX_FILE_BYTES as RECORD;
    use formats::probe::instrument::MAX_PROBE_INSTRUMENT_BYTES as PROBE;
    use report::json::read::MAX_REPORT_BYTES as VALUES;
    let mut raw: Vec<(&str, String, &'static str, &str, u64)> = Vec::new();
    if let Some((f, r)) = &inputs.identification {
        for (i, x) in r.records.iter().enumerate() {
            let field = format!("records[{i}].data");
            raw.push((f, field, "identification: fitted record", &x.data, RECORD));
        }
        if let Some(file) = r.probe.as_ref().and_then(|p| p.file.as_ref()) {
            raw.push((f, PROBE_FIELD.into(), "identification: probe", file, PROBE));
        }
    }
    for (f, v) in &inputs.validations {
        for (i, x) in v.records.iter().enumerate() {
            let field = format!("records[{i}].data");
            raw.push((f, field, "validation: record", &x.data, RECORD));
        }
        raw.push((f, "params".into(), "validation: values", &v.params, VALUES));
    }
    if let Some((f, d)) = &inputs.diagnosis {
        for (i, x) in d.records.iter().enumerate() {
            let role = if x.role == "fitted" {
                "diagnosis: fitted record"
            } else {
                "diagnosis: held-out record"
            };
            raw.push((f, format!("records[{i}].data"), role, &x.data, RECORD));
        }
        if d.records.is_empty() {
            for x in d.data.split(',') {
                raw.push((f, "data".into(), "diagnosis: fitted record", x, RECORD));
            }
            for (i, (x, _)) in d.held_out.iter().enumerate() {
                let field = format!("held_out[{i}]");
                raw.push((f, field, "diagnosis: held-out record", x, RECORD));
            }
        }
    }
    if let Some((f, c)) = &inputs.compensation {
        raw.push((
            f,
            "params_file".into(),
            "compensation: values",
            &c.params_file,
            VALUES,
        ));
        raw.push((
            f,
            "input".into(),
            "compensation: commanded poses",
            &c.input,
            RECORD,
        ));
    }
    raw.into_iter()
        .filter(|(_, _, _, name, _)| !name.is_empty())
        .map(|(json, field, role, name, max_bytes)| {
            let at = resolve(json, &field, name, data_dir)?;
            Ok(Named {
                json: json.to_string(),
                field,
                role,
                name: name.to_string(),
                at,
                max_bytes,
            })
        })
        .collect()
}

/// Where the file `name`, given by field `field` of report `json`, is looked for: relative to
/// the report's directory, or to `data_dir`.
///
/// # Errors
/// A bad input for an absolute name, or one whose `..` leave that directory.
fn resolve(json: &str, field: &str, name: &str, data_dir: Option<&Path>) -> VerbResult<PathBuf> {
    use std::path::Component;
    let (base, dir_words) = match data_dir {
        Some(d) => (d.to_path_buf(), "--data-dir"),
        None => (
            Path::new(json)
                .parent()
                .unwrap_or(Path::new(""))
                .to_path_buf(),
            "the report's directory",
        ),
    };
    let refuse = |what: &str| {
        Error::input(format!(
            "{json}: field `{field}`: `{name}` is {what}: rtest report reads the files a report names relative to {dir_words}, never elsewhere (give the files beside the report, or --data-dir DIR with the names relative to DIR)"
        ))
    };
    let mut depth = 0usize;
    for c in Path::new(name).components() {
        match c {
            Component::Prefix(_) | Component::RootDir => return Err(refuse("an absolute path")),
            Component::CurDir => {}
            Component::ParentDir => {
                depth = depth
                    .checked_sub(1)
                    .ok_or_else(|| refuse(&format!("a path that leaves {dir_words}")))?;
            }
            Component::Normal(_) => depth += 1,
        }
    }
    Ok(base.join(name))
}

/// Reads every regular file of `named` (at most its kind's bytes), hashed as read, and lists
/// it in `files` (once: a file two reports name, or that is given itself, is listed once);
/// anything else (a pipe, a device, a directory, a missing file) is listed as not hashed, and
/// never opened. The records' bytes (and the probe file's) are kept for the figures.
pub(super) fn read_named(named: &[Named], files: &mut Vec<InputFile>) -> Records {
    let mut records = Records::new();
    for n in named {
        let shown = n.at.display().to_string();
        let read = read_regular(&n.at, n.max_bytes);
        if !files.iter().any(|f| same_path(Path::new(&f.path), &n.at)) {
            files.push(match &read {
                Ok((_, digest)) => InputFile::read(n.role, &shown, &n.at, digest.clone()),
                Err(why) => InputFile::not_hashed(n.role, &shown, Some(&n.at), why),
            });
        }
        let kept = (n.field.starts_with("records[") && !n.role.starts_with("diagnosis"))
            || n.field == PROBE_FIELD;
        if kept {
            let at = n.at.display();
            records.insert(
                (n.json.clone(), n.name.clone()),
                read.map(|(bytes, _)| bytes)
                    .map_err(|why| format!("{at}: {why}")),
            );
        }
    }
    records
}

/// Whether `a` and `b` name the same file: equal once `./` prefixes are dropped, or both
/// found and the same file (resolved without opening either).
fn same_path(a: &Path, b: &Path) -> bool {
    let plain = |p: &Path| {
        p.components()
            .filter(|c| *c != std::path::Component::CurDir)
            .collect::<PathBuf>()
    };
    if plain(a) == plain(b) {
        return true;
    }
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// The bytes of the regular file at `path` (at most `max_bytes`) and their digest, or why it
/// is not read (one line): not a regular file (a pipe, a device, a directory, or a link to
/// one: told by `metadata`, and the file is opened without blocking so that one swapped in
/// meanwhile cannot make the report wait), missing, unreadable or too large.
fn read_regular(path: &Path, max_bytes: u64) -> Result<(Vec<u8>, Digest), String> {
    const NOT_REGULAR: &str = "not a regular file";
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot be read here ({e})"))?;
    if !meta.is_file() {
        return Err(NOT_REGULAR.into());
    }
    let mut open = std::fs::OpenOptions::new();
    open.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        open.custom_flags(O_NONBLOCK);
    }
    let file = open
        .open(path)
        .map_err(|e| format!("cannot be read here ({e})"))?;
    if !file.metadata().is_ok_and(|m| m.is_file()) {
        return Err(NOT_REGULAR.into());
    }
    model_spec::text::read_bytes_from(&path.display().to_string(), file, max_bytes).map_err(|e| {
        match e {
            model_spec::text::TextError::TooLarge { limit, .. } => {
                format!("larger than {limit} bytes, the most a file of its kind may have")
            }
            model_spec::text::TextError::Io { error, .. } => {
                format!("cannot be read here ({error})")
            }
            other => other.to_string(),
        }
    })
}

/// `O_NONBLOCK` of `open(2)`: opening a FIFO for reading returns at once instead of waiting
/// for a writer (a regular file reads as without it).
#[cfg(any(target_os = "linux", target_os = "android"))]
const O_NONBLOCK: i32 = 0o4000;
#[cfg(any(
    target_os = "macos",
    target_os = "ios",
    target_os = "freebsd",
    target_os = "netbsd",
    target_os = "openbsd",
    target_os = "dragonfly"
))]
const O_NONBLOCK: i32 = 0x0004;
/// No known `O_NONBLOCK` here: the type told by `metadata` before opening decides alone.
#[cfg(all(
    unix,
    not(any(
        target_os = "linux",
        target_os = "android",
        target_os = "macos",
        target_os = "ios",
        target_os = "freebsd",
        target_os = "netbsd",
        target_os = "openbsd",
        target_os = "dragonfly"
    ))
))]
const O_NONBLOCK: i32 = 0;
