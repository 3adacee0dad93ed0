//! Every plot the tool draws, as PNG bytes: [`draw`] of [`Curve`]s, on plotters' bitmap
//! backend, with text by ab_glyph from a font that ships in a crate (no system fonts needed).
//! `radiosity compare` draws error against time, Fig. 2's decay and Fig. 5's cost per shot
//! (`compare::report::plots`); `radiosity sweep` draws time and memory against patches.

use crate::Error;
use plotters::prelude::*;
use std::sync::Once;

const SIZE: (u32, u32) = (680, 430);
const FONT: &str = "sans-serif";

const COLOURS: [RGBColor; 8] = [
    RGBColor(213, 94, 0),
    RGBColor(0, 114, 178),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(120, 120, 120),
];

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is a valid TTF shipped by the crate; if it ever were not, text would be
        // missing and plotters reports that as a drawing error.
        let _ = plotters::style::register_font(
            FONT,
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

fn plot_error(e: impl std::fmt::Display) -> Error {
    Error::Plot(e.to_string())
}

/// A positive range covering `values` (with a margin), for a log axis.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(v), h.max(v)));
    if !(lo.is_finite() && hi > 0.0) {
        return 0.1..1.0;
    }
    let (lo, hi) = if hi / lo < 1.5 {
        (lo / 1.5, hi * 1.5)
    } else {
        (lo / 1.2, hi * 1.2)
    };
    lo..hi
}

/// One curve per method.
pub struct Curve {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// Draws curves on a chart with a log y axis (and a log x axis if `log_x`) into PNG bytes.
pub fn draw(
    title: &str,
    x_desc: &str,
    y_desc: &str,
    curves: &[Curve],
    log_x: bool,
) -> Result<Vec<u8>, Error> {
    register_font();
    let (w, h) = SIZE;
    let mut buf = vec![0u8; (w * h * 3) as usize];
    let positive = |c: &Curve| -> Vec<(f64, f64)> {
        c.points
            .iter()
            .copied()
            .filter(|&(x, y)| y.is_finite() && y > 0.0 && x.is_finite() && (!log_x || x > 0.0))
            .collect()
    };
    let pts: Vec<Vec<(f64, f64)>> = curves.iter().map(positive).collect();
    let ys = log_range(pts.iter().flatten().map(|p| p.1));
    {
        let root = BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let mut builder = ChartBuilder::on(&root);
        builder
            .caption(title, (FONT, 20))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(64);
        macro_rules! finish {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(x_desc)
                    .y_desc(y_desc)
                    .label_style((FONT, 13))
                    .y_label_formatter(&|v| format!("{v:.2e}"))
                    .draw()
                    .map_err(plot_error)?;
                for (k, (c, p)) in curves.iter().zip(&pts).enumerate() {
                    let colour = COLOURS[k % COLOURS.len()];
                    chart
                        .draw_series(LineSeries::new(p.iter().copied(), colour.stroke_width(2)))
                        .map_err(plot_error)?
                        .label(c.label.clone())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                        });
                }
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .label_font((FONT, 13))
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()
                    .map_err(plot_error)?;
            }};
        }
        if log_x {
            let xs = log_range(pts.iter().flatten().map(|p| p.0));
            finish!(builder
                .build_cartesian_2d(xs.log_scale(), ys.log_scale())
                .map_err(plot_error)?);
        } else {
            finish!(builder
                .build_cartesian_2d(0.0..100.0, ys.log_scale())
                .map_err(plot_error)?);
        }
        root.present().map_err(plot_error)?;
    }
    let img = image::RgbImage::from_raw(w, h, buf)
        .ok_or_else(|| Error::Plot("the plot buffer has the wrong size".into()))?;
    // Plots are committed to the repository (docs/compare): the best compression.
    let mut png = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new_with_quality(
        &mut png,
        image::codecs::png::CompressionType::Best,
        image::codecs::png::FilterType::Adaptive,
    );
    img.write_with_encoder(encoder).map_err(plot_error)?;
    Ok(png)
}
