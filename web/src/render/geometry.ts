/**
 * The head's geometry, as the Python synthesis computes it: knot offsets spread to every vertex
 * (facemime.animate.deform), lips sealed, lids closed (facemime.animate.eyes.close_lids), the
 * pose shown (facemime.animate.synth.Puppet.pose) and the orthographic projection
 * (facemime.types.pose).
 *
 * Model space: x to the subject's left, y up, z towards the camera (model units, millimetres for
 * the built-in head). Image: pixels, x right, y down, (0, 0) the centre of the top-left pixel.
 * Vertices are Float64Array of N*3 (x, y, z per vertex); points Float64Array of N*2.
 */
import { CONTOUR_GROUPS, LOWER_LID, REACH, SOFTEN, UPPER_LID } from '../shared_constants';

export interface Model {
  vertices: Float64Array; // N*3
  triangles: Uint32Array; // F*3
  uv: Float64Array; // N*2, [0, 1] from the texture's top-left corner
  groups: Record<string, number[]>;
}

export interface Pose { yaw: number; pitch: number; roll: number; scale: number; tx: number; ty: number }

/** Rz(roll) Rx(pitch) Ry(yaw), degrees, row-major 3x3. */
export function rotation(yaw: number, pitch: number, roll: number): number[] {
  const [y, p, r] = [yaw, pitch, roll].map((a) => (a * Math.PI) / 180);
  const ry = [Math.cos(y), 0, Math.sin(y), 0, 1, 0, -Math.sin(y), 0, Math.cos(y)];
  const rx = [1, 0, 0, 0, Math.cos(p), -Math.sin(p), 0, Math.sin(p), Math.cos(p)];
  const rz = [Math.cos(r), -Math.sin(r), 0, Math.sin(r), Math.cos(r), 0, 0, 0, 1];
  return mul3(rz, mul3(rx, ry));
}

function mul3(a: number[], b: number[]): number[] {
  const out = new Array<number>(9).fill(0);
  for (let i = 0; i < 3; i++) for (let j = 0; j < 3; j++) for (let k = 0; k < 3; k++) out[i * 3 + j] += a[i * 3 + k] * b[k * 3 + j];
  return out;
}

/** Image points (N*2) and depths (N, larger = nearer) of model ``vertices`` seen in ``pose``. */
export function project(vertices: Float64Array, pose: Pose): { points: Float64Array; depth: Float64Array } {
  const r = rotation(pose.yaw, pose.pitch, pose.roll);
  const n = vertices.length / 3;
  const points = new Float64Array(n * 2);
  const depth = new Float64Array(n);
  for (let i = 0; i < n; i++) {
    const x = vertices[3 * i], y = vertices[3 * i + 1], z = vertices[3 * i + 2];
    points[2 * i] = pose.tx + pose.scale * (r[0] * x + r[1] * y + r[2] * z);
    points[2 * i + 1] = pose.ty - pose.scale * (r[3] * x + r[4] * y + r[5] * z);
    depth[i] = pose.scale * (r[6] * x + r[7] * y + r[8] * z);
  }
  return { points, depth };
}

/** Distance between the outer eye corners, model units (facemime.types.head.model_iod). */
export function modelIod(m: Model): number {
  const a = m.groups.eye_right[0], b = m.groups.eye_left[4];
  return Math.hypot(m.vertices[3 * a] - m.vertices[3 * b], m.vertices[3 * a + 1] - m.vertices[3 * b + 1]);
}

/** The mouth corners' distance in the model's (x, y) plane of ``vertices``, model units. */
export function mouthWidth(m: Model, vertices: Float64Array): number {
  const g = m.groups.mouth_outer_upper;
  const a = g[0], b = g[g.length - 1];
  return Math.hypot(vertices[3 * b] - vertices[3 * a], vertices[3 * b + 1] - vertices[3 * a + 1]);
}

/** The strip between the inner lips, knot to knot (facemime.types.head.lip_strip): per pair of
 * knots i, i + 1 the triangles (upper i, upper i + 1, lower i + 1) and (upper i, lower i + 1,
 * lower i), leaving out any whose vertices repeat (the corners the lips share); none where the
 * inner lips' knot counts differ. */
export function lipStrip(model: Model): Uint32Array {
  const upper = model.groups.mouth_inner_upper ?? [], lower = model.groups.mouth_inner_lower ?? [];
  if (upper.length !== lower.length) return new Uint32Array(0);
  const out: number[] = [];
  for (let i = 0; i + 1 < upper.length; i++) {
    const [a, b, c, d] = [upper[i], upper[i + 1], lower[i + 1], lower[i]];
    for (const t of [[a, b, c], [a, c, d]]) if (new Set(t).size === 3) out.push(...t);
  }
  return Uint32Array.from(out);
}

/** Whether the model's mouth is capped: one of its triangles is one of lipStrip's, in either
 * winding (facemime.types.head.mouth_capped). */
export function mouthCapped(model: Model): boolean {
  const key = (a: number, b: number, c: number) => [a, b, c].sort((x, y) => x - y).join(',');
  const strip = lipStrip(model), tri = model.triangles, inStrip = new Set<string>();
  for (let t = 0; t < strip.length; t += 3) inStrip.add(key(strip[t], strip[t + 1], strip[t + 2]));
  for (let t = 0; t < tri.length; t += 3) if (inStrip.has(key(tri[t], tri[t + 1], tri[t + 2]))) return true;
  return false;
}

/** Drives a model by its knots (facemime.animate.deform.Deformer). */
export class Deformer {
  readonly knots: number[];
  /** N x K, row-major: how much of each knot's offset each vertex takes. */
  readonly weights: Float64Array;
  private readonly slot = new Map<number, number>();
  private readonly inner: [number[], number[]];
  /** Whether the model's mouth is capped (facemime.types.head.mouth_capped): see sealed. */
  private readonly capped: boolean;
  /** Per share closed, the model's own closing (sealed takes it back on a capped mouth). */
  private readonly rest = new Map<number, Float64Array | null>();

  constructor(readonly model: Model) {
    const g = model.groups;
    for (const name of [...CONTOUR_GROUPS, 'eye_left', 'eye_right']) {
      if (!g[name]) throw new Error(`the actor's head model lacks the group ${name}`);
    }
    this.knots = [...new Set(CONTOUR_GROUPS.flatMap((n) => g[n]))].sort((a, b) => a - b);
    this.knots.forEach((v, k) => this.slot.set(v, k));
    const u = g.mouth_inner_upper, l = g.mouth_inner_lower;
    this.inner = [u.slice(1, -1), l.slice(1, -1)];
    this.weights = this.spread();
    this.capped = mouthCapped(model);
  }

  private spread(): Float64Array {
    const m = this.model, g = m.groups, v = m.vertices;
    const n = v.length / 3, k = this.knots.length;
    const iod = modelIod(m);
    const eyes = [...g.eye_left, ...g.eye_right];
    const eyeY = eyes.reduce((s, i) => s + v[3 * i + 1], 0) / eyes.length;
    const mu = g.mouth_outer_upper;
    const mouthY = (v[3 * mu[0] + 1] + v[3 * mu[mu.length - 1] + 1]) / 2;
    const slots = (names: string[]) => [...new Set(names.flatMap((x) => g[x]))].sort((a, b) => a - b)
      .map((i) => this.slot.get(i) as number);
    const sets = {
      upper: slots(['mouth_outer_upper', 'mouth_inner_upper']),
      lower: slots(['mouth_outer_lower', 'mouth_inner_lower']),
      brows: slots(CONTOUR_GROUPS.filter((x) => x.startsWith('brow'))),
    };
    const anchorList: number[] = [];
    for (const name of ['eye_left', 'eye_right', 'nose']) if (g[name]) anchorList.push(...g[name]);
    if (g.face_outline) anchorList.push(...g.face_outline.filter((i) => v[3 * i + 1] > mouthY));
    const knotSet = new Set(this.knots);
    const anchors = [...new Set(anchorList)].filter((i) => !knotSet.has(i)).sort((a, b) => a - b);
    const soft2 = (SOFTEN * iod) ** 2, far = 1 / (REACH * iod) ** 2;
    const d2 = (a: number, b: number) =>
      (v[3 * a] - v[3 * b]) ** 2 + (v[3 * a + 1] - v[3 * b + 1]) ** 2 + (v[3 * a + 2] - v[3 * b + 2]) ** 2;
    const w = new Float64Array(n * k);
    for (let j = 0; j < n; j++) {
      const own = this.slot.get(j);
      if (own !== undefined) {
        w[j * k + own] = 1;
        continue;
      }
      const y = v[3 * j + 1];
      const chosen = y > eyeY ? sets.brows : y >= mouthY ? sets.upper : sets.lower;
      const ws = chosen.map((s) => 1 / (d2(this.knots[s], j) + soft2));
      let rest = far;
      for (const a of anchors) if (a !== j) rest += 1 / (d2(a, j) + soft2);
      const total = ws.reduce((s, x) => s + x, 0) + rest;
      chosen.forEach((s, i) => { w[j * k + s] = ws[i] / total; });
    }
    return w;
  }

  /** The model's vertices moved by knot ``offsets`` (K*2, model units) times ``gain``. */
  vertices(offsets: Float64Array, gain = 1): Float64Array {
    const out = Float64Array.from(this.model.vertices);
    this.add(out, offsets, gain);
    return out;
  }

  private add(out: Float64Array, offsets: Float64Array, gain: number): void {
    const k = this.knots.length, n = out.length / 3, w = this.weights;
    for (let j = 0; j < n; j++) {
      let dx = 0, dy = 0;
      for (let s = 0; s < k; s++) {
        const c = w[j * k + s];
        if (c !== 0) { dx += c * offsets[2 * s]; dy += c * offsets[2 * s + 1]; }
      }
      out[3 * j] += gain * dx;
      out[3 * j + 1] += gain * dy;
    }
  }

  /** ``vertices`` with the lips shut where the inner lips lie closer than ``closed`` times the
   * mouth's width (Deformer.sealed): a copy. On a capped mouth what this does to the model's own
   * vertices is taken back, so that the key frame's mouth is drawn as it was fitted. */
  sealed(vertices: Float64Array, closed: number): Float64Array {
    const close = this.closing(vertices, closed);
    if (close === null) return vertices;
    if (this.capped && !this.rest.has(closed)) this.rest.set(closed, this.closing(this.model.vertices, closed));
    const rest = this.capped ? (this.rest.get(closed) ?? null) : null;
    if (rest !== null) for (let i = 0; i < close.length; i++) close[i] -= rest[i];
    const out = Float64Array.from(vertices);
    this.add(out, close, 1);
    return out;
  }

  /** The K*2 knot moves that shut the lips of ``vertices`` as sealed says, model units (null where
   * the inner lips' knot counts differ or the mouth has no width). */
  private closing(vertices: Float64Array, closed: number): Float64Array | null {
    const [upper, lower] = this.inner;
    const g = this.model.groups.mouth_outer_upper;
    const c0 = g[0], c1 = g[g.length - 1];
    const ax = vertices[3 * c1] - vertices[3 * c0], ay = vertices[3 * c1 + 1] - vertices[3 * c0 + 1];
    const width = mouthWidth(this.model, vertices);
    if (upper.length !== lower.length || width <= 0) return null;
    const ux = -ay / width, uy = ax / width;
    const limit = closed * width;
    const close = new Float64Array(this.knots.length * 2);
    upper.forEach((u, i) => {
      const l = lower[i];
      const gap = (vertices[3 * u] - vertices[3 * l]) * ux + (vertices[3 * u + 1] - vertices[3 * l + 1]) * uy;
      const shown = gap < limit ? 0 : gap < 2 * limit ? 2 * (gap - limit) : gap;
      const half = 0.5 * (gap - shown);
      const su = this.slot.get(u) as number, sl = this.slot.get(l) as number;
      close[2 * su] = -half * ux; close[2 * su + 1] = -half * uy;
      close[2 * sl] = half * ux; close[2 * sl + 1] = half * uy;
    });
    return close;
  }
}

/** ``vertices`` with each eye's upper lid moved ``closure[e]`` of the way to its lower lid, for
 * the eye rings ``eye_right`` then ``eye_left``: a copy. */
export function closeLids(m: Model, vertices: Float64Array, closure: [number, number]): Float64Array {
  const out = Float64Array.from(vertices);
  ['eye_right', 'eye_left'].forEach((name, e) => {
    const c = closure[e], ring = m.groups[name];
    if (!c) return;
    UPPER_LID.forEach((p, i) => {
      const up = ring[p], low = ring[LOWER_LID[i]];
      for (let d = 0; d < 3; d++) out[3 * up + d] = vertices[3 * up + d] + c * (vertices[3 * low + d] - vertices[3 * up + d]);
    });
  });
  return out;
}

/** The pose the actor is shown in for a stream's decoded pose ``measured`` (Puppet.pose for the
 * receiver's puppet, the actor driven by its own motion): in its scene, the actor's own pose
 * ``rest`` moved by the motion relative to the stream's reference pose ``key``; alone, as
 * measured. */
export function shownPose(measured: Pose, rest: Pose, key: Pose, inScene: boolean): Pose {
  if (!inScene) return { ...measured };
  const ratio = rest.scale / key.scale;
  return {
    yaw: rest.yaw + measured.yaw - key.yaw, pitch: rest.pitch + measured.pitch - key.pitch,
    roll: rest.roll + measured.roll - key.roll, scale: (rest.scale * measured.scale) / key.scale,
    tx: rest.tx + ratio * (measured.tx - key.tx), ty: rest.ty + ratio * (measured.ty - key.ty),
  };
}

/** A stream frame's pose from its parameters 0-5 (yaw, pitch, roll, ln scale, tx, ty). */
export function poseFromValues(v: ArrayLike<number>): Pose {
  return { yaw: v[0], pitch: v[1], roll: v[2], scale: Math.exp(v[3]), tx: v[4], ty: v[5] };
}
