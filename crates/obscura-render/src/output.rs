//! Writing images: EXR (linear 32-bit float RGBA) and PNG (8-bit sRGB), chosen by extension,
//! written whole or not at all.

use crate::error::RenderError;
use crate::film::Image;
use std::path::{Path, PathBuf};

/// The image formats the renderer writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// OpenEXR, linear 32-bit float RGBA.
    Exr,
    /// PNG, 8-bit sRGB RGBA.
    Png,
}

impl OutputFormat {
    /// The format a file name asks for, by its extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Self, RenderError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("exr") => Ok(OutputFormat::Exr),
            Some("png") => Ok(OutputFormat::Png),
            _ => Err(RenderError::Setting {
                name: "-o",
                message: format!("{}: the output must end in .exr or .png", path.display()),
            }),
        }
    }
}

/// Metadata written with an image.
#[derive(Clone, Debug, Default)]
pub struct ImageInfo {
    /// True when the render stopped before all its samples were taken.
    pub partial: bool,
    /// Samples per pixel actually taken (for a partial image, fewer than asked).
    pub samples_per_pixel: u32,
}

/// Writes `image` to `path` atomically: into a temporary file beside it, then renamed over it,
/// so an interrupted write never leaves a truncated image or destroys an older one.
pub fn write_image(path: &Path, image: &Image, info: &ImageInfo) -> Result<(), RenderError> {
    let format = OutputFormat::from_path(path)?;
    let tmp = temporary_beside(path);
    let written = match format {
        OutputFormat::Exr => write_exr(&tmp, image, info),
        OutputFormat::Png => write_png(&tmp, image),
    };
    let renamed = written.and_then(|()| {
        std::fs::rename(&tmp, path).map_err(|source| RenderError::Io {
            file: path.to_path_buf(),
            action: "cannot move the finished image into place",
            source,
        })
    });
    if renamed.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    renamed
}

/// A hidden file name in the target's folder, unique to this process.
pub fn temporary_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "image".into());
    // Keep the real extension last: encoders that look at it see the right one.
    path.with_file_name(format!(
        ".{name}.{}.partial.{}",
        std::process::id(),
        extension(path)
    ))
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn write_exr(tmp: &Path, image: &Image, info: &ImageInfo) -> Result<(), RenderError> {
    use exr::prelude::*;
    let (w, h) = (image.width as usize, image.height as usize);
    let channels = SpecificChannels::rgba(|pos: Vec2<usize>| {
        let p = image.pixels[pos.y() * w + pos.x()];
        (p[0], p[1], p[2], p[3])
    });
    let mut attributes = LayerAttributes {
        software_name: Some(Text::from("obscura")),
        ..LayerAttributes::default()
    };
    attributes.other.insert(
        Text::from("obscuraPartial"),
        AttributeValue::I32(i32::from(info.partial)),
    );
    // One custom attribute only: `other` is a hash map, so two entries would be written in a
    // different order on every run. The sample count goes into the standard comments.
    let comment = format!(
        "obscura: {} samples per pixel{}",
        info.samples_per_pixel,
        if info.partial { " (partial)" } else { "" }
    );
    attributes.comments = Some(Text::from(comment.as_str()));
    let layer = Layer::new((w, h), attributes, Encoding::FAST_LOSSLESS, channels);
    // Compressed in order on this thread: parallel encoding writes blocks in the order they
    // finish, and the same image must give the same bytes every time.
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_file(tmp)
        .map_err(|e| RenderError::Encode {
            file: tmp.to_path_buf(),
            message: format!("cannot write EXR: {e}"),
        })
}

/// Linear to sRGB-encoded 8 bits, clamped.
pub fn srgb_8bit(linear: f32) -> u8 {
    let c = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

fn write_png(tmp: &Path, image: &Image) -> Result<(), RenderError> {
    let rgba = image::RgbaImage::from_fn(image.width, image.height, |x, y| {
        let p = image.pixel(x, y);
        // Alpha is coverage, a linear fraction: not sRGB-encoded.
        let a = (p[3].clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        image::Rgba([srgb_8bit(p[0]), srgb_8bit(p[1]), srgb_8bit(p[2]), a])
    });
    rgba.save_with_format(tmp, image::ImageFormat::Png)
        .map_err(|e| RenderError::Encode {
            file: tmp.to_path_buf(),
            message: format!("cannot write PNG: {e}"),
        })
}

/// Reads an EXR written by [`write_image`] (or any RGBA EXR) back as linear floats, with its
/// partial flag. For tests and tools.
pub fn read_exr(path: &Path) -> Result<(Image, bool), RenderError> {
    let bytes = std::fs::read(path).map_err(|e| RenderError::Encode {
        file: path.to_path_buf(),
        message: format!("cannot read EXR: {e}"),
    })?;
    decode_exr(&bytes, path)
}

/// The most pixels an EXR read here may declare (2 GiB of RGBA floats): a header that claims
/// more is refused before any pixel memory is allocated, so a corrupt or hostile size cannot
/// abort the process.
pub const MAX_EXR_PIXELS: u64 = 1 << 27;

/// [`read_exr`] of a file's bytes; `path` names the file in errors.
pub fn decode_exr(bytes: &[u8], path: &Path) -> Result<(Image, bool), RenderError> {
    use exr::prelude::*;
    // The headers first: the pixel reader allocates the declared size up front.
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| RenderError::Encode {
            file: path.to_path_buf(),
            message: format!("cannot read EXR: {e}"),
        })?;
    for header in meta.headers.iter() {
        let size = header.layer_size;
        let pixels = size.width() as u64 * size.height() as u64;
        if pixels > MAX_EXR_PIXELS {
            return Err(RenderError::Encode {
                file: path.to_path_buf(),
                message: format!(
                    "cannot read EXR: its header declares {} x {} pixels, more than the {MAX_EXR_PIXELS} this reader accepts",
                    size.width(),
                    size.height()
                ),
            });
        }
        // The reader sizes each chunk's buffer by the declared tile before reading it, so a
        // tile far larger than the image costs gigabytes even when the file is a few bytes.
        // A tile as large as the image (or 256 x 256, for small images) is all a file needs.
        if let exr::meta::BlockDescription::Tiles(tiles) = &header.blocks {
            let tile = tiles.tile_size;
            if tile.width() as u64 * tile.height() as u64 > pixels.max(1 << 16) {
                return Err(RenderError::Encode {
                    file: path.to_path_buf(),
                    message: format!(
                        "cannot read EXR: its header declares tiles of {} x {} pixels, larger than its {} x {} image",
                        tile.width(),
                        tile.height(),
                        size.width(),
                        size.height()
                    ),
                });
            }
        }
    }
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |res, _| (res.width(), vec![[0.0f32; 4]; res.width() * res.height()]),
            |(w, px), pos, (r, g, b, a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = [r, g, b, a]
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| RenderError::Encode {
            file: path.to_path_buf(),
            message: format!("cannot read EXR: {e}"),
        })?;
    let partial = matches!(
        img.layer_data
            .attributes
            .other
            .get(&Text::from("obscuraPartial")),
        Some(AttributeValue::I32(1))
    );
    let size = img.layer_data.size;
    let (_, pixels) = img.layer_data.channel_data.pixels;
    Ok((
        crate::film::Image {
            width: size.width() as u32,
            height: size.height() as u32,
            pixels,
        },
        partial,
    ))
}

/// Writes `bytes` to `path` whole or not at all: a temporary file beside it, flushed to disk,
/// then renamed over it, so a crash mid-write leaves the previous file intact. `actions` name
/// the write and the rename in errors.
pub(crate) fn write_whole(
    path: &Path,
    bytes: &[u8],
    actions: [&'static str; 2],
) -> Result<(), RenderError> {
    let tmp = temporary_beside(path);
    let io = |action: &'static str| {
        move |source| RenderError::Io {
            file: path.to_path_buf(),
            action,
            source,
        }
    };
    let written = std::fs::File::create(&tmp)
        .and_then(|mut f| {
            std::io::Write::write_all(&mut f, bytes)?;
            f.sync_all()
        })
        .map_err(io(actions[0]))
        .and_then(|()| std::fs::rename(&tmp, path).map_err(io(actions[1])));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_encoding_matches_the_standard_at_known_points() {
        // 0 -> 0, 1 -> 255, linear 0.5 -> 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 188.
        assert_eq!(srgb_8bit(0.0), 0);
        assert_eq!(srgb_8bit(1.0), 255);
        assert_eq!(srgb_8bit(4.0), 255);
        assert_eq!(srgb_8bit(0.5), 188);
        assert_eq!(srgb_8bit(f32::NAN), 0);
    }

    #[test]
    fn exr_round_trips_and_png_writes_atomically() {
        let dir = std::env::temp_dir().join(format!("obscura-output-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let image = Image {
            width: 2,
            height: 1,
            pixels: vec![[0.25, 2.0, -1.0, 1.0], [0.0, 0.5, 1e6, 0.5]],
        };
        let exr = dir.join("a.exr");
        write_image(
            &exr,
            &image,
            &ImageInfo {
                partial: true,
                samples_per_pixel: 3,
            },
        )
        .unwrap();
        let (back, partial) = read_exr(&exr).unwrap();
        assert_eq!(back, image);
        assert!(partial);
        let png = dir.join("a.png");
        write_image(&png, &image, &ImageInfo::default()).unwrap();
        let decoded = image::open(&png).unwrap().to_rgba8();
        assert_eq!(decoded.get_pixel(0, 0).0, [137, 255, 0, 255]);
        assert_eq!(decoded.get_pixel(1, 0).0, [0, 188, 255, 128]);
        // No temporary files are left behind.
        let names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
        assert!(OutputFormat::from_path(Path::new("x.jpg")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
