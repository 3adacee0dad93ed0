//! An indexed 4-ary heap of patches by a key (unshot flux, unshot radiosity): the books'
//! queues ([`super::books`]). A patch is in it at most once and moves when its key changes, so
//! picking a shooter costs O(log patches), never a scan, and no stale entry is popped (an
//! earlier design pushed a new entry per change: on a million patches a sixth of the
//! shooting's time went into popping them).

use std::cmp::Ordering;

/// A heap entry: a key and the patch it was computed for; ordered by key, ties to the lower
/// patch number.
#[derive(Clone, Copy, PartialEq)]
pub(super) struct Entry(pub f64, pub u32);
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        self.0.total_cmp(&o.0).then(o.1.cmp(&self.1))
    }
}

/// Max-heap of patches by a key, indexed: each patch is in it at most once, at the position
/// `pos` records, so a key that changes is moved in place (O(log patches)) rather than
/// pushed again. Ties go to the lower patch number ([`Entry`]'s order). A patch whose key
/// changed without [`Self::set`] (a shooter, zeroed when taken) is put right when it comes
/// to the top ([`Self::peek`]).
#[derive(Default)]
pub(super) struct KeyHeap {
    heap: Vec<Entry>,
    /// Position of each patch in `heap`; [`ABSENT`] when it is not in it.
    pos: Vec<u32>,
}

/// [`KeyHeap::pos`] of a patch not in the heap.
const ABSENT: u32 = u32::MAX;

/// Children per node: a 4-ary heap is half as deep as a binary one, and a node's four
/// children (16 bytes each) share a cache line. The top is the largest entry whatever the
/// arity (keys and ties make a total order), so the solver's shots are the same.
const ARITY: usize = 4;

impl KeyHeap {
    pub(super) fn with_patches(n: usize) -> KeyHeap {
        KeyHeap {
            heap: Vec::new(),
            pos: vec![ABSENT; n],
        }
    }

    /// Patch `i`'s key is now `key`: inserted, moved, or (key ≤ 0) taken out.
    pub(super) fn set(&mut self, key: f64, i: usize) {
        if key <= 0.0 {
            self.remove(i);
            return;
        }
        let e = Entry(key, i as u32);
        match self.pos[i] {
            ABSENT => {
                self.heap.push(e);
                self.pos[i] = (self.heap.len() - 1) as u32;
                self.up(self.heap.len() - 1);
            }
            p => {
                let p = p as usize;
                let old = std::mem::replace(&mut self.heap[p], e);
                if e > old {
                    self.up(p);
                } else {
                    self.down(p);
                }
            }
        }
    }

    /// Takes patch `i` out, if it is in.
    pub(super) fn remove(&mut self, i: usize) {
        let p = self.pos[i];
        if p == ABSENT {
            return;
        }
        let p = p as usize;
        self.pos[i] = ABSENT;
        let last = self
            .heap
            .pop()
            .expect("a patch with a position is in the heap");
        if p < self.heap.len() {
            self.heap[p] = last;
            self.pos[last.1 as usize] = p as u32;
            self.up(p);
            self.down(self.pos[last.1 as usize] as usize);
        }
    }

    /// The top entry, its key checked against `key_of` (and put right first where stale).
    pub(super) fn peek(&mut self, key_of: impl Fn(usize) -> f64) -> Option<Entry> {
        while let Some(&top) = self.heap.first() {
            let key = key_of(top.1 as usize);
            if key == top.0 {
                return Some(top);
            }
            self.set(key, top.1 as usize);
        }
        None
    }

    /// Takes the top entry out.
    pub(super) fn pop(&mut self) {
        if let Some(top) = self.heap.first() {
            self.remove(top.1 as usize);
        }
    }

    /// Moves the entry at `k` up past the parents smaller than it (each moved down a place
    /// into the hole it leaves).
    fn up(&mut self, mut k: usize) {
        let e = self.heap[k];
        while k > 0 {
            let parent = (k - 1) / ARITY;
            if e <= self.heap[parent] {
                break;
            }
            self.put(k, self.heap[parent]);
            k = parent;
        }
        self.put(k, e);
    }

    /// Moves the entry at `k` down past its largest child while that child is larger.
    fn down(&mut self, mut k: usize) {
        let n = self.heap.len();
        let e = self.heap[k];
        loop {
            let first = ARITY * k + 1;
            if first >= n {
                break;
            }
            let mut big = first;
            for c in first + 1..(first + ARITY).min(n) {
                if self.heap[c] > self.heap[big] {
                    big = c;
                }
            }
            if self.heap[big] <= e {
                break;
            }
            self.put(k, self.heap[big]);
            k = big;
        }
        self.put(k, e);
    }

    fn put(&mut self, k: usize, e: Entry) {
        self.heap[k] = e;
        self.pos[e.1 as usize] = k as u32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The indexed heap gives the same top as a scan over the current keys, whatever mix of
    /// inserts, moves up and down, removals and pops, ties to the lower patch number; a key
    /// lowered without `set` (as a shooter's is, zeroed when taken) is put right at the top.
    #[test]
    fn key_heap_top_is_the_largest_current_key() {
        let n = 200;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut keys = vec![0.0f64; n];
        let mut heap = KeyHeap::with_patches(n);
        for step in 0..20_000 {
            let i = rng.gen_range(0..n);
            match rng.gen_range(0..6) {
                // Few distinct keys, so ties are common.
                0 | 1 => {
                    keys[i] = rng.gen_range(0..8) as f64;
                    heap.set(keys[i], i);
                    assert_eq!(heap.pos[i] != ABSENT, keys[i] > 0.0, "step {step}");
                }
                2 => {
                    keys[i] = 0.0;
                    heap.remove(i);
                }
                3 => keys[i] *= 0.5,
                4 => keys[i] = 0.0,
                _ => {
                    if let Some(top) = heap.peek(|j| keys[j]) {
                        keys[top.1 as usize] = 0.0;
                        heap.pop();
                    }
                }
            }
            let want = (0..n)
                .filter(|&j| keys[j] > 0.0)
                .map(|j| Entry(keys[j], j as u32))
                .max();
            let got = heap.peek(|j| keys[j]);
            assert_eq!(got.map(|e| e.1), want.map(|e| e.1), "step {step}");
        }
    }
}
