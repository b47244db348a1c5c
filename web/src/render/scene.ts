/**
 * The scene around the face (facemime.render.scene.SceneMesh): the actor's key frame as a 2-D
 * mesh that the face outline's motion warps. Vertices: the anchors (the model's face outline,
 * projected each frame), two rings around it following a share of the outline's least-squares
 * similarity motion, and the picture's border, which never moves.
 *
 * Pixels: x right, y down, (0, 0) the centre of the top-left pixel; the border lies on the
 * picture's outer pixel edges (-0.5 and W - 0.5).
 */
import Delaunator from 'delaunator';
import { BORDER_STEPS, EDGE_MARGIN, RINGS } from '../shared_constants';

export class SceneMesh {
  /** Every vertex in the key frame, N*2 px (the texture coordinates, once normalised). */
  readonly rest: Float64Array;
  readonly follow: Float64Array;
  readonly triangles: Uint32Array;

  constructor(readonly width: number, readonly height: number, readonly anchors: number[], outline: Float64Array) {
    const a = outline.length / 2;
    let cx = 0, cy = 0;
    for (let i = 0; i < a; i++) { cx += outline[2 * i]; cy += outline[2 * i + 1]; }
    cx /= a; cy /= a;
    const margin = EDGE_MARGIN * Math.min(width, height);
    const pts: number[] = Array.from(outline);
    const follow: number[] = new Array<number>(a).fill(1);
    for (const [reach, share] of RINGS) {
      for (let i = 0; i < a; i++) {
        const x = cx + reach * (outline[2 * i] - cx), y = cy + reach * (outline[2 * i + 1] - cy);
        if (x > -0.5 + margin && x < width - 0.5 - margin && y > -0.5 + margin && y < height - 0.5 - margin) {
          pts.push(x, y);
          follow.push(share);
        }
      }
    }
    const lo = [-0.5, -0.5], hi = [width - 0.5, height - 0.5];
    const corners = [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
    for (let c = 0; c < 4; c++) {
      const p = corners[c], q = corners[(c + 1) % 4];
      for (let s = 0; s < BORDER_STEPS - 1; s++) {
        const t = s / (BORDER_STEPS - 1);
        pts.push(p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]));
        follow.push(0);
      }
    }
    this.rest = Float64Array.from(pts);
    this.follow = Float64Array.from(follow);
    this.triangles = Uint32Array.from(new Delaunator(this.rest).triangles);
  }

  /** Every vertex now (N*2 px) for the face outline now at ``outline`` (A*2 px). */
  points(outline: Float64Array): Float64Array {
    const a = this.anchors.length, n = this.rest.length / 2;
    const m = similarity(this.rest.subarray(0, 2 * a), outline);
    const out = new Float64Array(2 * n);
    for (let i = 0; i < n; i++) {
      const x = this.rest[2 * i], y = this.rest[2 * i + 1], f = this.follow[i];
      const mx = m[0] * x + m[1] * y + m[2], my = m[3] * x + m[4] * y + m[5];
      out[2 * i] = i < a ? outline[2 * i] : Math.min(Math.max(x + f * (mx - x), -0.5), this.width - 0.5);
      out[2 * i + 1] = i < a ? outline[2 * i + 1] : Math.min(Math.max(y + f * (my - y), -0.5), this.height - 0.5);
    }
    return out;
  }
}

/** The least-squares 2x3 similarity [a, -b, tx, b, a, ty] mapping ``src`` onto ``dst`` (N*2). */
export function similarity(src: ArrayLike<number>, dst: ArrayLike<number>): number[] {
  const n = src.length / 2;
  let sx = 0, sy = 0, dx = 0, dy = 0;
  for (let i = 0; i < n; i++) { sx += src[2 * i]; sy += src[2 * i + 1]; dx += dst[2 * i]; dy += dst[2 * i + 1]; }
  sx /= n; sy /= n; dx /= n; dy /= n;
  let dot = 0, cross = 0, norm = 0;
  for (let i = 0; i < n; i++) {
    const px = src[2 * i] - sx, py = src[2 * i + 1] - sy, qx = dst[2 * i] - dx, qy = dst[2 * i + 1] - dy;
    dot += px * qx + py * qy;
    cross += px * qy - py * qx;
    norm += px * px + py * py;
  }
  const a = norm > 0 ? dot / norm : 1, b = norm > 0 ? cross / norm : 0;
  return [a, -b, dx - a * sx + b * sy, b, a, dy - b * sx - a * sy];
}
