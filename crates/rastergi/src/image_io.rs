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
    // The exr crate panics on an empty image.
    if image.width == 0 || image.height == 0 {
        return Err(image_error(path, "cannot write an empty image (0 pixels wide or high)"));
    }
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

/// Reads the first RGB(A) layer of an EXR file as linear RGB, at most the default texel
/// budget's pixels ([`crate::scene::Budgets`]).
pub fn read_exr(path: &Path) -> Result<LinearImage> {
    read_exr_within(path, crate::scene::Budgets::default().texels)
}

/// [`read_exr`] of at most `max_pixels` pixels in any layer (the headers are read first, the
/// pixels only if they are within it).
pub fn read_exr_within(path: &Path, max_pixels: u64) -> Result<LinearImage> {
    let file = std::fs::File::open(path).map_err(|e| image_error(path, format!("cannot be opened: {e}")))?;
    decode_exr(std::io::BufReader::new(file), max_pixels).map_err(|m| image_error(path, m))
}

/// Decodes the first RGB(A) layer of an EXR image as linear RGB; refuses, before reading a
/// pixel, an image with a layer of more than `max_pixels` (the size its header declares,
/// which reading would allocate). Errors say what is wrong without naming the file.
pub fn decode_exr(
    mut reader: impl std::io::Read + std::io::Seek,
    max_pixels: u64,
) -> std::result::Result<LinearImage, String> {
    use exr::prelude::*;
    let meta = exr::meta::MetaData::read_from_buffered(&mut reader, false)
        .map_err(|e| format!("cannot read EXR: {}", crate::error::one_line(e)))?;
    for header in meta.headers.iter() {
        let (w, h) = (header.layer_size.width() as u64, header.layer_size.height() as u64);
        let budgets = crate::scene::Budgets { texels: max_pixels, ..Default::default() };
        let check = budgets.check(crate::scene::Budget::Texels, w.saturating_mul(h), &format!("{w}x{h}"));
        check.map_err(|m| format!("its header {m}"))?;
    }
    reader.seek(std::io::SeekFrom::Start(0)).map_err(|e| format!("cannot be read again: {e}"))?;
    let img = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |resolution, _| (resolution.width(), vec![[0.0f32; 3]; resolution.width() * resolution.height()]),
            |(w, px): &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = [r, g, b]
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(reader)
        .map_err(|e| format!("cannot read EXR: {}", crate::error::one_line(e)))?;
    let size = img.layer_data.size;
    Ok(LinearImage {
        width: size.width() as u32,
        height: size.height() as u32,
        pixels: img.layer_data.channel_data.pixels.1,
    })
}

/// The display encoding of `image` on the CPU, as the film's resolve pass makes it on the GPU
/// (`resolve.wgsl`): 2^exposure · value, clamped to [0, 1], the sRGB transfer function,
/// rounded to 8 bits; alpha 255.
pub fn display_encode(image: &LinearImage, exposure: f32) -> DisplayImage {
    let scale = exposure.exp2();
    let encode = |v: f32| {
        let c = (v * scale).clamp(0.0, 1.0);
        let e = if c <= 0.0031308 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (e * 255.0).round() as u8
    };
    let rgba = image.pixels.iter().flat_map(|p| [encode(p[0]), encode(p[1]), encode(p[2]), 255]).collect();
    DisplayImage { width: image.width, height: image.height, rgba }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1): display value in [0, 1] → linear.
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}

/// Reads a PNG as linear RGB: the 8- or 16-bit sRGB values are decoded by the sRGB transfer
/// function (grey images are spread over R, G, B; alpha is ignored). A PNG holds display values,
/// clamped to [0, 1] and quantised, so it only approximates the radiance it was made from.
pub fn read_png(path: &Path) -> Result<LinearImage> {
    let mut reader = image::ImageReader::open(path).map_err(|e| image_error(path, format!("cannot be opened: {e}")))?;
    reader.set_format(image::ImageFormat::Png);
    let decoded =
        reader.decode().map_err(|e| image_error(path, format!("cannot read PNG: {}", crate::error::one_line(e))))?;
    let rgb = decoded.to_rgb32f();
    Ok(LinearImage {
        width: rgb.width(),
        height: rgb.height(),
        pixels: rgb.pixels().map(|p| p.0.map(srgb_to_linear)).collect(),
    })
}

/// Reads an image for comparison, by its extension: `.exr` as linear radiance
/// ([`read_exr`]), `.png` as display values decoded to linear ([`read_png`]). Refuses a missing
/// file, another extension and an image without pixels.
pub fn read_image(path: &Path) -> Result<LinearImage> {
    if !path.exists() {
        return Err(image_error(path, "no such file"));
    }
    if path.is_dir() {
        return Err(image_error(path, "is a directory, not an image"));
    }
    let image = match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
        Some("exr") => read_exr(path)?,
        Some("png") => read_png(path)?,
        _ => return Err(image_error(path, "unsupported image format; use a .exr (linear) or .png (display) file")),
    };
    non_empty(path, image)
}

fn non_empty(path: &Path, image: LinearImage) -> Result<LinearImage> {
    if image.width == 0 || image.height == 0 || image.pixels.is_empty() {
        return Err(image_error(path, format!("the image is empty ({} x {} pixels)", image.width, image.height)));
    }
    Ok(image)
}

/// Pixels of an image that are NaN or infinite in some channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NonFinitePixels {
    /// How many pixels have a NaN or infinite channel.
    pub count: usize,
    /// Column and row (0-based, row 0 at the top) of the first, in row-major order.
    pub first: (u32, u32),
}

impl std::fmt::Display for NonFinitePixels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (x, y) = self.first;
        let pixels = if self.count == 1 { "pixel is" } else { "pixels are" };
        write!(f, "{} {pixels} NaN or infinite, the first at x = {x}, y = {y} (0-based, row 0 at the top)", self.count)
    }
}

impl std::error::Error for NonFinitePixels {}

/// Checks that every channel of every pixel is a finite number.
pub fn validate_finite(image: &LinearImage) -> std::result::Result<(), NonFinitePixels> {
    let bad = |p: &[f32; 3]| !p.iter().all(|c| c.is_finite());
    let Some(first) = image.pixels.iter().position(bad) else { return Ok(()) };
    let width = image.width.max(1) as usize;
    Err(NonFinitePixels {
        count: image.pixels.iter().filter(|p| bad(p)).count(),
        first: ((first % width) as u32, (first / width) as u32),
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

    #[test]
    fn png_is_decoded_from_srgb_to_linear() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        // Two pixels: sRGB 0, 10, 128 and 255, 200, 188 (alpha ignored).
        let rgba = vec![0, 10, 128, 255, 255, 200, 188, 7];
        write_png(&path, &DisplayImage { width: 2, height: 1, rgba: rgba.clone() }).unwrap();
        let img = read_image(&path).unwrap();
        assert_eq!((img.width, img.height), (2, 1));
        // IEC 61966-2-1, written out: linear = v/12.92 below 0.04045, else ((v+0.055)/1.055)^2.4.
        let expected = |v: u8| {
            let v = v as f64 / 255.0;
            if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
        };
        for (i, p) in img.pixels.iter().enumerate() {
            for c in 0..3 {
                assert!((p[c] as f64 - expected(rgba[4 * i + c])).abs() < 1e-6, "pixel {i} channel {c}: {}", p[c]);
            }
        }
        assert!((img.pixels[0][2] - 0.2158605).abs() < 1e-6, "sRGB 128 is linear 0.2158605");
    }

    #[test]
    fn read_image_refuses_missing_unknown_corrupt_and_empty_files() {
        let dir = tempfile::tempdir().unwrap();
        let missing = read_image(&dir.path().join("nope.exr")).unwrap_err().to_string();
        assert!(missing.contains("nope.exr") && missing.contains("no such file"), "{missing}");
        let tif = dir.path().join("a.tif");
        std::fs::write(&tif, b"II*\0").unwrap();
        assert!(read_image(&tif).unwrap_err().to_string().contains("unsupported image format"));
        for name in ["bad.exr", "bad.png"] {
            let path = dir.path().join(name);
            std::fs::write(&path, b"not an image at all").unwrap();
            let e = read_image(&path).unwrap_err().to_string();
            assert!(e.contains(name) && e.contains("cannot read"), "{e}");
        }
        let e = read_image(dir.path()).unwrap_err().to_string();
        assert!(e.contains("directory"), "{e}");
        // EXR and PNG files cannot hold an empty image; the check behind read_image still says so.
        let empty = non_empty(&tif, LinearImage { width: 0, height: 4, pixels: vec![] }).unwrap_err().to_string();
        assert!(empty.contains("a.tif") && empty.contains("empty (0 x 4 pixels)"), "{empty}");
        assert!(
            write_exr(&dir.path().join("empty.exr"), &LinearImage { width: 0, height: 4, pixels: vec![] }).is_err()
        );
    }

    #[test]
    fn non_finite_pixels_are_counted_and_the_first_located() {
        let mut img = LinearImage { width: 4, height: 3, pixels: vec![[0.5; 3]; 12] };
        assert_eq!(validate_finite(&img), Ok(()));
        img.pixels[2 * 4 + 1][1] = f32::NAN; // x 1, y 2
        img.pixels[2 * 4 + 3][0] = f32::INFINITY;
        img.pixels[4 + 2][2] = f32::NEG_INFINITY; // x 2, y 1: the first in row-major order
        let e = validate_finite(&img).unwrap_err();
        assert_eq!(e, NonFinitePixels { count: 3, first: (2, 1) });
        assert!(e.to_string().starts_with("3 pixels are NaN or infinite, the first at x = 2, y = 1"), "{e}");
    }
}
