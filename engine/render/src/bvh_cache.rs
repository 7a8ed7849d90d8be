//! The BVH cached on disk beside the scene cache, so a path-traced scene
//! whose geometry has not changed skips the build. An entry is named after a
//! hash of the world-space triangles it was built over (FNV-1a of their
//! bytes), and holds that hash again, the triangle count, the nodes and the
//! leaf order. A moved model, a new instance or an edited mesh changes the
//! triangles, hence the name: the BVH is rebuilt exactly when geometry
//! changes. A damaged or foreign entry is a miss, never an error.
//!
//! Layout: magic, format version (u32), hash (u64), triangle count (u64),
//! node count (u64), the nodes as the GPU reads them, the leaf order (u32
//! each); all little endian.

use crate::bvh::{Bvh, GpuBvhNode};
use glam::Vec3;
use std::path::{Path, PathBuf};

/// The first bytes of every entry.
const MAGIC: [u8; 8] = *b"WEFTBVH\0";

/// Bumped whenever the builder's output or the layout changes.
pub const BVH_CACHE_VERSION: u32 = 1;

/// FNV-1a over the triangles' coordinates, the key of their BVH.
pub fn geometry_hash(triangles: &[[Vec3; 3]]) -> u64 {
    bytemuck::cast_slice::<[Vec3; 3], u8>(triangles)
        .iter()
        .fold(0xcbf2_9ce4_8422_2325, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        })
}

/// The entry file for geometry of `hash` in cache folder `dir`.
pub fn entry_for(dir: &Path, hash: u64) -> PathBuf {
    dir.join(format!("bvh-{hash:016x}.weftbvh"))
}

/// The BVH over `triangles`: read from `dir` when an entry for exactly these
/// triangles is there, else built and written there (a failed write only
/// loses the cache). Without a folder it is built.
pub fn load_or_build(triangles: &[[Vec3; 3]], dir: Option<&Path>) -> Bvh {
    let Some(dir) = dir else {
        return Bvh::build(triangles);
    };
    let hash = geometry_hash(triangles);
    let entry = entry_for(dir, hash);
    if let Some(bvh) = std::fs::read(&entry)
        .ok()
        .and_then(|bytes| decode(&bytes, hash, triangles.len()))
    {
        return bvh;
    }
    let bvh = Bvh::build(triangles);
    let _ = write(dir, &entry, &encode(&bvh, hash, triangles.len()));
    bvh
}

fn encode(bvh: &Bvh, hash: u64, triangle_count: usize) -> Vec<u8> {
    let mut bytes = MAGIC.to_vec();
    bytes.extend_from_slice(&BVH_CACHE_VERSION.to_le_bytes());
    bytes.extend_from_slice(&hash.to_le_bytes());
    bytes.extend_from_slice(&(triangle_count as u64).to_le_bytes());
    bytes.extend_from_slice(&(bvh.nodes.len() as u64).to_le_bytes());
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

/// The BVH in `bytes` when it is a current entry for `triangle_count`
/// triangles hashing to `hash`, and every index in it is in range.
fn decode(bytes: &[u8], hash: u64, triangle_count: usize) -> Option<Bvh> {
    let mut r = Reader(bytes.strip_prefix(&MAGIC)?);
    if r.u32()? != BVH_CACHE_VERSION || r.u64()? != hash || r.u64()? != triangle_count as u64 {
        return None;
    }
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
        nodes.push(GpuBvhNode {
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

/// Writes an entry atomically (a temporary file renamed into place).
fn write(dir: &Path, entry: &Path, bytes: &[u8]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let temp = entry.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&temp, bytes)?;
    std::fs::rename(&temp, entry)
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
        let built = load_or_build(&tris, Some(&dir));
        let entry = entry_for(&dir, geometry_hash(&tris));
        assert!(entry.exists());
        assert_eq!(built, Bvh::build(&tris));
        let bytes = std::fs::read(&entry).expect("entry");
        assert_eq!(
            decode(&bytes, geometry_hash(&tris), tris.len()),
            Some(built.clone())
        );
        assert_eq!(load_or_build(&tris, Some(&dir)), built);
        let moved = triangles(0.5);
        assert_ne!(geometry_hash(&moved), geometry_hash(&tris));
        assert_eq!(decode(&bytes, geometry_hash(&moved), moved.len()), None);
        assert_eq!(load_or_build(&moved, Some(&dir)), Bvh::build(&moved));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn damaged_entries_are_misses() {
        let tris = triangles(1.0);
        let bvh = Bvh::build(&tris);
        let hash = geometry_hash(&tris);
        let bytes = encode(&bvh, hash, tris.len());
        assert_eq!(
            decode(&bytes[..bytes.len() - 1], hash, tris.len()),
            None,
            "truncated"
        );
        let mut versioned = bytes.clone();
        versioned[8..12].copy_from_slice(&(BVH_CACHE_VERSION + 1).to_le_bytes());
        assert_eq!(
            decode(&versioned, hash, tris.len()),
            None,
            "another version"
        );
        let mut wild = bytes.clone();
        // The root's `first` pointing past the nodes.
        let at = 8 + 4 + 8 + 8 + 8 + 12;
        wild[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(
            decode(&wild, hash, tris.len()),
            None,
            "an index out of range"
        );
        // A damaged entry in the folder is rebuilt and replaced.
        let dir = temp_dir("damaged");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        std::fs::write(entry_for(&dir, hash), &bytes[..40]).expect("write");
        assert_eq!(load_or_build(&tris, Some(&dir)), bvh);
        assert_eq!(std::fs::read(entry_for(&dir, hash)).expect("entry"), bytes);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
