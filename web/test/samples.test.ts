/** The actor's own mouth and eyes on the page (src/render/samples.ts) on a toy head: the lip strip
 * and its interior layout, the stream's sample choices, the choice by shape and the paste. (Against
 * the Python painter on real streams: tests/web/test_receiver_page.py.) */

import assert from 'node:assert/strict';
import { test } from 'node:test';
import type { Picture, SampleGroup } from '../src/render/actor';
import type { Model } from '../src/render/geometry';
import { lipStrip } from '../src/render/geometry';
import { interiorUv, SamplePainter, sentSamples } from '../src/render/samples';

/** Inner lips of three knots sharing their corners (vertices 0 and 2); outer lips 4-7. */
const MODEL: Model = {
  vertices: new Float64Array(8 * 3),
  triangles: new Uint32Array(0),
  uv: new Float64Array(8 * 2),
  groups: {
    mouth_inner_upper: [0, 1, 2], mouth_inner_lower: [0, 3, 2],
    mouth_outer_upper: [4, 5, 6], mouth_outer_lower: [4, 7, 6],
  },
};

test('the lip strip leaves out the triangles whose vertices repeat at the corners', () => {
  assert.deepEqual([...lipStrip(MODEL)], [0, 1, 3, 1, 2, 3]);
  const uneven = { ...MODEL, groups: { ...MODEL.groups, mouth_inner_lower: [0, 2] } };
  assert.equal(lipStrip(uneven).length, 0);
});

test('the interior lays the upper lip along the top, the lower along the bottom, corners between', () => {
  const uv = interiorUv(MODEL);
  const at = (v: number) => [uv[2 * v], uv[2 * v + 1]];
  assert.deepEqual([at(0), at(1), at(2), at(3)], [[0, 0.5], [0.5, 0], [1, 0.5], [0.5, 1]]);
});

test('sample choices are the index plus one, rounded half to even, and absent without their kinds', () => {
  // kinds: a look value, then eyes (7) and mouth (8); the extras start at index 2 of the values
  assert.deepEqual(sentSamples([1, 7, 8], [9, 9, 0.5, 3, 0], 2), [2, null]);
  assert.deepEqual(sentSamples([8], [2.5], 0), [null, 1]); // 2.5 rounds to 2: sample 1
  assert.equal(sentSamples([1, 2], [0, 0], 0), null);
});

const picture = (w: number, h: number, grey: number): Picture =>
  ({ width: w, height: h, rgba: new Uint8Array(w * h * 4).fill(grey) });

function eyes(): SampleGroup {
  return {
    name: 'eyes',
    boxes: [[2, 2, 24, 18], [32, 2, 24, 18]],
    keys: [Float64Array.from([1, 1, 0, 0, 0, 0]), Float64Array.from([0, 0, 0.1, 0, 0.1, 0])],
    frames: [3, 7],
    images: [[picture(24, 18, 200), picture(24, 18, 200)], [picture(24, 18, 50), picture(24, 18, 50)]],
    interiors: null,
  };
}

test('the sample nearest the shape is chosen, none at the key frame\'s, and a sent choice overrides', () => {
  const painter = new SamplePainter([eyes()], MODEL, [0, 1, 2, 3]);
  const still = new Float64Array(8);
  assert.deepEqual(painter.choose(still, [0.9, 1, 0, 0, 0, 0]), [0]);
  assert.deepEqual(painter.choose(still, [0, 0, 0.09, 0, 0.11, 0]), [1]);
  assert.deepEqual(painter.choose(still, [0, 0, 0, 0, 0, 0]), [null]);
  assert.deepEqual(painter.choose(still, [0.9, 1, 0, 0, 0, 0], [1, null]), [1]);
  assert.deepEqual(painter.choose(still, [0.9, 1, 0, 0, 0, 0], [5, null]), [null]); // beyond the samples
});

test('a chosen sample is pasted inside its boxes, faded at their edges, and nothing else changes', () => {
  const painter = new SamplePainter([eyes()], MODEL, [0, 1, 2, 3]);
  const texture = picture(60, 40, 100);
  const out = painter.paint(texture, [0]);
  const grey = (p: Picture, x: number, y: number) => p.rgba[4 * (y * p.width + x)];
  assert.equal(grey(texture, 14, 10), 100); // the texture given is left alone
  assert.equal(grey(out, 14, 10), 200);
  assert.equal(grey(out, 44, 10), 200);
  assert.equal(grey(out, 30, 30), 100);
  assert.ok(grey(out, 14, 2) > 100 && grey(out, 14, 2) < 200);
  assert.equal(painter.paint(texture, [null]), texture);
});
