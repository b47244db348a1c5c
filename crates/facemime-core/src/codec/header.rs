//! The stream header (`docs/bitstream.md`, "Header"): what a receiver needs before the first
//! packet — picture, timing, which model, how the parameters are quantised and the basis that
//! turns coefficients into knot offsets.

use super::model::CLASSES;
use crate::error::Result;
use crate::invalid;

/// The four bytes every header starts with.
pub const MAGIC: &[u8; 4] = b"FMST";
/// The format version this code writes and reads.
pub const VERSION: u8 = 1;
/// Head-pose parameters that start every frame's parameter vector: yaw, pitch, roll (degrees),
/// ln scale (scale in px per model unit), tx, ty (px).
pub const POSE_PARAMETERS: usize = 6;
/// Most parameters per frame.
pub const MAX_PARAMETERS: usize = 255;
/// Largest picture side, px.
pub const MAX_SIDE: u16 = 16384;
/// Largest quantised value's magnitude.
pub const MAX_VALUE: i64 = 1 << 30;

/// One parameter's quantiser: value ≈ `q * step`; intra frames code `q - reference`; `class`
/// is the spread of its starting table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantiser {
    pub step: f32,
    pub reference: i32,
    pub class: u8,
}

/// Everything the header carries.
#[derive(Debug, Clone, PartialEq)]
pub struct Header {
    /// Frame rate, `fps_num / fps_den` frames per second.
    pub fps_num: u32,
    pub fps_den: u32,
    /// Picture size, px.
    pub width: u16,
    pub height: u16,
    /// Identifies the head model's topology (which vertices the knots are).
    pub topology: [u8; 8],
    /// Frames per packet (the last packet may hold fewer).
    pub packet_frames: u8,
    /// Packets from one intra packet to the next.
    pub keyframe_packets: u16,
    /// Per parameter: the six pose parameters, then one per basis vector.
    pub quantisers: Vec<Quantiser>,
    /// Length of each basis vector: twice the knot count (x, y per knot).
    pub basis_rows: u16,
    /// The basis vectors, one after the other, entries ×32767.
    pub basis: Vec<i16>,
    /// Identifies the actor (SHA-256, `docs/bitstream.md`, "Actor").
    pub actor_id: [u8; 32],
    /// Whether an actor chunk follows the header.
    pub actor_in_stream: bool,
}

struct Bytes<'a> {
    buf: &'a [u8],
    at: usize,
}

impl<'a> Bytes<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        match self.buf.get(self.at..self.at + n) {
            Some(s) => {
                self.at += n;
                Ok(s)
            }
            None => invalid!("the stream header is cut short"),
        }
    }
    fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }
    fn u16(&mut self) -> Result<u16> {
        Ok(u16::from_le_bytes(
            self.take(2)?.try_into().expect("two bytes"),
        ))
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("four bytes"),
        ))
    }
}

impl Header {
    /// Coefficients per frame (parameters after the pose).
    pub fn coefficients(&self) -> usize {
        self.quantisers.len() - POSE_PARAMETERS
    }

    /// Checks every field's range.
    pub fn validate(&self) -> Result<()> {
        if self.fps_num == 0
            || self.fps_den == 0
            || self.fps_num as f64 / self.fps_den as f64 > 1000.0
        {
            return invalid!(
                "frame rate {}/{} is not in (0, 1000] frames/s",
                self.fps_num,
                self.fps_den
            );
        }
        if self.width == 0 || self.height == 0 || self.width > MAX_SIDE || self.height > MAX_SIDE {
            return invalid!(
                "picture size {}x{} is not within 1..{MAX_SIDE}",
                self.width,
                self.height
            );
        }
        if self.packet_frames == 0 || self.packet_frames as usize > super::chunk::MAX_PACKET_FRAMES
        {
            return invalid!(
                "{} frames per packet is not within 1..32",
                self.packet_frames
            );
        }
        if self.keyframe_packets == 0 {
            return invalid!("the keyframe interval must be at least one packet");
        }
        let n = self.quantisers.len();
        if !(POSE_PARAMETERS..=MAX_PARAMETERS).contains(&n) {
            return invalid!(
                "{n} parameters per frame is not within {POSE_PARAMETERS}..{MAX_PARAMETERS}"
            );
        }
        for (i, q) in self.quantisers.iter().enumerate() {
            if !(q.step.is_finite() && q.step > 0.0)
                || q.class as usize >= CLASSES
                || q.reference.unsigned_abs() as i64 > MAX_VALUE
            {
                return invalid!(
                    "parameter {i} has a bad quantiser (step {}, class {})",
                    q.step,
                    q.class
                );
            }
        }
        if self.basis.len() != self.coefficients() * self.basis_rows as usize {
            return invalid!(
                "the basis holds {} entries, not {} x {}",
                self.basis.len(),
                self.coefficients(),
                self.basis_rows
            );
        }
        Ok(())
    }

    /// The header chunk's payload.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(64 + 9 * self.quantisers.len() + 2 * self.basis.len());
        out.extend_from_slice(MAGIC);
        out.push(VERSION);
        out.extend_from_slice(&self.fps_num.to_le_bytes());
        out.extend_from_slice(&self.fps_den.to_le_bytes());
        out.extend_from_slice(&self.width.to_le_bytes());
        out.extend_from_slice(&self.height.to_le_bytes());
        out.extend_from_slice(&self.topology);
        out.push(self.packet_frames);
        out.extend_from_slice(&self.keyframe_packets.to_le_bytes());
        out.push(self.quantisers.len() as u8);
        for q in &self.quantisers {
            out.extend_from_slice(&q.step.to_le_bytes());
            out.extend_from_slice(&q.reference.to_le_bytes());
            out.push(q.class);
        }
        out.extend_from_slice(&self.basis_rows.to_le_bytes());
        for v in &self.basis {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.actor_id);
        out.push(self.actor_in_stream as u8);
        out
    }

    /// Parses and validates a header chunk's payload.
    pub fn parse(buf: &[u8]) -> Result<Header> {
        let mut b = Bytes { buf, at: 0 };
        if b.take(4)? != MAGIC {
            return invalid!("not a facemime stream (no FMST header)");
        }
        let version = b.u8()?;
        if version != VERSION {
            return invalid!(
                "stream format version {version}; this decoder reads version {VERSION}"
            );
        }
        let (fps_num, fps_den, width, height) = (b.u32()?, b.u32()?, b.u16()?, b.u16()?);
        let topology: [u8; 8] = b.take(8)?.try_into().expect("eight bytes");
        let (packet_frames, keyframe_packets, n) = (b.u8()?, b.u16()?, b.u8()? as usize);
        if !(POSE_PARAMETERS..=MAX_PARAMETERS).contains(&n) {
            return invalid!(
                "{n} parameters per frame is not within {POSE_PARAMETERS}..{MAX_PARAMETERS}"
            );
        }
        let mut quantisers = Vec::with_capacity(n);
        for _ in 0..n {
            let step = f32::from_le_bytes(b.take(4)?.try_into().expect("four bytes"));
            let reference = b.u32()? as i32;
            quantisers.push(Quantiser {
                step,
                reference,
                class: b.u8()?,
            });
        }
        let basis_rows = b.u16()?;
        let entries = (n - POSE_PARAMETERS) * basis_rows as usize;
        let basis = b
            .take(2 * entries)?
            .chunks_exact(2)
            .map(|c| i16::from_le_bytes([c[0], c[1]]))
            .collect();
        let actor_id: [u8; 32] = b.take(32)?.try_into().expect("32 bytes");
        let actor_in_stream = match b.u8()? {
            0 => false,
            1 => true,
            v => return invalid!("the header's actor flag is {v}, not 0 or 1"),
        };
        if b.at != buf.len() {
            return invalid!("the stream header has {} bytes too many", buf.len() - b.at);
        }
        let header = Header {
            fps_num,
            fps_den,
            width,
            height,
            topology,
            packet_frames,
            keyframe_packets,
            quantisers,
            basis_rows,
            basis,
            actor_id,
            actor_in_stream,
        };
        header.validate()?;
        Ok(header)
    }
}
