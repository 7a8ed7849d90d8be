//! The BVH cached on disk beside the scene cache, so a path-traced scene
//! whose geometry has not changed skips the build. An entry is named after
//! the hash ([`weft_io::hash`]) of the world-space triangles it was built
//! over, and is framed by [`weft_io::entry`] with that hash and the triangle
//! count as its key and a checksum: a moved model, a new instance or an
//! edited mesh changes the triangles, hence the name, so the BVH is rebuilt
//! exactly when geometry changes; a damaged or foreign entry is a miss with a
//! warning, never an error, and is replaced.
//!
//! Payload: node count (u64), the nodes as the GPU reads them, the leaf order
//! (u32 each); all little endian.

use crate::bvh::{Bvh, BvhNode};
use glam::Vec3;
use std::path::{Path, PathBuf};

/// The entry kind of BVHs; its version is bumped whenever the builder's
/// output or the layout changes.
const KIND: weft_io::entry::Kind = weft_io::entry::Kind {
    name: "bvh",
    version: 2,
};

/// The largest entry read (a BVH of 2^26 triangles is about 1.5 GiB).
const MAX_ENTRY_BYTES: u64 = 4 << 30;

/// The hash of the triangles' coordinates, the key of their BVH.
pub fn geometry_hash(triangles: &[[Vec3; 3]]) -> u128 {
    weft_io::hash::hash(bytemuck::cast_slice::<[Vec3; 3], u8>(triangles))
}

/// The entry file for geometry of `hash` in cache folder `dir`.
pub fn entry_for(dir: &Path, hash: u128) -> PathBuf {
    dir.join(format!("bvh-{}.weftbvh", weft_io::hash::hex(hash)))
}

/// The full key of an entry: the geometry's hash and its triangle count.
fn key(hash: u128, triangle_count: usize) -> [u8; 24] {
    let mut key = [0u8; 24];
    key[..16].copy_from_slice(&hash.to_le_bytes());
    key[16..].copy_from_slice(&(triangle_count as u64).to_le_bytes());
    key
}

/// The BVH over `triangles`: read from `dir` when an entry for exactly these
/// triangles is there, else built and written there (a failed write only
/// loses the cache). Without a folder it is built. The warning, if any, says
/// why an entry that was there could not be used or written.
pub fn load_or_build(triangles: &[[Vec3; 3]], dir: Option<&Path>) -> (Bvh, Option<String>) {
    let Some(dir) = dir else {
        return (Bvh::build(triangles), None);
    };
    let hash = geometry_hash(triangles);
    let entry = entry_for(dir, hash);
    let key = key(hash, triangles.len());
    let damaged = |why: &str| {
        format!(
            "the BVH cache entry {} is damaged ({why}); built again",
            entry.display()
        )
    };
    let mut warning = match weft_io::entry::read(&entry, KIND, &key, MAX_ENTRY_BYTES) {
        Ok(Some(payload)) => match decode(&payload, triangles.len()) {
            Some(bvh) => return (bvh, None),
            None => Some(damaged("its nodes are out of range")),
        },
        Ok(None) => None,
        Err(damage) => Some(damaged(&damage.to_string())),
    };
    let bvh = Bvh::build(triangles);
    if let Err(e) = weft_io::entry::write(&entry, KIND, &key, &encode(&bvh)) {
        warning = Some(format!(
            "cannot write the BVH cache {}: {e}",
            entry.display()
        ));
    }
    (bvh, warning)
}

fn encode(bvh: &Bvh) -> Vec<u8> {
    let mut bytes = (bvh.nodes.len() as u64).to_le_bytes().to_vec();
    for node in &bvh.nodes {
        for v in node.min {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&node.first.to_le_bytes());
        for v in node.max {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&node.count.to_le_bytes());
    }
    for t in &bvh.triangles {
        bytes.extend_from_slice(&t.to_le_bytes());
    }
    bytes
}

/// Reads little-endian words off the front of a byte slice.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn u32(&mut self) -> Option<u32> {
        let (word, rest) = self.0.split_first_chunk::<4>()?;
        self.0 = rest;
        Some(u32::from_le_bytes(*word))
    }

    fn f32(&mut self) -> Option<f32> {
        self.u32().map(f32::from_bits)
    }

    fn u64(&mut self) -> Option<u64> {
        let (word, rest) = self.0.split_first_chunk::<8>()?;
        self.0 = rest;
        Some(u64::from_le_bytes(*word))
    }
}

/// The BVH in an entry's payload for `triangle_count` triangles, when every
/// index in it is in range.
fn decode(bytes: &[u8], triangle_count: usize) -> Option<Bvh> {
    let mut r = Reader(bytes);
    let node_count = usize::try_from(r.u64()?).ok()?;
    if r.0.len()
        != node_count
            .checked_mul(32)?
            .checked_add(triangle_count.checked_mul(4)?)?
    {
        return None;
    }
    let mut nodes = Vec::with_capacity(node_count);
    for _ in 0..node_count {
        let min = [r.f32()?, r.f32()?, r.f32()?];
        let first = r.u32()?;
        let max = [r.f32()?, r.f32()?, r.f32()?];
        let count = r.u32()?;
        nodes.push(BvhNode {
            min,
            first,
            max,
            count,
        });
    }
    let triangles: Vec<u32> = (0..triangle_count)
        .map(|_| r.u32())
        .collect::<Option<_>>()?;
    let sound = nodes.iter().all(|n| {
        let (first, count) = (n.first as usize, n.count as usize);
        if count == 0 {
            first + 1 < node_count || (node_count == 1 && triangle_count == 0)
        } else {
            first + count <= triangle_count
        }
    }) && triangles.iter().all(|&t| (t as usize) < triangle_count);
    sound.then_some(Bvh { nodes, triangles })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangles(offset: f32) -> Vec<[Vec3; 3]> {
        (0..200)
            .map(|i| {
                let p = Vec3::new(
                    i as f32 * 0.37 + offset,
                    (i * 7 % 13) as f32,
                    (i % 5) as f32,
                );
                [p, p + Vec3::X, p + Vec3::Y]
            })
            .collect()
    }

    fn temp_dir(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("weft-bvh-cache-{name}-{}", std::process::id()))
    }

    #[test]
    fn a_cached_bvh_is_the_built_one_and_other_geometry_misses() {
        let dir = temp_dir("roundtrip");
        let _ = std::fs::remove_dir_all(&dir);
        let tris = triangles(0.0);
        let (built, warning) = load_or_build(&tris, Some(&dir));
        assert_eq!(warning, None);
        let entry = entry_for(&dir, geometry_hash(&tris));
        assert!(entry.exists());
        assert_eq!(built, Bvh::build(&tris));
        assert_eq!(load_or_build(&tris, Some(&dir)), (built.clone(), None));
        let moved = triangles(0.5);
        assert_ne!(geometry_hash(&moved), geometry_hash(&tris));
        assert_eq!(
            load_or_build(&moved, Some(&dir)),
            (Bvh::build(&moved), None)
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn damaged_entries_are_rebuilt_with_a_warning_and_replaced() {
        let tris = triangles(1.0);
        let bvh = Bvh::build(&tris);
        let payload = encode(&bvh);
        assert_eq!(decode(&payload, tris.len()), Some(bvh.clone()));
        assert_eq!(
            decode(&payload[..payload.len() - 1], tris.len()),
            None,
            "truncated"
        );
        let mut wild = payload.clone();
        // The root's `first` pointing past the nodes.
        let at = 8 + 12;
        wild[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(decode(&wild, tris.len()), None, "an index out of range");

        let dir = temp_dir("damaged");
        let _ = std::fs::remove_dir_all(&dir);
        let entry = entry_for(&dir, geometry_hash(&tris));
        load_or_build(&tris, Some(&dir));
        let good = std::fs::read(&entry).expect("entry");
        let other = triangles(2.0);
        load_or_build(&other, Some(&dir));
        let foreign = std::fs::read(entry_for(&dir, geometry_hash(&other))).expect("entry");
        let mut flipped = good.clone();
        let last = flipped.len() - 1;
        flipped[last] ^= 1;
        for (why, bytes) in [
            ("truncated", good[..good.len() - 9].to_vec()),
            ("checksum", flipped),
            ("stored for another input", foreign),
            ("not a weft cache entry", Vec::new()),
        ] {
            std::fs::write(&entry, &bytes).expect("damage");
            let (read, warning) = load_or_build(&tris, Some(&dir));
            assert_eq!(read, bvh, "{why}");
            assert!(
                warning.as_deref().is_some_and(|w| w.contains(why)),
                "{why}: {warning:?}"
            );
            assert_eq!(
                std::fs::read(&entry).expect("entry"),
                good,
                "{why}: replaced"
            );
        }
        std::fs::remove_file(&entry).expect("rm");
        std::os::unix::fs::symlink("/dev/zero", &entry).expect("link");
        let (read, warning) = load_or_build(&tris, Some(&dir));
        assert_eq!(read, bvh);
        assert!(warning.is_some_and(|w| w.contains("it is a device")));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
