//! The facemime bitstream (`docs/bitstream.md`): a face's motion as a few hundred bytes a
//! second. Each frame's head pose, basis coefficients and extras (the look, format version 2)
//! are quantised, predicted from the previous decoded frame, and range coded with adaptive
//! integer models (the coder is the `constriction` crate's range coder on 16-bit words); frames
//! travel in packets framed with a length, a sequence number and a CRC-32, with an intra packet
//! every so often. From version 2 on, appearance chunks carry updates of the actor's texture,
//! passed on to the receiver as they are.

pub mod chunk;
pub mod decoder;
pub mod encoder;
pub mod header;
pub mod model;
pub mod packet;

pub use decoder::{Decoder, Output, Stats};
pub use encoder::{choose_classes, dequantise, Encoder, Quantise};
pub use header::{Header, Quantiser};
