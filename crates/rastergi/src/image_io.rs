//! Images in and out. Output format follows the file extension: `.exr` is linear f32 RGB,
//! `.png` the display encoding. Files are written to a temporary file in the target's
//! directory and renamed over the target only once complete, so a failed write never leaves
//! a broken file or clobbers a good one.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Linear RGB radiance, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl LinearImage {
    pub fn at(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Mean of each channel.
    pub fn mean(&self) -> [f64; 3] {
        let mut m = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                m[c] += p[c] as f64;
            }
        }
        m.map(|v| v / self.pixels.len().max(1) as f64)
    }
}

/// 8-bit sRGB RGBA, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct DisplayImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

/// The image formats rastergi writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Exr,
    Png,
}

impl ImageFormat {
    pub fn from_path(path: &Path) -> Result<ImageFormat> {
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("exr") => Ok(ImageFormat::Exr),
            Some("png") => Ok(ImageFormat::Png),
            _ => Err(image_error(path, "unsupported output format; use a .exr (linear) or .png (display) file name")),
        }
    }
}

fn image_error(path: &Path, message: impl Into<String>) -> Error {
    Error::ImageFile { path: path.to_path_buf(), message: message.into() }
}

/// Writes via a temporary file in the same directory, renamed over `path` on success.
fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> std::result::Result<(), String>) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let suffix = path.extension().map(|e| format!(".{}", e.to_string_lossy())).unwrap_or_default();
    let mut builder = tempfile::Builder::new();
    builder.prefix(".rastergi-").suffix(&suffix);
    // Temporary files are private by default; the image should get the usual permissions.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    let tmp = builder
        .tempfile_in(&dir)
        .map_err(|e| image_error(path, format!("cannot create a file in {}: {e}", dir.display())))?;
    write(tmp.path()).map_err(|e| image_error(path, e))?;
    tmp.persist(path).map_err(|e| image_error(path, format!("cannot replace the file: {}", e.error)))?;
    Ok(())
}

pub fn write_exr(path: &Path, image: &LinearImage) -> Result<()> {
    if image.pixels.len() != (image.width * image.height) as usize {
        return Err(image_error(path, "pixel count does not match the image size"));
    }
    write_atomically(path, |tmp| {
        let w = image.width as usize;
        exr::prelude::write_rgb_file(tmp, w, image.height as usize, |x, y| {
            let p = image.pixels[y * w + x];
            (p[0], p[1], p[2])
        })
        .map_err(|e| e.to_string())
    })
}

pub fn write_png(path: &Path, image: &DisplayImage) -> Result<()> {
    if image.rgba.len() != 4 * (image.width * image.height) as usize {
        return Err(image_error(path, "pixel count does not match the image size"));
    }
    write_atomically(path, |tmp| {
        image::save_buffer_with_format(
            tmp,
            &image.rgba,
            image.width,
            image.height,
            image::ExtendedColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .map_err(|e| e.to_string())
    })
}

/// Reads the first RGB(A) layer of an EXR file as linear RGB.
pub fn read_exr(path: &Path) -> Result<LinearImage> {
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        path,
        |resolution, _| (resolution.width(), vec![[0.0f32; 3]; resolution.width() * resolution.height()]),
        |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| px[pos.y() * *w + pos.x()] = [r, g, b],
    )
    .map_err(|e| image_error(path, format!("cannot read EXR: {e}")))?;
    let size = img.layer_data.size;
    Ok(LinearImage {
        width: size.width() as u32,
        height: size.height() as u32,
        pixels: img.layer_data.channel_data.pixels.1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trips_and_rows_start_at_the_top() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let img = LinearImage { width: 3, height: 2, pixels: (0..6).map(|i| [i as f32, 0.5, -1.0]).collect() };
        write_exr(&path, &img).unwrap();
        assert_eq!(read_exr(&path).unwrap(), img);
    }

    #[test]
    fn failed_write_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("keep.png");
        std::fs::write(&path, b"good").unwrap();
        // An encoder that fails half-way through its output.
        let result = write_atomically(&path, |tmp| {
            std::fs::write(tmp, b"half").unwrap();
            Err("disk full".into())
        });
        assert!(result.unwrap_err().to_string().contains("disk full"));
        assert_eq!(std::fs::read(&path).unwrap(), b"good");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // A pixel buffer that does not match the size is refused before anything is written.
        let bad = DisplayImage { width: 4, height: 4, rgba: vec![0; 3] };
        assert!(write_png(&path, &bad).is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"good");
    }

    #[test]
    fn unknown_extension_is_refused() {
        assert!(ImageFormat::from_path(Path::new("x.jpg")).is_err());
        assert_eq!(ImageFormat::from_path(Path::new("x.EXR")).unwrap(), ImageFormat::Exr);
    }
}
