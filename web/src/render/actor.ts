/**
 * The actor a stream carries (``facemime.actor/1``, docs/bitstream.md "Actor"): a ZIP archive of
 * ``actor.json`` (the head model, its pose on the source picture, the source's size), the
 * texture and, when it has one, the scene (the source picture the face is drawn in).
 *
 * Images are RGBA, row-major from the top-left pixel.
 */
import { unzipSync } from 'fflate';
import type { Model, Pose } from './geometry';

export interface Picture { width: number; height: number; rgba: Uint8Array }

export interface Actor {
  model: Model;
  pose: Pose;
  source: { width: number; height: number };
  texture: Picture;
  scene: Picture | null;
}

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
  return { model, pose: doc.pose as Pose, source: doc.source, texture, scene };
}
