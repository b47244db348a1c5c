/**
 * The actor a stream carries (``facemime.actor/1``, docs/bitstream.md "Actor"): a ZIP archive of
 * ``actor.json`` (the head model, its pose on the source picture, the source's size), the
 * texture and, when it has one, the scene (the source picture the face is drawn in), and, when it
 * has one, its sample library of its own mouth and eyes (``samples.json``, per group and box
 * ``samples/<group>/<box>.webp`` holding the samples stacked top to bottom, and the mouth's
 * openings stacked in ``samples/mouth/interior.webp``; facemime.io.samples_file).
 *
 * Images are RGBA, row-major from the top-left pixel.
 */
import { unzipSync } from 'fflate';
import type { Model, Pose } from './geometry';
import { INTERIOR_SIZE, SAMPLE_GROUPS } from '../shared_constants';

export interface Picture { width: number; height: number; rgba: Uint8Array }

export interface Actor {
  model: Model;
  pose: Pose;
  source: { width: number; height: number };
  texture: Picture;
  scene: Picture | null;
  /** The sample library's groups, in the file's order; null: the actor has none. */
  samples: SampleGroup[] | null;
}

/** One group of an actor's samples (facemime.types.samples.SampleGroup). */
export interface SampleGroup {
  name: (typeof SAMPLE_GROUPS)[number];
  /** Each rectangle's [x, y, width, height] in the texture, texels. */
  boxes: [number, number, number, number][];
  /** Per sample, its shape as stored: the look vector (eyes) or the mouth knots' offsets. */
  keys: Float64Array[];
  /** Per sample, the frame it was taken from (informative). */
  frames: number[];
  /** Per sample, its image of each box (RGBA, the box's size). */
  images: Picture[][];
  /** Per sample, the mouth's opening laid out between the inner lips (samples.interiorUv; null:
   * the sample has none); null: no sample of the group has one. */
  interiors: (Picture | null)[] | null;
}

/** At most this many samples and boxes a group (facemime.io.samples_file). */
const MAX_SAMPLES = 64, MAX_BOXES = 4, MAX_KEY = 1e4, MAX_TEXELS = 1 << 24;

/** Largest member accepted, bytes (as the Python reader). */
const MAX_MEMBER = 64 << 20;

/** An image file's bytes (PNG or WebP) as RGBA pixels, colours as stored (no colour management). */
export async function decodeImage(bytes: Uint8Array, type: string): Promise<Picture> {
  const bitmap = await createImageBitmap(new Blob([bytes as BlobPart], { type }),
    { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
  const canvas = document.createElement('canvas');
  canvas.width = bitmap.width;
  canvas.height = bitmap.height;
  const ctx = canvas.getContext('2d', { willReadFrequently: true }) as CanvasRenderingContext2D;
  ctx.drawImage(bitmap, 0, 0);
  const data = ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
  bitmap.close();
  return { width: canvas.width, height: canvas.height, rgba: new Uint8Array(data.buffer) };
}

const numbers = (a: unknown, what: string): number[] => {
  const flat = (a as unknown[]).flat(2) as unknown[];
  if (!Array.isArray(a) || flat.some((x) => typeof x !== 'number' || !Number.isFinite(x))) {
    throw new Error(`the actor's ${what} are malformed`);
  }
  return flat as number[];
};

/** Reads an actor file's bytes; throws an Error with a one-line reason when it is not one. */
export async function readActor(data: Uint8Array): Promise<Actor> {
  let files: Record<string, Uint8Array>;
  try {
    files = unzipSync(data, { filter: (f) => f.originalSize <= MAX_MEMBER });
  } catch (e) {
    throw new Error(`the actor is not a facemime actor file (${(e as Error).message})`);
  }
  const text = files['actor.json'];
  if (!text) throw new Error('the actor has no actor.json');
  const doc = JSON.parse(new TextDecoder().decode(text));
  if (doc?.format !== 'facemime.actor/1') throw new Error(`the actor's format is ${JSON.stringify(doc?.format)}`);
  const m = doc.model;
  const vertices = Float64Array.from(numbers(m.vertices, 'vertices'));
  const model: Model = {
    vertices,
    triangles: Uint32Array.from(numbers(m.triangles, 'triangles')),
    uv: Float64Array.from(numbers(m.uv, 'texture coordinates')),
    groups: m.groups,
  };
  const n = vertices.length / 3;
  if (model.uv.length !== 2 * n || model.triangles.some((i) => i >= n)) throw new Error("the actor's model is inconsistent");
  const picture = async (stem: string) => {
    for (const [ext, type] of [['webp', 'image/webp'], ['png', 'image/png']]) {
      const bytes = files[`${stem}.${ext}`];
      if (bytes) return decodeImage(bytes, type);
    }
    return null;
  };
  const texture = await picture('texture');
  if (!texture) throw new Error('the actor has no texture');
  const scene = doc.scene ? await picture('scene') : null;
  const samples = files['samples.json'] ? await readSamples(files, texture, model) : null;
  return { model, pose: doc.pose as Pose, source: doc.source, texture, scene, samples };
}

/** An actor's sample library from its members (facemime.io.samples_file.samples_from_members,
 * with facemime.types.samples' checks); throws an Error with a one-line reason when malformed. */
async function readSamples(files: Record<string, Uint8Array>, texture: Picture, model: Model): Promise<SampleGroup[]> {
  const bad = (why: string): never => { throw new Error(`the actor's samples.json is malformed (${why})`); };
  let doc;
  try {
    doc = JSON.parse(new TextDecoder().decode(files['samples.json']));
  } catch (e) {
    return bad((e as Error).message);
  }
  if (doc?.format !== 'facemime.samples/1' || !Array.isArray(doc.groups)) bad('not a facemime.samples/1 document');
  const groups: SampleGroup[] = [];
  for (const g of doc.groups as unknown[]) {
    const { name, boxes, samples } = (g ?? {}) as { name: unknown; boxes: unknown; samples: unknown };
    if (!SAMPLE_GROUPS.includes(name as SampleGroup['name'])) bad(`a group is one of ${SAMPLE_GROUPS.join(', ')}, got ${JSON.stringify(name)}`);
    if (groups.some((h) => h.name === name)) bad(`group ${name} appears twice`);
    if (!Array.isArray(boxes) || boxes.length < 1 || boxes.length > MAX_BOXES
      || boxes.some((b) => !Array.isArray(b) || b.length !== 4 || b.some((v) => !Number.isInteger(v) || v < 0) || b[2] < 1 || b[3] < 1
        || b[0] + b[2] > texture.width || b[1] + b[3] > texture.height)) {
      bad(`group ${name}: boxes must be 1-${MAX_BOXES} rows of x, y, width, height inside the texture`);
    }
    if (!Array.isArray(samples) || samples.length < 1 || samples.length > MAX_SAMPLES) bad(`group ${name}: a group holds 1-${MAX_SAMPLES} samples`);
    const entries = samples as { frame: unknown; key: unknown; interior?: unknown }[];
    const keys = entries.map((e) => {
      const key = e?.key;
      if (!Array.isArray(key) || key.some((v) => typeof v !== 'number' || !Number.isFinite(v) || Math.abs(v) > MAX_KEY)) return bad(`group ${name}: a sample's key is not a list of finite numbers within ±${MAX_KEY}`);
      return Float64Array.from(key as number[]);
    });
    const lips = new Set(['mouth_outer_upper', 'mouth_outer_lower', 'mouth_inner_upper', 'mouth_inner_lower'].flatMap((g) => [...model.groups[g]])).size;
    if (keys.some((k) => k.length !== (name === 'eyes' ? 6 : 2 * lips))) bad(`group ${name}: keys of the wrong length`);
    const rectsAll = boxes as [number, number, number, number][];
    if (entries.length * rectsAll.reduce((t, [, , w, h]) => t + w * h, 0) > MAX_TEXELS) bad(`group ${name}: more than ${MAX_TEXELS} texels of images`);
    if (entries.some((e) => e?.interior !== undefined && typeof e.interior !== 'boolean')) bad(`group ${name}: a sample's interior is true or false`);
    const frames = entries.map((e) => (Number.isInteger(e?.frame) ? (e.frame as number) : bad(`group ${name}: a sample's frame is not an integer`)));
    const rects = boxes as [number, number, number, number][];
    const inside = entries.map((e) => e?.interior === true);
    // a group's images of box `b` (its index, or 'interior'), PNG or WebP, stacked top to bottom:
    // cut into `count` of equal height
    const atlas = async (b: number | 'interior', count: number): Promise<Picture[]> => {
      for (const [ext, type] of [['png', 'image/png'], ['webp', 'image/webp']]) {
        const member = `samples/${name}/${b}.${ext}`;
        const bytes = files[member];
        if (!bytes) continue;
        let whole: Picture;
        try {
          whole = await decodeImage(bytes, type);
        } catch {
          return bad(`sample image ${member} does not decode`);
        }
        if (whole.height % count) bad(`sample image ${member} does not hold ${count} images of one height`);
        const h = whole.height / count, row = 4 * whole.width;
        return Array.from({ length: count }, (_, k) => ({
          width: whole.width, height: h, rgba: whole.rgba.slice(k * h * row, (k + 1) * h * row),
        }));
      }
      return bad(`group ${name} has no image of ${b === 'interior' ? 'its interiors' : `box ${b}`}`);
    };
    const perBox = await Promise.all(rects.map(async ([, , w, h], b) => {
      const cut = await atlas(b, entries.length);
      if (cut[0].width !== w || cut[0].height !== h) bad(`sample image samples/${name}/${b} is not its box's size`);
      return cut;
    }));
    const images = entries.map((_, s) => perBox.map((cut) => cut[s]));
    const opened = inside.filter((i) => i).length;
    const openings = opened ? await atlas('interior', opened) : [];
    if (opened && (openings[0].width !== INTERIOR_SIZE[0] || openings[0].height !== INTERIOR_SIZE[1])) {
      bad(`group ${name}: an interior is a ${INTERIOR_SIZE[0]} x ${INTERIOR_SIZE[1]} image`);
    }
    let next = 0;
    const interiors = opened ? inside.map((i) => (i ? openings[next++] : null)) : null;
    groups.push({ name: name as SampleGroup['name'], boxes: rects, keys, frames, images, interiors });
  }
  return groups;
}
