//! How the explorer shows an off-axis stereo pair (`[camera.stereo]` on a perspective camera)
//! in its one preview image.
//!
//! Both eyes render, each into its own film, and the preview is composed as `obscura render`
//! composes the pair ([`compose_stereo`](obscura_render::compose_stereo)): side by side (left
//! eye on the left) or the red-cyan anaglyph. A `separate` pair, which the command line writes
//! as two files, is previewed side by side. A position in the preview names an eye and a
//! raster position on that eye's film ([`pick`]); in an anaglyph it names the rig's centre.

use crate::error::ExploreError;
use obscura_camera::{AnyCamera, StereoEye};
use obscura_render::{SceneDescription, StereoLayout, camera_of};

/// The layout the preview composes for a pair the scene lays out as `layout`: the same, but
/// `separate` (two files on the command line) side by side, since the page has one image.
pub(crate) fn shown(layout: StereoLayout) -> StereoLayout {
    match layout {
        StereoLayout::Separate => StereoLayout::SideBySide,
        other => other,
    }
}

/// The width of the page's image for eyes `eye_width` pixels wide, shown as `shown` (None: a
/// single view): twice as wide for a pair side by side.
pub(crate) fn image_width(shown: Option<StereoLayout>, eye_width: u32) -> u32 {
    match shown {
        Some(StereoLayout::SideBySide | StereoLayout::Separate) => 2 * eye_width,
        Some(StereoLayout::Anaglyph) | None => eye_width,
    }
}

/// The layout a scene file gives a perspective stereo pair; None when the view renders one
/// image (no `[camera.stereo]`, or the ODS camera, whose pair is its own projection).
pub(crate) fn pair_layout(d: &SceneDescription) -> Option<StereoLayout> {
    let layout = d.camera.stereo?.layout;
    // `stereo_eyes` is the scene layer's own word on which scenes render a pair.
    d.stereo_eyes().map(|_| layout)
}

/// The scene format's name of a layout.
pub(crate) fn layout_name(layout: StereoLayout) -> &'static str {
    match layout {
        StereoLayout::SideBySide => "side_by_side",
        StereoLayout::Separate => "separate",
        StereoLayout::Anaglyph => "anaglyph",
    }
}

/// The name of an eye, as the command line suffixes its files (`NAME-left.EXT`).
pub(crate) fn eye_name(eye: StereoEye) -> &'static str {
    match eye {
        StereoEye::Left => "left",
        StereoEye::Right => "right",
    }
}

/// An eye by its name (`left`, `right`); None for anything else.
pub(crate) fn eye_of_name(name: &str) -> Option<StereoEye> {
    match name {
        "left" => Some(StereoEye::Left),
        "right" => Some(StereoEye::Right),
        _ => None,
    }
}

/// The view's camera and, for a stereo pair, its eyes' (left, right), each built and checked
/// by the camera crate as `obscura render` builds them.
pub(crate) fn cameras_of(
    d: &SceneDescription,
) -> Result<(AnyCamera, Option<[AnyCamera; 2]>), ExploreError> {
    let centre = camera_of(d)?;
    let eyes = match d.stereo_eyes() {
        Some([left, right]) => Some([camera_of(&left)?, camera_of(&right)?]),
        None => None,
    };
    Ok((centre, eyes))
}

/// Where a preview position falls: the eye whose film shows it (None: the view's own camera)
/// and the raster position on that film.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pick {
    /// The eye; None for a single view, and for an anaglyph (see [`pick`]).
    pub eye: Option<StereoEye>,
    /// Raster x on the film.
    pub x: f32,
    /// Raster y on the film.
    pub y: f32,
}

/// Which camera shows preview position (`x`, `y`) of a view whose pair (if any) is `shown`,
/// each eye's image being `eye_width` pixels wide. Side by side: the left half is the left
/// eye's film, the right half the right eye's, shifted back by `eye_width`. An anaglyph
/// overlays the eyes: a point's red (left) and cyan (right) images lie either side of where
/// the rig's centre sees it, at equal distances (the left eye's screen x is
/// `s (x + b/2) / z - s b / 2C`, the right's `s (x - b/2) / z + s b / 2C`, whose mean is the
/// centre's `s x / z`; obscura-camera's stereo.rs), so the centre's camera answers.
pub(crate) fn pick(shown: Option<StereoLayout>, eye_width: u32, x: f32, y: f32) -> Pick {
    match shown {
        Some(StereoLayout::SideBySide | StereoLayout::Separate) => {
            let w = eye_width as f32;
            if x < w {
                Pick {
                    eye: Some(StereoEye::Left),
                    x,
                    y,
                }
            } else {
                Pick {
                    eye: Some(StereoEye::Right),
                    x: x - w,
                    y,
                }
            }
        }
        Some(StereoLayout::Anaglyph) | None => Pick { eye: None, x, y },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_by_side_halves_are_the_eyes_and_an_anaglyph_is_the_centre() {
        let sbs = Some(StereoLayout::SideBySide);
        assert_eq!(
            pick(sbs, 40, 39.5, 3.0),
            Pick {
                eye: Some(StereoEye::Left),
                x: 39.5,
                y: 3.0
            }
        );
        assert_eq!(
            pick(sbs, 40, 40.0, 3.0),
            Pick {
                eye: Some(StereoEye::Right),
                x: 0.0,
                y: 3.0
            }
        );
        assert_eq!(pick(Some(StereoLayout::Anaglyph), 40, 50.0, 1.0).eye, None);
        assert_eq!(pick(None, 40, 50.0, 1.0).x, 50.0);
        assert_eq!(shown(StereoLayout::Separate), StereoLayout::SideBySide);
        for eye in [StereoEye::Left, StereoEye::Right] {
            assert_eq!(eye_of_name(eye_name(eye)), Some(eye));
        }
        assert_eq!(eye_of_name("centre"), None);
    }
}
