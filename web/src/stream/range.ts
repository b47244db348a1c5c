/** Entropy decoding (docs/bitstream.md, "Range decoding", "Tables"): the range decoder with
 * 32-bit state and 12-bit probabilities over 16-bit words, frequency tables, the value table
 * with its escape, and adaptive contexts. Integer arithmetic only: every decoder gets the same
 * probabilities. */

/** Bits of the tables' probabilities: every table sums to 2^12. */
export const PRECISION = 12;
const ONE = 1 << PRECISION;
/** Values in -RADIUS..RADIUS are one symbol of a value table; others escape. */
export const RADIUS = 12;
/** Symbols of a value table: 25 values and the escape. */
export const ALPHABET = 2 * RADIUS + 2;
/** The escape symbol of a value table. */
export const ESCAPE = ALPHABET - 1;
/** Spread classes of the starting tables. */
export const CLASSES = 16;
/** Per class, the ratio of neighbouring starting frequencies, x65536. */
export const DECAY: readonly number[] = [
  3764, 6909, 11147, 16245, 21852, 27600, 33170, 38337, 42966, 47001, 50443, 53330, 55718, 57674, 59263, 60544,
];
/** Symbols of the frame-flags table: bit 0 a face, bits 1-4 the features lost. */
export const FLAG_SYMBOLS = 32;
/** A context's frequencies are halved once their total exceeds this. */
const LIMIT = 1 << 24;

/** A payload the range decoder cannot read (no encoder writes it). */
export class InvalidPayload extends Error {}

/** A table: cumulative frequencies, `cdf[0] = 0 < ... < cdf[n] = 4096`. */
export type Table = Uint16Array;

/** The table of integer frequencies `freq` (each >= 1): symbol s gets
 * `1 + floor(f_s * (4096 - n) / T)`, the most frequent (first on ties) also what is left. */
export function tableFromFrequencies(freq: ArrayLike<number>): Table {
  const n = freq.length;
  let total = 0;
  for (let s = 0; s < n; s++) total += freq[s];
  const spare = ONE - n;
  const probs = new Array<number>(n);
  let used = 0;
  let top = 0;
  for (let s = 0; s < n; s++) {
    // f * spare < 2^53 and the quotient < 2^12: the float division floors exactly
    probs[s] = 1 + Math.floor((freq[s] * spare) / total);
    used += probs[s];
    if (freq[s] > freq[top]) top = s;
  }
  probs[top] += ONE - used;
  const cdf = new Uint16Array(n + 1);
  let acc = 0;
  for (let s = 0; s < n; s++) {
    acc += probs[s];
    cdf[s + 1] = acc;
  }
  return cdf;
}

/** The uniform table over 2^bits symbols (bits <= 12). */
export function uniformTable(bits: number): Table {
  const share = 1 << (PRECISION - bits);
  const cdf = new Uint16Array((1 << bits) + 1);
  for (let s = 0; s <= 1 << bits; s++) cdf[s] = s * share;
  return cdf;
}

/** The uniform tables of 0-12 bits. */
export const UNIFORM: readonly Table[] = Array.from({ length: PRECISION + 1 }, (_, b) => uniformTable(b));

/** The starting frequencies of spread class `c` (0-15): f(0) = 4096,
 * f(k) = max(1, f(k-1) * D_c >> 16), symbol 12 +- k getting f(k), the escape max(1, f(12)). */
export function startingFrequencies(c: number): number[] {
  const f = new Array<number>(ALPHABET).fill(0);
  let level = 4096;
  f[RADIUS] = level;
  for (let k = 1; k <= RADIUS; k++) {
    level = Math.max(1, Math.floor((level * DECAY[c]) / 65536));
    f[RADIUS + k] = level;
    f[RADIUS - k] = level;
  }
  f[ESCAPE] = Math.max(1, level);
  return f;
}

/** The intra table: the starting table of class 15, never adapted. */
export const INTRA_TABLE: Table = tableFromFrequencies(startingFrequencies(CLASSES - 1));

/** An adaptive table: after each symbol its frequency grows by `max(1, T0 >> 4)`; once the
 * total exceeds 2^24 every frequency becomes `(f + 1) >> 1`. */
export class Context {
  private readonly freq: number[];
  private total: number;
  private readonly step: number;
  /** The table to decode the next symbol with. */
  table: Table;

  constructor(freq: ArrayLike<number>) {
    this.freq = Array.from(freq);
    this.total = this.freq.reduce((a, b) => a + b, 0);
    this.step = Math.max(1, this.total >> 4);
    this.table = tableFromFrequencies(this.freq);
  }

  /** The value context of spread class `c`. */
  static values(c: number): Context {
    return new Context(startingFrequencies(c));
  }

  /** The frame-flags context: 16 for every symbol, 496 for symbol 1 (a face, nothing lost). */
  static flags(): Context {
    const f = new Array<number>(FLAG_SYMBOLS).fill(16);
    f[1] = 16 * (FLAG_SYMBOLS - 1);
    return new Context(f);
  }

  /** Learns that `symbol` was decoded. */
  update(symbol: number): void {
    this.freq[symbol] += this.step;
    this.total += this.step;
    if (this.total > LIMIT) {
      this.total = 0;
      for (let s = 0; s < this.freq.length; s++) {
        this.freq[s] = (this.freq[s] + 1) >> 1;
        this.total += this.freq[s];
      }
    }
    this.table = tableFromFrequencies(this.freq);
  }
}

/** The range decoder of one packet's payload (16-bit little-endian words). */
export class RangeDecoder {
  private readonly words: Uint16Array;
  private next: number;
  private lower = 0;
  private range = 0xffffffff;
  private point: number;

  /** Throws InvalidPayload for an odd payload length. */
  constructor(payload: Uint8Array) {
    if (payload.length % 2 !== 0) throw new InvalidPayload("a packet's payload has an odd length");
    const n = payload.length / 2;
    this.words = new Uint16Array(n);
    for (let i = 0; i < n; i++) this.words[i] = payload[2 * i] | (payload[2 * i + 1] << 8);
    this.point = n >= 2 ? ((this.words[0] << 16) | this.words[1]) >>> 0 : n === 1 ? (this.words[0] << 16) >>> 0 : 0;
    this.next = Math.min(n, 2);
  }

  /** Decodes one symbol with `cdf`; throws InvalidPayload when the quantile is >= 4096. */
  symbol(cdf: Table): number {
    const scale = this.range >>> PRECISION;
    const quantile = Math.floor(((this.point - this.lower) >>> 0) / scale);
    if (quantile >= ONE) throw new InvalidPayload('range decoder: invalid data');
    // the last s with cdf[s] <= quantile
    let lo = 0;
    let hi = cdf.length - 2;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (cdf[mid] <= quantile) lo = mid;
      else hi = mid - 1;
    }
    const s = lo;
    this.lower = (this.lower + scale * cdf[s]) >>> 0;
    this.range = scale * (cdf[s + 1] - cdf[s]);
    if (this.range < 0x10000) {
      this.lower = (this.lower << 16) >>> 0;
      this.range = (this.range << 16) >>> 0;
      const w = this.next < this.words.length ? this.words[this.next] : 0;
      this.next++;
      this.point = ((this.point << 16) | w) >>> 0;
    }
    return s;
  }

  /** Decodes an integer with value table `cdf`: the value and the table's symbol (the escape's
   * extra symbols are uniform: sign, bit length n of m = |v| - 13, then m's n - 1 low bits in
   * chunks of at most 12, most significant first). */
  value(cdf: Table): { value: number; symbol: number } {
    const symbol = this.symbol(cdf);
    if (symbol !== ESCAPE) return { value: symbol - RADIUS, symbol };
    const negative = this.symbol(UNIFORM[1]) === 1;
    const n = this.symbol(UNIFORM[5]);
    let m = n === 0 ? 0 : 1;
    let left = Math.max(n - 1, 0);
    while (left > 0) {
      const b = Math.min(left, PRECISION);
      m = m * 2 ** b + this.symbol(UNIFORM[b]);
      left -= b;
    }
    const magnitude = m + RADIUS + 1;
    return { value: negative ? -magnitude : magnitude, symbol };
  }
}
