/** Paints looks' irises on a texture with the browser receiver's LookPainter and writes the results:
 *
 *     node .test-build/eyes-cli.mjs JOB.json
 *
 * JOB.json: `texture` (a file of raw RGBA bytes, rows from the top-left, relative to JOB.json's
 * folder), `width`, `height`, `uv` (N*2 texture coordinates), `groups` (name -> vertex indices),
 * `looks` (per look [[u, v], [u, v]] iris shifts, eye widths). Writes `look_K.rgba` (the painted
 * texture of look K, raw RGBA) beside JOB.json and prints JSON: `same` (per look, whether texture()
 * returned null, the last texture kept) and the milliseconds spent constructing the painter and per
 * texture() call. Used by tests/web/test_web_eyes.py. */

import { readFileSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { LookPainter } from '../src/render/eyes';
import type { Picture } from '../src/render/actor';

interface Job {
  texture: string; width: number; height: number; uv: number[]; groups: Record<string, number[]>;
  looks: [number, number][][];
}

function main(argv: string[]): number {
  if (argv.length !== 1) {
    process.stderr.write('usage: eyes-cli JOB.json\n');
    return 2;
  }
  const dir = dirname(argv[0]);
  const job = JSON.parse(readFileSync(argv[0], 'utf8')) as Job;
  const texture: Picture = { width: job.width, height: job.height, rgba: new Uint8Array(readFileSync(join(dir, job.texture))) };
  const model = { vertices: new Float64Array(0), triangles: new Uint32Array(0), uv: Float64Array.from(job.uv),
    groups: job.groups };
  let t0 = performance.now();
  const painter = new LookPainter(texture, model);
  const construct = performance.now() - t0;
  const same: boolean[] = [], calls: number[] = [];
  let last: Picture | null = null;
  job.looks.forEach((look, k) => {
    t0 = performance.now();
    const out = painter.texture(look);
    calls.push(performance.now() - t0);
    same.push(out === null);
    if (out) last = out;
    if (!last) throw new Error('the first texture() returned null');
    writeFileSync(join(dir, `look_${k}.rgba`), (last as Picture).rgba);
  });
  process.stdout.write(JSON.stringify({ same, construct_ms: construct, texture_ms: calls }) + '\n');
  return 0;
}

process.exitCode = main(process.argv.slice(2));
