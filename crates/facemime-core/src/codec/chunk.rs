//! Chunk framing (`docs/bitstream.md`, "Chunks"): every unit of a stream is
//! `tag, sequence number, length, payload, CRC-32`, so that damage is detected and the reader
//! finds the next good chunk again.

use crate::error::Result;
use crate::invalid;

/// What a chunk holds (the tag's top three bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The stream header.
    Header = 1,
    /// The actor (model and texture), once.
    Actor = 2,
    /// Frames coded without reference to earlier packets.
    Intra = 3,
    /// Frames predicted from the previous decoded frame.
    Inter = 4,
    /// An update of a rectangle of the actor's texture (format version 2; "Appearance").
    Appearance = 5,
}

impl Kind {
    fn from_bits(bits: u8) -> Option<Kind> {
        match bits {
            1 => Some(Kind::Header),
            2 => Some(Kind::Actor),
            3 => Some(Kind::Intra),
            4 => Some(Kind::Inter),
            5 => Some(Kind::Appearance),
            _ => None,
        }
    }

    /// The largest payload a chunk of this kind may declare, bytes.
    pub fn max_payload(self) -> usize {
        match self {
            Kind::Header | Kind::Appearance => 1 << 20,
            Kind::Actor => 1 << 26,
            Kind::Intra | Kind::Inter => 1 << 16,
        }
    }
}

/// Most frames one packet holds.
pub const MAX_PACKET_FRAMES: usize = 32;

/// Bytes before an appearance payload's image: `u32` first frame, `u16` x, `u16` y. A shorter
/// payload is undecodable.
pub const APPEARANCE_PREFIX: usize = 8;

/// One chunk read from a stream.
#[derive(Debug, Clone, PartialEq)]
pub struct Chunk {
    pub kind: Kind,
    /// Frames in a packet (1..=32); 0 for the other kinds.
    pub frames: usize,
    /// The packet's sequence number (mod 2^16); 0 as written for the other kinds, which a
    /// reader ignores.
    pub seq: u16,
    pub payload: Vec<u8>,
}

/// The bytes of a chunk.
pub fn write(kind: Kind, frames: usize, seq: u16, payload: &[u8]) -> Vec<u8> {
    let tag = ((kind as u8) << 5) | (frames.saturating_sub(1) as u8 & 0x1f);
    let mut out = Vec::with_capacity(payload.len() + 12);
    out.push(tag);
    out.extend_from_slice(&seq.to_le_bytes());
    let mut n = payload.len();
    loop {
        let byte = (n & 0x7f) as u8;
        n >>= 7;
        if n == 0 {
            out.push(byte);
            break;
        }
        out.push(byte | 0x80);
    }
    out.extend_from_slice(payload);
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

/// The appearance chunk carrying `payload` (`u32` first frame, `u16` x, `u16` y, then a WebP
/// image; the payload is not parsed here): an error when it is shorter than
/// [`APPEARANCE_PREFIX`] or longer than the kind's limit (1 MiB).
pub fn appearance(payload: &[u8]) -> Result<Vec<u8>> {
    if payload.len() < APPEARANCE_PREFIX {
        return invalid!(
            "an appearance payload must hold at least {APPEARANCE_PREFIX} bytes (frame, x, y), got {}",
            payload.len()
        );
    }
    if payload.len() > Kind::Appearance.max_payload() {
        return invalid!(
            "an appearance payload must hold at most {} bytes, got {}",
            Kind::Appearance.max_payload(),
            payload.len()
        );
    }
    Ok(write(Kind::Appearance, 0, 0, payload))
}

/// What reading a chunk at the start of a buffer found.
#[derive(Debug, PartialEq)]
pub enum Read {
    /// A good chunk, and the bytes it took.
    Chunk(Chunk, usize),
    /// The buffer ends before the chunk does.
    Short,
    /// No chunk starts here (a bad tag, a length over its kind's limit, a wrong checksum).
    Bad,
}

/// Reads the chunk that starts at `buf[0]`.
pub fn read(buf: &[u8]) -> Read {
    let Some(&tag) = buf.first() else {
        return Read::Short;
    };
    let Some(kind) = Kind::from_bits(tag >> 5) else {
        return Read::Bad;
    };
    let packet = matches!(kind, Kind::Intra | Kind::Inter);
    if !packet && tag & 0x1f != 0 {
        return Read::Bad;
    }
    if buf.len() < 3 {
        return Read::Short;
    }
    let seq = u16::from_le_bytes([buf[1], buf[2]]);
    let (mut len, mut at) = (0usize, 3usize);
    for shift in (0..28).step_by(7) {
        let Some(&b) = buf.get(at) else {
            return Read::Short;
        };
        at += 1;
        len |= ((b & 0x7f) as usize) << shift;
        if b & 0x80 == 0 {
            break;
        }
        if shift == 21 {
            return Read::Bad; // a length of more than four bytes
        }
    }
    if len > kind.max_payload() {
        return Read::Bad;
    }
    let end = at + len;
    if buf.len() < end + 4 {
        return Read::Short;
    }
    let crc = u32::from_le_bytes([buf[end], buf[end + 1], buf[end + 2], buf[end + 3]]);
    if crc32fast::hash(&buf[..end]) != crc {
        return Read::Bad;
    }
    let frames = if packet { (tag & 0x1f) as usize + 1 } else { 0 };
    Read::Chunk(
        Chunk {
            kind,
            frames,
            seq,
            payload: buf[at..end].to_vec(),
        },
        end + 4,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chunk_reads_back_and_any_flipped_bit_is_caught() {
        let payload: Vec<u8> = (0..300u32).map(|i| (i * 7) as u8).collect();
        let bytes = write(Kind::Inter, 5, 513, &payload);
        let Read::Chunk(c, used) = read(&bytes) else {
            panic!("not read")
        };
        assert_eq!(
            (c.kind, c.frames, c.seq, used),
            (Kind::Inter, 5, 513, bytes.len())
        );
        assert_eq!(c.payload, payload);
        for bit in 0..bytes.len() * 8 {
            let mut b = bytes.clone();
            b[bit / 8] ^= 1 << (bit % 8);
            assert!(!matches!(read(&b), Read::Chunk(..)), "bit {bit}");
        }
        for cut in 0..bytes.len() {
            assert_ne!(read(&bytes[..cut]), Read::Chunk(c.clone(), used));
        }
    }

    #[test]
    fn an_appearance_chunk_reads_back_with_no_frames_and_its_limits_hold() {
        let payload: Vec<u8> = (0..40u8).collect();
        let bytes = appearance(&payload).unwrap();
        assert_eq!(bytes[0], 5 << 5);
        let Read::Chunk(c, used) = read(&bytes) else {
            panic!("not read")
        };
        assert_eq!(
            (c.kind, c.frames, c.seq, used),
            (Kind::Appearance, 0, 0, bytes.len())
        );
        assert_eq!(c.payload, payload);
        // frame bits set: not a chunk, even with a good CRC
        let mut tagged = write(Kind::Appearance, 2, 0, &payload);
        assert_eq!(tagged[0], (5 << 5) | 1);
        assert_eq!(read(&tagged), Read::Bad);
        tagged[0] = 5 << 5; // the CRC no longer matches
        assert_eq!(read(&tagged), Read::Bad);
        // a declared length over 2^20 is not a chunk, whatever follows; 2^20 is (still to come)
        let declaring = |n: usize| {
            let leb = [
                (n & 0x7f) as u8 | 0x80,
                (n >> 7 & 0x7f) as u8 | 0x80,
                (n >> 14) as u8,
            ];
            read(&[[5 << 5, 0, 0].as_slice(), &leb].concat())
        };
        assert_eq!(declaring((1 << 20) + 1), Read::Bad);
        assert_eq!(declaring(1 << 20), Read::Short);
        // the writer refuses what no reader would take
        assert!(appearance(&payload[..7]).is_err());
        assert!(appearance(&vec![0; (1 << 20) + 1]).is_err());
        assert!(appearance(&vec![0; 1 << 20]).is_ok());
    }
}
