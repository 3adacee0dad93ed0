//! An indexed 4-ary heap of patches by a key (unshot flux, unshot radiosity): the books'
//! queues ([`super::books`]). A patch is in it at most once and moves when its key changes, so
//! picking a shooter costs O(log patches), never a scan, and no stale entry is popped (an
//! earlier design pushed a new entry per change: on a million patches a sixth of the
//! shooting's time went into popping them).
//!
//! **Hot and cold.** Only the patches whose key is at least a *floor* are kept in order (the
//! hot ones, about [`hot_size`] of them); a change to a key below it costs one comparison.
//! The top of the heap is then the largest key of all as long as it is at or above the floor;
//! when it falls below (the hot patches shot), the heap is rebuilt from every patch's current
//! key with a new floor, the [`hot_size`]-th largest key — O(patches), a scan in memory order,
//! once per [`hot_size`] shooters or so. So the top, and the shooters' order, are exactly what
//! one heap of every patch gives; a wave's deposits, most of them on patches far from being
//! shot, no longer sift through a heap of a million (docs/results/hot-queues.md).

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
/// to the top ([`Self::peek`]). Only keys at or above `floor` are kept in order (module
/// notes): below it an entry may be missing or stale, which [`Self::peek`] allows for.
pub(super) struct KeyHeap {
    heap: Vec<Entry>,
    /// Position of each patch in `heap`; [`ABSENT`] when it is not in it.
    pos: Vec<u32>,
    /// Every patch whose current key is at least this (and positive) is in `heap` with that
    /// key; 0 until the heap first grows past twice `hot` ([`Self::trim`]).
    floor: f64,
    /// How many patches a rebuild keeps hot.
    hot: usize,
    /// [`Self::trim`] rebuilds past this many entries: twice what the last rebuild left
    /// (at least twice `hot`; more where keys tie the floor), so a heap of ties is not
    /// rebuilt after every batch.
    limit: usize,
}

/// [`KeyHeap::pos`] of a patch not in the heap.
const ABSENT: u32 = u32::MAX;

/// Children per node: a 4-ary heap is half as deep as a binary one, and a node's four
/// children (16 bytes each) share a cache line. The top is the largest entry whatever the
/// arity (keys and ties make a total order), so the solver's shots are the same.
const ARITY: usize = 4;

/// How many of `n` patches a rebuild keeps hot: a sixteenth, at least 4,096.
pub(super) fn hot_size(n: usize) -> usize {
    (n / 16).max(4096)
}

impl KeyHeap {
    pub(super) fn with_patches(n: usize) -> KeyHeap {
        KeyHeap::with_hot(n, hot_size(n))
    }

    /// A heap of `n` patches that keeps `hot` of them in order.
    pub(super) fn with_hot(n: usize, hot: usize) -> KeyHeap {
        KeyHeap {
            heap: Vec::new(),
            pos: vec![ABSENT; n],
            floor: 0.0,
            hot: hot.max(1),
            limit: 2 * hot.max(1),
        }
    }

    /// Patch `i`'s key is now `key`: inserted, moved, or (key ≤ 0) taken out; below the
    /// floor, left as it is (cold).
    pub(super) fn set(&mut self, key: f64, i: usize) {
        if key <= 0.0 {
            self.remove(i);
            return;
        }
        if key < self.floor {
            return;
        }
        self.place(key, i);
    }

    /// Patch `i` (key > 0) put in at `key`, or moved there.
    fn place(&mut self, key: f64, i: usize) {
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

    /// Rebuilds the heap when it holds more than twice what the last rebuild left (after a
    /// batch of [`Self::set`]s), `key_of` giving every patch's current key.
    pub(super) fn trim(&mut self, key_of: impl Fn(usize) -> f64) {
        if self.heap.len() > self.limit {
            self.rebuild(&key_of);
        }
    }

    /// The heap of the patches whose key is at least the new floor: the `hot`-th largest
    /// positive key (0 when there are no more positive keys than `hot`).
    fn rebuild(&mut self, key_of: &impl Fn(usize) -> f64) {
        for e in &self.heap {
            self.pos[e.1 as usize] = ABSENT;
        }
        // One pass over the keys: every patch with a positive key, then the hot ones kept.
        let mut heap = std::mem::take(&mut self.heap);
        heap.clear();
        heap.extend((0..self.pos.len()).filter_map(|i| {
            let k = key_of(i);
            (k > 0.0).then_some(Entry(k, i as u32))
        }));
        self.floor = if heap.len() <= self.hot {
            0.0
        } else {
            let at = heap.len() - self.hot;
            heap.select_nth_unstable_by(at, |a, b| a.0.total_cmp(&b.0));
            let floor = heap[at].0;
            heap.retain(|e| e.0 >= floor);
            floor
        };
        for (k, e) in heap.iter().enumerate() {
            self.pos[e.1 as usize] = k as u32;
        }
        self.heap = heap;
        self.limit = 2 * self.heap.len().max(self.hot);
        // Floyd's heap construction: every inner node sifted down, the last first.
        for k in (0..self.heap.len().div_ceil(ARITY)).rev() {
            self.down(k);
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

    /// The top entry, its key checked against `key_of` (and put right first where stale):
    /// the largest current key of all patches. A top below the floor, or an empty heap above
    /// a floor, means a cold patch may be larger: the heap is rebuilt first.
    pub(super) fn peek(&mut self, key_of: impl Fn(usize) -> f64) -> Option<Entry> {
        loop {
            let Some(&top) = self.heap.first() else {
                if self.floor > 0.0 {
                    self.rebuild(&key_of);
                    continue;
                }
                return None;
            };
            let key = key_of(top.1 as usize);
            if key != top.0 {
                if key > 0.0 {
                    self.place(key, top.1 as usize);
                } else {
                    self.remove(top.1 as usize);
                }
                continue;
            }
            if key < self.floor {
                self.rebuild(&key_of);
                continue;
            }
            return Some(top);
        }
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
    /// lowered without `set` (as a shooter's is, zeroed when taken) is put right at the top;
    /// with few patches hot, as with all of them.
    #[test]
    fn key_heap_top_is_the_largest_current_key() {
        let n = 200;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        // Every patch hot (never rebuilt), and 8 of 200 hot (rebuilt again and again).
        for hot in [n, 8] {
            let mut heap = KeyHeap::with_hot(n, hot);
            let floor = top_stays_the_largest(&mut heap, &mut rng);
            assert_eq!(floor > 0.0, hot < n, "{hot}");
        }
    }

    /// Random sets, removals, keys halved or zeroed without `set`, pops and trims: after
    /// each, `peek` gives the largest current key. Returns the highest floor there was.
    fn top_stays_the_largest(heap: &mut KeyHeap, rng: &mut rand_pcg::Pcg64) -> f64 {
        let mut floor = 0.0f64;
        let n = heap.pos.len();
        let mut keys = vec![0.0f64; n];
        for step in 0..20_000 {
            let i = rng.gen_range(0..n);
            match rng.gen_range(0..6) {
                // Few distinct keys, so ties are common.
                0 | 1 => {
                    keys[i] = rng.gen_range(0..8) as f64;
                    heap.set(keys[i], i);
                    if keys[i] >= heap.floor {
                        assert_eq!(heap.pos[i] != ABSENT, keys[i] > 0.0, "step {step}");
                    }
                    if step % 7 == 0 {
                        heap.trim(|j| keys[j]);
                    }
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
            floor = floor.max(heap.floor);
        }
        floor
    }
}
