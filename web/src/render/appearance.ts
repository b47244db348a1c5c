/**
 * Appearance updates (docs/bitstream.md, "Appearance"): a WebP image pasted into a rectangle of
 * the actor's texture from frame F on, its fading edges blended over 8 texels with the integer
 * rule of the specification (pasteFaded, which the actor's mouth and eye samples share).
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
  return pasteFaded(texture, u.image, u.x, u.y);
}

/** Pastes ``image`` into ``texture`` in place with its top-left texel at (x, y), its edges faded
 * into the texture over 8 texels (facemime.render.paste.paste_faded): a texel at distance d from
 * the nearest edge that is not on the texture's border weighs k / 8, k = min(8, d + 1), and
 * becomes (k u + (8 - k) t + 4) // 8; texels beyond the texture are ignored. False (nothing
 * changed) when the image lies wholly outside the texture. */
export function pasteFaded(texture: Picture, image: Picture, x: number, y: number): boolean {
  const tw = texture.width, th = texture.height, w = image.width, h = image.height;
  if (x >= tw || y >= th) return false;
  const fadeLeft = x > 0, fadeTop = y > 0, fadeRight = x + w < tw, fadeBottom = y + h < th;
  for (let j = 0; j < h && y + j < th; j++) {
    for (let i = 0; i < w && x + i < tw; i++) {
      let d = Infinity;
      if (fadeLeft) d = Math.min(d, i);
      if (fadeRight) d = Math.min(d, w - 1 - i);
      if (fadeTop) d = Math.min(d, j);
      if (fadeBottom) d = Math.min(d, h - 1 - j);
      const k = Math.min(8, d + 1);
      const s = 4 * (j * w + i), t = 4 * ((y + j) * tw + x + i);
      for (let c = 0; c < 3; c++) {
        texture.rgba[t + c] = Math.floor((k * image.rgba[s + c] + (8 - k) * texture.rgba[t + c] + 4) / 8);
      }
    }
  }
  return true;
}
