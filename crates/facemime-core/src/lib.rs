//! facemime-core: the pure-Rust algorithms of facemime (no Python in here).
//!
//! Conventions shared by every module:
//! - Images are row-major `u8` buffers of shape (H, W, C), C = 1..=4 channels.
//! - Points are (x, y) pixels, x to the right, y down, (0, 0) at the *centre* of the top-left
//!   pixel, so pixel centres sit on integer coordinates.
//! - Depth is a float along the view direction, **larger = nearer the camera**.

pub mod adjust;
mod border;
pub mod codec;
pub mod corners;
mod cpu;
pub mod error;
pub mod extent;
pub mod flow;
mod grey;
pub mod head;
pub mod lip_placement;
pub mod lip_search;
mod median;
pub mod motion;
pub mod pose;
pub mod raster;
pub mod snake;
pub mod template;

pub use error::CoreError;
