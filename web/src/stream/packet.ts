/** Frames in a packet (docs/bitstream.md, "Frames in a packet"): per frame the flags, then with
 * a face each parameter's difference from the predictor (adaptive contexts) or, with no
 * predictor yet, from the header's reference (the intra table). */

import { MAX_VALUE, type Header } from './header';
import { Context, INTRA_TABLE, InvalidPayload, RangeDecoder } from './range';

/** The flags' bit 0: the frame shows a face. */
export const FACE = 1;

/** One decoded frame as the coder sees it: flags and, with a face, the quantised parameters. */
export interface CodedFrame {
  flags: number;
  q: Int32Array | null;
}

/** The coding state from one intra packet to the next. */
export class CodingState {
  readonly values: Context[];
  readonly flags = Context.flags();
  /** The last frame with a face since the intra packet: what the next one is predicted from. */
  pred: Int32Array | null = null;
  readonly references: number[];

  /** The state at the start of an intra packet. */
  constructor(header: Header) {
    this.values = header.classes.map((c) => Context.values(c));
    this.references = header.references;
  }
}

/** Decodes a packet of `frames` frames with `state` (which it advances); throws InvalidPayload
 * on data no encoder writes (the state is then unusable). */
export function decodePacket(state: CodingState, payload: Uint8Array, frames: number): CodedFrame[] {
  const dec = new RangeDecoder(payload);
  const n = state.references.length;
  const out: CodedFrame[] = [];
  for (let j = 0; j < frames; j++) {
    const flags = dec.symbol(state.flags.table);
    state.flags.update(flags);
    if ((flags & FACE) === 0) {
      out.push({ flags, q: null });
      continue;
    }
    const q = new Int32Array(n);
    const pred = state.pred;
    for (let i = 0; i < n; i++) {
      let v: number;
      if (pred) {
        const r = dec.value(state.values[i].table);
        state.values[i].update(r.symbol);
        v = pred[i] + r.value;
      } else {
        v = state.references[i] + dec.value(INTRA_TABLE).value;
      }
      if (Math.abs(v) > MAX_VALUE) throw new InvalidPayload(`parameter ${i} decodes to ${v}, beyond the format's range`);
      q[i] = v;
    }
    state.pred = q;
    out.push({ flags, q });
  }
  return out;
}
