// Bundles the browser receiver (src/main.ts) into python/facemime/web/receiver.js, which the
// Python package serves. `node build.mjs --check` rebuilds in memory and exits 1 when the
// committed file differs (for CI).
import { build } from 'esbuild';
import { mkdir, readFile, writeFile } from 'node:fs/promises';
import { dirname, join, relative } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const target = join(here, '..', 'python', 'facemime', 'web', 'receiver.js');
const check = process.argv.includes('--check');

const result = await build({
  entryPoints: [join(here, 'src', 'main.ts')],
  absWorkingDir: here,
  bundle: true,
  format: 'iife',
  target: 'es2020',
  minify: false,
  sourcemap: false,
  charset: 'utf8',
  legalComments: 'none',
  write: false,
  logLevel: 'warning',
  outfile: target,
});
const code = result.outputFiles[0].contents;
const name = relative(join(here, '..'), target);

if (check) {
  const committed = await readFile(target).catch(() => null);
  if (committed === null || Buffer.compare(Buffer.from(code), committed) !== 0) {
    console.error(`${name} is out of date: run \`npm run build\` in web/ and commit it`);
    process.exit(1);
  }
  console.log(`${name} is up to date`);
} else {
  await mkdir(dirname(target), { recursive: true });
  await writeFile(target, code);
  console.log(`wrote ${name} (${code.length} bytes)`);
}
