//! The decoder: reads chunks from bytes as they arrive, survives damage, loss and reordering,
//! and shows the last good frame until it can decode again (`docs/bitstream.md`, "Decoding
//! with loss").

use super::chunk::{self, Chunk, Kind, Read};
use super::encoder::dequantise;
use super::header::Header;
use super::packet::{self, State, FACE};

/// A jump of more packets than this is taken as a new start, not concealed frame by frame.
pub const MAX_GAP_PACKETS: u64 = 256;

/// What the decoder outputs, in stream order: frames in frame order, and each appearance
/// update where its chunk was read (before the frames of the packets that follow it).
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    /// A decoded frame: its index from the stream's start, flags and parameter values.
    Frame {
        index: u64,
        face: bool,
        lost: u8,
        values: Vec<f64>,
    },
    /// `count` frames from `first` that could not be decoded (lost, damaged, or after a loss
    /// before the next intra packet): show the last good frame for them.
    Concealed { first: u64, count: u64 },
    /// An appearance chunk's payload (`docs/bitstream.md`, "Appearance"), not parsed: `u32`
    /// first frame, `u16` x, `u16` y, then a WebP image. At least
    /// [`chunk::APPEARANCE_PREFIX`] bytes.
    Appearance(Vec<u8>),
}

/// What the decoder met.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// Packets read and decoded.
    pub packets: u64,
    /// Packets missing from the sequence numbers.
    pub lost_packets: u64,
    /// Packets that came after a later one (reordered or repeated), dropped.
    pub late_packets: u64,
    /// Good chunks whose payload did not decode (and packets and appearance updates before any
    /// header).
    pub undecodable: u64,
    /// Appearance updates output.
    pub appearance: u64,
    /// Runs of bytes in which no chunk was found (damage), and their bytes.
    pub damaged_runs: u64,
    pub damaged_bytes: u64,
    /// Frames decoded, and frames concealed.
    pub frames: u64,
    pub concealed: u64,
}

/// Decodes a stream fed in pieces of any size.
#[derive(Debug, Clone)]
pub struct Decoder {
    /// True: the stream starts at packet 0 (a file), so missing leading packets are concealed;
    /// false: a receiver joining a live stream starts at the first packet it gets.
    from_start: bool,
    buf: Vec<u8>,
    in_damage: bool,
    header: Option<Header>,
    header_error: Option<String>,
    actor: Option<Vec<u8>>,
    state: Option<State>,
    next: Option<u64>,
    shown: Vec<i32>,
    /// A segment read stopped before a header that changes the stream ([`Decoder::segment`]).
    pending: bool,
    pub stats: Stats,
}

impl Decoder {
    pub fn new(from_start: bool) -> Decoder {
        Decoder {
            from_start,
            buf: Vec::new(),
            in_damage: false,
            header: None,
            header_error: None,
            actor: None,
            state: None,
            next: None,
            shown: Vec::new(),
            pending: false,
            stats: Stats::default(),
        }
    }

    /// The stream header, once one was read.
    pub fn header(&self) -> Option<&Header> {
        self.header.as_ref()
    }

    /// Why a well-framed header was refused (another format version, bad fields), if one was.
    pub fn header_error(&self) -> Option<&str> {
        self.header_error.as_deref()
    }

    /// The actor chunk's payload, once one was read.
    pub fn actor(&self) -> Option<&[u8]> {
        self.actor.as_deref()
    }

    /// Reads `bytes` (appended to what is buffered) and returns the frames they completed and
    /// the appearance updates they held, in stream order.
    pub fn push(&mut self, bytes: &[u8]) -> Vec<Output> {
        self.buf.extend_from_slice(bytes);
        self.drain(false, false)
    }

    /// Reads what is buffered as the stream's end (a chunk cut short there is damage).
    pub fn finish(&mut self) -> Vec<Output> {
        self.drain(true, false)
    }

    /// Like [`Decoder::push`] (`end`: like [`Decoder::finish`]), but stops before a header that
    /// starts a new stream when something was output under the one in force, so that every
    /// output of one call belongs to the header [`Decoder::header`] gives after it. While
    /// [`Decoder::pending`], call again (with no bytes) for the rest.
    pub fn segment(&mut self, bytes: &[u8], end: bool) -> Vec<Output> {
        self.buf.extend_from_slice(bytes);
        self.drain(end, true)
    }

    /// Whether the last [`Decoder::segment`] stopped before a new header.
    pub fn pending(&self) -> bool {
        self.pending
    }

    fn drain(&mut self, end: bool, segment: bool) -> Vec<Output> {
        let mut out = Vec::new();
        let mut at = 0;
        self.pending = false;
        while at < self.buf.len() {
            match chunk::read(&self.buf[at..]) {
                Read::Chunk(c, _) if segment && !out.is_empty() && self.starts_stream(&c) => {
                    self.pending = true;
                    break;
                }
                Read::Chunk(c, used) => {
                    self.in_damage = false;
                    at += used;
                    self.chunk(c, &mut out);
                }
                Read::Short if !end => break,
                Read::Short | Read::Bad => {
                    if !self.in_damage {
                        self.stats.damaged_runs += 1;
                        self.in_damage = true;
                    }
                    self.stats.damaged_bytes += 1;
                    at += 1;
                }
            }
        }
        self.buf.drain(..at);
        out
    }

    /// Whether `c` is a valid header other than the one in force.
    fn starts_stream(&self, c: &Chunk) -> bool {
        c.kind == Kind::Header
            && Header::parse(&c.payload).is_ok_and(|h| self.header.as_ref() != Some(&h))
    }

    fn chunk(&mut self, c: Chunk, out: &mut Vec<Output>) {
        match c.kind {
            Kind::Header => match Header::parse(&c.payload) {
                Ok(h) if self.header.as_ref() == Some(&h) => {}
                Ok(h) => {
                    self.shown = h.quantisers.iter().map(|q| q.reference).collect();
                    self.header = Some(h);
                    self.state = None;
                    self.next = None;
                }
                Err(e) => self.header_error = Some(e.to_string()),
            },
            Kind::Actor => self.actor = Some(c.payload),
            Kind::Intra | Kind::Inter => self.packet(c, out),
            Kind::Appearance => self.appearance(c.payload, out),
        }
    }

    /// Passes an appearance update on as it is; it touches no coding state, sequence number or
    /// concealment. One before any header, or too short to hold its frame and place, is
    /// undecodable.
    fn appearance(&mut self, payload: Vec<u8>, out: &mut Vec<Output>) {
        if self.header.is_none() || payload.len() < chunk::APPEARANCE_PREFIX {
            self.stats.undecodable += 1;
            return;
        }
        self.stats.appearance += 1;
        out.push(Output::Appearance(payload));
    }

    fn packet(&mut self, c: Chunk, out: &mut Vec<Output>) {
        let Some(header) = &self.header else {
            self.stats.undecodable += 1;
            return;
        };
        let per = header.packet_frames as u64;
        let expected = self
            .next
            .unwrap_or(if self.from_start { 0 } else { c.seq as u64 });
        let delta = c.seq.wrapping_sub(expected as u16) as u64;
        if delta >= 1 << 15 {
            self.stats.late_packets += 1;
            return;
        }
        let seq = expected + delta;
        if delta > MAX_GAP_PACKETS {
            self.stats.lost_packets += delta;
            self.state = None;
        } else if delta > 0 {
            self.stats.lost_packets += delta;
            self.state = None;
            conceal(&mut self.stats, expected * per, delta * per, out);
        }
        self.next = Some(seq + 1);
        let first = seq * per;
        if c.frames as u64 > per {
            self.stats.undecodable += 1;
            self.state = None;
            return conceal(&mut self.stats, first, c.frames as u64, out);
        }
        if c.kind == Kind::Intra {
            self.state = Some(State::new(header));
        }
        let Some(state) = &mut self.state else {
            return conceal(&mut self.stats, first, c.frames as u64, out);
        };
        match packet::decode(state, &c.payload, c.frames) {
            Ok(frames) => {
                self.stats.packets += 1;
                self.stats.frames += frames.len() as u64;
                for (j, f) in frames.into_iter().enumerate() {
                    let face = f.flags & FACE != 0;
                    if face {
                        self.shown = f.q;
                    }
                    let values = dequantise(header, &self.shown);
                    out.push(Output::Frame {
                        index: first + j as u64,
                        face,
                        lost: (f.flags >> 1) & 0x0f,
                        values,
                    });
                }
            }
            Err(_) => {
                self.stats.undecodable += 1;
                self.state = None;
                conceal(&mut self.stats, first, c.frames as u64, out);
            }
        }
    }
}

fn conceal(stats: &mut Stats, first: u64, count: u64, out: &mut Vec<Output>) {
    if count > 0 {
        stats.concealed += count;
        out.push(Output::Concealed { first, count });
    }
}
