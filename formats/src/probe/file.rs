//! A probe file of either kind, told apart by its header: a sphere centres CSV has the column
//! `cx`, a probe hits CSV does not.

use super::centres::read_centres_from;
use super::hits::read_hits_from;
use super::{ProbeHits, SphereCentres};
use crate::csv::CsvError;
use model_spec::Machine;
use model_spec::sha256::{Digest, HashingReader};
use std::io::{BufRead, BufReader, Cursor, Read};
use std::path::Path;

/// The longest prefix (comments and blank lines before the header, and the header) read to
/// tell the kinds apart, bytes; a longer one is read as hits (and refused there if it is not).
const SNIFF_BYTES: usize = 1 << 20;

/// The content of a probe file.
#[derive(Clone, Debug, PartialEq)]
pub enum ProbeFile {
    /// A probe hits CSV.
    Hits(ProbeHits),
    /// A sphere centres CSV.
    Centres(SphereCentres),
}

/// Reads the probe file at `path` of machine `m`: a sphere centres CSV when its header (its
/// first line that is neither blank nor a comment) names a column `cx`, else a probe hits CSV;
/// with the digest of the bytes read (the file is opened once).
///
/// # Errors
/// As [`super::read_probe_hits`] and [`super::read_sphere_centres`].
pub fn read_probe_file(path: &Path, m: &Machine) -> Result<(ProbeFile, Digest), CsvError> {
    let file = path.display().to_string();
    let io = |source| CsvError::Io {
        file: file.clone(),
        source,
    };
    let f = std::fs::File::open(path).map_err(io)?;
    let mut hashing = HashingReader::new(f);
    let content = {
        let mut buffered = BufReader::new(&mut hashing);
        let mut prefix = Vec::new();
        let mut centres = false;
        while prefix.len() < SNIFF_BYTES {
            let start = prefix.len();
            let read = (&mut buffered)
                .take((SNIFF_BYTES - start) as u64)
                .read_until(b'\n', &mut prefix)
                .map_err(io)?;
            if read == 0 {
                break;
            }
            let line = String::from_utf8_lossy(&prefix[start..]);
            let line = line.trim_start_matches('\u{feff}').trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            centres = line
                .split(',')
                .any(|c| c.trim().trim_matches('"').trim().eq_ignore_ascii_case("cx"));
            break;
        }
        let rest = Cursor::new(prefix).chain(buffered);
        if centres {
            ProbeFile::Centres(read_centres_from(&file, rest, m)?)
        } else {
            ProbeFile::Hits(read_hits_from(&file, rest, m)?)
        }
    };
    Ok((content, hashing.digest()))
}
