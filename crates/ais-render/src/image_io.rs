//! RGB float images: reading EXR (exr crate) and Radiance HDR (image crate) with
//! sanitising, and writing EXR (32-bit float RGB) and a tone-mapped sRGB PNG preview.

use crate::atomic_write::write_atomically;
use crate::error::InputError;
use std::path::Path;

/// A linear RGB image, row-major from the top-left pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width * height` pixels.
    pub pixels: Vec<[f32; 3]>,
}

/// An image read from a file, with the texels that had to be sanitised.
#[derive(Clone, Debug)]
pub struct LoadedImage {
    /// The image, every channel finite and non-negative.
    pub image: RgbImage,
    /// A warning naming the file and counting the channels clamped to 0, if any were.
    pub warning: Option<String>,
}

impl RgbImage {
    /// A black image.
    pub fn new(width: usize, height: usize) -> Self {
        RgbImage {
            width,
            height,
            pixels: vec![[0.0; 3]; width * height],
        }
    }

    /// Replaces NaN, infinite, negative and absurdly large (above [`LARGEST_TEXEL`])
    /// channels by 0; returns how many there were.
    pub fn sanitize(&mut self) -> usize {
        let mut count = 0;
        for channel in self.pixels.iter_mut().flatten() {
            if !(channel.is_finite() && (0.0..=LARGEST_TEXEL).contains(channel)) {
                *channel = 0.0;
                count += 1;
            }
        }
        count
    }
}

/// The most texels an image may have (16384 × 16384).
pub const LARGEST_IMAGE_TEXELS: usize = 1 << 28;

/// The largest texel value read as is: beyond it, sums of texels (an envmap's sampling
/// weights, a pixel's estimate) overflow f32.
pub const LARGEST_TEXEL: f32 = 1e20;

/// Reads an `.exr` or `.hdr` file into linear RGB, sanitising bad texels.
pub fn read_image(path: &Path) -> Result<LoadedImage, InputError> {
    crate::error::check_input_file(path, "image file")?;
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let mut image = match extension.as_deref() {
        Some("exr") => read_exr(path)?,
        Some("hdr") => read_hdr(path)?,
        _ => {
            return Err(InputError::new(
                path,
                "unsupported image format: use .exr or .hdr",
            ))
        }
    };
    let bad = image.sanitize();
    let warning = (bad > 0).then(|| {
        format!(
            "{}: {bad} texel channel(s) were NaN, infinite, negative or above 1e20 and were set to 0",
            path.display()
        )
    });
    Ok(LoadedImage { image, warning })
}

fn read_exr(path: &Path) -> Result<RgbImage, InputError> {
    check_exr_header(path)?;
    let result = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |resolution, _| RgbImage::new(resolution.width(), resolution.height()),
        |image: &mut RgbImage, position, (r, g, b, _a): (f32, f32, f32, f32)| {
            let index = position.y() * image.width + position.x();
            image.pixels[index] = [r, g, b];
        },
    )
    .map_err(|e| InputError::new(path, format!("cannot read EXR: {e}")))?;
    Ok(result.layer_data.channel_data.pixels)
}

/// Refuses an EXR whose first layer is larger than [`LARGEST_IMAGE_TEXELS`] or has no R, G
/// or B channel (a luminance-only image, say), naming the channels it has.
fn check_exr_header(path: &Path) -> Result<(), InputError> {
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .map_err(|e| InputError::new(path, format!("cannot read EXR: {e}")))?;
    let Some(header) = meta.headers.first() else {
        return Err(InputError::new(path, "the EXR has no layer"));
    };
    let size = header.layer_size;
    if size.area() > LARGEST_IMAGE_TEXELS {
        return Err(InputError::new(
            path,
            format!(
                "the EXR is {}×{} texels, more than the {LARGEST_IMAGE_TEXELS} ais reads",
                size.width(),
                size.height()
            ),
        ));
    }
    let names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    let has = |name: &str| {
        names
            .iter()
            .any(|n| n == name || n.ends_with(&format!(".{name}")))
    };
    if has("R") || has("G") || has("B") {
        return Ok(());
    }
    Err(InputError::new(
        path,
        format!(
            "the EXR has the channels {} but no R, G or B; ais reads RGB images",
            names.join(", ")
        ),
    ))
}

fn read_hdr(path: &Path) -> Result<RgbImage, InputError> {
    let decoded = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| InputError::new(path, format!("cannot open HDR: {e}")))?
        .decode()
        .map_err(|e| InputError::new(path, format!("cannot read HDR: {e}")))?
        .into_rgb32f();
    Ok(RgbImage {
        width: decoded.width() as usize,
        height: decoded.height() as usize,
        pixels: decoded.pixels().map(|p| p.0).collect(),
    })
}

/// Reads a PNG, JPEG, BMP, TGA or PPM/PGM texture into linear RGB: sRGB-decoded when `srgb` (Mitsuba's
/// default for such images), else the stored values scaled to [0, 1]. At most 16384 texels
/// a side; alpha is dropped.
pub fn read_ldr_image(path: &Path, srgb: bool) -> Result<RgbImage, InputError> {
    crate::error::check_input_file(path, "image file")?;
    let mut reader = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| InputError::new(path, format!("cannot open image: {e}")))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(16384);
    limits.max_image_height = Some(16384);
    reader.limits(limits);
    let decoded = reader
        .decode()
        .map_err(|e| InputError::new(path, format!("cannot read image: {e}")))?
        .into_rgb32f();
    let decode = |c: f32| if srgb { srgb_to_linear(c) } else { c };
    Ok(RgbImage {
        width: decoded.width() as usize,
        height: decoded.height() as usize,
        pixels: decoded.pixels().map(|p| p.0.map(decode)).collect(),
    })
}

/// The sRGB transfer function, inverted: an encoded value in [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// An error while writing an output image.
#[derive(Debug)]
pub struct WriteError(pub String);

impl From<std::io::Error> for WriteError {
    fn from(e: std::io::Error) -> Self {
        WriteError(e.to_string())
    }
}

impl std::fmt::Display for WriteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for WriteError {}

/// Writes 32-bit float RGB EXR atomically. Refuses images with non-finite pixels.
pub fn write_exr(path: &Path, image: &RgbImage) -> Result<(), WriteError> {
    write_atomically(path, |temporary| encode_exr(temporary, image, path))
}

/// Writes 32-bit float RGB EXR to `file` (errors name `target`, the file it stands for).
/// Chunks are compressed in order on one thread, so the same image always gives the same
/// bytes. Refuses images with non-finite pixels.
pub fn encode_exr(file: &Path, image: &RgbImage, target: &Path) -> Result<(), WriteError> {
    if let Some(index) = image
        .pixels
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(WriteError(format!(
            "{}: pixel ({}, {}) is not finite; refusing to write",
            target.display(),
            index % image.width,
            index / image.width
        )));
    }
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|Vec2(x, y)| {
        let p: [f32; 3] = image.pixels[y * image.width + x];
        (p[0], p[1], p[2])
    });
    Image::from_channels((image.width, image.height), channels)
        .write()
        .non_parallel()
        .to_file(file)
        .map_err(|e| WriteError(format!("{}: cannot write EXR: {e}", target.display())))
}

/// The sRGB transfer function of a linear value in [0, 1].
fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// Writes an 8-bit sRGB PNG preview atomically: pixels scaled by 2^`exposure`, clamped.
pub fn write_png(path: &Path, image: &RgbImage, exposure: f32) -> Result<(), WriteError> {
    write_atomically(path, |temporary| {
        encode_png(temporary, image, exposure, path)
    })
}

/// Writes an 8-bit sRGB PNG preview to `file` (errors name `target`, the file it stands
/// for): pixels scaled by 2^`exposure`, clamped.
pub fn encode_png(
    file: &Path,
    image: &RgbImage,
    exposure: f32,
    target: &Path,
) -> Result<(), WriteError> {
    let scale = exposure.exp2();
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|p| p.map(|c| (srgb_encode((c * scale).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8))
        .collect();
    image::save_buffer_with_format(
        file,
        &bytes,
        image.width as u32,
        image.height as u32,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|e| WriteError(format!("{}: cannot write PNG: {e}", target.display())))
}
