/** Helpers for the tests: the repository's files, and decoding a stream in pieces. */

import { readFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { StreamDecoder, type Event, type Frame } from '../src/stream/index';

/** The repository's root (the tests run bundled from web/.test-build/). */
export const ROOT = join(dirname(fileURLToPath(import.meta.url)), '..', '..');

/** A file of tests/codec/data. */
export function codecData(name: string): Uint8Array {
  return new Uint8Array(readFileSync(join(ROOT, 'tests', 'codec', 'data', name)));
}

/** The events of `data` pushed in pieces of `piece` bytes (0: at once), then finished. */
export function decodeAll(data: Uint8Array, piece = 0, fromStart = true): { dec: StreamDecoder; events: Event[] } {
  const dec = new StreamDecoder(fromStart);
  const events: Event[] = [];
  const step = piece > 0 ? piece : Math.max(data.length, 1);
  for (let at = 0; at < data.length; at += step) events.push(...dec.push(data.subarray(at, at + step)));
  events.push(...dec.finish());
  return { dec, events };
}

/** The frames among `events`. */
export function framesOf(events: Event[]): Frame[] {
  return events.flatMap((e) => (e.kind === 'frame' ? [e.frame] : []));
}

/** The bytes of `chunks` joined. */
export function concat(chunks: Uint8Array[]): Uint8Array {
  const out = new Uint8Array(chunks.reduce((n, c) => n + c.length, 0));
  let at = 0;
  for (const c of chunks) {
    out.set(c, at);
    at += c.length;
  }
  return out;
}

/** The chunks of an undamaged stream, each as its bytes. */
export function splitChunks(data: Uint8Array, read: (buf: Uint8Array, at: number) => number): Uint8Array[] {
  const out: Uint8Array[] = [];
  for (let at = 0; at < data.length; ) {
    const used = read(data, at);
    out.push(data.slice(at, at + used));
    at += used;
  }
  return out;
}
