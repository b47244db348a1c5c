//! Texture-mapping rasteriser (docs/method.md §3, the paper's eq. 18).
//!
//! - [`span`]: which pixels a triangle covers, scan line by scan line, with exact integer edge
//!   functions so that triangles sharing an edge cover every pixel exactly once.
//! - [`sampler`]: nearest and bilinear texture lookups in 16.16 fixed point.
//! - [`mesh`]: a whole textured mesh: back-face culling, far-to-near order or a z-buffer.
//! - [`affine`]: a picture resampled through an affine map (the face networks' crops, eye patches).

pub mod affine;
pub mod image;
pub mod mesh;
pub mod sampler;
#[cfg(target_arch = "x86_64")]
mod simd;
pub mod span;

pub use affine::{sample_affine, Border};
pub use image::{ImageMut, ImageRef, MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE};
pub use mesh::{coverage, render_mesh_into, DepthMode, Filter, RenderOptions, RenderStats};
