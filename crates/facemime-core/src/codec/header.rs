//! The stream header (`docs/bitstream.md`, "Header"): what a receiver needs before the first
//! packet — picture, timing, which model, how the parameters are quantised, which of them are
//! extras (version 2) and the basis that turns coefficients into knot offsets.

use super::model::CLASSES;
use crate::error::Result;
use crate::invalid;

/// The four bytes every header starts with.
pub const MAGIC: &[u8; 4] = b"FMST";
/// The format version of a header without extra parameters (written byte for byte as before
/// version 2 existed).
pub const VERSION: u8 = 1;
/// The format version of a header with extra parameters; the newest this code reads.
pub const VERSION_EXTRAS: u8 = 2;
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
    /// Per parameter: the six pose parameters, then one per basis vector, then the extras.
    pub quantisers: Vec<Quantiser>,
    /// The kind (1-255, distinct) of each extra parameter, the last `extras.len()` of the
    /// quantisers (`docs/bitstream.md`, "Look"); empty for a version-1 header. The core codes
    /// extras like any parameter and never interprets their kinds.
    pub extras: Vec<u8>,
    /// Length of each basis vector: twice the knot count (x, y per knot).
    pub basis_rows: u16,
    /// The basis vectors, one after the other, entries ×32767.
    pub basis: Vec<i16>,
    /// Identifies the actor (SHA-256, `docs/bitstream.md`, "Actor").
    pub actor_id: [u8; 32],
    /// Whether an actor chunk follows the header.
    pub actor_in_stream: bool,
}

/// Checks the extra parameters' kinds against `n` parameters: at most `n - 6` of them, each
/// 1-255, no kind twice.
fn check_extras(n: usize, kinds: &[u8]) -> Result<()> {
    if kinds.len() > n.saturating_sub(POSE_PARAMETERS) {
        return invalid!(
            "{} extra parameters do not fit in {n} parameters per frame (at most {} after the pose)",
            kinds.len(),
            n.saturating_sub(POSE_PARAMETERS)
        );
    }
    for (i, &k) in kinds.iter().enumerate() {
        if k == 0 {
            return invalid!("extra parameter {i} has kind 0; kinds are 1-255");
        }
        if kinds[..i].contains(&k) {
            return invalid!("extra parameter kind {k} appears twice");
        }
    }
    Ok(())
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
    /// Coefficients per frame (parameters between the pose and the extras); 0 for a header
    /// with more extras than parameters after the pose (which [`Header::validate`] refuses).
    pub fn coefficients(&self) -> usize {
        self.quantisers
            .len()
            .saturating_sub(POSE_PARAMETERS + self.extras.len())
    }

    /// The format version this header is written in: 1 without extras, 2 with.
    pub fn version(&self) -> u8 {
        if self.extras.is_empty() {
            VERSION
        } else {
            VERSION_EXTRAS
        }
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
        check_extras(n, &self.extras)?;
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
        let mut out = Vec::with_capacity(64 + 10 * self.quantisers.len() + 2 * self.basis.len());
        out.extend_from_slice(MAGIC);
        out.push(self.version());
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
        if !self.extras.is_empty() {
            out.push(self.extras.len() as u8);
            out.extend_from_slice(&self.extras);
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
        if version != VERSION && version != VERSION_EXTRAS {
            return invalid!(
                "stream format version {version}; this decoder reads versions {VERSION} and {VERSION_EXTRAS}"
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
        let extras = if version == VERSION_EXTRAS {
            let x = b.u8()? as usize;
            let kinds = b.take(x)?.to_vec();
            check_extras(n, &kinds)?;
            kinds
        } else {
            Vec::new()
        };
        let basis_rows = b.u16()?;
        let entries = (n - POSE_PARAMETERS - extras.len()) * basis_rows as usize;
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
            extras,
            basis_rows,
            basis,
            actor_id,
            actor_in_stream,
        };
        header.validate()?;
        Ok(header)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A header of `coefficients` basis vectors of 4 rows and extras of `kinds`.
    fn header(coefficients: usize, kinds: &[u8]) -> Header {
        let n = POSE_PARAMETERS + coefficients + kinds.len();
        Header {
            fps_num: 30000,
            fps_den: 1001,
            width: 640,
            height: 480,
            topology: *b"top-olog",
            packet_frames: 8,
            keyframe_packets: 4,
            quantisers: (0..n)
                .map(|i| Quantiser {
                    step: 0.25 + i as f32,
                    reference: i as i32 - 3,
                    class: (i % CLASSES) as u8,
                })
                .collect(),
            extras: kinds.to_vec(),
            basis_rows: 4,
            basis: (0..4 * coefficients).map(|i| i as i16 * 97 - 500).collect(),
            actor_id: [3; 32],
            actor_in_stream: true,
        }
    }

    #[test]
    fn a_header_without_extras_is_version_1_and_one_with_extras_version_2() {
        let v1 = header(3, &[]).to_bytes();
        assert_eq!(v1[4], 1);
        assert_eq!(
            v1.len(),
            4 + 1 + 8 + 4 + 8 + 1 + 2 + 1 + 9 * 9 + 2 + 2 * 3 * 4 + 32 + 1
        );
        let h = header(3, &[1, 2, 9]);
        let v2 = h.to_bytes();
        assert_eq!(v2[4], 2);
        // the same fields, plus X and the kinds right after the 9 x N parameter bytes
        let at = 4 + 1 + 8 + 4 + 8 + 1 + 2 + 1 + 9 * 12;
        assert_eq!(v2[at..at + 4], [3, 1, 2, 9]);
        assert_eq!(Header::parse(&v2), Ok(h.clone()));
        assert_eq!(h.coefficients(), 3);
    }

    #[test]
    fn a_version_2_header_with_no_extras_reads_as_version_1() {
        let h = header(2, &[]);
        let mut raw = h.to_bytes();
        raw[4] = 2;
        let at = 4 + 1 + 8 + 4 + 8 + 1 + 2 + 1 + 9 * 8;
        raw.insert(at, 0);
        assert_eq!(Header::parse(&raw), Ok(h));
    }

    #[test]
    fn bad_extras_are_refused_with_a_reason() {
        let reason = |raw: &[u8]| Header::parse(raw).unwrap_err().to_string();
        let h = header(1, &[4, 5]);
        let raw = h.to_bytes();
        let x = 4 + 1 + 8 + 4 + 8 + 1 + 2 + 1 + 9 * 9;
        assert_eq!(raw[x..x + 3], [2, 4, 5]);
        let mut dup = raw.clone();
        dup[x + 2] = 4;
        assert_eq!(reason(&dup), "extra parameter kind 4 appears twice");
        let mut zero = raw.clone();
        zero[x + 1] = 0;
        assert_eq!(
            reason(&zero),
            "extra parameter 0 has kind 0; kinds are 1-255"
        );
        // four extras claimed where only three parameters follow the pose
        let mut many = raw.clone();
        many[x] = 4;
        many.splice(x + 3..x + 3, [6, 7]);
        assert_eq!(
            reason(&many),
            "4 extra parameters do not fit in 9 parameters per frame (at most 3 after the pose)"
        );
        let mut v3 = raw.clone();
        v3[4] = 3;
        assert_eq!(
            reason(&v3),
            "stream format version 3; this decoder reads versions 1 and 2"
        );
        let mut bad = h.clone();
        bad.extras = vec![1, 2, 3, 4];
        assert!(bad.validate().is_err());
        bad.extras = vec![255, 1];
        assert_eq!(bad.validate(), Ok(()));
        // every cut of a version-2 header is refused
        for cut in 0..raw.len() {
            assert!(Header::parse(&raw[..cut]).is_err(), "cut at {cut}");
        }
    }

    proptest! {
        #[test]
        fn any_valid_header_reads_back_as_itself(
            coefficients in 0usize..20,
            kinds in proptest::collection::btree_set(1u8..=255, 0..12),
            order in any::<u64>(),
        ) {
            let mut kinds: Vec<u8> = kinds.into_iter().collect();
            let len = kinds.len().max(1);
            kinds.rotate_left(order as usize % len);
            let h = header(coefficients, &kinds);
            prop_assert_eq!(h.validate(), Ok(()));
            let raw = h.to_bytes();
            prop_assert_eq!(raw[4], if kinds.is_empty() { 1 } else { 2 });
            prop_assert_eq!(raw.len(), 4 + 1 + 8 + 4 + 8 + 1 + 2 + 1 + 9 * h.quantisers.len()
                + if kinds.is_empty() { 0 } else { 1 + kinds.len() } + 2 + 8 * coefficients + 33);
            prop_assert_eq!(Header::parse(&raw), Ok(h));
        }
    }
}
