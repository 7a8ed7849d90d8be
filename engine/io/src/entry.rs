//! Cache entries that prove what they serve. Every entry weft writes (models,
//! SPIR-V, BVHs, reference images) is framed by one header:
//!
//! ```text
//! magic "WEFTCACH" | kind (8 bytes) | format version (u32 LE)
//! | key length (u32 LE) | key | payload length (u64 LE)
//! | payload checksum (XXH3-128, LE) | payload
//! ```
//!
//! The key is the full key the entry was stored under (a model's absolute
//! path, the digest of a shader's inputs), so an entry copied or swapped onto
//! another's name is noticed, and the checksum catches truncation and flipped
//! bits. Reading refuses anything that is not a regular file. A damaged entry
//! is a miss with one warning, and the caller writes it again
//! ([`write_atomic`]: written aside and renamed into place, so readers never
//! see half an entry and concurrent writers never mix theirs).

use crate::hash::hash;
use crate::read::{read_capped, ReadError};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

const MAGIC: &[u8; 8] = b"WEFTCACH";

/// What an entry is for, checked as its first field after the magic.
#[derive(Debug, Clone, Copy)]
pub struct Kind {
    /// Up to 8 ASCII bytes naming the cache (`model`, `spirv`, `bvh`, `ref`).
    pub name: &'static str,
    /// Bumped whenever the payload's encoding or meaning changes.
    pub version: u32,
}

impl Kind {
    fn tag(&self) -> [u8; 8] {
        let mut tag = [0u8; 8];
        let name = self.name.as_bytes();
        tag[..name.len().min(8)].copy_from_slice(&name[..name.len().min(8)]);
        tag
    }
}

/// Why an entry was not used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Damage {
    #[error("it is not a weft cache entry")]
    NotAnEntry,
    #[error("it is a {found} entry, not a {expected} one")]
    OtherKind {
        found: String,
        expected: &'static str,
    },
    #[error("it has format version {found}, not {expected}")]
    OtherVersion { found: u32, expected: u32 },
    #[error("it was stored for another input")]
    OtherKey,
    #[error("it is truncated ({found} of {expected} payload bytes)")]
    Truncated { found: u64, expected: u64 },
    #[error("it has {0} bytes after its payload")]
    Trailing(u64),
    #[error("its checksum does not match its payload")]
    Checksum,
    #[error("{0}")]
    Unreadable(String),
}

/// The entry's bytes: header, then `payload`.
pub fn encode(kind: Kind, key: &[u8], payload: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(64 + key.len() + payload.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&kind.tag());
    bytes.extend_from_slice(&kind.version.to_le_bytes());
    bytes.extend_from_slice(&(key.len() as u32).to_le_bytes());
    bytes.extend_from_slice(key);
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&hash(payload).to_le_bytes());
    bytes.extend_from_slice(payload);
    bytes
}

/// The payload of an entry written by [`encode`] with the same kind and key.
pub fn decode<'a>(bytes: &'a [u8], kind: Kind, key: &[u8]) -> Result<&'a [u8], Damage> {
    let mut rest = bytes;
    let mut take = |n: usize| -> Option<&'a [u8]> {
        let (head, tail) = rest.split_at_checked(n)?;
        rest = tail;
        Some(head)
    };
    if take(8) != Some(MAGIC) {
        return Err(Damage::NotAnEntry);
    }
    let tag = take(8).ok_or(Damage::NotAnEntry)?;
    if tag != kind.tag() {
        let found = String::from_utf8_lossy(tag)
            .trim_end_matches('\0')
            .to_string();
        return Err(Damage::OtherKind {
            found,
            expected: kind.name,
        });
    }
    let u32_at = |b: Option<&[u8]>| b.and_then(|b| b.try_into().ok()).map(u32::from_le_bytes);
    let version = u32_at(take(4)).ok_or(Damage::NotAnEntry)?;
    if version != kind.version {
        return Err(Damage::OtherVersion {
            found: version,
            expected: kind.version,
        });
    }
    let key_len = u32_at(take(4)).ok_or(Damage::OtherKey)? as usize;
    if take(key_len) != Some(key) {
        return Err(Damage::OtherKey);
    }
    let expected = take(8)
        .and_then(|b| b.try_into().ok())
        .map(u64::from_le_bytes)
        .ok_or(Damage::Truncated {
            found: 0,
            expected: 0,
        })?;
    let checksum = take(16)
        .and_then(|b| b.try_into().ok())
        .map(u128::from_le_bytes)
        .ok_or(Damage::Truncated { found: 0, expected })?;
    let found = rest.len() as u64;
    if found < expected {
        return Err(Damage::Truncated { found, expected });
    }
    if found > expected {
        return Err(Damage::Trailing(found - expected));
    }
    if hash(rest) != checksum {
        return Err(Damage::Checksum);
    }
    Ok(rest)
}

/// Reads the entry at `path`: `Ok(None)` when there is none, the payload when
/// it is sound, and why not otherwise (not a regular file, too large, damaged).
pub fn read(path: &Path, kind: Kind, key: &[u8], limit: u64) -> Result<Option<Vec<u8>>, Damage> {
    let bytes = match read_capped(path, limit) {
        Ok(bytes) => bytes,
        Err(ReadError::Missing { .. }) => return Ok(None),
        Err(ReadError::NotRegular { kind: k, .. }) => {
            return Err(Damage::Unreadable(format!("it is {}", k.describe())))
        }
        Err(ReadError::TooLarge { size, limit, .. }) => {
            return Err(Damage::Unreadable(format!(
                "it is {size} bytes, over the limit of {limit}"
            )))
        }
        Err(e) => return Err(Damage::Unreadable(e.to_string())),
    };
    decode(&bytes, kind, key).map(|payload| Some(payload.to_vec()))
}

/// Writes `bytes` to `path` through a file of its own beside it, renamed into
/// place: a reader sees the old entry or the new one, never part of one, and
/// writers in several processes or threads never interleave. Creates the folder.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    static WRITES: AtomicU64 = AtomicU64::new(0);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    let mut partial = path.as_os_str().to_owned();
    partial.push(format!(
        ".partial-{}-{}",
        std::process::id(),
        WRITES.fetch_add(1, Ordering::Relaxed)
    ));
    let partial = std::path::PathBuf::from(partial);
    let written = std::fs::write(&partial, bytes).and_then(|()| std::fs::rename(&partial, path));
    if written.is_err() {
        let _ = std::fs::remove_file(&partial);
    }
    written
}

/// Encodes and writes an entry ([`encode`], [`write_atomic`]).
pub fn write(path: &Path, kind: Kind, key: &[u8], payload: &[u8]) -> std::io::Result<()> {
    write_atomic(path, &encode(kind, key, payload))
}

#[cfg(test)]
mod tests {
    use super::*;

    const KIND: Kind = Kind {
        name: "test",
        version: 3,
    };

    #[test]
    fn every_kind_of_damage_is_a_named_miss() {
        let good = encode(KIND, b"key", b"payload bytes");
        assert_eq!(decode(&good, KIND, b"key"), Ok(&b"payload bytes"[..]));
        assert_eq!(decode(&good, KIND, b"other"), Err(Damage::OtherKey));
        let other_kind = Kind {
            name: "spirv",
            version: 3,
        };
        assert!(matches!(
            decode(&good, other_kind, b"key"),
            Err(Damage::OtherKind { .. })
        ));
        let newer = Kind {
            name: "test",
            version: 4,
        };
        assert_eq!(
            decode(&good, newer, b"key"),
            Err(Damage::OtherVersion {
                found: 3,
                expected: 4
            })
        );
        assert_eq!(decode(b"", KIND, b"key"), Err(Damage::NotAnEntry));
        assert_eq!(
            decode(&good[..good.len() - 3], KIND, b"key"),
            Err(Damage::Truncated {
                found: 10,
                expected: 13
            })
        );
        // Every single flipped bit, anywhere in the entry, is caught.
        for byte in 0..good.len() {
            for bit in 0..8 {
                let mut bad = good.clone();
                bad[byte] ^= 1 << bit;
                assert!(decode(&bad, KIND, b"key").is_err(), "byte {byte} bit {bit}");
            }
        }
        let mut longer = good.clone();
        longer.push(0);
        assert_eq!(decode(&longer, KIND, b"key"), Err(Damage::Trailing(1)));
    }

    #[test]
    fn reads_refuse_devices_and_folders_and_writes_are_atomic() {
        let dir = std::env::temp_dir().join(format!("weft-io-entry-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let path = dir.join("sub/e.bin");
        assert_eq!(read(&path, KIND, b"k", 1 << 20), Ok(None), "no entry yet");
        write(&path, KIND, b"k", b"abc").expect("write");
        assert_eq!(read(&path, KIND, b"k", 1 << 20), Ok(Some(b"abc".to_vec())));
        let names: Vec<_> = std::fs::read_dir(dir.join("sub"))
            .expect("dir")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, ["e.bin"], "no partial file left behind");
        std::fs::remove_file(&path).expect("rm");
        std::os::unix::fs::symlink("/dev/zero", &path).expect("link");
        assert_eq!(
            read(&path, KIND, b"k", 1 << 20),
            Err(Damage::Unreadable("it is a device".into()))
        );
        write(&path, KIND, b"k", b"abc").expect("a link is replaced");
        assert_eq!(read(&path, KIND, b"k", 1 << 20), Ok(Some(b"abc".to_vec())));
        std::fs::remove_file(&path).expect("rm");
        std::fs::create_dir(&path).expect("a folder in the entry's place");
        assert_eq!(
            read(&path, KIND, b"k", 1 << 20),
            Err(Damage::Unreadable("it is a directory".into()))
        );
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    mod damage {
        use super::super::*;
        use proptest::prelude::*;

        const KIND: Kind = Kind {
            name: "prop",
            version: 1,
        };

        /// One way an entry is damaged on disk.
        #[derive(Debug, Clone)]
        enum Damage {
            Truncate(usize),
            Flip(usize, u8),
            Splice(usize, Vec<u8>),
            Replace(Vec<u8>),
        }

        fn damage() -> impl Strategy<Value = Damage> {
            prop_oneof![
                any::<usize>().prop_map(Damage::Truncate),
                (any::<usize>(), 1u8..=255).prop_map(|(at, mask)| Damage::Flip(at, mask)),
                (
                    any::<usize>(),
                    proptest::collection::vec(any::<u8>(), 1..16)
                )
                    .prop_map(|(at, bytes)| Damage::Splice(at, bytes)),
                proptest::collection::vec(any::<u8>(), 0..128).prop_map(Damage::Replace),
            ]
        }

        fn apply(entry: &[u8], damage: &Damage) -> Vec<u8> {
            let mut bytes = entry.to_vec();
            match damage {
                Damage::Truncate(at) => bytes.truncate(at % bytes.len()),
                Damage::Flip(at, mask) => {
                    let at = at % bytes.len();
                    bytes[at] ^= mask;
                }
                Damage::Splice(at, extra) => {
                    let at = at % (bytes.len() + 1);
                    bytes.splice(at..at, extra.iter().copied());
                }
                Damage::Replace(other) => bytes = other.clone(),
            }
            bytes
        }

        proptest! {
            #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

            /// Whatever happens to an entry, reading it gives the payload
            /// that was stored under this key, or an error: never other bytes.
            #[test]
            fn damaged_entries_never_yield_other_bytes(
                key in proptest::collection::vec(any::<u8>(), 0..40),
                payload in proptest::collection::vec(any::<u8>(), 0..300),
                other_key in proptest::collection::vec(any::<u8>(), 0..40),
                damages in proptest::collection::vec(damage(), 1..4),
            ) {
                let entry = encode(KIND, &key, &payload);
                let mut damaged = entry.clone();
                for d in &damages {
                    if damaged.is_empty() {
                        break;
                    }
                    damaged = apply(&damaged, d);
                }
                match decode(&damaged, KIND, &key) {
                    Ok(read) => prop_assert_eq!(read, &payload[..]),
                    Err(_) => prop_assert_ne!(&damaged, &entry),
                }
                if other_key != key {
                    prop_assert!(decode(&entry, KIND, &other_key).is_err());
                }
            }
        }
    }
}
