/**
 * Appearance updates (docs/bitstream.md, "Appearance"): a WebP image pasted into a rectangle of
 * the actor's texture from frame F on, its fading edges blended over 8 texels with the integer
 * rule of the specification.
 */
import { decodeImage, type Picture } from './actor';

export interface Update { frame: number; x: number; y: number; image: Picture }

/** Decodes an appearance chunk's payload; null when it is too short or its image does not
 * decode (the receiver counts it as undecodable). */
export async function readUpdate(payload: Uint8Array): Promise<Update | null> {
  if (payload.length < 8) return null;
  const view = new DataView(payload.buffer, payload.byteOffset, payload.byteLength);
  try {
    const image = await decodeImage(payload.subarray(8), 'image/webp');
    return { frame: view.getUint32(0, true), x: view.getUint16(4, true), y: view.getUint16(6, true), image };
  } catch {
    return null;
  }
}

/** Applies ``u`` to ``texture`` in place; false (nothing changed) when its rectangle lies wholly
 * outside the texture. */
export function applyUpdate(texture: Picture, u: Update): boolean {
  const tw = texture.width, th = texture.height, w = u.image.width, h = u.image.height;
  if (u.x >= tw || u.y >= th) return false;
  const fadeLeft = u.x > 0, fadeTop = u.y > 0, fadeRight = u.x + w < tw, fadeBottom = u.y + h < th;
  for (let j = 0; j < h && u.y + j < th; j++) {
    for (let i = 0; i < w && u.x + i < tw; i++) {
      let d = Infinity;
      if (fadeLeft) d = Math.min(d, i);
      if (fadeRight) d = Math.min(d, w - 1 - i);
      if (fadeTop) d = Math.min(d, j);
      if (fadeBottom) d = Math.min(d, h - 1 - j);
      const k = Math.min(8, d + 1);
      const s = 4 * (j * w + i), t = 4 * ((u.y + j) * tw + u.x + i);
      for (let c = 0; c < 3; c++) {
        texture.rgba[t + c] = Math.floor((k * u.image.rgba[s + c] + (8 - k) * texture.rgba[t + c] + 4) / 8);
      }
    }
  }
  return true;
}
