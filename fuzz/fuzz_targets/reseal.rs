//! Shared by the checkpoint and partial targets: both formats end in an FNV-1a checksum of
//! every byte before it, which a random mutation almost never keeps.

use std::hash::Hasher;

/// `data` with its last eight bytes replaced by the FNV-1a checksum of the rest (`None` when
/// it is shorter than a checksum), so that mutations reach the field checks behind it.
pub fn resealed(data: &[u8]) -> Option<Vec<u8>> {
    let body = data.len().checked_sub(8).map(|n| &data[..n])?;
    let mut hash = fnv::FnvHasher::default();
    hash.write(body);
    let mut out = body.to_vec();
    out.extend_from_slice(&hash.finish().to_le_bytes());
    Some(out)
}
