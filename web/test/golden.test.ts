/** The golden streams of tests/codec/data decode to their checked-in values exactly, whole and
 * fed a byte at a time. */

import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { test } from 'node:test';
import { codecData, decodeAll, framesOf, ROOT } from './util';

interface Expected {
  extras?: number[];
  frames: { index: number; face: boolean; lost: number; values: number[] }[];
}

function expected(name: string): Expected {
  return JSON.parse(readFileSync(join(ROOT, 'tests', 'codec', 'data', name), 'utf8')) as Expected;
}

function checkGolden(stream: string, json: string, piece: number) {
  const want = expected(json);
  const { dec, events } = decodeAll(codecData(stream), piece);
  const frames = framesOf(events);
  assert.equal(frames.length, want.frames.length);
  frames.forEach((f, k) => {
    const w = want.frames[k];
    assert.deepEqual([f.index, f.face, f.lost, f.concealed], [w.index, w.face, w.lost, false], `frame ${k}`);
    assert.deepEqual(Array.from(f.values), w.values, `frame ${k}'s values`); // exactly, bit for bit
  });
  assert.equal(events[0].kind, 'header');
  assert.deepEqual(dec.header?.extras, want.extras ?? []);
  assert.deepEqual(dec.stats, {
    packets: Math.ceil(want.frames.length / (dec.header?.packetFrames ?? 1)), lost_packets: 0, late_packets: 0,
    undecodable: 0, appearance: 0, damaged_runs: 0, damaged_bytes: 0, frames: want.frames.length, concealed: 0,
  });
  return dec;
}

test('the version-1 golden stream decodes to golden.json exactly', () => {
  const dec = checkGolden('golden.fmstream', 'golden.json', 0);
  const h = dec.header!;
  assert.deepEqual([h.version, h.fps, h.width, h.height, new TextDecoder().decode(h.topology), h.packetFrames,
    h.keyframePackets], [1, [25, 1], 320, 240, 'golden!!', 5, 4]);
  assert.deepEqual(h.steps, [0.5, 0.5, 0.5, Math.fround(0.004), 0.5, 0.5, 2, 2, 2, 2]);
  assert.deepEqual(h.references, [0, 0, 0, 173, 320, 240, 0, 0, 0, 0]);
  assert.deepEqual(h.classes, [5, 5, 5, 3, 7, 7, 6, 6, 6, 6]);
  assert.equal(h.basisLength, 6);
  assert.deepEqual(Array.from(h.basis), Array.from({ length: 24 }, (_, i) => i * 1111 - 12000));
  assert.deepEqual(Array.from(h.actorId), Array.from({ length: 32 }, (_, i) => i));
  assert.equal(h.actorInStream, false);
});

test('the version-2 golden stream decodes to golden_v2.json exactly', () => {
  const dec = checkGolden('golden_v2.fmstream', 'golden_v2.json', 0);
  assert.equal(dec.header!.version, 2);
  assert.equal(dec.header!.basis.length, 2 * 6);
});

test('the golden streams fed a byte at a time decode the same', () => {
  checkGolden('golden.fmstream', 'golden.json', 1);
  checkGolden('golden_v2.fmstream', 'golden_v2.json', 1);
  checkGolden('golden_v2.fmstream', 'golden_v2.json', 7);
});
