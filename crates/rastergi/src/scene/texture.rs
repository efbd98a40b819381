//! Textures as a scene holds them: decoded images, 8 bits per channel, sRGB-encoded colour
//! (what PNG and JPEG base-colour and emissive images store) or linear data (normal maps), and
//! a linear alpha channel (opacity). Resampling, mip maps and sampling are
//! the renderer's business ([`crate::textures`]).

use std::io::Cursor;
use std::path::Path;

/// Largest image side accepted when decoding (a guard against hostile headers; the largest
/// texture WebGPU guarantees).
pub const MAX_DECODED_SIDE: u32 = 8192;
/// Largest allocation the image decoder may make for one image (8192² texels of 16-bit RGBA).
const MAX_DECODE_BYTES: u64 = 512 << 20;

/// An image used as a texture. Texture coordinates (u, v) address it with u to the
/// right and v down the image, (0, 0) the top-left corner of the first row (glTF's and
/// WebGPU's convention), repeating outside [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// Row by row from the top: red, green, blue (sRGB-encoded unless `linear`) and a linear
    /// alpha (255 where the image has none).
    pub texels: Vec<[u8; 4]>,
    /// The red, green and blue codes are linear values c/255 (normal maps), not sRGB colour.
    pub linear: bool,
}

/// A PNG or JPEG reader of `bytes` (the format recognised from them).
fn reader(bytes: &[u8]) -> Result<image::ImageReader<Cursor<&[u8]>>, String> {
    let reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot be read: {}", crate::error::one_line(e)))?;
    match reader.format() {
        Some(_) => Ok(reader),
        None => Err("is not a PNG or JPEG image".into()),
    }
}

impl Texture {
    /// The width and height a PNG or JPEG image declares, read from its header alone: what
    /// decoding it would allocate, to check against a budget first.
    pub fn dimensions(bytes: &[u8]) -> Result<(u32, u32), String> {
        reader(bytes)?
            .into_dimensions()
            .map_err(|e| format!("is not a valid PNG or JPEG image ({})", crate::error::one_line(e)))
    }

    /// Decodes a PNG or JPEG image (the format is recognised from its bytes), at most
    /// [`MAX_DECODED_SIDE`] texels a side.
    pub fn decode(name: &str, bytes: &[u8]) -> Result<Texture, String> {
        let mut reader = reader(bytes)?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_DECODED_SIDE);
        limits.max_image_height = Some(MAX_DECODED_SIDE);
        limits.max_alloc = Some(MAX_DECODE_BYTES);
        reader.limits(limits);
        let image =
            reader.decode().map_err(|e| format!("is not a valid PNG or JPEG image ({})", crate::error::one_line(e)))?;
        let rgba = image.into_rgba8();
        let (width, height) = rgba.dimensions();
        if width == 0 || height == 0 {
            return Err("is an empty image".into());
        }
        // The decoded bytes become the texels in place where the allocation allows.
        let texels = bytemuck::allocation::try_cast_vec(rgba.into_raw())
            .unwrap_or_else(|(_, raw)| raw.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect());
        Ok(Texture { name: name.to_owned(), width, height, texels, linear: false })
    }

    /// Reads and decodes an image file; errors say what is wrong without naming the file.
    pub fn read(path: &Path) -> Result<Texture, String> {
        let bytes = std::fs::read(path).map_err(|e| format!("cannot be read ({e})"))?;
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        Texture::decode(&name, &bytes)
    }

    /// The same image read as linear data (a normal map).
    pub fn into_linear(self) -> Texture {
        Texture { linear: true, ..self }
    }

    /// Whether some texel is not fully opaque.
    pub fn has_alpha(&self) -> bool {
        self.texels.iter().any(|t| t[3] < 255)
    }

    /// The alpha channel at `uv` (repeat addressing, bilinear between texel centres) of the
    /// image as decoded, level 0.
    pub fn alpha_at(&self, uv: glam::Vec2) -> f32 {
        let (w, h) = (self.width as i64, self.height as i64);
        let (x, y) = (uv.x * w as f32 - 0.5, uv.y * h as f32 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (a, b) = (x - x0, y - y0);
        let at = |i: i64, j: i64| self.texels[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize][3] as f32 / 255.0;
        let (i, j) = (x0 as i64, y0 as i64);
        (at(i, j) * (1.0 - a) + at(i + 1, j) * a) * (1.0 - b) + (at(i, j + 1) * (1.0 - a) + at(i + 1, j + 1) * a) * b
    }

    /// Checks the texel count against the size.
    pub fn validate(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err(format!("texture '{}' is empty ({}x{})", self.name, self.width, self.height));
        }
        if self.texels.len() as u64 != self.width as u64 * self.height as u64 {
            return Err(format!(
                "texture '{}' has {} texels for a size of {}x{}",
                self.name,
                self.texels.len(),
                self.width,
                self.height
            ));
        }
        Ok(())
    }
}
