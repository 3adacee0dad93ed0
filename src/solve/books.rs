//! The shooting solvers' books: per-patch unshot and kept flux, the priority queues that
//! pick the next shooter, and the energy accounts. Shared by the ray shots
//! ([`super::ray_shots`]) and the hemi-cube shots ([`super::cube_shots`]), so every method
//! keeps the same books and stops by the same criterion (Sec. 3, [`super::stopping`]).
//!
//! Picking a shooter costs O(log patches): indexed 4-ary heaps (`key_heap`), one by unshot
//! flux (who shoots next) and one by unshot radiosity (the stopping criterion), not a scan per
//! shot. A patch is in each at most once and moves when its key changes (an earlier design
//! pushed a new entry per change and skipped stale ones: on a million patches a sixth of the
//! shooting's time went into popping them); only the patches near the top are kept in order,
//! the rest rebuilt in when the top reaches them (`KeyHeap`'s hot and cold patches).

use super::estimate::{self, Books, Estimator};
use super::key_heap::KeyHeap;
use super::{scalar, EnergyBalance, SolveStats, TracePoint};
use crate::mesh::Mesh;
use crate::scene::Material;

/// A patch's unshot radiosity (scalar), its key in the max-ΔB queue.
#[inline]
fn key_b(p: &PatchState) -> f64 {
    scalar(&p.unshot) * p.inv_area as f64
}

/// `key` if it is at least `threshold`, else 0 (not in the max-ΔB queue).
#[inline]
fn above(key: f64, threshold: f64) -> f64 {
    if key >= threshold {
        key
    } else {
        0.0
    }
}

/// a += b, per channel.
#[inline]
pub(super) fn add3(a: &mut [f64; 3], b: &[f64; 3]) {
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
}

/// Per-patch solver state, packed into one cache line so applying a hit costs one miss.
/// Energies are f64; ρ and 1/A are stored as f32 (exact enough for a reflectance, and the
/// energy books stay exact because what is absorbed is computed as Φ − ρΦ in f64).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct PatchState {
    /// Unshot flux ΔΦ_j (W).
    pub unshot: [f64; 3],
    /// Flux received and kept (ρ_j × what arrived), W: B_j = E_j + kept/A_j.
    pub kept: [f64; 3],
    pub rho: [f32; 3],
    pub inv_area: f32,
}

/// Per-light channels (`--per-light`, Images 1a/1b): one unshot and one kept flux per light
/// group and patch, `k` groups side by side per patch. A shot sends every channel of its
/// shooter along the same samples, so the channels sum to the combined solution (to rounding)
/// and each one is the solution with only its light on. Absent unless asked for: a solve
/// without it allocates nothing per light.
pub(super) struct Channels {
    pub k: usize,
    pub unshot: Vec<[f64; 3]>,
    pub kept: Vec<[f64; 3]>,
}

/// The solver's mutable state: patches, heaps and energy accounts.
pub(super) struct State {
    pub patches: Vec<PatchState>,
    by_flux: KeyHeap,
    by_b: KeyHeap,
    pub energy: EnergyBalance,
    /// Σ B_j·A_j, for the mean radiosity.
    pub b_flux: [f64; 3],
    touched: Vec<bool>,
    touched_list: Vec<u32>,
    /// Rays cast and applied.
    pub rays: u64,
    /// Hemi-cube cells (form-factor samples) of the shots applied.
    pub cells: u64,
    stop_fraction: f64,
    pub total_area: f64,
    /// Scalar flux taken off the queue to be shot so far.
    pub shot_flux: f64,
    /// Area-weighted mean and largest reflectance (scalar).
    pub rho_mean: f64,
    rho_max: f64,
    /// Of each patch's kept flux, what hemi-cube shots left (scalar), and its sampling
    /// variance Σ ρ·e_cell·kept (see [`super::estimate`]). Empty until a hemi-cube shot lands.
    cube_kept: Vec<f64>,
    cube_var: Vec<f64>,
    pub channels: Option<Channels>,
    /// Scalar flux from the model's own patches that met the back of each one-sided surface
    /// patch (W): where the model's winding loses light (`Solution::back`). The sky's and the
    /// sun's light on backs is a one-sided model's outside, not counted. Empty until a ray
    /// meets a back.
    pub back: Vec<f64>,
}

/// What a checkpoint keeps of the books (`State::save`, `State::restore`): every
/// patch's unshot and kept flux, the hemi-cube share of the kept flux and its variance, the
/// per-light channels, and the energy accounts and counters. [`super::checkpoint`] lays it out
/// in the file.
#[derive(Clone, Debug, Default)]
pub struct Saved {
    pub energy: EnergyBalance,
    /// Σ B_j·A_j, for the mean radiosity.
    pub b_flux: [f64; 3],
    pub rays: u64,
    pub cells: u64,
    pub shot_flux: f64,
    /// Per patch (W, RGB).
    pub unshot: Vec<[f64; 3]>,
    pub kept: Vec<[f64; 3]>,
    /// Per patch, what hemi-cube shots left of the kept flux (scalar) and its variance; empty
    /// until a hemi-cube shot lands.
    pub cube_kept: Vec<f64>,
    pub cube_var: Vec<f64>,
    /// Light channels per patch (0 without `--per-light`), and their unshot and kept flux,
    /// `channels` per patch side by side.
    pub channels: usize,
    pub ch_unshot: Vec<[f64; 3]>,
    pub ch_kept: Vec<[f64; 3]>,
}

impl State {
    /// Every patch's unshot flux is its emission E·A (Sec. 1: the lights shoot first).
    pub fn new(mesh: &Mesh, materials: &[Material], stop_fraction: f64) -> State {
        let n = mesh.patches.len();
        let patches: Vec<PatchState> = mesh
            .patches
            .iter()
            .map(|p| {
                let m = &materials[p.material as usize];
                // Glazing: only the 1 − T of rays that do not go through land, and they
                // carry all its reflection (`RayCaster::with_glazing`). Tinted glazing lets
                // rays through by the mean T too, so a channel it transmits less than the
                // mean may keep more than it receives from the rays that land (ρ_c > 1 − T):
                // not clamped, or that channel's reflection would be biased low. ρ_c + T_c ≤ 1
                // keeps every channel's total below what it receives (docs/design.md §9).
                let land = (1.0 - m.transmittance).max(1e-6);
                let cap = if m.is_tinted() { f64::INFINITY } else { 1.0 };
                PatchState {
                    unshot: m.emission().map(|x| x * p.area),
                    kept: [0.0; 3],
                    rho: m.rho.map(|r| (r / land).min(cap) as f32),
                    inv_area: (1.0 / p.area) as f32,
                }
            })
            .collect();
        let mut st = State {
            patches,
            by_flux: KeyHeap::with_patches(n),
            by_b: KeyHeap::with_patches(n),
            energy: EnergyBalance::default(),
            b_flux: [0.0; 3],
            touched: vec![false; n],
            touched_list: Vec::new(),
            rays: 0,
            cells: 0,
            stop_fraction,
            total_area: mesh.total_area(),
            shot_flux: 0.0,
            rho_mean: 0.0,
            rho_max: 0.0,
            cube_kept: Vec::new(),
            cube_var: Vec::new(),
            channels: None,
            back: Vec::new(),
        };
        let mut rho_area = 0.0;
        for (p, s) in mesh.patches.iter().zip(&st.patches) {
            let r = scalar(&s.rho.map(f64::from));
            rho_area += r * p.area;
            st.rho_max = st.rho_max.max(r);
        }
        st.rho_mean = rho_area / st.total_area.max(f64::MIN_POSITIVE);
        for i in 0..n {
            let p = st.patches[i];
            add3(&mut st.energy.emitted, &p.unshot);
            add3(&mut st.b_flux, &p.unshot);
            let (kf, kb) = (st.key_flux(i), st.key_b(i));
            st.by_flux.set(kf, i);
            st.by_b.set(kb, i);
        }
        st
    }

    #[inline]
    fn key_flux(&self, i: usize) -> f64 {
        scalar(&self.patches[i].unshot)
    }
    #[inline]
    fn key_b(&self, i: usize) -> f64 {
        key_b(&self.patches[i])
    }

    /// Area-weighted mean radiosity (scalar), W/m².
    pub fn mean_b(&self) -> f64 {
        scalar(&self.b_flux) / self.total_area
    }

    /// How much radiosity a unit of unshot radiosity will still add, all bounces counted:
    /// 1/(1 − r), r the share of shot light that came back to be shot again so far (the mean
    /// reflectance before anything was shot). `in_flight`: flux cast but not yet applied.
    /// Sec. 3's criterion is applied to unshot radiosity times this: in a stiff scene
    /// (ρ near 1) unshot light is worth many times itself, and the paper's 0.06 % of unshot
    /// radiosity alone would leave 0.06 %/(1 − ρ) of the answer missing (6 % at ρ = 0.99).
    pub fn amplification(&self, in_flight: f64) -> f64 {
        let kept = scalar(&self.b_flux) - scalar(&self.energy.emitted);
        let shot = self.shot_flux - in_flight;
        let r = if shot > 0.0 && kept > 0.0 {
            kept / shot
        } else {
            self.rho_mean
        };
        1.0 / (1.0 - r.clamp(0.0, self.rho_max.min(0.999_999)))
    }

    /// The share of the emitted light not yet come to rest: unshot, or in flight (`in_flight`,
    /// scalar W); of a sky's or the sun's, only what reached the model counts. The unshot flux comes from the accounts, O(1): Σ B_j·A_j less what has been
    /// taken to be shot (a distant emitter's flux is shot without being held unshot); rounding
    /// makes it differ from the sum over the patches in the last digits.
    pub fn unshot_share(&self, in_flight: f64) -> f64 {
        // Of a distant emitter's light, what missed the model never was in it.
        let emitted = scalar(&self.energy.emitted) - scalar(&self.energy.distant_missed);
        if emitted <= 0.0 {
            // Nothing emitted yet (a sky about to shoot): all of it is still to come.
            return 1.0;
        }
        let held = scalar(&self.b_flux) - self.shot_flux + scalar(&self.energy.distant);
        (held.max(0.0) + in_flight) / emitted
    }

    /// Max unshot radiosity (scalar) over the patches above the stop threshold, from the heap
    /// (0 when none is above it).
    ///
    /// A patch below the threshold now may be left out even if it was above it when last
    /// touched (the queue is rebuilt from the current threshold): whatever is below the
    /// threshold satisfies Sec. 3's stop as 0 does, so the verdict is the same.
    pub fn max_unshot_b(&mut self) -> f64 {
        let threshold = self.b_threshold();
        let patches = &self.patches;
        self.by_b
            .peek(|i| above(key_b(&patches[i]), threshold))
            .map_or(0.0, |e| e.0)
    }

    /// The max-ΔB queue's pruning threshold, f·mean(B)·(1 − ρ_max) (see `finish_batch`).
    fn b_threshold(&self) -> f64 {
        self.stop_fraction * self.mean_b() * (1.0 - self.rho_max)
    }

    /// Is any unshot energy left?
    pub fn has_unshot(&mut self) -> bool {
        let patches = &self.patches;
        self.by_flux.peek(|i| scalar(&patches[i].unshot)).is_some()
    }

    /// The patch with the most unshot flux and that flux (scalar), left on the heap.
    pub fn peek_shooter(&mut self) -> Option<(usize, f64)> {
        let patches = &self.patches;
        let top = self.by_flux.peek(|i| scalar(&patches[i].unshot))?;
        Some((top.1 as usize, top.0))
    }

    /// Takes the patch with the most unshot flux: returns it and its unshot flux (RGB), which
    /// is zeroed here (it is about to be shot).
    pub fn take_shooter(&mut self) -> Option<(usize, [f64; 3])> {
        let (i, flux) = self.peek_shooter()?;
        self.by_flux.pop();
        self.shot_flux += flux;
        Some((i, std::mem::take(&mut self.patches[i].unshot)))
    }

    /// Starts per-light channels: `group[j]` is patch j's light group (`u32::MAX`: not a
    /// light), `k` groups in all; each light's emission starts in its own channel.
    pub fn start_channels(&mut self, group: &[u32], k: usize) {
        let n = self.patches.len();
        let mut ch = Channels {
            k,
            unshot: vec![[0.0; 3]; n * k],
            kept: vec![[0.0; 3]; n * k],
        };
        for (j, &g) in group.iter().enumerate() {
            if (g as usize) < k {
                ch.unshot[j * k + g as usize] = self.patches[j].unshot;
            }
        }
        self.channels = Some(ch);
    }

    /// The shooter's unshot flux per channel, zeroed (call right after `take_shooter`).
    pub fn take_channels(&mut self, i: usize) -> Vec<[f64; 3]> {
        match &mut self.channels {
            Some(ch) => ch.unshot[i * ch.k..(i + 1) * ch.k]
                .iter_mut()
                .map(std::mem::take)
                .collect(),
            None => Vec::new(),
        }
    }

    /// Patch j receives `scale` of every channel of a shot (`shot_ch`, per channel flux),
    /// times `tint` per colour when the ray went through tinted glazing.
    #[inline]
    pub fn deposit_channels(
        &mut self,
        j: usize,
        shot_ch: &[[f64; 3]],
        scale: f64,
        tint: Option<[f64; 3]>,
    ) {
        if let Some(ch) = &mut self.channels {
            let rho = self.patches[j].rho;
            let k = ch.k;
            for (c, phi) in shot_ch.iter().enumerate() {
                for (x, r) in rho.iter().enumerate() {
                    let mut kept = *r as f64 * phi[x] * scale;
                    if let Some(t) = tint {
                        kept *= t[x];
                    }
                    ch.unshot[j * k + c][x] += kept;
                    ch.kept[j * k + c][x] += kept;
                }
            }
        }
    }

    /// Radiosity per channel and patch: B_j^c = E_j (if j is light c) + kept_j^c / A_j.
    pub fn channel_radiosity(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        group: &[u32],
    ) -> Vec<Vec<[f64; 3]>> {
        let Some(ch) = &self.channels else {
            return Vec::new();
        };
        (0..ch.k)
            .map(|c| {
                mesh.patches
                    .iter()
                    .enumerate()
                    .map(|(j, p)| {
                        let e = if group[j] as usize == c {
                            materials[p.material as usize].emission()
                        } else {
                            [0.0; 3]
                        };
                        let g = ch.kept[j * ch.k + c];
                        [0, 1, 2].map(|x| e[x] + g[x] / p.area)
                    })
                    .collect()
            })
            .collect()
    }

    /// Flux `phi` arrives on the front of patch `j`: ρ_j·phi is kept (and will be shot on),
    /// the rest absorbed.
    #[inline]
    pub fn deposit(&mut self, j: usize, phi: &[f64; 3]) {
        let p = &mut self.patches[j];
        for (c, &phi) in phi.iter().enumerate() {
            let kept = p.rho[c] as f64 * phi;
            p.unshot[c] += kept;
            p.kept[c] += kept;
            self.b_flux[c] += kept;
            self.energy.absorbed[c] += phi - kept;
        }
        if !self.touched[j] {
            self.touched[j] = true;
            self.touched_list.push(j as u32);
        }
    }

    /// [`Self::deposit`] from a hemi-cube shot whose cells carry `e_cell` (scalar W) each on
    /// average: also books the sampling variance it adds.
    #[inline]
    pub fn deposit_cube(&mut self, j: usize, phi: &[f64; 3], e_cell: f64) {
        if self.cube_kept.is_empty() {
            self.cube_kept = vec![0.0; self.patches.len()];
            self.cube_var = vec![0.0; self.patches.len()];
        }
        let rho = self.patches[j].rho.map(f64::from);
        let kept = scalar(&[0, 1, 2].map(|c| rho[c] * phi[c]));
        self.cube_kept[j] += kept;
        self.cube_var[j] += scalar(&rho) * e_cell * kept;
        self.deposit(j, phi);
    }

    /// A ray of flux `phi` went through tinted glazing and carries `tinted` on (`phi` × the
    /// product of the panes' T_c / T): the difference is the panes' (absorbed; negative in a
    /// channel the tint favours, which the rays that go through less often make up on
    /// average), so the books close per channel ray by ray (docs/design.md §9).
    #[inline]
    pub fn tint(&mut self, phi: &[f64; 3], tinted: &[f64; 3]) {
        for c in 0..3 {
            self.energy.absorbed[c] += phi[c] - tinted[c];
        }
    }

    /// Flux that arrived on the back of one-sided patch `j` (absorbed there).
    #[inline]
    pub fn deposit_back(&mut self, j: usize, phi: &[f64; 3]) {
        add3(&mut self.energy.absorbed_back, phi);
        self.note_back(j, phi);
    }

    /// Flux absorbed on back faces with no patch to name (a shot from a covered part whose
    /// every ray was covered).
    #[inline]
    pub fn absorb_back(&mut self, phi: &[f64; 3]) {
        add3(&mut self.energy.absorbed_back, phi);
    }

    /// Records where light met a back ([`Self::back`]).
    #[inline]
    fn note_back(&mut self, j: usize, phi: &[f64; 3]) {
        if self.back.is_empty() {
            self.back = vec![0.0; self.patches.len()];
        }
        self.back[j] += scalar(phi);
    }

    /// A distant emitter (a sky piece, the sun: [`super::sky_shots`]) shoots `phi`: emitted,
    /// and never held unshot by a patch.
    pub fn emit_distant(&mut self, phi: &[f64; 3]) {
        add3(&mut self.energy.emitted, phi);
        add3(&mut self.energy.distant, phi);
        self.shot_flux += scalar(phi);
    }

    /// A luminaire ([`super::luminaire_shots`]) shoots `phi`: emitted from a point no patch
    /// holds, so never held unshot (in `distant`'s account, with the other emitters that have
    /// no patch; its rays that meet nothing or a back count as any shot's).
    pub fn emit_point(&mut self, phi: &[f64; 3]) {
        add3(&mut self.energy.emitted, phi);
        add3(&mut self.energy.distant, phi);
        self.shot_flux += scalar(phi);
    }

    /// Flux from a distant emitter that arrived on a back face (absorbed there): a one-sided
    /// model's outside, not a winding error.
    #[inline]
    pub fn deposit_back_distant(&mut self, phi: &[f64; 3]) {
        add3(&mut self.energy.absorbed_back, phi);
        add3(&mut self.energy.distant_back, phi);
    }

    /// A distant emitter's ray that missed the model.
    #[inline]
    pub fn escape_distant(&mut self, phi: &[f64; 3]) {
        add3(&mut self.energy.escaped, phi);
        add3(&mut self.energy.distant_missed, phi);
    }

    /// Flux that left an open scene.
    #[inline]
    pub fn escape(&mut self, phi: &[f64; 3]) {
        add3(&mut self.energy.escaped, phi);
    }

    /// Ends a batch of deposits: new heap entries for every patch whose unshot energy grew.
    /// The max-ΔB heap only needs patches that could block convergence: the threshold
    /// f·mean(B)·(1 − ρ_max) never falls (B only grows; the amplification is at most
    /// 1/(1 − ρ_max)), so a patch below it now matters again only once it grows, and then it
    /// is pushed again.
    pub fn finish_batch(&mut self) {
        let threshold = self.b_threshold();
        let list = std::mem::take(&mut self.touched_list);
        for &j in &list {
            let j = j as usize;
            self.touched[j] = false;
            let (kf, kb) = (self.key_flux(j), self.key_b(j));
            self.by_flux.set(kf, j);
            if kb >= threshold {
                self.by_b.set(kb, j);
            } else {
                self.by_b.remove(j);
            }
        }
        self.touched_list = list;
        self.touched_list.clear();
        self.trim_queues(threshold);
    }

    /// Rebuilds a queue grown past twice its last rebuild (`KeyHeap::trim`), the max-ΔB queue
    /// from the patches at or above `threshold` only.
    fn trim_queues(&mut self, threshold: f64) {
        let patches = &self.patches;
        self.by_flux.trim(|i| scalar(&patches[i].unshot));
        self.by_b.trim(|i| above(key_b(&patches[i]), threshold));
    }

    /// Radiosity per patch: B_j = E_j + kept_j / A_j.
    pub fn radiosity(&self, mesh: &Mesh, materials: &[Material]) -> Vec<[f64; 3]> {
        self.patches
            .iter()
            .zip(&mesh.patches)
            .map(|(s, p)| {
                let e = materials[p.material as usize].emission();
                [0, 1, 2].map(|c| e[c] + s.kept[c] / p.area)
            })
            .collect()
    }

    /// The error estimate's parts per patch from the books as they stand (no wave in flight):
    /// what the final gather weighs its own estimates against (`super::final_gather`).
    pub fn estimate_parts(&self, est: &Estimator) -> super::estimate::Parts {
        let kept: Vec<f64> = self.patches.iter().map(|p| scalar(&p.kept)).collect();
        est.parts(&Books {
            gathered: &kept,
            cube_gathered: &self.cube_kept,
            cube_var: &self.cube_var,
            kept: kept.iter().sum(),
            unshot: self.patches.iter().map(|p| scalar(&p.unshot)).sum(),
            shot: self.shot_flux,
        })
    }

    /// Moves what is still unshot into the books (at the end of a solve).
    pub fn close_books(&mut self) {
        let mut unshot = [0.0; 3];
        for p in &self.patches {
            add3(&mut unshot, &p.unshot);
        }
        self.energy.unshot = unshot;
    }

    /// What a checkpoint keeps of the books (assembled by [`super::checkpoint`]).
    pub fn save(&self) -> Saved {
        let (channels, ch_unshot, ch_kept) = match &self.channels {
            Some(c) => (c.k, c.unshot.clone(), c.kept.clone()),
            None => (0, Vec::new(), Vec::new()),
        };
        Saved {
            energy: self.energy,
            b_flux: self.b_flux,
            rays: self.rays,
            cells: self.cells,
            shot_flux: self.shot_flux,
            unshot: self.patches.iter().map(|p| p.unshot).collect(),
            kept: self.patches.iter().map(|p| p.kept).collect(),
            cube_kept: self.cube_kept.clone(),
            cube_var: self.cube_var.clone(),
            channels,
            ch_unshot,
            ch_kept,
        }
    }

    /// Puts saved books back (onto a state built for the same mesh and settings) and rebuilds
    /// the queues from them.
    pub fn restore(&mut self, s: &Saved) -> Result<(), String> {
        let n = self.patches.len();
        if s.unshot.len() != n || s.kept.len() != n {
            return Err(format!(
                "the checkpoint has {} patches, this mesh {n}",
                s.unshot.len()
            ));
        }
        let k = self.channels.as_ref().map_or(0, |c| c.k);
        if s.channels != k {
            return Err(format!(
                "the checkpoint has {} light channels, this run {k} (--per-light must match)",
                s.channels
            ));
        }
        for (p, (u, g)) in self.patches.iter_mut().zip(s.unshot.iter().zip(&s.kept)) {
            p.unshot = *u;
            p.kept = *g;
        }
        self.energy = s.energy;
        self.b_flux = s.b_flux;
        self.rays = s.rays;
        self.cells = s.cells;
        self.shot_flux = s.shot_flux;
        self.cube_kept = s.cube_kept.clone();
        self.cube_var = s.cube_var.clone();
        if let Some(c) = &mut self.channels {
            c.unshot = s.ch_unshot.clone();
            c.kept = s.ch_kept.clone();
        }
        // The queues hold one current entry per patch with unshot light (the ones below the
        // max-ΔB heap's pruning threshold left out, as the running solve does).
        self.by_flux = KeyHeap::with_patches(n);
        self.by_b = KeyHeap::with_patches(n);
        let threshold = self.b_threshold();
        for j in 0..n {
            let (kf, kb) = (self.key_flux(j), self.key_b(j));
            self.by_flux.set(kf, j);
            if kb >= threshold {
                self.by_b.set(kb, j);
            }
        }
        self.trim_queues(threshold);
        Ok(())
    }

    /// Adds a trace point (and tells the caller): the solver's own error estimate always, the
    /// error against `reference` when there is one. The heap knows the max only above the stop
    /// threshold; a trace point is rare enough to scan for the exact value.
    // Eight: the books, and the driver's running figures (stats, time, the stop's max, the
    // estimator, the reference, what is in flight), each owned by a different part of it.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        stats: &mut SolveStats,
        elapsed: f64,
        max_b: f64,
        est: &Estimator,
        reference: Option<&[[f64; 3]]>,
        in_flight: f64,
        on_trace: &mut impl FnMut(&TracePoint),
    ) {
        let exact_max = self
            .patches
            .iter()
            .map(|p| scalar(&p.unshot) * p.inv_area as f64)
            .fold(max_b, f64::max);
        let unshot_flux: f64 = self.patches.iter().map(|p| scalar(&p.unshot)).sum();
        let kept: Vec<f64> = self.patches.iter().map(|p| scalar(&p.kept)).collect();
        let estimate = est.metrics(&Books {
            gathered: &kept,
            cube_gathered: &self.cube_kept,
            cube_var: &self.cube_var,
            kept: kept.iter().sum(),
            // A wave cast but not applied yet is still light to come.
            unshot: unshot_flux + in_flight,
            shot: self.shot_flux - in_flight,
        });
        let error = reference.map(|r| {
            let b: Vec<[f64; 3]> = kept
                .iter()
                .zip(est.emission)
                .zip(est.area)
                .map(|((g, e), a)| [e + g / a; 3])
                .collect();
            estimate::against(est.area, &b, r)
        });
        let p = TracePoint {
            time_s: elapsed,
            shots: stats.shots,
            rays: self.rays,
            cells: self.cells,
            max_unshot_b: exact_max,
            mean_b: self.mean_b(),
            unshot_flux,
            estimate,
            error,
        };
        stats.trace.push(p);
        on_trace(&p);
    }
}
