//! Borrowed views of row-major (H, W, C) `u8` images, C = 1..=4.

use crate::error::Result;
use crate::invalid;

/// Largest width or height (pixels) of any image the core reads or writes.
pub const MAX_IMAGE_SIDE: usize = 16_384;
/// Largest number of pixels (W·H) of any image the core reads or writes.
pub const MAX_IMAGE_PIXELS: usize = 1 << 26;

/// Checks that a `width` x `height` image is non-empty and within the size limits.
pub fn check_size(what: &str, width: usize, height: usize) -> Result<()> {
    check_dims(what, width * height, width, height, 1)
}

fn check_dims(what: &str, len: usize, width: usize, height: usize, channels: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return invalid!("{what} must not be empty, got {width}x{height}");
    }
    if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE || width * height > MAX_IMAGE_PIXELS {
        return invalid!(
            "{what} of {width}x{height} pixels is too large (at most {MAX_IMAGE_SIDE} per side \
             and {MAX_IMAGE_PIXELS} pixels)"
        );
    }
    if !(1..=4).contains(&channels) {
        return invalid!("{what} must have 1 to 4 channels, got {channels}");
    }
    if len != width * height * channels {
        return invalid!("{what} buffer holds {len} bytes, expected {width}x{height}x{channels}");
    }
    Ok(())
}

/// A read-only image (the texture).
#[derive(Clone, Copy)]
pub struct ImageRef<'a> {
    pub data: &'a [u8],
    pub width: usize,
    pub height: usize,
    pub channels: usize,
}

impl<'a> ImageRef<'a> {
    /// Wraps a row-major buffer of `height * width * channels` bytes (a texture).
    pub fn new(data: &'a [u8], width: usize, height: usize, channels: usize) -> Result<Self> {
        Self::named("texture", data, width, height, channels)
    }

    /// [`ImageRef::new`] for an image that errors call `what`.
    pub fn named(
        what: &str,
        data: &'a [u8],
        width: usize,
        height: usize,
        channels: usize,
    ) -> Result<Self> {
        check_dims(what, data.len(), width, height, channels)?;
        Ok(Self {
            data,
            width,
            height,
            channels,
        })
    }
}

/// A writable image (the render target).
pub struct ImageMut<'a> {
    pub data: &'a mut [u8],
    pub width: usize,
    pub height: usize,
    pub channels: usize,
}

impl<'a> ImageMut<'a> {
    /// Wraps a row-major buffer of `height * width * channels` bytes.
    pub fn new(data: &'a mut [u8], width: usize, height: usize, channels: usize) -> Result<Self> {
        check_dims("output image", data.len(), width, height, channels)?;
        Ok(Self {
            data,
            width,
            height,
            channels,
        })
    }
}
