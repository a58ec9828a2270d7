//! Checkpoints: a film's accumulated sums saved to a file, so that a long render can stop and
//! continue later to exactly the image an uninterrupted render would have made.
//!
//! The format is small and our own, little-endian throughout:
//!
//! ```text
//! magic        8 bytes  "OBSCKPT\0"
//! version      u32      CHECKPOINT_VERSION
//! fingerprint  u64      scene_fingerprint(): what determines the image, sampler values included
//! spp          u32      samples per pixel the render is going to
//! passes_done  u32      complete passes in the sums (<= spp)
//! bounds       4 x u32  x0, y0, x1, y1 of the film's pixel bounds
//! sums         (x1 - x0) (y1 - y0) x 5 i128: radiance r, g, b, weight, coverage, row by row
//! checksum     u64      FNV-1a of every byte before it
//! ```
//!
//! A render is a fixed sequence of passes (pass `k` takes sample `k` of every pixel) and the sums
//! are the film's exact fixed-point integers ([`PixelSums`]), so continuing from a checkpoint
//! adds exactly what the uninterrupted render would have added. Version 1 held f64 sums, which
//! this build's films no longer keep; such checkpoints are refused by their version.
//!
//! A slice's partial film ([`crate::Partial`]) uses the same sums and checksum.

use crate::error::RenderError;
use crate::film::{Film, PixelRect, PixelSums};
use crate::scene::SceneDescription;
use std::path::Path;

/// The first eight bytes of a checkpoint file.
pub const CHECKPOINT_MAGIC: [u8; 8] = *b"OBSCKPT\0";

/// The format version this build reads and writes.
pub const CHECKPOINT_VERSION: u32 = 2;

/// Bytes before the sums: magic, version, fingerprint, spp, passes, bounds.
const HEADER_BYTES: usize = 8 + 4 + 8 + 4 + 4 + 16;

/// A film part-way through a render, with what identifies the render it belongs to.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// [`scene_fingerprint`] of the scene and settings.
    pub fingerprint: u64,
    /// Samples per pixel the render is going to.
    pub samples_per_pixel: u32,
    /// Complete passes (samples per pixel) in `film`.
    pub passes_done: u32,
    /// The accumulated sums.
    pub film: Film,
}

/// 64-bit FNV-1a: a stable hash (unlike std's, which may change between Rust releases).
fn fnv1a(mut hash: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// A fingerprint of everything that determines the image: the scene file's bytes, every
/// setting after the command line's overrides (resolution, filter, sampler, spp, seed,
/// integrator, camera, materials, shapes, lights), which values this build's samplers give
/// ([`obscura_sample::SEQUENCE_VERSION`]) and which its path tracer gives
/// ([`obscura_shade::ESTIMATOR_VERSION`]). Thread counts do not enter: they do not change the
/// image. Files the scene names (meshes, environment maps) enter by path only.
pub fn scene_fingerprint(source: &[u8], description: &SceneDescription) -> u64 {
    fingerprint_with(
        source,
        description,
        [
            obscura_sample::SEQUENCE_VERSION,
            obscura_shade::ESTIMATOR_VERSION,
        ],
    )
}

/// [`scene_fingerprint`] for a build whose samplers' and path tracer's values are
/// `[sequence_version, estimator_version]`.
fn fingerprint_with(source: &[u8], description: &SceneDescription, versions: [u32; 2]) -> u64 {
    let d = description;
    let [sequence_version, estimator_version] = versions;
    let settings = format!(
        "{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|sequences {sequence_version}|estimator {estimator_version}",
        d.film, d.sampler, d.integrator, d.camera, d.materials, d.shapes, d.lights
    );
    let hash = fnv1a(FNV_OFFSET, &(source.len() as u64).to_le_bytes());
    let hash = fnv1a(hash, source);
    fnv1a(hash, settings.as_bytes())
}

impl Checkpoint {
    /// The checkpoint's bytes, in the format of the module documentation.
    pub fn to_bytes(&self) -> Vec<u8> {
        let b = self.film.bounds();
        let sums = self.film.sums();
        let mut out = Vec::with_capacity(HEADER_BYTES + sums.len() * SUM_BYTES + 8);
        out.extend_from_slice(&CHECKPOINT_MAGIC);
        out.extend_from_slice(&CHECKPOINT_VERSION.to_le_bytes());
        out.extend_from_slice(&self.fingerprint.to_le_bytes());
        out.extend_from_slice(&self.samples_per_pixel.to_le_bytes());
        out.extend_from_slice(&self.passes_done.to_le_bytes());
        for v in [b.x0, b.y0, b.x1, b.y1] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        put_sums(&mut out, sums);
        seal(&mut out);
        out
    }

    /// Reads a checkpoint from its bytes; `file` names it in errors. Wrong magic, another
    /// version, a truncated or padded file, a bad checksum and inconsistent fields are errors,
    /// never panics.
    pub fn from_bytes(bytes: &[u8], file: &Path) -> Result<Checkpoint, RenderError> {
        let bad = |message: String| RenderError::Checkpoint {
            file: file.to_path_buf(),
            message,
        };
        if bytes.len() < 8 || bytes[..8] != CHECKPOINT_MAGIC {
            return Err(bad("not an obscura checkpoint (wrong magic bytes)".into()));
        }
        if bytes.len() < HEADER_BYTES + 8 {
            return Err(bad(format!(
                "truncated: {} bytes, shorter than the header",
                bytes.len()
            )));
        }
        let mut reader = Reader { bytes, at: 8 };
        let version = reader.u32();
        if version != CHECKPOINT_VERSION {
            return Err(bad(format!(
                "format version {version}, this obscura reads version {CHECKPOINT_VERSION}"
            )));
        }
        let fingerprint = reader.u64();
        let samples_per_pixel = reader.u32();
        let passes_done = reader.u32();
        let bounds = PixelRect {
            x0: reader.u32(),
            y0: reader.u32(),
            x1: reader.u32(),
            y1: reader.u32(),
        };
        if bounds.x1 < bounds.x0 || bounds.y1 < bounds.y0 {
            return Err(bad(format!(
                "corrupt: pixel bounds {bounds:?} are reversed"
            )));
        }
        check_length_and_checksum(bytes, HEADER_BYTES, bounds).map_err(bad)?;
        if passes_done > samples_per_pixel {
            return Err(bad(format!(
                "corrupt: {passes_done} passes done of {samples_per_pixel}"
            )));
        }
        let film = take_film(&mut reader, bounds).map_err(bad)?;
        Ok(Checkpoint {
            fingerprint,
            samples_per_pixel,
            passes_done,
            film,
        })
    }

    /// Writes the checkpoint to `path` atomically (a temporary file beside it, flushed to disk,
    /// then renamed over it): a crash mid-write leaves the previous checkpoint intact.
    pub fn save(&self, path: &Path) -> Result<(), RenderError> {
        crate::output::write_whole(
            path,
            &self.to_bytes(),
            [
                "cannot write the checkpoint",
                "cannot move the checkpoint into place",
            ],
        )
    }

    /// Reads a checkpoint file.
    pub fn load(path: &Path) -> Result<Checkpoint, RenderError> {
        let bytes = std::fs::read(path).map_err(|source| RenderError::Io {
            file: path.to_path_buf(),
            action: "cannot read the checkpoint",
            source,
        })?;
        Checkpoint::from_bytes(&bytes, path)
    }

    /// `Ok` when this checkpoint belongs to a render of `fingerprint` to `samples_per_pixel`
    /// over `bounds`; otherwise an error saying what differs. `file` names the checkpoint.
    pub fn check_matches(
        &self,
        fingerprint: u64,
        samples_per_pixel: u32,
        bounds: PixelRect,
        file: &Path,
    ) -> Result<(), RenderError> {
        let bad = |message: String| RenderError::Checkpoint {
            file: file.to_path_buf(),
            message,
        };
        if self.film.bounds() != bounds {
            let b = self.film.bounds();
            return Err(bad(format!(
                "made for pixels {}..{} x {}..{}, this render covers {}..{} x {}..{} (a different resolution or crop)",
                b.x0, b.x1, b.y0, b.y1, bounds.x0, bounds.x1, bounds.y0, bounds.y1
            )));
        }
        if self.samples_per_pixel != samples_per_pixel {
            return Err(bad(format!(
                "made for {} samples per pixel, this render asks for {samples_per_pixel}",
                self.samples_per_pixel
            )));
        }
        if self.fingerprint != fingerprint {
            return Err(bad(
                "made from a different scene file or settings (seed, integrator, overrides), or by a build whose samplers give other values; resume with the same scene, flags and build".into(),
            ));
        }
        Ok(())
    }
}

/// Bytes of one pixel's sums in a file: five i128.
pub(crate) const SUM_BYTES: usize = 5 * 16;

/// Appends the sums, row by row, five little-endian i128 each.
pub(crate) fn put_sums(out: &mut Vec<u8>, sums: &[PixelSums]) {
    for s in sums {
        for v in [
            s.radiance[0],
            s.radiance[1],
            s.radiance[2],
            s.weight,
            s.coverage,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
}

/// Appends the FNV-1a checksum of everything in `out`.
pub(crate) fn seal(out: &mut Vec<u8>) {
    let checksum = fnv1a(FNV_OFFSET, out);
    out.extend_from_slice(&checksum.to_le_bytes());
}

/// `Ok` when `bytes` is exactly a header of `header` bytes, the sums of `bounds` and a
/// matching checksum; otherwise what is wrong (truncated, padded or corrupt).
pub(crate) fn check_length_and_checksum(
    bytes: &[u8],
    header: usize,
    bounds: PixelRect,
) -> Result<(), String> {
    let expected = u128::from(bounds.area()) * SUM_BYTES as u128 + header as u128 + 8;
    if bytes.len() as u128 != expected {
        return Err(format!(
            "truncated or corrupt: {} bytes, expected {expected} for {}x{} pixels",
            bytes.len(),
            bounds.width(),
            bounds.height()
        ));
    }
    let body = bytes.len() - 8;
    let stored = u64::from_le_bytes(bytes[body..].try_into().unwrap_or_default());
    if stored != fnv1a(FNV_OFFSET, &bytes[..body]) {
        return Err("corrupt: the checksum does not match the contents".into());
    }
    Ok(())
}

/// Reads the sums of `bounds` (the length was checked by [`check_length_and_checksum`]).
pub(crate) fn take_film(reader: &mut Reader<'_>, bounds: PixelRect) -> Result<Film, String> {
    let body = reader.bytes.len() - 8;
    let mut sums = Vec::with_capacity(bounds.area() as usize);
    while reader.at < body {
        sums.push(PixelSums {
            radiance: [reader.i128(), reader.i128(), reader.i128()],
            weight: reader.i128(),
            coverage: reader.i128(),
        });
    }
    Film::from_sums(bounds, sums)
        .ok_or_else(|| "corrupt: the pixel count does not match the bounds".into())
}

/// Reads little-endian numbers; callers have checked the length first.
pub(crate) struct Reader<'a> {
    pub(crate) bytes: &'a [u8],
    pub(crate) at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0; N];
        if let Some(s) = self.bytes.get(self.at..self.at + N) {
            out.copy_from_slice(s);
        }
        self.at += N;
        out
    }
    pub(crate) fn bytes<const N: usize>(&mut self) -> [u8; N] {
        self.take()
    }
    pub(crate) fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    pub(crate) fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    fn i128(&mut self) -> i128 {
        i128::from_le_bytes(self.take())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn sample_checkpoint(w: u32, h: u32, seed: u64) -> Checkpoint {
        let bounds = PixelRect {
            x0: 1,
            y0: 2,
            x1: 1 + w,
            y1: 2 + h,
        };
        let sums = (0..u64::from(w * h))
            .map(|i| {
                let v = i128::from(i ^ seed);
                PixelSums {
                    radiance: [v * 3, -v, i128::MIN + v],
                    weight: v << 64,
                    coverage: i128::MAX - v,
                }
            })
            .collect();
        Checkpoint {
            fingerprint: seed.wrapping_mul(31),
            samples_per_pixel: 16,
            passes_done: 5,
            film: Film::from_sums(bounds, sums).unwrap(),
        }
    }

    #[test]
    fn header_layout_is_as_documented() {
        let c = sample_checkpoint(2, 1, 7);
        let bytes = c.to_bytes();
        // 44 header bytes + 2 pixels x 5 i128 + 8 checksum bytes = 44 + 160 + 8 = 212.
        assert_eq!(bytes.len(), 212);
        assert_eq!(&bytes[..8], b"OBSCKPT\0");
        assert_eq!(bytes[8..12], 2u32.to_le_bytes());
        assert_eq!(bytes[20..24], 16u32.to_le_bytes());
        assert_eq!(bytes[24..28], 5u32.to_le_bytes());
        // Bounds 1, 2, 3, 3.
        assert_eq!(bytes[28..32], 1u32.to_le_bytes());
        assert_eq!(bytes[40..44], 3u32.to_le_bytes());
        // The first pixel's red sum, (0 ^ 7) * 3 = 21, little-endian over 16 bytes.
        let mut red = [0u8; 16];
        red[0] = 21;
        assert_eq!(bytes[44..60], red);
    }

    #[test]
    fn truncation_padding_and_flipped_bytes_are_refused() {
        let c = sample_checkpoint(3, 2, 1);
        let bytes = c.to_bytes();
        let file = Path::new("c.ckpt");
        for cut in [0, 7, 8, 43, 52, bytes.len() - 1] {
            assert!(
                Checkpoint::from_bytes(&bytes[..cut], file).is_err(),
                "cut {cut}"
            );
        }
        let mut padded = bytes.clone();
        padded.push(0);
        assert!(Checkpoint::from_bytes(&padded, file).is_err());
        for at in [8, 13, 30, 60, bytes.len() - 3] {
            let mut flipped = bytes.clone();
            flipped[at] ^= 0x10;
            let e = Checkpoint::from_bytes(&flipped, file).unwrap_err();
            assert!(e.to_string().starts_with("c.ckpt: "), "{e}");
        }
    }

    #[test]
    fn a_version_1_checkpoint_of_f64_sums_is_refused_by_its_version() {
        let mut bytes = sample_checkpoint(2, 1, 4).to_bytes();
        bytes[8..12].copy_from_slice(&1u32.to_le_bytes());
        let e = Checkpoint::from_bytes(&bytes, Path::new("old.ckpt")).unwrap_err();
        assert!(
            e.to_string()
                .contains("format version 1, this obscura reads version 2"),
            "{e}"
        );
    }

    #[test]
    fn the_fingerprint_follows_the_samplers_values() {
        let source = r#"
            [film]
            resolution = [8, 8]
            [camera]
            eye = [0.0, 0.0, 3.0]
            target = [0.0, 0.0, 0.0]
            fov = 30.0
        "#;
        let d = crate::parse_description(Path::new("s.toml"), source).unwrap();
        let this = scene_fingerprint(source.as_bytes(), &d);
        let (seq, est) = (
            obscura_sample::SEQUENCE_VERSION,
            obscura_shade::ESTIMATOR_VERSION,
        );
        assert_eq!(this, fingerprint_with(source.as_bytes(), &d, [seq, est]));
        // A build whose samplers or path tracer give other values makes films that must not
        // be resumed or merged with this build's.
        assert_ne!(
            this,
            fingerprint_with(source.as_bytes(), &d, [seq + 1, est])
        );
        assert_ne!(
            this,
            fingerprint_with(source.as_bytes(), &d, [seq, est + 1])
        );
        // And the scene's settings still count.
        let mut other = d.clone();
        other.sampler.seed += 1;
        assert_ne!(this, scene_fingerprint(source.as_bytes(), &other));
    }

    #[test]
    fn a_checkpoint_from_other_settings_is_refused() {
        let c = sample_checkpoint(2, 2, 3);
        let file = Path::new("c.ckpt");
        let b = c.film.bounds();
        assert!(c.check_matches(c.fingerprint, 16, b, file).is_ok());
        assert!(c.check_matches(c.fingerprint + 1, 16, b, file).is_err());
        assert!(c.check_matches(c.fingerprint, 32, b, file).is_err());
        let other = PixelRect { x1: b.x1 + 1, ..b };
        assert!(c.check_matches(c.fingerprint, 16, other, file).is_err());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn round_trips_bit_for_bit(w in 0u32..6, h in 0u32..6, seed in any::<u64>()) {
            let c = sample_checkpoint(w, h, seed);
            let back = Checkpoint::from_bytes(&c.to_bytes(), Path::new("c")).unwrap();
            prop_assert_eq!(back.to_bytes(), c.to_bytes());
            prop_assert_eq!(back, c);
        }

        #[test]
        fn any_bytes_give_ok_or_err(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
            let _ = Checkpoint::from_bytes(&bytes, Path::new("c"));
            let mut framed = CHECKPOINT_MAGIC.to_vec();
            framed.extend_from_slice(&bytes);
            let _ = Checkpoint::from_bytes(&framed, Path::new("c"));
        }
    }
}
