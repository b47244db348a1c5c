/** The iris painter (src/render/eyes.ts) on a synthetic texture: a dark iris on a white eye moves by
 * the shift asked for, and nothing outside the eyes changes. (Against the Python painter:
 * tests/web/test_web_eyes.py.) */

import assert from 'node:assert/strict';
import { test } from 'node:test';
import type { Picture } from '../src/render/actor';
import type { Model } from '../src/render/geometry';
import { LookPainter } from '../src/render/eyes';

const W = 256, H = 160;
/** The eyes' middles (texture px), their width (px) and the lids' half-height at the middle. */
const CENTRES: [number, number][] = [[80, 70], [176, 70]];
const WIDTH = 60, HALF_OPEN = 22;
const IRIS = 0.21 * WIDTH;
const SKIN = [200, 160, 140], WHITE = [235, 235, 235], DARK = [60, 40, 30];

/** An eye ring (corner, 3 upper, corner, 3 lower), px, of the eye at `c`. */
function ring(c: [number, number]): [number, number][] {
  const lid = (x: number) => HALF_OPEN * Math.sqrt(1 - (x / (WIDTH / 2)) ** 2);
  const xs = [-30, -15, 0, 15, 30, 15, 0, -15];
  return xs.map((x, k) => [c[0] + x, c[1] + (k === 0 || k === 4 ? 0 : k < 4 ? -lid(x) : lid(x))]);
}

function insidePolygon(poly: [number, number][], x: number, y: number): boolean {
  let inside = false;
  for (let i = 0, j = poly.length - 1; i < poly.length; j = i++) {
    const [xi, yi] = poly[i], [xj, yj] = poly[j];
    if (yi > y !== yj > y && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}

/** The texture (skin, white eye openings, dark irises anti-aliased) and a model of the two rings. */
function scene(): { texture: Picture; model: Model } {
  const rgba = new Uint8Array(W * H * 4);
  const rings = CENTRES.map(ring);
  for (let y = 0; y < H; y++) {
    for (let x = 0; x < W; x++) {
      let colour = SKIN;
      const k = rings.findIndex((r) => insidePolygon(r, x, y));
      if (k >= 0) {
        let cover = 0; // of the iris, 4 x 4 samples
        for (let a = 0; a < 4; a++) {
          for (let b = 0; b < 4; b++) {
            cover += +(Math.hypot(x - 0.375 + a / 4 - CENTRES[k][0], y - 0.375 + b / 4 - CENTRES[k][1]) <= IRIS);
          }
        }
        colour = WHITE.map((v, c) => Math.round(v + (cover / 16) * (DARK[c] - v)));
      }
      rgba.set([...colour, 255], (y * W + x) * 4);
    }
  }
  const uv = new Float64Array(32);
  rings.flat().forEach(([x, y], i) => { uv[2 * i] = (x + 0.5) / W; uv[2 * i + 1] = (y + 0.5) / H; });
  const model: Model = { vertices: new Float64Array(48), triangles: new Uint32Array(0), uv,
    groups: { eye_right: [0, 1, 2, 3, 4, 5, 6, 7], eye_left: [8, 9, 10, 11, 12, 13, 14, 15] } };
  return { texture: { width: W, height: H, rgba }, model };
}

/** The darkness-weighted centre (x, y) px of the pixels darker than 150 (grey) near eye `k`. */
function darkCentre(p: Picture, k: number): [number, number] {
  let sw = 0, sx = 0, sy = 0;
  const [cx, cy] = CENTRES[k];
  for (let y = cy - 30; y <= cy + 30; y++) {
    for (let x = cx - 40; x <= cx + 40; x++) {
      const o = (y * W + x) * 4;
      const wt = Math.max(0, 150 - (p.rgba[o] + p.rgba[o + 1] + p.rgba[o + 2]) / 3);
      sw += wt; sx += wt * x; sy += wt * y;
    }
  }
  return [sx / sw, sy / sw];
}

/** Whether (x, y) lies outside both eyes' boxes (the patch's span: 0.7 x 0.55 eye widths each side,
 * plus a texel). */
const outsideBoxes = (x: number, y: number) =>
  CENTRES.every(([cx, cy]) => Math.abs(x - cx) > 0.7 * WIDTH + 1 || Math.abs(y - cy) > 0.55 * WIDTH + 1);

test('a still look gives the texture as it was, and the same look again gives null', () => {
  const { texture, model } = scene();
  const painter = new LookPainter(texture, model);
  const first = painter.texture([[0, 0], [0, 0]]);
  assert.ok(first);
  assert.deepEqual(first.rgba, texture.rgba);
  assert.equal(painter.texture([[0, 0], [0, 0]]), null);
  assert.equal(painter.texture([[0.001, 0], [0, 0.002]]), null, 'shifts under a quarter texel are still');
  assert.ok(painter.texture([[0.05, 0], [0, 0]]));
  assert.equal(painter.texture([[0.05, 0], [0, 0]]), null);
  const back = painter.texture([[0, 0], [0, 0]]);
  assert.ok(back);
  assert.deepEqual(back.rgba, texture.rgba);
});

test('an iris shift moves the dark disc by shift @ axes texels and nothing outside the eyes', () => {
  const { texture, model } = scene();
  const before = CENTRES.map((_, k) => darkCentre(texture, k));
  const looks: [number, number][][] = [[[0.05, 0.03], [-0.04, -0.02]], [[-0.06, 0.0], [0.0, 0.05]], [[0.02, -0.04], [0.07, 0.01]]];
  for (const look of looks) {
    const painter = new LookPainter(texture, model);
    const out = painter.texture(look);
    assert.ok(out);
    look.forEach(([u, v], k) => {
      // the eyes are level: axes [[WIDTH, 0], [0, WIDTH]]
      const [x, y] = darkCentre(out, k);
      const want = [before[k][0] + u * WIDTH, before[k][1] + v * WIDTH];
      assert.ok(Math.abs(x - want[0]) < 0.3 && Math.abs(y - want[1]) < 0.3,
        `eye ${k}, look ${JSON.stringify(look)}: centre (${x.toFixed(2)}, ${y.toFixed(2)}), `
        + `wanted (${want[0].toFixed(2)}, ${want[1].toFixed(2)})`);
    });
    let changed = 0, outside = 0;
    for (let y = 0; y < H; y++) {
      for (let x = 0; x < W; x++) {
        for (let c = 0; c < 4; c++) {
          const o = (y * W + x) * 4 + c;
          if (out.rgba[o] !== texture.rgba[o]) {
            changed++;
            if (outsideBoxes(x, y)) outside++;
          }
        }
      }
    }
    assert.ok(changed > 100, 'the eyes changed');
    assert.equal(outside, 0, 'nothing outside the eyes changed');
  }
});
