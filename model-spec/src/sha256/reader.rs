//! [`HashingReader`]: a reader that hashes every byte it hands out. A long file's bytes are
//! hashed on a thread of their own while the parser reads on (SHA-256 of a 143 MB measurement
//! CSV is about half a second, a quarter of reading it), so that hashing costs a long read no
//! time where a second core is free; a short one is hashed as it is read.

use super::{Digest, Sha256};
use std::io::Read;
use std::sync::mpsc::{Receiver, SyncSender, channel, sync_channel};
use std::thread;

/// Bytes hashed as they are read before the rest goes to a hashing thread: a file shorter than
/// this never starts one.
const HASH_HERE: u64 = 4 << 20;

/// Bytes handed to the hashing thread at once.
const CHUNK: usize = 1 << 20;

/// Chunks waiting for the hashing thread at most (the reader waits beyond: bounded memory).
const QUEUE: usize = 8;

/// What the hashing thread is asked.
enum Job {
    /// Hash these bytes next.
    Bytes(Vec<u8>),
    /// Send back the hash of every byte sent before.
    Snapshot(std::sync::mpsc::Sender<Sha256>),
}

/// The hashing thread: the queue to it.
#[derive(Debug)]
struct Behind {
    to: SyncSender<Job>,
}

impl Behind {
    /// Starts a thread that goes on from `hash` with the bytes it is sent; `None` when the
    /// system has no thread to give (the bytes are then hashed as they are read).
    fn start(hash: Sha256) -> Option<Behind> {
        let (to, from) = sync_channel(QUEUE);
        thread::Builder::new()
            .name("sha256".into())
            .spawn(move || hash_jobs(hash, from))
            .ok()?;
        Some(Behind { to })
    }

    /// Sends `job`. The thread ends only when the queue closes (hashing cannot fail), so a
    /// send that fails is a broken invariant, not an input's fault.
    fn send(&self, job: Job) {
        if self.to.send(job).is_err() {
            panic!("the SHA-256 thread ended while its reader was reading");
        }
    }

    /// The hash of every byte sent so far.
    fn snapshot(&self) -> Sha256 {
        let (reply, answer) = channel();
        self.send(Job::Snapshot(reply));
        answer
            .recv()
            .unwrap_or_else(|_| panic!("the SHA-256 thread ended while its reader was reading"))
    }
}

/// Hashes the bytes of `jobs` in order after those of `hash`, until the queue closes.
fn hash_jobs(mut hash: Sha256, jobs: Receiver<Job>) {
    for job in jobs {
        match job {
            Job::Bytes(b) => hash.update(&b),
            Job::Snapshot(reply) => {
                // A reader that stopped waiting needs no answer.
                let _ = reply.send(hash.clone());
            }
        }
    }
}

/// A reader that hashes every byte it hands out: wrap the source a parser reads, and the
/// [`HashingReader::digest`] after the parser is done is that of exactly what it read (of the
/// whole file when it read to the end). After the first 4 MiB, the bytes are hashed on a
/// thread of their own, in chunks of 1 MiB, while the parser reads on; the digest is the same.
#[derive(Debug)]
pub struct HashingReader<R> {
    inner: R,
    /// The hash of the bytes read, or of those read before the hashing thread started.
    hash: Sha256,
    /// Bytes read and not yet sent to the hashing thread.
    pending: Vec<u8>,
    /// The hashing thread, once started.
    behind: Option<Behind>,
    /// No hashing thread could be started: every byte is hashed here.
    alone: bool,
    bytes: u64,
}

impl<R> HashingReader<R> {
    /// Hashes what is read from `inner`.
    pub fn new(inner: R) -> HashingReader<R> {
        HashingReader {
            inner,
            hash: Sha256::new(),
            pending: Vec::new(),
            behind: None,
            alone: false,
            bytes: 0,
        }
    }

    /// The digest of the bytes read so far.
    pub fn digest(&self) -> Digest {
        let mut hash = match &self.behind {
            None => self.hash.clone(),
            Some(behind) => behind.snapshot(),
        };
        hash.update(&self.pending);
        Digest {
            bytes: self.bytes,
            sha256: hash.hex(),
        }
    }

    /// Hashes `bytes`, just handed out: here while no more than [`HASH_HERE`] were read (or
    /// when no thread could be started), else queued for the hashing thread.
    fn take(&mut self, bytes: &[u8]) {
        self.bytes += bytes.len() as u64;
        if self.behind.is_none() && self.bytes > HASH_HERE && !self.alone {
            match Behind::start(self.hash.clone()) {
                Some(b) => self.behind = Some(b),
                None => self.alone = true,
            }
        }
        let Some(behind) = &self.behind else {
            self.hash.update(bytes);
            return;
        };
        self.pending.extend_from_slice(bytes);
        if self.pending.len() >= CHUNK {
            let chunk = std::mem::replace(&mut self.pending, Vec::with_capacity(CHUNK));
            behind.send(Job::Bytes(chunk));
        }
    }
}

impl<R: Read> Read for HashingReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.take(&buf[..n]);
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hashing_reader_hashes_what_it_hands_out() {
        let bytes: Vec<u8> = (0..200_000u32).map(|i| (i % 251) as u8).collect();
        let mut r = HashingReader::new(&bytes[..]);
        // Read in uneven pieces, stopping short of the end: the digest is of what was read.
        let mut buf = [0u8; 777];
        let mut taken = 0usize;
        while taken < 150_000 {
            taken += r.read(&mut buf).unwrap();
        }
        assert_eq!(r.digest(), Digest::of(&bytes[..taken]));
        std::io::copy(&mut r, &mut std::io::sink()).unwrap();
        assert_eq!(r.digest(), Digest::of(&bytes));
        assert_eq!(r.digest().bytes, 200_000);
    }

    /// A file long enough to be hashed on a thread: read in uneven pieces, with digests asked
    /// on the way (before the thread starts, just after, mid-chunk) and at the end, each that
    /// of the bytes read so far.
    #[test]
    fn a_long_read_hashed_on_a_thread_has_the_digest_of_its_bytes() {
        let bytes: Vec<u8> = (0..11_000_037u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        let mut r = HashingReader::new(&bytes[..]);
        let mut buf = vec![0u8; 65_537];
        let mut taken = 0usize;
        let mut asked = 0;
        for stop in [1_000_000, (HASH_HERE as usize) + 10, 7_654_321, bytes.len()] {
            while taken < stop {
                let n = r.read(&mut buf[..(stop - taken).min(65_537)]).unwrap();
                taken += n;
            }
            assert_eq!(
                r.digest(),
                Digest::of(&bytes[..taken]),
                "after {taken} bytes"
            );
            asked += 1;
        }
        assert!(r.behind.is_some(), "the thread never started");
        assert_eq!(asked, 4);
        assert_eq!(r.read(&mut buf).unwrap(), 0);
        assert_eq!(r.digest(), Digest::of(&bytes));
    }
}
