//! The entropy models of the bitstream (`docs/bitstream.md`, "Entropy models"): integer
//! frequency tables, normalised to `2^PRECISION` for the range coder, and the adaptive
//! per-parameter contexts built on them. Everything here is integer arithmetic, so that any
//! decoder written from the specification reproduces the same probabilities.

use std::num::NonZeroU16;

use constriction::stream::model::{DecoderModel, EncoderModel, EntropyModel};

/// Bits of the coder's fixed-point probabilities: every table sums to `1 << PRECISION`.
pub const PRECISION: usize = 12;
/// Values in `-RADIUS..=RADIUS` are coded as one symbol; larger ones escape.
pub const RADIUS: i32 = 12;
/// Symbols of a value table: `2 * RADIUS + 1` values and the escape.
pub const ALPHABET: usize = 2 * RADIUS as usize + 2;
/// The escape symbol of a value table.
pub const ESCAPE: usize = ALPHABET - 1;
/// Spread classes of a parameter's starting table.
pub const CLASSES: usize = 16;
/// Per class, the ratio of neighbouring frequencies of its starting table, ×65536: a
/// two-sided geometric (discrete Laplacian) whose mean absolute value grows ×1.27 per class,
/// from 0.35 (class 0) to 12.6 (class 15) quantiser steps.
pub const DECAY: [u32; CLASSES] = [
    3764, 6909, 11147, 16245, 21852, 27600, 33170, 38337, 42966, 47001, 50443, 53330, 55718, 57674,
    59263, 60544,
];
/// Mean absolute value of each class's distribution, in quantiser steps (informative: how an
/// encoder picks a class; decoders never need it).
pub fn class_spread(class: usize) -> f64 {
    0.35 * 1.27f64.powi(class as i32)
}
/// Symbols of the frame-flags table: bit 0 = face present, bits 1..=4 = features lost.
pub const FLAG_SYMBOLS: usize = 32;
/// A context's frequencies are halved once their total exceeds this.
const LIMIT: u32 = 1 << 24;

/// A probability table: cumulative frequencies, `cdf[0] = 0`, `cdf[n] = 1 << PRECISION`, every
/// symbol's share at least 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    cdf: Vec<u16>,
}

impl Table {
    /// The normalised table of frequencies `freq` (each ≥ 1, at most 2^12 symbols): symbol `s`
    /// gets `1 + floor(freq[s] * (2^12 - n) / total)`, and what is left of `2^12` goes to the
    /// most frequent symbol (the first one on ties).
    pub fn from_frequencies(freq: &[u32]) -> Table {
        let n = freq.len() as u64;
        let total: u64 = freq.iter().map(|&f| f as u64).sum();
        let spare = (1u64 << PRECISION) - n;
        let mut probs: Vec<u64> = freq.iter().map(|&f| 1 + f as u64 * spare / total).collect();
        let used: u64 = probs.iter().sum();
        let mut top = 0;
        for (s, &f) in freq.iter().enumerate() {
            if f > freq[top] {
                top = s;
            }
        }
        probs[top] += (1u64 << PRECISION) - used;
        let mut cdf = Vec::with_capacity(freq.len() + 1);
        let mut acc = 0u64;
        cdf.push(0);
        for p in probs {
            acc += p;
            cdf.push(acc as u16);
        }
        Table { cdf }
    }

    /// The uniform table over `1 << bits` symbols (`bits` ≤ 12).
    pub fn uniform(bits: u32) -> Table {
        let share = 1u32 << (PRECISION as u32 - bits);
        Table {
            cdf: (0..=(1u32 << bits)).map(|s| (s * share) as u16).collect(),
        }
    }

    /// Number of symbols.
    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    /// Whether the table has no symbols (never, for the tables built here).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl EntropyModel<PRECISION> for Table {
    type Symbol = usize;
    type Probability = u16;
}

impl EncoderModel<PRECISION> for Table {
    fn left_cumulative_and_probability(
        &self,
        symbol: impl std::borrow::Borrow<usize>,
    ) -> Option<(u16, NonZeroU16)> {
        let s = *symbol.borrow();
        let (lo, hi) = (*self.cdf.get(s)?, *self.cdf.get(s + 1)?);
        Some((lo, NonZeroU16::new(hi - lo)?))
    }
}

impl DecoderModel<PRECISION> for Table {
    fn quantile_function(&self, quantile: u16) -> (usize, u16, NonZeroU16) {
        // the last symbol whose left edge is at or below the quantile; cdf[0] = 0 ≤ quantile
        // < 2^12 = cdf[n], and every share is ≥ 1, so the found symbol's share is nonzero
        let s = self.cdf.partition_point(|&c| c <= quantile) - 1;
        let s = s.min(self.len() - 1);
        let (lo, hi) = (self.cdf[s], self.cdf[s + 1]);
        (s, lo, NonZeroU16::new(hi - lo).unwrap_or(NonZeroU16::MIN))
    }
}

/// The starting frequencies of a value table of spread `class` (< [`CLASSES`]): `f(0) = 4096`,
/// `f(k) = max(1, f(k-1) * DECAY[class] >> 16)` for `k = 1..=RADIUS`, symbol `v + RADIUS`
/// getting `f(|v|)`, and the escape `max(1, f(RADIUS))`.
pub fn starting_frequencies(class: usize) -> [u32; ALPHABET] {
    let mut f = [0u32; ALPHABET];
    let mut level = 4096u32;
    f[RADIUS as usize] = level;
    for k in 1..=RADIUS as usize {
        level = ((level as u64 * DECAY[class] as u64) >> 16).max(1) as u32;
        f[RADIUS as usize + k] = level;
        f[RADIUS as usize - k] = level;
    }
    f[ESCAPE] = level.max(1);
    f
}

/// An adaptive table: after each coded symbol its frequency grows by a sixteenth of the
/// starting total, and all frequencies are halved (rounding up) once the total exceeds 2^24.
#[derive(Debug, Clone)]
pub struct Context {
    freq: Vec<u32>,
    total: u32,
    step: u32,
    table: Table,
}

impl Context {
    /// A context starting from frequencies `freq` (each ≥ 1).
    pub fn new(freq: &[u32]) -> Context {
        let total = freq.iter().sum::<u32>();
        Context {
            freq: freq.to_vec(),
            total,
            step: (total >> 4).max(1),
            table: Table::from_frequencies(freq),
        }
    }

    /// The value context of spread `class`.
    pub fn values(class: usize) -> Context {
        Context::new(&starting_frequencies(class))
    }

    /// The frame-flags context: 16 for every symbol, 496 for symbol 1 (a face, nothing lost).
    pub fn flags() -> Context {
        let mut f = [16u32; FLAG_SYMBOLS];
        f[1] = 16 * (FLAG_SYMBOLS as u32 - 1);
        Context::new(&f)
    }

    /// The table to code the next symbol with.
    pub fn table(&self) -> &Table {
        &self.table
    }

    /// Learns that `symbol` was coded.
    pub fn update(&mut self, symbol: usize) {
        self.freq[symbol] += self.step;
        self.total += self.step;
        if self.total > LIMIT {
            for f in &mut self.freq {
                *f = (*f + 1) >> 1;
            }
            self.total = self.freq.iter().sum();
        }
        self.table = Table::from_frequencies(&self.freq);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_sum_to_one_and_keep_every_symbol() {
        for class in 0..CLASSES {
            let t = Table::from_frequencies(&starting_frequencies(class));
            assert_eq!(*t.cdf.last().unwrap() as u32, 1 << PRECISION);
            assert!(t.cdf.windows(2).all(|w| w[1] > w[0]));
        }
        let mut c = Context::flags();
        for _ in 0..100_000 {
            c.update(1);
        }
        assert!(c.table().cdf.windows(2).all(|w| w[1] > w[0]));
        assert!(c.table().cdf[2] - c.table().cdf[1] > 3900);
    }

    #[test]
    fn quantile_function_inverts_the_cumulative() {
        let t = Table::from_frequencies(&starting_frequencies(5));
        for q in 0..(1u16 << PRECISION) {
            let (s, lo, p) = t.quantile_function(q);
            assert!(lo <= q && q < lo + p.get());
            assert_eq!(t.left_cumulative_and_probability(s), Some((lo, p)));
        }
    }

    #[test]
    fn wider_classes_spread_their_mass() {
        let share = |c: usize| {
            let t = Table::from_frequencies(&starting_frequencies(c));
            t.left_cumulative_and_probability(RADIUS as usize)
                .unwrap()
                .1
                .get()
        };
        assert!((1..CLASSES).all(|c| share(c) < share(c - 1)));
    }
}
