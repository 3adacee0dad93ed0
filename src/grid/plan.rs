//! The false-colour plan of a grid, the picture daylight reports show: one top view per storey,
//! side by side at one scale, each sensor a cell coloured by its illuminance, north up.
//!
//! The colours are those of [`false_colour`]: viridis on a log scale fitted to the values (at
//! most four decades, ends on 1–2–5 steps), with its legend in lux on the right; or, for
//! values that are not illuminances (the annual metrics' % of hours), on a fixed linear scale
//! in their unit ([`PlanScale`]). Each storey
//! ([`storeys`]) is labelled with the height of its lowest sensors ("+0.8 m": the plane's
//! height, not the floor's). A lattice's cells tile the plan; points from a file are drawn as
//! squares of their typical spacing. Where cells overlap (two floors of one storey in a
//! column), the higher sensor is drawn on top, as seen from above.

use super::{spacing, storeys, Sensor};
use crate::render::false_colour::{self, colour_at, Scale, BACKGROUND, LEGEND_WIDTH};
use crate::render::glyphs;
use crate::sky::Compass;
use glam::{DVec2, DVec3};

/// Pixels around and between the panels.
const MARGIN: i64 = 8;
/// The plan's least width, pixels: narrower would leave no room for a panel.
const MIN_WIDTH: u32 = 64;
/// The picture's least height, pixels, so the legend stays readable over a long, flat plan.
const MIN_HEIGHT: u32 = 200;
/// Text, the north marker and the storey labels.
const INK: [u8; 3] = [230, 230, 230];

/// How a plan colours its values and labels its legend and panels.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanScale {
    /// Illuminance: the log scale [`Scale::fit`] fits to the values, the legend in lux, each
    /// panel's figures "Eav 540 lx U0 0.15 Emin/Emax 0.05" (the grid's plan, `grid.png`).
    Lux,
    /// A fixed linear scale from `lo` (the bottom colour) to `hi` (the top; values beyond
    /// either end take its colour), ticks every `step` from `lo`, `unit` on top of the legend
    /// and after each panel's mean: "+0.8 m  av 54 %" (the annual metrics' plans: % of
    /// occupied hours, hours).
    Linear {
        lo: f64,
        hi: f64,
        step: f64,
        unit: String,
    },
}

impl PlanScale {
    /// The colour of `v`.
    fn colour(&self, log: &Scale, v: f64) -> [u8; 3] {
        match self {
            PlanScale::Lux => colour_at(log.t(v)),
            PlanScale::Linear { lo, hi, .. } => colour_at((v - lo) / (hi - lo)),
        }
    }

    /// Draws the legend in the panel from column `x0`.
    fn draw_legend(&self, img: &mut image::RgbImage, x0: u32, log: &Scale) {
        match self {
            PlanScale::Lux => false_colour::draw_legend(img, x0, log, "lux"),
            PlanScale::Linear { lo, hi, step, unit } => {
                let n = if *step > 0.0 && hi > lo {
                    ((hi - lo) / step + 1e-9).floor().min(100.0) as usize
                } else {
                    0
                };
                let ticks: Vec<(f64, String)> = (0..=n)
                    .map(|k| lo + k as f64 * step)
                    .map(|v| ((v - lo) / (hi - lo), false_colour::label(v)))
                    .collect();
                false_colour::draw_legend_ticks(img, x0, unit, &ticks);
            }
        }
    }
}

/// The plan of `sensors` (with `lux`, one value per sensor) oriented by `compass`: panels `width`
/// pixels wide in all (at least 64) and the legend ([`LEGEND_WIDTH`]) to their right; the height
/// follows from the plan's shape. `spacing_hint` is the cell size in metres (the lattice's
/// spacing); 0 estimates it from the points (the median distance to the nearest neighbour).
///
/// # Panics
/// If `lux` does not hold one value per sensor (a caller's bug).
pub fn plan_image(
    sensors: &[Sensor],
    lux: &[f64],
    compass: &Compass,
    spacing_hint: f32,
    width: u32,
) -> image::RgbImage {
    plan_image_scaled(sensors, lux, compass, spacing_hint, width, &PlanScale::Lux)
}

/// [`plan_image`] of any values (one per sensor) on `scale`: the same picture for
/// [`PlanScale::Lux`]; a value that is not finite is drawn as 0.
///
/// # Panics
/// If `values` does not hold one value per sensor (a caller's bug).
pub fn plan_image_scaled(
    sensors: &[Sensor],
    values: &[f64],
    compass: &Compass,
    spacing_hint: f32,
    width: u32,
    scale: &PlanScale,
) -> image::RgbImage {
    assert_eq!(sensors.len(), values.len(), "one value per sensor");
    let local: Vec<DVec3> = sensors
        .iter()
        .map(|s| compass.to_local(s.position.as_dvec3()))
        .collect();
    let storey = storeys(&local.iter().map(|p| p.z).collect::<Vec<_>>());
    let cell = cell_size(&local, &storey, spacing_hint);
    let layout = Layout::new(&local, &storey, cell, width.max(MIN_WIDTH));
    let mut seen: Vec<f64> = values.to_vec();
    let log = Scale::fit(&mut seen);
    let mut img = image::RgbImage::from_pixel(
        layout.width + LEGEND_WIDTH,
        layout.height,
        image::Rgb(BACKGROUND),
    );
    // Bottom up, so the higher of two overlapping cells is seen, as from above.
    let mut order: Vec<usize> = (0..sensors.len()).collect();
    order.sort_by(|&a, &b| local[a].z.total_cmp(&local[b].z));
    for k in order {
        let colour = scale.colour(&log, super::csv::finite(values[k]));
        fill(&mut img, layout.cell(local[k], storey[k]), colour);
    }
    layout.draw_labels(&mut img, &local, &storey, values, scale);
    draw_north(&mut img, layout.font, layout.top);
    scale.draw_legend(&mut img, layout.width, &log);
    img
}

/// The cell size: the hint, else the points' typical spacing, else a twentieth of the plan (a
/// single point, or one per storey), else a metre.
fn cell_size(local: &[DVec3], storey: &[u32], hint: f32) -> f64 {
    if hint > 0.0 && hint.is_finite() {
        return hint as f64;
    }
    let plan: Vec<DVec2> = local.iter().map(|p| p.truncate()).collect();
    spacing::estimate(&plan, storey).unwrap_or_else(|| {
        let (lo, hi) = plan_bounds(local);
        let extent = (hi - lo).max_element() / 20.0;
        if extent > 0.0 {
            extent
        } else {
            1.0
        }
    })
}

/// The plan bounds of the sensors (east, north); zero when there are none.
fn plan_bounds(local: &[DVec3]) -> (DVec2, DVec2) {
    let mut it = local.iter().map(|p| p.truncate());
    let first = it.next().unwrap_or(DVec2::ZERO);
    it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

/// Where things go: panels side by side, one per storey, at one scale.
struct Layout {
    /// Width of the panels' part and height of the whole picture, pixels.
    width: u32,
    height: u32,
    /// Font scale of the labels.
    font: u32,
    /// West and north edges of the cells (metres), and the cell size.
    west: f64,
    north: f64,
    cell: f64,
    /// Pixels per metre.
    ppm: f64,
    /// Left edge of each storey's panel, top edge of all, pixels.
    panel_x: Vec<i64>,
    panel_w: i64,
    panel_h: i64,
    top: i64,
}

impl Layout {
    fn new(local: &[DVec3], storey: &[u32], cell: f64, width: u32) -> Layout {
        let font = if width >= 400 { 2 } else { 1 };
        let fh = (glyphs::HEIGHT * font) as i64;
        let strip = 2 * MARGIN + (glyphs::width("N") * font) as i64;
        let n = storey.iter().max().map_or(1, |&s| s as i64 + 1);
        let panel_w = ((width as i64 - strip - MARGIN - (n - 1) * 2 * MARGIN) / n).max(1);
        let (lo, hi) = plan_bounds(local);
        let extent = hi - lo + DVec2::splat(cell);
        // At most twice as high as wide, so a long north–south plan stays a picture.
        let ppm = (panel_w as f64 / extent.x).min(2.0 * width as f64 / extent.y);
        let panel_h = (extent.y * ppm).ceil() as i64;
        let top = 2 * MARGIN + fh;
        Layout {
            width,
            height: ((top + panel_h + MARGIN) as u32).max(MIN_HEIGHT),
            font,
            west: lo.x - cell / 2.0,
            north: hi.y + cell / 2.0,
            cell,
            ppm,
            panel_x: (0..n).map(|k| strip + k * (panel_w + 2 * MARGIN)).collect(),
            panel_w,
            panel_h,
            top,
        }
    }

    /// The pixels of the cell of the sensor at `p` (local) on `storey`: [x0, x1) × [y0, y1),
    /// at least one pixel, clipped to its panel. Edges round outwards, so neighbouring cells
    /// of a lattice overlap by a pixel at most and never leave a seam.
    fn cell(&self, p: DVec3, storey: u32) -> [i64; 4] {
        let h = self.cell / 2.0;
        let x = |e: f64| (e - self.west) * self.ppm;
        let y = |n: f64| (self.north - n) * self.ppm;
        let (px, py) = (self.panel_x[storey as usize], self.top);
        let x0 = x(p.x - h).floor() as i64;
        let y0 = y(p.y + h).floor() as i64;
        let x1 = (x(p.x + h).ceil() as i64).max(x0 + 1);
        let y1 = (y(p.y - h).ceil() as i64).max(y0 + 1);
        [
            px + x0.clamp(0, self.panel_w),
            py + y0.clamp(0, self.panel_h),
            px + x1.clamp(0, self.panel_w),
            py + y1.clamp(0, self.panel_h),
        ]
    }

    /// Each panel's label: the height of its lowest sensors, "+0.8 m", then, where the panel
    /// is wide enough, its figures: for lux as a lighting designer reads them, "Eav 540 lx U0
    /// 0.15 Emin/Emax 0.05" (or the first two alone); on a linear scale the mean and the
    /// unit, "av 54 %".
    fn draw_labels(
        &self,
        img: &mut image::RgbImage,
        local: &[DVec3],
        storey: &[u32],
        values: &[f64],
        scale: &PlanScale,
    ) {
        let n = self.panel_x.len();
        let mut lowest = vec![f64::INFINITY; n];
        let mut of_panel = vec![Vec::new(); n];
        for ((p, &s), &e) in local.iter().zip(storey).zip(values) {
            lowest[s as usize] = lowest[s as usize].min(p.z);
            of_panel[s as usize].push(super::csv::finite(e));
        }
        for ((x, z), v) in self.panel_x.iter().zip(lowest).zip(&of_panel) {
            if !z.is_finite() {
                continue;
            }
            let s = super::stats::stats(v, &vec![0.0; v.len()]);
            let height = format!("{z:+.1} m");
            let figures = match scale {
                PlanScale::Lux => [
                    format!("  Eav {:.0} lx  U0 {:.2}", s.mean_lux, s.uniformity),
                    format!("  Emin/Emax {:.2}", s.min_over_max),
                ],
                PlanScale::Linear { unit, .. } => {
                    [format!("  av {:.0} {unit}", s.mean_lux), String::new()]
                }
            };
            let fits = |t: &str| (glyphs::width(t) * self.font) as i64 <= self.panel_w;
            let label = [
                height.clone() + &figures[0] + &figures[1],
                height.clone() + &figures[0],
                height,
            ]
            .into_iter()
            .find(|t| fits(t))
            .unwrap_or_default();
            glyphs::draw(img, *x, MARGIN, self.font, &label, INK);
        }
    }
}

/// Fills the rectangle [x0, x1) × [y0, y1) (already inside the image).
fn fill(img: &mut image::RgbImage, [x0, y0, x1, y1]: [i64; 4], colour: [u8; 3]) {
    for y in y0..y1 {
        for x in x0..x1 {
            img.put_pixel(x as u32, y as u32, image::Rgb(colour));
        }
    }
}

/// "N" left of the panels' top, level with them (apart from the storeys' labels above), and an
/// arrow under it pointing up: the plan's north.
fn draw_north(img: &mut image::RgbImage, font: u32, top: i64) {
    let f = font as i64;
    let fh = glyphs::HEIGHT as i64 * f;
    glyphs::draw(img, MARGIN, top, font, "N", INK);
    let cx = MARGIN + (glyphs::width("N") as i64 * f) / 2;
    let tip = top + fh + MARGIN / 2;
    let head = 2 * f;
    for k in 0..=head {
        fill_clipped(img, [cx - k, tip + k, cx + k + 1, tip + k + 1]);
    }
    fill_clipped(img, [cx - f / 2, tip + head, cx - f / 2 + f, tip + 6 * fh]);
}

/// [`fill`] with [`INK`], clipped to the image.
fn fill_clipped(img: &mut image::RgbImage, [x0, y0, x1, y1]: [i64; 4]) {
    let (w, h) = (img.width() as i64, img.height() as i64);
    fill(
        img,
        [
            x0.clamp(0, w),
            y0.clamp(0, h),
            x1.clamp(0, w),
            y1.clamp(0, h),
        ],
        INK,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Two storeys of a 10 × 6 lattice of 0.5 m (Y up, north −Z: rows j run northwards), lux
    /// rising to the east.
    fn two_storeys() -> (Vec<Sensor>, Vec<f64>) {
        let mut s = Vec::new();
        let mut lux = Vec::new();
        for y in [0.8, 3.8] {
            for j in 0..6 {
                for i in 0..10 {
                    s.push(Sensor {
                        position: Vec3::new(0.25 + 0.5 * i as f32, y, -0.25 - 0.5 * j as f32),
                        normal: Vec3::Y,
                    });
                    lux.push(50.0 * (i + 1) as f64 * if y > 1.0 { 10.0 } else { 1.0 });
                }
            }
        }
        (s, lux)
    }

    fn centre_pixel(l: &Layout, p: DVec3, storey: u32) -> (u32, u32) {
        let [x0, y0, x1, y1] = l.cell(p, storey);
        (((x0 + x1) / 2) as u32, ((y0 + y1) / 2) as u32)
    }

    #[test]
    fn grid_plan_colours_every_sensor_cell_with_its_lux() {
        let (s, lux) = two_storeys();
        let compass = Compass::default();
        let img = plan_image(&s, &lux, &compass, 0.5, 600);
        assert_eq!(img.width(), 600 + LEGEND_WIDTH);
        let local: Vec<DVec3> = s
            .iter()
            .map(|x| compass.to_local(x.position.as_dvec3()))
            .collect();
        let storey = storeys(&local.iter().map(|p| p.z).collect::<Vec<_>>());
        assert_eq!(storey.iter().max(), Some(&1));
        let layout = Layout::new(&local, &storey, 0.5, 600);
        assert_eq!(img.height(), layout.height);
        let scale = Scale::fit(&mut lux.clone());
        for k in 0..s.len() {
            let (x, y) = centre_pixel(&layout, local[k], storey[k]);
            assert_eq!(
                img.get_pixel(x, y).0,
                colour_at(scale.t(lux[k])),
                "sensor {k}"
            );
        }
        // The lattice tiles each panel: every pixel inside it is a cell's colour.
        let [x0, .., south] = layout.cell(local[0], 0); // south-west: j = 0, i = 0
        let [_, north, x1, _] = layout.cell(local[59], 0); // north-east: j = 5, i = 9
        assert!(x1 > x0 && south > north);
        let background = (x0..x1)
            .flat_map(|x| (north..south).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x as u32, y as u32).0 == BACKGROUND)
            .count();
        assert_eq!(background, 0);
        // West is left, north is up: the eastern cells are brighter, rows alike.
        let (wx, _) = centre_pixel(&layout, local[0], 0);
        let (ex, _) = centre_pixel(&layout, local[9], 0);
        let (_, ny) = centre_pixel(&layout, local[50], 0);
        let (_, sy) = centre_pixel(&layout, local[0], 0);
        assert!(wx < ex && ny < sy);
        // Labels and the north marker are inked; a second call draws the same picture.
        assert!(img.pixels().filter(|p| p.0 == INK).count() > 50);
        assert_eq!(plan_image(&s, &lux, &compass, 0.5, 600), img);
    }

    #[test]
    fn grid_plan_on_a_linear_scale_colours_by_the_scale_not_the_values() {
        let (s, lux) = two_storeys();
        let compass = Compass::default();
        let scaled = |scale: &PlanScale| plan_image_scaled(&s, &lux, &compass, 0.5, 600, scale);
        assert_eq!(
            scaled(&PlanScale::Lux),
            plan_image(&s, &lux, &compass, 0.5, 600)
        );
        let pct: Vec<f64> = (0..s.len())
            .map(|k| (k % 10) as f64 * 100.0 / 9.0)
            .collect();
        let linear = PlanScale::Linear {
            lo: 0.0,
            hi: 200.0,
            step: 50.0,
            unit: "%".into(),
        };
        let img = plan_image_scaled(&s, &pct, &compass, 0.5, 600, &linear);
        let local: Vec<DVec3> = s
            .iter()
            .map(|x| compass.to_local(x.position.as_dvec3()))
            .collect();
        let storey = storeys(&local.iter().map(|p| p.z).collect::<Vec<_>>());
        let layout = Layout::new(&local, &storey, 0.5, 600);
        for k in 0..s.len() {
            let (x, y) = centre_pixel(&layout, local[k], storey[k]);
            assert_eq!(
                img.get_pixel(x, y).0,
                colour_at(pct[k] / 200.0),
                "sensor {k}"
            );
        }
        assert_ne!(img, scaled(&PlanScale::Lux));
    }

    #[test]
    fn grid_plan_of_points_estimates_their_spacing() {
        let (s, lux) = two_storeys();
        let compass = Compass::default();
        assert_eq!(
            plan_image(&s, &lux, &compass, 0.0, 300),
            plan_image(&s, &lux, &compass, 0.5, 300),
            "a lattice's spacing is found from its points"
        );
        let one = plan_image(&s[..1], &lux[..1], &compass, 0.0, 10);
        assert_eq!(one.width(), MIN_WIDTH + LEGEND_WIDTH);
        assert_eq!(one.height(), MIN_HEIGHT);
        let none = plan_image(&[], &[], &compass, 0.0, 300);
        assert_eq!(none.width(), 300 + LEGEND_WIDTH);
    }
}
