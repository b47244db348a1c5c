//! The encoder: quantises each frame's parameters, gathers frames into packets and codes them
//! (`docs/bitstream.md`). Its reconstruction is the decoder's output, bit for bit.

use super::chunk::{self, Kind};
use super::header::{Header, MAX_VALUE};
use super::model::{class_spread, CLASSES};
use super::packet::{self, CodedFrame, State, FACE};
use crate::error::Result;
use crate::invalid;

/// Quantises a frame's parameters with hysteresis: a parameter keeps its previous value while
/// it stays within `0.5 + hysteresis` steps of it (tracking noise then costs no bits), and is
/// rounded to the nearest step otherwise. An encoder's choice: decoders never see it.
#[derive(Debug, Clone)]
pub struct Quantise {
    steps: Vec<f64>,
    hysteresis: f64,
    held: Option<Vec<i32>>,
}

impl Quantise {
    /// A quantiser of parameters with `steps` (each > 0).
    pub fn new(steps: Vec<f64>, hysteresis: f64) -> Result<Quantise> {
        if !(0.0..=4.0).contains(&hysteresis) {
            return invalid!("hysteresis {hysteresis} is not within 0..4 steps");
        }
        if steps.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return invalid!("quantiser steps must be finite and positive");
        }
        Ok(Quantise {
            steps,
            hysteresis,
            held: None,
        })
    }

    /// The quantised values of one frame's parameters.
    pub fn apply(&mut self, values: &[f64]) -> Result<Vec<i32>> {
        if values.len() != self.steps.len() {
            return invalid!(
                "a frame has {} parameters, the stream {}",
                values.len(),
                self.steps.len()
            );
        }
        let mut q = Vec::with_capacity(values.len());
        for (i, (&v, &step)) in values.iter().zip(&self.steps).enumerate() {
            let u = v / step;
            if !u.is_finite() || u.abs() > MAX_VALUE as f64 {
                return invalid!(
                    "parameter {i} is {v}: not finite, or beyond the format's range at step {step}"
                );
            }
            q.push(match &self.held {
                Some(h) if (u - h[i] as f64).abs() <= 0.5 + self.hysteresis => h[i],
                _ => u.round() as i32,
            });
        }
        self.held = Some(q.clone());
        Ok(q)
    }
}

/// The spread class (`model::CLASSES`) per parameter that fits a clip: quantised as the
/// encoder will, the class whose mean absolute value (in steps) is nearest, in ratio, to that
/// of the parameter's frame-to-frame differences. `frames`: the values of the frames that show
/// a face, in order.
pub fn choose_classes(steps: &[f64], hysteresis: f64, frames: &[Vec<f64>]) -> Result<Vec<u8>> {
    let mut quantise = Quantise::new(steps.to_vec(), hysteresis)?;
    let mut sums = vec![0.0f64; steps.len()];
    let mut prev: Option<Vec<i32>> = None;
    for values in frames {
        let q = quantise.apply(values)?;
        if let Some(p) = &prev {
            for (s, (a, b)) in sums.iter_mut().zip(q.iter().zip(p)) {
                *s += (*a as f64 - *b as f64).abs();
            }
        }
        prev = Some(q);
    }
    let n = frames.len().saturating_sub(1).max(1) as f64;
    Ok(sums
        .iter()
        .map(|s| {
            let mean = (s / n).max(1e-3);
            (0..CLASSES)
                .min_by(|&a, &b| {
                    let da = (class_spread(a) / mean).ln().abs();
                    let db = (class_spread(b) / mean).ln().abs();
                    da.total_cmp(&db)
                })
                .unwrap_or(0) as u8
        })
        .collect())
}

/// Values of quantised parameters: `q * step` (the reconstruction both sides share).
pub fn dequantise(header: &Header, q: &[i32]) -> Vec<f64> {
    q.iter()
        .zip(&header.quantisers)
        .map(|(&v, h)| v as f64 * h.step as f64)
        .collect()
}

/// Encodes frames one at a time into packets of `header.packet_frames` frames.
#[derive(Debug, Clone)]
pub struct Encoder {
    header: Header,
    quantise: Quantise,
    state: State,
    pending: Vec<CodedFrame>,
    /// The last reconstruction with a face (what a frame without one shows).
    shown: Vec<i32>,
    packets: u64,
    /// The next packet is intra whatever its number (a receiver asked for one).
    forced: bool,
}

impl Encoder {
    /// An encoder for `header` (validated), quantising with `hysteresis` steps (see [`Quantise`]).
    pub fn new(header: Header, hysteresis: f64) -> Result<Encoder> {
        header.validate()?;
        let quantise = Quantise::new(
            header.quantisers.iter().map(|q| q.step as f64).collect(),
            hysteresis,
        )?;
        let state = State::new(&header);
        let shown = header.quantisers.iter().map(|q| q.reference).collect();
        Ok(Encoder {
            header,
            quantise,
            state,
            pending: Vec::new(),
            shown,
            packets: 0,
            forced: false,
        })
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The header chunk: the first bytes of a stream (and what a sender repeats to a receiver
    /// that joins).
    pub fn header_chunk(&self) -> Vec<u8> {
        chunk::write(Kind::Header, 0, 0, &self.header.to_bytes())
    }

    /// Adds a frame: `face` (false: the parameters are ignored and the last face is shown),
    /// `lost` (bits 0..=3: the features lost), `values` (one per parameter). Returns what the
    /// decoder will output for it, and the packet when this frame completed one.
    pub fn push(
        &mut self,
        face: bool,
        lost: u8,
        values: &[f64],
    ) -> Result<(Vec<f64>, Option<Vec<u8>>)> {
        let q = if face {
            self.quantise.apply(values)?
        } else {
            self.shown.clone()
        };
        if face {
            self.shown = q.clone();
        }
        self.pending.push(CodedFrame {
            flags: (face as u8 * FACE) | ((lost & 0x0f) << 1),
            q: q.clone(),
        });
        let packet = if self.pending.len() == self.header.packet_frames as usize {
            Some(self.flush()?)
        } else {
            None
        };
        Ok((dequantise(&self.header, &q), packet))
    }

    /// The last, shorter packet, if frames are pending.
    pub fn finish(&mut self) -> Result<Option<Vec<u8>>> {
        if self.pending.is_empty() {
            return Ok(None);
        }
        self.flush().map(Some)
    }

    /// Whether the next packet is an intra packet: every `keyframe_packets`-th, and the next
    /// one after [`Encoder::request_intra`].
    pub fn next_is_intra(&self) -> bool {
        self.forced
            || self
                .packets
                .is_multiple_of(self.header.keyframe_packets as u64)
    }

    /// Makes the next packet an intra packet (a live receiver that joined or lost a packet asks
    /// for one); the regular schedule goes on as before.
    pub fn request_intra(&mut self) {
        self.forced = true;
    }

    fn flush(&mut self) -> Result<Vec<u8>> {
        let intra = self.next_is_intra();
        if intra {
            self.state = State::new(&self.header);
            self.forced = false;
        }
        let frames = std::mem::take(&mut self.pending);
        let payload = packet::encode(&mut self.state, &frames)?;
        if payload.len() > Kind::Inter.max_payload() {
            return invalid!(
                "a packet of {} bytes is more than the format allows: use fewer frames per packet",
                payload.len()
            );
        }
        let kind = if intra { Kind::Intra } else { Kind::Inter };
        let bytes = chunk::write(kind, frames.len(), self.packets as u16, &payload);
        self.packets += 1;
        Ok(bytes)
    }
}
