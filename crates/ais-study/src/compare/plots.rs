//! Log-log convergence plots as SVG text (plotters; text is left to the browser's fonts).

use plotters::prelude::*;
use std::ops::Range;

/// One line of a plot: a label and its (x, y) points, both positive.
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// Distinct colours for up to eight series (then they repeat).
const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(127, 127, 127),
];

/// Whether a value can sit on a log axis.
fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// The x and y ranges of a log-log plot of `series`, padded by 15%; None without a point.
fn log_ranges(series: &[Series]) -> Option<(Range<f64>, Range<f64>)> {
    let (xs, ys): (Vec<f64>, Vec<f64>) = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(|&(x, y)| positive(x) && positive(y))
        .unzip();
    let range = |v: &[f64]| {
        let (lo, hi) = v
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        (lo / 1.15)..(hi * 1.15)
    };
    (!xs.is_empty()).then(|| (range(&xs), range(&ys)))
}

/// A log-log line plot.
#[derive(Clone, Copy, Debug)]
pub struct LogLogPlot<'a> {
    /// Its caption.
    pub title: &'a str,
    /// The x axis's label.
    pub x_label: &'a str,
    /// The y axis's label.
    pub y_label: &'a str,
    /// `(width, height)` in pixels.
    pub size: (u32, u32),
}

impl LogLogPlot<'_> {
    /// The plot of `series` as SVG.
    pub fn svg(&self, series: &[Series]) -> Result<String, String> {
        let title = self.title;
        let Some((x_range, y_range)) = log_ranges(series) else {
            // A black scene, or a perfect match: every relMSE is zero.
            return Ok(format!(
                r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}"><text x="12" y="24">{title}: no positive relMSE to plot (a black scene, or a perfect match)</text></svg>"#,
                self.size.0, self.size.1
            ));
        };
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, self.size).into_drawing_area();
            let error = |e: DrawingAreaErrorKind<_>| format!("{title}: {e}");
            root.fill(&WHITE).map_err(error)?;
            let mut chart = ChartBuilder::on(&root)
                .caption(title, ("sans-serif", 18))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(64)
                .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())
                .map_err(error)?;
            chart
                .configure_mesh()
                .x_desc(self.x_label)
                .y_desc(self.y_label)
                .x_labels(5)
                .y_labels(6)
                .x_label_formatter(&|x| format!("{x:.2e}"))
                .y_label_formatter(&|y| format!("{y:.1e}"))
                .draw()
                .map_err(error)?;
            for (i, s) in series.iter().enumerate() {
                let colour = COLOURS[i % COLOURS.len()];
                let points: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|&(x, y)| positive(x) && positive(y))
                    .collect();
                chart
                    .draw_series(LineSeries::new(points, colour.stroke_width(2)))
                    .map_err(error)?
                    .label(s.label.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(error)?;
            root.present().map_err(error)?;
        }
        Ok(svg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_have_a_line_per_series_and_the_labels() {
        let series = vec![
            Series {
                label: "off".into(),
                points: vec![(1.0, 0.1), (2.0, 0.05), (4.0, 0.025)],
            },
            Series {
                label: "aggressive".into(),
                points: vec![(1.0, 0.08), (2.0, 0.04), (0.0, 1.0)],
            },
        ];
        let plot = |title| LogLogPlot {
            title,
            x_label: "seconds",
            y_label: "relMSE",
            size: (480, 320),
        };
        let svg = plot("relMSE").svg(&series).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..40.min(svg.len())]);
        // Each series' colour draws its line and its legend mark.
        for colour in ["#1F77B4", "#D62728"] {
            assert!(svg.matches(colour).count() >= 2, "{colour} in {svg}");
        }
        assert!(!svg.contains("#2CA02C"), "a third series appeared");
        assert!(svg.contains("aggressive") && svg.contains("seconds"));
        assert!(plot("t").svg(&[]).unwrap().contains("no positive relMSE"));
    }
}
