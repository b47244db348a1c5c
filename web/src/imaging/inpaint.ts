/**
 * OpenCV's Telea inpainting (cv2.inpaint with INPAINT_TELEA): fast marching from the hole's edge,
 * in OpenCV's order, on an 8-bit RGB image (row-major from the top-left pixel).
 */
import { rint } from './filters';

const KNOWN = 0, BAND = 1, INSIDE = 2, CHANGE = 3;

/** OpenCV's CvPriorityQueueFloat: the smallest T first, first in first out among equal T; holds
 * at most `capacity` elements. */
class MarchQueue {
  private readonly t: Float64Array;
  private readonly seq: Float64Array;
  private readonly at: Int32Array;
  size = 0;
  private count = 0;

  constructor(capacity: number) {
    this.t = new Float64Array(capacity);
    this.seq = new Float64Array(capacity);
    this.at = new Int32Array(capacity);
  }

  private less(a: number, b: number): boolean {
    return this.t[a] < this.t[b] || (this.t[a] === this.t[b] && this.seq[a] < this.seq[b]);
  }

  private swap(a: number, b: number): void {
    const { t, seq, at } = this;
    const tt = t[a], ts = seq[a], ta = at[a];
    t[a] = t[b]; seq[a] = seq[b]; at[a] = at[b];
    t[b] = tt; seq[b] = ts; at[b] = ta;
  }

  push(index: number, t: number): void {
    let n = this.size++;
    this.t[n] = t;
    this.seq[n] = this.count++;
    this.at[n] = index;
    while (n > 0) {
      const p = (n - 1) >> 1;
      if (!this.less(n, p)) break;
      this.swap(n, p);
      n = p;
    }
  }

  /** The index (row * cols + col) of the element popped. */
  pop(): number {
    const top = this.at[0];
    const last = --this.size;
    this.t[0] = this.t[last]; this.seq[0] = this.seq[last]; this.at[0] = this.at[last];
    let n = 0;
    for (;;) {
      const l = 2 * n + 1, r = l + 1;
      let m = n;
      if (l < last && this.less(l, m)) m = l;
      if (r < last && this.less(r, m)) m = r;
      if (m === n) break;
      this.swap(n, m);
      n = m;
    }
    return top;
  }
}

/** OpenCV's FastMarching_solve on flags `f` and times `t` (cols `ec`). */
function solve(i1: number, j1: number, i2: number, j2: number, f: Uint8Array, t: Float32Array, ec: number): number {
  const a11 = t[i1 * ec + j1], a22 = t[i2 * ec + j2], m12 = Math.min(a11, a22);
  let sol: number;
  if (f[i1 * ec + j1] !== INSIDE) {
    if (f[i2 * ec + j2] !== INSIDE) {
      sol = Math.abs(a11 - a22) >= 1.0 ? 1 + m12 : (a11 + a22 + Math.sqrt(2 - (a11 - a22) * (a11 - a22))) * 0.5;
    } else sol = 1 + a11;
  } else if (f[i2 * ec + j2] !== INSIDE) sol = 1 + a22;
  else sol = 1 + m12;
  return Math.fround(sol);
}

function solve4(i: number, j: number, f: Uint8Array, t: Float32Array, ec: number): number {
  return Math.min(solve(i - 1, j, i, j - 1, f, t, ec), solve(i + 1, j, i, j - 1, f, t, ec),
    solve(i - 1, j, i, j + 1, f, t, ec), solve(i + 1, j, i, j + 1, f, t, ec));
}

/** Dilation of an er x ec 8-bit image by a (2 r + 1) square, or (`cross`) by a 3 x 3 cross. */
function dilate(src: Uint8Array, er: number, ec: number, r: number, cross = false): Uint8Array {
  const at = (i: number, j: number) => (i >= 0 && i < er && j >= 0 && j < ec ? src[i * ec + j] : 0);
  const out = new Uint8Array(er * ec);
  if (cross) {
    for (let i = 0; i < er; i++) {
      for (let j = 0; j < ec; j++) out[i * ec + j] = Math.max(at(i, j), at(i - 1, j), at(i + 1, j), at(i, j - 1), at(i, j + 1));
    }
    return out;
  }
  const rows = new Uint8Array(er * ec);
  for (let i = 0; i < er; i++) {
    for (let j = 0; j < ec; j++) {
      let m = 0;
      for (let d = Math.max(0, j - r); d <= Math.min(ec - 1, j + r); d++) if (src[i * ec + d] > m) m = src[i * ec + d];
      rows[i * ec + j] = m;
    }
  }
  for (let i = 0; i < er; i++) {
    for (let j = 0; j < ec; j++) {
      let m = 0;
      for (let d = Math.max(0, i - r); d <= Math.min(er - 1, i + r); d++) if (rows[d * ec + j] > m) m = rows[d * ec + j];
      out[i * ec + j] = m;
    }
  }
  return out;
}

function zeroBorder(a: Uint8Array, er: number, ec: number): void {
  a.fill(0, 0, ec);
  a.fill(0, (er - 1) * ec, er * ec);
  for (let i = 1; i < er - 1; i++) a[i * ec] = a[i * ec + ec - 1] = 0;
}

/** cv2.inpaint(img, mask, inpaintRange, cv2.INPAINT_TELEA) in place: `img` w x h RGB 8-bit,
 * `mask` w x h, non-zero where to fill. */
export function inpaintTelea(img: Uint8Array, mask: Uint8Array, w: number, h: number, inpaintRange: number): void {
  const range = Math.min(Math.max(rint(inpaintRange), 1), 100);
  const ec = w + 2, er = h + 2;
  const f = new Uint8Array(er * ec); // the "mask" matrix: INSIDE where to fill, 1 px border
  for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) if (mask[y * w + x]) f[(y + 1) * ec + x + 1] = INSIDE;
  zeroBorder(f, er, ec);
  const t = new Float32Array(er * ec).fill(1.0e6);
  const band = dilate(f, er, ec, 1, true);
  for (let k = 0; k < band.length; k++) band[k] = Math.max(band[k] - f[k], 0);
  zeroBorder(band, er, ec);
  const heap = new MarchQueue(er * ec);
  for (let k = 0; k < band.length; k++) if (band[k]) { heap.push(k, 0); t[k] = 0; }
  if (heap.size === 0) return;
  // the distances outside the hole, negative, within the range (icvCalcFMM with negate)
  const out = dilate(f, er, ec, range);
  for (let k = 0; k < out.length; k++) out[k] = Math.max(out[k] - f[k], 0);
  const outer = new MarchQueue(er * ec);
  for (let k = 0; k < band.length; k++) if (band[k]) outer.push(k, 0);
  for (let k = 0; k < out.length; k++) out[k] = Math.max(out[k] - band[k], 0);
  zeroBorder(out, er, ec);
  while (outer.size) {
    const at = outer.pop(), ii = Math.floor(at / ec), jj = at - ii * ec;
    out[at] = CHANGE;
    for (let q = 0; q < 4; q++) {
      const i = q === 0 ? ii - 1 : q === 2 ? ii + 1 : ii, j = q === 1 ? jj - 1 : q === 3 ? jj + 1 : jj;
      if (i <= 0 || j <= 0 || i >= er || j >= ec) continue;
      if (out[i * ec + j] === INSIDE) {
        const dist = solve4(i, j, out, t, ec);
        t[i * ec + j] = dist;
        out[i * ec + j] = BAND;
        outer.push(i * ec + j, dist);
      }
    }
  }
  for (let k = 0; k < out.length; k++) if (out[k] === CHANGE) t[k] = -t[k];
  // Telea's fill, marching inwards (icvTeleaInpaintFMM, 3 channels)
  const fr = Math.fround;
  // the neighbours within the range: per row offset, the half-width; 1 / |r|^3 per offset
  const side = 2 * range + 1;
  const reach = new Int32Array(side), dst = new Float32Array(side * side);
  for (let dk = -range; dk <= range; dk++) {
    while ((reach[dk + range] + 1) ** 2 + dk * dk <= range * range) reach[dk + range]++;
    for (let dl = -range; dl <= range; dl++) {
      const len = dk * dk + dl * dl;
      dst[(dk + range) * side + dl + range] = fr(1 / (len * Math.sqrt(len)));
    }
  }
  const ia = new Float64Array(3), jx = new Float64Array(3), jy = new Float64Array(3);
  const rowStep = w * 3;
  while (heap.size) {
    const at = heap.pop(), ii = Math.floor(at / ec), jj = at - ii * ec;
    f[at] = KNOWN;
    for (let q = 0; q < 4; q++) {
      const i = q === 0 ? ii - 1 : q === 2 ? ii + 1 : ii, j = q === 1 ? jj - 1 : q === 3 ? jj + 1 : jj;
      if (i <= 1 || j <= 1 || i > er - 1 || j > ec - 1) continue;
      const ij = i * ec + j;
      if (f[ij] !== INSIDE) continue;
      const dist = solve4(i, j, f, t, ec);
      t[ij] = dist;
      let gtx: number, gty: number;
      if (f[ij + 1] !== INSIDE) gtx = f[ij - 1] !== INSIDE ? fr(fr(t[ij + 1] - t[ij - 1]) * 0.5) : fr(t[ij + 1] - t[ij]);
      else gtx = f[ij - 1] !== INSIDE ? fr(t[ij] - t[ij - 1]) : 0;
      if (f[ij + ec] !== INSIDE) gty = f[ij - ec] !== INSIDE ? fr(fr(t[ij + ec] - t[ij - ec]) * 0.5) : fr(t[ij + ec] - t[ij]);
      else gty = f[ij - ec] !== INSIDE ? fr(t[ij] - t[ij - ec]) : 0;
      ia.fill(0); jx.fill(0); jy.fill(0);
      let s = fr(1.0e-20);
      const tij = t[ij];
      for (let k = Math.max(i - range, 1); k <= Math.min(i + range, er - 2); k++) {
        const ry = i - k, half = reach[k - i + range], drow = (k - i + range) * side + range - j;
        const km = k - 1 + +(k === 1), kp = k - 1 - +(k === er - 2), rowM = km * rowStep;
        const fry = fr(ry * gty);
        for (let l = Math.max(j - half, 1); l <= Math.min(j + half, ec - 2); l++) {
          const kl = k * ec + l;
          if (f[kl] === INSIDE) continue; // (i, j) itself among them
          const rx = j - l;
          const lev = fr(1 / fr(1 + Math.abs(fr(t[kl] - tij))));
          let dir = fr(fr(rx * gtx) + fry);
          if (Math.abs(dir) <= 0.01) dir = fr(0.000001);
          const wt = Math.abs(fr(fr(dst[drow + l] * lev) * dir));
          const lm = l - 1 + +(l === 1), lp = l - 1 - +(l === ec - 2);
          const right = f[kl + 1] !== INSIDE, left = f[kl - 1] !== INSIDE;
          const below = f[kl + ec] !== INSIDE, above = f[kl - ec] !== INSIDE;
          const here = (km * w + lm) * 3;
          for (let c = 0; c < 3; c++) {
            let gx: number, gy: number;
            if (right) {
              gx = left ? (img[rowM + (lp + 1) * 3 + c] - img[here - 3 + c]) * 2 : img[rowM + (lp + 1) * 3 + c] - img[here + c];
            } else gx = left ? img[rowM + lp * 3 + c] - img[here - 3 + c] : 0;
            if (below) {
              gy = above ? (img[(kp + 1) * rowStep + lm * 3 + c] - img[here - rowStep + c]) * 2
                : img[(kp + 1) * rowStep + lm * 3 + c] - img[here + c];
            } else gy = above ? img[kp * rowStep + lm * 3 + c] - img[here - rowStep + c] : 0;
            ia[c] = fr(ia[c] + fr(wt * img[here + c]));
            jx[c] = fr(jx[c] - fr(wt * fr(gx * rx)));
            jy[c] = fr(jy[c] - fr(wt * fr(gy * ry)));
          }
          s = fr(s + wt);
        }
      }
      for (let c = 0; c < 3; c++) {
        const norm = fr(fr(Math.sqrt(fr(fr(jx[c] * jx[c]) + fr(jy[c] * jy[c])))) + fr(1.0e-20));
        const sat = fr(fr(fr(ia[c] / s) + fr(fr(jx[c] + jy[c]) / norm)) + 0.5);
        img[((i - 1) * w + j - 1) * 3 + c] = Math.min(Math.max(rint(sat), 0), 255);
      }
      f[ij] = BAND;
      heap.push(ij, dist);
    }
  }
}

// ---- the eyes ----
