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
    let f = std::fs::File::open(path).map_err(|source| CsvError::Io {
        file: file.clone(),
        source,
    })?;
    let mut hashing = HashingReader::new(f);
    let content = read_probe_from(&file, &mut hashing, m)?;
    Ok((content, hashing.digest()))
}

/// Reads a probe file of machine `m` (named `file` in messages) from `reader`, told apart as
/// [`read_probe_file`] tells it: the bytes a caller already holds (`&[u8]`) are read as the
/// file was.
///
/// # Errors
/// As [`read_probe_file`].
pub fn read_probe_from(file: &str, reader: impl Read, m: &Machine) -> Result<ProbeFile, CsvError> {
    let io = |source| CsvError::Io {
        file: file.to_string(),
        source,
    };
    let mut buffered = BufReader::new(reader);
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
    Ok(if centres {
        ProbeFile::Centres(read_centres_from(file, rest, m)?)
    } else {
        ProbeFile::Hits(read_hits_from(file, rest, m)?)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bytes held in memory and the file itself are told apart and read alike, a byte-order
    /// mark or a comment before the header notwithstanding.
    #[test]
    fn bytes_and_files_are_told_apart_by_the_header() {
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let hits = "\u{feff}pose,X,Y,Z,A,C,nx,ny,nz,t_s\np1,0,0,0,0,0,1,0,0,0\n";
        let centres = "# from the CMM\npose,X,Y,Z,A,C,cx,cy,cz\np1,0,0,0,0,0,0.001,0,0\n";
        assert!(matches!(
            read_probe_from("h.csv", hits.as_bytes(), &m).unwrap(),
            ProbeFile::Hits(_)
        ));
        let read = read_probe_from("c.csv", centres.as_bytes(), &m);
        assert!(matches!(read, Ok(ProbeFile::Centres(_))), "{read:?}");
        let dir = std::env::temp_dir().join(format!("rtest-probe-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("c.csv");
        std::fs::write(&path, centres).unwrap();
        let (from_file, digest) = read_probe_file(&path, &m).unwrap();
        assert_eq!(from_file, read.unwrap());
        assert_eq!(digest.bytes, centres.len() as u64);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
