/**
 * A stream's frames drawn on its actor, as ``facemime decode`` draws them
 * (facemime.animate.synth.Puppet driven by the actor's own motion): the knot offsets deform the
 * head, the look closes the lids and moves the irises, the actor's own mouth and eye samples the
 * stream chose (or, in a stream that sends no choice, those nearest the frame's shape) are pasted
 * into the texture, the mouth's opening is drawn from the chosen mouth sample's interior where it
 * has one (else painted: cavity and teeth), the pose places it, and the picture is the actor's
 * scene warped to follow the face (or the face alone on a dark background when the actor has no
 * scene). A frame without a face shows the last face, dimmed.
 */
import type { Header } from '../stream';
import type { Actor, Picture } from './actor';
import { closeLids, Deformer, lipStrip, mouthWidth, poseFromValues, project, shownPose, type Pose } from './geometry';
import { LookPainter } from './eyes';
import { Renderer, type Layer } from './gl';
import { mouthPatch, teethUncovered } from './mouth';
import { interiorUv, SamplePainter, sentSamples } from './samples';
import { SceneMesh } from './scene';
import { BACKGROUND, BASIS_ONE, LOOK_NAMES, NO_FACE_DIM, SAMPLE_GROUPS, SEAL, SLOW } from '../shared_constants';

/** One frame's motion, as decoded: the parameter values of the stream (pose, coefficients,
 * extras) and whether it shows a face. */
export interface Motion { values: ArrayLike<number>; face: boolean }

export class Synthesizer {
  private readonly deformer: Deformer;
  private readonly scene: SceneMesh | null;
  private readonly sceneLayer: Layer | null;
  private readonly sceneUv: Float32Array | null;
  private textureLayer: Layer;
  private painter: LookPainter;
  private readonly samples: SamplePainter | null;
  /** The texture the look painted last (LookPainter.texture), the samples pasted into it. */
  private looked: Picture | null = null;
  /** The samples chosen in the texture uploaded last (SamplePainter.choose, joined). */
  private pasted = '';
  /** The mouth interiors' texture coordinates per vertex (interiorUv) and the strip between the
   * inner lips they are drawn on (lipStrip). */
  private readonly interiorUv: Float64Array;
  private readonly strip: Uint32Array;
  /** The mouth samples' interiors uploaded so far, by sample index. */
  private readonly interiors = new Map<number, Layer>();
  private readonly key: Pose;
  private readonly basis: Float64Array;
  private readonly restWidth: number;

  constructor(readonly renderer: Renderer, readonly actor: Actor, readonly header: Header) {
    const m = actor.model;
    this.deformer = new Deformer(m);
    if (header.basisLength !== 2 * this.deformer.knots.length) {
      throw new Error(`the stream's basis does not fit the ${this.deformer.knots.length} knots of its actor`);
    }
    this.basis = Float64Array.from(header.basis, (x) => x / BASIS_ONE);
    this.key = poseFromValues(header.references.slice(0, 6).map((r, i) => r * header.steps[i]));
    this.restWidth = mouthWidth(m, m.vertices);
    this.textureLayer = renderer.upload(actor.texture);
    this.painter = new LookPainter(actor.texture, m);
    this.samples = actor.samples ? new SamplePainter(actor.samples, m, this.deformer.knots) : null;
    this.interiorUv = interiorUv(m);
    this.strip = lipStrip(m);
    if (actor.scene) {
      const { width, height } = actor.source;
      const outline = m.groups.face_outline;
      const projected = project(m.vertices, actor.pose).points;
      this.scene = new SceneMesh(width, height, outline, Float64Array.from(outline.flatMap((i) => [projected[2 * i], projected[2 * i + 1]])));
      this.sceneLayer = renderer.upload(actor.scene);
      this.sceneUv = Float32Array.from(this.scene.rest, (p, i) => (p + 0.5) / (i % 2 ? height : width));
    } else {
      this.scene = this.sceneLayer = this.sceneUv = null;
    }
  }

  /** The picture's size, px: the scene's, or the stream's when the actor has none. */
  get size(): [number, number] {
    return this.scene ? [this.scene.width, this.scene.height] : [this.header.width, this.header.height];
  }

  /** Replaces the actor's texture (after an appearance update); same size. Its irises are found
   * again, as the Python synthesis does (a few hundred ms for a large texture). */
  retexture(texture: Picture): void {
    this.painter = new LookPainter(texture, this.actor.model);
  }

  /** Draws ``motion`` into the renderer's canvas, letterboxed into ``view`` ([x, y, w, h]). */
  draw(motion: Motion, view?: number[]): void {
    const v = motion.values, m = this.actor.model, knots = this.deformer.knots.length;
    const coefficients = this.basis.length / (2 * knots);
    const offsets = new Float64Array(2 * knots);
    for (let c = 0; c < coefficients; c++) {
      const q = v[6 + c];
      for (let r = 0; r < 2 * knots; r++) offsets[r] += this.basis[c * 2 * knots + r] * q;
    }
    const look = this.look(v, 6 + coefficients);
    let vertices = this.deformer.sealed(this.deformer.vertices(offsets), SEAL);
    vertices = closeLids(m, vertices, look.closure);
    const pose = shownPose(poseFromValues(v), this.actor.pose, this.key, this.scene !== null);
    const { points, depth } = project(vertices, pose);
    const [w, h] = this.size;
    const pick = (name: string) => Float64Array.from(m.groups[name].flatMap((i) => [points[2 * i], points[2 * i + 1]]));
    const spread = mouthWidth(m, vertices) / Math.max(this.restWidth, 1e-9);
    const chosen = this.samples?.choose(offsets, [...look.closure, ...look.iris[0], ...look.iris[1]],
      sentSamples(this.header.extras, v, 6 + coefficients)) ?? [];
    const interior = this.samples?.interior(chosen) ?? null;
    const patch = interior ? null : mouthPatch(pick('mouth_inner_upper'), pick('mouth_inner_lower'), teethUncovered(spread), [w, h]);
    // the eyes' sample covers the eyes: their irises are not moved under it (Puppet.render)
    const eyesChosen = (chosen[SAMPLE_GROUPS.indexOf('eyes')] ?? null) !== null;
    this.uploadTexture(chosen, eyesChosen ? [[0, 0], [0, 0]] : look.iris);
    const r = this.renderer;
    r.begin(w, h, BACKGROUND, view);
    if (this.scene && this.sceneLayer && this.sceneUv) {
      const at = this.scene.points(pick('face_outline'));
      const rest = this.scene.rest, tris = this.scene.triangles;
      const slow: number[] = [], fast: number[] = [];
      for (let t = 0; t < tris.length; t += 3) {
        let moved = 0;
        for (let c = 0; c < 3; c++) {
          const i = tris[t + c];
          moved = Math.max(moved, Math.abs(at[2 * i] - rest[2 * i]), Math.abs(at[2 * i + 1] - rest[2 * i + 1]));
        }
        (moved < SLOW ? slow : fast).push(tris[t], tris[t + 1], tris[t + 2]);
      }
      // still and slow triangles nearest (the still ones land on the key frame's own pixels)
      r.mesh(this.sceneLayer, at, this.sceneUv, Uint32Array.from(slow), false, false);
      r.mesh(this.sceneLayer, at, this.sceneUv, Uint32Array.from(fast), true, false);
    }
    if (interior) {
      // the chosen sample's opening, stretched between the inner lips (both sides drawn)
      let layer = this.interiors.get(interior.sample);
      if (!layer) this.interiors.set(interior.sample, (layer = r.upload(interior.image)));
      r.mesh(layer, points, this.interiorUv, paintersOrder(points, depth, this.strip, false), true, false);
    } else if (patch) {
      r.mouthPatch(patch);
    }
    r.mesh(this.textureLayer, points, m.uv, paintersOrder(points, depth, m.triangles), true, false);
    if (!motion.face) r.dim(NO_FACE_DIM, w, h);
  }

  /** Uploads the frame's texture when it differs from the last uploaded: the look's irises
   * painted (LookPainter.texture), then the ``chosen`` samples pasted (SamplePainter.choose;
   * facemime.animate.synth.Puppet.render, the stream's own actor: offsets in its model units, no
   * gain). */
  private uploadTexture(chosen: (number | null)[], iris: [number, number][]): void {
    const painted = this.painter.texture(iris);
    if (painted) this.looked = painted;
    const looked = this.looked as Picture;
    if (!this.samples) {
      if (painted) this.textureLayer = this.renderer.upload(painted, this.textureLayer);
      return;
    }
    const pasted = chosen.join(',');
    if (!painted && pasted === this.pasted) return;
    this.pasted = pasted;
    this.textureLayer = this.renderer.upload(this.samples.paint(looked, chosen), this.textureLayer);
  }

  private look(v: ArrayLike<number>, first: number): { closure: [number, number]; iris: [number, number][] } {
    const at = (name: (typeof LOOK_NAMES)[number]) => {
      const j = this.header.extras.indexOf(LOOK_NAMES.indexOf(name) + 1); // kinds count the look's values from 1
      return j < 0 ? 0 : v[first + j];
    };
    return {
      closure: [at('eye_right_closure'), at('eye_left_closure')],
      iris: [[at('iris_right_u'), at('iris_right_v')], [at('iris_left_u'), at('iris_left_v')]],
    };
  }
}

/** The front-facing triangles (counter-clockwise in the image, y down; with ``cull`` false, all
 * but those of zero area) far to near by mean depth, a stable sort (facemime.render.raster's
 * painter order). */
export function paintersOrder(points: Float64Array, depth: Float64Array, triangles: Uint32Array, cull = true): Uint32Array {
  const order: [number, number][] = [];
  for (let f = 0; f < triangles.length / 3; f++) {
    const a = triangles[3 * f], b = triangles[3 * f + 1], c = triangles[3 * f + 2];
    const area2 = (points[2 * b] - points[2 * a]) * (points[2 * c + 1] - points[2 * a + 1])
      - (points[2 * b + 1] - points[2 * a + 1]) * (points[2 * c] - points[2 * a]);
    if (cull ? area2 < 0 : area2 !== 0) order.push([(depth[a] + depth[b] + depth[c]) / 3, f]);
  }
  order.sort((x, y) => x[0] - y[0]);
  const out = new Uint32Array(order.length * 3);
  order.forEach(([, f], i) => out.set(triangles.subarray(3 * f, 3 * f + 3), 3 * i));
  return out;
}
