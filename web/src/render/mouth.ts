/**
 * The mouth interior (facemime.animate.synth.draw_mouth_interior): a dark cavity with upper and
 * lower teeth, painted behind the lips, drawn here with a 2-D canvas into an RGBA patch (colour
 * already shaded, alpha the opening's anti-aliased mask) that the renderer blends in.
 *
 * Points: image pixels, x right, y down, (0, 0) the centre of the top-left pixel (a canvas puts
 * pixel centres at +0.5, hence the shift below).
 */

const CAVITY = [52, 18, 22];
const TEETH = [185, 165, 150];
const GAPS = [150, 140, 128];
const UPPER_TEETH = 0.11;
const LOWER_TEETH = 0.07;
const TEETH_SPAN = 0.72;
const UPPER_SHARE = 0.6;
const LOWER_SHARE = 0.4;
const TEETH_FROM = 0.04;
const TEETH_SPREAD = [0.9, 1.05];
const UPPER_MIN = 0.5;

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

const css = (c: number[]) => `rgb(${c[0]},${c[1]},${c[2]})`;

/** The interior of the opening bounded by the inner lips ``upper`` and ``lower`` (K*2 px each,
 * corner to corner), ``uncovered`` of the teeth shown, in a picture of ``size``; null when the
 * opening is empty or off the picture. */
export function mouthPatch(upper: Float64Array, lower: Float64Array, uncovered: number,
  size: [number, number], canvas: HTMLCanvasElement): MouthPatch | null {
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
  canvas.width = w;
  canvas.height = h;
  const ctx = canvas.getContext('2d', { willReadFrequently: true }) as CanvasRenderingContext2D;
  const path = (pts: number[]) => {
    ctx.beginPath();
    for (let i = 0; i < pts.length; i += 2) {
      const q = fix(pts[i], pts[i + 1]);
      if (i === 0) ctx.moveTo(q[0], q[1]); else ctx.lineTo(q[0], q[1]);
    }
    ctx.closePath();
  };
  // points to 1/16 px, as the Python drawing does, then to canvas coordinates
  const fix = (x: number, y: number) => [Math.round((x - x0) * 16) / 16 + 0.5, Math.round((y - y0) * 16) / 16 + 0.5];
  // the mask first
  ctx.clearRect(0, 0, w, h);
  ctx.fillStyle = '#fff';
  path(poly);
  ctx.fill();
  const mask = ctx.getImageData(0, 0, w, h).data;
  let any = false;
  for (let i = 3; i < mask.length; i += 4) if (mask[i]) { any = true; break; }
  if (!any) return null;
  // the paint: cavity, teeth, the gaps between them
  ctx.fillStyle = css(CAVITY);
  ctx.fillRect(0, 0, w, h);
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
    ctx.fillStyle = css(TEETH);
    path(outline);
    ctx.fill();
    ctx.strokeStyle = css(GAPS);
    ctx.lineWidth = 1;
    for (let j = 1; j < idx.length - 1; j++) {
      const a = fix(edge[2 * j], edge[2 * j + 1]), b = fix(tips[2 * j], tips[2 * j + 1]);
      ctx.beginPath();
      ctx.moveTo(a[0], a[1]);
      ctx.lineTo(b[0], b[1]);
      ctx.stroke();
    }
  }
  const paint = ctx.getImageData(0, 0, w, h).data;
  const centre = (upper[0] + upper[2 * (k - 1)]) / 2, half = Math.max(width / 2, 1);
  const rgba = new Uint8Array(w * h * 4);
  for (let x = 0; x < w; x++) {
    const cx = (x0 + x - centre) / half;
    const shade = Math.min(Math.max(1.15 - 0.6 * cx * cx, 0.35), 1);
    for (let y = 0; y < h; y++) {
      const p = 4 * (y * w + x);
      for (let c = 0; c < 3; c++) rgba[p + c] = Math.round(paint[p + c] * shade);
      rgba[p + 3] = mask[p + 3];
    }
  }
  return { x0, y0, width: w, height: h, rgba };
}
