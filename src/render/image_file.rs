//! Image files the renderer writes: PNG, or JPEG, chosen by the file's extension. Anything else
//! is refused before a frame is drawn, so a user never finds PNG bytes under a .jpg name.

use crate::gpu::Pixels;
use std::path::Path;

/// JPEG quality (1–100): high enough that curve edges and the HUD text stay clean.
const JPEG_QUALITY: u8 = 92;

/// How an image file is encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Jpeg,
}

impl ImageFormat {
    /// The format `path`'s extension names (case does not matter), or why none fits.
    pub fn of(path: &Path) -> Result<Self, String> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("jpg" | "jpeg") => Ok(ImageFormat::Jpeg),
            Some(other) => Err(format!(
                "{}: cannot write .{other} images (use .png, .jpg or .jpeg)",
                path.display()
            )),
            None => Err(format!(
                "{}: the image needs an extension that names its format (.png, .jpg or .jpeg)",
                path.display()
            )),
        }
    }
}

/// Writes `pixels` to `path` in the format its extension names.
pub fn write_image(pixels: &Pixels, path: &Path) -> Result<(), String> {
    match ImageFormat::of(path)? {
        ImageFormat::Png => pixels.write_png(path).map_err(|e| e.to_string()),
        ImageFormat::Jpeg => {
            let width = u16::try_from(pixels.width).ok();
            let height = u16::try_from(pixels.height).ok();
            let (Some(w), Some(h)) = (width, height) else {
                return Err(format!(
                    "{}: JPEG images are at most 65535 pixels wide and high",
                    path.display()
                ));
            };
            let encoder = jpeg_encoder::Encoder::new_file(path, JPEG_QUALITY)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            encoder
                .encode(&pixels.rgba, w, h, jpeg_encoder::ColorType::Rgba)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_come_from_the_extension() {
        assert_eq!(ImageFormat::of(Path::new("a.png")), Ok(ImageFormat::Png));
        assert_eq!(ImageFormat::of(Path::new("a.JPG")), Ok(ImageFormat::Jpeg));
        assert_eq!(
            ImageFormat::of(Path::new("d/a.jpeg")),
            Ok(ImageFormat::Jpeg)
        );
        let gif = ImageFormat::of(Path::new("a.gif")).unwrap_err();
        assert!(gif.contains("cannot write .gif images"), "{gif}");
        assert!(ImageFormat::of(Path::new("noext")).is_err());
    }
}
