/** The stream header (docs/bitstream.md, "Header"), versions 1 and 2 (with extra parameters). */
import { POSE_FIELDS } from '../shared_constants';

/** Head-pose parameters that start every frame: yaw, pitch, roll (degrees), ln scale (scale in
 * px per model unit), tx, ty (px). */
export const POSE_PARAMETERS = POSE_FIELDS.length;

/** Largest magnitude of a quantised value (and of a reference). */
export const MAX_VALUE = 2 ** 30;
/** Largest picture side, px. */
export const MAX_SIDE = 16384;

/** Everything a header carries. */
export interface Header {
  /** The version byte as read: 1, or 2 (with extras; a version-2 header with X = 0 is the same
   * header as a version-1 one). */
  version: number;
  /** Frame rate: fps[0] / fps[1] frames per second. */
  fps: [number, number];
  /** Picture size, px. */
  width: number;
  height: number;
  /** 8 bytes naming the head model's topology. */
  topology: Uint8Array;
  /** P, frames per packet (1-32). */
  packetFrames: number;
  /** K, packets from one intra packet to the next. */
  keyframePackets: number;
  /** Per parameter (N of them): the quantiser step (an f32, as a float64), the reference and
   * the spread class (0-15). */
  steps: number[];
  references: number[];
  classes: number[];
  /** The kinds (1-255, distinct) of the last `extras.length` parameters; empty for version 1. */
  extras: number[];
  /** R: the length of each basis vector (twice the knots). */
  basisLength: number;
  /** The basis, (N - 6 - X) x R, row-major, entries x32767. */
  basis: Int16Array;
  /** SHA-256 of the actor's `actor.json`. */
  actorId: Uint8Array;
  /** Whether an actor chunk follows the header. */
  actorInStream: boolean;
}

/** A header payload that is refused; `message` says why (the Rust decoder's wording). */
export class InvalidHeader extends Error {}

class Bytes {
  at = 0;
  private readonly view: DataView;
  constructor(private readonly buf: Uint8Array) {
    this.view = new DataView(buf.buffer, buf.byteOffset, buf.byteLength);
  }
  take(n: number): Uint8Array {
    const at = this.skip(n);
    return this.buf.slice(at, at + n);
  }
  private skip(n: number): number {
    if (this.at + n > this.buf.length) throw new InvalidHeader('the stream header is cut short');
    const at = this.at;
    this.at += n;
    return at;
  }
  u8(): number {
    return this.buf[this.skip(1)];
  }
  u16(): number {
    return this.view.getUint16(this.skip(2), true);
  }
  u32(): number {
    return this.view.getUint32(this.skip(4), true);
  }
  i32(): number {
    return this.view.getInt32(this.skip(4), true);
  }
  f32(): number {
    return this.view.getFloat32(this.skip(4), true);
  }
}

function checkExtras(n: number, kinds: ArrayLike<number>): void {
  const room = Math.max(n - POSE_PARAMETERS, 0);
  if (kinds.length > room) {
    throw new InvalidHeader(
      `${kinds.length} extra parameters do not fit in ${n} parameters per frame (at most ${room} after the pose)`,
    );
  }
  for (let i = 0; i < kinds.length; i++) {
    if (kinds[i] === 0) throw new InvalidHeader(`extra parameter ${i} has kind 0; kinds are 1-255`);
    for (let j = 0; j < i; j++) {
      if (kinds[j] === kinds[i]) throw new InvalidHeader(`extra parameter kind ${kinds[i]} appears twice`);
    }
  }
}

/** Parses and validates a header chunk's payload; throws InvalidHeader. */
export function parseHeader(buf: Uint8Array): Header {
  const b = new Bytes(buf);
  const magic = b.take(4);
  if (String.fromCharCode(...magic) !== 'FMST') throw new InvalidHeader('not a facemime stream (no FMST header)');
  const version = b.u8();
  if (version !== 1 && version !== 2) {
    throw new InvalidHeader(`stream format version ${version}; this decoder reads versions 1 and 2`);
  }
  const fpsNum = b.u32();
  const fpsDen = b.u32();
  const width = b.u16();
  const height = b.u16();
  const topology = b.take(8);
  const packetFrames = b.u8();
  const keyframePackets = b.u16();
  const n = b.u8();
  if (n < POSE_PARAMETERS) {
    throw new InvalidHeader(`${n} parameters per frame is not within ${POSE_PARAMETERS}..255`);
  }
  const steps: number[] = [];
  const references: number[] = [];
  const classes: number[] = [];
  for (let i = 0; i < n; i++) {
    steps.push(b.f32());
    references.push(b.i32());
    classes.push(b.u8());
  }
  let extras: number[] = [];
  if (version === 2) {
    const x = b.u8();
    extras = Array.from(b.take(x));
    checkExtras(n, extras);
  }
  const basisLength = b.u16();
  const entries = (n - POSE_PARAMETERS - extras.length) * basisLength;
  const raw = b.take(2 * entries);
  const basis = new Int16Array(entries);
  for (let i = 0; i < entries; i++) basis[i] = (raw[2 * i] | (raw[2 * i + 1] << 8)) << 16 >> 16;
  const actorId = b.take(32);
  const flag = b.u8();
  if (flag > 1) throw new InvalidHeader(`the header's actor flag is ${flag}, not 0 or 1`);
  if (b.at !== buf.length) throw new InvalidHeader(`the stream header has ${buf.length - b.at} bytes too many`);
  // the fields' ranges
  if (fpsNum === 0 || fpsDen === 0 || fpsNum / fpsDen > 1000) {
    throw new InvalidHeader(`frame rate ${fpsNum}/${fpsDen} is not in (0, 1000] frames/s`);
  }
  if (width === 0 || height === 0 || width > MAX_SIDE || height > MAX_SIDE) {
    throw new InvalidHeader(`picture size ${width}x${height} is not within 1..${MAX_SIDE}`);
  }
  if (packetFrames === 0 || packetFrames > 32) {
    throw new InvalidHeader(`${packetFrames} frames per packet is not within 1..32`);
  }
  if (keyframePackets === 0) throw new InvalidHeader('the keyframe interval must be at least one packet');
  for (let i = 0; i < n; i++) {
    if (!(Number.isFinite(steps[i]) && steps[i] > 0) || classes[i] >= 16 || Math.abs(references[i]) > MAX_VALUE) {
      throw new InvalidHeader(`parameter ${i} has a bad quantiser (step ${steps[i]}, class ${classes[i]})`);
    }
  }
  return {
    version,
    fps: [fpsNum, fpsDen],
    width,
    height,
    topology,
    packetFrames,
    keyframePackets,
    steps,
    references,
    classes,
    extras,
    basisLength,
    basis,
    actorId,
    actorInStream: flag === 1,
  };
}

function sameArray(a: ArrayLike<number>, b: ArrayLike<number>): boolean {
  if (a.length !== b.length) return false;
  for (let i = 0; i < a.length; i++) if (a[i] !== b[i]) return false;
  return true;
}

/** Whether two headers are the same header: equal fields, whatever their version byte. */
export function sameHeader(a: Header, b: Header): boolean {
  return (
    a.fps[0] === b.fps[0] &&
    a.fps[1] === b.fps[1] &&
    a.width === b.width &&
    a.height === b.height &&
    sameArray(a.topology, b.topology) &&
    a.packetFrames === b.packetFrames &&
    a.keyframePackets === b.keyframePackets &&
    sameArray(a.steps, b.steps) &&
    sameArray(a.references, b.references) &&
    sameArray(a.classes, b.classes) &&
    sameArray(a.extras, b.extras) &&
    a.basisLength === b.basisLength &&
    sameArray(a.basis, b.basis) &&
    sameArray(a.actorId, b.actorId) &&
    a.actorInStream === b.actorInStream
  );
}

/** Parameter i's value: `q_i * step_i` in float64. */
export function dequantise(header: Header, q: ArrayLike<number>): Float64Array {
  const out = new Float64Array(q.length);
  for (let i = 0; i < q.length; i++) out[i] = q[i] * header.steps[i];
  return out;
}
