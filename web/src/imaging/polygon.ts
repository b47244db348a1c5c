/**
 * OpenCV's anti-aliased drawing (cv2.fillPoly and cv2.line with LINE_AA and sub-pixel shift bits),
 * in OpenCV's fixed-point arithmetic, on an 8-bit image of 1 or 3 interleaved channels (row-major
 * from the top-left pixel; pixel centres on integer coordinates). The same arithmetic in OpenCV
 * 4.9 to 5.1.
 */

const XY_SHIFT = 16, XY_ONE = 1 << XY_SHIFT;
const SLOPE_CORR = [181, 181, 181, 182, 182, 183, 184, 185, 187, 188, 190, 192, 194, 196, 198, 201,
  203, 206, 209, 211, 214, 218, 221, 224, 227, 231, 235, 238, 242, 246, 250, 254];
const FILTER = [168, 177, 185, 194, 202, 210, 218, 224, 231, 236, 241, 246, 249, 252, 254, 254,
  254, 254, 252, 249, 246, 241, 236, 231, 224, 218, 210, 202, 194, 185, 177, 168,
  158, 149, 140, 131, 122, 114, 105, 97, 89, 82, 75, 68, 62, 56, 50, 45,
  40, 36, 32, 28, 25, 22, 19, 16, 14, 12, 11, 9, 8, 7, 5, 5];
/** Arithmetic right shift of an integer beyond 32 bits. */
const sar = (v: number, s: number) => Math.floor(v / 2 ** s);

/** OpenCV's clipLine on a size (fixed point); false when the line is outside. */
function clipLine(width: number, height: number, p: number[]): boolean {
  const right = width - 1, bottom = height - 1;
  if (width <= 0 || height <= 0) return false;
  let [x1, y1, x2, y2] = p;
  let c1 = +(x1 < 0) + +(x1 > right) * 2 + +(y1 < 0) * 4 + +(y1 > bottom) * 8;
  let c2 = +(x2 < 0) + +(x2 > right) * 2 + +(y2 < 0) * 4 + +(y2 > bottom) * 8;
  if ((c1 & c2) === 0 && (c1 | c2) !== 0) {
    if (c1 & 12) {
      const a = c1 < 8 ? 0 : bottom;
      x1 += Math.trunc(((a - y1) * (x2 - x1)) / (y2 - y1));
      y1 = a;
      c1 = +(x1 < 0) + +(x1 > right) * 2;
    }
    if (c2 & 12) {
      const a = c2 < 8 ? 0 : bottom;
      x2 += Math.trunc(((a - y2) * (x2 - x1)) / (y2 - y1));
      y2 = a;
      c2 = +(x2 < 0) + +(x2 > right) * 2;
    }
    if ((c1 & c2) === 0 && (c1 | c2) !== 0) {
      if (c1) {
        const a = c1 === 1 ? 0 : right;
        y1 += Math.trunc(((a - x1) * (y2 - y1)) / (x2 - x1));
        x1 = a;
        c1 = 0;
      }
      if (c2) {
        const a = c2 === 1 ? 0 : right;
        y2 += Math.trunc(((a - x2) * (y2 - y1)) / (x2 - x1));
        x2 = a;
        c2 = 0;
      }
    }
  }
  p[0] = x1; p[1] = y1; p[2] = x2; p[3] = y2;
  return (c1 | c2) === 0;
}

/** An 8-bit image: `w` x `h` pixels of `colour.length` interleaved channels, drawn in `colour`. */
export interface Canvas { img: Uint8Array; w: number; h: number; colour: readonly number[] }

/** OpenCV's LineAA on `cv`; points (x, y) in 16.16 fixed point. */
function lineAA(cv: Canvas, ax0: number, ay0: number, ax1: number, ay1: number): void {
  const { img, w, h, colour } = cv;
  const ch = colour.length;
  const p = [ax0 - 2 * XY_ONE, ay0 - 2 * XY_ONE, ax1 - 2 * XY_ONE, ay1 - 2 * XY_ONE];
  if (!clipLine((w - 5) * XY_ONE + 1, (h - 5) * XY_ONE + 1, p)) return;
  let [x1, y1, x2, y2] = p;
  let dx = x2 - x1, dy = y2 - y1;
  const ax = Math.abs(dx), ay = Math.abs(dy);
  let xStep: number, yStep: number, ecount: number, slope: number, i: number, j: number;
  const horizontal = ax > ay;
  if (horizontal) {
    if (dx < 0) { dy = -dy; [x1, x2] = [x2, x1]; [y1, y2] = [y2, y1]; }
    xStep = XY_ONE;
    yStep = Math.trunc((dy * XY_ONE) / (ax | 1));
    x2 += XY_ONE;
    ecount = sar(x2, XY_SHIFT) - sar(x1, XY_SHIFT);
    j = -(x1 - sar(x1, XY_SHIFT) * XY_ONE);
    y1 += sar(yStep * j, XY_SHIFT) + (XY_ONE >> 1);
    slope = sar(yStep, XY_SHIFT - 5) & 0x3f;
    slope ^= yStep < 0 ? 0x3f : 0;
    i = sar(x1, XY_SHIFT - 7) & 0x78;
    j = sar(x2, XY_SHIFT - 7) & 0x78;
  } else {
    if (dy < 0) { dx = -dx; [x1, x2] = [x2, x1]; [y1, y2] = [y2, y1]; }
    xStep = Math.trunc((dx * XY_ONE) / (ay | 1));
    yStep = XY_ONE;
    y2 += XY_ONE;
    ecount = sar(y2, XY_SHIFT) - sar(y1, XY_SHIFT);
    j = -(y1 - sar(y1, XY_SHIFT) * XY_ONE);
    x1 += sar(xStep * j, XY_SHIFT) + (XY_ONE >> 1);
    slope = sar(xStep, XY_SHIFT - 5) & 0x3f;
    slope ^= xStep < 0 ? 0x3f : 0;
    i = sar(y1, XY_SHIFT - 7) & 0x78;
    j = sar(y2, XY_SHIFT - 7) & 0x78;
  }
  slope = slope & 0x20 ? 0x100 : SLOPE_CORR[slope];
  const ep = new Array<number>(9);
  {
    const t0 = slope << 7, t1 = ((0x78 - i) | 4) * slope, t2 = (j | 4) * slope;
    ep[0] = 0;
    ep[8] = slope;
    ep[1] = ep[3] = ((((((j - i) & 0x78) | 4) * slope) >> 8) & 0x1ff);
    ep[2] = (t1 >> 8) & 0x1ff;
    ep[4] = (((((j - i) + 0x80) | 4) * slope) >> 8) & 0x1ff;
    ep[5] = ((t1 + t0) >> 8) & 0x1ff;
    ep[6] = (t2 >> 8) & 0x1ff;
    ep[7] = ((t2 + t0) >> 8) & 0x1ff;
  }
  const put = (at: number, a: number) => {
    for (let c = 0; c < ch; c++) {
      for (let n = 0; n < 2; n++) img[at * ch + c] += ((colour[c] - img[at * ch + c]) * a + 127) >> 8;
    }
  };
  const index = (n: number) => (n >= 2 ? 2 : n);
  let scount = 0;
  // the image seen by the drawing starts 2 px in (the line was moved by -2 px)
  if (horizontal) {
    let col = sar(x1, XY_SHIFT) + 2;
    while (ecount >= 0) {
      const row = sar(y1, XY_SHIFT) - 1 + 2;
      const corr = ep[index(scount) * 3 + index(ecount)];
      const dist = sar(y1, XY_SHIFT - 5) & 31;
      put(row * w + col, ((corr * FILTER[dist + 32]) >> 8) & 0xff);
      put((row + 1) * w + col, ((corr * FILTER[dist]) >> 8) & 0xff);
      put((row + 2) * w + col, ((corr * FILTER[63 - dist]) >> 8) & 0xff);
      y1 += yStep;
      col++;
      scount++;
      ecount--;
    }
  } else {
    let row = sar(y1, XY_SHIFT) + 2;
    while (ecount >= 0) {
      const col = sar(x1, XY_SHIFT) - 1 + 2;
      const corr = ep[index(scount) * 3 + index(ecount)];
      const dist = sar(x1, XY_SHIFT - 5) & 31;
      put(row * w + col, ((corr * FILTER[dist + 32]) >> 8) & 0xff);
      put(row * w + col + 1, ((corr * FILTER[dist]) >> 8) & 0xff);
      put(row * w + col + 2, ((corr * FILTER[63 - dist]) >> 8) & 0xff);
      x1 += xStep;
      row++;
      scount++;
      ecount--;
    }
  }
}

interface PolyEdge { y0: number; y1: number; x: number; dx: number; next: PolyEdge | null }

/** cv2.line(img, a, b, colour, 1, cv2.LINE_AA, shift) on `cv`: `a`, `b` (x, y), integers in
 * units of 2^-shift px. */
export function lineAAShifted(cv: Canvas, a: number[], b: number[], shift: number): void {
  const s = 2 ** (XY_SHIFT - shift);
  lineAA(cv, a[0] * s, a[1] * s, b[0] * s, b[1] * s);
}

/** cv2.fillPoly(img, [pts], colour, cv2.LINE_AA, shift) on `cv`: `pts` (x, y) pairs, integers in
 * units of 2^-shift px (OpenCV's CollectPolyEdges and FillEdgeCollection). */
export function fillPolyAA(cv: Canvas, pts: number[], shift: number): void {
  const { img, w, h, colour } = cv;
  const ch = colour.length;
  const count = pts.length / 2;
  const delta = (1 << shift) >> 1;
  const edges: PolyEdge[] = [];
  let p0x = pts[2 * count - 2] * 2 ** (XY_SHIFT - shift), p0y = sar(pts[2 * count - 1] + delta, shift);
  for (let i = 0; i < count; i++) {
    const p1x = pts[2 * i] * 2 ** (XY_SHIFT - shift), p1y = sar(pts[2 * i + 1] + delta, shift);
    lineAA(cv, p0x, p0y * XY_ONE, p1x, p1y * XY_ONE);
    if (p0y !== p1y) {
      const up = p0y < p1y;
      edges.push({ y0: up ? p0y : p1y, y1: up ? p1y : p0y, x: up ? p0x : p1x,
        dx: Math.trunc((p1x - p0x) / (p1y - p0y)), next: null });
    }
    p0x = p1x;
    p0y = p1y;
  }
  const total = edges.length;
  if (total < 2) return;
  let yMax = -Infinity, yMin = Infinity, xMax = -Infinity, xMin = Infinity;
  for (const e1 of edges) {
    const xEnd = e1.x + (e1.y1 - e1.y0) * e1.dx;
    yMin = Math.min(yMin, e1.y0);
    yMax = Math.max(yMax, e1.y1);
    xMin = Math.min(xMin, e1.x, xEnd);
    xMax = Math.max(xMax, e1.x, xEnd);
  }
  if (yMax < 0 || yMin >= h || xMax < 0 || xMin >= w * XY_ONE) return;
  edges.sort((a, b) => (a.y0 !== b.y0 ? a.y0 - b.y0 : a.x !== b.x ? a.x - b.x : a.dx - b.dx));
  edges.push({ y0: 2 ** 31 - 1, y1: 0, x: 0, dx: 0, next: null });
  const tmp: PolyEdge = { y0: 2 ** 31 - 1, y1: 0, x: 0, dx: 0, next: null };
  let i = 0;
  let e = edges[0];
  yMax = Math.min(yMax, h);
  for (let y = e.y0; y < yMax; y++) {
    let prelast: PolyEdge = tmp, last = tmp.next, keep: PolyEdge | null;
    let sortFlag = false, draw = false;
    const clip = y < 0;
    while (last || e.y0 === y) {
      if (last && last.y1 === y) { // the edge ends
        prelast.next = last.next;
        last = last.next;
        continue;
      }
      keep = prelast;
      if (last && (e.y0 > y || last.x < e.x)) {
        prelast = last;
        last = last.next;
      } else if (i < total) { // an edge starts
        prelast.next = e;
        e.next = last;
        prelast = e;
        e = edges[++i];
      } else break;
      if (draw) {
        if (!clip) {
          let x1: number, x2: number;
          if (keep.x > prelast.x) {
            x1 = sar(prelast.x + XY_ONE - 1, XY_SHIFT);
            x2 = sar(keep.x, XY_SHIFT);
          } else {
            x1 = sar(keep.x + XY_ONE - 1, XY_SHIFT);
            x2 = sar(prelast.x, XY_SHIFT);
          }
          if (x1 < w && x2 >= 0) {
            x1 = Math.max(x1, 0);
            x2 = Math.min(x2, w - 1);
            for (let x = x1; x <= x2; x++) for (let c = 0; c < ch; c++) img[(y * w + x) * ch + c] = colour[c];
          }
        }
        keep.x += keep.dx;
        prelast.x += prelast.dx;
      }
      draw = !draw;
    }
    // bubble sort of the active edges by x
    keep = null;
    do {
      prelast = tmp;
      last = tmp.next;
      while (last !== keep && last !== null && last.next !== null) {
        const te: PolyEdge = last.next;
        if (last.x > te.x) {
          prelast.next = te;
          last.next = te.next;
          te.next = last;
          prelast = te;
          sortFlag = true;
        } else {
          prelast = last;
          last = te;
        }
      }
      keep = prelast;
    } while (sortFlag && keep !== tmp.next && keep !== tmp);
  }
}

// ---- filters ----
