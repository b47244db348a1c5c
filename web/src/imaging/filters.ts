/**
 * Image filters as OpenCV and numpy compute them (their rounding, kernels and borders), on plain
 * arrays, for the eye painter: rounding, border reflection, the elliptic erosion, the Gaussian blur,
 * percentiles. Images are row-major from the top-left pixel, channels interleaved.
 */

/** Rounds half to even (numpy's round, C's lrint, OpenCV's cvRound). */
export function rint(x: number): number {
  const f = Math.floor(x), d = x - f;
  if (d > 0.5) return f + 1;
  if (d < 0.5) return f;
  return f % 2 === 0 ? f : f + 1;
}

/** OpenCV's borderInterpolate for BORDER_REFLECT_101 (delta 1). */
function reflect101(p: number, len: number): number {
  if (len === 1) return 0;
  while (p < 0 || p >= len) p = p < 0 ? -p : 2 * len - 2 - p;
  return p;
}

/** ``p`` clamped into 0 .. len - 1 (BORDER_REPLICATE). */
export const clampIndex = (p: number, len: number) => (p < 0 ? 0 : p >= len ? len - 1 : p);

/** cv2.erode with cv2.getStructuringElement(MORPH_ELLIPSE, (k, k)) (k odd); the border ignored. */
export function erodeEllipse(src: Float32Array, w: number, h: number, k: number): Float32Array {
  const r = k >> 1, c = k >> 1;
  const half: number[] = []; // per kernel row, the half-width of its run (-1: empty)
  for (let i = 0; i < k; i++) {
    const dy = i - r;
    const dx = rint(c * Math.sqrt((r * r - dy * dy) / (r * r)));
    const j1 = Math.max(c - dx, 0), j2 = Math.min(c + dx + 1, k);
    half.push(j2 > j1 ? Math.min(c - j1, j2 - 1 - c) : -1);
  }
  // runs[m]: the minimum over x - m .. x + m of each row, built one step at a time
  const runs: Float32Array[] = [src];
  const most = Math.max(...half);
  for (let m = 1; m <= most; m++) {
    const prev = runs[m - 1], next = new Float32Array(w * h);
    for (let y = 0; y < h; y++) {
      const o = y * w;
      for (let x = 0; x < w; x++) {
        let v = prev[o + x];
        if (x - m >= 0 && src[o + x - m] < v) v = src[o + x - m];
        if (x + m < w && src[o + x + m] < v) v = src[o + x + m];
        next[o + x] = v;
      }
    }
    runs.push(next);
  }
  const out = new Float32Array(w * h).fill(Infinity);
  for (let i = 0; i < k; i++) {
    if (half[i] < 0) continue;
    const run = runs[half[i]], dy = i - r;
    for (let y = Math.max(0, -dy); y < Math.min(h, h - dy); y++) {
      const o = y * w, q = (y + dy) * w;
      for (let x = 0; x < w; x++) if (run[q + x] < out[o + x]) out[o + x] = run[q + x];
    }
  }
  return out;
}

/** The size of the kernel cv2.GaussianBlur picks for a float image and `sigma`: round(8 sigma + 1) | 1. */
export const gaussianSize = (sigma: number) => rint(sigma * 4 * 2 + 1) | 1;

/** cv2.GaussianBlur(src, (0, 0), sigma) of a w x h float image of `ch` interleaved channels
 * (BORDER_REFLECT_101), computed only in the window columns x0..x1 - 1, rows y0..y1 - 1 (0
 * elsewhere). */
export function gaussianBlur(src: Float32Array, w: number, h: number, ch: number, sigma: number,
  [x0, y0, x1, y1]: number[]): Float32Array {
  const n = gaussianSize(sigma), half = n >> 1;
  const kernel = new Float64Array(n);
  let sum = 0;
  for (let i = 0; i < n; i++) {
    const x = i - (n - 1) * 0.5;
    kernel[i] = Math.exp((-0.5 / (sigma * sigma)) * x * x);
    sum += kernel[i];
  }
  for (let i = 0; i < n; i++) kernel[i] = Math.fround(kernel[i] / sum);
  const out = new Float32Array(w * h * ch);
  if (x1 <= x0 || y1 <= y0) return out;
  // the rows filtered along x (the window's columns), for the rows the window's column filter reads
  const span = (x1 - x0) * ch;
  const rows = new Map<number, Float32Array>();
  const pad = new Float32Array((x1 - x0 + 2 * half) * ch), acc = new Float64Array(span);
  const filtered = (y: number): Float32Array => {
    let row = rows.get(y);
    if (row) return row;
    for (let x = 0; x < x1 - x0 + 2 * half; x++) {
      const from = (y * w + reflect101(x0 + x - half, w)) * ch;
      for (let c = 0; c < ch; c++) pad[x * ch + c] = src[from + c];
    }
    const along = new Float64Array(span);
    for (let i = 0; i < n; i++) {
      const kv = kernel[i], o = i * ch;
      for (let q = 0; q < span; q++) along[q] += kv * pad[o + q];
    }
    row = Float32Array.from(along);
    rows.set(y, row);
    return row;
  };
  for (let y = y0; y < y1; y++) {
    acc.fill(0);
    for (let i = 0; i < n; i++) {
      const kv = kernel[i], row = filtered(reflect101(y + i - half, h));
      for (let q = 0; q < span; q++) acc[q] += kv * row[q];
    }
    out.set(acc, (y * w + x0) * ch);
  }
  return out;
}

/** The `q`-th percentile of `a` (numpy's default, linear interpolation); sorts `a`. */
export function percentile(a: Float64Array, q: number): number {
  a.sort();
  const at = (q / 100) * (a.length - 1), lo = Math.floor(at), t = at - lo;
  if (lo + 1 >= a.length) return a[a.length - 1];
  const d = a[lo + 1] - a[lo];
  return t >= 0.5 ? a[lo + 1] - d * (1 - t) : a[lo] + d * t;
}

/** numpy's median of `a`; sorts `a`. */
export function median(a: Float64Array): number {
  a.sort();
  const m = a.length >> 1;
  return a.length % 2 ? a[m] : (a[m - 1] + a[m]) / 2;
}

// ---- cv2.inpaint(src, mask, range, cv2.INPAINT_TELEA) on 8-bit RGB ----
