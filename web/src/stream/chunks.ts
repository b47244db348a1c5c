/** Chunk framing (docs/bitstream.md, "Chunks"): `tag, seq, length (LEB128), payload, CRC-32`.
 * A reader that finds no good chunk at a byte skips it and tries the next (resync). */

import { crc32 } from './crc32';

/** Chunk kinds (the tag's top three bits). */
export const KIND_HEADER = 1;
export const KIND_ACTOR = 2;
export const KIND_INTRA = 3;
export const KIND_INTER = 4;
export const KIND_APPEARANCE = 5;

/** Most frames one packet holds. */
export const MAX_PACKET_FRAMES = 32;
/** Bytes before an appearance payload's image: `u32` first frame, `u16` x, `u16` y. */
export const APPEARANCE_PREFIX = 8;

/** The largest payload each kind may declare, bytes (index: kind). */
const MAX_PAYLOAD: readonly number[] = [0, 1 << 20, 1 << 26, 1 << 16, 1 << 16, 1 << 20];

/** One good chunk. */
export interface Chunk {
  kind: number;
  /** Frames in a packet (1-32); 0 for the other kinds. */
  frames: number;
  /** The packet's sequence number modulo 2^16 (0 as written for the other kinds). */
  seq: number;
  payload: Uint8Array;
}

/** What reading at a position found: a chunk and the bytes it took, too few bytes to tell
 * (`short`), or no chunk (`bad`). */
export type ReadResult = { chunk: Chunk; used: number } | 'short' | 'bad';

/** The largest payload of `kind`, bytes; 0 for an invalid kind. */
export function maxPayload(kind: number): number {
  return MAX_PAYLOAD[kind] ?? 0;
}

/** Reads the LEB128 length at `buf[at, end)`: the value and the bytes it took, `short` when the
 * bytes end first, `bad` when it would take more than four bytes. */
export function readLength(buf: Uint8Array, at: number, end = buf.length): { value: number; used: number } | 'short' | 'bad' {
  let value = 0;
  for (let i = 0; i < 4; i++) {
    if (at + i >= end) return 'short';
    const b = buf[at + i];
    value += (b & 0x7f) * 2 ** (7 * i);
    if ((b & 0x80) === 0) return { value, used: i + 1 };
  }
  return 'bad';
}

/** Reads the chunk that starts at `buf[start]` (the bytes up to `end` are available). */
export function readChunk(buf: Uint8Array, start = 0, end = buf.length): ReadResult {
  if (start >= end) return 'short';
  const tag = buf[start];
  const kind = tag >> 5;
  const limit = maxPayload(kind);
  if (limit === 0) return 'bad';
  const packet = kind === KIND_INTRA || kind === KIND_INTER;
  if (!packet && (tag & 0x1f) !== 0) return 'bad';
  if (end - start < 3) return 'short';
  const seq = buf[start + 1] | (buf[start + 2] << 8);
  const length = readLength(buf, start + 3, end);
  if (length === 'short' || length === 'bad') return length;
  if (length.value > limit) return 'bad';
  const from = start + 3 + length.used;
  const to = from + length.value;
  if (end < to + 4) return 'short';
  const crc = (buf[to] | (buf[to + 1] << 8) | (buf[to + 2] << 16) | (buf[to + 3] << 24)) >>> 0;
  if (crc32(buf, start, to) !== crc) return 'bad';
  return {
    chunk: { kind, frames: packet ? (tag & 0x1f) + 1 : 0, seq, payload: buf.slice(from, to) },
    used: to + 4 - start,
  };
}

/** The bytes of a chunk (what an encoder writes; used by tests). `frames`: 0 for non-packets. */
export function writeChunk(kind: number, frames: number, seq: number, payload: Uint8Array): Uint8Array {
  const length: number[] = [];
  let n = payload.length;
  for (;;) {
    const byte = n & 0x7f;
    n = Math.floor(n / 128);
    if (n === 0) {
      length.push(byte);
      break;
    }
    length.push(byte | 0x80);
  }
  const out = new Uint8Array(3 + length.length + payload.length + 4);
  out[0] = (kind << 5) | (Math.max(frames - 1, 0) & 0x1f);
  out[1] = seq & 0xff;
  out[2] = (seq >> 8) & 0xff;
  out.set(length, 3);
  out.set(payload, 3 + length.length);
  const end = 3 + length.length + payload.length;
  const crc = crc32(out, 0, end);
  out[end] = crc & 0xff;
  out[end + 1] = (crc >>> 8) & 0xff;
  out[end + 2] = (crc >>> 16) & 0xff;
  out[end + 3] = crc >>> 24;
  return out;
}

/** A growable byte buffer: bytes are appended at the end and consumed from the front. */
export class ByteQueue {
  private buf = new Uint8Array(256);
  private start = 0;
  private end = 0;

  /** Bytes held. */
  get length(): number {
    return this.end - this.start;
  }

  /** The backing array and the held bytes' bounds in it (valid until the next append). */
  view(): { buf: Uint8Array; start: number; end: number } {
    return { buf: this.buf, start: this.start, end: this.end };
  }

  append(bytes: Uint8Array): void {
    if (this.end + bytes.length > this.buf.length) {
      const held = this.end - this.start;
      if (held + bytes.length <= this.buf.length) {
        this.buf.copyWithin(0, this.start, this.end);
      } else {
        let size = this.buf.length;
        while (size < held + bytes.length) size *= 2;
        const next = new Uint8Array(size);
        next.set(this.buf.subarray(this.start, this.end));
        this.buf = next;
      }
      this.start = 0;
      this.end = held;
    }
    this.buf.set(bytes, this.end);
    this.end += bytes.length;
  }

  /** Drops the first `n` held bytes. */
  consume(n: number): void {
    this.start += n;
    if (this.start === this.end) this.start = this.end = 0;
  }
}
