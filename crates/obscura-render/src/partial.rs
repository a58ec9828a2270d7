//! Slices of a render and their partial films: a render split over processes or machines, and
//! the exact merge of the pieces.
//!
//! Slice `i` of `N` takes a contiguous share of the passes (sample indices; the default) or of
//! the tiles, and writes a [`Partial`]: its film's fixed-point sums with a header that says
//! which render and which slice they belong to. Because the film's sums are integers,
//! [`merge_partials`] adds the `N` partials in any order to exactly the film that one process
//! would have made (see docs/ARCHITECTURE.md, "Slices and the exact merge").
//!
//! The format follows the checkpoint's (little-endian, the same sums and checksum):
//!
//! ```text
//! magic        8 bytes   "OBSPART\0"
//! version      u32       PARTIAL_VERSION
//! fingerprint  u64       scene_fingerprint(): the scene file, every setting, the sampler values
//! seed         u64       sampler seed
//! spp          u32       samples per pixel of the whole render
//! integrator   16 bytes  its name, zero-padded
//! resolution   2 x u32   width, height
//! bounds       4 x u32   x0, y0, x1, y1 of the film's pixel bounds
//! slicing      u32       0: by passes, 1: by tiles
//! index        u32       this slice, < count
//! count        u32       slices in all
//! sums         (x1 - x0) (y1 - y0) x 5 i128, as in a checkpoint
//! checksum     u64       FNV-1a of every byte before it
//! ```

use crate::checkpoint::{Reader, check_length_and_checksum, put_sums, seal, take_film};
use crate::error::RenderError;
use crate::film::{Film, PixelRect};
use crate::scene::IntegratorKind;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The first eight bytes of a partial file.
pub const PARTIAL_MAGIC: [u8; 8] = *b"OBSPART\0";

/// The partial format version this build reads and writes.
pub const PARTIAL_VERSION: u32 = 1;

/// Bytes before the sums.
const HEADER_BYTES: usize = 8 + 4 + 8 + 8 + 4 + 16 + 8 + 16 + 4 + 4 + 4;

/// What a render is split by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SliceBy {
    /// Contiguous ranges of passes (sample indices): every slice covers the whole image.
    Passes,
    /// Contiguous ranges of tiles (row by row): every slice takes every sample of its tiles.
    Tiles,
}

impl SliceBy {
    /// The command line's name: `passes` or `tiles`.
    pub fn name(self) -> &'static str {
        match self {
            SliceBy::Passes => "passes",
            SliceBy::Tiles => "tiles",
        }
    }

    /// The kind a name stands for.
    pub fn parse(name: &str) -> Option<SliceBy> {
        match name {
            "passes" => Some(SliceBy::Passes),
            "tiles" => Some(SliceBy::Tiles),
            _ => None,
        }
    }

    fn code(self) -> u32 {
        match self {
            SliceBy::Passes => 0,
            SliceBy::Tiles => 1,
        }
    }
}

/// Slice `index` of `count`, by passes or tiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Slice {
    /// This slice, `0..count`.
    pub index: u32,
    /// Slices in all, at least 1.
    pub count: u32,
    /// What is split.
    pub by: SliceBy,
}

impl Slice {
    /// Parses `i/N` (the command line's `--slice`), with `0 <= i < N`.
    pub fn parse(text: &str, by: SliceBy) -> Result<Slice, RenderError> {
        let bad = |why: &str| RenderError::Setting {
            name: "--slice",
            message: format!("expected i/N with 0 <= i < N, e.g. 0/4, got `{text}`{why}"),
        };
        let (i, n) = text.split_once('/').ok_or_else(|| bad(""))?;
        let (index, count): (u32, u32) = (
            i.trim().parse().map_err(|_| bad(""))?,
            n.trim().parse().map_err(|_| bad(""))?,
        );
        if count == 0 {
            return Err(bad(" (N must be >= 1)"));
        }
        if index >= count {
            return Err(bad(" (slices are numbered from 0)"));
        }
        Ok(Slice { index, count, by })
    }

    /// This slice's share of `0..total` items (passes or tiles): contiguous, as even as can
    /// be, and the `count` shares cover `0..total` once. Empty when `count > total` leaves
    /// this slice nothing.
    pub fn range(&self, total: u64) -> Range<u64> {
        let at = |i: u32| u64::try_from(u128::from(total) * u128::from(i) / u128::from(self.count));
        at(self.index).unwrap_or(total)..at(self.index + 1).unwrap_or(total)
    }
}

impl fmt::Display for Slice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{} by {}", self.index, self.count, self.by.name())
    }
}

/// A slice's film with what identifies the render and the slice.
#[derive(Clone, Debug, PartialEq)]
pub struct Partial {
    /// [`crate::scene_fingerprint`] of the scene and settings.
    pub fingerprint: u64,
    /// The sampler's seed.
    pub seed: u64,
    /// Samples per pixel of the whole render.
    pub samples_per_pixel: u32,
    /// The integrator.
    pub integrator: IntegratorKind,
    /// The image's width and height.
    pub resolution: [u32; 2],
    /// Which slice this is.
    pub slice: Slice,
    /// The slice's sums.
    pub film: Film,
}

/// Every integrator, for reading its name back.
const INTEGRATORS: [IntegratorKind; 6] = [
    IntegratorKind::Path,
    IntegratorKind::Depth,
    IntegratorKind::Distance,
    IntegratorKind::Position,
    IntegratorKind::Normal,
    IntegratorKind::Albedo,
];

impl Partial {
    /// The partial's bytes, in the format of the module documentation.
    pub fn to_bytes(&self) -> Vec<u8> {
        let b = self.film.bounds();
        let sums = self.film.sums();
        let mut out =
            Vec::with_capacity(HEADER_BYTES + sums.len() * crate::checkpoint::SUM_BYTES + 8);
        out.extend_from_slice(&PARTIAL_MAGIC);
        out.extend_from_slice(&PARTIAL_VERSION.to_le_bytes());
        out.extend_from_slice(&self.fingerprint.to_le_bytes());
        out.extend_from_slice(&self.seed.to_le_bytes());
        out.extend_from_slice(&self.samples_per_pixel.to_le_bytes());
        let mut name = [0u8; 16];
        let n = self.integrator.name().as_bytes();
        name[..n.len().min(16)].copy_from_slice(&n[..n.len().min(16)]);
        out.extend_from_slice(&name);
        for v in self.resolution {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [b.x0, b.y0, b.x1, b.y1] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [self.slice.by.code(), self.slice.index, self.slice.count] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        put_sums(&mut out, sums);
        seal(&mut out);
        out
    }

    /// Reads a partial from its bytes; `file` names it in errors. Wrong magic, another
    /// version, a truncated or padded file, a bad checksum and inconsistent fields are errors,
    /// never panics.
    pub fn from_bytes(bytes: &[u8], file: &Path) -> Result<Partial, RenderError> {
        let bad = |message: String| RenderError::Partial {
            file: file.to_path_buf(),
            message,
        };
        if bytes.len() < 8 || bytes[..8] != PARTIAL_MAGIC {
            return Err(bad(
                "not an obscura partial (wrong magic bytes; made by `obscura render --slice`?)"
                    .into(),
            ));
        }
        if bytes.len() < HEADER_BYTES + 8 {
            return Err(bad(format!(
                "truncated: {} bytes, shorter than the header",
                bytes.len()
            )));
        }
        let mut reader = Reader { bytes, at: 8 };
        let version = reader.u32();
        if version != PARTIAL_VERSION {
            return Err(bad(format!(
                "format version {version}, this obscura reads version {PARTIAL_VERSION}"
            )));
        }
        let fingerprint = reader.u64();
        let seed = reader.u64();
        let samples_per_pixel = reader.u32();
        let name: [u8; 16] = reader.bytes();
        let resolution = [reader.u32(), reader.u32()];
        let bounds = PixelRect {
            x0: reader.u32(),
            y0: reader.u32(),
            x1: reader.u32(),
            y1: reader.u32(),
        };
        let (by, index, count) = (reader.u32(), reader.u32(), reader.u32());
        if bounds.x1 < bounds.x0 || bounds.y1 < bounds.y0 {
            return Err(bad(format!(
                "corrupt: pixel bounds {bounds:?} are reversed"
            )));
        }
        check_length_and_checksum(bytes, HEADER_BYTES, bounds).map_err(bad)?;
        // The checksum holds: what follows catches files written by a faulty writer.
        // The name and zeros after it, exactly as written: bytes after the name's end would
        // not survive a rewrite (found by the partial fuzz target).
        let integrator = INTEGRATORS
            .into_iter()
            .find(|k| {
                let n = k.name().as_bytes();
                name.get(..n.len()) == Some(n) && name[n.len()..].iter().all(|&b| b == 0)
            })
            .ok_or_else(|| {
                bad(format!(
                    "corrupt: unknown integrator `{}`",
                    String::from_utf8_lossy(&name).trim_end_matches('\0')
                ))
            })?;
        let by = match by {
            0 => SliceBy::Passes,
            1 => SliceBy::Tiles,
            other => return Err(bad(format!("corrupt: unknown slicing {other}"))),
        };
        if count == 0 || index >= count {
            return Err(bad(format!("corrupt: slice {index} of {count}")));
        }
        let film = take_film(&mut reader, bounds).map_err(bad)?;
        Ok(Partial {
            fingerprint,
            seed,
            samples_per_pixel,
            integrator,
            resolution,
            slice: Slice { index, count, by },
            film,
        })
    }

    /// Writes the partial to `path` whole or not at all (a temporary file beside it, flushed
    /// to disk, then renamed over it).
    pub fn save(&self, path: &Path) -> Result<(), RenderError> {
        crate::output::write_whole(
            path,
            &self.to_bytes(),
            [
                "cannot write the partial",
                "cannot move the partial into place",
            ],
        )
    }

    /// Reads a partial file.
    pub fn load(path: &Path) -> Result<Partial, RenderError> {
        let bytes = std::fs::read(path).map_err(|source| RenderError::Io {
            file: path.to_path_buf(),
            action: "cannot read the partial",
            source,
        })?;
        Partial::from_bytes(&bytes, path)
    }

    /// What differs between the renders of `self` and `other` (named `file`), if anything
    /// besides the slice index: the first difference, in words.
    fn mismatch(&self, other: &Partial) -> Option<String> {
        let (a, b) = (self, other);
        if a.slice.by != b.slice.by || a.slice.count != b.slice.count {
            return Some(format!(
                "sliced differently: {} of {} by {}, not of {} by {}",
                b.slice.index,
                b.slice.count,
                b.slice.by.name(),
                a.slice.count,
                a.slice.by.name()
            ));
        }
        if a.seed != b.seed {
            return Some(format!("another seed: {}, not {}", b.seed, a.seed));
        }
        if a.samples_per_pixel != b.samples_per_pixel {
            return Some(format!(
                "another sample count: {} spp, not {}",
                b.samples_per_pixel, a.samples_per_pixel
            ));
        }
        if a.integrator != b.integrator {
            return Some(format!(
                "another integrator: {}, not {}",
                b.integrator.name(),
                a.integrator.name()
            ));
        }
        if a.resolution != b.resolution || a.film.bounds() != b.film.bounds() {
            return Some(format!(
                "another resolution or crop: {}x{}, not {}x{}",
                b.resolution[0], b.resolution[1], a.resolution[0], a.resolution[1]
            ));
        }
        if a.fingerprint != b.fingerprint {
            return Some(
                "another scene: the scene file, a setting or the build's sampler values differ \
                 (fingerprints do not match)"
                    .into(),
            );
        }
        None
    }
}

/// The result of reading a set of parts: what [`merge_partials`] found.
#[derive(Debug)]
pub struct PartSet {
    /// The first part read, its film replaced by the sum of every part's film (the whole
    /// render's film once no slice is missing); `None` when no part was given.
    pub merged: Option<Partial>,
    /// The slice indices read, ascending.
    pub present: Vec<u32>,
    /// The indices of `0..count` without a part, ascending.
    pub missing: Vec<u32>,
}

/// Reads the parts one at a time and adds their films, checking that they are one render's
/// slices: the same render (scene, seed, spp, integrator, resolution, slicing), each slice at
/// most once. `expected` is the slice count asked for, if any. Errors name the file at fault.
/// Memory holds two films whatever the number of parts: the sum and the part being read.
/// The sums are exact, so the order of `paths` does not matter.
pub fn merge_partials(paths: &[PathBuf], expected: Option<u32>) -> Result<PartSet, RenderError> {
    let mut merged: Option<(Partial, &PathBuf)> = None;
    let mut present: Vec<(u32, &PathBuf)> = Vec::with_capacity(paths.len());
    for path in paths {
        let part = Partial::load(path)?;
        let refuse = |message: String| RenderError::Partial {
            file: path.clone(),
            message,
        };
        match &merged {
            Some((first, first_path)) => {
                if let Some(why) = first.mismatch(&part) {
                    return Err(refuse(format!(
                        "not a slice of the same render as {}: {why}",
                        first_path.display()
                    )));
                }
            }
            None => {
                if let Some(n) = expected.filter(|&n| n != part.slice.count) {
                    return Err(refuse(format!(
                        "a slice of {}, not of {n}",
                        part.slice.count
                    )));
                }
            }
        }
        if let Some((_, other)) = present.iter().find(|(i, _)| *i == part.slice.index) {
            return Err(refuse(format!(
                "duplicate: slice {} is also in {}",
                part.slice,
                other.display()
            )));
        }
        present.push((part.slice.index, path));
        match &mut merged {
            Some((sum, _)) => sum.film.add(&part.film),
            None => merged = Some((part, path)),
        }
    }
    let count = merged
        .as_ref()
        .map_or(expected.unwrap_or(0), |(p, _)| p.slice.count);
    let mut present: Vec<u32> = present.into_iter().map(|(i, _)| i).collect();
    present.sort_unstable();
    let missing = (0..count)
        .filter(|i| present.binary_search(i).is_err())
        .collect();
    Ok(PartSet {
        merged: merged.map(|(p, _)| p),
        present,
        missing,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::PixelSums;
    use proptest::prelude::*;

    fn sample_partial(index: u32, count: u32, seed: u64) -> Partial {
        let bounds = PixelRect {
            x0: 0,
            y0: 0,
            x1: 3,
            y1: 2,
        };
        let sums = (0..6i128)
            .map(|i| PixelSums {
                radiance: [i + i128::from(index), -i, i << 70],
                weight: (i + 1) << 64,
                coverage: i,
            })
            .collect();
        Partial {
            fingerprint: 0xfeed,
            seed,
            samples_per_pixel: 8,
            integrator: IntegratorKind::Depth,
            resolution: [3, 2],
            slice: Slice {
                index,
                count,
                by: SliceBy::Passes,
            },
            film: Film::from_sums(bounds, sums).unwrap(),
        }
    }

    #[test]
    fn slice_parse_accepts_i_of_n_only() {
        let s = Slice::parse("2/7", SliceBy::Tiles).unwrap();
        assert_eq!((s.index, s.count, s.by), (2, 7, SliceBy::Tiles));
        for bad in ["", "3", "4/4", "0/0", "-1/3", "a/3", "1/3/4", "1 / x"] {
            assert!(Slice::parse(bad, SliceBy::Passes).is_err(), "{bad}");
        }
    }

    #[test]
    fn slice_ranges_by_hand() {
        let r = |i, n, total| {
            Slice {
                index: i,
                count: n,
                by: SliceBy::Passes,
            }
            .range(total)
        };
        assert_eq!([r(0, 3, 8), r(1, 3, 8), r(2, 3, 8)], [0..2, 2..5, 5..8]);
        assert_eq!(
            [r(0, 4, 2), r(1, 4, 2), r(2, 4, 2), r(3, 4, 2)],
            [0..0, 0..1, 1..1, 1..2]
        );
        assert_eq!(r(0, 1, 5), 0..5);
    }

    #[test]
    fn header_layout_is_as_documented() {
        let bytes = sample_partial(1, 4, 9).to_bytes();
        assert_eq!(bytes.len(), HEADER_BYTES + 6 * 80 + 8);
        assert_eq!(HEADER_BYTES, 84);
        assert_eq!(&bytes[..8], b"OBSPART\0");
        assert_eq!(bytes[12..20], 0xfeedu64.to_le_bytes());
        assert_eq!(bytes[20..28], 9u64.to_le_bytes());
        assert_eq!(bytes[28..32], 8u32.to_le_bytes());
        assert_eq!(&bytes[32..38], b"depth\0");
        assert_eq!(bytes[48..52], 3u32.to_le_bytes());
        assert_eq!(bytes[72..76], 0u32.to_le_bytes());
        assert_eq!(bytes[76..80], 1u32.to_le_bytes());
        assert_eq!(bytes[80..84], 4u32.to_le_bytes());
    }

    #[test]
    fn bytes_after_the_integrators_name_are_refused_even_under_a_valid_checksum() {
        // Found by the partial fuzz target (which reseals its inputs): "depth" followed by a
        // non-zero padding byte parsed as depth and wrote back with zeros.
        let bytes = sample_partial(0, 2, 1).to_bytes();
        for at in 32 + 5..48 {
            let mut body = bytes[..bytes.len() - 8].to_vec();
            body[at] = 28;
            crate::checkpoint::seal(&mut body);
            let e = Partial::from_bytes(&body, Path::new("p.part")).unwrap_err();
            assert!(e.to_string().contains("unknown integrator `depth"), "{e}");
        }
        // The untouched bytes still parse and write back to themselves.
        let p = Partial::from_bytes(&bytes, Path::new("p.part")).unwrap();
        assert_eq!(p.to_bytes(), bytes);
    }

    #[test]
    fn every_flipped_byte_and_every_cut_is_refused() {
        let bytes = sample_partial(0, 2, 1).to_bytes();
        let file = Path::new("p.part");
        for at in 0..bytes.len() {
            let mut flipped = bytes.clone();
            flipped[at] ^= 0x01;
            let e = Partial::from_bytes(&flipped, file).unwrap_err();
            assert!(e.to_string().starts_with("p.part: "), "{e}");
            assert!(Partial::from_bytes(&bytes[..at], file).is_err(), "cut {at}");
        }
        let mut padded = bytes.clone();
        padded.push(0);
        assert!(Partial::from_bytes(&padded, file).is_err());
        // A checkpoint is not a partial.
        let mut ckpt = crate::CHECKPOINT_MAGIC.to_vec();
        ckpt.extend_from_slice(&bytes[8..]);
        assert!(Partial::from_bytes(&ckpt, file).is_err());
    }

    #[test]
    fn mismatches_are_named() {
        let a = sample_partial(0, 2, 1);
        assert_eq!(a.mismatch(&sample_partial(1, 2, 1)), None);
        let cases: [(Partial, &str); 5] = [
            (sample_partial(1, 2, 5), "seed"),
            (sample_partial(1, 3, 1), "sliced differently"),
            (
                Partial {
                    samples_per_pixel: 9,
                    ..sample_partial(1, 2, 1)
                },
                "sample count",
            ),
            (
                Partial {
                    integrator: IntegratorKind::Path,
                    ..sample_partial(1, 2, 1)
                },
                "integrator",
            ),
            (
                Partial {
                    fingerprint: 1,
                    ..sample_partial(1, 2, 1)
                },
                "another scene",
            ),
        ];
        for (b, word) in cases {
            let why = a.mismatch(&b).unwrap();
            assert!(why.contains(word), "{why} lacks {word}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn round_trips_bit_for_bit(index in 0u32..9, extra in 1u32..9, seed in any::<u64>()) {
            let p = sample_partial(index, index + extra, seed);
            let back = Partial::from_bytes(&p.to_bytes(), Path::new("p")).unwrap();
            prop_assert_eq!(back.to_bytes(), p.to_bytes());
            prop_assert_eq!(back, p);
        }

        #[test]
        fn any_bytes_give_ok_or_err(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
            let _ = Partial::from_bytes(&bytes, Path::new("p"));
            let mut framed = PARTIAL_MAGIC.to_vec();
            framed.extend_from_slice(&bytes);
            let _ = Partial::from_bytes(&framed, Path::new("p"));
        }

        #[test]
        fn the_shares_cover_everything_once(count in 1u32..40, total in 0u64..200) {
            let mut next = 0;
            for index in 0..count {
                let r = Slice { index, count, by: SliceBy::Passes }.range(total);
                prop_assert_eq!(r.start, next);
                prop_assert!(r.end >= r.start);
                next = r.end;
            }
            prop_assert_eq!(next, total);
        }
    }
}
