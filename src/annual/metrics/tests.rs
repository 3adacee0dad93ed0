//! Hand-counted cases of the annual metrics.

use super::super::schedule::tests::year_of_hours;
use super::super::schedule::{Dst, LM83_HOURS};
use super::super::{Period, Stamp};
use super::*;

/// `days` days of 24 hours from 1 June (no daylight saving under any rule's absence), each
/// hour's diffuse daylight its hour's centre when the sun is up (6–18), else 0.
fn june(days: u32) -> Period {
    let stamps: Vec<Stamp> = (0..days * 24)
        .map(|k| Stamp {
            month: 6,
            day: 1 + k / 24,
            hour: (k % 24) as f64 + 0.5,
        })
        .collect();
    let diffuse = stamps
        .iter()
        .map(|s| {
            if (6.0..18.0).contains(&s.hour) {
                s.hour
            } else {
                0.0
            }
        })
        .collect();
    Period { stamps, diffuse }
}

/// The rows of every hour of `period` whose centre is in [from, to).
fn rows_between(period: &Period, from: f64, to: f64) -> Vec<usize> {
    (0..period.len())
        .filter(|&k| (from..to).contains(&period.stamps[k].hour))
        .collect()
}

/// The metrics with `lux[row][sensor]` (and no sun), equal weights, the default schedule.
fn run(period: &Period, rows: &[usize], lux: &[Vec<f32>]) -> AnnualMetrics {
    let sensors = lux.first().map_or(0, Vec::len);
    let flat: Vec<f32> = lux.iter().flatten().copied().collect();
    let sun = vec![0.0; flat.len()];
    let series = Series {
        period,
        rows,
        sensors,
        lux: &flat,
        sun_lux: &sun,
    };
    let weights = vec![1.0; sensors];
    annual_metrics(
        &series,
        &weights,
        &Occupancy::default(),
        &Thresholds::default(),
    )
    .unwrap()
}

#[test]
fn annual_da_counts_300_lux_and_sda_half_the_hours() {
    // One day: 10 occupied hours (8.5 … 17.5), rows 6.5 … 18.5.
    let p = june(1);
    let rows = rows_between(&p, 6.0, 19.0);
    // Sensor 0: exactly 300 lux in 5 occupied hours, 299.9 in the others: DA 50 %, in sDA.
    // Sensor 1: 300 lux in 4 of them: DA 40 %, not in sDA. Both 5000 lux outside occupancy.
    let lux: Vec<Vec<f32>> = rows
        .iter()
        .map(|&k| {
            let h = p.stamps[k].hour;
            if !(8.0..18.0).contains(&h) {
                return vec![5000.0, 5000.0];
            }
            let n = h as u32 - 8; // 0 … 9
            vec![
                if n < 5 { 300.0 } else { 299.9 },
                if n < 4 { 300.0 } else { 299.9 },
            ]
        })
        .collect();
    let m = run(&p, &rows, &lux);
    assert_eq!(m.summary.occupied_hours, 10);
    assert_eq!(m.summary.simulated_hours, 13);
    assert_eq!(m.sensors[0].da_percent, 50.0);
    assert_eq!(m.sensors[1].da_percent, 40.0);
    assert_eq!(m.summary.sda_percent, 50.0);
    assert_eq!(m.summary.da_mean_percent, 45.0);
    // All of it is useful daylight.
    assert_eq!(m.summary.udi_useful_percent, 100.0);
    assert_eq!(m.summary.udi_fell_short_percent, 0.0);
}

#[test]
fn annual_udi_limits_and_dark_occupied_hours() {
    // Rows only at 10.5 … 13.5: the other 6 occupied hours are dark and fell short.
    let p = june(1);
    let rows = rows_between(&p, 10.0, 14.0);
    let lux = vec![vec![99.9], vec![100.0], vec![3000.0], vec![3000.5]];
    let m = run(&p, &rows, &lux);
    let s = m.sensors[0];
    assert_eq!(s.udi_fell_short_percent, 70.0);
    assert_eq!(s.udi_useful_percent, 20.0);
    assert_eq!(s.udi_exceeded_percent, 10.0);
    // DA: 100 and 99.9 are below 300; 3000 and 3000.5 above: 2 of 10 hours.
    assert_eq!(s.da_percent, 20.0);
    assert_eq!(m.summary.udi_exceeded_percent, 10.0);
}

#[test]
fn annual_ase_needs_more_than_250_hours() {
    // 30 days: 300 occupied hours. Sun at 1000 lux (exactly) for 250, 251 and 300 occupied
    // hours at sensors 0, 1, 2; at 999.9 lux at sensor 3; 5000 lux at 7.5 (unoccupied) at all.
    let p = june(30);
    let rows = rows_between(&p, 7.0, 18.0);
    let limits = [250usize, 251, 300, 300];
    let mut occupied_seen = 0;
    let mut sun = Vec::new();
    for &k in &rows {
        let h = p.stamps[k].hour;
        if h < 8.0 {
            sun.extend([5000.0f32; 4]);
            continue;
        }
        for (s, &n) in limits.iter().enumerate() {
            let lit = occupied_seen < n;
            sun.push(match (lit, s) {
                (true, 3) => 999.9,
                (true, _) => 1000.0,
                (false, _) => 0.0,
            });
        }
        occupied_seen += 1;
    }
    let lux = vec![500.0f32; sun.len()];
    let series = Series {
        period: &p,
        rows: &rows,
        sensors: 4,
        lux: &lux,
        sun_lux: &sun,
    };
    let t = Thresholds::default();
    let m = annual_metrics(&series, &[1.0; 4], &Occupancy::default(), &t).unwrap();
    assert_eq!(m.summary.occupied_hours, 300);
    let hours: Vec<u32> = m.sensors.iter().map(|s| s.ase_hours).collect();
    assert_eq!(hours, [250, 251, 300, 0]);
    assert_eq!(
        m.summary.ase_percent, 50.0,
        "251 and 300 h are exposed, 250 is not"
    );
    // Weights: the exposed sensors weigh 1 of 1 + 3 + 0 + 0.
    let m = annual_metrics(&series, &[3.0, 1.0, 0.0, 0.0], &Occupancy::default(), &t).unwrap();
    assert_eq!(m.summary.ase_percent, 25.0);
    assert_eq!((m.summary.sensors, m.summary.weight), (2, 4.0));
}

#[test]
fn annual_dst_moves_the_counted_hours() {
    // Saturday 11 and Sunday 12 March 2023; light only in the 7.5 hour (7:00–8:00 standard).
    let p = Period {
        stamps: (0..48)
            .map(|k| Stamp {
                month: 3,
                day: 11 + k / 24,
                hour: (k % 24) as f64 + 0.5,
            })
            .collect(),
        diffuse: vec![1.0; 48],
    };
    let rows: Vec<usize> = (0..48).collect();
    let lux: Vec<f32> = (0..48)
        .map(|k| if k % 24 == 7 { 800.0 } else { 0.0 })
        .collect();
    let series = Series {
        period: &p,
        rows: &rows,
        sensors: 1,
        lux: &lux,
        sun_lux: &[0.0; 48],
    };
    let t = Thresholds::default();
    let none = annual_metrics(&series, &[1.0], &Occupancy::default(), &t).unwrap();
    assert_eq!(none.summary.occupied_hours, 20);
    assert_eq!(none.sensors[0].da_percent, 0.0);
    let us = Occupancy {
        dst: Dst::Us,
        ..Occupancy::default()
    };
    let m = annual_metrics(&series, &[1.0], &us, &t).unwrap();
    assert_eq!(m.summary.occupied_hours, 20);
    // On the Sunday the clock reads 8:00–9:00: occupied, 1 hour of 20.
    assert_eq!(m.sensors[0].da_percent, 5.0);
    // Under the EU rule daylight saving starts on the 26th: nothing counts.
    let eu = Occupancy { dst: Dst::Eu, ..us };
    let m = annual_metrics(&series, &[1.0], &eu, &t).unwrap();
    assert_eq!(m.sensors[0].da_percent, 0.0);
}

#[test]
fn annual_a_year_counts_lm83s_3650_hours() {
    // Daylit 6:00–18:00, 12 hours a day: every occupied hour has a row, at 500 lux.
    let stamps = year_of_hours();
    let day = |s: &Stamp| (6.0..18.0).contains(&s.hour);
    let diffuse = stamps.iter().map(|s| day(s) as u8 as f64).collect();
    let p = Period { stamps, diffuse };
    let rows = rows_between(&p, 6.0, 18.0);
    let lux = vec![vec![500.0f32]; rows.len()];
    let m = run(&p, &rows, &lux);
    assert_eq!(m.summary.period_hours, 8760);
    assert_eq!(m.summary.occupied_hours, LM83_HOURS);
    assert_eq!(m.sensors[0].da_percent, 100.0);
    assert_eq!(m.summary.sda_percent, 100.0);
    // EN 17037: 4,380 daylight hours, the 12 daylit hours of each day, all at 500 lux.
    let en = &m.summary.en17037;
    assert_eq!(en.daylight_hours, 4380);
    assert_eq!(en.levels[1].target_hours_percent, 100.0);
    assert_eq!(en.levels[2].target_hours_percent, 0.0);
    assert_eq!(en.level, "medium");
}

#[test]
fn annual_nothing_to_count_gives_zeros_not_nan() {
    let p = june(1);
    // No sensors, no rows.
    let m = run(&p, &[], &[]);
    let json = serde_json::to_string(&m).unwrap();
    assert!(!json.contains("null") && !json.contains("NaN"), "{json}");
    assert_eq!(m.summary.sda_percent, 0.0);
    // All weights 0; a window of no occupied hour (0:00–0:30 holds no centre).
    let series = Series {
        period: &p,
        rows: &[12],
        sensors: 1,
        lux: &[1000.0],
        sun_lux: &[0.0],
    };
    let t = Thresholds::default();
    let m = annual_metrics(&series, &[0.0], &Occupancy::default(), &t).unwrap();
    assert_eq!(
        (m.summary.sda_percent, m.summary.da_mean_percent),
        (0.0, 0.0)
    );
    let empty = Occupancy {
        start: 0.0,
        end: 0.5,
        ..Occupancy::default()
    };
    let m = annual_metrics(&series, &[1.0], &empty, &t).unwrap();
    assert_eq!(m.summary.occupied_hours, 0);
    assert_eq!(m.sensors[0].udi_fell_short_percent, 0.0);
    let json = serde_json::to_string(&m).unwrap();
    assert!(!json.contains("null"), "{json}");
}

/// The error of the metrics of one sensor with `lux` at `rows` of a June day, weighed `w`.
fn error_of(lux: &[f32], rows: &[usize], w: f64, t: &Thresholds) -> String {
    let p = june(1);
    let sun = vec![0.0; lux.len()];
    let series = Series {
        period: &p,
        rows,
        sensors: 1,
        lux,
        sun_lux: &sun,
    };
    let e = annual_metrics(&series, &[w], &Occupancy::default(), t).unwrap_err();
    let e = e.to_string();
    assert!(!e.contains('\n'), "one line: {e}");
    e
}

#[test]
fn annual_bad_inputs_are_one_line_errors() {
    let t = Thresholds::default();
    assert_eq!(
        error_of(&[1.0, f32::NAN], &[9, 10], 1.0, &t),
        "annual metrics: lux at row 1 (1 Jun 10:30), sensor 0 is NaN, not a finite illuminance"
    );
    let e = error_of(&[1.0, f32::INFINITY], &[9, 10], 1.0, &t);
    assert!(e.contains("is inf"), "{e}");
    assert!(error_of(&[1.0, 2.0], &[10, 9], 1.0, &t).contains("rising"));
    let e = error_of(&[1.0, 2.0], &[9, 24], 1.0, &t);
    assert!(e.contains("hour 24 of a period of 24"), "{e}");
    let e = error_of(&[1.0], &[9, 10], 1.0, &t);
    assert!(e.contains("1 values, not 2 hours × 1 sensors"), "{e}");
    assert!(error_of(&[1.0, 2.0], &[9, 10], -1.0, &t).contains("weight -1"));
    let udi = Thresholds {
        udi_low: 3000.0,
        udi_high: 100.0,
        ..t
    };
    let e = error_of(&[1.0, 2.0], &[9, 10], 1.0, &udi);
    assert!(e.contains("UDI limits must rise"), "{e}");
    let da = Thresholds {
        da_lux: f64::NAN,
        ..t
    };
    assert!(error_of(&[1.0, 2.0], &[9, 10], 1.0, &da).contains("DA illuminance"));
}

#[test]
fn annual_indoor_weights_leave_out_outdoor_sensors() {
    let z = |indoor| Zone {
        storey: 0,
        room: 0,
        indoor,
    };
    assert_eq!(
        indoor_weights(&[z(true), z(false), z(true)]),
        [1.0, 0.0, 1.0]
    );
    // None indoors: the grid kept them all, and so do the figures.
    assert_eq!(indoor_weights(&[z(false), z(false)]), [1.0, 1.0]);
    assert!(indoor_weights(&[]).is_empty());
}
