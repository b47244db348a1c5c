//! A packet's payload (`docs/bitstream.md`, "Packets"): its frames' flags and quantised
//! parameters, predicted and range coded. The coding state (contexts, predictor) runs from
//! one intra packet through the inter packets after it; encoder and decoder keep identical
//! copies.

use constriction::backends::Cursor;
use constriction::stream::queue::{SmallRangeDecoder, SmallRangeEncoder};
use constriction::stream::{Decode, Encode};

use super::header::{Header, MAX_VALUE};
use super::model::{starting_frequencies, Context, Table, CLASSES, ESCAPE, RADIUS};
use crate::error::Result;
use crate::invalid;

/// Flag bit of a frame that shows a face; bits 1..=4 mark the features lost (mouth outer,
/// mouth inner, left brow, right brow).
pub const FACE: u8 = 1;

/// One frame as the coder sees it: flags and quantised parameters (read only with [`FACE`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CodedFrame {
    pub flags: u8,
    pub q: Vec<i32>,
}

/// The coding state shared by the packets from one intra packet to the next.
#[derive(Debug, Clone)]
pub struct State {
    values: Vec<Context>,
    flags: Context,
    /// The last frame with a face since the intra packet: what the next one is predicted from.
    pred: Option<Vec<i32>>,
    reference: Vec<i32>,
    intra: Table,
    uniform: Vec<Table>,
}

impl State {
    /// The state at the start of an intra packet.
    pub fn new(header: &Header) -> State {
        State {
            values: header
                .quantisers
                .iter()
                .map(|q| Context::values(q.class as usize))
                .collect(),
            flags: Context::flags(),
            pred: None,
            reference: header.quantisers.iter().map(|q| q.reference).collect(),
            intra: Table::from_frequencies(&starting_frequencies(CLASSES - 1)),
            uniform: (0..=12).map(Table::uniform).collect(),
        }
    }
}

fn coder_error<E: std::fmt::Debug>(e: E) -> crate::error::CoreError {
    crate::error::CoreError::InvalidInput(format!("range coder: {e:?}"))
}

fn put(enc: &mut SmallRangeEncoder, uniform: &[Table], v: i64, table: &Table) -> Result<usize> {
    let symbol = if v.abs() <= RADIUS as i64 {
        (v + RADIUS as i64) as usize
    } else {
        ESCAPE
    };
    enc.encode_symbol(symbol, table).map_err(coder_error)?;
    if symbol == ESCAPE {
        let m = (v.unsigned_abs() - RADIUS as u64 - 1) as u32;
        enc.encode_symbol((v < 0) as usize, &uniform[1])
            .map_err(coder_error)?;
        let n = 32 - m.leading_zeros();
        enc.encode_symbol(n as usize, &uniform[5])
            .map_err(coder_error)?;
        let mut left = n.saturating_sub(1);
        while left > 0 {
            let b = left.min(12);
            let chunk = (m >> (left - b)) & ((1 << b) - 1);
            enc.encode_symbol(chunk as usize, &uniform[b as usize])
                .map_err(coder_error)?;
            left -= b;
        }
    }
    Ok(symbol)
}

type RangeDecoder = SmallRangeDecoder<Cursor<u16, Vec<u16>>>;

fn get(dec: &mut RangeDecoder, uniform: &[Table], table: &Table) -> Result<(i64, usize)> {
    let symbol: usize = dec.decode_symbol(table).map_err(coder_error)?;
    if symbol != ESCAPE {
        return Ok((symbol as i64 - RADIUS as i64, symbol));
    }
    let negative = dec.decode_symbol(&uniform[1]).map_err(coder_error)? == 1;
    let n = dec.decode_symbol(&uniform[5]).map_err(coder_error)? as u32;
    let mut m: u64 = if n == 0 { 0 } else { 1 };
    let mut left = n.saturating_sub(1);
    while left > 0 {
        let b = left.min(12);
        m = (m << b)
            | dec
                .decode_symbol(&uniform[b as usize])
                .map_err(coder_error)? as u64;
        left -= b;
    }
    let magnitude = m as i64 + RADIUS as i64 + 1;
    Ok((if negative { -magnitude } else { magnitude }, symbol))
}

/// Codes `frames` (each with one value per parameter) as one packet's payload: per frame its
/// flags, then, with a face, each parameter's difference from the predictor (the last frame
/// with a face since the intra packet) in its adaptive context, or, with no predictor yet, its
/// difference from the header's reference in the intra table.
pub fn encode(state: &mut State, frames: &[CodedFrame]) -> Result<Vec<u8>> {
    let mut enc = SmallRangeEncoder::new();
    for f in frames {
        if f.q.len() != state.reference.len() {
            return invalid!(
                "a frame has {} parameters, the stream {}",
                f.q.len(),
                state.reference.len()
            );
        }
        let flags = f.flags as usize & 0x1f;
        enc.encode_symbol(flags, state.flags.table())
            .map_err(coder_error)?;
        state.flags.update(flags);
        if f.flags & FACE == 0 {
            continue;
        }
        for (i, &q) in f.q.iter().enumerate() {
            if (q as i64).abs() > MAX_VALUE {
                return invalid!("parameter {i} quantised to {q}, beyond the format's range");
            }
            match &state.pred {
                Some(p) => {
                    let s = put(
                        &mut enc,
                        &state.uniform,
                        q as i64 - p[i] as i64,
                        state.values[i].table(),
                    )?;
                    state.values[i].update(s);
                }
                None => {
                    put(
                        &mut enc,
                        &state.uniform,
                        q as i64 - state.reference[i] as i64,
                        &state.intra,
                    )?;
                }
            }
        }
        state.pred = Some(f.q.clone());
    }
    let words = enc.into_compressed().map_err(coder_error)?;
    Ok(words.iter().flat_map(|w| w.to_le_bytes()).collect())
}

/// Decodes a packet of `frames` frames (a frame without a face has no values: it shows the last
/// face). Errors on data no encoder writes.
pub fn decode(state: &mut State, payload: &[u8], frames: usize) -> Result<Vec<CodedFrame>> {
    if !payload.len().is_multiple_of(2) {
        return invalid!("a packet's payload has an odd length");
    }
    let words: Vec<u16> = payload
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect();
    let mut dec = SmallRangeDecoder::from_compressed(words).map_err(coder_error)?;
    let mut out = Vec::with_capacity(frames);
    for _ in 0..frames {
        let flags: usize = dec
            .decode_symbol(state.flags.table())
            .map_err(coder_error)?;
        state.flags.update(flags);
        if flags as u8 & FACE == 0 {
            out.push(CodedFrame {
                flags: flags as u8,
                q: Vec::new(),
            });
            continue;
        }
        let mut q = Vec::with_capacity(state.reference.len());
        for i in 0..state.reference.len() {
            let v = match &state.pred {
                Some(p) => {
                    let (r, s) = get(&mut dec, &state.uniform, state.values[i].table())?;
                    state.values[i].update(s);
                    p[i] as i64 + r
                }
                None => state.reference[i] as i64 + get(&mut dec, &state.uniform, &state.intra)?.0,
            };
            if v.abs() > MAX_VALUE {
                return invalid!("parameter {i} decodes to {v}, beyond the format's range");
            }
            q.push(v as i32);
        }
        state.pred = Some(q.clone());
        out.push(CodedFrame {
            flags: flags as u8,
            q,
        });
    }
    Ok(out)
}
