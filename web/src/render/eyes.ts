/**
 * The irises in the synthesis (facemime.animate.eyes.LookPainter.texture): the actor's texture
 * is the key frame, iris and all. On it, each eye's iris is found (facemime.track.eyes.find_iris
 * in the texture's own eye frame); a copy of the eye with the iris painted out (OpenCV's Telea
 * inpainting) is kept, and each frame the iris disc is pasted back, shifted by the look, inside
 * the eye's opening. The lids are closed by the geometry (closeLids), not here.
 *
 * The Python code's warps are facemime.render.bilinear's fixed arithmetic, followed here step for
 * step; the OpenCV operations it uses are reimplemented as OpenCV computes them (RGB to grey, the
 * anti-aliased polygon, the elliptic erosion, Gaussian kernels and borders, Telea's fast
 * marching), so that the texture matches `facemime decode`'s.
 *
 * Texture pixels: (x, y), x right, y down, (0, 0) the centre of the top-left texel (uv 0..1 from
 * its corner). Eye coordinates (u, v): units of the eye's width from the middle of its corners,
 * u along the line from the image-left corner to the image-right one, v across it (down).
 */
import type { Picture } from './actor';
import type { Model } from './geometry';
import { clampIndex, erodeEllipse, gaussianBlur, gaussianSize, median, percentile, rint } from '../imaging/filters';
import { inpaintTelea } from '../imaging/inpaint';
import { fillPolyAA } from '../imaging/polygon';
import { DENSITY, EYES, IRIS_RADIUS, IRIS_REACH, IRIS_U, IRIS_V, LID_EDGE, PASTE_STILL, SPAN_U, SPAN_V } from '../shared_constants';

/** One eye's frame on the texture: `origin` the middle of its corners (x, y) px, `axes` the u and
 * v directions scaled to one eye width (px), rows [ux, uy, vx, vy]. */
class EyeFrame {
  constructor(readonly origin: [number, number], readonly axes: [number, number, number, number]) {}

  /** The frame of an eye ring of 8 points (corner, 3 upper, corner, 3 lower), px (x, y) pairs. */
  static of(ring: Float64Array): EyeFrame {
    const [a, b] = ring[0] <= ring[8] ? [0, 8] : [8, 0];
    const ex = ring[b] - ring[a], ey = ring[b + 1] - ring[a + 1];
    return new EyeFrame([(ring[a] + ring[b]) / 2, (ring[a + 1] + ring[b + 1]) / 2], [ex, ey, -ey, ex]);
  }

  /** The eye's width, px. */
  get width(): number { return Math.hypot(this.axes[0], this.axes[1]); }

  /** Texture (x, y) px of eye coordinates (u, v). */
  toImage(u: number, v: number): [number, number] {
    const a = this.axes;
    return [this.origin[0] + (u * a[0] + v * a[2]), this.origin[1] + (u * a[1] + v * a[3])];
  }
}

/** (rows, columns) of an eye's patch. */
const PATCH_ROWS = rint((SPAN_V[1] - SPAN_V[0]) * DENSITY) + 1;
const PATCH_COLS = rint((SPAN_U[1] - SPAN_U[0]) * DENSITY) + 1;
const uOf = (col: number) => SPAN_U[0] + col / DENSITY;
const vOf = (row: number) => SPAN_V[0] + row / DENSITY;
const colOf = (u: number) => rint((u - SPAN_U[0]) * DENSITY);
const rowOf = (v: number) => rint((v - SPAN_V[0]) * DENSITY);

/** The eye's grey patch of an RGBA texture (EyeFrame.patch: facemime.render.bilinear.sample_affine,
 * bilinear in fixed point (1/32 px, weights of 1/1024), the border replicated, then
 * cv2.COLOR_RGB2GRAY): PATCH_ROWS x PATCH_COLS, rows along v. */
function eyePatch(tex: Picture, frame: EyeFrame): Float64Array {
  const a = frame.axes;
  const start = frame.toImage(SPAN_U[0], SPAN_V[0]);
  // patch (col, row) -> texture (x, y): x = m0 col + m1 row + m2, y = m3 col + m4 row + m5
  const m = [a[0] / DENSITY, a[2] / DENSITY, start[0], a[1] / DENSITY, a[3] / DENSITY, start[1]];
  const { width: w, height: h, rgba } = tex;
  const out = new Float64Array(PATCH_ROWS * PATCH_COLS);
  const rgb = [0, 0, 0];
  for (let r = 0; r < PATCH_ROWS; r++) {
    const x0 = rint((m[1] * r + m[2]) * 1024) + 16, y0 = rint((m[4] * r + m[5]) * 1024) + 16;
    for (let c = 0; c < PATCH_COLS; c++) {
      const X = (x0 + rint(m[0] * c * 1024)) >> 5, Y = (y0 + rint(m[3] * c * 1024)) >> 5;
      const sx = X >> 5, sy = Y >> 5, fx = X & 31, fy = Y & 31;
      const xa = clampIndex(sx, w), xb = clampIndex(sx + 1, w), ya = clampIndex(sy, h), yb = clampIndex(sy + 1, h);
      const w00 = (32 - fx) * (32 - fy), w01 = fx * (32 - fy), w10 = (32 - fx) * fy, w11 = fx * fy;
      for (let k = 0; k < 3; k++) {
        const s = w00 * rgba[(ya * w + xa) * 4 + k] + w01 * rgba[(ya * w + xb) * 4 + k]
          + w10 * rgba[(yb * w + xa) * 4 + k] + w11 * rgba[(yb * w + xb) * 4 + k];
        rgb[k] = (s + 512) >> 10;
      }
      out[r * PATCH_COLS + c] = (rgb[0] * 4899 + rgb[1] * 9617 + rgb[2] * 1868 + 8192) >> 14;
    }
  }
  return out;
}

/** `i` moved to the vertex of the parabola through values at i - 1, i, i + 1 (track.eyes._peak). */
function peak(values: number[], i: number): number {
  if (i > 0 && i < values.length - 1) {
    const a = values[i - 1], b = values[i], c = values[i + 1];
    const d = a - 2 * b + c;
    if (d !== 0) return i + Math.min(Math.max((0.5 * (a - c)) / d, -0.5), 0.5);
  }
  return i;
}

/** The iris centre (u, v) in an eye's patch (track.eyes.find_iris): where a disc of the iris's
 * radius is darkest against the mean of a box on either side. */
function findIris(patch: Float64Array): [number, number] {
  const rows = PATCH_ROWS, cols = PATCH_COLS;
  const rad = IRIS_RADIUS * DENSITY;
  const kr = Math.ceil(rad);
  const taps: number[] = []; // dy, dx of the disc kernel (cv2.filter2D, BORDER_REPLICATE)
  for (let y = -kr; y <= kr; y++) for (let x = -kr; x <= kr; x++) if (x * x + y * y <= rad * rad) taps.push(y, x);
  const n = taps.length / 2;
  const inside = new Float64Array(rows * cols);
  for (let r = 0; r < rows; r++) {
    for (let c = 0; c < cols; c++) {
      let s = 0;
      for (let t = 0; t < taps.length; t += 2) {
        s += patch[clampIndex(r + taps[t], rows) * cols + clampIndex(c + taps[t + 1], cols)];
      }
      inside[r * cols + c] = s / n;
    }
  }
  const side = rint(0.6 * rad), tall = rint(1.2 * rad); // cv2.blur (side, tall), BORDER_REPLICATE
  const ax = side >> 1, ay = tall >> 1;
  const box = new Float64Array(rows * cols);
  for (let r = 0; r < rows; r++) {
    for (let c = 0; c < cols; c++) {
      let s = 0;
      for (let y = 0; y < tall; y++) {
        for (let x = 0; x < side; x++) s += patch[clampIndex(r + y - ay, rows) * cols + clampIndex(c + x - ax, cols)];
      }
      box[r * cols + c] = s / (side * tall);
    }
  }
  const shift = rint(rad + side / 2);
  const beside = new Float64Array(rows * cols);
  for (let r = 0; r < rows; r++) {
    const o = r * cols;
    for (let c = shift; c < cols - shift; c++) beside[o + c] = 0.5 * (box[o + c - shift] + box[o + c + shift]);
    for (let c = 0; c < shift; c++) beside[o + c] = beside[o + shift];
    for (let c = cols - shift; c < cols; c++) beside[o + c] = beside[o + cols - shift - 1];
  }
  const r0 = rowOf(IRIS_V[0]), r1 = rowOf(IRIS_V[1]), c0 = colOf(-IRIS_U), c1 = colOf(IRIS_U);
  const score = (r: number, c: number) => inside[r * cols + c] - 0.5 * beside[r * cols + c];
  let best = Infinity, br = r0, bc = c0;
  for (let r = r0; r <= r1; r++) {
    for (let c = c0; c <= c1; c++) {
      const s = score(r, c);
      if (s < best) { best = s; br = r; bc = c; }
    }
  }
  const across: number[] = [], down: number[] = [];
  for (let c = c0; c <= c1; c++) across.push(score(br, c));
  for (let r = r0; r <= r1; r++) down.push(score(r, bc));
  return [uOf(c0 + peak(across, bc - c0)), vOf(r0 + peak(down, br - r0))];
}

// ---- cv2.fillPoly(..., LINE_AA, shift) on an 8-bit single-channel image, as OpenCV draws it ----

/** One eye of the texture: its box, the box's pixels with the iris (`iris`) and with the iris
 * painted out (`clean`), RGB float; the iris disc's alpha and the opening's mask. */
class Eye {
  readonly frame: EyeFrame;
  /** The box on the texture, px: columns x0..x1 - 1, rows y0..y1 - 1. */
  readonly x0: number; readonly y0: number; readonly x1: number; readonly y1: number;
  readonly irisUv: [number, number];
  readonly radius: number;
  readonly disc: Float64Array;
  readonly opening: Float32Array;
  readonly iris: Float32Array;
  readonly clean: Float32Array;
  /** The key frame's box, RGBA as on the texture. */
  readonly key: Uint8Array;

  /** The eye of `tex` whose ring (8 points, (x, y) px pairs) is `ring`. */
  constructor(tex: Picture, ring: Float64Array) {
    const frame = EyeFrame.of(ring);
    this.frame = frame;
    const ew = frame.width;
    let lx = Infinity, ly = Infinity, hx = -Infinity, hy = -Infinity;
    for (const u of SPAN_U) {
      for (const v of SPAN_V) {
        const [x, y] = frame.toImage(u, v);
        lx = Math.min(lx, x); ly = Math.min(ly, y); hx = Math.max(hx, x); hy = Math.max(hy, y);
      }
    }
    const x0 = Math.max(Math.floor(lx), 0), y0 = Math.max(Math.floor(ly), 0);
    const x1 = Math.min(Math.ceil(hx) + 1, tex.width), y1 = Math.min(Math.ceil(hy) + 1, tex.height);
    this.x0 = x0; this.y0 = y0; this.x1 = x1; this.y1 = y1;
    const w = Math.max(x1 - x0, 0), h = Math.max(y1 - y0, 0), n = w * h;
    const region = new Uint8Array(n * 3);
    this.key = new Uint8Array(n * 4);
    for (let y = 0; y < h; y++) {
      const row = tex.rgba.subarray(((y0 + y) * tex.width + x0) * 4, ((y0 + y) * tex.width + x1) * 4);
      this.key.set(row, y * w * 4);
      for (let x = 0; x < w; x++) for (let c = 0; c < 3; c++) region[(y * w + x) * 3 + c] = row[x * 4 + c];
    }
    this.irisUv = findIris(eyePatch(tex, frame));
    const centre = frame.toImage(this.irisUv[0], this.irisUv[1]);
    const cx = centre[0] - x0, cy = centre[1] - y0;
    this.radius = IRIS_RADIUS * ew * IRIS_REACH;
    this.disc = new Float64Array(n);
    for (let y = 0; y < h; y++) {
      for (let x = 0; x < w; x++) {
        const dx = x - cx, dy = y - cy;
        this.disc[y * w + x] = Math.min(Math.max(this.radius + 0.5 - Math.sqrt(dx * dx + dy * dy), 0), 1);
      }
    }
    const mask = new Uint8Array(n);
    const pts: number[] = [];
    for (let k = 0; k < 8; k++) pts.push(rint((ring[2 * k] - x0) * 16), rint((ring[2 * k + 1] - y0) * 16));
    if (n) fillPolyAA({ img: mask, w, h, colour: [255] }, pts, 4);
    this.opening = new Float32Array(n);
    for (let k = 0; k < n; k++) this.opening[k] = Math.fround(mask[k] / 255);
    // only what the key frame's opening showed of the iris moves, not the lid's edge
    const inner = erodeEllipse(this.opening, w, h, 2 * Math.max(1, rint(LID_EDGE * ew)) + 1);
    const hole = new Uint8Array(n), inside = new Uint8Array(n);
    let nBeside = 0, nInside = 0;
    for (let k = 0; k < n; k++) {
      this.disc[k] *= inner[k];
      hole[k] = +(this.disc[k] > 0);
      inside[k] = +(inner[k] > 0.5);
      nInside += inside[k];
      nBeside += +(inside[k] && !hole[k]);
    }
    // the sclera: the brightest quarter of the opening's pixels beside the iris
    const pick = (k: number) => (nBeside ? inside[k] && !hole[k] : nInside ? inside[k] : 1);
    const grey: number[] = [];
    const chosen: number[] = [];
    for (let k = 0; k < n; k++) {
      if (!pick(k)) continue;
      chosen.push(k);
      grey.push(region[3 * k] * 0.299 + region[3 * k + 1] * 0.587 + region[3 * k + 2] * 0.114);
    }
    const sclera = [0, 0, 0];
    if (chosen.length) {
      const p75 = percentile(Float64Array.from(grey), 75);
      const bright = chosen.filter((_, m) => grey[m] >= p75);
      for (let c = 0; c < 3; c++) sclera[c] = rint(median(Float64Array.from(bright, (k) => region[3 * k + c])));
    }
    // the hole is filled from the sclera beside it and from sclera colour at and beyond the
    // lids, smoothed, and blended in over a few texels so that no outline shows
    const source = region.slice();
    for (let k = 0; k < n; k++) if (!inside[k]) for (let c = 0; c < 3; c++) source[3 * k + c] = sclera[c];
    const grown = new Uint8Array(n);
    for (let y = 0; y < h; y++) {
      for (let x = 0; x < w; x++) {
        let on = 0;
        for (let dy = -1; dy <= 1 && !on; dy++) {
          for (let dx = -1; dx <= 1; dx++) {
            const yy = y + dy, xx = x + dx;
            if (yy >= 0 && yy < h && xx >= 0 && xx < w && hole[yy * w + xx]) { on = 1; break; }
          }
        }
        grown[y * w + x] = on;
      }
    }
    if (n) inpaintTelea(source, grown, w, h, Math.max(2.0, this.radius / 3));
    // both blurs are needed only where the blend reaches: the hole and the blend's kernel about it
    const blendSigma = Math.max(1.0, this.radius / 8), reach = gaussianSize(blendSigma) >> 1;
    let hx0 = w, hy0 = h, hx1 = 0, hy1 = 0;
    for (let k = 0; k < n; k++) {
      if (!hole[k]) continue;
      const x = k % w, y = (k - x) / w;
      hx0 = Math.min(hx0, x); hx1 = Math.max(hx1, x + 1); hy0 = Math.min(hy0, y); hy1 = Math.max(hy1, y + 1);
    }
    const win = [Math.max(hx0 - reach, 0), Math.max(hy0 - reach, 0), Math.min(hx1 + reach, w), Math.min(hy1 + reach, h)];
    const fill = gaussianBlur(Float32Array.from(source), w, h, 3, Math.max(1.0, this.radius / 4), win);
    const blend = gaussianBlur(Float32Array.from(hole), w, h, 1, blendSigma, win);
    this.iris = Float32Array.from(region);
    this.clean = new Float32Array(n * 3);
    const fr = Math.fround;
    for (let k = 0; k < n; k++) {
      const b = Math.max(fr(blend[k] * this.opening[k]), hole[k]);
      for (let c = 0; c < 3; c++) {
        const i = this.iris[3 * k + c];
        this.clean[3 * k + c] = fr(i + fr(b * fr(fill[3 * k + c] - i)));
      }
    }
  }

  /** The warp's offset for an iris shift (u, v) eye widths: texture px (dx, dy) moved, quantised
   * to 1/32 px as facemime.render.bilinear.shift_offset does: each pixel samples the key frame at (x + ox / 32, y + oy / 32);
   * null when the shift is below PASTE_STILL. */
  offset(shift: [number, number]): [number, number] | null {
    const a = this.frame.axes;
    const dx = shift[0] * a[0] + shift[1] * a[2], dy = shift[0] * a[1] + shift[1] * a[3];
    if (Math.max(Math.abs(dx), Math.abs(dy)) < PASTE_STILL) return null;
    return [(rint(-Math.fround(dx) * 1024) + 16) >> 5, (rint(-Math.fround(dy) * 1024) + 16) >> 5];
  }

  /** Paints the eye into `out` (the texture's RGBA working copy, `width` px wide) with the warp
   * offset `off` (offset()), or as on the key frame when null. */
  paint(out: Uint8Array, width: number, off: [number, number] | null): void {
    const { x0, y0, x1, y1 } = this;
    const w = x1 - x0, h = y1 - y0;
    if (w <= 0 || h <= 0) return;
    if (!off) {
      for (let y = 0; y < h; y++) out.set(this.key.subarray(y * w * 4, (y + 1) * w * 4), ((y0 + y) * width + x0) * 4);
      return;
    }
    const sx = off[0] >> 5, sy = off[1] >> 5, fx = (off[0] & 31) / 32, fy = (off[1] & 31) / 32;
    const fr = Math.fround;
    const w00 = fr((1 - fx) * (1 - fy)), w01 = fr(fx * (1 - fy)), w10 = fr((1 - fx) * fy), w11 = fr(fx * fy);
    const { iris, clean, disc, opening } = this;
    for (let y = 0; y < h; y++) {
      const ya = y + sy, yb = ya + 1;
      const ra = clampIndex(ya, h) * w, rb = clampIndex(yb, h) * w;
      const inA = ya >= 0 && ya < h, inB = yb >= 0 && yb < h;
      for (let x = 0; x < w; x++) {
        const xa = x + sx, xb = xa + 1;
        const ca = clampIndex(xa, w), cb = clampIndex(xb, w);
        const inXa = xa >= 0 && xa < w, inXb = xb >= 0 && xb < w;
        // the disc: taps outside the box are 0 (BORDER_CONSTANT)
        const alpha = (w00 * (inA && inXa ? disc[ra + ca] : 0) + w01 * (inA && inXb ? disc[ra + cb] : 0)
          + w10 * (inB && inXa ? disc[rb + ca] : 0) + w11 * (inB && inXb ? disc[rb + cb] : 0)) * opening[y * w + x];
        const o = ((y0 + y) * width + x0 + x) * 4, k = (y * w + x) * 3;
        for (let c = 0; c < 3; c++) {
          // the iris: BORDER_REPLICATE
          const moved = fr(w00 * iris[(ra + ca) * 3 + c] + w01 * iris[(ra + cb) * 3 + c]
            + w10 * iris[(rb + ca) * 3 + c] + w11 * iris[(rb + cb) * 3 + c]);
          const v = clean[k + c] + alpha * fr(moved - clean[k + c]) + 0.5;
          out[o + c] = v <= 0 ? 0 : v >= 255 ? 255 : Math.floor(v);
        }
      }
    }
  }
}

/** Paints a look's irises on an actor's texture (facemime.animate.eyes.LookPainter.texture). */
export class LookPainter {
  private readonly eyes: (Eye | null)[];
  private readonly work: Picture;
  /** The eyes' warp offsets last painted (Eye.offset, 'still' as on the key frame); null before
   * the first call. */
  private last: string | null = null;

  /** Finds each eye's iris on `texture` (RGBA) at `model`'s eye rings (groups eye_right and
   * eye_left, 8 vertices each) and prepares the eye with the iris painted out. An eye whose group
   * is missing or malformed is left as on the texture. */
  constructor(texture: Picture, model: Model) {
    this.eyes = EYES.map((name) => {
      const ring = model.groups[name];
      if (!ring || ring.length !== 8) return null;
      const px = new Float64Array(16);
      ring.forEach((v, k) => {
        px[2 * k] = model.uv[2 * v] * texture.width - 0.5;
        px[2 * k + 1] = model.uv[2 * v + 1] * texture.height - 0.5;
      });
      return new Eye(texture, px);
    });
    this.work = { width: texture.width, height: texture.height, rgba: texture.rgba.slice() };
  }

  /** The texture with the irises shifted by `iris` ([[u, v] of the subject's right eye (group
   * eye_right), [u, v] of the left eye (eye_left)], eye widths), or null when it is the same as
   * the last returned one (so the caller need not re-upload; the first call always returns it).
   * The returned Picture is a working copy reused between calls. */
  texture(iris: [number, number][]): Picture | null {
    const offsets = this.eyes.map((eye, k) => eye?.offset(iris[k] ?? [0, 0]) ?? null);
    const key = offsets.map((o) => (o ? `${o[0]},${o[1]}` : 'still')).join(';');
    if (key === this.last) return null;
    // each eye's box is painted whole, in order: the rest stays the actor's texture
    this.eyes.forEach((eye, k) => eye?.paint(this.work.rgba, this.work.width, offsets[k]));
    this.last = key;
    return this.work;
  }
}
