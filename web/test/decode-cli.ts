/** Decodes a facemime stream and prints JSON Lines, one per event, then the stats:
 *
 *     node .test-build/decode-cli.mjs [--live] [--piece N] [FILE | -]
 *
 * `--live`: a receiver joining a live stream (fromStart false); `--piece N`: push N bytes at a
 * time (default: the whole stream in one push), then finish. Frames: index, face, lost, q,
 * values, concealed; appearance: the payload's length, CRC-32 and `after`, the frames output
 * before it; the last line: the stats. Used by tests/web/test_web_decoder.py. */

import { readFileSync } from 'node:fs';
import { crc32, StreamDecoder, type Event } from '../src/stream/index';

function main(argv: string[]): number {
  let live = false;
  let piece = 0;
  let file = '-';
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === '--live') live = true;
    else if (argv[i] === '--piece') piece = Number(argv[++i]);
    else file = argv[i];
  }
  if (!Number.isInteger(piece) || piece < 0) {
    process.stderr.write('usage: decode-cli [--live] [--piece N] [FILE | -]\n');
    return 2;
  }
  const data = new Uint8Array(readFileSync(file === '-' ? 0 : file));
  const dec = new StreamDecoder(!live);
  const lines: string[] = [];
  let output = 0; // frames output so far
  const emit = (events: Event[]) => {
    for (const e of events) {
      if (e.kind === 'frame') {
        const f = e.frame;
        lines.push(JSON.stringify({ kind: 'frame', index: f.index, face: f.face, lost: f.lost, q: Array.from(f.q),
          values: Array.from(f.values), concealed: f.concealed }));
        output++;
      } else if (e.kind === 'appearance') {
        lines.push(JSON.stringify({ kind: 'appearance', length: e.payload.length, crc: crc32(e.payload), after: output }));
      } else if (e.kind === 'actor') {
        lines.push(JSON.stringify({ kind: 'actor', length: e.data.length }));
      } else {
        const h = e.header;
        lines.push(JSON.stringify({ kind: 'header', version: h.version, fps: h.fps, size: [h.width, h.height],
          packet_frames: h.packetFrames, keyframe_packets: h.keyframePackets, steps: h.steps,
          references: h.references, classes: h.classes, extras: h.extras, basis_length: h.basisLength,
          actor_in_stream: h.actorInStream }));
      }
    }
  };
  const step = piece > 0 ? piece : Math.max(data.length, 1);
  for (let at = 0; at < data.length; at += step) emit(dec.push(data.subarray(at, at + step)));
  emit(dec.finish());
  lines.push(JSON.stringify({ kind: 'stats', ...dec.stats, header_error: dec.headerError }));
  process.stdout.write(lines.join('\n') + '\n');
  return 0;
}

process.exitCode = main(process.argv.slice(2));
