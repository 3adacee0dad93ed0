//! The annual metrics of a grid: per sensor, then of the grid as its sensors' weights share it.
//!
//! Every metric counts the **occupied hours** of the period ([`super::schedule`]), dark ones
//! included (an occupied hour without a row in the matrices has E = 0), so a year's figures
//! are shares of LM-83-12's 3,650 hours whatever the latitude. At a sensor, with E its total
//! and E_sun its direct-sun illuminance:
//!
//! - **DA** (daylight autonomy, as IES LM-83-12 §2.1.1 uses it): the share of occupied hours
//!   with E ≥ 300 lux ([`Thresholds::da_lux`]).
//! - **sDA300/50%** (spatial daylight autonomy, LM-83-12 §2.1): the share of the grid (by weight)
//!   whose DA is at least 50 % ([`Thresholds::sda_percent`]).
//! - **ASE hours** and **ASE1000,250h** (annual sunlight exposure, LM-83-12): a sensor's
//!   occupied hours with E_sun ≥ 1000 lux ([`Thresholds::ase_lux`]), E_sun the direct
//!   sunlight alone (no sky, no interreflection), blinds open; ASE is the share of the grid (by
//!   weight) with **more than** 250 such hours ([`Thresholds::ase_hours`]): 250 hours are not
//!   exposed, 251 are.
//! - **UDI** (useful daylight illuminance, Nabil & Mardaljevic, *Lighting Res. Technol.* 37(1),
//!   2005): the occupied hours split three ways, as shares: fell short (E < 100 lux,
//!   [`Thresholds::udi_low`]), useful (100 ≤ E ≤ 3000 lux) and exceeded (E > 3000 lux,
//!   [`Thresholds::udi_high`]); the three add up to 100 %. The paper's upper limit was 2000
//!   lux; 3000 is the one later work settled on (Mardaljevic et al., *Daylighting metrics: is
//!   there a relation between useful daylight illuminance and daylight glare probability?*,
//!   2012), and both are settings.
//!
//! The grid's figures weigh each sensor by its weight ([`indoor_weights`]: indoor sensors
//! alike, outdoor ones 0): sDA and ASE are shares of the weight, the DA and UDI figures
//! weighted means. LM-83-12's analysis points lie on a regular grid (§2.2.5), each standing for
//! the same area, as a work plane's sensors do.

use super::en17037::{self, En17037};
use super::schedule::Occupancy;
use super::{invalid, percent, ratio, AnnualError, Series};
use crate::grid::Zone;
use crate::settings::Invalid;

/// The thresholds of the metrics (the [module docs](self)); the defaults are the standards'.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Thresholds {
    /// DA's illuminance, lux (300): an hour counts when E ≥ this.
    pub da_lux: f64,
    /// sDA's share of occupied hours, % (50): a sensor counts when its DA ≥ this.
    pub sda_percent: f64,
    /// ASE's direct-sun illuminance, lux (1000): an hour counts when E_sun ≥ this.
    pub ase_lux: f64,
    /// ASE's hours (250): a sensor is exposed with **more** hours than this.
    pub ase_hours: u32,
    /// UDI's lower limit, lux (100): below it an hour fell short.
    pub udi_low: f64,
    /// UDI's upper limit, lux (3000): above it an hour exceeded.
    pub udi_high: f64,
}

impl Default for Thresholds {
    fn default() -> Thresholds {
        Thresholds {
            da_lux: 300.0,
            sda_percent: 50.0,
            ase_lux: 1000.0,
            ase_hours: 250,
            udi_low: 100.0,
            udi_high: 3000.0,
        }
    }
}

impl Thresholds {
    /// Checks that the illuminances are positive and finite, UDI's lower limit below its upper
    /// one and sDA's share within (0, 100] %.
    pub fn validate(&self) -> Result<(), Invalid> {
        for (what, v) in [
            ("DA illuminance", self.da_lux),
            ("ASE illuminance", self.ase_lux),
            ("UDI lower limit", self.udi_low),
            ("UDI upper limit", self.udi_high),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Invalid::err(format!(
                    "the {what} must be a positive number of lux, got {v}"
                ));
            }
        }
        if self.udi_low >= self.udi_high {
            return Invalid::err(format!(
                "the UDI limits must rise: {} lux is not below {} lux",
                self.udi_low, self.udi_high
            ));
        }
        if !(self.sda_percent > 0.0 && self.sda_percent <= 100.0) {
            return Invalid::err(format!(
                "the sDA share must be within (0, 100] %, got {}",
                self.sda_percent
            ));
        }
        Ok(())
    }
}

/// One sensor's metrics (the [module docs](self)); shares in % of the occupied hours.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SensorMetrics {
    /// The sensor's weight in the grid's figures.
    pub weight: f64,
    /// DA: occupied hours with E ≥ [`Thresholds::da_lux`], %.
    pub da_percent: f64,
    /// UDI fell short: occupied hours with E < [`Thresholds::udi_low`], %.
    pub udi_fell_short_percent: f64,
    /// UDI useful: occupied hours with E within the limits, %.
    pub udi_useful_percent: f64,
    /// UDI exceeded: occupied hours with E > [`Thresholds::udi_high`], %.
    pub udi_exceeded_percent: f64,
    /// Occupied hours with E_sun ≥ [`Thresholds::ase_lux`].
    pub ase_hours: u32,
}

/// The grid's figures, for `summary.json`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AnnualSummary {
    /// The occupied hours' rule.
    pub occupancy: Occupancy,
    /// The metrics' thresholds.
    pub thresholds: Thresholds,
    /// Hours in the weather file.
    pub period_hours: usize,
    /// Hours with a row in the matrices (the daylit hours the solver computed).
    pub simulated_hours: usize,
    /// Occupied hours of the period, dark ones included: what DA, UDI and ASE count over.
    pub occupied_hours: usize,
    /// Sensors with a weight above 0, and their total weight.
    pub sensors: usize,
    pub weight: f64,
    /// sDA: the share of weight with DA ≥ [`Thresholds::sda_percent`], %.
    pub sda_percent: f64,
    /// ASE: the share of weight with more than [`Thresholds::ase_hours`] ASE hours, %.
    pub ase_percent: f64,
    /// The weighted means of the sensors' DA and UDI shares, %.
    pub da_mean_percent: f64,
    pub udi_fell_short_percent: f64,
    pub udi_useful_percent: f64,
    pub udi_exceeded_percent: f64,
    /// EN 17037's daylight provision.
    pub en17037: En17037,
}

/// The grid's figures and each sensor's, in the matrices' sensor order.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AnnualMetrics {
    pub summary: AnnualSummary,
    pub sensors: Vec<SensorMetrics>,
}

/// The weights the figures take by default: 1 for an indoor sensor, 0 for an outdoor one,
/// and 1 for all when none is indoors (a model without a roof, whose grid keeps every sensor:
/// [`crate::grid::Placed::warning`]).
pub fn indoor_weights(zones: &[Zone]) -> Vec<f64> {
    let any = zones.iter().any(|z| z.indoor);
    zones
        .iter()
        .map(|z| if z.indoor || !any { 1.0 } else { 0.0 })
        .collect()
}

/// The metrics of `series` over the hours `occupancy` occupies, each sensor weighted by
/// `weights` (one per sensor, finite, ≥ 0). Refuses bad settings, inputs that do not fit and
/// values that are not finite, each with one line.
pub fn annual_metrics(
    series: &Series,
    weights: &[f64],
    occupancy: &Occupancy,
    thresholds: &Thresholds,
) -> Result<AnnualMetrics, AnnualError> {
    occupancy.validate()?;
    thresholds.validate()?;
    series.validate()?;
    check_weights(weights, series.sensors)?;
    let occupied = occupancy.occupied(&series.period.stamps);
    let occupied_hours = occupied.iter().filter(|&&o| o).count();
    let sensors: Vec<SensorMetrics> = count_hours(series, &occupied, thresholds)
        .iter()
        .zip(weights)
        .map(|(c, &w)| c.metrics(w, occupied_hours))
        .collect();
    let daylight = en17037::daylight_hours(&series.period.diffuse);
    let en17037 = en17037::evaluate(series, weights, &daylight);
    let weight: f64 = weights.iter().sum();
    let share = |pass: &dyn Fn(&SensorMetrics) -> bool| {
        let w: f64 = sensors.iter().filter(|m| pass(m)).map(|m| m.weight).sum();
        ratio(100.0 * w, weight)
    };
    let mean = |value: &dyn Fn(&SensorMetrics) -> f64| {
        ratio(sensors.iter().map(|m| m.weight * value(m)).sum(), weight)
    };
    let summary = AnnualSummary {
        occupancy: *occupancy,
        thresholds: *thresholds,
        period_hours: series.period.len(),
        simulated_hours: series.rows.len(),
        occupied_hours,
        sensors: weights.iter().filter(|&&w| w > 0.0).count(),
        weight,
        sda_percent: share(&|m| m.da_percent >= thresholds.sda_percent),
        ase_percent: share(&|m| m.ase_hours > thresholds.ase_hours),
        da_mean_percent: mean(&|m| m.da_percent),
        udi_fell_short_percent: mean(&|m| m.udi_fell_short_percent),
        udi_useful_percent: mean(&|m| m.udi_useful_percent),
        udi_exceeded_percent: mean(&|m| m.udi_exceeded_percent),
        en17037,
    };
    Ok(AnnualMetrics { summary, sensors })
}

/// One sensor's occupied hours above each threshold.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Counts {
    da: u32,
    useful: u32,
    exceeded: u32,
    ase: u32,
}

impl Counts {
    /// The sensor's metrics over `occupied` hours; the hours not useful nor exceeded fell
    /// short (dark occupied hours among them).
    fn metrics(&self, weight: f64, occupied: usize) -> SensorMetrics {
        let short = occupied - (self.useful + self.exceeded) as usize;
        SensorMetrics {
            weight,
            da_percent: percent(self.da as usize, occupied),
            udi_fell_short_percent: percent(short, occupied),
            udi_useful_percent: percent(self.useful as usize, occupied),
            udi_exceeded_percent: percent(self.exceeded as usize, occupied),
            ase_hours: self.ase,
        }
    }
}

/// Each sensor's counts over the rows whose hour is occupied.
fn count_hours(series: &Series, occupied: &[bool], t: &Thresholds) -> Vec<Counts> {
    let n = series.sensors;
    let mut counts = vec![Counts::default(); n];
    for (r, &p) in series.rows.iter().enumerate() {
        if !occupied[p] {
            continue;
        }
        let lux = &series.lux[r * n..(r + 1) * n];
        let sun = &series.sun_lux[r * n..(r + 1) * n];
        for ((c, &e), &s) in counts.iter_mut().zip(lux).zip(sun) {
            let e = e as f64;
            c.da += (e >= t.da_lux) as u32;
            c.useful += (e >= t.udi_low && e <= t.udi_high) as u32;
            c.exceeded += (e > t.udi_high) as u32;
            c.ase += (s as f64 >= t.ase_lux) as u32;
        }
    }
    counts
}

/// Checks one finite, non-negative weight per sensor.
fn check_weights(weights: &[f64], sensors: usize) -> Result<(), AnnualError> {
    if weights.len() != sensors {
        return Err(invalid(format!(
            "{} weights for {sensors} sensors",
            weights.len()
        )));
    }
    match weights.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
        Some(k) => Err(invalid(format!(
            "sensor {k}'s weight {} is not a finite number >= 0",
            weights[k]
        ))),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests;
