/**
 * The mouth interior (facemime.animate.synth.draw_mouth_interior): a dark cavity with upper and
 * lower teeth, painted behind the lips, drawn into an RGBA patch (colour already shaded, alpha the
 * opening's anti-aliased mask) that the renderer blends in.
 *
 * Points: image pixels, x right, y down, (0, 0) the centre of the top-left pixel.
 */
import { rint } from '../imaging/filters';
import { fillPolyAA, lineAAShifted } from '../imaging/polygon';
import {
  CAVITY, GAPS, LOWER_SHARE, LOWER_TEETH, SHIFT, TEETH, TEETH_FROM, TEETH_SPAN, TEETH_SPREAD, UPPER_MIN, UPPER_SHARE, UPPER_TEETH,
} from '../shared_constants';

/** How much of the teeth the lips uncover, 0..1, for corners ``spread`` times their rest
 * distance apart. */
export function teethUncovered(spread: number): number {
  return Math.min(Math.max((spread - TEETH_SPREAD[0]) / (TEETH_SPREAD[1] - TEETH_SPREAD[0]), 0), 1);
}

export interface MouthPatch {
  /** The patch's top-left pixel in the picture, and its size, px. */
  x0: number; y0: number; width: number; height: number;
  /** RGBA, row-major from the top-left: colour shaded, alpha the opening. */
  rgba: Uint8Array;
}

/** The interior of the opening bounded by the inner lips ``upper`` and ``lower`` (K*2 px each,
 * corner to corner), ``uncovered`` of the teeth shown, in a picture of ``size``; null when the
 * opening is empty or off the picture. Drawn as the Python code draws it, with OpenCV's
 * anti-aliased polygons and lines (imaging/polygon) on points rounded to 1/16 px. */
export function mouthPatch(upper: Float64Array, lower: Float64Array, uncovered: number,
  size: [number, number]): MouthPatch | null {
  const k = upper.length / 2, kl = lower.length / 2;
  const poly: number[] = [];
  for (let i = 0; i < k; i++) poly.push(upper[2 * i], upper[2 * i + 1]);
  for (let i = kl - 1; i >= 0; i--) poly.push(lower[2 * i], lower[2 * i + 1]);
  let minX = Infinity, minY = Infinity, maxX = -Infinity, maxY = -Infinity;
  for (let i = 0; i < poly.length; i += 2) {
    minX = Math.min(minX, poly[i]); maxX = Math.max(maxX, poly[i]);
    minY = Math.min(minY, poly[i + 1]); maxY = Math.max(maxY, poly[i + 1]);
  }
  const x0 = Math.max(Math.floor(minX) - 1, 0), y0 = Math.max(Math.floor(minY) - 1, 0);
  const x1 = Math.min(Math.ceil(maxX) + 2, size[0]), y1 = Math.min(Math.ceil(maxY) + 2, size[1]);
  if (x1 - x0 < 2 || y1 - y0 < 2) return null;
  const w = x1 - x0, h = y1 - y0;
  // points to 1/16 px in the patch (numpy's rounding, half to even)
  const fix = (pts: ArrayLike<number>) => Array.from(pts, (v, i) => rint((v - (i % 2 ? y0 : x0)) * (1 << SHIFT)));
  // the mask first
  const mask = new Uint8Array(w * h);
  fillPolyAA({ img: mask, w, h, colour: [255] }, fix(poly), SHIFT);
  if (!mask.some((v) => v > 0)) return null;
  // the paint: cavity, teeth, the gaps between them
  const paint = new Uint8Array(w * h * 3);
  for (let p = 0; p < w * h; p++) paint.set(CAVITY, 3 * p);
  const ax = upper[2 * (k - 1)] - upper[0], ay = upper[2 * (k - 1) + 1] - upper[1];
  const width = Math.hypot(ax, ay);
  const downX = -ay / Math.max(width, 1e-9), downY = ax / Math.max(width, 1e-9);
  const same = k === kl;
  let keep = Array.from({ length: k }, (_, i) => same ? Math.abs(k > 1 ? -1 + (2 * i) / (k - 1) : -1) <= TEETH_SPAN : true);
  if (same && keep.filter(Boolean).length < 2) keep = keep.map(() => true);
  const idx = keep.flatMap((kept, i) => (kept ? [i] : []));
  const opening = idx.map((i) => {
    const o = same ? (lower[2 * i] - upper[2 * i]) * downX + (lower[2 * i + 1] - upper[2 * i + 1]) * downY : width;
    return o * Math.min(Math.max(o / (TEETH_FROM * width) - 1, 0), 1);
  });
  const rows: [Float64Array, number, number, number, number][] = [
    [upper, UPPER_TEETH, UPPER_SHARE, Math.max(uncovered, UPPER_MIN), 1],
    [lower, LOWER_TEETH, LOWER_SHARE, uncovered, -1],
  ];
  for (const [curve, height, share, shown, sign] of rows) {
    const reach = opening.map((o) => shown * Math.min(height * width, share * o));
    if (Math.max(...reach) < 0.5) continue;
    const edge = idx.flatMap((i) => [curve[2 * i], curve[2 * i + 1]]);
    const tips = idx.flatMap((_, j) => [edge[2 * j] + sign * reach[j] * downX, edge[2 * j + 1] + sign * reach[j] * downY]);
    const outline = [...edge];
    for (let j = idx.length - 1; j >= 0; j--) outline.push(tips[2 * j], tips[2 * j + 1]);
    fillPolyAA({ img: paint, w, h, colour: TEETH }, fix(outline), SHIFT);
    const gaps = { img: paint, w, h, colour: GAPS };
    for (let j = 1; j < idx.length - 1; j++) {
      lineAAShifted(gaps, fix(edge.slice(2 * j, 2 * j + 2)), fix(tips.slice(2 * j, 2 * j + 2)), SHIFT);
    }
  }
  const centre = (upper[0] + upper[2 * (k - 1)]) / 2, half = Math.max(width / 2, 1);
  const rgba = new Uint8Array(w * h * 4);
  for (let x = 0; x < w; x++) {
    const cx = (x0 + x - centre) / half;
    const shade = Math.min(Math.max(1.15 - 0.6 * cx * cx, 0.35), 1);
    for (let y = 0; y < h; y++) {
      const p = 4 * (y * w + x);
      for (let c = 0; c < 3; c++) rgba[p + c] = Math.round(paint[3 * (y * w + x) + c] * shade);
      rgba[p + 3] = mask[y * w + x];
    }
  }
  return { x0, y0, width: w, height: h, rgba };
}
