//! The gallery command at a tiny resolution: every picture is made, decodes, and is not blank.

use crate::scratch;
use camera_obscura::gallery::{FIGURES, Quality, generate};

#[test]
fn quick_gallery_makes_every_picture_and_none_is_blank() {
    let dir = scratch("gallery");
    let made = generate(&dir, Quality::Quick, |_| {}).expect("the gallery renders");
    assert_eq!(made.len(), FIGURES.len());
    for figure in FIGURES {
        // Each picture sits beside the scene that made it.
        let scene = dir.join(format!("{}.toml", figure.name));
        assert!(scene.is_file(), "{} missing", scene.display());
        let png = dir.join(format!("{}.png", figure.name));
        let image = image::open(&png)
            .unwrap_or_else(|e| panic!("{}: {e}", png.display()))
            .to_rgba8();
        assert!(
            image.width() >= 4 && image.height() >= 4,
            "{}",
            png.display()
        );
        // Opaque: the gallery composites the sky, so no pixel is transparent.
        assert!(
            image.pixels().all(|p| p[3] == 255),
            "{} has transparent pixels",
            png.display()
        );
        // Not blank: the luminance varies across the picture.
        let lum: Vec<f64> = image
            .pixels()
            .map(|p| (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0)
            .collect();
        let mean = lum.iter().sum::<f64>() / lum.len() as f64;
        let variance = lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lum.len() as f64;
        assert!(
            variance > 1.0,
            "{} is blank (variance {variance})",
            png.display()
        );
    }
    // The comparison figures report where their two renders differ.
    for m in &made {
        let comparison = m
            .png
            .file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with("postprocess");
        assert_eq!(!m.hot_cells.is_empty(), comparison, "{}", m.png.display());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
