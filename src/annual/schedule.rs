//! The occupied hours: which hours of a weather file the annual metrics count.
//!
//! **The window.** An hour is occupied when its centre, on the clock, lies in [start, end):
//! by default 8 to 18, the "8 AM to 6 PM" of IES LM-83-12 (§2.2.1, *Period of Analysis*), ten
//! hours a day (centres 8.5 … 17.5), 3,650 hours in a 365-day year ([`LM83_HOURS`]).
//!
//! **The clock.** Weather files count local **standard** time ([`crate::weather`]). LM-83-12
//! counts its window in standard time too, all year: that is [`Dst::None`], the default. Under
//! a daylight-saving rule the clock runs one hour ahead of standard time on the dates it
//! covers, so the occupied window is one hour **earlier** in standard time: 7 to 17, centres
//! 7.5 … 16.5. The rules, dates in the schedule's year ([`Occupancy::year`]):
//!
//! - [`Dst::Us`]: from the second Sunday of March to the first Sunday of November (the US
//!   Energy Policy Act of 2005, in force since 2007);
//! - [`Dst::Eu`]: from the last Sunday of March to the last Sunday of October (Directive
//!   2000/84/EC).
//!
//! Clocks change at night (02:00 local in the US, 01:00 UTC in the EU), so the rule is taken
//! by date: the first Sunday is daylight-saving all day, the last (the change back) standard
//! all day. Hours before 3 AM on those two Sundays are the only ones this misdates, and no
//! window that starts after 3 AM contains them.
//!
//! **The year.** A typical-year weather file has no year ([`crate::weather`]), but the
//! Sundays that start and end daylight saving, and the weekdays, need one. The default is
//! [`crate::weather::TYPICAL_YEAR`] (2023, not a leap year; 1 January is a Sunday), the year
//! the weather module dates the hours in, so the schedule's calendar is the one the sky was
//! made for: daylight saving runs 12 March – 4 November (US) and 26 March – 28 October (EU).
//! 29 February, in a leap-year file, takes the weekday of 1 March and is never
//! daylight-saving.
//!
//! **Weekdays.** [`Occupancy::weekdays_only`] leaves out Saturdays and Sundays (off by
//! default: LM-83-12 counts every day of the year). Holidays are not modelled.

use super::Stamp;
use crate::settings::Invalid;
use crate::sky::solar::{days_in_month, DateTime};

/// The occupied hours of IES LM-83-12 in a 365-day year: 8 AM to 6 PM, standard time.
pub const LM83_HOURS: usize = 3650;

/// A daylight-saving rule (see the [module docs](self)).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Dst {
    /// None: standard time all year, as IES LM-83-12 counts (the default).
    #[default]
    None,
    /// The United States: second Sunday of March to first Sunday of November.
    Us,
    /// The European Union: last Sunday of March to last Sunday of October.
    Eu,
}

impl Dst {
    /// The rule's name, as a flag takes it.
    pub fn name(self) -> &'static str {
        match self {
            Dst::None => "none",
            Dst::Us => "us",
            Dst::Eu => "eu",
        }
    }

    /// The first date of daylight saving and the first date after it, (month, day) in `year`;
    /// `None` for [`Dst::None`].
    pub fn dates(self, year: i32) -> Option<((u32, u32), (u32, u32))> {
        match self {
            Dst::None => None,
            Dst::Us => Some(((3, nth_sunday(year, 3, 2)), (11, nth_sunday(year, 11, 1)))),
            Dst::Eu => Some(((3, last_sunday(year, 3)), (10, last_sunday(year, 10)))),
        }
    }
}

/// When a space is occupied: the clock window [start, end) in hours, the daylight-saving rule,
/// the year its dates are taken in and whether weekends count (the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Occupancy {
    /// The window's start on the clock, hours (default 8).
    pub start: f64,
    /// The window's end on the clock, hours, not included (default 18).
    pub end: f64,
    /// The daylight-saving rule (default none: standard time, as LM-83-12).
    pub dst: Dst,
    /// The year the Sundays and weekdays are taken in (default
    /// [`crate::weather::TYPICAL_YEAR`]).
    pub year: i32,
    /// Mondays to Fridays only (default false: every day).
    pub weekdays_only: bool,
}

impl Default for Occupancy {
    fn default() -> Occupancy {
        Occupancy {
            start: 8.0,
            end: 18.0,
            dst: Dst::None,
            year: crate::weather::TYPICAL_YEAR,
            weekdays_only: false,
        }
    }
}

impl Occupancy {
    /// Checks the window (0 ≤ start < end ≤ 24, finite) and the year (1583–9999: the
    /// Gregorian calendar).
    pub fn validate(&self) -> Result<(), Invalid> {
        let ok = |v: f64| v.is_finite() && (0.0..=24.0).contains(&v);
        if !(ok(self.start) && ok(self.end) && self.start < self.end) {
            return Invalid::err(format!(
                "occupied hours {}-{} are not a window of the day (0 <= start < end <= 24)",
                self.start, self.end
            ));
        }
        if !(1583..=9999).contains(&self.year) {
            return Invalid::err(format!(
                "the schedule's year {} is not within 1583-9999",
                self.year
            ));
        }
        Ok(())
    }

    /// Whether the clocks are on daylight-saving time on `month`/`day` of [`Occupancy::year`].
    pub fn is_dst(&self, month: u32, day: u32) -> bool {
        match self.dst.dates(self.year) {
            Some((first, after)) => (month, day) >= first && (month, day) < after,
            None => false,
        }
    }

    /// Whether the hour at `stamp` is occupied: its centre, on the clock, in [start, end)
    /// (one hour later than standard time under daylight saving), on a counted day.
    pub fn is_occupied(&self, stamp: Stamp) -> bool {
        if self.weekdays_only && weekday(self.year, stamp.month, stamp.day) >= 5 {
            return false;
        }
        let shift = if self.is_dst(stamp.month, stamp.day) {
            1.0
        } else {
            0.0
        };
        let clock = stamp.hour + shift;
        self.start <= clock && clock < self.end
    }

    /// [`Occupancy::is_occupied`] of each stamp.
    pub fn occupied(&self, stamps: &[Stamp]) -> Vec<bool> {
        stamps.iter().map(|&s| self.is_occupied(s)).collect()
    }
}

/// The day of the week of a date, 0 = Monday … 6 = Sunday (from the Julian day, Meeus ch. 7).
/// A day past the month's end counts on into the next month (29 February of a common year is
/// 1 March).
pub fn weekday(year: i32, month: u32, day: u32) -> u32 {
    let noon = DateTime {
        year,
        month,
        day,
        hour: 12,
        minute: 0,
        second: 0.0,
        utc_offset: 0.0,
    };
    // JD 0 (at noon) was a Monday.
    noon.julian_day().round().rem_euclid(7.0) as u32
}

/// The day of the month of the `n`th Sunday (from 1) of `month` in `year`.
fn nth_sunday(year: i32, month: u32, n: u32) -> u32 {
    let first = 1 + (6 + 7 - weekday(year, month, 1)) % 7;
    first + 7 * (n - 1)
}

/// The day of the month of the last Sunday of `month` in `year`.
fn last_sunday(year: i32, month: u32) -> u32 {
    let last = days_in_month(year, month);
    last - (weekday(year, month, last) + 1) % 7
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// Every hour of a common year, centres h + 0.5.
    pub(crate) fn year_of_hours() -> Vec<Stamp> {
        let mut out = Vec::with_capacity(8760);
        for month in 1..=12 {
            for day in 1..=days_in_month(2023, month) {
                for h in 0..24 {
                    out.push(Stamp {
                        month,
                        day,
                        hour: h as f64 + 0.5,
                    });
                }
            }
        }
        out
    }

    fn count(o: &Occupancy, stamps: &[Stamp]) -> usize {
        o.occupied(stamps).iter().filter(|&&b| b).count()
    }

    #[test]
    fn annual_weekdays_and_sundays_are_the_calendars() {
        // 1 January 2023 was a Sunday, 2018 a Monday; 29 February 2024 a Thursday.
        assert_eq!(weekday(2023, 1, 1), 6);
        assert_eq!(weekday(2018, 1, 1), 0);
        assert_eq!(weekday(2024, 2, 29), 3);
        assert_eq!(weekday(2000, 1, 1), 5);
        // US: 12 March – 5 November 2023, 10 March – 3 November 2024.
        assert_eq!(Dst::Us.dates(2023), Some(((3, 12), (11, 5))));
        assert_eq!(Dst::Us.dates(2024), Some(((3, 10), (11, 3))));
        // EU: 26 March – 29 October 2023, 31 March – 27 October 2024.
        assert_eq!(Dst::Eu.dates(2023), Some(((3, 26), (10, 29))));
        assert_eq!(Dst::Eu.dates(2024), Some(((3, 31), (10, 27))));
        assert_eq!(Dst::None.dates(2023), None);
    }

    #[test]
    fn annual_lm83_counts_3650_hours_in_standard_time() {
        let year = year_of_hours();
        let o = Occupancy::default();
        assert_eq!(count(&o, &year), LM83_HOURS);
        let day: Vec<bool> = o.occupied(&year[..24]);
        let on: Vec<usize> = (0..24).filter(|&h| day[h]).collect();
        assert_eq!(on, (8..18).collect::<Vec<_>>(), "centres 8.5 … 17.5");
        // A window edge: a centre on the start counts, one on the end does not.
        let at = |hour| Stamp {
            month: 6,
            day: 1,
            hour,
        };
        assert!(o.is_occupied(at(8.0)));
        assert!(!o.is_occupied(at(18.0)));
        assert!(!o.is_occupied(at(7.999)));
        // Daylight saving moves hours, it does not add or drop any.
        for dst in [Dst::Us, Dst::Eu] {
            let d = Occupancy { dst, ..o };
            assert_eq!(count(&d, &year), LM83_HOURS, "{dst:?}");
        }
    }

    #[test]
    fn annual_dst_shifts_the_window_on_the_right_dates() {
        let at = |month, day, hour| Stamp { month, day, hour };
        let us = Occupancy {
            dst: Dst::Us,
            ..Occupancy::default()
        };
        // Saturday 11 March 2023: standard time, 8.5 … 17.5.
        assert!(!us.is_occupied(at(3, 11, 7.5)));
        assert!(us.is_occupied(at(3, 11, 17.5)));
        // Sunday 12 March: daylight saving, 7.5 … 16.5 in standard time.
        assert!(us.is_occupied(at(3, 12, 7.5)));
        assert!(!us.is_occupied(at(3, 12, 17.5)));
        // Saturday 4 November still daylight saving; Sunday 5 November standard again.
        assert!(us.is_occupied(at(11, 4, 7.5)));
        assert!(!us.is_occupied(at(11, 5, 7.5)));
        assert!(us.is_occupied(at(11, 5, 17.5)));
        let eu = Occupancy {
            dst: Dst::Eu,
            ..Occupancy::default()
        };
        assert!(!eu.is_dst(3, 25) && eu.is_dst(3, 26));
        assert!(eu.is_dst(10, 28) && !eu.is_dst(10, 29));
        assert!(!eu.is_occupied(at(3, 25, 7.5)) && eu.is_occupied(at(3, 26, 7.5)));
        // Another year moves the Sundays: EU 2024 starts 31 March.
        let eu24 = Occupancy { year: 2024, ..eu };
        assert!(!eu24.is_dst(3, 30) && eu24.is_dst(3, 31));
        assert!(!eu24.is_dst(2, 29));
    }

    #[test]
    fn annual_weekdays_only_leaves_out_weekends() {
        let year = year_of_hours();
        let o = Occupancy {
            weekdays_only: true,
            ..Occupancy::default()
        };
        // 2023 has 260 weekdays (it starts and ends on a Sunday).
        assert_eq!(count(&o, &year), 2600);
        let at = |day| Stamp {
            month: 1,
            day,
            hour: 12.5,
        };
        assert!(!o.is_occupied(at(1)) && o.is_occupied(at(2)) && !o.is_occupied(at(7)));
    }

    #[test]
    fn annual_occupancy_refuses_empty_windows() {
        let bad = |start, end| Occupancy {
            start,
            end,
            ..Occupancy::default()
        };
        assert!(Occupancy::default().validate().is_ok());
        assert!(bad(0.0, 24.0).validate().is_ok());
        for (s, e) in [
            (18.0, 8.0),
            (8.0, 8.0),
            (-1.0, 8.0),
            (8.0, 25.0),
            (f64::NAN, 8.0),
        ] {
            let err = bad(s, e).validate().unwrap_err().0;
            assert!(err.contains("occupied hours"), "{err}");
        }
        let year = Occupancy {
            year: 1200,
            ..Occupancy::default()
        };
        assert!(year.validate().is_err());
    }
}
