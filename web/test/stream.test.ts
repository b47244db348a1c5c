/** Chunks, CRC, LEB128 lengths, resync after damage, loss, appearance chunks and headers. */

import assert from 'node:assert/strict';
import { test } from 'node:test';
import { crc32, KIND_APPEARANCE, KIND_HEADER, parseHeader, readChunk, readLength, writeChunk } from '../src/stream/index';
import { codecData, concat, decodeAll, framesOf, splitChunks } from './util';

const golden = codecData('golden.fmstream');
const goldenV2 = codecData('golden_v2.fmstream');
const chunksOf = (data: Uint8Array) =>
  splitChunks(data, (buf, at) => {
    const r = readChunk(buf, at);
    assert.ok(typeof r === 'object', `a chunk at ${at}`);
    return r.used;
  });
const bytes = (...b: number[]) => new Uint8Array(b);

test('CRC-32 is zlib\'s', () => {
  assert.equal(crc32(new TextEncoder().encode('123456789')), 0xcbf43926);
  assert.equal(crc32(new Uint8Array(0)), 0);
  assert.equal(crc32(new TextEncoder().encode('The quick brown fox jumps over the lazy dog')), 0x414fa339);
});

test('LEB128 lengths take at most four bytes and each kind has its limit', () => {
  assert.deepEqual(readLength(bytes(0x7f), 0), { value: 127, used: 1 });
  assert.deepEqual(readLength(bytes(0x80, 0x01), 0), { value: 128, used: 2 });
  assert.deepEqual(readLength(bytes(0xff, 0xff, 0xff, 0x7f), 0), { value: 2 ** 28 - 1, used: 4 });
  assert.equal(readLength(bytes(0x80, 0x80, 0x80, 0x80, 0x01), 0), 'bad');
  assert.equal(readLength(bytes(0x80, 0x80), 0), 'short');
  const declaring = (kind: number, n: number) =>
    readChunk(bytes(kind << 5, 0, 0, (n & 0x7f) | 0x80, ((n >> 7) & 0x7f) | 0x80, n >> 14));
  assert.equal(declaring(KIND_APPEARANCE, 2 ** 20 + 1), 'bad');
  assert.equal(declaring(KIND_APPEARANCE, 2 ** 20), 'short');
  assert.equal(declaring(3, 2 ** 16 + 1), 'bad');
  assert.equal(declaring(3, 2 ** 16), 'short');
  assert.equal(readChunk(bytes(KIND_HEADER << 5, 0, 0, 0x80, 0x80, 0x80, 0x80, 0x00)), 'bad'); // five bytes
  assert.equal(readChunk(bytes(0)), 'bad'); // kind 0
  assert.equal(readChunk(bytes(7 << 5)), 'bad'); // kind 7
  assert.equal(readChunk(bytes((KIND_HEADER << 5) | 1)), 'bad'); // frame bits on a header
  const c = writeChunk(4, 5, 513, bytes(1, 2, 3));
  const r = readChunk(c);
  assert.ok(typeof r === 'object');
  assert.deepEqual([r.chunk.kind, r.chunk.frames, r.chunk.seq, Array.from(r.chunk.payload), r.used],
    [4, 5, 513, [1, 2, 3], c.length]);
  for (let bit = 0; bit < c.length * 8; bit++) {
    const d = c.slice();
    d[bit >> 3] ^= 1 << (bit & 7);
    assert.ok(typeof readChunk(d) !== 'object', `bit ${bit}`);
  }
  for (let cut = 0; cut < c.length; cut++) assert.equal(readChunk(c.subarray(0, cut)), 'short');
});

test('a damaged byte is skipped and counted, and the stream decodes as before', () => {
  const plain = framesOf(decodeAll(golden).events);
  const chunks = chunksOf(golden);
  const junk = concat([chunks[0], bytes(0xee), ...chunks.slice(1)]);
  for (const piece of [0, 1, 5]) {
    const { dec, events } = decodeAll(junk, piece);
    assert.deepEqual(framesOf(events), plain);
    assert.equal(dec.stats.damaged_runs, 1);
    assert.equal(dec.stats.damaged_bytes, 1);
  }
});

test('a flipped byte costs its packet: concealed until the next intra packet', () => {
  const chunks = chunksOf(golden); // header, then packets of 5 frames, an intra packet every 4
  const damaged = chunks.map((c) => c.slice());
  damaged[2][6] ^= 0x10; // packet 1 (inter)
  const { dec, events } = decodeAll(concat(damaged));
  const frames = framesOf(events);
  const plain = framesOf(decodeAll(golden).events);
  assert.deepEqual(frames.map((f) => f.index), plain.map((f) => f.index));
  assert.deepEqual(frames.filter((f) => f.concealed).map((f) => f.index), Array.from({ length: 15 }, (_, i) => 5 + i));
  for (const f of frames.filter((f) => f.concealed)) assert.deepEqual(f.values, plain[4].values);
  assert.deepEqual(frames.slice(20), plain.slice(20));
  assert.deepEqual(dec.stats, { packets: 5, lost_packets: 1, late_packets: 0, undecodable: 0, appearance: 0,
    damaged_runs: 1, damaged_bytes: chunks[2].length, frames: 25, concealed: 15 });
});

test('frames before the first decodable one show the reference pose', () => {
  const chunks = chunksOf(golden);
  const { dec, events } = decodeAll(concat([chunks[0], ...chunks.slice(2)]));
  const frames = framesOf(events);
  const h = dec.header!;
  assert.equal(frames[0].concealed, true);
  assert.deepEqual([frames[0].face, frames[0].lost], [false, 15]);
  assert.deepEqual(Array.from(frames[0].values), h.references.map((r, i) => (i < 6 ? r * h.steps[i] : 0)));
  assert.equal(frames.filter((f) => f.concealed).length, 20);
});

test('late and repeated packets are dropped; a receiver joining live starts at its first packet', () => {
  const chunks = chunksOf(golden);
  const { dec } = decodeAll(concat([chunks[0], chunks[1], chunks[2], chunks[1], chunks[3]]));
  assert.equal(dec.stats.late_packets, 1);
  assert.equal(dec.stats.frames, 15);
  const live = decodeAll(concat([chunks[0], ...chunks.slice(3)]), 0, false);
  const frames = framesOf(live.events);
  assert.equal(frames[0].index, 10);
  assert.equal(frames.filter((f) => f.concealed).length, 10); // packets 2-3, inter, wait for packet 4
});

test('appearance chunks come out where they were read; short ones and ones before a header are undecodable', () => {
  const chunks = chunksOf(goldenV2);
  const payload = bytes(4, 0, 0, 0, 1, 0, 2, 0, 0x52);
  const mixed = concat([writeChunk(KIND_APPEARANCE, 0, 0, payload), chunks[0],
    writeChunk(KIND_APPEARANCE, 0, 0, payload.subarray(0, 7)), chunks[1],
    writeChunk(KIND_APPEARANCE, 0, 0, payload), ...chunks.slice(2)]);
  for (const piece of [0, 1]) {
    const { dec, events } = decodeAll(mixed, piece);
    const kinds = events.map((e) => (e.kind === 'frame' ? e.frame.index : e.kind));
    assert.deepEqual(kinds.slice(0, 7), ['header', 0, 1, 2, 3, 'appearance', 4]);
    assert.equal(dec.stats.undecodable, 2);
    assert.equal(dec.stats.appearance, 1);
    assert.equal(dec.stats.damaged_runs, 0);
  }
});

test('an equal header is ignored, whatever its version byte; a different one starts a new stream', () => {
  const chunks = chunksOf(golden);
  const r = readChunk(chunks[0]);
  assert.ok(typeof r === 'object');
  const p = r.chunk.payload;
  // version 2 with X = 0: the X byte goes after the 9 x N parameter bytes
  const x = 29 + 9 * p[28];
  const v2 = concat([p.subarray(0, 4), bytes(2), p.subarray(5, x), bytes(0), p.subarray(x)]);
  assert.deepEqual({ ...parseHeader(v2), version: 1 }, parseHeader(p));
  const again = writeChunk(KIND_HEADER, 0, 0, v2);
  const plain = decodeAll(golden);
  const repeated = decodeAll(concat([...chunks.slice(0, 3), again, ...chunks.slice(3)]));
  assert.deepEqual(repeated.events.filter((e) => e.kind === 'frame'), plain.events.filter((e) => e.kind === 'frame'));
  assert.equal(repeated.events.filter((e) => e.kind === 'header').length, 1);
  // a different header (another actor id): the stream starts over from packet 0
  const other = p.slice();
  other[other.length - 2] ^= 1;
  const { dec, events } = decodeAll(concat([...chunks.slice(0, 3), writeChunk(KIND_HEADER, 0, 0, other),
    ...chunks.slice(1)]), 1);
  assert.equal(events.filter((e) => e.kind === 'header').length, 2);
  assert.deepEqual(framesOf(events).map((f) => f.index).slice(0, 12), [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 0, 1]);
  assert.equal(dec.stats.frames, 50);
});

test('a refused header says why and decodes nothing', () => {
  const chunks = chunksOf(golden);
  const r = readChunk(chunks[0]);
  assert.ok(typeof r === 'object');
  const p = r.chunk.payload.slice();
  p[4] = 3;
  const { dec, events } = decodeAll(concat([writeChunk(KIND_HEADER, 0, 0, p), ...chunks.slice(1)]));
  assert.equal(dec.header, null);
  assert.equal(dec.headerError, 'stream format version 3; this decoder reads versions 1 and 2');
  assert.equal(events.length, 0);
  assert.equal(dec.stats.undecodable, chunks.length - 1);
});

test('a packet decodes by its kind: an intra packet at any number resets the state', () => {
  // the golden stream's packet 2 is inter; losing packet 1 stops it, an intra packet 3 would not
  const chunks = chunksOf(golden);
  const { events } = decodeAll(concat([chunks[0], chunks[1], chunks[3]]));
  assert.deepEqual(framesOf(events).map((f) => f.concealed), [...Array(5).fill(false), ...Array(10).fill(true)]);
});

test('a jump of up to 256 packets is concealed, a longer one is a new start, one of 2^15 or more is late', () => {
  const chunks = chunksOf(golden);
  const renumber = (c: Uint8Array, shift: number) => {
    const r = readChunk(c);
    assert.ok(typeof r === 'object');
    return writeChunk(r.chunk.kind, r.chunk.frames, (r.chunk.seq + shift) % 65536, r.chunk.payload);
  };
  for (const [shift, concealed, late] of [[256, 1280, 0], [257, 0, 0], [32767, 0, 0], [32768, 0, 4]]) {
    const moved = concat([...chunks.slice(0, 5), ...chunks.slice(5).map((c) => renumber(c, shift))]);
    const { dec, events } = decodeAll(moved);
    assert.equal(dec.stats.concealed, concealed, `shift ${shift}`);
    assert.equal(dec.stats.late_packets, late);
    assert.equal(dec.stats.lost_packets, late ? 0 : shift);
    const frames = framesOf(events);
    if (!late) assert.equal(frames[frames.length - 1].index, 39 + 5 * shift);
  }
});

test('a header that differs in any field is a new header', () => {
  const chunks = chunksOf(golden);
  const r = readChunk(chunks[0]);
  assert.ok(typeof r === 'object');
  let different = 0;
  for (let at = 5; at < r.chunk.payload.length; at++) {
    const p = r.chunk.payload.slice();
    p[at] ^= 1;
    try {
      parseHeader(p);
    } catch {
      continue; // refused: decodes nothing new
    }
    const { events } = decodeAll(concat([...chunks.slice(0, 3), writeChunk(KIND_HEADER, 0, 0, p)]));
    assert.equal(events.filter((e) => e.kind === 'header').length, 2, `byte ${at}`);
    different++;
  }
  assert.ok(different > 100);
});
