//! A monotone priority queue for the loop engine's Dijkstra searches
//! (src/layout/loops.rs): the radix heap of Ahuja, Mehlhorn, Orlin and
//! Tarjan, *Faster algorithms for the shortest path problem* (J. ACM 37,
//! 1990), §2, on 32-bit keys — the bit patterns of non-negative `f32`
//! distances, which order like the distances. Dijkstra only pushes keys at
//! or above the last popped one, so an entry is moved O(32) times at most
//! and a push is O(1), against a binary heap's O(log n) cache-missing
//! sift per push and pop.
//!
//! Deviation: a key below the last popped one (impossible for non-negative
//! weights, kept as a guard) is raised to it, so it pops next.

/// Entries `(key, value)`, popped in non-decreasing key order (ties in no
/// particular, but deterministic, order).
#[derive(Debug, Clone)]
pub struct RadixHeap {
    /// Bucket 0 holds keys equal to `last`; bucket i > 0 keys whose highest
    /// bit differing from `last` is bit i − 1.
    buckets: [Vec<(u32, u32)>; 33],
    last: u32,
    len: usize,
}

impl Default for RadixHeap {
    fn default() -> Self {
        RadixHeap {
            buckets: std::array::from_fn(|_| Vec::new()),
            last: 0,
            len: 0,
        }
    }
}

impl RadixHeap {
    #[inline]
    fn bucket(last: u32, key: u32) -> usize {
        32 - (key ^ last).leading_zeros() as usize
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Empties the heap (keeping its memory); the next keys may be any.
    pub fn clear(&mut self) {
        for b in &mut self.buckets {
            b.clear();
        }
        self.last = 0;
        self.len = 0;
    }

    #[inline]
    pub fn push(&mut self, key: u32, value: u32) {
        let key = key.max(self.last);
        self.buckets[Self::bucket(self.last, key)].push((key, value));
        self.len += 1;
    }

    /// The entry with the smallest key.
    #[inline]
    pub fn pop(&mut self) -> Option<(u32, u32)> {
        if self.len == 0 {
            return None;
        }
        if self.buckets[0].is_empty() {
            let i = (1..33).find(|&i| !self.buckets[i].is_empty())?;
            let moved = std::mem::take(&mut self.buckets[i]);
            self.last = moved.iter().map(|e| e.0).min().unwrap_or(self.last);
            for &(k, v) in &moved {
                self.buckets[Self::bucket(self.last, k)].push((k, v));
            }
            // Keep the emptied bucket's memory.
            let mut moved = moved;
            moved.clear();
            self.buckets[i] = moved;
        }
        self.len -= 1;
        self.buckets[0].pop()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::{RngCore, SeedableRng};
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;

    /// A Dijkstra-like sequence (each push at or above the last pop): the
    /// keys come out in the order of a binary heap's.
    #[test]
    fn pops_in_the_order_of_a_binary_heap() {
        let mut rng = rand_pcg::Pcg32::seed_from_u64(3);
        let mut radix = RadixHeap::default();
        let mut reference = BinaryHeap::new();
        let mut last = 0.0f32;
        for round in 0..20_000 {
            let pushes = if round < 10 {
                5
            } else {
                (rng.next_u32() % 3) as usize
            };
            for _ in 0..pushes {
                let d = last + (rng.next_u32() % 1000) as f32 * 1e-3;
                let v = rng.next_u32();
                radix.push(d.to_bits(), v);
                reference.push(Reverse(d.to_bits()));
            }
            match (radix.pop(), reference.pop()) {
                (Some((k, _)), Some(Reverse(r))) => {
                    assert_eq!(k, r, "round {round}");
                    last = f32::from_bits(k);
                }
                (None, None) => {}
                (a, b) => panic!("round {round}: {a:?} vs {b:?}"),
            }
            assert_eq!(radix.len(), reference.len());
        }
        radix.clear();
        assert!(radix.is_empty() && radix.pop().is_none());
        radix.push(7, 1);
        assert_eq!(radix.pop(), Some((7, 1)));
    }
}
