/** The stream decoder (docs/bitstream.md, "Decoding with loss"): reads chunks from bytes as they
 * arrive, survives damage, loss and reordering, and conceals what it cannot decode with the last
 * good frame. Its output is the Rust decoder's as `facemime.codec.decoder.MotionDecoder` presents
 * it: frame by frame, each push's frames in index order, concealed frames filled in. */

import { APPEARANCE_PREFIX, ByteQueue, KIND_ACTOR, KIND_APPEARANCE, KIND_HEADER, KIND_INTRA, readChunk,
  type Chunk } from './chunks';
import { dequantise, InvalidHeader, parseHeader, POSE_PARAMETERS, sameHeader, type Header } from './header';
import { CodingState, decodePacket, FACE, type CodedFrame } from './packet';
import { InvalidPayload } from './range';

/** A jump of more packets than this is a new start: nothing is concealed. */
export const MAX_GAP_PACKETS = 256;

/** One frame out of the decoder. */
export interface Frame {
  /** The frame's index from the stream's start (packet s holds frames from s * P). */
  index: number;
  /** Whether the frame shows a face (false: show the last face, dimmed). */
  face: boolean;
  /** Features lost by the tracker, bits 0-3: mouth outer, mouth inner, left brow, right brow. */
  lost: number;
  /** The quantised parameters shown (the last face's for a frame without one). */
  q: Int32Array;
  /** Parameter values, `q_i * step_i` in float64: yaw, pitch, roll (degrees), ln scale, tx, ty
   * (px), the basis coefficients (model units), then the extras (version 2). */
  values: Float64Array;
  /** Lost or damaged: repeats the last good frame (before any, the reference pose, face false,
   * every feature lost). */
  concealed: boolean;
}

/** What the decoder outputs, in stream order. `actor`: an actor chunk's payload (an actor
 * file); `appearance`: an appearance chunk's payload, unparsed (`u32` first frame, `u16` x,
 * `u16` y, a WebP image), placed between the frames output before it was read and after. */
export type Event =
  | { kind: 'header'; header: Header }
  | { kind: 'actor'; data: Uint8Array }
  | { kind: 'appearance'; payload: Uint8Array }
  | { kind: 'frame'; frame: Frame };

/** What the decoder met (the Rust decoder's counts, same names). */
export interface Stats {
  /** Packets read and decoded. */
  packets: number;
  /** Packets missing from the sequence numbers. */
  lost_packets: number;
  /** Packets that came after a later one (reordered or repeated), dropped. */
  late_packets: number;
  /** Good chunks whose payload did not decode (and packets and appearance chunks before any
   * header). */
  undecodable: number;
  /** Appearance updates output. */
  appearance: number;
  /** Runs of bytes in which no chunk was found (damage), and their bytes. */
  damaged_runs: number;
  damaged_bytes: number;
  /** Frames decoded, and frames concealed. */
  frames: number;
  concealed: number;
}

/** One call's output before it is put in order: decoded frames, concealed runs, and the other
 * events with the count of frames output before them. */
type Raw =
  | { t: 'frame'; frame: Frame }
  | { t: 'concealed'; first: number; count: number }
  | { t: 'event'; event: Event };

/** Decodes a stream fed in pieces of any size. */
export class StreamDecoder {
  /** What the decoder met so far. */
  readonly stats: Stats = {
    packets: 0, lost_packets: 0, late_packets: 0, undecodable: 0, appearance: 0, damaged_runs: 0,
    damaged_bytes: 0, frames: 0, concealed: 0,
  };
  private readonly queue = new ByteQueue();
  private inDamage = false;
  private current: Header | null = null;
  private refused: string | null = null;
  private actorData: Uint8Array | null = null;
  private state: CodingState | null = null;
  /** The next expected packet number (unwrapped), once a packet was read. */
  private next: number | null = null;
  /** The quantised parameters of the last face (the header's references before any). */
  private shown: Int32Array = new Int32Array(0);
  /** The last good decoded frame, which concealed frames repeat. */
  private last: Frame | null = null;
  private raw: Raw[] = [];
  /** The header the output's current part was read under. */
  private partHeader: Header | null = null;

  /** `fromStart`: the bytes start at the stream's start (a file: missing leading packets are
   * concealed); false for a receiver joining a live stream at the first packet it gets. */
  constructor(private readonly fromStart = true) {}

  /** The header in force, once one was read. */
  get header(): Header | null {
    return this.current;
  }

  /** Why the last well-framed header was refused, if one was. */
  get headerError(): string | null {
    return this.refused;
  }

  /** The last actor chunk's payload, once one was read. */
  get actor(): Uint8Array | null {
    return this.actorData;
  }

  /** Reads `bytes` (after what is buffered); returns the events they completed. */
  push(bytes: Uint8Array): Event[] {
    this.queue.append(bytes);
    this.drain(false);
    return this.output();
  }

  /** Reads what is buffered as the stream's end (a chunk cut short there is damage). */
  finish(): Event[] {
    this.drain(true);
    return this.output();
  }

  private drain(end: boolean): void {
    const { buf, start, end: stop } = this.queue.view();
    let at = start;
    while (at < stop) {
      const r = readChunk(buf, at, stop);
      if (r === 'short' && !end) break;
      if (r === 'short' || r === 'bad') {
        if (!this.inDamage) {
          this.stats.damaged_runs++;
          this.inDamage = true;
        }
        this.stats.damaged_bytes++;
        at++;
        continue;
      }
      this.inDamage = false;
      at += r.used;
      this.chunk(r.chunk);
    }
    this.queue.consume(at - start);
  }

  private chunk(c: Chunk): void {
    switch (c.kind) {
      case KIND_HEADER: {
        let h: Header;
        try {
          h = parseHeader(c.payload);
        } catch (e) {
          if (!(e instanceof InvalidHeader)) throw e;
          this.refused = e.message;
          return;
        }
        if (this.current && sameHeader(this.current, h)) return;
        this.shown = Int32Array.from(h.references);
        this.current = h;
        this.state = null;
        this.next = null;
        this.raw.push({ t: 'event', event: { kind: 'header', header: h } });
        return;
      }
      case KIND_ACTOR:
        this.actorData = c.payload;
        this.raw.push({ t: 'event', event: { kind: 'actor', data: c.payload } });
        return;
      case KIND_APPEARANCE:
        if (!this.current || c.payload.length < APPEARANCE_PREFIX) {
          this.stats.undecodable++;
          return;
        }
        this.stats.appearance++;
        this.raw.push({ t: 'event', event: { kind: 'appearance', payload: c.payload } });
        return;
      default:
        this.packet(c);
    }
  }

  private packet(c: Chunk): void {
    const header = this.current;
    if (!header) {
      this.stats.undecodable++;
      return;
    }
    const per = header.packetFrames;
    const expected = this.next ?? (this.fromStart ? 0 : c.seq);
    const delta = (c.seq - (expected % 65536) + 65536) % 65536;
    if (delta >= 1 << 15) {
      this.stats.late_packets++;
      return;
    }
    const seq = expected + delta;
    if (delta > 0) {
      this.stats.lost_packets += delta;
      this.state = null;
      if (delta <= MAX_GAP_PACKETS) this.conceal(expected * per, delta * per);
    }
    this.next = seq + 1;
    const first = seq * per;
    if (c.frames > per) {
      this.stats.undecodable++;
      this.state = null;
      this.conceal(first, c.frames);
      return;
    }
    if (c.kind === KIND_INTRA) this.state = new CodingState(header);
    if (!this.state) {
      this.conceal(first, c.frames);
      return;
    }
    let frames: CodedFrame[];
    try {
      frames = decodePacket(this.state, c.payload, c.frames);
    } catch (e) {
      if (!(e instanceof InvalidPayload)) throw e;
      this.stats.undecodable++;
      this.state = null;
      this.conceal(first, c.frames);
      return;
    }
    this.stats.packets++;
    this.stats.frames += frames.length;
    frames.forEach((f, j) => {
      const face = (f.flags & FACE) !== 0;
      if (f.q) this.shown = f.q;
      const frame: Frame = {
        index: first + j,
        face,
        lost: (f.flags >> 1) & 0x0f,
        q: this.shown.slice(),
        values: dequantise(header, this.shown),
        concealed: false,
      };
      this.raw.push({ t: 'frame', frame });
    });
  }

  private conceal(first: number, count: number): void {
    if (count > 0) {
      this.stats.concealed += count;
      this.raw.push({ t: 'concealed', first, count });
    }
  }

  /** This call's events, in parts split where a header starts a new stream (the header event
   * between them), as MotionDecoder reads them (the Rust decoder's segments): in each part its
   * frames in index order (a stable sort, decoded frames before concealed runs on a tie),
   * concealed runs filled in, each other event after as many frames as the decoder had output
   * before reading it. */
  private output(): Event[] {
    const raw = this.raw;
    this.raw = [];
    const out: Event[] = [];
    let part: Raw[] = [];
    for (const r of raw) {
      if (r.t === 'event' && r.event.kind === 'header') {
        out.push(...this.part(part), r.event);
        this.partHeader = r.event.header;
        part = [];
      } else {
        part.push(r);
      }
    }
    out.push(...this.part(part));
    return out;
  }

  /** One part of a call's output, read under the header `partHeader`. */
  private part(raw: Raw[]): Event[] {
    const runs: { first: number; frame: Frame | null; count: number }[] = [];
    const others: { before: number; event: Event }[] = [];
    let seen = 0;
    for (const r of raw) {
      if (r.t === 'frame') {
        runs.push({ first: r.frame.index, frame: r.frame, count: 1 });
        seen++;
      } else if (r.t === 'concealed') {
        seen += r.count;
      } else {
        others.push({ before: seen, event: r.event });
      }
    }
    for (const r of raw) if (r.t === 'concealed') runs.push({ first: r.first, frame: null, count: r.count });
    runs.sort((a, b) => a.first - b.first);
    const out: Event[] = [];
    let k = 0;
    let emitted = 0;
    const flush = () => {
      while (k < others.length && others[k].before <= emitted) out.push(others[k++].event);
    };
    flush();
    for (const run of runs) {
      if (run.frame) {
        this.last = run.frame;
        out.push({ kind: 'frame', frame: run.frame });
        emitted++;
        flush();
        continue;
      }
      for (let j = 0; j < run.count; j++) {
        out.push({ kind: 'frame', frame: this.concealedFrame(run.first + j) });
        emitted++;
        flush();
      }
    }
    while (k < others.length) out.push(others[k++].event);
    return out;
  }

  private concealedFrame(index: number): Frame {
    const last = this.last;
    if (last) {
      return { index, face: last.face, lost: last.lost, q: last.q.slice(), values: last.values.slice(), concealed: true };
    }
    // before any decoded frame: the reference pose, zero offsets, the neutral look
    const header = this.partHeader as Header; // concealment needs a header
    const q = new Int32Array(header.references.length);
    for (let i = 0; i < POSE_PARAMETERS; i++) q[i] = header.references[i];
    return { index, face: false, lost: 15, q, values: dequantise(header, q), concealed: true };
  }
}
