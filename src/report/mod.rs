//! What a run reports: the JSON summary of a solve and the description of a scene (`info`);
//! [`trace`] writes the error-against-time log (`trace.csv`), [`plot`] draws every plot
//! (compare's error against time, decay and cost per shot; the sweep's growth).

pub mod plot;
pub mod sky;
pub mod trace;

use crate::intersect::select;
use crate::mesh::{Mesh, PatchClass};
use crate::scene::{RhoSource, Scene};
use crate::solve::estimate::ErrorMetrics;
use crate::solve::{scalar, EnergyBalance, SolveStats, StopReason, SwitchInfo, TracePoint};
use serde::Serialize;

/// An emitting material and the power it puts out.
#[derive(Clone, Debug, Serialize)]
pub struct LightInfo {
    pub material: String,
    /// Emitted radiosity E = π·Ke, W/m².
    pub emission: [f64; 3],
    /// Area of its patches, m².
    pub area: f64,
    /// Emitted power Φ = E·A, W per channel.
    pub power: [f64; 3],
}

/// A placed luminaire (`--luminaires`) and the light it puts out.
#[derive(Clone, Debug, Serialize)]
pub struct LuminaireInfo {
    pub name: String,
    pub group: String,
    /// Its photometric file.
    pub file: String,
    /// Its photometric centre, m.
    pub position: [f64; 3],
    /// Where it aims (γ = 0), a unit direction.
    pub aim: [f64; 3],
    /// Its C0 plane's direction (the luminaire's length), unit, perpendicular to `aim`.
    pub c0: [f64; 3],
    /// What its web is multiplied by (light-loss factor × count) and its tint (luminance 1).
    pub scale: f64,
    pub colour: [f64; 3],
    /// Luminous flux, lm: the web's × light-loss factor × count × tilt factor.
    pub lumens: f64,
    /// Radiant flux per channel at 179 lm/W, W.
    pub watts: [f64; 3],
}

/// The model's own sun as `info` lists it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SunInfo {
    pub name: String,
    /// Unit vector from the model towards the sun.
    pub towards: [f64; 3],
    /// Illuminance normal to its direction, lux.
    pub lux: f64,
}

/// The scene's luminaires as the summaries list them.
pub fn luminaires(scene: &Scene) -> Vec<LuminaireInfo> {
    (scene.luminaires.iter())
        .map(|l| LuminaireInfo {
            name: l.name.clone(),
            group: l.group.clone(),
            file: l.file.display().to_string(),
            position: l.position.to_array(),
            aim: l.frame.aim.to_array(),
            c0: l.frame.c0.to_array(),
            scale: l.scale * l.tilt_factor,
            colour: l.colour,
            lumens: l.flux_lumens(),
            watts: l.flux_watts(),
        })
        .collect()
}

#[derive(Clone, Debug, Serialize)]
pub struct MaterialInfo {
    pub name: String,
    pub rho: [f64; 3],
    /// Where `rho` came from: `Kd`, `Kd` × a texture's mean colour, clamped, … (in JSON, an
    /// object whose `kind` says which).
    pub rho_source: RhoSource,
    /// Emitted radiance `Ke`, W/sr/m² (after `--emit`).
    pub ke: [f64; 3],
    /// Emitted radiosity E = π·Ke, W/m² (0 for a material that does not emit).
    pub emission: [f64; 3],
    /// Glazing's straight-through transmittance (0: opaque): the mean of its colour.
    pub transmittance: f64,
    /// Glazing's transmittance per channel: its colour when tinted, `transmittance` in every
    /// channel when grey (or opaque).
    pub transmittance_rgb: [f64; 3],
    pub polygons: usize,
}

/// `radiosity info`: what a scene is made of.
#[derive(Clone, Debug, Serialize)]
pub struct SceneInfo {
    pub scene: String,
    pub polygons: usize,
    pub patches: usize,
    pub patch_size: f32,
    pub suggested_patch_size: f32,
    pub axial_fraction_count: f64,
    pub axial_fraction_area: f64,
    /// Back twins among the patches (two-sided surfaces, docs/design.md §7).
    pub back_patches: usize,
    /// Doubled faces merged into two-sided ones, and repeats dropped, at load time.
    pub merged: crate::scene::sides::Merged,
    /// Patches whose side no light can reach (inside closed solids, under faces lying on
    /// them: `mesh::Hidden`), their area, and the patches a face lies on (`mesh::Contacts`).
    pub hidden: HiddenReport,
    pub contact_patches: usize,
    pub total_area: f64,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    pub materials: Vec<MaterialInfo>,
    pub lights: Vec<LightInfo>,
    /// Luminaires placed by `--luminaires` or by the model itself (a glTF's point and spot
    /// lights); empty without.
    pub luminaires: Vec<LuminaireInfo>,
    /// The model's own sun (a glTF directional light), if it has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sun: Option<SunInfo>,
    /// What `--intersector auto` picks for this scene, and why.
    pub intersector: &'static str,
    pub intersector_reason: String,
    pub warnings: Vec<String>,
}

/// Axis-aligned share of the patches, by count and by area.
pub fn axial_fractions(mesh: &Mesh) -> (f64, f64) {
    let n = mesh.patches.len().max(1) as f64;
    let total = mesh.total_area().max(f64::MIN_POSITIVE);
    let (mut c, mut a) = (0usize, 0.0);
    for p in &mesh.patches {
        if matches!(p.class, PatchClass::Axial(_)) {
            c += 1;
            a += p.area;
        }
    }
    (c as f64 / n, a / total)
}

/// Lights, by emitting material.
pub fn lights(scene: &Scene, mesh: &Mesh) -> Vec<LightInfo> {
    let mut area = vec![0.0; scene.materials.len()];
    for p in &mesh.patches {
        area[p.material as usize] += p.area;
    }
    scene
        .materials
        .iter()
        .enumerate()
        .filter(|(k, m)| m.is_emitter() && area[*k] > 0.0)
        .map(|(k, m)| {
            let e = m.emission();
            LightInfo {
                material: m.name.clone(),
                emission: e,
                area: area[k],
                power: e.map(|x| x * area[k]),
            }
        })
        .collect()
}

pub fn scene_info(scene: &Scene, mesh: &Mesh, suggested: f32) -> SceneInfo {
    let (fc, fa) = axial_fractions(mesh);
    let (lo, hi) = scene.bounds();
    let (auto, why) = select::auto_rule(&select::SceneShape::of(mesh));
    let mut count = vec![0usize; scene.materials.len()];
    for p in &scene.polygons {
        count[p.material as usize] += 1;
    }
    SceneInfo {
        scene: scene.name.clone(),
        polygons: scene.polygons.len(),
        patches: mesh.patches.len(),
        patch_size: mesh.patch_size,
        suggested_patch_size: suggested,
        axial_fraction_count: fc,
        axial_fraction_area: fa,
        back_patches: mesh.back_twins(),
        merged: scene.merged,
        total_area: mesh.total_area(),
        bounds_min: lo.to_array(),
        bounds_max: hi.to_array(),
        materials: scene
            .materials
            .iter()
            .zip(&count)
            .map(|(m, &polygons)| MaterialInfo {
                name: m.name.clone(),
                rho: m.rho,
                rho_source: m.rho_source.clone(),
                ke: m.ke,
                emission: m.emission(),
                transmittance: m.transmittance,
                transmittance_rgb: m.transmittance_rgb(),
                polygons,
            })
            .collect(),
        lights: lights(scene, mesh),
        luminaires: luminaires(scene),
        sun: scene.sun.as_ref().map(|s| SunInfo {
            name: s.name.clone(),
            towards: s.towards.to_array(),
            lux: s.illuminance,
        }),
        intersector: auto.name(),
        intersector_reason: why,
        warnings: scene.warnings.clone(),
        hidden: {
            let (patches, area_m2) = mesh.hidden.count(mesh);
            HiddenReport { patches, area_m2 }
        },
        contact_patches: mesh.contacts.len(),
    }
}

impl std::fmt::Display for SceneInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "scene          {}", self.scene)?;
        writeln!(f, "polygons       {}", self.polygons)?;
        writeln!(
            f,
            "patches        {} at patch size {} m (suggested {} m)",
            self.patches, self.patch_size, self.suggested_patch_size
        )?;
        writeln!(
            f,
            "axis-aligned   {:.1} % of patches, {:.1} % of area",
            100.0 * self.axial_fraction_count,
            100.0 * self.axial_fraction_area
        )?;
        writeln!(
            f,
            "sides          {} back patches; {} doubled faces merged into two-sided ones, {} repeated faces dropped",
            self.back_patches, self.merged.two_sided, self.merged.repeated
        )?;
        writeln!(
            f,
            "hidden         {} patches ({:.2} m²) no light can reach (inside closed solids, under faces lying on them); {} patches with a face lying on them",
            self.hidden.patches, self.hidden.area_m2, self.contact_patches
        )?;
        writeln!(f, "surface area   {:.4} m²", self.total_area)?;
        let (lo, hi) = (self.bounds_min, self.bounds_max);
        writeln!(
            f,
            "bounds         [{:.4}, {:.4}, {:.4}] .. [{:.4}, {:.4}, {:.4}] m (size {:.4} × {:.4} × {:.4})",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]
        )?;
        let (z, n) = (crate::sky::DEFAULT_ZENITH, crate::sky::DEFAULT_NORTH);
        writeln!(
            f,
            "orientation    zenith {},{},{}  north {},{},{} (for --sky and --grid; change with --zenith, --north)",
            z.x, z.y, z.z, n.x, n.y, n.z
        )?;
        writeln!(f, "materials      {}", self.materials.len())?;
        for m in &self.materials {
            writeln!(
                f,
                "  {:<20} rho {:.3} {:.3} {:.3}  Ke {} {} {}  ({} polygons)",
                m.name, m.rho[0], m.rho[1], m.rho[2], m.ke[0], m.ke[1], m.ke[2], m.polygons
            )?;
            writeln!(f, "  {:<20} rho from {}", "", m.rho_source)?;
            if m.transmittance > 0.0 {
                let t = m.transmittance_rgb;
                if t[0] == t[1] && t[1] == t[2] {
                    writeln!(
                        f,
                        "  {:<20} glazing: transmittance {:.3} (grey)",
                        "", m.transmittance
                    )?;
                } else {
                    writeln!(
                        f,
                        "  {:<20} glazing: transmittance {:.3} (mean), tinted {:.3} {:.3} {:.3}",
                        "", m.transmittance, t[0], t[1], t[2]
                    )?;
                }
            }
        }
        writeln!(f, "lights         {}", self.lights.len())?;
        for l in &self.lights {
            writeln!(
                f,
                "  {:<20} E {:.4} {:.4} {:.4} W/m² over {:.4} m²: {:.4} {:.4} {:.4} W",
                l.material,
                l.emission[0],
                l.emission[1],
                l.emission[2],
                l.area,
                l.power[0],
                l.power[1],
                l.power[2]
            )?;
        }
        if !self.luminaires.is_empty() {
            let total: f64 = self.luminaires.iter().map(|l| l.lumens).sum();
            writeln!(
                f,
                "luminaires     {} ({:.0} lm in all)",
                self.luminaires.len(),
                total
            )?;
            for l in &self.luminaires {
                let (p, a) = (l.position, l.aim);
                writeln!(
                    f,
                    "  {:<20} {:.0} lm at {:.3},{:.3},{:.3} aimed {:.3},{:.3},{:.3} (group {}; {})",
                    l.name, l.lumens, p[0], p[1], p[2], a[0], a[1], a[2], l.group, l.file
                )?;
            }
        }
        if let Some(s) = &self.sun {
            let t = s.towards;
            writeln!(
                f,
                "sun            '{}': {:.0} lux from {:.3},{:.3},{:.3} (the model's directional light; lights a solve unless --sun places one)",
                s.name, s.lux, t[0], t[1], t[2]
            )?;
        }
        writeln!(
            f,
            "intersector    {} (auto: {})",
            self.intersector, self.intersector_reason
        )?;
        for w in &self.warnings {
            writeln!(f, "warning: {w}")?;
        }
        Ok(())
    }
}

/// Wall time of each phase of a solve, seconds.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timings {
    pub load: f64,
    pub mesh: f64,
    pub build: f64,
    /// Finding the hidden sides (`intersect::hidden`).
    pub sides: f64,
    pub solve: f64,
    pub output: f64,
    /// Of `output`: refining the elements (with the intersector they need, when the method
    /// cast no rays).
    pub elements: f64,
    /// Of `output`: drawing `render.png`.
    pub picture: f64,
    /// Of `output`: measuring the sensor grid (`--grid`).
    pub grid: f64,
    pub total: f64,
    /// The same phases' CPU time (`summary.json`: `cpu_seconds`).
    #[serde(skip)]
    pub cpu: CpuSeconds,
    /// The peak memory at the end of each phase (`summary.json`: `peak_mib`).
    #[serde(skip)]
    pub peak: PeakMemory,
}

/// Process CPU time (user + system, all threads) of the phases that do the work, seconds:
/// beside the wall times of [`Timings`], figures that hold when other jobs share the cores
/// (a wall time on a busy machine measures the machine; `scripts/radiance/daylight.py` sets
/// the tool's CPU seconds against Radiance's beside the wall times).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct CpuSeconds {
    pub solve: f64,
    /// Measuring the sensor grid (`--grid`).
    pub grid: f64,
    pub total: f64,
}

/// The process's peak resident memory (MiB, the high-water mark `VmHWM` of
/// `/proc/self/status`) at the end of each phase of a solve: what a model of that size needs
/// to have room for, phase by phase (`summary.json`: `peak_mib`). 0 where the platform does
/// not tell.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct PeakMemory {
    pub load: f64,
    pub mesh: f64,
    pub build: f64,
    pub sides: f64,
    pub solve: f64,
    /// After the elements.
    pub elements: f64,
    /// After the picture.
    pub picture: f64,
    /// After the elements, the picture and the files: the whole run's peak.
    pub output: f64,
}

/// The process's resident memory now and its peak so far (KiB), from `/proc/self/status`;
/// zeros where there is none (not Linux).
pub fn resident_kib() -> (f64, f64) {
    let text = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |name: &str| {
        text.lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (field("VmRSS:"), field("VmHWM:"))
}

/// The peak resident memory so far, MiB ([`resident_kib`]).
pub fn peak_mib() -> f64 {
    resident_kib().1 / 1024.0
}

/// CPU time this process has used so far (all threads, user + system), seconds; 0 where the
/// platform does not tell.
pub fn process_cpu_seconds() -> f64 {
    cpu_time::ProcessTime::try_now()
        .map(|t| t.as_duration().as_secs_f64())
        .unwrap_or(0.0)
}

/// The energy balance with its residual (docs/design.md §1: emitted = absorbed + absorbed on back faces + escaped + unshot).
#[derive(Clone, Debug, Serialize)]
pub struct EnergyReport {
    #[serde(flatten)]
    pub balance: EnergyBalance,
    /// |emitted − accounted| / emitted, worst channel.
    pub relative_residual: f64,
    /// Share of the emitted flux that arrived on back faces.
    pub back_fraction: f64,
    pub escaped_fraction: f64,
}

impl From<&EnergyBalance> for EnergyReport {
    fn from(b: &EnergyBalance) -> Self {
        EnergyReport {
            balance: *b,
            relative_residual: b.relative_residual(),
            back_fraction: b.back_fraction(),
            // Sky and sun rays that missed the model never entered it.
            escaped_fraction: (scalar(&b.escaped) - scalar(&b.distant_missed)).max(0.0)
                / (scalar(&b.emitted) - scalar(&b.distant_missed)).max(f64::MIN_POSITIVE),
        }
    }
}

/// The faces a first shooting found lit from behind and gave back patches
/// (`pipeline::stages::lit_backs`; `summary.json`: `lit_backs`).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct LitBacks {
    /// Share of the emitted light that met the back of a one-sided face (not a hidden one) in
    /// the first shooting.
    pub back_fraction: f64,
    /// Polygons given back patches, and the back patches made.
    pub polygons: usize,
    pub patches: usize,
    /// Wall seconds of the first shooting.
    pub seconds: f64,
    /// The first shooting's shots and rays.
    pub shots: u64,
    pub rays: u64,
    /// Patches of the mesh the first shooting ran on: the model's own, or past
    /// `pipeline::stages::LIT_BACKS_PROBE_PATCHES` surface patches a coarser cut of the scene.
    pub probe_patches: usize,
}

/// Sides no light can reach (`mesh::Hidden`; `summary.json`: `hidden`): the patches whose side
/// is hidden, and their area. They are black, and kept out of the black-patch counts.
#[derive(Clone, Copy, Debug, Default, Serialize, serde::Deserialize)]
pub struct HiddenReport {
    pub patches: usize,
    pub area_m2: f64,
}

/// The JSON summary of a solve (`summary.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub version: &'static str,
    pub scene: String,
    pub polygons: usize,
    pub patches: usize,
    pub patch_size: f32,
    pub axial_fraction_area: f64,
    pub lights: Vec<LightInfo>,
    /// Luminaires placed by `--luminaires` (left out without).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub luminaires: Vec<LuminaireInfo>,
    pub method: &'static str,
    pub intersector: &'static str,
    /// Why that intersector (the `auto` rule's reason, or "forced by --intersector").
    pub intersector_reason: String,
    pub seed: u64,
    pub threads: usize,
    pub tolerance: f64,
    pub energy_per_ray: f64,
    pub stop_fraction: f64,
    pub stop_reason: Option<StopReason>,
    /// With `--error`: the target, the estimate reached, whether it was, and the passes.
    pub error_target: Option<crate::solve::passes::ErrorTarget>,
    pub shots: u64,
    pub rays: u64,
    pub waves: u64,
    /// Shots taken by hemi-cube (the `hemicube` methods, and `adaptive-hybrid` before it
    /// switched), and their cells (form-factor samples).
    pub hemicube_shots: u64,
    pub hemicube_cells: u64,
    /// Resolution N of the uniform hemi-cube (`hemicube`, `hemicube-jittered`, `gathering`).
    pub hemicube_n: Option<usize>,
    /// `adaptive-hybrid`: the shot at which it switched from hemi-cubes to rays, and the
    /// measured costs that decided it (Sec. 4).
    pub switch: Option<SwitchInfo>,
    /// The final gather after the shooting (patches gathered, rays, seconds, black patches
    /// before and after), when one ran; `rays` above are the shooting's.
    pub final_gather: Option<crate::solve::final_gather::GatherStats>,
    /// Patches whose side no light can reach (inside closed solids, under other faces).
    pub hidden: HiddenReport,
    /// The back patches made for faces lit from behind (absent with `--two-sided`,
    /// `--one-sided`, or a method that casts no rays).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lit_backs: Option<LitBacks>,
    /// The adaptive elements refined after the solve (count, rays, seconds), when they were
    /// (`--elements auto`, the default, or `on`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elements: Option<crate::elements::ElementStats>,
    /// Rays cast per second of solve time.
    pub rays_per_second: f64,
    pub seconds: Timings,
    pub cpu_seconds: CpuSeconds,
    /// Peak resident memory (MiB) at the end of each phase.
    pub peak_mib: PeakMemory,
    pub energy: EnergyReport,
    /// Names of the per-light channels kept (`--per-light`), in channel order.
    pub light_channels: Vec<String>,
    /// The solver's own estimate of its final error (fractions; see `solve::estimate`).
    pub error_estimate: ErrorMetrics,
    /// The final error against `--reference`, when given.
    pub error: Option<ErrorMetrics>,
    /// Final max unshot radiosity over the mean radiosity (Sec. 3's criterion).
    pub max_unshot_over_mean: f64,
    pub warnings: Vec<String>,
    pub outputs: Vec<String>,
    /// Every setting that shaped the result (`pipeline::RunSettings`), derived, not listed by
    /// hand: `load`, `mesh`, `solve`, `intersector`, `per_light`.
    pub settings: serde_json::Value,
    /// The max-unshot trace, against time and shots.
    pub trace: Vec<TracePoint>,
    /// The sky (docs/design.md §9), when the solve had one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sky: Option<sky::SkyReport>,
    /// The sensor grid's statistics (`--grid`): the whole grid's, the outdoor sensors found,
    /// and each storey's and room's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid: Option<crate::grid::GridReport>,
}

impl Summary {
    /// One line: the final error, measured against the reference or estimated.
    pub fn error_line(&self) -> String {
        let e = &self.error_estimate;
        let est = format!(
            "estimated error {:.2} % average weighted, {:.2} % energy",
            100.0 * e.weighted_percent,
            100.0 * e.energy
        );
        match &self.error {
            Some(r) => format!(
                "error against the reference {:.2} % average weighted, {:.2} % energy, {:.2} % RMS ({est})",
                100.0 * r.weighted_percent,
                100.0 * r.energy,
                100.0 * r.rms_relative
            ),
            None => est,
        }
    }

    pub fn stats_line(stats: &SolveStats) -> String {
        let mut line = format!("{} shots", stats.shots);
        if stats.hemicube_shots > 0 {
            line += &format!(
                " ({} by hemi-cube, {} cells)",
                stats.hemicube_shots, stats.hemicube_cells
            );
        }
        if let Some(s) = &stats.switch {
            line += &format!(
                ", switched to rays at shot {} (hemi-cube {:.2} ms vs {} rays {:.2} ms)",
                s.shot,
                1e3 * s.hemicube_shot_seconds,
                s.rays,
                1e3 * s.ray_shot_seconds
            );
        }
        if stats.rays > 0 {
            line += &format!(
                ", {} rays ({:.2} Mrays/s)",
                stats.rays,
                stats.rays as f64 / stats.seconds.max(1e-9) / 1e6
            );
        }
        if let Some(g) = &stats.final_gather {
            line += &format!(", {}", Self::gather_line(g));
        }
        line += &format!(" in {:.2} s", stats.seconds);
        if let Some(t) = &stats.error_target {
            line += &format!(
                "; error target {:.2} % {} after {} pass{}{} (estimate {:.2} %)",
                100.0 * t.target,
                if t.reached { "reached" } else { "NOT reached" },
                t.passes,
                if t.passes == 1 { "" } else { "es" },
                match t.regathers {
                    0 => String::new(),
                    1 => " and 1 gather round".into(),
                    k => format!(" and {k} gather rounds"),
                },
                100.0 * t.estimate
            );
            if t.gave_up {
                line += &format!(
                    " (the default target stops at {}× the first pass's rays: give --error to go on)",
                    crate::solve::settings::DEFAULT_ERROR_MAX_FACTOR
                );
            }
        }
        line
    }

    /// What the final gather did, in a few words.
    pub fn gather_line(g: &crate::solve::final_gather::GatherStats) -> String {
        let pilot = g.pilot.map_or(String::new(), |p| {
            format!(
                "; {} rays a patch, chosen by a pilot of {} patches for an estimate of {:.2} %",
                p.rays_per_patch,
                p.patches,
                100.0 * p.predicted
            )
        });
        format!(
            "final gather of {} patches ({} rays, {:.2} s; black patches {} → {}{pilot})",
            g.patches, g.rays, g.seconds, g.black_before, g.black_after
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshOptions;
    use crate::scene::{load_obj_from_strs, LoadOptions};

    /// `info --json` carries each material as the loader made it, so scripts read materials
    /// from the tool rather than from the MTL: ρ after the clamp and where it came from,
    /// `Ke` after `--emit`, E = π·Ke, and the glazing's transmittance per channel.
    #[test]
    fn the_info_json_has_every_material_as_the_loader_made_it() {
        let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                   usemtl white\nf 1 2 3 4\nusemtl lamp\nf 4 3 2 1\nusemtl pane\nf 1 2 3\n";
        let mtl = "newmtl white\nKd 1.2 0.5 0.5\nnewmtl lamp\nKd 0.1 0.1 0.1\n\
                   newmtl pane\nKd 0.1 0.1 0.1\nTf 0.2 0.6 0.3\nillum 4\n";
        let load = LoadOptions {
            emit: vec![("lamp".into(), [1.0, 2.0, 3.0])],
            ..Default::default()
        };
        let scene = load_obj_from_strs("m.obj", obj, mtl, &load).unwrap();
        let mesh = crate::mesh::build(&scene, &MeshOptions::default());
        let json = serde_json::to_value(scene_info(&scene, &mesh, 1.0)).unwrap();
        let by_name = |n: &str| {
            json["materials"]
                .as_array()
                .unwrap()
                .iter()
                .find(|m| m["name"] == n)
                .unwrap()
                .clone()
        };
        let white = by_name("white");
        assert_eq!(
            white["rho"][0].as_f64(),
            Some(crate::scene::MAX_REFLECTANCE)
        );
        assert_eq!(white["rho_source"]["kind"], "clamped");
        assert_eq!(white["emission"][0].as_f64(), Some(0.0));
        let lamp = by_name("lamp");
        assert_eq!(lamp["ke"][2].as_f64(), Some(3.0));
        let e = lamp["emission"][2].as_f64().unwrap();
        assert!((e - 3.0 * std::f64::consts::PI).abs() < 1e-12, "{e}");
        let pane = by_name("pane");
        assert_eq!(pane["transmittance_rgb"][1].as_f64(), Some(0.6));
        assert!((pane["transmittance"].as_f64().unwrap() - 1.1 / 3.0).abs() < 1e-12);
    }
}
