//! Annual daylight: a year of hourly illuminance at the grid sensors from one solve.

pub mod hourly;
