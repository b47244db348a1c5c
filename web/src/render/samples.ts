/**
 * The actor's own mouth and eyes in the synthesis (facemime.animate.samples.SamplePainter): per
 * frame, each sample group's sample is pasted into the texture, its edges faded in (pasteFaded,
 * the appearance updates' rule): the sample the stream chose (docs/bitstream.md, "Sample
 * choices"), or, in a stream that sends no choice, the sample whose shape is nearest the frame's.
 *
 * The nearest sample: the smallest Euclidean distance between keys, the look's iris shifts
 * weighed IRIS_WEIGHT times its lid closures; the mouth's key is its knots' offsets, model units.
 * The key frame is a sample of every group at key zero that pastes nothing: where the frame's key
 * is nearer zero than any sample's, the group pastes nothing.
 *
 * A mouth sample taken from an open mouth also holds its interior: the opening between the inner
 * lips laid out on a rectangle (interiorUv), which the synthesis draws between the frame's inner
 * lips (lipStrip) instead of the painted cavity and teeth.
 */
import type { Model } from './geometry';
import type { Picture, SampleGroup } from './actor';
import { pasteFaded } from './appearance';
import { IRIS_WEIGHT, SAMPLE_GROUPS, SAMPLE_KINDS } from '../shared_constants';

/** The head model's groups whose knots key the mouth's samples. */
export const MOUTH_GROUPS = ['mouth_outer_upper', 'mouth_outer_lower', 'mouth_inner_upper', 'mouth_inner_lower'];

/** Where the inner lips' vertices lie on a mouth sample's interior image
 * (facemime.animate.samples.interior_uv): per vertex of the model (u, v) flattened, [0, 1] from
 * the image's top-left corner: knot i of the K on the upper inner lip at (i / (K - 1), 0), on the
 * lower at (i / (K - 1), 1), one on both (a corner) at (i / (K - 1), 0.5); 0 for the others. */
export function interiorUv(model: Model): Float64Array {
  const uv = new Float64Array(model.vertices.length / 3 * 2);
  const upper = model.groups.mouth_inner_upper ?? [], lower = model.groups.mouth_inner_lower ?? [];
  for (const [curve, v] of [[upper, 0], [lower, 1]] as const) {
    // numpy.linspace(0, 1, K): i * step, its last exactly 1
    const step = 1 / (curve.length - 1);
    curve.forEach((vertex, i) => {
      uv[2 * vertex] = curve.length > 1 && i === curve.length - 1 ? 1 : i * step || 0;
      uv[2 * vertex + 1] = v;
    });
  }
  for (const vertex of upper) if (lower.includes(vertex)) uv[2 * vertex + 1] = 0.5;
  return uv;
}

/** ``x`` rounded to the nearest integer, halves to the even one (Python's round). */
function roundHalfEven(x: number): number {
  const f = Math.floor(x), d = x - f;
  return d < 0.5 ? f : d > 0.5 ? f + 1 : f % 2 === 0 ? f : f + 1;
}

/** The samples a stream chose for a frame (docs/bitstream.md, "Sample choices";
 * facemime.codec.params.samples_from_extras): per group of SAMPLE_GROUPS the index of the sample
 * drawn, null for the key frame's own; null when the stream carries no choice (the receiver
 * chooses by the shapes). ``kinds``: the header's extra kinds; ``values``: the frame's parameter
 * values, its extras from ``first`` on in the order of ``kinds``. */
export function sentSamples(kinds: ArrayLike<number>, values: ArrayLike<number>, first: number): (number | null)[] | null {
  const extras = Array.from(kinds);
  if (!extras.some((k) => (SAMPLE_KINDS as readonly number[]).includes(k))) return null;
  return SAMPLE_KINDS.map((kind) => {
    const j = extras.indexOf(kind);
    const k = roundHalfEven(j < 0 ? 0 : values[first + j]);
    return k < 1 ? null : k - 1;
  });
}

/** An eye key (look vector: closures, then iris u, v of each eye) weighed for distances. */
export function weighEyes(key: ArrayLike<number>): Float64Array {
  return Float64Array.from(key, (v, j) => v * (j < 2 ? 1 : IRIS_WEIGHT));
}

/** The sum of `x`'s values in the order of numpy's pairwise summation (its float64 add.reduce
 * along a contiguous axis), so that distances equal numpy's to the last bit. */
function pairwiseSum(x: Float64Array, start: number, n: number): number {
  if (n < 8) {
    let s = -0;
    for (let i = 0; i < n; i++) s += x[start + i];
    return s;
  }
  if (n <= 128) {
    const r = [0, 1, 2, 3, 4, 5, 6, 7].map((i) => x[start + i]);
    let i = 8;
    for (; i < n - (n % 8); i += 8) for (let j = 0; j < 8; j++) r[j] += x[start + i + j];
    let s = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
    for (; i < n; i++) s += x[start + i];
    return s;
  }
  let n2 = Math.floor(n / 2);
  n2 -= n2 % 8;
  return pairwiseSum(x, start, n2) + pairwiseSum(x, start + n2, n - n2);
}

/** The index of the sample nearest `key` (the first of equals), or null when the key frame (key
 * zero) is at least as near (facemime.animate.samples.nearest). */
export function nearest(keys: Float64Array[], key: Float64Array): number | null {
  const sq = new Float64Array(key.length);
  let best = -1, bestD = Infinity;
  keys.forEach((k, s) => {
    for (let j = 0; j < key.length; j++) sq[j] = (k[j] - key[j]) * (k[j] - key[j]);
    const d = Math.sqrt(pairwiseSum(sq, 0, key.length));
    if (best < 0 || d < bestD) { best = s; bestD = d; }
  });
  let norm2 = 0;
  for (let j = 0; j < key.length; j++) norm2 += key[j] * key[j];
  return best < 0 || Math.sqrt(norm2) <= bestD ? null : best;
}

/** Pastes an actor's samples into its texture, frame by frame. */
export class SamplePainter {
  /** Per group, its keys as weighed for distances. */
  private readonly keys: Float64Array[][];
  /** The offsets' entries (x, y of each knot, flattened) of the knots on the lips. */
  private readonly mouth: number[];
  private work: Picture | null = null;

  /** `knots`: the model's knots' vertex indices (Deformer.knots). */
  constructor(readonly groups: SampleGroup[], model: Model, knots: number[]) {
    this.keys = groups.map((g) => (g.name === 'eyes' ? g.keys.map(weighEyes) : g.keys));
    const lips = new Set(MOUTH_GROUPS.flatMap((name) => model.groups[name] ?? []));
    this.mouth = knots.flatMap((v, k) => (lips.has(v) ? [2 * k, 2 * k + 1] : []));
  }

  /** Each group's sample for a frame (in the groups' order; null: nothing pasted): the stream's
   * ``sent`` choice (per group of SAMPLE_GROUPS, sentSamples; an index beyond a group's samples
   * draws none), or, where the stream sends none, the sample nearest the frame's shape: `offsets`
   * the knots' (x, y) offsets flattened, the actor's model units; `look` the frame's look vector
   * (closures, then iris u, v of each eye). */
  choose(offsets: Float64Array, look: ArrayLike<number>, sent: (number | null)[] | null = null): (number | null)[] {
    if (sent) {
      return this.groups.map((g) => {
        const k = sent[SAMPLE_GROUPS.indexOf(g.name)] ?? null;
        return k !== null && k < g.keys.length ? k : null;
      });
    }
    const frame = {
      eyes: weighEyes(look),
      mouth: Float64Array.from(this.mouth, (r) => offsets[r]),
    };
    return this.groups.map((g, i) => {
      const key = frame[g.name];
      return this.keys[i][0].length === key.length ? nearest(this.keys[i], key) : null;
    });
  }

  /** The chosen mouth sample's interior image (interiorUv), and the sample's index; null where
   * no mouth sample is chosen or it has none. */
  interior(chosen: (number | null)[]): { sample: number; image: Picture } | null {
    const i = this.groups.findIndex((g) => g.name === 'mouth'), k = i < 0 ? null : chosen[i];
    const image = k === null ? null : this.groups[i].interiors?.[k] ?? null;
    return image && k !== null ? { sample: k, image } : null;
  }

  /** `texture` with the chosen samples pasted (a working copy reused between calls), or
   * `texture` itself when none is chosen. */
  paint(texture: Picture, chosen: (number | null)[]): Picture {
    if (chosen.every((k) => k === null)) return texture;
    if (!this.work || this.work.width !== texture.width || this.work.height !== texture.height) {
      this.work = { width: texture.width, height: texture.height, rgba: texture.rgba.slice() };
    } else {
      this.work.rgba.set(texture.rgba);
    }
    this.groups.forEach((g, i) => {
      const k = chosen[i];
      if (k !== null) g.boxes.forEach(([x, y], b) => pasteFaded(this.work as Picture, g.images[k][b], x, y));
    });
    return this.work;
  }
}
