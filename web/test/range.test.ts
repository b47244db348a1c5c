/** The range decoder's tables and contexts (docs/bitstream.md, "Tables"). */

import assert from 'node:assert/strict';
import { test } from 'node:test';
import { Context, INTRA_TABLE, RangeDecoder, startingFrequencies, tableFromFrequencies, uniformTable }
  from '../src/stream/range';

test('tables: 1 + f (4096 - n) / T each, the rest to the most frequent (the first on ties)', () => {
  assert.deepEqual(Array.from(tableFromFrequencies([1, 1, 1])), [0, 1366, 2731, 4096]);
  assert.deepEqual(Array.from(tableFromFrequencies([5, 9, 9, 1])), [0, 853, 2390, 3925, 4096]);
  assert.deepEqual(Array.from(uniformTable(2)), [0, 1024, 2048, 3072, 4096]);
  assert.deepEqual(startingFrequencies(0).slice(10, 16), [13, 235, 4096, 235, 13, 1]);
  assert.deepEqual(Array.from(INTRA_TABLE.subarray(25)), [3999, 4096]);
});

test('a context halves its frequencies once the total exceeds 2^24, not when it reaches it', () => {
  // T0 + (T0 >> 4) = 2^24 exactly: no halving after the first update; the second shows it
  const c = new Context([15790321 - 2001, 1000, 1001]);
  c.update(0);
  c.update(1);
  assert.deepEqual(Array.from(c.table), [0, 3867, 4095, 4096]); // docs' rule, by the reference decoder
  const flags = Context.flags();
  assert.deepEqual(Array.from(flags.table.subarray(0, 3)), [0, 66, 2116]);
  flags.update(3); // by 992 >> 4 = 62
  assert.deepEqual(Array.from(flags.table.subarray(0, 5)), [0, 62, 1997, 2059, 2360]);
});

test('the range decoder reads past the payload as zeros and refuses a quantile of 4096 or more', () => {
  const table = uniformTable(1);
  const empty = new RangeDecoder(new Uint8Array(0)); // point 0
  assert.deepEqual([empty.symbol(table), empty.symbol(table), empty.symbol(uniformTable(12))], [0, 0, 0]);
  const high = new RangeDecoder(new Uint8Array([0xff, 0x7f])); // point 0x7fff0000: just below the half
  assert.equal(high.symbol(table), 0);
  assert.equal(new RangeDecoder(new Uint8Array([0x00, 0x80])).symbol(table), 1);
  // point 2^32 - 1: (2^32 - 1) / ((2^32 - 1) >> 12) = 4096
  assert.throws(() => new RangeDecoder(new Uint8Array([0xff, 0xff, 0xff, 0xff])).symbol(table));
  assert.throws(() => new RangeDecoder(new Uint8Array(3)));
});
